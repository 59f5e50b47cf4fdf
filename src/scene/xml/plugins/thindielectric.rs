//! `<bsdf type="thindielectric">`: a thin dielectric sheet (`bsdf::thindielectric`): `int_ior`
//! (default `bk7`), `ext_ior` (default `air`), `specular_reflectance` and
//! `specular_transmittance` (default 1).

use super::{Build, Plugin, Run};
use crate::bsdf::interface::Slot;
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "thindielectric", run: Run::Bsdf(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let eta = p.ior("int_ior", "bk7")? / p.ior("ext_ior", "air")?;
    let r = b.color_param(p, "specular_reflectance", Vec3::ONE, Slot::Color(0))?;
    let t = b.color_param(p, "specular_transmittance", Vec3::ONE, Slot::Color(1))?;
    Ok(super::diffuse::registry_material(crate::bsdf::thindielectric::params(eta, r, t)))
}

//! `<bsdf type="dielectric">`: a smooth dielectric boundary (`bsdf::dielectric`): `int_ior`
//! (default `bk7`), `ext_ior` (default `air`), each a number or a name of Mitsuba's table;
//! `specular_reflectance` and `specular_transmittance` (default 1).

use super::{Build, Plugin, Run};
use crate::bsdf::interface::Slot;
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "dielectric", run: Run::Bsdf(run) };

/// The relative index int_ior / ext_ior of a dielectric-like element.
pub fn relative_ior(p: &Props) -> Result<f32, SceneError> {
    Ok(p.ior("int_ior", "bk7")? / p.ior("ext_ior", "air")?)
}

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let eta = relative_ior(p)?;
    let r = b.color_param(p, "specular_reflectance", Vec3::ONE, Slot::Color(0))?;
    let t = b.color_param(p, "specular_transmittance", Vec3::ONE, Slot::Color(1))?;
    Ok(super::diffuse::registry_material(crate::bsdf::dielectric::params(eta, r, t)))
}

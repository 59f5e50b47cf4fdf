//! `<bsdf type="roughdielectric">`: a rough dielectric boundary (`bsdf::roughdielectric`):
//! `distribution`, `alpha` or `alpha_u`/`alpha_v`, `sample_visible` as `roughconductor`;
//! `int_ior` (`bk7`), `ext_ior` (`air`); `specular_reflectance` and `specular_transmittance` (1).

use super::{Build, Plugin, Run};
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "roughdielectric", run: Run::Bsdf(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let (kind, au, av, visible) = super::roughconductor::microfacet(p, true)?;
    let eta = super::dielectric::relative_ior(p)?;
    let r = p.rgb_only("specular_reflectance", Vec3::ONE)?;
    let t = p.rgb_only("specular_transmittance", Vec3::ONE)?;
    Ok(super::diffuse::registry_material(crate::bsdf::roughdielectric::params(kind, au, av, visible, eta, r, t)))
}

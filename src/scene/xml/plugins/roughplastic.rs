//! `<bsdf type="roughplastic">`: rough plastic (`bsdf::roughplastic`): `distribution`
//! (`beckmann`), `alpha` (0.1; isotropic only, as Mitsuba), `sample_visible` (true),
//! `diffuse_reflectance` (0.5), `specular_reflectance` (1), `int_ior` (`polypropylene`),
//! `ext_ior` (`air`), `nonlinear` (false). The reflectances may be textures (per hit; the lobe
//! choice's weight uses their means, as Mitsuba's); `alpha` is a float, as Mitsuba's. One-sided
//! unless in a `twosided`.

use super::{Build, Plugin, Run};
use crate::bsdf::interface::Slot;
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "roughplastic", run: Run::Bsdf(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let (kind, alpha, _, visible) = super::roughconductor::microfacet(b, p, false, None)?;
    let d = b.color_param(p, "diffuse_reflectance", Vec3::splat(0.5), Slot::Color(0))?;
    let s = b.color_param(p, "specular_reflectance", Vec3::ONE, Slot::Color(1))?;
    let eta = p.ior("int_ior", "polypropylene")? / p.ior("ext_ior", "air")?;
    let nonlinear = p.bool("nonlinear", false)?;
    Ok(super::diffuse::registry_material(crate::bsdf::roughplastic::params(kind, alpha, visible, eta, d, s, nonlinear)))
}

//! `<bsdf type="roughdielectric">`: a rough dielectric boundary (`bsdf::roughdielectric`):
//! `distribution`, `alpha` or `alpha_u`/`alpha_v`, `sample_visible` as `roughconductor`;
//! `int_ior` (`bk7`), `ext_ior` (`air`); `specular_reflectance` and `specular_transmittance` (1).

use super::{Build, Plugin, Run};
use crate::bsdf::interface::Slot;
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "roughdielectric", run: Run::Bsdf(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let (kind, au, av, visible) =
        super::roughconductor::microfacet(b, p, true, Some([Slot::Scalar(1), Slot::Scalar(2)]))?;
    let eta = super::dielectric::relative_ior(p)?;
    let r = b.color_param(p, "specular_reflectance", Vec3::ONE, Slot::Color(0))?;
    let t = b.color_param(p, "specular_transmittance", Vec3::ONE, Slot::Color(1))?;
    Ok(super::diffuse::registry_material(crate::bsdf::roughdielectric::params(kind, au, av, visible, eta, r, t)))
}

//! `<bsdf type="roughconductor">`: a rough metal (`bsdf::roughconductor`). `distribution`
//! (`beckmann` default, `ggx`), `alpha` (0.1) or `alpha_u` and `alpha_v` (anisotropic),
//! `sample_visible` (true), `material` or `eta`/`k` as `conductor` (default `none`: a perfect
//! mirror), `specular_reflectance` (1). Textured roughness or reflectance is refused, naming the
//! property. One-sided unless in a `twosided`.

use super::{Build, Plugin, Run};
use crate::bsdf::microfacet::Distribution;
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "roughconductor", run: Run::Bsdf(run) };

/// Mitsuba's microfacet properties of a rough BSDF: (distribution, alpha_u, alpha_v,
/// sample_visible); `anisotropic` allows `alpha_u`/`alpha_v` (both required together, not with
/// `alpha`).
pub fn microfacet(p: &Props, anisotropic: bool) -> Result<(Distribution, f32, f32, bool), SceneError> {
    let kind = match p.string("distribution")? {
        None => Distribution::Beckmann,
        Some(name) => Distribution::from_name(name).ok_or_else(|| {
            let at = p.get("distribution").map_or(&p.elem.at, |e| &e.at);
            at.err(format!("{}: unknown distribution \"{name}\" (expected beckmann or ggx)", p.elem.what()))
        })?,
    };
    let alpha = |name: &str, default: f32| -> Result<f32, SceneError> {
        let a = p.float(name, default)?;
        if !(a.is_finite() && a >= 0.0) {
            let at = p.get(name).map_or(&p.elem.at, |e| &e.at);
            return Err(at.err(format!("{}: \"{name}\" must be a finite roughness >= 0, not {a}", p.elem.what())));
        }
        Ok(a)
    };
    let (au, av) = if anisotropic && (p.has("alpha_u") || p.has("alpha_v")) {
        if p.has("alpha") || !(p.has("alpha_u") && p.has("alpha_v")) {
            return Err(p
                .elem
                .at
                .err(format!("{}: give \"alpha\", or both \"alpha_u\" and \"alpha_v\"", p.elem.what())));
        }
        (alpha("alpha_u", 0.1)?, alpha("alpha_v", 0.1)?)
    } else {
        let a = alpha("alpha", 0.1)?;
        (a, a)
    };
    Ok((kind, au, av, p.bool("sample_visible", true)?))
}

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let (kind, au, av, visible) = microfacet(p, true)?;
    let (eta, k) = super::conductor::eta_k(p)?;
    let specular = p.rgb_only("specular_reflectance", Vec3::ONE)?;
    Ok(super::diffuse::registry_material(crate::bsdf::roughconductor::params(kind, au, av, visible, eta, k, specular)))
}

//! `<bsdf type="roughconductor">`: a rough metal (`bsdf::roughconductor`). `distribution`
//! (`beckmann` default, `ggx`), `alpha` (0.1) or `alpha_u` and `alpha_v` (anisotropic),
//! `sample_visible` (true), `material` or `eta`/`k` as `conductor` (default `none`: a perfect
//! mirror), `specular_reflectance` (1). Roughness, eta, k and reflectance may be textures (evaluated per
//! hit into the row's slots). One-sided unless in a `twosided`.

use super::{Build, Plugin, Run};
use crate::bsdf::interface::Slot;
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
pub fn microfacet<'e>(
    b: &mut Build<'e>,
    p: &Props<'e>,
    anisotropic: bool,
    slots: Option<[Slot; 2]>,
) -> Result<(Distribution, f32, f32, bool), SceneError> {
    let kind = match p.string("distribution")? {
        None => Distribution::Beckmann,
        Some(name) => Distribution::from_name(name).ok_or_else(|| {
            let at = p.get("distribution").map_or(&p.elem.at, |e| &e.at);
            at.err(format!("{}: unknown distribution \"{name}\" (expected beckmann or ggx)", p.elem.what()))
        })?,
    };
    let alpha = |b: &mut Build<'e>, name: &str, slot: usize| -> Result<f32, SceneError> {
        let a = b.float_param(p, name, 0.1, slots.map(|s| s[slot]))?;
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
        (alpha(b, "alpha_u", 0)?, alpha(b, "alpha_v", 1)?)
    } else {
        let a = alpha(b, "alpha", 0)?;
        // One texture gives both alphas.
        if let (Some([u, v]), Some(&(last, t))) = (slots, b.pending_params.last()) {
            if last == u && p.get("alpha").is_some_and(|e| e.tag == "texture") {
                b.pending_params.push((v, t));
            }
        }
        (a, a)
    };
    Ok((kind, au, av, p.bool("sample_visible", true)?))
}

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let (kind, au, av, visible) = microfacet(b, p, true, Some([Slot::Scalar(0), Slot::Scalar(1)]))?;
    let (eta, k) = super::conductor::eta_k(b, p)?;
    let specular = b.color_param(p, "specular_reflectance", Vec3::ONE, Slot::Color(2))?;
    Ok(super::diffuse::registry_material(crate::bsdf::roughconductor::params(kind, au, av, visible, eta, k, specular)))
}

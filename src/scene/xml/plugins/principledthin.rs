//! `<bsdf type="principledthin">`: Mitsuba's thin principled BSDF (`bsdf::principledthin`), a
//! two-sided sheet: `base_color` (0.5; rgb or texture), `roughness` (0.5), `anisotropic`,
//! `spec_trans`, `spec_tint`, `sheen`, `sheen_tint`, `flatness`, `diff_trans` (0, in [0, 2]),
//! `eta` (1.5) (floats or textures, read as Mitsuba's `eval_1`; at most four textured scalars per
//! BSDF), and the sampling rates `specular_reflectance_sampling_rate`,
//! `specular_transmittance_sampling_rate`, `diffuse_reflectance_sampling_rate`,
//! `diffuse_transmittance_sampling_rate` (1).

use super::{Build, Plugin, Run};
use crate::bsdf::interface::Slot;
use crate::bsdf::principledthin::{params, PARAMS};
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "principledthin", run: Run::Bsdf(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let base = b.color_param(p, "base_color", Vec3::splat(0.5), Slot::Color(0))?;
    let entry = super::principled::scalars(b, p, &PARAMS, &[])?;
    let j = PARAMS.iter().position(|q| q.0 == "eta").unwrap_or(0);
    if entry.values[j] <= 0.0 {
        let at = p.get("eta").map_or(&p.elem.at, |e| &e.at);
        return Err(at.err(format!("{}: \"eta\" must be > 0, not {}", p.elem.what(), entry.values[j])));
    }
    Ok(super::diffuse::registry_material(params(base, entry)))
}

//! `<bsdf type="blendbsdf">`: Mitsuba's blend of two nested BSDFs by `weight` (float or
//! `<texture>`, evaluated per hit; default 0.5): `(1 - weight)` of the first plus `weight` of the
//! second (`bsdf::blendbsdf`). strata blends two `diffuse` BSDFs of constant reflectance; any
//! other pair is refused, naming the nested BSDF.

use super::{Build, Plugin, Run};
use crate::bsdf::interface::{Slot, COURSE};
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "blendbsdf", run: Run::Bsdf(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let inner = p.objects("bsdf");
    let [first, second] = inner.as_slice() else {
        return Err(p.elem.at.err(format!("{} takes two nested <bsdf>, not {}", p.elem.what(), inner.len())));
    };
    let weight = b.float_param(p, "weight", 0.5, Some(Slot::Scalar(0)))?;
    if !weight.is_finite() {
        let at = p.get("weight").map_or(&p.elem.at, |e| &e.at);
        return Err(at.err(format!("{}: \"weight\" must be finite, not {weight}", p.elem.what())));
    }
    let mut lambert = |e: &'e crate::scene::xml::doc::Elem| -> Result<Vec3, SceneError> {
        let before = b.pending_texture;
        let m = b.bsdf(e)?;
        let plain = m.bsdf.kind == COURSE && m.specular == Vec3::ZERO && !crate::bsdf::mask::masked(&m.bsdf);
        if !plain || b.pending_texture != before || e.attr("type") != Some("diffuse") {
            return Err(e.at.err(format!(
                "{}: strata blends two `diffuse` BSDFs of constant reflectance, not {}",
                p.elem.what(),
                e.what()
            )));
        }
        Ok(m.diffuse)
    };
    let (r0, r1) = (lambert(first)?, lambert(second)?);
    Ok(super::diffuse::registry_material(crate::bsdf::blendbsdf::params(r0, r1, weight.clamp(0.0, 1.0))))
}

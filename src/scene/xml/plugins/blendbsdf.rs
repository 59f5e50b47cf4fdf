//! `<bsdf type="blendbsdf">`: Mitsuba's blend of two nested BSDFs by `weight` (float or
//! `<texture>`, evaluated per hit; default 0.5): `(1 - weight)` of the first plus `weight` of the
//! second (`bsdf::blendbsdf`). The nested BSDFs are any the XML front end makes (`diffuse`, the
//! registry's, `twosided`, `mask`, another `blendbsdf`), with constant parameters: a texture
//! inside a nested BSDF, or a nested `normalmap`/`bumpmap`, is refused naming the nested element.

use super::{Build, Plugin, Run};
use crate::bsdf::interface::{BsdfParams, Slot, COURSE};
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::doc::Elem;
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
    let (r0, r1) = (nested(b, p, first)?, nested(b, p, second)?);
    let weight = b.float_param(p, "weight", 0.5, Some(Slot::Scalar(0)))?;
    if !weight.is_finite() {
        let at = p.get("weight").map_or(&p.elem.at, |e| &e.at);
        return Err(at.err(format!("{}: \"weight\" must be finite, not {weight}", p.elem.what())));
    }
    Ok(super::diffuse::registry_material(crate::bsdf::blendbsdf::params(r0, r1, weight.clamp(0.0, 1.0))))
}

/// The row of the nested `<bsdf>` `e` of the blend `p`.
fn nested<'e>(b: &mut Build<'e>, p: &Props<'e>, e: &'e Elem) -> Result<BsdfParams, SceneError> {
    let (texture, params, frame) = (b.pending_texture.take(), b.pending_params.clone(), b.pending_frame.take());
    let m = b.bsdf(e)?;
    let textured = b.pending_texture.is_some() || b.pending_params != params;
    let mapped = b.pending_frame.is_some();
    (b.pending_texture, b.pending_params, b.pending_frame) = (texture, params, frame);
    let refuse = |what: &str| Err(e.at.err(format!("{}: {what} inside a blendbsdf is not supported", p.elem.what())));
    if textured {
        return refuse(&format!("a textured parameter of {}", e.what()));
    }
    if mapped {
        return refuse(&format!("{} (a normal or bump map)", e.what()));
    }
    if m.bsdf.kind != COURSE {
        return Ok(m.bsdf);
    }
    if m.specular != Vec3::ZERO {
        return refuse(&format!("{} (a course material)", e.what()));
    }
    let r = crate::bsdf::blendbsdf::lambert(m.diffuse);
    Ok(BsdfParams { twosided: m.bsdf.twosided, opacity: m.bsdf.opacity, ..r })
}

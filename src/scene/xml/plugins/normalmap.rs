//! `<bsdf type="normalmap">`: Mitsuba 3's normal-map wrapper of one nested BSDF. The texture
//! `normalmap` (raw RGB `t`, a `bitmap` or `rawconstant`) gives the shading normal `2 t - 1` in
//! the hit's shading frame; the nested BSDF is shaded in the perturbed frame
//! (`scene::desc::FrameMap::Normal`, applied at hits by `scene/perturb.rs`).
//! `flip_invalid_normals` and `use_shadowing_function` are Mitsuba's defaults (true); false is
//! refused.

use super::{Build, Plugin, Run};
use crate::scene::desc::{FrameMap, Material};
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "normalmap", run: Run::Bsdf(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let texture = match p.color("normalmap", false)? {
        Some(Color::Texture(t)) => b.texture(t)?,
        Some(Color::Rgb(_)) => {
            return Err(p.elem.at.err("normalmap's \"normalmap\" must be a <texture> (bitmap or rawconstant)"))
        }
        None => return Err(p.elem.at.err("normalmap needs a <texture name=\"normalmap\">")),
    };
    let m = super::bumpmap::nested(b, p)?;
    b.pending_frame = Some(FrameMap::Normal { texture });
    Ok(m)
}

//! `<bsdf type="bumpmap">`: Mitsuba 3's bump-map wrapper of one nested BSDF. Its one nested
//! `<texture>` (any name; a `bitmap` or `rawconstant`) is a height field: the gradient in uv of
//! its luminance times `scale` (default 1) displaces the surface along the shading normal, and the
//! nested BSDF is shaded in the frame of the displaced surface (`scene::desc::FrameMap::Bump`,
//! applied at hits by `scene/perturb.rs`). `flip_invalid_normals` and `use_shadowing_function`
//! are Mitsuba's defaults (true); false is refused.

use super::{Build, Plugin, Run};
use crate::scene::desc::{FrameMap, Material};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "bumpmap", run: Run::Bsdf(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let scale = p.float("scale", 1.0)?;
    if !scale.is_finite() {
        return Err(p.elem.at.err(format!("bumpmap: \"scale\" must be finite, not {scale}")));
    }
    let texture = match p.objects("texture").as_slice() {
        [t] => {
            let i = b.texture(t)?;
            let probe = crate::texture::TexQuery {
                uv: glam::Vec2::ZERO,
                tri: crate::texture::NO_TRIANGLE,
                bary: glam::Vec2::ZERO,
            };
            if b.desc.textures[i as usize].grad_luminance(&probe).is_none() {
                return Err(t.at.err(format!("bumpmap: {} has no gradient (use a bitmap)", t.what())));
            }
            i
        }
        _ => return Err(p.elem.at.err("bumpmap takes one nested <texture> (the height field)")),
    };
    let m = nested(b, p)?;
    b.pending_frame = Some(FrameMap::Bump { texture, scale });
    Ok(m)
}

/// The material of a wrapper's one nested `<bsdf>` (normalmap, bumpmap), with Mitsuba's flags
/// `flip_invalid_normals` and `use_shadowing_function` checked (only their defaults, true). A
/// second wrapper inside is refused.
pub fn nested<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    for flag in ["flip_invalid_normals", "use_shadowing_function"] {
        if !p.bool(flag, true)? {
            let at = p.get(flag).map_or(&p.elem.at, |e| &e.at);
            return Err(at.err(format!("{}: \"{flag}\" false is not supported", p.elem.what())));
        }
    }
    let inner = p.objects("bsdf");
    let [one] = inner.as_slice() else {
        return Err(p.elem.at.err(format!("{} takes exactly one nested <bsdf>", p.elem.what())));
    };
    let m = b.bsdf(one)?;
    if b.pending_frame.is_some() {
        return Err(one.at.err(format!("{} inside another normalmap or bumpmap is not supported", one.what())));
    }
    Ok(m)
}

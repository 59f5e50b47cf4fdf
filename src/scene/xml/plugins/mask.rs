//! `<bsdf type="mask">`: Mitsuba's opacity mask (`bsdf::mask`) around one nested `<bsdf>`:
//! `opacity` (float, spectrum or rgb: its luminance; or a `<texture>`, evaluated per hit;
//! default 0.5), clamped to [0, 1]. A textured opacity keeps the texture's mean (below 1) in the
//! row, so the scene's kernel compiles masks in.

use super::{Build, Plugin, Run};
use crate::bsdf::interface::Slot;
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "mask", run: Run::Bsdf(run) };

/// Largest f32 below 1.
const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let inner = p.objects("bsdf");
    let [one] = inner.as_slice() else {
        return Err(p.elem.at.err(format!("{} takes exactly one nested <bsdf>, not {}", p.elem.what(), inner.len())));
    };
    let opacity = match p.color("opacity", false)? {
        None => 0.5,
        Some(Color::Rgb(c)) => {
            let o = crate::texture::scalar(c);
            if !o.is_finite() {
                let at = p.get("opacity").map_or(&p.elem.at, |e| &e.at);
                return Err(at.err(format!("{}: \"opacity\" must be finite, not {o}", p.elem.what())));
            }
            o.clamp(0.0, 1.0)
        }
        Some(Color::Texture(t)) => {
            let i = b.texture_param(Slot::Opacity, t)?;
            let mean = b.desc.textures[i as usize].mean();
            crate::texture::luminance(mean).clamp(0.0, ONE_MINUS)
        }
    };
    let mut m = b.bsdf(one)?;
    if crate::bsdf::mask::masked(&m.bsdf) {
        return Err(one.at.err(format!("{}: a mask inside a mask is not supported", p.elem.what())));
    }
    m.bsdf.opacity = opacity;
    Ok(m)
}

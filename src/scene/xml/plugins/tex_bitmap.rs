//! `<texture type="bitmap">`: `filename` (PNG/JPEG/BMP/HDR/EXR), `raw`, `filter_type`
//! (bilinear, nearest), `wrap_mode` (repeat, mirror, clamp), `to_uv`; `format` (Mitsuba's storage
//! precision) is read and ignored: texels are f32.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::texture::{Bitmap, BitmapLimits, BitmapOptions, BitmapTexture, FilterType, Texture, UvTransform, WrapMode};
use std::sync::Arc;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "texture", kind: "bitmap", run: Run::Texture(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Texture, SceneError> {
    let path = b.file(p)?;
    let raw = p.bool("raw", false)?;
    let filter = match p.string("filter_type")? {
        None => FilterType::default(),
        Some(f) => FilterType::from_name(f)
            .ok_or_else(|| p.elem.at.err(format!("unknown filter_type \"{f}\" (supported: bilinear, nearest)")))?,
    };
    let wrap = match p.string("wrap_mode")? {
        None => WrapMode::default(),
        Some(w) => WrapMode::from_name(w)
            .ok_or_else(|| p.elem.at.err(format!("unknown wrap_mode \"{w}\" (supported: repeat, mirror, clamp)")))?,
    };
    let to_uv = UvTransform::from_mat4(p.transform("to_uv")?);
    p.ignore("id");
    // Mitsuba's storage precision (`variant`, `uint8`...): strata keeps texels in f32 either way.
    p.ignore("format");
    let bitmap = Bitmap::load(&path, &BitmapOptions { raw, filter, wrap }, &BitmapLimits::default())
        .map_err(|e| p.elem.at.err(format!("{}: {e}", p.elem.what())))?;
    Ok(Texture::BitmapTexture(BitmapTexture { bitmap: Arc::new(bitmap), to_uv }))
}

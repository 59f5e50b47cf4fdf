//! `<film type="hdrfilm">`: `width`, `height` (default 768 x 576), the crop window
//! (`crop_offset_x/y`, `crop_width/height`: the image is the window, the projection the full
//! frame's), and its
//! nested `rfilter` (default: Mitsuba's gaussian). Output format settings are strata's own.

use super::{Build, Plugin, Run};
use crate::scene::desc::FilmCrop;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "film", kind: "hdrfilm", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let side = |name: &str, default: i64| -> Result<u32, SceneError> {
        let v = p.int(name, default)?;
        if v < 1 || v > i64::from(b.limits.max_side) {
            return Err(p.elem.at.err(format!("film {name} {v} must be in 1..={}", b.limits.max_side)));
        }
        Ok(v as u32)
    };
    let (w, h) = (side("width", 768)?, side("height", 576)?);
    if u64::from(w) * u64::from(h) > b.limits.max_pixels {
        return Err(p.elem.at.err(format!("film {w}x{h} is over the limit of {} pixels", b.limits.max_pixels)));
    }
    let (cx, cy) = (p.int("crop_offset_x", 0)?, p.int("crop_offset_y", 0)?);
    let (cw, ch) = (p.int("crop_width", i64::from(w))?, p.int("crop_height", i64::from(h))?);
    let inside = |o: i64, n: i64, full: u32| o >= 0 && n >= 1 && o + n <= i64::from(full);
    if !inside(cx, cw, w) || !inside(cy, ch, h) {
        return Err(p.elem.at.err(format!(
            "crop window {cw}x{ch} at ({cx}, {cy}) does not fit in the {w}x{h} film (offsets >= 0, sizes >= 1)"
        )));
    }
    if (cx, cy, cw, ch) == (0, 0, i64::from(w), i64::from(h)) {
        b.desc.width = w;
        b.desc.height = h;
    } else {
        b.desc.width = cw as u32;
        b.desc.height = ch as u32;
        b.desc.crop = Some(FilmCrop { full_width: w, full_height: h, x: cx as u32, y: cy as u32 });
    }
    // Output formatting: strata writes RGB float EXR (and PNG) itself.
    for name in ["pixel_format", "component_format", "file_format", "banner", "sample_border", "compensate"] {
        p.ignore(name);
    }
    match p.object("rfilter")? {
        Some(f) => b.run_scene(f)?,
        // Mitsuba's default filter.
        None => b.desc.filter = crate::scene::desc::PixelFilter::Gaussian { stddev: 0.5 },
    }
    Ok(())
}

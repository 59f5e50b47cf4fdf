//! `<film type="hdrfilm">`: `width`, `height` (default 768 x 576), a full-frame crop, and its
//! nested `rfilter` (default: Mitsuba's gaussian). Output format settings are strata's own.

use super::{Build, Plugin, Run};
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
    if (cx, cy, cw, ch) != (0, 0, i64::from(w), i64::from(h)) {
        return Err(p.elem.at.err("a film crop window is not supported yet (render the full frame)"));
    }
    b.desc.width = w;
    b.desc.height = h;
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

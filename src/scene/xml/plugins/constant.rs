//! `<emitter type="constant">`: uniform environment `radiance` (default 1), strata's sky
//! (path tracer only).

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "emitter", kind: "constant", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let r = match p.color("radiance", true)? {
        Some(Color::Rgb(c)) => c,
        Some(Color::Texture(t)) => return Err(t.at.err("a textured constant emitter is not supported")),
        // Mitsuba's default is a uniform spectrum of 1, which its RGB variants make xyz_to_srgb(1).
        None => crate::scene::xml::values::spectrum_default_emitter(),
    };
    if b.desc.sky.is_some() {
        return Err(p.elem.at.err("a second constant emitter is not supported"));
    }
    b.desc.sky = Some(r);
    Ok(())
}

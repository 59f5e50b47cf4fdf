//! `<rfilter type="box">`: the one-pixel box filter, strata's pixel jitter.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "rfilter", kind: "box", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let r = p.float("radius", 0.5)?;
    if r != 0.5 {
        return Err(p.elem.at.err(format!("a box filter of radius {r} is not supported (only 0.5: one pixel)")));
    }
    b.desc.filter = crate::scene::desc::PixelFilter::Box;
    Ok(())
}

//! `<rfilter type="gaussian">`: Mitsuba's default filter (`stddev` 0.5), by filter importance
//! sampling.

use super::{Build, Plugin, Run};
use crate::scene::desc::PixelFilter;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "rfilter", kind: "gaussian", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let stddev = p.float("stddev", 0.5)?;
    if !(stddev > 0.0 && stddev <= 16.0) {
        return Err(p.elem.at.err(format!("gaussian stddev {stddev} must be in (0, 16]")));
    }
    b.desc.filter = PixelFilter::Gaussian { stddev };
    Ok(())
}

//! `<integrator type="moment">`: Mitsuba's wrapper adding moment outputs; strata renders its one
//! nested integrator (its variance is in strata's own statistics).

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "integrator", kind: "moment", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    match p.objects("integrator").as_slice() {
        [one] => {
            b.warn(&p.elem.at, "the moment integrator is unwrapped: strata renders its nested integrator");
            b.run_scene(one)
        }
        _ => Err(p.elem.at.err("moment takes exactly one nested <integrator> here")),
    }
}

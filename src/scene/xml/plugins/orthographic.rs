//! `<sensor type="orthographic">`: parallel rays along `to_world`'s +z over its scaled unit view,
//! from `near_clip`; its nested `film` and `sampler` (see `perspective::sensor`).

use super::{Build, Plugin, Run};
use crate::scene::desc::Projection;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "sensor", kind: "orthographic", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    super::perspective::sensor(b, p, Projection::Orthographic)
}

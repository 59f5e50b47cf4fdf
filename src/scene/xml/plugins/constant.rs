//! `<emitter type="constant">`: uniform environment `radiance` (Mitsuba's default: a uniform
//! spectrum of 1, in its RGB variants `xyz_to_srgb(1, 1, 1)`).

use super::{Build, Plugin, Run};
use crate::scene::desc::EnvironmentDesc;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "emitter", kind: "constant", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let r = b.emitter_rgb(p, "radiance")?;
    b.set_environment(p, EnvironmentDesc::Constant(r))
}

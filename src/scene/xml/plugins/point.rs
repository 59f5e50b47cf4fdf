//! `<emitter type="point">`: `intensity` (W/sr) at `position` (or `to_world`'s origin).

use super::{Build, Plugin, Run};
use crate::scene::desc::DeltaLightDesc;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "emitter", kind: "point", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let position = match p.vec3("position")? {
        Some(v) => v,
        None => p.transform("to_world")?.transform_point3(Vec3::ZERO),
    };
    let intensity = b.emitter_rgb(p, "intensity")?;
    p.ignore("id");
    b.desc.delta_lights.push(DeltaLightDesc::Point { position, intensity });
    Ok(())
}

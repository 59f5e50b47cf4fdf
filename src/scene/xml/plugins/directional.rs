//! `<emitter type="directional">`: `irradiance` travelling along `direction` (or `to_world`
//! applied to +z).

use super::{Build, Plugin, Run};
use crate::scene::desc::DeltaLightDesc;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "emitter", kind: "directional", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let d = match p.vec3("direction")? {
        Some(v) => v,
        None => p.transform("to_world")?.transform_vector3(Vec3::Z),
    };
    if !(d.length_squared() > 0.0) {
        return Err(p.elem.at.err("a directional emitter needs a non-zero direction"));
    }
    let irradiance = b.emitter_rgb(p, "irradiance")?;
    p.ignore("id");
    b.desc.delta_lights.push(DeltaLightDesc::Directional { direction: d.normalize(), irradiance });
    Ok(())
}

//! `<emitter type="envmap">`: a latitude-longitude image (`filename`, EXR/HDR/PNG/...), `scale`,
//! `to_world`; importance sampled by the renderer.

use super::{Build, Plugin, Run};
use crate::scene::desc::EnvironmentDesc;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "emitter", kind: "envmap", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let path = b.file(p)?;
    let image = b.load_image(p, &path, false)?;
    let scale = p.float("scale", 1.0)?;
    let to_world = p.transform("to_world")?;
    p.ignore("id");
    b.set_environment(p, EnvironmentDesc::Envmap { image, scale, to_world })
}

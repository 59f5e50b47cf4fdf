//! `<shape type="cube">`: Mitsuba's cube (its parameterization and uvs) through `to_world`.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::{self, ShapeOut};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "cube", run: Run::Shape(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    shape::mesh(p, crate::scene::mesh::shapes::cube())
}

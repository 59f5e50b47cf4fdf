//! `<shape type="shapegroup">`: shapes declared for `instance`s (placed only through them).

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::ShapeOut;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "shapegroup", run: Run::Shape(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    p.ignore("id");
    // The members are read (and checked) by every instance.
    p.objects("shape");
    Ok(ShapeOut::Nothing)
}

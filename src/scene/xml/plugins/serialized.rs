//! `<shape type="serialized">`: Mitsuba's compressed mesh format (`filename`, `shape_index`).

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::{self, ShapeOut};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "serialized", run: Run::Shape(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    let path = b.file(p)?;
    let index = p.int("shape_index", 0)?;
    let index = u32::try_from(index).map_err(|_| p.elem.at.err(format!("shape_index {index} must be >= 0")))?;
    let m =
        crate::scene::mesh::serialized::load_serialized(&path, index, b.limits).map_err(|e| shape::load_error(p, e))?;
    shape::mesh(p, m)
}

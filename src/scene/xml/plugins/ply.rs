//! `<shape type="ply">`: a PLY mesh (`filename`; ASCII or binary, with vertex and face attributes).

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::{self, ShapeOut};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "ply", run: Run::Shape(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    let path = b.file(p)?;
    let m = crate::scene::mesh::ply::load_ply(&path, b.limits).map_err(|e| shape::load_error(p, e))?;
    shape::mesh(p, m)
}

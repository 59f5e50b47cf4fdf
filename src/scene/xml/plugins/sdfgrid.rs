//! `<shape type="sdfgrid">`: a signed-distance grid (`filename`, a `.vol`), meshed at 4x the grid
//! resolution (see `scene::mesh::sdfgrid` for how close that is); `normals` smooth or flat.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::{self, ShapeOut};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "sdfgrid", run: Run::Shape(run) };

/// Mesh cells per grid cell along each axis.
const REFINE: u32 = 4;

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    let path = b.file(p)?;
    let mut m =
        crate::scene::mesh::sdfgrid::load_sdfgrid(&path, REFINE, b.limits).map_err(|e| shape::load_error(p, e))?;
    match p.string("normals")?.unwrap_or("smooth") {
        "smooth" => m.ensure_vertex_normals(),
        "flat" => m.face_normals(),
        other => return Err(p.elem.at.err(format!("sdfgrid normals \"{other}\" is not smooth or flat"))),
    }
    shape::mesh(p, m)
}

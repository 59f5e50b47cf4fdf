//! `<shape type="sdfgrid">`: a signed-distance grid (`filename`, a `.vol`), meshed at 4x the grid
//! resolution (see `scene::mesh::sdfgrid` for how close that is); `normals` smooth or flat. Its uv
//! is (0, 0) everywhere, as Mitsuba's sdfgrid reports no parameterization (a textured BSDF reads
//! its texture at the origin there: the corpus' `various_shapes` torus is uniformly `color0`);
//! without explicit uvs a mesh's uv would be its barycentrics. The uvs are `texturing::ZERO_UV`
//! (`-0.0`), since all-`+0.0` corners mean "no uvs".

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
    m.uvs = vec![crate::scene::texturing::ZERO_UV; m.positions.len()];
    shape::mesh(p, m)
}

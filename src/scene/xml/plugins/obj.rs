//! `<shape type="obj">`: a Wavefront OBJ (`filename`, `flip_tex_coords` default true), read as
//! Mitsuba reads it (its MTL ignored).

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::{self, ShapeOut};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "obj", run: Run::Shape(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    let path = b.file(p)?;
    let flip = p.bool("flip_tex_coords", true)?;
    let m = crate::scene::mesh::obj::load_obj(&path, flip, b.limits).map_err(|e| shape::load_error(p, e))?;
    shape::mesh(p, m)
}

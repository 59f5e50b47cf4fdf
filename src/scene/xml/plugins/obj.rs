//! `<shape type="obj">`: a Wavefront OBJ (`filename`), its MTL ignored as Mitsuba ignores it.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::{self, ShapeOut};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "obj", run: Run::Shape(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    let name = p.string("filename")?.ok_or_else(|| p.elem.at.err("<shape type=\"obj\"> needs a `filename` string"))?;
    let path = b.resolve(name);
    let m = crate::scene::obj::load_bounded(&path, b.limits.max_file_bytes)
        .map_err(|e| p.elem.at.err(format!("cannot load {}: {e}", path.display())))?;
    let mut normals = vec![glam::Vec3::ZERO; m.positions.len()];
    // Mitsuba keeps one normal per vertex: the OBJ's per-corner normals, per position.
    for (f, ns) in m.faces.iter().zip(&m.face_normals) {
        for (&vi, &ni) in f.iter().zip(ns) {
            if let Some(&n) = m.normals.get(ni as usize) {
                normals[vi as usize] = n;
            }
        }
    }
    if m.face_normals.is_empty() {
        normals.clear();
    }
    p.refuse("flip_tex_coords", "texture coordinates arrive with the `textures` work of issue 29")?;
    shape::mesh(p, m.positions, normals, m.faces)
}

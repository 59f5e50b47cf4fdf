//! Wavefront OBJ/MTL meshes: as a whole scene (`strata render model.obj`) or placed into a `.test`
//! scene by the `obj FILE` command (see `scene::parse`).
//!
//! The OBJ is read by [`parse_obj`] (here, not `tobj`: real-world files need repairs `tobj` cannot
//! make); MTL libraries are checked by [`locate_mtl_error`] and read by `tobj::load_mtl_buf`.
//! Faces are triangulated as fans `(c0, ci, ci+1)`, as `tobj` does. Positions are used for
//! geometry; vertex normals (`vn`, validated, unit length: [`ObjMesh::normals`] /
//! [`ObjMesh::face_normals`]) become per-corner shading normals ([`place`]; see
//! `scene::build` for interpolation and the consistency guard); texture
//! coordinates are read, checked and ignored. Materials, per face:
//! - a face whose MTL material has a non-zero `Ke` is an area light: radiance `Ke`, emitted on one
//!   side only, towards `(v1 - v0) x (v2 - v0)` of its (transformed) vertices, i.e. the side from
//!   which the face is wound counter-clockwise; it reflects nothing (black), like a `quadLight`;
//! - otherwise `Kd` -> `diffuse`, `Ks` -> `specular`, `Ns` -> `shininess` (modified Phong), each
//!   taken from the MTL where it gives it and from the *current material* where it does not; every
//!   other field (`emission`, `ambient`, `brdf`, `roughness`) is the current material's. A face with
//!   no MTL material (no `usemtl`, unknown name, missing library) gets the current material.
//!
//! The current material is the `.test` material state where the `obj` command appears, and
//! [`whole_scene_material`] for a whole-scene OBJ.
//!
//! Real errors (unreadable or UTF-16 files, malformed numbers, non-finite positions, bad face
//! indices, malformed MTL values, no faces) are refused with the file and the 1-based line.
//! What mainstream loaders (tinyobjloader, Blender, assimp) accept is loaded, and each repair or
//! ignored feature gives one [`ObjWarning`] with file and line:
//! - a missing `mtllib` file: tried at its path, then by its base name beside the OBJ (paths
//!   relative to some other directory), then, when no library of the OBJ is found at all,
//!   `<obj stem>.mtl` beside the OBJ; otherwise skipped (default materials when none is found);
//! - several files on one `mtllib` line, and `\ `-escaped spaces in their names;
//! - text that is not UTF-8 is read as Latin-1 (names and comments; numbers must still parse);
//! - `\` at the end of a line continues it on the next one;
//! - an empty `usemtl` or an unknown material name: the current material;
//! - texture coordinates, `l`/`p` elements, curves and unknown keywords are ignored;
//! - broken vertex normals (malformed or non-finite or zero `vn`, out-of-range normal indices): the
//!   faces using them get none;
//! - `v x y z w` with `w = 0`: `w` ignored (otherwise positions are divided by `w`, as in `tobj`);
//!   extra numbers after `x y z` (colours) ignored;
//! - in an MTL: `newmtl` without a name (the material an empty `usemtl` selects), and `Ka`/`Kd`/
//!   `Ks`/`Ke`/`Tf` with one number `r` (`r r r`, as the MTL spec defines it).
//!
//! [`load`] and [`scene_from_obj`] print the warnings to stderr (`strata: warning: FILE:LINE: ...`);
//! [`load_with_warnings`] and [`scene_from_obj_with_warnings`] return them instead.
//! Nothing here panics on bad input (a panic inside `tobj` would be caught and reported).

mod faces;
pub mod frame;
mod line_error;
mod mtl;
mod place;
mod procedural;
mod read;
mod text;

pub use faces::{locate_obj_error, parse_obj, ParsedObj};
pub use mtl::locate_mtl_error;
pub use place::{
    frame_camera, normal_matrix, place, scene_from_obj, scene_from_obj_with_warnings, whole_scene_material,
};
pub use procedural::{procedural_mesh, procedural_mesh_bytes, write_obj};
pub use read::{load, load_bounded, load_with_warnings, load_with_warnings_bounded};

use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use glam::Vec3;
use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};
/// A scene path naming a Wavefront OBJ (extension `.obj`, any case) rather than a `.test` file.
pub fn is_obj(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// One MTL material: the fields strata uses, `None` where the MTL does not give them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MtlMaterial {
    /// `newmtl` name
    pub name: String,
    /// `Kd`
    pub kd: Option<Vec3>,
    /// `Ks`
    pub ks: Option<Vec3>,
    /// `Ns`
    pub ns: Option<f32>,
    /// `Ke`
    pub ke: Option<Vec3>,
}

impl MtlMaterial {
    /// Radiance if this material makes its faces area lights (`Ke` given and not all zero).
    pub fn emission(&self) -> Option<Vec3> {
        self.ke.filter(|k| *k != Vec3::ZERO)
    }

    /// The material of a non-emissive face: MTL fields where given, `current` elsewhere.
    pub fn resolve(&self, current: &Material) -> Material {
        Material {
            diffuse: self.kd.unwrap_or(current.diffuse),
            specular: self.ks.unwrap_or(current.specular),
            shininess: self.ns.unwrap_or(current.shininess),
            ..*current
        }
    }
}

/// "No normal" in [`ObjMesh::face_normals`].
pub const NO_NORMAL: u32 = u32::MAX;

/// A loaded OBJ: triangles over one position array, with their MTL material and vertex normals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjMesh {
    /// vertex positions, as in the file (one per `v` line, in order)
    pub positions: Vec<Vec3>,
    /// triangles (indices into `positions`)
    pub faces: Vec<[u32; 3]>,
    /// per triangle: index into `materials`, or `u32::MAX` for none
    pub face_material: Vec<u32>,
    /// the MTL materials
    pub materials: Vec<MtlMaterial>,
    /// vertex normals, one per `vn` line in order, normalized; an invalid one (not finite, zero
    /// length, malformed) is stored as `Vec3::ZERO` and never referenced. Empty when no triangle has
    /// normals.
    pub normals: Vec<Vec3>,
    /// per triangle, the indices into `normals` of its three corners (same corner order as
    /// `faces`), or `[NO_NORMAL; 3]` when any corner has no valid normal. Empty (not
    /// `faces.len()` long) when no triangle has normals.
    pub face_normals: Vec<[u32; 3]>,
    /// the MTL libraries read for it
    pub libraries: Vec<PathBuf>,
}

impl ObjMesh {
    /// Axis-aligned bounds of the positions used by faces (None without faces).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        bounds(self.faces.iter().flatten().map(|&i| self.positions[i as usize]))
    }
}

/// Bounds of points (None if there are none).
pub fn bounds(points: impl Iterator<Item = Vec3>) -> Option<(Vec3, Vec3)> {
    points.fold(None, |b, p| Some(b.map_or((p, p), |(lo, hi): (Vec3, Vec3)| (lo.min(p), hi.max(p)))))
}

/// Something repaired or ignored while loading an OBJ or MTL file (see the module docs).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ObjWarning {
    /// the OBJ or MTL file
    pub file: PathBuf,
    /// 1-based line; 0 when not tied to a line
    pub line: usize,
    /// what was repaired or ignored, and how
    pub message: String,
}

impl fmt::Display for ObjWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}: {}", self.file.display(), self.message)
        } else {
            write!(f, "{}:{}: {}", self.file.display(), self.line, self.message)
        }
    }
}

/// Prints warnings to stderr, one line each: `strata: warning: FILE:LINE: message`.
pub fn print_warnings(warnings: &[ObjWarning]) {
    let mut e = std::io::stderr().lock();
    for w in warnings {
        let _ = writeln!(e, "strata: warning: {w}");
    }
}

fn err(file: &Path, line: usize, message: impl Into<String>) -> SceneError {
    SceneError::new(file, line, message)
}

fn warn(file: &Path, line: usize, message: impl Into<String>) -> ObjWarning {
    ObjWarning { file: file.to_path_buf(), line, message: message.into() }
}

/// `s`, cut to 40 characters (with `...`) for an error message.
fn short(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((cut, _)) => format!("{}...", &s[..cut]),
        None => s.to_string(),
    }
}

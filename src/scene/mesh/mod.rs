//! Triangle meshes of the Mitsuba 3 scene format, in object space, without XML: the [`Mesh`] type,
//! its loaders and generators. The XML front end (`scene::xml`) reads a shape's properties, calls
//! one function here and places the result with [`SceneDesc::add_mesh`](crate::scene::desc::SceneDesc::add_mesh).
//!
//! # API (plain Rust; every loader returns `Result<Mesh, MeshError>`)
//! - [`Mesh`]: `positions`, `normals` (empty = none), `uvs` (empty = none), `indices`
//!   (`[u32; 3]`, counter-clockwise seen from the outside), and named per-vertex / per-face
//!   [`MeshAttr`]s (`vertex_color`, `face_color`, `face_weight`, ...; `dims` 1 or 3).
//!   - [`Mesh::transform`]: positions by the matrix, normals by its inverse transpose (unit
//!     length); a mirroring matrix (negative determinant) also reverses each triangle's winding, so
//!     that `(v1-v0) x (v2-v0)` keeps pointing to the side the transformed normals point to.
//!   - [`Mesh::flip_normals`] (Mitsuba's `flip_normals`: reversed winding and negated normals),
//!     [`Mesh::face_normals`] (Mitsuba's `face_normals`: drops the vertex normals),
//!     [`Mesh::ensure_vertex_normals`] (what Mitsuba does when a file has no normals and
//!     `face_normals` is false: angle-weighted vertex normals; the loaders do not call it).
//! - Loaders, each checking [`Limits`](crate::scene::limits::Limits) (`max_file_bytes`,
//!   `max_vertices`, `max_primitives`) before it allocates:
//!   [`ply::load_ply`] (ASCII, binary little/big endian), [`serialized::load_serialized`]
//!   (`shape_index`), [`obj::load_obj`] (Mitsuba's reading: one mesh, `flip_tex_coords`), and
//!   [`sdfgrid::load_sdfgrid`] (a `.vol` SDF grid to triangles; see that module for how exact).
//! - Generators with Mitsuba's parameterization ([`shapes`]): [`shapes::rectangle`],
//!   [`shapes::disk`], [`shapes::cube`], [`shapes::cylinder`]. The analytic sphere is rendered as a
//!   `SphereDesc`; its uv at hits is `scene::texturing::sphere_uv`.
//! - Into the scene: [`SceneDesc::add_mesh`](crate::scene::desc::SceneDesc::add_mesh) (world-space
//!   mesh, material index): triangles, per-corner shading normals, and the uv/attribute tables
//!   (`place.rs`).
//!
//! Errors ([`MeshError`]) name the file and, where there is one, the line, the element (`vertex
//! 12`, `face 3`) or the byte offset. No loader panics on a hostile file (truncated, huge counts,
//! bad indices, NaN): each has such cases among its tests.

pub mod obj;
mod place;
pub use place::ShapeGroup;
pub mod ply;
pub mod sdfgrid;
pub mod serialized;
pub mod shapes;

use glam::{Mat3, Mat4, Vec2, Vec3};
use std::path::{Path, PathBuf};

/// A named per-vertex or per-face attribute: `dims` floats per vertex (or face), interleaved.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshAttr {
    /// Mitsuba's name, with its prefix: `vertex_color`, `face_weight`, ...
    pub name: String,
    /// values per vertex or face (1 or 3)
    pub dims: usize,
    /// `dims * count` values
    pub data: Vec<f32>,
}

impl MeshAttr {
    /// The `dims` values of vertex (or face) `i`.
    pub fn get(&self, i: usize) -> &[f32] {
        &self.data[i * self.dims..(i + 1) * self.dims]
    }
}

/// A triangle mesh in object space (or world space after [`Mesh::transform`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// vertex positions
    pub positions: Vec<Vec3>,
    /// unit vertex normals, one per position; empty: none (faceted)
    pub normals: Vec<Vec3>,
    /// texture coordinates, one per position; empty: none
    pub uvs: Vec<Vec2>,
    /// triangles, indices into `positions`
    pub indices: Vec<[u32; 3]>,
    /// per-vertex attributes (`vertex_*`), `data.len() == dims * positions.len()`
    pub vertex_attrs: Vec<MeshAttr>,
    /// per-face attributes (`face_*`), `data.len() == dims * indices.len()`
    pub face_attrs: Vec<MeshAttr>,
}

/// Where in a file a [`MeshError`] is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// the file as a whole
    File,
    /// a 1-based text line
    Line(usize),
    /// the `index`th (0-based) element of a kind (`vertex`, `face`, `shape`)
    Element(String, u64),
    /// a byte offset (binary formats)
    Byte(u64),
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Location::File => Ok(()),
            Location::Line(l) => write!(f, ":{l}"),
            Location::Element(kind, i) => write!(f, ": {kind} {i}"),
            Location::Byte(b) => write!(f, ": byte {b}"),
        }
    }
}

/// A mesh file that cannot be loaded.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file cannot be opened or read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// the file
        file: PathBuf,
        /// why
        source: std::io::Error,
    },
    /// The file is malformed at `at`.
    #[error("{}{at}: {message}", file.display())]
    Malformed {
        /// the file
        file: PathBuf,
        /// where
        at: Location,
        /// what is wrong and what was expected
        message: String,
    },
    /// The file asks for more than a `--limit` allows (checked before allocating).
    #[error("{}: {what}: {count} is more than the limit of {limit} ({hint})", file.display(), hint = crate::scene::limits::limit_hint(.field))]
    Limit {
        /// the file
        file: PathBuf,
        /// what is counted (`vertices`, `triangles`, `bytes`)
        what: &'static str,
        /// how many the file declares
        count: u64,
        /// the limit
        limit: u64,
        /// the `--limit` field name
        field: &'static str,
    },
}

impl MeshError {
    /// A [`MeshError::Malformed`].
    pub fn malformed(file: &Path, at: Location, message: impl Into<String>) -> Self {
        MeshError::Malformed { file: file.to_path_buf(), at, message: message.into() }
    }

    /// The 1-based line of the error, 0 when it is not tied to a line.
    pub fn line(&self) -> usize {
        match self {
            MeshError::Malformed { at: Location::Line(l), .. } => *l,
            _ => 0,
        }
    }
}

/// Refuses `count` above `limit` (a `--limit` field) for `file`.
pub(crate) fn check_limit(
    file: &Path,
    what: &'static str,
    count: u64,
    limit: u64,
    field: &'static str,
) -> Result<(), MeshError> {
    if count > limit {
        return Err(MeshError::Limit { file: file.to_path_buf(), what, count, limit, field });
    }
    Ok(())
}

impl Mesh {
    /// Checks the invariants every loader and generator guarantees: indices in range, finite
    /// positions, normals/uvs/attributes of the right lengths. The message names the first
    /// offending element.
    pub fn validate(&self) -> Result<(), (Location, String)> {
        let n = self.positions.len();
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err((Location::Element("vertex".into(), i as u64), "position is not finite".into()));
        }
        if !self.normals.is_empty() && self.normals.len() != n {
            return Err((Location::File, format!("{} normals for {n} vertices", self.normals.len())));
        }
        if !self.uvs.is_empty() && self.uvs.len() != n {
            return Err((Location::File, format!("{} uvs for {n} vertices", self.uvs.len())));
        }
        for (f, t) in self.indices.iter().enumerate() {
            if let Some(&i) = t.iter().find(|&&i| i as usize >= n) {
                return Err((
                    Location::Element("face".into(), f as u64),
                    format!("vertex index {i} is out of range (the mesh has {n} vertices)"),
                ));
            }
        }
        for (attrs, count) in [(&self.vertex_attrs, n), (&self.face_attrs, self.indices.len())] {
            for a in attrs {
                if a.dims == 0 || a.data.len() != a.dims * count {
                    return Err((Location::File, format!("attribute `{}` has {} values", a.name, a.data.len())));
                }
            }
        }
        Ok(())
    }

    /// The attribute called `name` (`vertex_*` or `face_*`), if any.
    pub fn attr(&self, name: &str) -> Option<&MeshAttr> {
        self.vertex_attrs.iter().chain(&self.face_attrs).find(|a| a.name == name)
    }

    /// Maps the mesh by `m`: positions as points (divided by w when `m` is projective), normals
    /// by the inverse transpose of the linear part, renormalized (zero, read as "no normal", when
    /// `m` is singular). A mirroring `m` (negative determinant) also reverses each triangle's
    /// winding.
    pub fn transform(&mut self, m: &Mat4) {
        for p in &mut self.positions {
            *p = m.project_point3(*p);
        }
        let linear = Mat3::from_mat4(*m);
        let normal_matrix = linear.inverse().transpose();
        for n in &mut self.normals {
            *n = (normal_matrix * *n).normalize_or_zero();
        }
        if linear.determinant() < 0.0 {
            self.indices.iter_mut().for_each(|t| t.swap(1, 2));
        }
    }

    /// Mitsuba's `flip_normals`: reverses every triangle's winding and negates the normals.
    pub fn flip_normals(&mut self) {
        self.indices.iter_mut().for_each(|t| t.swap(1, 2));
        self.normals.iter_mut().for_each(|n| *n = -*n);
    }

    /// Mitsuba's `face_normals`: drops the vertex normals, so triangles shade flat.
    pub fn face_normals(&mut self) {
        self.normals.clear();
    }

    /// Unnormalized `(v1-v0) x (v2-v0)` of triangle `f` (twice its area, outward).
    pub fn face_cross(&self, f: usize) -> Vec3 {
        let [a, b, c] = self.indices[f].map(|i| self.positions[i as usize]);
        (b - a).cross(c - a)
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        (0..self.indices.len()).map(|f| 0.5 * f64::from(self.face_cross(f).length())).sum()
    }

    /// When the mesh has no normals, gives it smooth ones as Mitsuba does for a mesh read without
    /// normals and `face_normals` false: at each vertex, the sum of the unit normals of the
    /// triangles around it weighted by their angles at it, normalized (a vertex only on degenerate
    /// triangles gets the zero vector, which `add_mesh` reads as "no normal").
    pub fn ensure_vertex_normals(&mut self) {
        if !self.normals.is_empty() {
            return;
        }
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        for t in &self.indices {
            let p = t.map(|i| self.positions[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            if n == Vec3::ZERO {
                continue;
            }
            for k in 0..3 {
                let e1 = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
                let e2 = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
                let angle = e1.dot(e2).clamp(-1.0, 1.0).acos();
                acc[t[k] as usize] += n * angle;
            }
        }
        self.normals = acc.into_iter().map(Vec3::normalize_or_zero).collect();
    }

    /// Appends `other` (same attribute names and dims in both, or they are dropped) to this mesh.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        let had = !self.positions.is_empty();
        if !had || (self.normals.is_empty() == other.normals.is_empty()) {
            self.normals.extend_from_slice(&other.normals);
        } else {
            self.normals.clear();
        }
        if !had || (self.uvs.is_empty() == other.uvs.is_empty()) {
            self.uvs.extend_from_slice(&other.uvs);
        } else {
            self.uvs.clear();
        }
        let merge = |mine: &mut Vec<MeshAttr>, theirs: &[MeshAttr]| {
            if !had {
                *mine = theirs.to_vec();
                return;
            }
            mine.retain_mut(|a| match theirs.iter().find(|b| b.name == a.name && b.dims == a.dims) {
                Some(b) => {
                    a.data.extend_from_slice(&b.data);
                    true
                }
                None => false,
            });
        };
        merge(&mut self.vertex_attrs, &other.vertex_attrs);
        merge(&mut self.face_attrs, &other.face_attrs);
        self.positions.extend_from_slice(&other.positions);
        self.indices.extend(other.indices.iter().map(|t| t.map(|i| i + base)));
    }
}

/// Reads `path` whole through `files::open_regular` (a FIFO, device or directory is refused
/// before opening), refusing it when it has more than `max_bytes` bytes (checked before reading).
pub(crate) fn read_file(path: &Path, max_bytes: u64) -> Result<Vec<u8>, MeshError> {
    let io = |source| MeshError::Io { file: path.to_path_buf(), source };
    let (file, len) = crate::files::open_regular(path).map_err(io)?;
    check_limit(path, "bytes", len, max_bytes, "max_file_bytes")?;
    crate::files::read::read_all_of(file, len, max_bytes).map_err(io)
}

#[cfg(test)]
mod tests;

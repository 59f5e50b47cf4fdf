//! How a [`Mesh`] enters a [`SceneDesc`]: [`SceneDesc::add_mesh`].

use super::Mesh;
use crate::scene::desc::{SceneDesc, TriangleAttrDesc, TriangleDesc};
use glam::{Vec2, Vec3};

impl SceneDesc {
    /// Appends a world-space mesh (already [`Mesh::transform`]ed) with material index `material`:
    /// one `TriangleDesc` per triangle; its unit vertex normals, if any, as per-corner shading
    /// normals (`triangle_normals`, padded with "none" for the triangles before it; a zero normal
    /// is "none"); its uvs, if any, into `triangle_uvs` (padded likewise); and each attribute as a
    /// [`TriangleAttrDesc`] over its triangles (per corner for `vertex_*`, per face for `face_*`).
    /// A mesh without normals, uvs or attributes adds nothing to those tables, so the content hash
    /// of a scene without them is unchanged. Returns the index of its first triangle.
    ///
    /// The mesh must satisfy [`Mesh::validate`] (every loader and generator guarantees it).
    pub fn add_mesh(&mut self, mesh: &Mesh, material: u32) -> u32 {
        let first = self.triangles.len();
        let corner = |t: &[u32; 3]| t.map(|i| i as usize);
        self.triangles
            .extend(mesh.indices.iter().map(|t| TriangleDesc { v: corner(t).map(|i| mesh.positions[i]), material }));
        if !mesh.normals.is_empty() {
            self.triangle_normals.resize(first, [Vec3::ZERO; 3]);
            self.triangle_normals.extend(mesh.indices.iter().map(|t| corner(t).map(|i| mesh.normals[i])));
        }
        if !mesh.uvs.is_empty() {
            self.triangle_uvs.resize(first, [Vec2::ZERO; 3]);
            self.triangle_uvs.extend(mesh.indices.iter().map(|t| corner(t).map(|i| mesh.uvs[i])));
        }
        let count = mesh.indices.len() as u32;
        // A vertex attribute per corner of every triangle, a face attribute as it is.
        let attr = |name: &str, dims: usize, per_corner: bool, data: Vec<f32>| TriangleAttrDesc {
            name: name.to_string(),
            dims: dims as u32,
            per_corner,
            first: first as u32,
            count,
            data,
        };
        for a in &mesh.vertex_attrs {
            let mut data = Vec::with_capacity(mesh.indices.len() * 3 * a.dims);
            mesh.indices.iter().flatten().for_each(|&i| data.extend_from_slice(a.get(i as usize)));
            self.triangle_attrs.push(attr(&a.name, a.dims, true, data));
        }
        for a in &mesh.face_attrs {
            self.triangle_attrs.push(attr(&a.name, a.dims, false, a.data.clone()));
        }
        first as u32
    }
}

/// Mitsuba's `shapegroup`: meshes in the group's space, each with its material index.
pub type ShapeGroup = [(Mesh, u32)];

impl SceneDesc {
    /// Mitsuba's `instance` of a `shapegroup`, flattened: a copy of each member mesh mapped by
    /// `to_world` (as [`Mesh::transform`] does) is added with [`SceneDesc::add_mesh`]. (Embree
    /// instancing, `accel::SceneBuilder::add_mesh_instance`, would share the members' BVH; the
    /// shading tables are per world triangle, so this copy is what the renderer reads today.)
    /// Returns the index of the first triangle added.
    pub fn add_instance(&mut self, group: &ShapeGroup, to_world: &glam::Mat4) -> u32 {
        let first = self.triangles.len() as u32;
        for (mesh, material) in group {
            let mut copy = mesh.clone();
            copy.transform(to_world);
            self.add_mesh(&copy, *material);
        }
        first
    }
}

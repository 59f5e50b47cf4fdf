//! How a [`Mesh`] enters a [`SceneDesc`]: [`SceneDesc::add_mesh`].

use super::Mesh;
use crate::scene::desc::{GroupDesc, InstanceDesc, SceneDesc, SphereDesc, TriangleAttrDesc, TriangleDesc};
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
    /// Stores Mitsuba's `shapegroup` `id` once: its member meshes (group space, without
    /// attributes) as a [`GroupDesc`]'s triangles with their normals and uvs, and its spheres
    /// (group-space maps with their materials). Returns its index in `groups`.
    pub fn add_group(&mut self, id: &str, group: &ShapeGroup, spheres: Vec<(glam::Mat4, u32)>) -> u32 {
        let mut g = GroupDesc { id: id.to_string(), spheres, ..GroupDesc::default() };
        for (mesh, material) in group {
            let first = g.triangles.len();
            let corner = |t: &[u32; 3]| t.map(|i| i as usize);
            g.triangles.extend(
                mesh.indices
                    .iter()
                    .map(|t| TriangleDesc { v: corner(t).map(|i| mesh.positions[i]), material: *material }),
            );
            if !mesh.normals.is_empty() {
                g.triangle_normals.resize(first, [Vec3::ZERO; 3]);
                g.triangle_normals.extend(mesh.indices.iter().map(|t| corner(t).map(|i| mesh.normals[i])));
            }
            if !mesh.uvs.is_empty() {
                g.triangle_uvs.resize(first, [Vec2::ZERO; 3]);
                g.triangle_uvs.extend(mesh.indices.iter().map(|t| corner(t).map(|i| mesh.uvs[i])));
            }
        }
        self.groups.push(g);
        (self.groups.len() - 1) as u32
    }

    /// How many triangles the shapegroups store (each once, however many instances place it).
    pub fn group_triangles(&self) -> usize {
        self.groups.iter().map(|g| g.triangles.len()).sum()
    }

    /// The index of the stored shapegroup `id`, if [`SceneDesc::add_group`] stored it.
    pub fn group_index(&self, id: &str) -> Option<u32> {
        self.groups.iter().position(|g| g.id == id).map(|i| i as u32)
    }

    /// Mitsuba's `instance` of the stored group `group` through `to_world`: an [`InstanceDesc`]
    /// (its triangles stay stored once; the build makes it an Embree instance) and a copy of each
    /// of the group's spheres composed with `to_world`.
    pub fn add_instance(&mut self, group: u32, to_world: &glam::Mat4) {
        self.instances.push(InstanceDesc { group, to_world: *to_world });
        if let Some(g) = self.groups.get(group as usize) {
            let spheres =
                g.spheres.iter().map(|&(m, material)| SphereDesc { object_to_world: *to_world * m, material });
            self.spheres.extend(spheres.collect::<Vec<_>>());
        }
    }
}

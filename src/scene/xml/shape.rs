//! What shape plugins make ([`ShapeOut`]) and its placement in the scene with the shape's
//! material and area emitter; `to_world`, `flip_normals` and `face_normals` as Mitsuba applies them.

use super::doc::Loc;
use super::plugins::Build;
use super::props::Props;
use crate::scene::desc::{EmissiveTriangleDesc, Material, SphereDesc, TriangleDesc};
use crate::scene::error::SceneError;
use glam::{Mat4, Vec3};

/// A shape's geometry in world space.
pub enum ShapeOut {
    /// triangles over `positions`, with per-vertex unit normals (empty: faceted)
    Mesh {
        /// vertex positions, world space
        positions: Vec<Vec3>,
        /// per-vertex normals, world space (empty: none)
        normals: Vec<Vec3>,
        /// triangles
        faces: Vec<[u32; 3]>,
    },
    /// the unit sphere mapped by this object-to-world matrix
    Sphere(Mat4),
}

/// An object-space mesh through `to_world` (normals by the inverse transpose), with Mitsuba's
/// `flip_normals` (winding and normals reversed) and `face_normals` (vertex normals dropped).
pub fn mesh(
    props: &Props,
    mut positions: Vec<Vec3>,
    mut normals: Vec<Vec3>,
    mut faces: Vec<[u32; 3]>,
) -> Result<ShapeOut, SceneError> {
    let m = props.transform("to_world")?;
    let nm = Mat4::from_mat3(glam::Mat3::from_mat4(m).inverse().transpose());
    positions.iter_mut().for_each(|p| *p = m.transform_point3(*p));
    if props.bool("face_normals", false)? {
        normals.clear();
    }
    normals.iter_mut().for_each(|n| *n = nm.transform_vector3(*n).normalize_or_zero());
    if m.determinant() < 0.0 {
        // A mirroring transform turns the winding; Mitsuba's face normal follows the winding.
        faces.iter_mut().for_each(|f| f.swap(1, 2));
    }
    if props.bool("flip_normals", false)? {
        faces.iter_mut().for_each(|f| f.swap(1, 2));
        normals.iter_mut().for_each(|n| *n = -*n);
    }
    Ok(ShapeOut::Mesh { positions, normals, faces })
}

/// Places a shape: triangles with `material`, or emissive triangles (that also reflect with
/// `material`) when it carries an area emitter of `radiance`; a sphere as an ellipsoid.
pub fn place(
    b: &mut Build,
    out: ShapeOut,
    material: Material,
    emitter: Option<(Vec3, Loc)>,
    at: &Loc,
) -> Result<(), SceneError> {
    let mi = b.intern(material);
    match out {
        ShapeOut::Sphere(m) => {
            if let Some((_, eat)) = emitter {
                return Err(eat.err("an area emitter on a sphere is not supported yet: it needs solid-angle sphere light sampling (the `lights` work of issue 29)"));
            }
            b.desc.spheres.push(SphereDesc { object_to_world: m, material: mi });
        }
        ShapeOut::Mesh { positions, normals, faces } => {
            let n = b.desc.triangles.len() + b.desc.emissive_triangles.len() + faces.len();
            if n > b.limits.max_primitives {
                return Err(at.err(format!(
                    "the scene has more than {} triangles ({})",
                    b.limits.max_primitives,
                    crate::scene::limits::limit_hint("max_primitives")
                )));
            }
            for f in faces {
                let v = f.map(|i| positions[i as usize]);
                if let Some((radiance, _)) = emitter {
                    b.desc.emissive_materials.resize(b.desc.emissive_triangles.len(), u32::MAX);
                    b.desc.emissive_materials.push(mi);
                    b.desc.emissive_triangles.push(EmissiveTriangleDesc { v, radiance });
                    continue;
                }
                if !normals.is_empty() {
                    let ns = f.map(|i| normals[i as usize]);
                    if ns.iter().all(|n| *n != Vec3::ZERO) {
                        b.desc.triangle_normals.resize(b.desc.triangles.len(), [Vec3::ZERO; 3]);
                        b.desc.triangle_normals.push(ns);
                    }
                }
                b.desc.triangles.push(TriangleDesc { v, material: mi });
            }
        }
    }
    Ok(())
}

//! What shape plugins make ([`ShapeOut`]) and its placement in the scene with the shape's
//! material and area emitter; `to_world`, `flip_normals` and `face_normals` as Mitsuba applies
//! them (through `scene::mesh`).

use super::doc::Loc;
use super::props::Props;
use crate::scene::desc::{EmissiveTriangleDesc, SceneDesc, SphereDesc};
use crate::scene::error::SceneError;
use crate::scene::limits::Limits;
use crate::scene::mesh::{Mesh, MeshError};
use glam::{Mat4, Vec3};

/// A shape's geometry.
pub enum ShapeOut {
    /// a triangle mesh, world space (or the shape group's space)
    Mesh(Mesh),
    /// the unit sphere mapped by this object-to-world matrix
    Sphere(Mat4),
    /// nothing to place here (a `shapegroup`, placed by its instances; an `instance`, placed by
    /// its plugin)
    Nothing,
}

/// An object-space mesh through `to_world`, with Mitsuba's `face_normals` (vertex normals
/// dropped) and `flip_normals`.
pub fn mesh(p: &Props, mut m: Mesh) -> Result<ShapeOut, SceneError> {
    m.transform(&p.transform("to_world")?);
    if p.bool("face_normals", false)? {
        m.face_normals();
    }
    if p.bool("flip_normals", false)? {
        m.flip_normals();
    }
    Ok(ShapeOut::Mesh(m))
}

/// A mesh loader's error at the shape's element.
pub fn load_error(p: &Props, e: MeshError) -> SceneError {
    p.elem.at.err(format!("{}: {e}", p.elem.what()))
}

/// What an area emitter emits: `radiance`, times `texture` at the shape's uvs where it has one.
#[derive(Clone, Debug)]
pub struct AreaEmission {
    /// the radiance (a bitmap radiance: 1, the image carries it)
    pub radiance: Vec3,
    /// the bitmap `radiance`, if any
    pub texture: Option<std::sync::Arc<crate::scene::desc::RgbImage>>,
}

/// Places a shape into `desc` (within `limits`): its triangles with `material` (a material
/// index), or emissive triangles (that also reflect with `material`) when it carries an area
/// emitter of `radiance`; a sphere as an ellipsoid.
pub fn place(
    desc: &mut SceneDesc,
    limits: &Limits,
    out: ShapeOut,
    material: u32,
    emitter: Option<(AreaEmission, Loc)>,
    at: &Loc,
) -> Result<(), SceneError> {
    match out {
        ShapeOut::Nothing => {}
        ShapeOut::Sphere(m) => {
            if let Some((_, eat)) = emitter {
                return Err(eat.err("an area emitter on a sphere is not supported yet: it needs solid-angle sphere light sampling (the `lights` work of issue 29)"));
            }
            desc.spheres.push(SphereDesc { object_to_world: m, material });
        }
        ShapeOut::Mesh(mesh) => {
            let n = desc.triangles.len() + desc.emissive_triangles.len() + mesh.indices.len();
            if n > limits.max_primitives {
                return Err(at.err(format!(
                    "the scene has more than {} triangles ({})",
                    limits.max_primitives,
                    crate::scene::limits::limit_hint("max_primitives")
                )));
            }
            match emitter {
                None => {
                    desc.add_mesh(&mesh, material);
                }
                Some((em, eat)) => {
                    let radiance = em.radiance;
                    let image = match em.texture {
                        Some(_) if mesh.uvs.is_empty() => {
                            return Err(eat.err("a textured area emitter needs a shape with uvs"));
                        }
                        Some(t) => {
                            desc.emission_images.push(t);
                            Some(desc.emission_images.len() as u32 - 1)
                        }
                        None => None,
                    };
                    for f in &mesh.indices {
                        let v = f.map(|i| mesh.positions[i as usize]);
                        desc.emissive_materials.resize(desc.emissive_triangles.len(), u32::MAX);
                        desc.emissive_materials.push(material);
                        if let Some(i) = image {
                            let no = (u32::MAX, [glam::Vec2::ZERO; 3]);
                            desc.emissive_textures.resize(desc.emissive_triangles.len(), no);
                            desc.emissive_textures.push((i, f.map(|k| mesh.uvs[k as usize])));
                        }
                        desc.emissive_triangles.push(EmissiveTriangleDesc { v, radiance });
                    }
                }
            }
        }
    }
    Ok(())
}

//! What shape plugins make ([`ShapeOut`]) and its placement in the scene with the shape's
//! material and area emitter; `to_world`, `flip_normals` and `face_normals` as Mitsuba applies
//! them (through `scene::mesh`).

use super::doc::Loc;
use super::props::Props;
use crate::scene::desc::{EmissiveSphereDesc, EmissiveTriangleDesc, SceneDesc, SphereDesc};
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
            if let Some((em, eat)) = emitter {
                if em.texture.is_some() {
                    return Err(eat.err("a textured area emitter on a sphere is not supported (a bitmap radiance needs a mesh with uvs)"));
                }
                let radiance = em.radiance;
                let (center, radius) = similarity_sphere(&m).ok_or_else(|| {
                    eat.err("an area emitter on a sphere needs a `to_world` without non-uniform scale (Mitsuba's rule for spheres): this one makes an ellipsoid")
                })?;
                let sphere = desc.spheres.len() as u32;
                desc.emissive_spheres.push(EmissiveSphereDesc { sphere, center, radius, radiance });
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

/// Centre and radius of the unit sphere under `m` when `m`'s linear part is a rotation (or
/// reflection) times a uniform scale, to 1e-5 relative; None for an ellipsoid or a degenerate map.
pub fn similarity_sphere(m: &Mat4) -> Option<(Vec3, f32)> {
    let l = glam::Mat3::from_mat4(*m);
    let g = l.transpose() * l;
    let r2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    if !(r2 > 0.0 && r2.is_finite()) {
        return None;
    }
    let off = (g - glam::Mat3::from_diagonal(Vec3::splat(r2))).to_cols_array().iter().fold(0f32, |a, v| a.max(v.abs()));
    let c = m.w_axis.truncate();
    (off <= 1e-5 * r2 && c.is_finite()).then(|| (c, r2.sqrt()))
}

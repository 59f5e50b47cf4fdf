//! OBJ meshes in a scene: a whole-scene OBJ (camera, settings, interned materials) and the
//! placement of a mesh's faces, emitters and vertex normals into a `SceneDesc`.

use super::read::load_with_warnings_bounded;
use super::{err, print_warnings, MtlMaterial, ObjMesh, ObjWarning};
use crate::scene::desc::{CameraDesc, ImportanceSampling, IntegratorKind, Material, Nee, SceneDesc};
use crate::scene::error::{LineError, SceneError};
use crate::scene::limits::Limits;
use glam::Vec3;
use std::path::Path;

/// The current material of a whole-scene OBJ: grey diffuse 0.8, no ambient (faces without an MTL
/// material get it; MTL fields override it as in the module docs).
pub fn whole_scene_material() -> Material {
    Material { diffuse: Vec3::splat(0.8), ambient: Vec3::ZERO, ..Material::default() }
}

/// Camera framing the box `lo..hi`: looking along -z at its centre from +z (OBJ's convention: y up),
/// far enough that the bounding sphere fits the vertical field of view `fovy_deg` (and so the
/// horizontal one of any image at least as wide as tall).
pub fn frame_camera(lo: Vec3, hi: Vec3, fovy_deg: f32) -> CameraDesc {
    let center = 0.5 * (lo + hi);
    let r = (0.5 * (hi - lo).length()).max(1e-3);
    let dist = r / (0.5 * fovy_deg.to_radians()).sin();
    CameraDesc { eye: center + Vec3::Z * dist, center, up: Vec3::Y, fovy_deg }
}

/// A whole scene from one OBJ: its triangles (materials as in the module docs, current material
/// [`whole_scene_material`]), the automatic camera of [`super::frame::frame_scene`] for 640x480 and
/// the guessed up axis (replace it with `--camera`), 640x480, 16 spp, gamma 2.2, `pathtracer` with `nexteventestimation mis`,
/// `importancesampling brdf`, `maxdepth 5`, output named after the file.
/// Prints the warnings to stderr (see [`scene_from_obj_with_warnings`]).
pub fn scene_from_obj(path: &Path, limits: &Limits) -> Result<SceneDesc, SceneError> {
    let (desc, warnings) = scene_from_obj_with_warnings(path, limits)?;
    print_warnings(&warnings);
    Ok(desc)
}

/// [`scene_from_obj`], returning the loader's warnings instead of printing them.
pub fn scene_from_obj_with_warnings(path: &Path, limits: &Limits) -> Result<(SceneDesc, Vec<ObjWarning>), SceneError> {
    let (mesh, warnings) = load_with_warnings_bounded(path, limits.max_file_bytes)?;
    let mut desc = SceneDesc {
        source: path.to_path_buf(),
        inputs: mesh.libraries.clone(),
        spp: 16,
        gamma: 2.2,
        integrator: IntegratorKind::PathTracer,
        nee: Nee::Mis,
        importance_sampling: ImportanceSampling::Brdf,
        max_depth: 5,
        output: path.file_stem().map(|s| format!("{}.png", s.to_string_lossy())),
        ..SceneDesc::default()
    };
    if mesh.faces.len() > limits.max_primitives {
        return Err(err(path, 0, format!("more than {} triangles (--max-primitives)", limits.max_primitives)));
    }
    let current = whole_scene_material();
    let mut index_of = std::collections::HashMap::new();
    place(&mesh, &current, Ok, glam::DMat3::IDENTITY, &mut desc, &mut |m: Material, d: &mut SceneDesc| {
        let key: Vec<u32> = [m.diffuse, m.specular, m.emission, m.ambient]
            .iter()
            .flat_map(|v| v.to_array())
            .chain([m.shininess, m.roughness])
            .map(f32::to_bits)
            .collect();
        Ok(*index_of.entry(key).or_insert_with(|| {
            d.materials.push(m);
            d.materials.len() as u32 - 1
        }))
    })
    .map_err(|m| m.at(path, 0))?;
    let aspect = desc.width as f32 / desc.height as f32;
    desc.camera = super::frame::frame_scene(&desc, None, aspect).map(|f| f.camera);
    Ok((desc, warnings))
}

/// Adds `mesh` to `desc`: every face's vertices through `to_world`, emissive faces to
/// `emissive_triangles`, the others to `triangles` with the material `intern` returns an index for.
/// Vertex normals go through `normal_matrix` (see [`normal_matrix`]), renormalised, into
/// `desc.triangle_normals` (padded with "none" up to the triangle they belong to); a triangle whose
/// normals do not all survive (zero after the transform) is faceted; emissive faces ignore them.
pub fn place(
    mesh: &ObjMesh,
    current: &Material,
    to_world: impl Fn(Vec3) -> Result<Vec3, LineError>,
    normal_matrix: glam::DMat3,
    desc: &mut SceneDesc,
    intern: &mut dyn FnMut(Material, &mut SceneDesc) -> Result<u32, LineError>,
) -> Result<(), LineError> {
    use crate::scene::desc::{EmissiveTriangleDesc, TriangleDesc};
    // One resolved material index per MTL material (and one for "none"), computed on first use.
    let mut resolved: Vec<Option<u32>> = vec![None; mesh.materials.len() + 1];
    let world: Vec<Vec3> = mesh.positions.iter().map(|&p| to_world(p)).collect::<Result<_, _>>()?;
    let normals: Vec<Vec3> =
        mesh.normals.iter().map(|&n| (normal_matrix * n.as_dvec3()).as_vec3().normalize_or_zero()).collect();
    for (k, (f, &mi)) in mesh.faces.iter().zip(&mesh.face_material).enumerate() {
        let v = f.map(|i| world[i as usize]);
        let mtl = mesh.materials.get(mi as usize);
        if let Some(radiance) = mtl.and_then(MtlMaterial::emission) {
            desc.emissive_triangles.push(EmissiveTriangleDesc { v, radiance });
            continue;
        }
        let slot = if mtl.is_some() { mi as usize } else { mesh.materials.len() };
        let material = match resolved[slot] {
            Some(i) => i,
            None => {
                let m = mtl.map_or(*current, |m| m.resolve(current));
                let i = intern(m, desc)?;
                resolved[slot] = Some(i);
                i
            }
        };
        let corner = |c: u32| normals.get(c as usize).copied().unwrap_or(Vec3::ZERO);
        let ns = mesh.face_normals.get(k).map_or([Vec3::ZERO; 3], |c| c.map(corner));
        if ns.iter().all(|n| *n != Vec3::ZERO) {
            desc.triangle_normals.resize(desc.triangles.len(), [Vec3::ZERO; 3]);
            desc.triangle_normals.push(ns);
        }
        desc.triangles.push(TriangleDesc { v, material });
    }
    Ok(())
}

/// The matrix taking object-space normals to world space under the affine `m`: the cofactor
/// matrix of its linear part, `det * inverse transpose`, times the sign of `det` (so the direction
/// is that of the inverse transpose; the length is renormalised by the caller). Defined for any `m`
/// (zero for a singular one of rank < 2).
pub fn normal_matrix(m: &glam::DMat4) -> glam::DMat3 {
    let l = glam::DMat3::from_mat4(*m);
    let (a, b, c) = (l.x_axis, l.y_axis, l.z_axis);
    let cof = glam::DMat3::from_cols(b.cross(c), c.cross(a), a.cross(b));
    if l.determinant() < 0.0 {
        -cof
    } else {
        cof
    }
}

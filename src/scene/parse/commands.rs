//! The commands that add geometry, lights, a camera or materials, and the transform and material
//! state they read.

use super::args::{hint, show};
use super::{Args, LineError, Parser};
use crate::scene::desc::*;
use crate::scene::obj;
use glam::{DMat4, DVec3, Vec3};
use std::collections::HashMap;
use std::path::Path;

impl Parser<'_> {
    pub(super) fn size(&mut self, [w, h]: [i64; 2]) -> Result<(), LineError> {
        if w < 1 || h < 1 {
            return Err(format!("size expects positive integers, got {w} {h}").into());
        }
        let pixels = w as u128 * h as u128;
        let (max_pixels, max_side) = (self.limits.max_pixels, self.limits.max_side);
        if pixels > u128::from(max_pixels) {
            return Err(
                format!("image {w}x{h} exceeds the limit of {max_pixels} pixels ({})", hint("max_pixels")).into()
            );
        }
        let (Ok(width), Ok(height)) = (u32::try_from(w), u32::try_from(h)) else {
            return Err(format!("image {w}x{h} is too large").into());
        };
        if width.max(height) > max_side {
            return Err(format!(
                "image {w}x{h} exceeds the limit of {max_side} pixels per side ({})",
                hint("max_side")
            )
            .into());
        }
        (self.desc.width, self.desc.height) = (width, height);
        Ok(())
    }

    pub(super) fn camera(&mut self, c: [f32; 10]) -> Result<(), LineError> {
        let [ex, ey, ez, cx, cy, cz, ux, uy, uz, fovy_deg] = c;
        let (eye, center, up) = (Vec3::new(ex, ey, ez), Vec3::new(cx, cy, cz), Vec3::new(ux, uy, uz));
        if !(fovy_deg > 0.0 && fovy_deg < 180.0) {
            return Err(format!("camera fovy must be in (0, 180) degrees, got {fovy_deg}").into());
        }
        let look = (center.as_dvec3() - eye.as_dvec3()).try_normalize().ok_or("camera eye and centre coincide")?;
        let up_dir = up.as_dvec3().try_normalize().ok_or("camera up vector must be non-zero")?;
        if look.cross(up_dir).length() < 1e-9 {
            return Err("camera up vector is parallel to the viewing direction".into());
        }
        self.desc.camera = Some(CameraDesc { eye, center, up, fovy_deg });
        Ok(())
    }

    pub(super) fn triangle(&mut self, indices: [i64; 3]) -> Result<(), LineError> {
        let count = self.vertices.len();
        let mut v = [Vec3::ZERO; 3];
        for (slot, &i) in v.iter_mut().zip(&indices) {
            let vertex = usize::try_from(i).ok().and_then(|i| self.vertices.get(i));
            let vertex =
                vertex.ok_or_else(|| format!("tri index {i} out of range ({count} vertices defined so far)"))?;
            *slot = self.to_world(*vertex)?;
        }
        self.count_primitive()?;
        let material = self.material_index()?;
        self.desc.triangles.push(TriangleDesc { v, material });
        Ok(())
    }

    pub(super) fn sphere(&mut self, [x, y, z, r]: [f32; 4]) -> Result<(), LineError> {
        if r <= 0.0 {
            return Err(format!("sphere radius must be > 0, got {r}").into());
        }
        let m = self.matrix
            * DMat4::from_translation(DVec3::new(x.into(), y.into(), z.into()))
            * DMat4::from_scale(DVec3::splat(r.into()));
        let object_to_world = m.as_mat4();
        if !object_to_world.is_finite()
            || !object_to_world.determinant().is_normal()
            || !object_to_world.inverse().is_finite()
        {
            return Err("sphere transform is degenerate or out of range".into());
        }
        self.count_primitive()?;
        let material = self.material_index()?;
        self.desc.spheres.push(SphereDesc { object_to_world, material });
        Ok(())
    }

    pub(super) fn quad_light(&mut self, q: [f32; 12]) -> Result<(), LineError> {
        let [ax, ay, az, bx, by, bz, cx, cy, cz, r, g, b] = q;
        let light = QuadLightDesc {
            a: Vec3::new(ax, ay, az),
            ab: Vec3::new(bx, by, bz),
            ac: Vec3::new(cx, cy, cz),
            radiance: radiance("quadLight radiance", r, g, b)?,
        };
        let area = light.ab.cross(light.ac).length();
        if !(area > 0.0 && area.is_finite()) {
            return Err(format!("quadLight area |ab x ac| must be positive and finite, got {area}").into());
        }
        self.count_primitive()?;
        self.desc.quad_lights.push(light);
        Ok(())
    }

    /// `obj FILE`: the OBJ's faces (path relative to the `.test` file's directory) under the current
    /// transform, with materials by the rule of `scene::obj` (MTL fields where given, the current
    /// material elsewhere; faces with `Ke` become emissive triangles).
    pub(super) fn obj(&mut self, name: &str) -> Result<(), LineError> {
        let path = self.desc.source.parent().unwrap_or(Path::new("")).join(name);
        let mesh =
            obj::load_bounded(&path, self.limits.max_file_bytes).map_err(|e| format!("obj '{}': {e}", show(name)))?;
        let d = &self.desc;
        let n = d.triangles.len() + d.emissive_triangles.len() + d.spheres.len() + d.quad_lights.len();
        if n + mesh.faces.len() > self.limits.max_primitives {
            let max = self.limits.max_primitives;
            return Err(format!(
                "obj '{}': more than {max} primitives and lights ({})",
                show(name),
                hint("max_primitives")
            )
            .into());
        }
        let (matrix, current, lookup) = (self.matrix, self.material, &mut self.material_lookup);
        let normals = obj::normal_matrix(&matrix);
        obj::place(&mesh, &current, |p| to_world(&matrix, p), normals, &mut self.desc, &mut |m, d| {
            intern_material(lookup, d, &m)
        })
        .map_err(|e| LineError(format!("obj '{}': {e}", show(name))))
    }

    /// Right-multiplies the current matrix: M <- M * x.
    pub(super) fn transform(&mut self, x: DMat4) -> Result<(), LineError> {
        let m = self.matrix * x;
        if !m.is_finite() {
            return Err("the current transform overflows".into());
        }
        self.matrix = m;
        Ok(())
    }

    /// A point mapped by the current matrix, checked to stay finite in f32.
    pub(super) fn to_world(&self, p: Vec3) -> Result<Vec3, LineError> {
        to_world(&self.matrix, p)
    }

    pub(super) fn count_primitive(&self) -> Result<(), LineError> {
        let d = &self.desc;
        let n = d.triangles.len()
            + d.spheres.len()
            + d.quad_lights.len()
            + d.emissive_triangles.len()
            + d.point_lights.len()
            + d.directional_lights.len();
        if n >= self.limits.max_primitives {
            let max = self.limits.max_primitives;
            return Err(format!("more than {max} primitives and lights ({})", hint("max_primitives")).into());
        }
        Ok(())
    }

    /// Replaces the material state (forgetting its cached index if it changed).
    pub(super) fn set_material(&mut self, material: Material) {
        if material != self.material {
            self.material = material;
            self.material_index = None;
        }
    }

    /// Index of the current material state in `desc.materials`, adding it if it is new.
    fn material_index(&mut self) -> Result<u32, LineError> {
        if let Some(i) = self.material_index {
            return Ok(i);
        }
        let index = intern_material(&mut self.material_lookup, &mut self.desc, &self.material)?;
        self.material_index = Some(index);
        Ok(index)
    }
}

/// A point mapped by `matrix`, checked to stay finite in f32.
fn to_world(matrix: &DMat4, p: Vec3) -> Result<Vec3, LineError> {
    let w = matrix.transform_point3(p.as_dvec3()).as_vec3();
    if w.is_finite() {
        Ok(w)
    } else {
        Err(format!("point {p} is out of range after the current transform").into())
    }
}

/// Index of material `m` in `desc.materials` (`lookup` maps bit patterns to indices), adding it if new.
fn intern_material(lookup: &mut HashMap<[u32; 15], u32>, desc: &mut SceneDesc, m: &Material) -> Result<u32, LineError> {
    let vectors = [m.diffuse, m.specular, m.emission, m.ambient];
    let values = vectors.iter().flat_map(|v| v.to_array()).chain([m.shininess, m.roughness]);
    let mut key = [0u32; 15];
    for (k, v) in key.iter_mut().zip(values) {
        *k = (v + 0.0).to_bits(); // + 0.0 folds -0.0 into 0.0, as PartialEq does
    }
    key[14] = m.brdf as u32;
    Ok(match lookup.get(&key) {
        Some(&i) => i,
        None => {
            let i = u32::try_from(desc.materials.len()).map_err(|_| "too many distinct materials")?;
            desc.materials.push(*m);
            lookup.insert(key, i);
            i
        }
    })
}

/// A light's radiance or colour (`what` names it): every channel >= 0 (a negative emitter would
/// make negative pixels; NaN is refused by the number parser).
pub(super) fn radiance(what: &str, r: f32, g: f32, b: f32) -> Result<Vec3, LineError> {
    if r < 0.0 || g < 0.0 || b < 0.0 {
        return Err(format!("{what} must be >= 0 in every channel, got {r} {g} {b}").into());
    }
    Ok(Vec3::new(r, g, b))
}

/// One number that must be >= 0.
pub(super) fn non_negative(a: &Args) -> Result<f32, LineError> {
    let [v] = a.floats()?;
    if v < 0.0 {
        return Err(format!("{} must be >= 0, got {v}", a.cmd).into());
    }
    Ok(v)
}

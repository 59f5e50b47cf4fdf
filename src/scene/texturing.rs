//! Textures at hits: the hit's uv (triangles: their corner uvs interpolated at Embree's
//! barycentrics, or the barycentrics themselves when the mesh has none, as Mitsuba does; spheres
//! and ellipsoids: Mitsuba's sphere parameterization in object space) and the textured diffuse
//! reflectance of the lanes whose material has one. [`Scene::gather`] calls this only when the
//! scene has a textured material, so a scene without textures runs none of it.

use super::build::{Scene, NO_TEXTURE};
use super::gather::SurfaceHit8;
use crate::accel::{Hits8, GEOM_ELLIPSOIDS, GEOM_SPHERES, GEOM_TRIANGLES};
use crate::simd::{Vec3x8, F8, U8};
use crate::texture::{TexQuery8, NO_TRIANGLE};
use glam::{Vec2, Vec3};

/// Mitsuba's uv of a point of the unit sphere (object space): `u = phi / 2pi` with `phi` the
/// azimuth about +z in [0, 2pi) from +x, `v = theta / pi` with `theta` the angle from +z.
pub fn sphere_uv(p: Vec3) -> Vec2 {
    let p = p.normalize_or_zero();
    let mut phi = p.y.atan2(p.x);
    if phi < 0.0 {
        phi += std::f32::consts::TAU;
    }
    let theta = p.z.clamp(-1.0, 1.0).acos();
    Vec2::new(phi * (0.5 * std::f32::consts::FRAC_1_PI), theta * std::f32::consts::FRAC_1_PI)
}

/// The corner uvs that mean "none" (the barycentrics are the uv): all `+0.0`, bit for bit. A mesh
/// whose uv is the origin everywhere (Mitsuba's `sdfgrid`) stores [`ZERO_UV`] instead.
#[inline]
pub fn is_no_uv(c: &[Vec2; 3]) -> bool {
    c.iter().all(|v| v.x.to_bits() == 0 && v.y.to_bits() == 0)
}

/// A corner uv at the origin that is not "none" ([`is_no_uv`]): `-0.0`, which every texture reads
/// as 0.
pub const ZERO_UV: Vec2 = Vec2::new(-0.0, -0.0);

/// The uv at barycentrics `(b1, b2)` of a triangle with corner uvs `c` (`None`: the barycentrics).
#[inline]
pub fn triangle_uv(c: Option<&[Vec2; 3]>, b1: f32, b2: f32) -> Vec2 {
    match c {
        Some(c) => {
            let b0 = (1.0 - b1) - b2;
            (c[0] * b0 + c[1] * b1) + c[2] * b2
        }
        None => Vec2::new(b1, b2),
    }
}

impl Scene {
    /// The texture of material `m`, if any.
    #[inline]
    fn texture_of(&self, m: u32) -> Option<u32> {
        self.material_texture.get(m as usize).copied().filter(|&t| t != NO_TEXTURE)
    }

    /// Sets `out.mat.kd` on the hit lanes `bits` whose material has a diffuse texture to its value
    /// there (one texture evaluation, 8 lanes wide, per distinct texture of the packet). Out of
    /// line and cold, so that the gather of an untextured scene keeps its code.
    #[cold]
    #[inline(never)]
    pub(super) fn texture_hits(&self, bits: u32, hits: &Hits8, out: &mut SurfaceHit8) {
        let (geom, prim, p) = (hits.geom.as_array(), hits.prim.as_array(), out.p);
        let mut tex = [NO_TEXTURE; 8];
        let (mut u, mut v, mut tri) = ([0f32; 8], [0f32; 8], [NO_TRIANGLE; 8]);
        let (bu, bv) = (hits.u.as_array(), hits.v.as_array());
        for i in super::gather::lanes_of(bits) {
            let k = prim[i] as usize;
            let (m, uv, t) = match geom[i] {
                GEOM_TRIANGLES => {
                    let uv = triangle_uv(self.tri_uv.get(k).filter(|c| !is_no_uv(c)), bu[i], bv[i]);
                    (self.tri_material[k], uv, self.tri_source.get(k).copied().unwrap_or(NO_TRIANGLE))
                }
                GEOM_SPHERES | GEOM_ELLIPSOIDS => {
                    let table = if geom[i] == GEOM_SPHERES { &self.sphere_point_index } else { &self.ellipsoid_index };
                    let e = table[k] as usize;
                    let obj = self.ell_world_to_object[e].transform_point3(p.lane(i));
                    (self.ell_material[e], sphere_uv(obj), NO_TRIANGLE)
                }
                _ => continue,
            };
            (u[i], v[i], tri[i]) = (uv.x, uv.y, t);
            let Some(t_idx) = self.texture_of(m) else { continue };
            tex[i] = t_idx;
        }
        let q = TexQuery8 { u: F8::new(u), v: F8::new(v), tri: U8::new(tri), b1: hits.u, b2: hits.v };
        if !self.param_textures.is_empty() {
            out.tex = q;
        }
        let mut todo: u32 = (0..8).filter(|&i| tex[i] != NO_TEXTURE).map(|i| 1u32 << i).sum();
        if todo == 0 {
            return;
        }
        let mut kd = out.mat.kd;
        while todo != 0 {
            let t = tex[todo.trailing_zeros() as usize];
            let lanes: [bool; 8] = std::array::from_fn(|i| tex[i] == t);
            let value = self.textures[t as usize].eval_x8(&q);
            kd = Vec3x8::select(crate::simd::mask_from_bools(lanes), value, kd);
            todo &= !(0..8).filter(|&i| lanes[i]).map(|i| 1u32 << i).sum::<u32>();
        }
        out.mat.kd = kd;
    }

    /// Writes the textured BSDF parameters (`Scene::param_textures`) of the `valid` lanes of
    /// the hit record `sh` into their rows `p`: one texture evaluation, 8 lanes wide, per
    /// distinct (slot, texture) of the packet. Colour slots take the texture's RGB
    /// (`Texture::eval_x8`), scalar slots Mitsuba's float lookup (`Texture::eval_1_x8`: the
    /// luminance, a grey value's own, a checkerboard's colours swapped as Mitsuba's `eval_1`),
    /// the opacity that clamped to [0, 1]. Scenes without
    /// textured parameters never call it.
    #[cold]
    #[inline(never)]
    pub fn texture_params(&self, sh: &SurfaceHit8, valid: crate::simd::Mask8, p: &mut crate::bsdf::Params8) {
        use crate::bsdf::interface::Slot;
        let (ids, bits) = (sh.material.to_array(), valid.to_bitmask());
        let mut done: Vec<(Slot, u32)> = Vec::new();
        for i in super::gather::lanes_of(bits) {
            let Some(params) = self.param_textures.get(ids[i] as usize) else { continue };
            for &(slot, t) in params {
                if done.contains(&(slot, t)) {
                    continue;
                }
                done.push((slot, t));
                let lanes: [bool; 8] = std::array::from_fn(|j| {
                    bits & (1 << j) != 0
                        && self.param_textures.get(ids[j] as usize).is_some_and(|q| q.contains(&(slot, t)))
                });
                let m = crate::simd::mask_from_bools(lanes);
                let tex = &self.textures[t as usize];
                match slot {
                    Slot::Color(c) => {
                        p.color[c as usize] = Vec3x8::select(m, tex.eval_x8(&sh.tex), p.color[c as usize])
                    }
                    Slot::Scalar(c) => p.scalar[c as usize] = m.select(tex.eval_1_x8(&sh.tex), p.scalar[c as usize]),
                    Slot::Opacity => p.opacity = m.select(tex.eval_1_x8(&sh.tex).max(F8::ZERO).min(F8::ONE), p.opacity),
                }
            }
        }
    }
}

#[cfg(test)]
#[path = "texturing_tests.rs"]
mod tests;

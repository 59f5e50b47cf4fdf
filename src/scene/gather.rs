//! The one AoS -> SoA gather of hit records: Embree's per-lane hit records (geometry, primitive,
//! barycentrics, distance) become the 8-lane [`SurfaceHit8`] the integrators shade (see the
//! shading-normal conventions in [`super::build`]).

use super::build::Scene;
use crate::accel::{Hits8, GEOM_ELLIPSOIDS, GEOM_SPHERES, GEOM_TRIANGLES, INVALID_ID};
use crate::bsdf::interface::COURSE;
use crate::bsdf::{FrameMap8, Material8, Params8};
use crate::scene::desc::{BrdfKind, Material};
use crate::simd::{Mask8, Vec3x8, F8, U8};
use glam::Vec3;

/// Shading record of 8 hits, structure of arrays (the one AoS -> SoA gather).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit8 {
    /// lanes that hit a surface
    pub valid: Mask8,
    /// hit position, world space
    pub p: Vec3x8,
    /// unit shading normal facing the incoming ray (n . wo >= 0): the geometric normal `ng`, or on
    /// `smooth` lanes the interpolated vertex normal (see the module docs)
    pub n: Vec3x8,
    /// unit geometric normal flipped to face the incoming ray (ng . wo >= 0): for ray offsets
    pub ng: Vec3x8,
    /// lanes shaded with an interpolated vertex normal (`n` may differ from `ng`); integrators
    /// also require `ng . wi > 0` there for a direction to leave the surface
    pub smooth: Mask8,
    /// unit direction towards the viewer (-ray direction)
    pub wo: Vec3x8,
    /// the lanes' material, written in place by the gather (the one per-lane material shape):
    /// the course's fields (kd, ks, shininess, alpha, ggx; textured kd evaluated at the hit) on
    /// every packet with a hit; in scenes with registry BSDFs also the lanes' registry rows
    /// (`bsdf`, [`Scene::bsdf_params`] with their textured parameters), the sides hit (`back`)
    /// and, in scenes with normal or bump maps, the maps' terms in the shading frame
    /// (`frame_map`); the miss record's elsewhere
    pub mat: Material8,
    /// radiance emitted towards wo by the material (`emission`, every hit, any side)
    pub emitted: Vec3x8,
    /// ambient term of the material (`raytracer` only; zero on lights and misses)
    pub ambient: Vec3x8,
    /// radiance emitted towards wo by an area light (quad, emissive triangle or sphere light: its
    /// radiance on its emitting side, the outside of a sphere, else 0)
    pub le: Vec3x8,
    /// light index for hits on a light's geometry (emitting side or not), else u32::MAX
    pub light: U8,
    /// material index per lane (into `Scene::materials`; 0 on misses): the registry BSDF's row
    /// ([`Scene::bsdf_params`]); filled only in scenes with registry BSDFs
    pub material: U8,
    /// where textures are evaluated at the hit (uv, triangle, barycentrics); filled only in
    /// scenes with textured BSDF parameters (`Scene::param_textures`)
    pub tex: crate::texture::TexQuery8,
    /// unit shading tangent (Mitsuba's: dp/du made orthogonal to `n`; a normal or bump map's
    /// perturbed one); filled only in scenes with tangents (`Scene::tangents`), zero elsewhere
    pub s: Vec3x8,
    /// the shading normal before a normal or bump map perturbed `n` (facing as `n`); `n` on lanes
    /// without a map; filled only in scenes with such maps
    pub base_n: Vec3x8,
    /// the shadowing term's alpha^2 of a normal or bump map (`bsdf::FrameMap8`); 0 without one
    pub bump_a2: F8,
}

impl SurfaceHit8 {
    /// The record of eight misses (what [`Scene::gather`] gives lanes that hit nothing).
    pub const MISS: Self = Self {
        valid: F8::ZERO,
        p: Vec3x8::ZERO,
        n: Z8,
        ng: Z8,
        smooth: F8::ZERO,
        wo: Vec3x8::ZERO,
        mat: Material8 {
            kd: Vec3x8::ZERO,
            ks: Vec3x8::ZERO,
            shininess: F8::ZERO,
            alpha: F8::ONE,
            ggx: F8::ZERO,
            bsdf: Params8::COURSE,
            back: F8::ZERO,
            frame_map: None,
        },
        emitted: Vec3x8::ZERO,
        ambient: Vec3x8::ZERO,
        le: Vec3x8::ZERO,
        light: U8::MAX,
        material: U8::ZERO,
        tex: crate::texture::TexQuery8 { u: F8::ZERO, v: F8::ZERO, tri: U8::MAX, b1: F8::ZERO, b2: F8::ZERO },
        s: Vec3x8::ZERO,
        base_n: Z8,
        bump_a2: F8::ZERO,
    };
}

/// +z in every lane.
const Z8: Vec3x8 = Vec3x8 { x: F8::ZERO, y: F8::ZERO, z: F8::ONE };

impl Scene {
    /// Gathers the shading records of a packet's hits (rays `org + t dir`, `dir` unit).
    ///
    /// Per lane only the table lookups run (normal, material and light index by primitive); the
    /// rest is 8-wide: the two-sided flip, and the material fields, splatted once per distinct
    /// material of the hit lanes (one in the common case of a coherent packet). Lanes that missed
    /// get the miss record (normals +z, zero reflectances, roughness 1, no light).
    #[inline]
    pub fn gather(&self, org: Vec3x8, dir: Vec3x8, hits: &Hits8) -> SurfaceHit8 {
        let mut sh = SurfaceHit8::MISS;
        self.gather_into(org, dir, hits, &mut sh);
        sh
    }

    /// [`Scene::gather`] written into `out` (a record in a buffer: no copy of the record).
    #[inline]
    pub fn gather_into(&self, org: Vec3x8, dir: Vec3x8, hits: &Hits8, out: &mut SurfaceHit8) {
        let _p = crate::profile::leaf(crate::profile::Phase::Gather);
        if !self.instances.is_empty() {
            return self.gather_instanced(org, dir, hits, out);
        }
        self.gather_scene::<false>(org, dir, hits, out);
    }

    /// [`Scene::gather_into`] in a scene with instances: their hits name their group's triangle,
    /// made the scene's first. Out of line, so that scenes without instances keep their code.
    #[cold]
    #[inline(never)]
    fn gather_instanced(&self, org: Vec3x8, dir: Vec3x8, hits: &Hits8, out: &mut SurfaceHit8) {
        self.gather_scene::<true>(org, dir, &self.instances.remap(hits), out);
    }

    /// [`Scene::gather_into`] of hits whose primitives are scene triangles; `INST`: the scene
    /// has instances.
    #[inline(always)]
    fn gather_scene<const INST: bool>(&self, org: Vec3x8, dir: Vec3x8, hits: &Hits8, out: &mut SurfaceHit8) {
        let p = dir.mul_add(hits.t, org);
        let valid = hits.hit;
        let bits = valid.to_bitmask();
        if bits == 0 {
            // No lane hit: the miss record (what the lane loop below gives every missed lane), but
            // for `tex` and the tangent-frame fields, which only shaded lanes read (not writing
            // them keeps this path as short as before they existed).
            let m = &SurfaceHit8::MISS;
            (out.valid, out.p, out.n, out.ng, out.smooth, out.wo) = (m.valid, p, m.n, m.ng, m.smooth, -dir);
            let (o, z) = (&mut out.mat, &m.mat);
            (o.kd, o.ks, o.shininess, o.alpha, o.ggx, o.back) = (z.kd, z.ks, z.shininess, z.alpha, z.ggx, z.back);
            (out.emitted, out.ambient, out.le, out.light) = (m.emitted, m.ambient, m.le, m.light);
            out.material = m.material;
            return;
        }
        let (geom, prim) = (hits.geom.as_array(), hits.prim.as_array());
        let first = prim[bits.trailing_zeros() as usize];
        let tri = hits.geom.simd_eq(U8::splat(GEOM_TRIANGLES));
        let all_of = |m: U8| F8::from_bits(m).to_bitmask() & bits == bits;
        let all_triangles = !INST && all_of(tri);
        let one_triangle = all_triangles
            && all_of(hits.prim.simd_eq(U8::splat(first)))
            && self.tri_light.get(first as usize) == Some(&INVALID_ID);
        let Lanes8 { n, light, le, any_tri, mat } = if one_triangle {
            self.one_triangle(first as usize, valid)
        } else if all_triangles {
            self.distinct_triangles(valid, hits.prim, dir)
        } else {
            self.lane_by_lane::<INST>(bits, [geom, prim, hits.inst.as_array()], p, dir)
        };
        // Shade two-sided: flip the normal to face the incoming ray (the scalar Vec3::dot's
        // operation order, so the sign is the same as per lane).
        let facing = (n.x * dir.x + n.y * dir.y) + n.z * dir.z;
        let back = valid & facing.simd_gt(F8::ZERO);
        let ng = Vec3x8::select(back, -n, n);
        if one_triangle {
            self.uniform_materials(mat[0], valid, out);
        } else {
            self.gather_materials(valid, &mat, out);
        }
        if self.registry_bsdfs {
            out.material = U8::new(mat);
            out.mat.back = back;
        }
        let (ns, smooth) = if any_tri && !self.tri_corner_normals.is_empty() {
            self.smooth_normals(bits, geom, prim, hits, dir, ng)
        } else {
            (ng, crate::simd::mask_from_bools([false; 8]))
        };
        out.valid = valid;
        out.p = p;
        out.n = ns;
        out.ng = ng;
        out.smooth = smooth;
        out.wo = -dir;
        out.le = le;
        out.light = light;
        if self.hit_extras {
            self.extras(bits, hits, out);
        }
        if self.registry_bsdfs || self.frame_maps() {
            self.registry_rows(valid, out);
        }
        if !self.material_one_sided.is_empty() && back.any() {
            self.black_backs(back, &mat, out);
        }
    }

    /// Mitsuba's one-sided `diffuse`: no reflection on the lanes `back` (hit from behind) whose
    /// material is one-sided (`Scene::material_one_sided`).
    #[cold]
    #[inline(never)]
    fn black_backs(&self, back: Mask8, mat: &[u32; 8], out: &mut SurfaceHit8) {
        let one = mat.map(|m| self.material_one_sided.get(m as usize).copied().unwrap_or(false));
        let black = back & crate::simd::mask_from_bools(one);
        if black.any() {
            out.mat.kd = Vec3x8::select(black, Vec3x8::ZERO, out.mat.kd);
            out.mat.ks = Vec3x8::select(black, Vec3x8::ZERO, out.mat.ks);
        }
    }

    /// The part of the hit lanes' material that only scenes with registry BSDFs or maps have:
    /// the lanes' registry rows with their textured parameters evaluated at the hits, and the
    /// terms of a normal or bump map in the shading frame (the general kernel's
    /// `integrator::context::shading_frame`: the same function of the same normal and tangent,
    /// so the same bits).
    #[cold]
    #[inline(never)]
    fn registry_rows(&self, valid: Mask8, out: &mut SurfaceHit8) {
        if self.registry_bsdfs {
            let mut p = self.bsdf_params(out.material, valid);
            if !self.param_textures.is_empty() {
                self.texture_params(out, valid, &mut p);
            }
            out.mat.bsdf = p;
        }
        if self.frame_maps() {
            let frame = crate::simd::Frame8::from_normal_tangent(out.n, out.s);
            out.mat.frame_map = Some(FrameMap8 { base: frame.to_local(out.base_n), a2: out.bump_a2 });
        }
    }

    /// The per-lane fields of hit lanes `valid` that all hit triangle `t`, not a light's: its
    /// normal and material splatted (what [`Scene::lane_by_lane`] gives such lanes).
    #[inline]
    fn one_triangle(&self, t: usize, valid: Mask8) -> Lanes8 {
        Lanes8 {
            n: Vec3x8::select(valid, Vec3x8::splat(self.tri_normal[t]), Z8),
            light: U8::MAX,
            le: Vec3x8::ZERO,
            any_tri: true,
            mat: [self.tri_material[t]; 8],
        }
    }

    /// [`Scene::lane_by_lane`]'s fields where every hit lane (`bits`) hit a triangle (primitive
    /// ids `prim`): one pass of 8-wide selects per distinct triangle of the packet, where the
    /// lane loop's scalar stores into arrays, read back as vectors, stalled on store forwarding.
    /// The same values (a light's facing test in the scalar dot product's operation order).
    #[inline]
    fn distinct_triangles(&self, valid: Mask8, prim: U8, dir: Vec3x8) -> Lanes8 {
        let (mut n, mut light, mut le, mut mat) = (Z8, U8::splat(INVALID_ID), Vec3x8::ZERO, U8::splat(0));
        for (t, on) in distinct_ids(prim, valid) {
            let on_u: U8 = wide::bytemuck::cast(on);
            let t = t as usize;
            n = Vec3x8::select(on, Vec3x8::splat(self.tri_normal[t]), n);
            mat = on_u.select(U8::splat(self.tri_material[t]), mat);
            let l = self.tri_light[t];
            if l != INVALID_ID {
                light = on_u.select(U8::splat(l), light);
                let q = &self.emitters.list[l as usize];
                let s = |v: f32| F8::splat(v);
                let facing = (s(q.normal.x) * dir.x + s(q.normal.y) * dir.y) + s(q.normal.z) * dir.z;
                le = Vec3x8::select(on & facing.simd_lt(F8::ZERO), Vec3x8::splat(q.radiance), le);
            }
        }
        Lanes8 { n, light, le, any_tri: true, mat: mat.to_array() }
    }

    /// The per-lane fields of the hit lanes `bits`, one table lookup per lane: normal, material
    /// index, light index and light emission; `ids`: the lanes' geometry, primitive and
    /// instance ids; points `p` (spheres and ellipsoids) and ray directions `dir`.
    /// `INST`: the scene has instances (their lanes' normals are mapped to world space).
    fn lane_by_lane<const INST: bool>(&self, bits: u32, ids: [&[u32; 8]; 3], p: Vec3x8, dir: Vec3x8) -> Lanes8 {
        let [geom, prim, inst] = ids;
        let mut n = Lanes3::splat(Vec3::Z);
        let mut mat = [0u32; 8];
        let mut light = [INVALID_ID; 8];
        let mut le = Lanes3::splat(Vec3::ZERO);
        let mut any_tri = false;
        for i in lanes_of(bits) {
            let prim = prim[i] as usize;
            match geom[i] {
                GEOM_TRIANGLES => {
                    any_tri = true;
                    let l = self.tri_light[prim];
                    if l != INVALID_ID {
                        light[i] = l;
                        let q = &self.emitters.list[l as usize];
                        if q.normal.dot(dir.lane(i)) < 0.0 {
                            le.set(i, q.radiance);
                        }
                    }
                    n.set(i, self.tri_normal[prim]);
                    if INST && inst[i] != INVALID_ID {
                        n.set(i, self.instances.normal_of(inst[i], self.tri_normal[prim]));
                    }
                    mat[i] = self.tri_material[prim];
                }
                GEOM_SPHERES | GEOM_ELLIPSOIDS => {
                    let table = if geom[i] == GEOM_SPHERES { &self.sphere_point_index } else { &self.ellipsoid_index };
                    let e = table[prim] as usize;
                    let obj = self.ell_world_to_object[e].transform_point3(p.lane(i));
                    let normal = (self.ell_normal[e] * obj).normalize_or_zero();
                    n.set(i, normal);
                    mat[i] = self.ell_material[e];
                    // A sphere light emits outwards (the outward normal against the ray).
                    let l = self.ell_light.get(e).copied().unwrap_or(INVALID_ID);
                    if l != INVALID_ID {
                        light[i] = l;
                        if normal.dot(dir.lane(i)) < 0.0 {
                            le.set(i, self.emitters.list[l as usize].radiance);
                        }
                    }
                }
                _ => {}
            }
        }
        Lanes8 { n: n.get(), light: U8::new(light), le: le.get(), any_tri, mat }
    }

    /// Shading normals from the triangles' vertex normals (see the module docs) on the triangle
    /// lanes of `bits` that have them; `ng` elsewhere. Returns the normals and the `smooth` lanes.
    fn smooth_normals(
        &self,
        bits: u32,
        geom: &[u32; 8],
        prim: &[u32; 8],
        hits: &Hits8,
        dir: Vec3x8,
        ng: Vec3x8,
    ) -> (Vec3x8, Mask8) {
        let mut ns = Lanes3::of(ng);
        let mut smooth = [false; 8];
        let (bu, bv) = (hits.u.as_array(), hits.v.as_array());
        for i in lanes_of(bits) {
            if geom[i] != GEOM_TRIANGLES {
                continue;
            }
            let Some(c) = self.tri_corner_normals.get(prim[i] as usize).filter(|c| c[0] != Vec3::ZERO) else {
                continue;
            };
            let (u, v) = (bu[i], bv[i]);
            let mut s = (c[0] * (1.0 - u - v) + c[1] * u + c[2] * v).normalize_or_zero();
            if !self.instances.is_empty() && hits.inst.as_array()[i] != INVALID_ID {
                s = self.instances.normal_of(hits.inst.as_array()[i], s);
            }
            let g = ng.lane(i);
            let s = if s.dot(g) < 0.0 { -s } else { s };
            // The guard: the ray must arrive from above the shading normal too. Registry BSDFs
            // (Mitsuba's) see such a hit from the back of their shading frame, as Mitsuba does.
            let registry = || self.materials[self.tri_material[prim[i] as usize] as usize].bsdf.kind != COURSE;
            if s.dot(-dir.lane(i)) > 0.0 || registry() {
                ns.set(i, s);
                smooth[i] = true;
            }
        }
        (ns.get(), crate::simd::mask_from_bools(smooth))
    }

    /// The registry BSDF rows of the materials `ids` on the `valid` lanes (the course's
    /// elsewhere), eight lanes: what a kernel compiled with registry BSDFs shades.
    #[inline]
    pub fn bsdf_params(&self, ids: U8, valid: Mask8) -> crate::bsdf::Params8 {
        let bits = valid.to_bitmask();
        let ids = ids.to_array();
        let row = |i: usize| {
            if bits & (1 << i) != 0 {
                &self.materials[ids[i] as usize].bsdf
            } else {
                &crate::bsdf::BsdfParams::COURSE
            }
        };
        let first = ids[bits.trailing_zeros().min(7) as usize];
        if bits == 0xff && ids.iter().all(|&m| m == first) {
            return crate::bsdf::Params8::splat(&self.materials[first as usize].bsdf);
        }
        crate::bsdf::Params8::from_lanes(std::array::from_fn(row))
    }

    /// The course's fields of material `m0` (into `out.mat`) and its emission and ambient term
    /// on the hit lanes `valid`, the miss record's on the others.
    #[inline]
    fn uniform_materials(&self, m0: u32, valid: Mask8, out: &mut SurfaceHit8) {
        let (m, z) = (&self.materials[m0 as usize], &MISS_MATERIAL);
        let pick3 = |a: Vec3, b: Vec3| Vec3x8::select(valid, Vec3x8::splat(a), Vec3x8::splat(b));
        let pick = |a: f32, b: f32| valid.select(F8::splat(a), F8::splat(b));
        let o = &mut out.mat;
        o.kd = pick3(m.diffuse, z.diffuse);
        o.ks = pick3(m.specular, z.specular);
        o.shininess = pick(m.shininess, z.shininess);
        o.alpha = pick(m.roughness, z.roughness);
        o.ggx = if m.brdf == BrdfKind::Ggx { valid } else { crate::simd::mask_from_bools([false; 8]) };
        // 0 + emission, as the per-lane sum did (-0 becomes +0)
        out.emitted = Vec3x8::ZERO + pick3(m.emission, z.emission);
        out.ambient = pick3(m.ambient, z.ambient);
    }

    /// [`Scene::uniform_materials`] of the hit lanes `bits` (`mat`: material index per lane),
    /// the miss record's on the other lanes: one pass of 8-wide selects per distinct material of
    /// the packet (a per-lane copy of every field cost twice the instructions: callgrind,
    /// cornell-diffuse, 84.2 M -> 38.4 M).
    fn gather_materials(&self, valid: Mask8, mat: &[u32; 8], out: &mut SurfaceHit8) {
        // A packet holds a few distinct materials (often one): each one's lanes take its fields,
        // splatted.
        let z = &MISS_MATERIAL;
        let ids = U8::new(*mat);
        let o = &mut out.mat;
        let (mut kd, mut ks, mut emitted, mut ambient) =
            (Vec3x8::splat(z.diffuse), Vec3x8::splat(z.specular), Vec3x8::splat(z.emission), Vec3x8::splat(z.ambient));
        let (mut shin, mut rough, mut ggx) = (F8::splat(z.shininess), F8::splat(z.roughness), F8::ZERO);
        for (m0, same) in distinct_ids(ids, valid) {
            let m = &self.materials[m0 as usize];
            kd = Vec3x8::select(same, Vec3x8::splat(m.diffuse), kd);
            ks = Vec3x8::select(same, Vec3x8::splat(m.specular), ks);
            shin = same.select(F8::splat(m.shininess), shin);
            rough = same.select(F8::splat(m.roughness), rough);
            if m.brdf == BrdfKind::Ggx {
                ggx |= same;
            }
            // 0 + emission, as the uniform path (-0 becomes +0)
            emitted = Vec3x8::select(same, Vec3x8::splat(Vec3::ZERO + m.emission), emitted);
            ambient = Vec3x8::select(same, Vec3x8::splat(m.ambient), ambient);
        }
        (o.kd, o.ks, o.shininess, o.alpha, o.ggx) = (kd, ks, shin, rough, ggx);
        out.emitted = emitted;
        out.ambient = ambient;
    }
}

/// The material of the miss record's lanes.
const MISS_MATERIAL: Material = Material {
    diffuse: Vec3::ZERO,
    specular: Vec3::ZERO,
    shininess: 0.0,
    emission: Vec3::ZERO,
    ambient: Vec3::ZERO,
    brdf: BrdfKind::Phong,
    roughness: 1.0,
    bsdf: crate::bsdf::BsdfParams::COURSE,
};

/// The fields of a [`SurfaceHit8`] looked up per hit (the rest is 8-wide arithmetic).
struct Lanes8 {
    /// geometric normal, not yet flipped (+z on missed lanes)
    n: Vec3x8,
    light: U8,
    le: Vec3x8,
    /// some lane hit a triangle
    any_tri: bool,
    /// material index per lane (0 on misses)
    mat: [u32; 8],
}

/// The distinct values of `ids` on the lanes of `live`, in the order of their first lane, each
/// with its lanes among `live` as a mask: a packet's few distinct materials or triangles, each
/// taken in one pass of 8-wide selects.
#[inline(always)]
fn distinct_ids(ids: U8, live: Mask8) -> impl Iterator<Item = (u32, Mask8)> {
    let values = ids.to_array();
    let mut rest = live.to_bitmask();
    std::iter::from_fn(move || {
        (rest != 0).then(|| {
            let id = values[rest.trailing_zeros() as usize];
            let on = live & F8::from_bits(ids.simd_eq(U8::splat(id)));
            rest &= !on.to_bitmask();
            (id, on)
        })
    })
}

/// Eight vectors as three coordinate arrays, filled lane by lane (no AoS -> SoA transpose).
#[derive(Clone, Copy)]
struct Lanes3 {
    x: [f32; 8],
    y: [f32; 8],
    z: [f32; 8],
}

impl Lanes3 {
    #[inline]
    fn splat(v: Vec3) -> Self {
        Self { x: [v.x; 8], y: [v.y; 8], z: [v.z; 8] }
    }
    #[inline]
    fn of(v: Vec3x8) -> Self {
        Self { x: v.x.to_array(), y: v.y.to_array(), z: v.z.to_array() }
    }
    #[inline]
    fn set(&mut self, i: usize, v: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }
    #[inline]
    fn get(&self) -> Vec3x8 {
        Vec3x8::new(F8::new(self.x), F8::new(self.y), F8::new(self.z))
    }
}

/// The lane indices of the set bits of `bits` (a `move_mask`), in increasing order.
#[inline]
pub(super) fn lanes_of(mut bits: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (bits != 0).then(|| {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            i
        })
    })
}

#[cfg(test)]
#[path = "gather_tests.rs"]
mod tests;

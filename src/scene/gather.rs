//! The one AoS -> SoA gather of hit records: Embree's per-lane hit records (geometry, primitive,
//! barycentrics, distance) become the 8-lane [`SurfaceHit8`] the integrators shade (see the
//! shading-normal conventions in [`super::build`]).

use super::build::Scene;
use crate::accel::{Hits8, GEOM_ELLIPSOIDS, GEOM_SPHERES, GEOM_TRIANGLES, INVALID_ID};
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
    /// diffuse reflectance kd
    pub kd: Vec3x8,
    /// specular reflectance ks
    pub ks: Vec3x8,
    /// Phong exponent
    pub shininess: F8,
    /// GGX alpha
    pub roughness: F8,
    /// lanes whose material is GGX
    pub ggx: Mask8,
    /// radiance emitted towards wo by the material (`emission`, every hit, any side)
    pub emitted: Vec3x8,
    /// ambient term of the material (`raytracer` only; zero on lights and misses)
    pub ambient: Vec3x8,
    /// radiance emitted towards wo by an area light (quad or emissive triangle: its radiance on its
    /// emitting side, else 0)
    pub le: Vec3x8,
    /// light index for hits on a light's geometry (emitting side or not), else u32::MAX
    pub light: U8,
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
        kd: Vec3x8::ZERO,
        ks: Vec3x8::ZERO,
        shininess: F8::ZERO,
        roughness: F8::ONE,
        ggx: F8::ZERO,
        emitted: Vec3x8::ZERO,
        ambient: Vec3x8::ZERO,
        le: Vec3x8::ZERO,
        light: U8::MAX,
    };
}

/// +z in every lane.
const Z8: Vec3x8 = Vec3x8 { x: F8::ZERO, y: F8::ZERO, z: F8::ONE };

impl Scene {
    /// Gathers the shading records of a packet's hits (rays `org + t dir`, `dir` unit).
    ///
    /// Per lane only the table lookups run (normal, material and light index by primitive); the
    /// rest is 8-wide: the two-sided flip, and the material fields, splatted once when every hit
    /// lane has the same material (the common case of a coherent packet). Lanes that missed get
    /// the miss record (normals +z, zero reflectances, roughness 1, no light).
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
        let p = dir.mul_add(hits.t, org);
        let valid = hits.hit;
        let bits = valid.to_bitmask();
        let (geom, prim) = (hits.geom.as_array(), hits.prim.as_array());
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
                    mat[i] = self.tri_material[prim];
                }
                GEOM_SPHERES | GEOM_ELLIPSOIDS => {
                    let table = if geom[i] == GEOM_SPHERES { &self.sphere_point_index } else { &self.ellipsoid_index };
                    let e = table[prim] as usize;
                    let obj = self.ell_world_to_object[e].transform_point3(p.lane(i));
                    n.set(i, (self.ell_normal[e] * obj).normalize_or_zero());
                    mat[i] = self.ell_material[e];
                }
                _ => {}
            }
        }
        // Shade two-sided: flip the normal to face the incoming ray (the scalar Vec3::dot's
        // operation order, so the sign is the same as per lane).
        let n = n.get();
        let facing = (n.x * dir.x + n.y * dir.y) + n.z * dir.z;
        let ng = Vec3x8::select(valid & facing.simd_gt(F8::ZERO), -n, n);
        let (ns, smooth) = if any_tri && !self.desc.triangle_normals.is_empty() {
            self.smooth_normals(bits, geom, prim, hits, dir, ng)
        } else {
            (ng, crate::simd::mask_from_bools([false; 8]))
        };
        let m = self.gather_materials(bits, valid, &mat);
        out.valid = valid;
        out.p = p;
        out.n = ns;
        out.ng = ng;
        out.smooth = smooth;
        out.wo = -dir;
        out.kd = m.kd;
        out.ks = m.ks;
        out.shininess = m.shininess;
        out.roughness = m.roughness;
        out.ggx = m.ggx;
        out.emitted = m.emitted;
        out.ambient = m.ambient;
        out.le = le.get();
        out.light = U8::new(light);
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
            let s = (c[0] * (1.0 - u - v) + c[1] * u + c[2] * v).normalize_or_zero();
            let g = ng.lane(i);
            let s = if s.dot(g) < 0.0 { -s } else { s };
            // The guard: the ray must arrive from above the shading normal too.
            if s.dot(-dir.lane(i)) > 0.0 {
                ns.set(i, s);
                smooth[i] = true;
            }
        }
        (ns.get(), crate::simd::mask_from_bools(smooth))
    }

    /// The material fields of the hit lanes `bits` (`mat`: material index per lane), the miss
    /// record's on the other lanes.
    fn gather_materials(&self, bits: u32, valid: Mask8, mat: &[u32; 8]) -> Materials8 {
        let miss = Material {
            diffuse: Vec3::ZERO,
            specular: Vec3::ZERO,
            shininess: 0.0,
            emission: Vec3::ZERO,
            ambient: Vec3::ZERO,
            brdf: BrdfKind::Phong,
            roughness: 1.0,
        };
        let first = if bits == 0 { None } else { Some(mat[bits.trailing_zeros() as usize]) };
        let uniform = first.filter(|&m0| lanes_of(bits).all(|i| mat[i] == m0));
        if let Some(m0) = uniform {
            let (m, z) = (&self.materials[m0 as usize], &miss);
            let pick3 = |a: Vec3, b: Vec3| Vec3x8::select(valid, Vec3x8::splat(a), Vec3x8::splat(b));
            let pick = |a: f32, b: f32| valid.select(F8::splat(a), F8::splat(b));
            return Materials8 {
                kd: pick3(m.diffuse, z.diffuse),
                ks: pick3(m.specular, z.specular),
                shininess: pick(m.shininess, z.shininess),
                roughness: pick(m.roughness, z.roughness),
                ggx: if m.brdf == BrdfKind::Ggx { valid } else { crate::simd::mask_from_bools([false; 8]) },
                // 0 + emission, as the per-lane sum did (-0 becomes +0)
                emitted: Vec3x8::ZERO + pick3(m.emission, z.emission),
                ambient: pick3(m.ambient, z.ambient),
            };
        }
        let (mut kd, mut ks, mut emitted, mut ambient) = (
            Lanes3::splat(Vec3::ZERO),
            Lanes3::splat(Vec3::ZERO),
            Lanes3::splat(Vec3::ZERO),
            Lanes3::splat(Vec3::ZERO),
        );
        let (mut shin, mut rough, mut ggx) = ([0f32; 8], [1f32; 8], [false; 8]);
        for i in lanes_of(bits) {
            let m = &self.materials[mat[i] as usize];
            kd.set(i, m.diffuse);
            ks.set(i, m.specular);
            shin[i] = m.shininess;
            rough[i] = m.roughness;
            ggx[i] = m.brdf == BrdfKind::Ggx;
            emitted.set(i, Vec3::ZERO + m.emission);
            ambient.set(i, m.ambient);
        }
        Materials8 {
            kd: kd.get(),
            ks: ks.get(),
            shininess: F8::new(shin),
            roughness: F8::new(rough),
            ggx: crate::simd::mask_from_bools(ggx),
            emitted: emitted.get(),
            ambient: ambient.get(),
        }
    }
}

/// Material fields of 8 lanes (a part of [`SurfaceHit8`]).
struct Materials8 {
    kd: Vec3x8,
    ks: Vec3x8,
    shininess: F8,
    roughness: F8,
    ggx: Mask8,
    emitted: Vec3x8,
    ambient: Vec3x8,
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
fn lanes_of(mut bits: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (bits != 0).then(|| {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            i
        })
    })
}

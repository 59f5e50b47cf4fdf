//! `pathtracer`: unidirectional path tracing with next event estimation (off, on, MIS with the
//! power heuristic), Russian roulette and the format's importance-sampling strategies, run as a
//! wavefront over a tile's paths. After every bounce the live paths are compacted into full packets
//! of 8, so Embree sees full packets past the first bounce; shadow rays of a bounce are batched.
//!
//! Vertex numbering: vertex 1 is the camera hit. `maxdepth N` (FORMAT.md): with NEE, direct light
//! is gathered at vertices 1..N (N = 1 is direct lighting); without NEE, emission is counted at
//! vertices 1..N+1. Emission of area lights (quads, emissive triangles) follows the NEE mode (off:
//! always; on: vertex 1 only; MIS: vertex 1, then weighted against the light-sampling pdf);
//! `emission` of materials is not light-sampled and is counted at every vertex. Estimators stay
//! unbiased: no clamping unless `--clamp` asks for it (biased, reported).
//!
//! Sampler dimensions of vertex v: `DIM_PATH_BASE + 4 (v-1) + {0: light point, 1: (light choice,
//! lobe choice), 2: BSDF direction, 3: (Russian roulette, -)}`. Each is a stratified set over the
//! pixel's spp samples whose strata are shuffled per (pixel, dimension), so dimensions are
//! stratified independently of one another.

use super::context::{masked, TileCtx};
use super::direct::material;
use super::{Integrator, RayKind};
use crate::accel::{Hits8, Ray8, RayHit8};
use crate::bsdf::LobeSet;
use crate::light::emitters::LightSample8;
use crate::light::select::LightSelection;
use crate::sampler::shuffled_index_x8;
use crate::sampling::power_heuristic_x8;
use crate::scene::build::Scene;
use crate::scene::desc::{ImportanceSampling, Nee};
use crate::simd::{mask_from_bools, mask_to_bools, Frame8, Mask8, Vec3x8, F8, U8};
use glam::Vec3;

/// First sampler dimension of the path tracer's vertices.
pub const DIM_PATH_BASE: u32 = 64;
/// Hard cap on path vertices when `maxdepth -1` (Russian roulette normally ends paths far sooner).
pub const MAX_VERTICES_UNBOUNDED: u32 = 4096;

/// One live path between bounces (AoS, so that compaction is a plain copy). The wavefront is kept
/// padded to a multiple of 8 with [`PathLane::DEAD`] lanes, so packets are read without bounds checks.
#[derive(Clone, Copy, Debug)]
struct PathLane {
    /// index of (tile packet, lane) whose pixel this path belongs to: packet * 8 + lane
    slot: u32,
    /// linear pixel index (sampler input)
    pixel: u32,
    /// pixel sample index (sampler input)
    sample: u32,
    /// next ray origin and unit direction
    o: Vec3,
    d: Vec3,
    /// path throughput
    beta: Vec3,
    /// solid-angle pdf with which `d` was sampled (for the MIS weight of emission found along it)
    pdf: f32,
    /// the previous vertex's shading point and normal as NEE used them (for a point-dependent
    /// light selection's pmf in the MIS weight of emission found along `d`)
    prev_p: Vec3,
    prev_n: Vec3,
}

impl PathLane {
    /// Padding lane: traced inactive, contributes nothing, never continues.
    const DEAD: Self = Self {
        slot: u32::MAX,
        pixel: 0,
        sample: 0,
        o: Vec3::ZERO,
        d: Vec3::Z,
        beta: Vec3::ZERO,
        pdf: 0.0,
        prev_p: Vec3::ZERO,
        prev_n: Vec3::Z,
    };
}

impl ShadowLane {
    /// Padding lane of a shadow packet: inactive, adds nothing.
    const DEAD: Self = Self { slot: u32::MAX, o: Vec3::ZERO, d: Vec3::Z, tfar: 0.0, contrib: Vec3::ZERO };
}

/// Pads `v` with `dead` up to a multiple of 8 lanes.
#[inline]
fn pad8<T: Copy>(v: &mut Vec<T>, dead: T) {
    while !v.len().is_multiple_of(8) {
        v.push(dead);
    }
}

/// One shadow ray waiting to be packed: origin, unnormalized direction to the light sample,
/// interval end, and the contribution added to `slot` if it is unoccluded.
#[derive(Clone, Copy, Debug)]
struct ShadowLane {
    slot: u32,
    o: Vec3,
    d: Vec3,
    tfar: f32,
    contrib: Vec3,
}

/// Per-thread buffers of the path wavefront.
#[derive(Default)]
pub struct PathScratch {
    lanes: Vec<PathLane>,
    next: Vec<PathLane>,
    rh: Vec<(RayHit8, Mask8)>,
    radiance: Vec<Vec3>,
    shadow_lanes: Vec<ShadowLane>,
    shadow: Vec<(Ray8, Mask8)>,
    shadow_contrib: Vec<Vec3x8>,
    shadow_slots: Vec<[u32; 8]>,
}

impl Integrator {
    /// Stratified 2D point of dimension `dim` for pixel sample `s`, strata shuffled per (pixel, dim).
    #[inline]
    fn path_point(&self, pixel: U8, s: U8, dim: u32) -> (F8, F8) {
        let _p = crate::profile::leaf(crate::profile::Phase::SamplerPath);
        crate::sampler::replay::path_point(pixel, s, dim);
        let k = shuffled_index_x8(s, self.spp, pixel, dim, self.seed);
        self.path_set.point_x8(pixel, U8::splat(0), dim, k, self.seed)
    }
}

/// Radiance of pixel samples `samples` for each packet of the tile by path tracing, into `out`
/// (sample-major: `out[si * pks.len() + p]`). All paths of all these samples form one wavefront,
/// so packets stay full even when Russian roulette thins the paths out.
pub(super) fn tile<L: LobeSet>(
    it: &Integrator,
    ctx: &mut TileCtx,
    samples: std::ops::Range<u32>,
    out: &mut Vec<Vec3x8>,
) {
    it.path_tile::<L>(ctx, samples, out)
}

impl Integrator {
    fn path_tile<L: LobeSet>(&self, ctx: &mut TileCtx, samples: std::ops::Range<u32>, out: &mut Vec<Vec3x8>) {
        let TileCtx { scene, camera, pks, tracer, scratch } = ctx;
        let sc = &mut scratch.path;
        let nee = self.nee;
        let sel = self.light_selection;
        let n_all = self.light_set.n().max(1);
        let n_lights = scene.emitters.len() as u32;
        let max_v = if self.max_depth < 0 { MAX_VERTICES_UNBOUNDED } else { self.max_depth as u32 + 1 };
        sc.radiance.clear();
        let n_samples = samples.len();
        sc.radiance.resize(pks.len() * 8 * n_samples, Vec3::ZERO);
        sc.lanes.clear();
        // Camera paths: the tile's packets, kept as they are (coherent, 4x2 pixel blocks).
        for (si, s) in samples.enumerate() {
            for (p, pk) in pks.iter().enumerate() {
                let (org, dir) = camera.rays(pk, s);
                let (inside, pix, dirs) = (mask_to_bools(pk.active), pk.pixel.to_array(), dir.to_lanes());
                for i in 0..8 {
                    let slot = ((si * pks.len() + p) * 8 + i) as u32;
                    // Lanes outside the image travel as inactive placeholders in the first packets.
                    let slot = if inside[i] { slot } else { u32::MAX };
                    sc.lanes.push(PathLane {
                        slot,
                        pixel: pix[i],
                        sample: s,
                        o: org.lane(i),
                        d: dirs[i],
                        beta: Vec3::ONE,
                        pdf: 0.0,
                        prev_p: Vec3::ZERO,
                        prev_n: Vec3::Z,
                    });
                }
            }
        }
        let mut v = 1u32;
        while !sc.lanes.is_empty() && v <= max_v {
            let dims = DIM_PATH_BASE + 4 * (v - 1);
            // Trace: full packets of 8 live paths (the first bounce keeps the camera packets).
            // (Written in place: Embree resets a packet's hit ids itself.)
            let n_packets = sc.lanes.len() / 8;
            sc.rh.truncate(n_packets);
            sc.rh.resize(n_packets, (RayHit8::default(), F8::ZERO));
            for (chunk, (rh, active)) in sc.lanes.chunks_exact(8).zip(sc.rh.iter_mut()) {
                let (org, dir, lanes) = soa_rays(chunk);
                *active = rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), lanes);
            }
            tracer.intersect_all(&mut sc.rh, if v == 1 { RayKind::Camera } else { RayKind::Bounce });
            sc.next.clear();
            sc.shadow_lanes.clear();
            sc.shadow.clear();
            sc.shadow_contrib.clear();
            sc.shadow_slots.clear();
            for (ci, chunk) in sc.lanes.chunks_exact(8).enumerate() {
                let (rh, traced) = &sc.rh[ci];
                let (org, dir) = (rh.ray.org(), rh.ray.dir());
                let sh = scene.gather(org, dir, &Hits8::from_rayhit(rh, *traced));
                let hit = sh.valid;
                let beta = Vec3x8::from_lanes(std::array::from_fn(|i| chunk[i].beta));
                let slots: [u32; 8] = std::array::from_fn(|i| chunk[i].slot);
                let pixel = U8::new(std::array::from_fn(|i| chunk[i].pixel));
                let s = U8::new(std::array::from_fn(|i| chunk[i].sample));
                let prev_pdf = F8::new(std::array::from_fn(|i| chunk[i].pdf));

                // Emission: materials always; area lights (quads, emissive triangles) by the NEE mode.
                let mut le = masked(sh.emitted, hit);
                let is_light = hit & F8::from_bits(!sh.light.simd_eq(U8::splat(u32::MAX)));
                let light_w = match nee {
                    Nee::Off => F8::ONE,
                    Nee::On => F8::splat(if v == 1 { 1.0 } else { 0.0 }),
                    Nee::Mis if v == 1 => F8::ONE,
                    Nee::Mis => {
                        let _p = crate::profile::leaf(crate::profile::Phase::Mis);
                        let p_light = if sel == LightSelection::Uniform {
                            light_pdf_at_hit(scene, &sh, rh, is_light)
                        } else {
                            let pp = Vec3x8::from_lanes(std::array::from_fn(|i| chunk[i].prev_p));
                            let pn = Vec3x8::from_lanes(std::array::from_fn(|i| chunk[i].prev_n));
                            let pmf = match sel {
                                // N points on every light: multi-sample MIS against N p_light.
                                LightSelection::All => F8::splat(n_all as f32),
                                _ => self.light_sampler.pmf_x8(pp, pn, sh.light, is_light),
                            };
                            light_pdf_at_hit_pmf(scene, &sh, rh, is_light, pmf)
                        };
                        power_heuristic_x8(prev_pdf, p_light, is_light)
                    }
                };
                le += masked(sh.le, hit).scale(light_w);
                add_lanes(&mut sc.radiance, &slots, beta.mul_elem(le));

                // Shading frame: the normal faces wo, so wo.z > 0 in local coordinates.
                let shade = hit & !is_light;
                let nee_here = nee != Nee::Off && n_lights > 0 && v < max_v;
                let bounce_here = match nee {
                    Nee::On => v + 1 < max_v,
                    _ => v < max_v,
                };
                if shade.none() || (!nee_here && !bounce_here) {
                    continue;
                }
                let frame = Frame8::from_normal(sh.n);
                let wo = frame.to_local(sh.wo);
                let mat = material(&sh);
                let eps = scene.offset_eps(sh.p);
                // Offsets along the geometric normal (the shading one may point into the surface).
                let o = sh.ng.mul_add(eps, sh.p);
                // Smooth-shaded lanes: directions must also leave the geometric surface.
                let leaves = |wi: Vec3x8| !sh.smooth | sh.ng.dot(wi).simd_gt(F8::ZERO);
                // (light choice, lobe choice): drawn only where one of them is used (several
                // lights, or BRDF sampling's lobe pick); skipping it changes no other dimension.
                let (u_choice, u_lobe) = if n_lights > 1 || self.strategy == ImportanceSampling::Brdf {
                    self.path_point(pixel, s, dims + 1)
                } else {
                    (F8::ZERO, F8::ZERO)
                };

                if nee_here {
                    let (u, w) = self.path_point(pixel, s, dims);
                    let mut push = |ls: LightSample8, scale: Option<F8>, mis_n: Option<F8>, ok: Mask8| {
                        let (y, ln, l_rad, area, inv_pmf) = (ls.y, ls.normal, ls.radiance, ls.area, ls.inv_pmf);
                        let to = y - sh.p;
                        let d2 = to.length_squared();
                        let inv_d = F8::ONE / d2.sqrt();
                        let wi = to.scale(inv_d);
                        let cos_i = sh.n.dot(wi);
                        let cos_l = -ln.dot(wi);
                        let lit =
                            ok & cos_i.simd_gt(F8::ZERO) & cos_l.simd_gt(F8::ZERO) & d2.simd_gt(F8::ZERO) & leaves(wi);
                        if lit.none() {
                            return;
                        }
                        let (f, pdf_b) = {
                            let _p = crate::profile::leaf(crate::profile::Phase::BsdfEval);
                            mat.eval_pdf_k::<L>(self.strategy, wo, frame.to_local(wi), lit)
                        };
                        // L f cos_i / p_light with p_light = pmf d^2 / (A cos_l) (solid angle).
                        let mut g = cos_i * cos_l * area * inv_pmf * inv_d * inv_d;
                        if let Some(k) = scale {
                            g *= k;
                        }
                        // (The NEE side's weight is a few flops per lane: cheaper than a scope, so
                        // it stays in `other`; the light-hit side below is timed as `mis weights`.)
                        let w_light = if nee == Nee::Mis {
                            let p_light = d2 / (area * cos_l * inv_pmf);
                            let p_light = if let Some(k) = mis_n { p_light * k } else { p_light };
                            power_heuristic_x8(p_light, pdf_b, lit)
                        } else {
                            F8::ONE
                        };
                        let contrib = beta.mul_elem(f).mul_elem(l_rad).scale(g * w_light);
                        let tfar = F8::ONE - scene.offset_eps(y) * inv_d;
                        // Shadow rays are compacted per lane and sent in full packets below.
                        let (lit_b, os, ds, tf, cs) =
                            (mask_to_bools(lit), o.to_lanes(), (y - o).to_lanes(), tfar.to_array(), contrib.to_lanes());
                        for i in 0..8 {
                            if lit_b[i] {
                                sc.shadow_lanes.push(ShadowLane {
                                    slot: slots[i],
                                    o: os[i],
                                    d: ds[i],
                                    tfar: tf[i],
                                    contrib: cs[i],
                                });
                            }
                        }
                    };
                    match sel {
                        // One light chosen by `scene.emitters.all` (uniform among quads, by power
                        // with emissive triangles), one point on it, uniform in area: the
                        // historical path, kept bit-identical.
                        LightSelection::Uniform => {
                            let ls = {
                                let _p = crate::profile::leaf(crate::profile::Phase::Emitter);
                                scene.emitters.sample_x8(u_choice, u, w, shade)
                            };
                            push(ls, None, None, shade)
                        }
                        // Every light, N points each (a lattice rotated by (u, w)), each weighted
                        // 1/N and, with MIS, against N p_light.
                        LightSelection::All => {
                            let (scale, mis_n) = if n_all > 1 {
                                (Some(F8::splat(1.0 / n_all as f32)), Some(F8::splat(n_all as f32)))
                            } else {
                                (None, None)
                            };
                            for e in &scene.emitters.list {
                                for j in 0..n_all {
                                    let (uj, wj) = lattice_point(u, w, j, n_all);
                                    let ls = {
                                        let _p = crate::profile::leaf(crate::profile::Phase::Emitter);
                                        e.sample_x8(uj, wj)
                                    };
                                    push(ls, scale, mis_n, shade);
                                }
                            }
                        }
                        LightSelection::Power | LightSelection::Spatial => {
                            let (ls, ok) = {
                                let _p = crate::profile::leaf(crate::profile::Phase::Emitter);
                                self.light_sampler.sample_point_x8(&scene.emitters, u_choice, sh.p, sh.n, shade, (u, w))
                            };
                            push(ls, None, None, ok);
                        }
                    }
                }

                // Continue the path: sample the BSDF, then Russian roulette.
                if bounce_here {
                    let u2 = self.path_point(pixel, s, dims + 2);
                    let (wi_l, pdf, f) = {
                        let _p = crate::profile::leaf(crate::profile::Phase::BsdfSample);
                        mat.sample_k::<L>(self.strategy, wo, [u2.0, u2.1], u_lobe, shade)
                    };
                    let cos = wi_l.z;
                    let wi = frame.to_world(wi_l);
                    let ok = shade
                        & pdf.simd_gt(F8::ZERO)
                        & cos.simd_gt(F8::ZERO)
                        & f.max_elem().simd_gt(F8::ZERO)
                        & leaves(wi);
                    let mut nb = beta.mul_elem(f).scale(ok.select(cos / pdf, F8::ZERO));
                    let mut alive = ok & nb.max_elem().simd_gt(F8::ZERO) & nb.is_finite();
                    if self.russian_roulette {
                        let (u_rr, _) = self.path_point(pixel, s, dims + 3);
                        let q = nb.max_elem().min(F8::ONE);
                        alive &= u_rr.simd_lt(q);
                        nb = nb.scale(alive.select(F8::ONE / q, F8::ZERO));
                    }
                    if alive.any() {
                        let (alive_b, os, ds, bs, ps) =
                            (mask_to_bools(alive), o.to_lanes(), wi.to_lanes(), nb.to_lanes(), pdf.to_array());
                        let (sps, sns) = (sh.p.to_lanes(), sh.n.to_lanes());
                        let (pix, smp) = (pixel.to_array(), s.to_array());
                        for i in 0..8 {
                            if alive_b[i] {
                                sc.next.push(PathLane {
                                    slot: slots[i],
                                    pixel: pix[i],
                                    sample: smp[i],
                                    o: os[i],
                                    d: ds[i],
                                    beta: bs[i],
                                    pdf: ps[i],
                                    prev_p: sps[i],
                                    prev_n: sns[i],
                                });
                            }
                        }
                    }
                }
            }
            // Shadow packets of this bounce: full packets of 8 lanes, traced back to back.
            pad8(&mut sc.shadow_lanes, ShadowLane::DEAD);
            for chunk in sc.shadow_lanes.chunks_exact(8) {
                let o = Vec3x8::from_lanes(std::array::from_fn(|i| chunk[i].o));
                let d = Vec3x8::from_lanes(std::array::from_fn(|i| chunk[i].d));
                let tfar = F8::new(std::array::from_fn(|i| chunk[i].tfar));
                let active = mask_from_bools(std::array::from_fn(|i| chunk[i].slot != u32::MAX));
                let (ray, lit) = Ray8::new(o, d, F8::ZERO, tfar, active);
                sc.shadow.push((ray, lit));
                sc.shadow_contrib.push(Vec3x8::from_lanes(std::array::from_fn(|i| chunk[i].contrib)));
                sc.shadow_slots.push(std::array::from_fn(|i| chunk[i].slot));
            }
            let occluded_batch = crate::profile::scope(crate::profile::Phase::EmbreeOccluded);
            for (j, (ray, lit)) in sc.shadow.iter_mut().enumerate() {
                let occluded = tracer.occluded(ray, *lit);
                let visible = *lit & !occluded;
                add_lanes(&mut sc.radiance, &sc.shadow_slots[j], masked(sc.shadow_contrib[j], visible));
            }
            drop(occluded_batch);
            pad8(&mut sc.next, PathLane::DEAD);
            std::mem::swap(&mut sc.lanes, &mut sc.next);
            v += 1;
        }
        // Opt-in clamp (biased): scale a sample so its largest channel is at most `clamp`;
        // non-finite samples are left as they are, for the film to count and drop.
        if let Some(m) = self.clamp {
            for r in sc.radiance.iter_mut() {
                let top = r.max_element();
                if top > m {
                    *r *= m / top;
                }
            }
        }
        out.clear();
        out.extend(sc.radiance.chunks_exact(8).map(|l| Vec3x8::from_lanes(std::array::from_fn(|i| l[i]))));
    }
}

/// SoA rays of a packet of 8 lanes; placeholders (slot u32::MAX) are inactive.
#[inline]
fn soa_rays(chunk: &[PathLane]) -> (Vec3x8, Vec3x8, Mask8) {
    let o = Vec3x8::from_lanes(std::array::from_fn(|i| chunk[i].o));
    let d = Vec3x8::from_lanes(std::array::from_fn(|i| chunk[i].d));
    (o, d, mask_from_bools(std::array::from_fn(|i| chunk[i].slot != u32::MAX)))
}

/// Adds lane i of `v` to `radiance[slots[i]]` for every lane with a slot.
#[inline]
fn add_lanes(radiance: &mut [Vec3], slots: &[u32; 8], v: Vec3x8) {
    let lanes = v.to_lanes();
    for i in 0..8 {
        if let Some(r) = radiance.get_mut(slots[i] as usize) {
            *r += lanes[i];
        }
    }
}

/// Solid-angle pdf with which NEE would have picked the point hit on a light: pmf d^2 / (A cos_l)
/// (pmf = 1/#lights without emissive triangles); zero where `is_light` is off.
#[inline]
fn light_pdf_at_hit(scene: &Scene, sh: &crate::scene::build::SurfaceHit8, rh: &RayHit8, is_light: Mask8) -> F8 {
    let ids = sh.light.to_array();
    let pick = |i: usize| scene.emitters.list.get(ids[i] as usize);
    let area = F8::new(std::array::from_fn(|i| pick(i).map_or(1.0, |l| l.area)));
    let ln = Vec3x8::from_lanes(std::array::from_fn(|i| pick(i).map_or(Vec3::Z, |l| l.normal)));
    let inv_pmf = scene.emitters.inv_pmf_x8(sh.light, is_light);
    let t = F8::new(rh.ray.tfar);
    let cos_l = ln.dot(sh.wo);
    let p = t * t / (area * cos_l * inv_pmf);
    is_light.select(p, F8::ZERO)
}

/// Solid-angle pdf of NEE at a light hit for a light chosen with probability `pmf` (per lane):
/// pmf d^2 / (A cos_l); zero where `is_light` is off or `pmf` is 0.
#[inline]
fn light_pdf_at_hit_pmf(
    scene: &Scene,
    sh: &crate::scene::build::SurfaceHit8,
    rh: &RayHit8,
    is_light: Mask8,
    pmf: F8,
) -> F8 {
    let ids = sh.light.to_array();
    let pick = |i: usize| scene.emitters.list.get(ids[i] as usize);
    let area = F8::new(std::array::from_fn(|i| pick(i).map_or(1.0, |l| l.area)));
    let ln = Vec3x8::from_lanes(std::array::from_fn(|i| pick(i).map_or(Vec3::Z, |l| l.normal)));
    let t = F8::new(rh.ray.tfar);
    let cos_l = ln.dot(sh.wo);
    let p = pmf * t * t / (area * cos_l);
    is_light.select(p, F8::ZERO)
}

/// Point `j` of `n` on one light for `all`: a Fibonacci-like rank-1 lattice rotated by `(u, w)`
/// (every point uniform on the unit square; point 0 is `(u, w)` itself).
#[inline]
fn lattice_point(u: F8, w: F8, j: u32, n: u32) -> (F8, F8) {
    if j == 0 {
        return (u, w);
    }
    let fr = |x: F8| x - x.floor();
    let a = F8::splat(j as f32 / n as f32);
    let b = F8::splat((j as f32 * 0.618_034).fract());
    (fr(u + a).min(F8::splat(ONE_MINUS)), fr(w + b).min(F8::splat(ONE_MINUS)))
}

/// Largest f32 below 1.
const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

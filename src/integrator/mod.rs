//! Integrators: radiance of one 4x2 packet of camera samples. They reach Embree only through
//! `scene::build::Scene` and `accel` packets.
//!
//! Directions: `wo` points to the viewer, `wi` to the light; pdfs per unit solid angle unless named
//! `_area`. Dimensions given to the sampler: [`DIM_CAMERA`] for the pixel jitter, then
//! [`DIM_LIGHT_BASE`] + light index for the light samples of `direct`.

use crate::accel::{Hits8, Ray8, RayHit8};
use crate::light::polygonal::polygon_phi_x8;
use crate::render::PixelPacket;
use crate::sampler::{GridTable, PointSet, SamplerKind, Stream};
use crate::scene::build::{Scene, SurfaceHit8};
use crate::scene::desc::{ImportanceSampling, IntegratorKind, Nee};
use crate::simd::{Mask8, Vec3x8, F8, U8};
use kernel::Kernel;
use serde::Serialize;
use std::f32::consts::PI;

pub mod kernel;
mod path;
mod whitted;
pub use path::{PathScratch, DIM_PATH_BASE};

/// Sampler dimension of the camera (pixel) jitter.
pub const DIM_CAMERA: u32 = 0;
/// First sampler dimension of light sampling; light `l` uses `DIM_LIGHT_BASE + l`.
pub const DIM_LIGHT_BASE: u32 = 16;

/// Ray and packet counters of a render (summed over threads).
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq, Eq)]
pub struct Counters {
    /// camera rays traced
    pub camera: u64,
    /// shadow rays traced
    pub shadow: u64,
    /// bounce rays traced
    pub bounce: u64,
    /// camera packets sent to Embree
    pub camera_packets: u64,
    /// shadow packets sent to Embree
    pub shadow_packets: u64,
    /// bounce packets sent to Embree
    pub bounce_packets: u64,
    /// samples whose value was not finite (replaced by zero; must stay 0)
    pub nonfinite: u64,
}

/// Which kind of ray a packet carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKind {
    /// primary rays from the camera
    Camera,
    /// path continuation rays
    Bounce,
    /// occlusion rays towards light samples
    Shadow,
}

impl Counters {
    /// Adds another set of counters.
    pub fn merge(&mut self, o: &Counters) {
        self.camera += o.camera;
        self.shadow += o.shadow;
        self.bounce += o.bounce;
        self.camera_packets += o.camera_packets;
        self.shadow_packets += o.shadow_packets;
        self.bounce_packets += o.bounce_packets;
        self.nonfinite += o.nonfinite;
    }
    /// All rays traced.
    pub fn total_rays(&self) -> u64 {
        self.camera + self.shadow + self.bounce
    }
    /// All packets sent to Embree.
    pub fn packets(&self) -> u64 {
        self.camera_packets + self.shadow_packets + self.bounce_packets
    }
    /// Mean fraction of active lanes over all packets sent to Embree.
    pub fn occupancy(&self) -> f64 {
        ratio(self.total_rays(), 8 * self.packets())
    }
    /// Mean fraction of active lanes in bounce packets (paths past the first bounce).
    pub fn bounce_occupancy(&self) -> f64 {
        ratio(self.bounce, 8 * self.bounce_packets)
    }
    /// Mean fraction of active lanes in shadow packets.
    pub fn shadow_occupancy(&self) -> f64 {
        ratio(self.shadow, 8 * self.shadow_packets)
    }
    /// Mean number of rays traced per camera ray along a path (camera + bounce segments).
    pub fn mean_path_length(&self) -> f64 {
        ratio(self.camera + self.bounce, self.camera)
    }
    /// Counts one packet of `kind` whose traced lanes are `traced`.
    fn packet(&mut self, kind: RayKind, traced: Mask8) {
        let n = traced.to_bitmask().count_ones() as u64;
        let (rays, packets) = match kind {
            RayKind::Camera => (&mut self.camera, &mut self.camera_packets),
            RayKind::Bounce => (&mut self.bounce, &mut self.bounce_packets),
            RayKind::Shadow => (&mut self.shadow, &mut self.shadow_packets),
        };
        *rays += n;
        *packets += 1;
    }
}

/// Stratum of sample `s` of an n-point stratified set when sample 0 is at the centre: the stratum
/// holding (0.5, 0.5) (cell (nx/2, ny/2) of `strata_shape(n)`) is sample 0's, so its own sample
/// takes stratum 0; every other sample keeps its stratum.
fn centre_swap(s: u32, n: u32) -> u32 {
    let (nx, ny) = crate::sampler::strata_shape(n);
    let c = (ny / 2) * nx + nx / 2;
    if s % n == c {
        0
    } else {
        s
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

/// Optional capture of every packet traced, for measuring Embree's raw rate on the same rays.
#[derive(Default)]
pub struct RayLog {
    /// camera packets (rays and their active masks)
    pub camera: Vec<(RayHit8, Mask8)>,
    /// bounce packets (path continuation rays)
    pub bounce: Vec<(RayHit8, Mask8)>,
    /// shadow packets
    pub shadow: Vec<(Ray8, Mask8)>,
}

/// Where pixel sample 0 goes (`--first-sample`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FirstSample {
    /// Sample 0 through the pixel centre, as the CSE168 course code does (the default for `.test`
    /// scenes; at spp 1 the render is the course's deterministic one). With the stratified layout
    /// sample 0 takes the stratum that holds the centre (whose own sample takes sample 0's stratum),
    /// so the other samples keep one jittered point per stratum: the estimate is biased by
    /// (f(centre) - mean of f over that stratum) / spp, O(1/spp). `grid-center` is unchanged.
    Centre,
    /// Sample 0 is jittered like the others: strata's unbiased layout (the default for `.obj` scenes).
    Jittered,
}

impl FirstSample {
    /// "centre" | "center" | "jittered".
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim() {
            "centre" | "center" => Some(Self::Centre),
            "jittered" => Some(Self::Jittered),
            _ => None,
        }
    }

    /// Canonical name (accepted by `parse`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Centre => "centre",
            Self::Jittered => "jittered",
        }
    }
}

/// An integrator with its settings resolved from the scene and the command line.
#[derive(Clone, Debug)]
pub struct Integrator {
    /// which estimator
    pub kind: IntegratorKind,
    /// samples per pixel
    pub spp: u32,
    /// base seed
    pub seed: u64,
    /// pixel sample layout (over the spp samples of a pixel)
    pub pixel_set: PointSet,
    /// light sample layout (over the light samples of one pixel sample)
    pub light_set: PointSet,
    /// path tracer: layout of every path dimension over the spp samples of a pixel
    pub path_set: GridTable,
    /// path tracer: next event estimation
    pub nee: Nee,
    /// path tracer: Russian roulette
    pub russian_roulette: bool,
    /// path tracer: direction sampling strategy
    pub strategy: ImportanceSampling,
    /// path tracer: maximum bounces (-1 = unbounded)
    pub max_depth: i32,
    /// the kernel that runs (specialized for the scene's features, or [`Kernel::GENERAL`])
    pub kernel: Kernel,
    /// path tracer, opt-in and biased: each pixel sample is scaled so its largest channel is at
    /// most this radiance (None: no clamping, the unbiased default)
    pub clamp: Option<f32>,
    /// where pixel sample 0 goes ([`FirstSample`]; `new` gives `Jittered`)
    pub first_sample: FirstSample,
}

impl Integrator {
    /// Settings from the scene, overridden by explicit choices.
    pub fn new(
        scene: &Scene,
        spp: u32,
        seed: u64,
        light_sampler: Option<SamplerKind>,
        light_samples: Option<u32>,
        pixel_sampler: Option<SamplerKind>,
    ) -> Self {
        let d = &scene.desc;
        let n_light = light_samples.unwrap_or(d.light_samples).max(1);
        let light_kind =
            light_sampler.unwrap_or(if d.light_stratify { SamplerKind::Stratified } else { SamplerKind::Independent });
        Self {
            kind: d.integrator,
            spp: spp.max(1),
            seed,
            pixel_set: PointSet::new(pixel_sampler.unwrap_or(SamplerKind::Stratified), spp.max(1)),
            light_set: PointSet::new(light_kind, n_light),
            path_set: GridTable::new(PointSet::new(SamplerKind::Stratified, spp.max(1))),
            nee: d.nee,
            russian_roulette: d.russian_roulette,
            strategy: d.importance_sampling,
            max_depth: d.max_depth,
            kernel: Kernel::for_scene(scene),
            clamp: None,
            first_sample: FirstSample::Jittered,
        }
    }

    /// The same integrator for `spp` samples per pixel: the per-pixel layouts (pixel jitter, path
    /// dimensions) are rebuilt for that count. `None` (an spp not known in advance, as in
    /// equal-time runs) makes them independent, since a stratified layout needs its count.
    pub fn resampled(&self, spp: Option<u32>) -> Self {
        let mut it = self.clone();
        match spp {
            Some(n) => {
                it.spp = n.max(1);
                it.pixel_set = PointSet::new(self.pixel_set.kind(), it.spp);
                it.path_set = GridTable::new(PointSet::new(self.path_set.set().kind(), it.spp));
            }
            None => {
                it.spp = u32::MAX;
                it.pixel_set = PointSet::new(SamplerKind::Independent, 1);
                it.path_set = GridTable::new(PointSet::new(SamplerKind::Independent, 1));
            }
        }
        it
    }

    /// Camera rays of packet `pk` for pixel sample `s`: origins and unit directions.
    #[inline]
    pub fn camera_rays(&self, scene: &Scene, pk: &PixelPacket, s: u32) -> (Vec3x8, Vec3x8) {
        let kind = self.pixel_set.kind();
        let centre = self.first_sample == FirstSample::Centre && kind != SamplerKind::GridCenter;
        let (jx, jy) = if centre && s == 0 {
            (F8::splat(0.5), F8::splat(0.5))
        } else {
            // Stratified: the sample whose stratum holds the centre takes sample 0's stratum.
            let k = if centre && kind == SamplerKind::Stratified { centre_swap(s, self.pixel_set.n()) } else { s };
            self.pixel_set.point_x8(pk.pixel, U8::splat(0), DIM_CAMERA, U8::splat(k), self.seed)
        };
        let dir = scene.camera.dirs8(pk.x + jx, pk.y + jy);
        (Vec3x8::splat(scene.camera.eye), dir)
    }

    /// Radiance of pixel samples `samples` for each packet of `pks` (a tile), into `out`,
    /// sample-major: `out[si * pks.len() + p]` is packet p at sample `samples.start + si`
    /// (inactive lanes zero). `log` records every packet traced.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance_tile(
        &self,
        scene: &Scene,
        pks: &[PixelPacket],
        samples: std::ops::Range<u32>,
        out: &mut Vec<Vec3x8>,
        sc: &mut Scratch,
        c: &mut Counters,
        mut log: Option<&mut RayLog>,
    ) {
        if self.kind == IntegratorKind::PathTracer {
            // The kernel compiled for the scene's lobes (see `kernel`).
            let sp = &mut sc.path;
            return match (self.kernel.lobes.phong, self.kernel.lobes.ggx) {
                (false, false) => self.path_tile::<false, false>(scene, pks, samples, out, sp, c, log),
                (true, false) => self.path_tile::<true, false>(scene, pks, samples, out, sp, c, log),
                (false, true) => self.path_tile::<false, true>(scene, pks, samples, out, sp, c, log),
                (true, true) => self.path_tile::<true, true>(scene, pks, samples, out, sp, c, log),
            };
        }
        out.clear();
        let mut one = std::mem::take(&mut sc.one);
        for s in samples {
            self.radiance_tile_1(scene, pks, s, &mut one, sc, c, log.as_deref_mut());
            out.extend_from_slice(&one);
        }
        sc.one = one;
    }

    /// Radiance of pixel sample `s` for each packet of `pks` (direct lighting integrators): the
    /// tile is processed as a wavefront: all camera packets are traced, then gathered, then for each
    /// (light, light sample) all shadow packets are built and traced back to back.
    #[allow(clippy::too_many_arguments)]
    fn radiance_tile_1(
        &self,
        scene: &Scene,
        pks: &[PixelPacket],
        s: u32,
        out: &mut Vec<Vec3x8>,
        sc: &mut Scratch,
        c: &mut Counters,
        mut log: Option<&mut RayLog>,
    ) {
        let n = pks.len();
        out.clear();
        sc.rh.clear();
        sc.hits.clear();
        // Camera packets: coherent primary rays from 4x2 pixel blocks.
        for pk in pks {
            let (org, dir) = self.camera_rays(scene, pk, s);
            let mut rh = RayHit8::default();
            let active = rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), pk.active);
            if let Some(l) = log.as_deref_mut() {
                l.camera.push((rh, active));
            }
            sc.rh.push((rh, active));
        }
        for (rh, active) in sc.rh.iter_mut() {
            let traced = scene.accel.intersect8(rh, true, *active);
            c.packet(RayKind::Camera, traced);
            *active = traced;
        }
        // Gather: hit records to SoA shading records; emission.
        for (rh, traced) in &sc.rh {
            let org = Vec3x8::new(F8::new(rh.ray.org_x), F8::new(rh.ray.org_y), F8::new(rh.ray.org_z));
            let dir = Vec3x8::new(F8::new(rh.ray.dir_x), F8::new(rh.ray.dir_y), F8::new(rh.ray.dir_z));
            let sh = scene.gather(org, dir, &Hits8::from_rayhit(rh, *traced));
            out.push(masked(sh.emitted + sh.le, sh.valid));
            sc.hits.push(sh);
        }
        match self.kind {
            IntegratorKind::AnalyticDirect => {
                for (o, sh) in out.iter_mut().zip(&sc.hits) {
                    *o += analytic_direct(scene, sh);
                }
            }
            IntegratorKind::RayTracer => {
                for (o, sh) in out.iter_mut().zip(&sc.hits) {
                    *o += whitted::radiance(scene, self.max_depth, sh, c, log.as_deref_mut());
                }
            }
            _ => self.direct_tile(scene, pks, s, out, sc, c, log),
        }
        debug_assert_eq!(out.len(), n);
    }

    /// `direct`: for each light, the mean over the light samples of
    /// L f cos(th_i) cos(th_l) / (d^2 pdf_area) with visibility from shadow packets, added to `out`.
    #[allow(clippy::too_many_arguments)]
    fn direct_tile(
        &self,
        scene: &Scene,
        pks: &[PixelPacket],
        s: u32,
        out: &mut [Vec3x8],
        sc: &mut Scratch,
        c: &mut Counters,
        mut log: Option<&mut RayLog>,
    ) {
        let n_light = self.light_set.n();
        let inv_n = F8::splat(1.0 / n_light as f32);
        let sample_idx = U8::splat(s);
        // Lights shade nothing themselves (black, one-sided emitters).
        sc.shade.clear();
        sc.shade
            .extend(sc.hits.iter().map(|sh| sh.valid & F8::from_bits(sh.light.simd_eq(U8::splat(u32::MAX)).into())));
        sc.eps.clear();
        sc.eps.extend(sc.hits.iter().map(|sh| scene.offset_eps(sh.p)));
        // The Phong lobe is evaluated only in kernels that have it, and only where a hit has ks > 0.
        let any_spec = self.kernel.lobes.phong && sc.hits.iter().any(|sh| sh.ks.max_elem().simd_gt(F8::ZERO).any());
        for (li, light) in scene.lights.iter().enumerate() {
            let dim = DIM_LIGHT_BASE + li as u32;
            let (la, lab, lac, ln) =
                (Vec3x8::splat(light.a), Vec3x8::splat(light.ab), Vec3x8::splat(light.ac), Vec3x8::splat(light.normal));
            sc.acc.clear();
            sc.acc.resize(pks.len(), Vec3x8::ZERO);
            sc.streams.clear();
            sc.streams.extend(pks.iter().map(|pk| self.light_set.stream_x8(pk.pixel, sample_idx, dim, self.seed)));
            for k in 0..n_light {
                sc.shadow.clear();
                sc.contrib.clear();
                sc.owner.clear();
                for i in 0..pks.len() {
                    let (sh, shade) = (&sc.hits[i], sc.shade[i]);
                    if shade.none() {
                        continue;
                    }
                    // Sample a point on the light (uniform in area, pdf_area = 1/A).
                    let (u, v) = sc.streams[i].point(k);
                    let y = lac.mul_add(v, lab.mul_add(u, la));
                    let to = y - sh.p;
                    let d2 = to.length_squared();
                    let inv_d = F8::ONE / d2.sqrt();
                    let wi = to.scale(inv_d);
                    let cos_i = sh.n.dot(wi);
                    let cos_l = -ln.dot(wi);
                    let lit = shade & cos_i.simd_gt(F8::ZERO) & cos_l.simd_gt(F8::ZERO);
                    if lit.none() {
                        continue;
                    }
                    // Shade before visibility: f cos_i cos_l / d^2, kept if the shadow ray is clear.
                    let f = brdf_eval(sh, wi, lit, any_spec);
                    sc.contrib.push(f.scale(cos_i * cos_l * inv_d * inv_d));
                    // Shadow packet from the offset point towards the light sample, stopping short.
                    let o = sh.n.mul_add(sc.eps[i], sh.p);
                    let tfar = F8::ONE - scene.offset_eps(y) * inv_d;
                    let (ray, lit) = Ray8::new(o, y - o, F8::ZERO, tfar, lit);
                    sc.shadow.push((ray, lit));
                    sc.owner.push(i as u32);
                }
                trace_shadow_batch(scene, &mut sc.shadow, &sc.contrib, &sc.owner, &mut sc.acc, c, log.as_deref_mut());
            }
            let scale = Vec3x8::splat(light.radiance).scale(inv_n * F8::splat(light.area));
            for (o, acc) in out.iter_mut().zip(&sc.acc) {
                *o += acc.mul_elem(scale);
            }
        }
        if scene.emitters.n_triangles() > 0 {
            self.direct_triangles(scene, pks, s, out, sc, c, log, any_spec);
        }
    }

    /// `direct` for the emissive triangles, treated as one more light after the quad lights (sampler
    /// dimension `DIM_LIGHT_BASE + #quads`): each of the `lightsamples` samples picks a triangle by
    /// power and a point on it (one 2D sample does both, see `light::emitters`), and adds
    /// L f cos(th_i) cos(th_l) A / (d^2 pmf) over the number of samples where the shadow ray is clear.
    #[allow(clippy::too_many_arguments)]
    fn direct_triangles(
        &self,
        scene: &Scene,
        pks: &[PixelPacket],
        s: u32,
        out: &mut [Vec3x8],
        sc: &mut Scratch,
        c: &mut Counters,
        mut log: Option<&mut RayLog>,
        any_spec: bool,
    ) {
        let n_light = self.light_set.n();
        let inv_n = F8::splat(1.0 / n_light as f32);
        let dim = DIM_LIGHT_BASE + scene.lights.len() as u32;
        sc.streams.clear();
        sc.streams.extend(pks.iter().map(|pk| self.light_set.stream_x8(pk.pixel, U8::splat(s), dim, self.seed)));
        for k in 0..n_light {
            sc.shadow.clear();
            sc.contrib.clear();
            sc.owner.clear();
            for i in 0..pks.len() {
                let (sh, shade) = (&sc.hits[i], sc.shade[i]);
                if shade.none() {
                    continue;
                }
                let (u, v) = sc.streams[i].point(k);
                let ls = scene.emitters.sample_triangles_x8(u, v, shade);
                let to = ls.y - sh.p;
                let d2 = to.length_squared();
                let inv_d = F8::ONE / d2.sqrt();
                let wi = to.scale(inv_d);
                let cos_i = sh.n.dot(wi);
                let cos_l = -ls.normal.dot(wi);
                let lit = shade & cos_i.simd_gt(F8::ZERO) & cos_l.simd_gt(F8::ZERO) & d2.simd_gt(F8::ZERO);
                if lit.none() {
                    continue;
                }
                let f = brdf_eval(sh, wi, lit, any_spec);
                let w = cos_i * cos_l * inv_d * inv_d * ls.area * ls.inv_pmf * inv_n;
                sc.contrib.push(masked(f.mul_elem(ls.radiance).scale(w), lit));
                let o = sh.n.mul_add(sc.eps[i], sh.p);
                let tfar = F8::ONE - scene.offset_eps(ls.y) * inv_d;
                let (ray, lit) = Ray8::new(o, ls.y - o, F8::ZERO, tfar, lit);
                sc.shadow.push((ray, lit));
                sc.owner.push(i as u32);
            }
            trace_shadow_batch(scene, &mut sc.shadow, &sc.contrib, &sc.owner, out, c, log.as_deref_mut());
        }
    }
}

/// Per-thread buffers of the tile wavefront, reused across samples and tiles.
#[derive(Default)]
pub struct Scratch {
    rh: Vec<(RayHit8, Mask8)>,
    hits: Vec<SurfaceHit8>,
    shade: Vec<Mask8>,
    eps: Vec<F8>,
    acc: Vec<Vec3x8>,
    shadow: Vec<(Ray8, Mask8)>,
    contrib: Vec<Vec3x8>,
    owner: Vec<u32>,
    streams: Vec<Stream<U8>>,
    path: PathScratch,
    one: Vec<Vec3x8>,
}

/// `analyticdirect` without emission: kd/pi * sum over area lights of L * max(0, Phi . n) (no
/// visibility; as for quads, the receiver must see the whole light in its upper hemisphere and on
/// its emitting side for this to be exact).
fn analytic_direct(scene: &Scene, sh: &SurfaceHit8) -> Vec3x8 {
    let mut l_out = Vec3x8::ZERO;
    let shade = sh.valid & F8::from_bits(sh.light.simd_eq(U8::splat(u32::MAX)).into());
    // Quad lights, then emissive triangles (same polygon formula; `Emitter::corners` winds both alike).
    for light in &scene.emitters.list {
        let phi = polygon_phi_x8(sh.p, &light.corners(), shade);
        let e = phi.dot(sh.n).max(F8::ZERO);
        l_out += sh.kd.mul_elem(Vec3x8::splat(light.radiance)).scale(e * F8::splat(1.0 / PI));
    }
    l_out
}

/// Modified Phong (the format's definition) in world space:
/// kd/pi + ks (s+2)/(2 pi) max(0, r . wi)^s with r the mirror of wo about n; zero on inactive lanes.
/// `any_spec = false` promises ks = 0 on every lane and skips the lobe.
#[inline]
/// Traces a batch of shadow packets back to back (logging them) and adds `contrib[j]` to
/// `acc[owner[j]]` on the lanes of packet j whose shadow ray reached the light.
fn trace_shadow_batch(
    scene: &Scene,
    shadow: &mut [(Ray8, Mask8)],
    contrib: &[Vec3x8],
    owner: &[u32],
    acc: &mut [Vec3x8],
    c: &mut Counters,
    log: Option<&mut RayLog>,
) {
    if let Some(l) = log {
        l.shadow.extend_from_slice(shadow);
    }
    for (j, (ray, lit)) in shadow.iter_mut().enumerate() {
        let occluded = scene.accel.occluded8(ray, *lit);
        c.packet(RayKind::Shadow, *lit);
        acc[owner[j] as usize] += masked(contrib[j], *lit & !occluded);
    }
}

fn brdf_eval(sh: &SurfaceHit8, wi: Vec3x8, active: Mask8, any_spec: bool) -> Vec3x8 {
    let mut f = sh.kd.scale(F8::splat(1.0 / PI));
    if any_spec {
        let r = sh.n.scale(F8::splat(2.0) * sh.n.dot(sh.wo)) - sh.wo;
        let c = r.dot(wi);
        let has_spec = c.simd_gt(F8::ZERO);
        // c^s from 1 - c = sin^2 / (1 + c) with sin^2 = |r x wi|^2 (as the bsdf module does), so
        // a lobe of s = 1e6 keeps its shape near the mirror direction instead of moving by ~6% per
        // ulp of c.
        let pow = crate::sampling::cos_pow_x8(c, r.cross(wi).length_squared(), sh.shininess);
        let spec = pow * (sh.shininess + F8::splat(2.0)) * F8::splat(0.5 / PI);
        f += sh.ks.scale(has_spec.select(spec, F8::ZERO));
    }
    masked(f, active)
}

#[inline]
fn masked(v: Vec3x8, m: Mask8) -> Vec3x8 {
    Vec3x8::new(m.select(v.x, F8::ZERO), m.select(v.y, F8::ZERO), m.select(v.z, F8::ZERO))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{BrdfKind, Material};
    use crate::simd::mask_all;
    use glam::Vec3;

    /// `direct`'s world-space Phong evaluation equals the bsdf module's local-frame one, also for
    /// exponents up to 1e6 within a few thousandths of a degree of the mirror direction (where a
    /// plain exp(s ln c) from an f32 cosine is off by several percent).
    #[test]
    fn direct_phong_matches_the_bsdf_module_at_huge_exponents() {
        let n = Vec3::new(0.2, 0.9, -0.1).normalize();
        let wo = Vec3::new(-0.5, 0.6, 0.3).normalize();
        let r = 2.0 * n.dot(wo) * n - wo;
        let frame = glam::Mat3::from_cols(n.any_orthonormal_pair().0, n.any_orthonormal_pair().1, n);
        let to_local = |v: Vec3| frame.transpose() * v;
        for s in [0.0f32, 1.0, 1e3, 1e4, 1e6] {
            for k in 0..16 {
                // Directions at 0 .. ~3e-3 rad from the mirror direction.
                let t = k as f32 * 2e-4;
                let wi = (r + t * r.any_orthonormal_vector()).normalize();
                let m = Material {
                    kd: Vec3::splat(0.1),
                    ks: Vec3::splat(0.5),
                    shininess: s,
                    alpha: 1.0,
                    kind: BrdfKind::Phong,
                };
                let want = m.eval(to_local(wo), to_local(wi)).x;
                let sh = SurfaceHit8 {
                    valid: mask_all(),
                    p: Vec3x8::ZERO,
                    n: Vec3x8::splat(n),
                    wo: Vec3x8::splat(wo),
                    kd: Vec3x8::splat(m.kd),
                    ks: Vec3x8::splat(m.ks),
                    shininess: F8::splat(s),
                    roughness: F8::ONE,
                    ggx: Mask8::splat(0.0),
                    emitted: Vec3x8::ZERO,
                    ambient: Vec3x8::ZERO,
                    le: Vec3x8::ZERO,
                    light: U8::splat(0),
                };
                let got = brdf_eval(&sh, Vec3x8::splat(wi), mask_all(), true).x.to_array()[0];
                assert!((got - want).abs() <= 2e-3 * want.abs() + 1e-6, "s={s} t={t}: direct {got} bsdf {want}");
            }
        }
    }
}

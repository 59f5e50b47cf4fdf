//! Integrators: radiance of the 4x2 packets of camera samples of a tile. They reach Embree only
//! through the tile context's [`Tracer`] (one place that traces, counts and logs) and shade through
//! `bsdf::Material8`.
//!
//! One file per integrator: [`whitted`] (`raytracer`), [`analytic`] (`analyticdirect`), [`direct`]
//! (`direct`) and [`path`] (`pathtracer`). The three direct-lighting integrators share the camera-hit
//! wavefront of [`Integrator::radiance_tile`]; the path tracer runs its own wavefront. Kernels are
//! monomorphized over a `bsdf::LobeSet` (see [`kernel`]).
//!
//! Directions: `wo` points to the viewer, `wi` to the light; pdfs per unit solid angle unless named
//! `_area`. Dimensions given to the sampler: [`DIM_CAMERA`] for the pixel jitter, then
//! [`DIM_LIGHT_BASE`] + light index for the light samples of `direct`.

use crate::accel::{Hits8, RayHit8};
pub use crate::camera::FirstSample;
use crate::camera::{Camera, PixelPacket};
pub use crate::light::select::{LightSampler, LightSelection};
use crate::sampler::{GridTable, PointSet, SamplerKind};
use crate::scene::build::{Scene, SurfaceHit8};
use crate::scene::desc::{ImportanceSampling, IntegratorKind, Nee};
use crate::simd::{Vec3x8, F8};
use context::masked;
use kernel::Kernel;

pub mod analytic;
pub mod context;
pub mod direct;
pub mod kernel;
pub mod path;
pub mod stats;
pub mod whitted;

pub use crate::camera::DIM_CAMERA;
pub use context::{Scratch, TileCtx, Tracer};
pub use path::{PathScratch, DIM_PATH_BASE};
pub use stats::{Counters, RayKind, RayLog};

/// First sampler dimension of light sampling; light `l` uses `DIM_LIGHT_BASE + l`.
pub const DIM_LIGHT_BASE: u32 = 16;

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
    /// path tracer: how NEE chooses lights (`new` gives [`LightSelection::Uniform`], the path
    /// tracer's historical choice; see [`Integrator::set_light_selection`])
    pub light_selection: LightSelection,
    /// the light sampler of `light_selection` over the scene's emitters (shared by the threads)
    pub light_sampler: std::sync::Arc<LightSampler>,
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
            light_sampler.unwrap_or(if d.light_stratify { SamplerKind::STRATIFIED } else { SamplerKind::INDEPENDENT });
        Self {
            kind: d.integrator,
            spp: spp.max(1),
            seed,
            pixel_set: PointSet::for_image(pixel_sampler.unwrap_or(SamplerKind::STRATIFIED), spp.max(1), d.width),
            light_set: PointSet::for_image(light_kind, n_light, d.width),
            path_set: GridTable::new(PointSet::new(SamplerKind::STRATIFIED, spp.max(1))),
            nee: d.nee,
            russian_roulette: d.russian_roulette,
            strategy: d.importance_sampling,
            max_depth: d.max_depth,
            kernel: Kernel::for_scene(scene),
            clamp: None,
            first_sample: FirstSample::Jittered,
            light_selection: LightSelection::Uniform,
            light_sampler: std::sync::Arc::new(LightSampler::new(&scene.emitters.list, LightSelection::Uniform)),
        }
    }

    /// Switches NEE's light selection to `selection`, building its sampler over `scene`'s emitters.
    pub fn set_light_selection(&mut self, scene: &Scene, selection: LightSelection) {
        self.light_selection = selection;
        self.light_sampler = std::sync::Arc::new(LightSampler::new(&scene.emitters.list, selection));
    }

    /// The same integrator for `spp` samples per pixel: the per-pixel layouts (pixel jitter, path
    /// dimensions) are rebuilt for that count. `None` (an spp not known in advance, as in
    /// equal-time runs) makes them independent, since a stratified layout needs its count.
    pub fn resampled(&self, spp: Option<u32>) -> Self {
        let mut it = self.clone();
        match spp {
            Some(n) => {
                it.spp = n.max(1);
                it.pixel_set = self.pixel_set.with_n(it.spp);
                it.path_set = GridTable::new(PointSet::new(self.path_set.set().kind(), it.spp));
            }
            None => {
                it.spp = u32::MAX;
                it.pixel_set = PointSet::new(SamplerKind::INDEPENDENT, 1);
                it.path_set = GridTable::new(PointSet::new(SamplerKind::INDEPENDENT, 1));
            }
        }
        it
    }

    /// The camera of this integrator on `scene` (its pixel sampler and seed).
    pub fn camera<'a>(&'a self, scene: &'a Scene) -> Camera<'a> {
        Camera { lens: &scene.camera, pixel_set: &self.pixel_set, seed: self.seed, first_sample: self.first_sample }
    }

    /// Camera rays of packet `pk` for pixel sample `s`: origins and unit directions.
    #[inline]
    pub fn camera_rays(&self, scene: &Scene, pk: &PixelPacket, s: u32) -> (Vec3x8, Vec3x8) {
        self.camera(scene).rays(pk, s)
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
        log: Option<&mut RayLog>,
    ) {
        let mut ctx =
            TileCtx { scene, camera: self.camera(scene), pks, tracer: Tracer::new(scene, c, log), scratch: sc };
        if self.kind == IntegratorKind::PathTracer {
            // The kernel compiled for the scene's lobes (see `kernel`).
            return kernel::with_lobe_set!(self.kernel.lobes, L => path::tile::<L>(self, &mut ctx, samples, out));
        }
        out.clear();
        // The camera's pixel-sample streams, hashed once for the batch (if a sample draws).
        ctx.scratch.cam_streams.clear();
        if samples.clone().any(|s| ctx.camera.draws(s)) {
            ctx.camera.streams(pks, &mut ctx.scratch.cam_streams);
        }
        let mut one = std::mem::take(&mut ctx.scratch.one);
        for s in samples {
            kernel::with_lobe_set!(self.kernel.lobes, L => self.camera_hits_and_shade::<L>(&mut ctx, s, &mut one));
            out.extend_from_slice(&one);
        }
        ctx.scratch.one = one;
    }

    /// Radiance of pixel sample `s` for each packet of the tile (direct lighting integrators): the
    /// tile is processed as a wavefront: all camera packets are traced, then gathered (emission
    /// counted), then shaded by the integrator.
    fn camera_hits_and_shade<L: crate::bsdf::LobeSet>(&self, ctx: &mut TileCtx, s: u32, out: &mut Vec<Vec3x8>) {
        let n = ctx.pks.len();
        out.clear();
        let sc = &mut *ctx.scratch;
        // Packets and records are written in place (the buffers keep their length across samples;
        // Embree resets a packet's hit ids itself).
        sc.rh.truncate(n);
        sc.rh.resize(n, (RayHit8::default(), ctx.pks[0].active));
        sc.hits.truncate(n);
        sc.hits.resize(n, SurfaceHit8::MISS);
        // Camera packets: coherent primary rays from 4x2 pixel blocks.
        for (i, (pk, (rh, active))) in ctx.pks.iter().zip(sc.rh.iter_mut()).enumerate() {
            let (org, dir) = match sc.cam_streams.get(i) {
                Some(stream) => ctx.camera.rays_in(pk, i as u32, stream, s),
                None => ctx.camera.rays(pk, s),
            };
            *active = rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), pk.active);
        }
        ctx.tracer.intersect_all(&mut sc.rh, RayKind::Camera);
        // Gather: hit records to SoA shading records; emission.
        for ((rh, traced), sh) in sc.rh.iter().zip(sc.hits.iter_mut()) {
            ctx.scene.gather_into(rh.ray.org(), rh.ray.dir(), &Hits8::from_rayhit(rh, *traced), sh);
            out.push(masked(sh.emitted + sh.le, sh.valid));
        }
        match self.kind {
            IntegratorKind::AnalyticDirect => {
                for (o, sh) in out.iter_mut().zip(&sc.hits) {
                    *o += analytic::radiance(ctx.scene, sh);
                }
            }
            IntegratorKind::RayTracer => {
                for (o, sh) in out.iter_mut().zip(&sc.hits) {
                    *o += whitted::radiance(ctx.scene, self.max_depth, sh, &mut ctx.tracer);
                }
            }
            _ => direct::shade::<L>(self, ctx, s, out),
        }
        debug_assert_eq!(out.len(), n);
    }
}

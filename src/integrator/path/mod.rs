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
//! -), 2: BSDF direction, 3: (Russian roulette, lobe choice)}`. Dims 0 and 1 come from the light
//! layout (`--light-sampler`), 2 and 3 from the path layout (`--sampler`), each over the pixel's
//! spp samples (grid layouts with strata shuffled per (pixel, dimension), so dimensions are
//! stratified independently of one another; sequences decorrelate their dims themselves). Dim 1
//! is drawn only under `--light-choice dimension` with several lights (reuse takes the choice
//! from dim 0's first coordinate); dim 3 only where roulette or the lobe pick needs it. A
//! dimension not drawn changes no other.

use super::context::TileCtx;
use super::estimator::Estimator;
use super::samples::{Dim, Source, CAMERA};
use super::settings::Integrator;
use super::stats::RayKind;
use crate::accel::{Hits8, Ray8, RayHit8};
use crate::bsdf::LobeSet;
use crate::light::sky::Sky;
use crate::sampler::PathDim;
use crate::scene::build::Scene;
use crate::scene::desc::{IntegratorKind, Nee};
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Mask8, Vec3x8, F8, U8};
use bounce::{course_lobe_pick, Bounce, Vertex, Z};
use columns::{
    BETA, D, O, PATH_COLS, PDF, PIXEL, PREV_N, PREV_P, SAMPLE, SHADOW_COLS, SLOT, S_C, S_D, S_O, S_SLOT, S_TFAR,
};
use wave::{add_lanes, bits, Columns};

mod bounce;
mod columns;
pub mod settings;
mod sky;
mod wave;

pub use sky::DIM_SKY_BASE;

/// First sampler dimension of the path tracer's vertices.
pub const DIM_PATH_BASE: u32 = 64;
/// Camera packets of one wave of the path wavefront (whole samples of a tile's packets; at least
/// one sample): 1024 paths, enough to keep bounce packets full, few enough for the wave's
/// buffers (about 2.5 KB a packet) to stay in L2.
const WAVE_PACKETS: usize = 128;
/// Hard cap on path vertices when `maxdepth -1` (Russian roulette normally ends paths far sooner).
pub const MAX_VERTICES_UNBOUNDED: u32 = 4096;
// The sky's dimensions follow every vertex's own.
const _: () = assert!(DIM_SKY_BASE == DIM_PATH_BASE + 4 * MAX_VERTICES_UNBOUNDED);

/// The light point of vertex v (2D; under `--light-choice reuse` its u also picks the light).
pub const LIGHT_POINT: Dim = Dim { name: "light point", first: DIM_PATH_BASE, stride: 4, source: Source::Light };
/// The light choice of vertex v (x), only under `--light-choice dimension` with several lights.
pub const LIGHT_CHOICE: Dim = Dim { name: "light choice", first: DIM_PATH_BASE + 1, stride: 4, source: Source::Light };
/// The BSDF direction of vertex v (2D).
pub const DIRECTION: Dim = Dim { name: "BSDF direction", first: DIM_PATH_BASE + 2, stride: 4, source: Source::Path };
/// (Russian roulette, lobe choice) of vertex v, drawn only where one of them is used.
pub const ROULETTE_LOBE: Dim =
    Dim { name: "roulette, lobe choice", first: DIM_PATH_BASE + 3, stride: 4, source: Source::Path };
/// The sky's next event at vertex v (2D direction), with a sky only.
pub const SKY: Dim = Dim { name: "sky direction", first: DIM_SKY_BASE, stride: 1, source: Source::Light };

/// The `pathtracer` integrator (see the module docs).
pub struct PathTracer;

impl Estimator for PathTracer {
    const KIND: IntegratorKind = IntegratorKind::PathTracer;
    const DIMS: &'static [Dim] = &[CAMERA, LIGHT_POINT, LIGHT_CHOICE, DIRECTION, ROULETTE_LOBE, SKY];
    type Scratch = PathScratch;

    /// All paths of all the samples form one wavefront, so packets stay full even when Russian
    /// roulette thins the paths out.
    #[inline(never)]
    fn tile<L: LobeSet>(
        it: &Integrator,
        ctx: &mut TileCtx,
        scratch: &mut PathScratch,
        samples: std::ops::Range<u32>,
        out: &mut Vec<Vec3x8>,
    ) {
        path_tile::<L>(it, ctx, scratch, samples, out)
    }
}

/// Per-thread buffers of the path wavefront: the live paths of a bounce and the next one's,
/// structure of arrays in packets of 8 (see [`wave`]), their Embree packets, the shadow rays.
#[derive(Default)]
pub struct PathScratch {
    paths: Columns<PATH_COLS>,
    next: Columns<PATH_COLS>,
    prev: Columns<6>,
    next_prev: Columns<6>,
    rh: Vec<(RayHit8, Mask8)>,
    sh: Option<Box<SurfaceHit8>>,
    radiance: Vec<Vec3x8>,
    shadow: Columns<SHADOW_COLS>,
    shadow_rays: Vec<(Ray8, Mask8)>,
}

/// Radiance of pixel samples `samples` of every packet of the tile by path tracing (see
/// [`Estimator::tile`]).
fn path_tile<L: LobeSet>(
    it: &Integrator,
    ctx: &mut TileCtx,
    scratch: &mut PathScratch,
    samples: std::ops::Range<u32>,
    out: &mut Vec<Vec3x8>,
) {
    let TileCtx { scene, samples: smp, pks, tracer } = ctx;
    let PathScratch { paths, next, prev, next_prev, rh, sh, radiance, shadow, shadow_rays } = scratch;
    let sh = &mut **sh.get_or_insert_with(|| Box::new(SurfaceHit8::MISS));
    let max_v = if it.max_depth < 0 { MAX_VERTICES_UNBOUNDED } else { it.max_depth as u32 + 1 };
    // The previous vertex is kept only for a point-dependent light choice's MIS weight.
    let keep_prev = it.path.nee == Nee::Mis && it.light_sampler.depends_on_point();
    let course_lobe_pick = course_lobe_pick(it, scene);
    radiance.clear();
    radiance.resize(pks.len() * samples.len(), Vec3x8::ZERO);
    // Waves of at most WAVE_PACKETS camera packets (whole samples of the tile's packets), one
    // after the other: a wave's buffers stay in the caches (and small enough for the allocator
    // to reuse freed memory rather than map fresh pages). Every lane's path is the same in any
    // wave (Embree traces bounce and shadow rays one by one; a pixel sample's radiance is summed
    // vertex after vertex whatever the wave), so waves change no bit.
    let per_wave = (WAVE_PACKETS / pks.len().max(1)).max(1) as u32;
    let mut first = samples.start;
    while first < samples.end {
        let wave = first..samples.end.min(first + per_wave);
        first = wave.end;
        // Camera paths: the tile's packets, kept as they are (coherent, 4x2 pixel blocks); lanes
        // outside the image travel as inactive placeholders in the first packets.
        let n = pks.len() * wave.len();
        paths.set_packets(n);
        prev.set_packets(if keep_prev { n } else { 0 });
        // The next bounce has at most n packets of paths: room for them now, not by doubling.
        next.reserve_packets(n);
        // Packet buffers only grow (a bounce uses a prefix): no default packets written per batch.
        if rh.len() < n {
            rh.resize(n, (RayHit8::default(), F8::ZERO));
        }
        let lane = U8::new([0, 1, 2, 3, 4, 5, 6, 7]);
        for (sj, s) in wave.clone().enumerate() {
            for (p, pk) in pks.iter().enumerate() {
                let ci = sj * pks.len() + p;
                let (org, dir) = smp.camera_rays(pk, s);
                let (r, active) = &mut rh[ci];
                *active = r.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), pk.active);
                // The pixel sample's place in the tile's radiance (sample-major over `samples`).
                let slot = U8::splat(((s - samples.start) as usize * pks.len() + p) as u32 * 8) + lane;
                paths.set(SLOT, ci, pk.active.select(bits(slot), bits(U8::MAX)));
                paths.set(PIXEL, ci, bits(pk.pixel));
                paths.set(SAMPLE, ci, bits(U8::splat(s)));
                for c in 0..3 {
                    paths.set(BETA + c, ci, F8::ONE);
                }
                paths.set(PDF, ci, F8::ZERO);
                if keep_prev {
                    for c in 0..6 {
                        prev.set(c, ci, if c == PREV_N + 2 { F8::ONE } else { F8::ZERO });
                    }
                }
            }
        }
        let mut v = 1u32;
        while paths.len() > 0 && v <= max_v {
            let n_packets = paths.packets();
            let rh = &mut rh[..n_packets];
            if v > 1 {
                // Full packets of 8 live paths, written in place (Embree resets a packet's hit
                // ids itself).
                for (ci, (r, active)) in rh.iter_mut().enumerate() {
                    let live = F8::from_bits(!paths.get_u(SLOT, ci).simd_eq(U8::MAX));
                    let (o, d) = (paths.get3(O, ci), paths.get3(D, ci));
                    *active = r.ray.set(o, d, F8::ZERO, F8::splat(f32::INFINITY), live);
                }
            }
            tracer.intersect_all(rh, if v == 1 { RayKind::Camera } else { RayKind::Bounce });
            next.clear();
            next_prev.clear();
            shadow.clear();
            let dims = LIGHT_POINT.at(v - 1);
            // Dims 0 and 1 (light point, light choice) are light dimensions, 2 and 3 the others.
            let dk: [PathDim; 4] = std::array::from_fn(|j| smp.table_dim(j < 2, it.spp, dims + j as u32));
            let has_env = scene.sky.is_some() || scene.envmap.is_some();
            let dsky = has_env.then(|| smp.table_dim(true, it.spp, SKY.at(v - 1)));
            let mut b = Bounce {
                it,
                smp,
                scene,
                v,
                max_v,
                dk: &dk,
                dsky,
                keep_prev,
                course_lobe_pick,
                next,
                next_prev,
                shadow,
            };
            for (ci, (r, traced)) in rh.iter().enumerate() {
                // A packet without a traced lane hits nothing: no emission, no continuation.
                if traced.none() {
                    continue;
                }
                scene.gather_into(r.ray.org(), r.ray.dir(), &Hits8::from_rayhit(r, *traced), sh);
                // Under `hide_emitters` camera rays (v = 1) see no emitter.
                let missed = if v == 1 && scene.desc.hide_emitters { Mask8::default() } else { *traced & !sh.valid };
                if has_env && missed.any() {
                    let (slot, beta) = (paths.get_u(SLOT, ci), paths.get3(BETA, ci));
                    escaped::<L>(it, scene, v, r.ray.dir(), paths.get(PDF, ci), missed, |le| {
                        add_lanes(radiance, slot, beta.mul_elem(le), missed)
                    });
                }
                if sh.valid.none() {
                    continue;
                }
                let vx = Vertex {
                    sh,
                    rh: r,
                    slot: paths.get_u(SLOT, ci),
                    pixel: paths.get_u(PIXEL, ci),
                    s: paths.get_u(SAMPLE, ci),
                    beta: paths.get3(BETA, ci),
                };
                let (pp, pn) = if keep_prev { (prev.get3(PREV_P, ci), prev.get3(PREV_N, ci)) } else { (Z, Z) };
                if v > 1 || !scene.desc.hide_emitters {
                    let le = b.emission::<L>(&vx, paths.get(PDF, ci), pp, pn);
                    add_lanes(radiance, vx.slot, vx.beta.mul_elem(le), vx.sh.valid);
                }
                b.shade::<L>(&vx);
            }
            // Shadow packets of this bounce: full packets of 8 lanes, traced back to back.
            shadow.fill_tail(S_SLOT, bits(U8::MAX));
            let n_shadow = shadow.packets();
            if shadow_rays.len() < n_shadow {
                shadow_rays.resize(n_shadow, (Ray8::default(), F8::ZERO));
            }
            let shadow_rays = &mut shadow_rays[..n_shadow];
            for (j, (ray, lit)) in shadow_rays.iter_mut().enumerate() {
                let active = F8::from_bits(!shadow.get_u(S_SLOT, j).simd_eq(U8::MAX));
                let (o, d) = (shadow.get3(S_O, j), shadow.get3(S_D, j));
                *lit = ray.set(o, d, F8::ZERO, shadow.get(S_TFAR, j), active);
            }
            let occluded_batch = crate::profile::scope(crate::profile::Phase::EmbreeOccluded);
            for (j, (ray, lit)) in shadow_rays.iter_mut().enumerate() {
                let occluded = tracer.occluded(ray, *lit);
                add_lanes(radiance, shadow.get_u(S_SLOT, j), shadow.get3(S_C, j), *lit & !occluded);
            }
            drop(occluded_batch);
            next.fill_tail(SLOT, bits(U8::MAX));
            std::mem::swap(paths, next);
            std::mem::swap(prev, next_prev);
            v += 1;
        }
    }
    // Opt-in clamp (biased): scale a sample so its largest channel is at most `clamp`;
    // non-finite samples are left as they are, for the film to count and drop.
    if let Some(m) = it.path.clamp {
        for r in radiance.iter_mut() {
            let mut l = r.to_lanes();
            for c in l.iter_mut() {
                let top = c.max_element();
                if top > m {
                    *c *= m / top;
                }
            }
            *r = Vec3x8::from_lanes(l);
        }
    }
    std::mem::swap(out, radiance);
}

/// The environment's radiance (sky, then envmap), weighted by the next-event mode
/// ([`sky::escaped`]), that the rays `missed` of vertex `v` leaving along `dir` (sampled with
/// `pdf`) bring, each handed to `add` (kept out of line: scenes without an environment never run
/// it).
#[inline(never)]
fn escaped<L: LobeSet>(
    it: &Integrator,
    scene: &Scene,
    v: u32,
    dir: Vec3x8,
    pdf: F8,
    missed: Mask8,
    mut add: impl FnMut(Vec3x8),
) {
    if let Some(sky) = scene.sky.as_ref() {
        let (le, p_sky) = (Vec3x8::splat(sky.radiance), F8::splat(Sky::PDF));
        add(sky::escaped::<L>(it, v, le, p_sky, pdf, missed));
    }
    if let Some(env) = scene.envmap.as_ref() {
        let (le, p_env) = env.radiance_pdf_x8(dir, missed);
        add(sky::escaped::<L>(it, v, le, p_env, pdf, missed));
    }
}

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

use super::context::{masked, shading_frame, TileCtx};
use super::estimator::Estimator;
use super::light_term::{
    area_sample, env_sample, light_pdf_at_hit_pmf, point_shadow, towards, AreaChoice, EnvSample, PointTerm, Shading,
    SkySampling,
};
use super::samples::{Dim, Samples, Source, CAMERA};
use super::settings::Integrator;
use super::stats::RayKind;
use crate::accel::{Hits8, Ray8, RayHit8};
use crate::bsdf::interface::flags as lobe_flags;
use crate::bsdf::{BsdfSet, LobeSet};
use crate::light::emitters::LightSample8;
use crate::light::select::LightChoice;
use crate::light::sky::Sky;
use crate::profile::Phase;
use crate::sampler::PathDim;
use crate::sampling::power_heuristic_x8;
use crate::scene::build::Scene;
use crate::scene::desc::IntegratorKind;
use crate::scene::desc::{BrdfKind, ImportanceSampling, Nee};
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Mask8, Vec3x8, F8, U8};
use wave::{add_lanes, bits, Columns, Pack};

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

// Columns of a live path (`Columns<PATH_COLS>`): the index of (tile packet, lane) whose pixel
// sample it is, `packet * 8 + lane` (u32::MAX: a placeholder lane, traced inactive); the linear
// pixel index and the pixel sample index (sampler inputs); the next ray's origin and unit
// direction; the throughput; the solid-angle pdf with which the direction was sampled (for the
// MIS weight of emission found along it).
const SLOT: usize = 0;
const PIXEL: usize = 1;
const SAMPLE: usize = 2;
const O: usize = 3;
const D: usize = 6;
const BETA: usize = 9;
const PDF: usize = 12;
const PATH_COLS: usize = 13;
// Columns of the previous vertex's shading point and normal as NEE used them (for a
// point-dependent light selection's pmf in the MIS weight of emission found along the path),
// kept only when that selection needs them.
const PREV_P: usize = 0;
const PREV_N: usize = 3;
// Columns of a shadow ray: pixel sample slot, origin, unnormalized direction to the light
// sample, interval end, and the contribution added to the slot if it is unoccluded.
const S_SLOT: usize = 0;
const S_O: usize = 1;
const S_D: usize = 4;
const S_TFAR: usize = 7;
const S_C: usize = 8;
const SHADOW_COLS: usize = 11;

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

/// Vertex of the path packet being shaded: where it is and what it carries.
struct Vertex<'a> {
    sh: &'a SurfaceHit8,
    rh: &'a RayHit8,
    slot: U8,
    pixel: U8,
    s: U8,
    beta: Vec3x8,
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

/// Whether the course's BRDF mixture of some material can pick its specular lobe: under
/// `importancesampling brdf`, with a material whose specular probability (`Material8::
/// specular_probability`) is not exactly 0 (GGX, or a non-zero `specular`). Otherwise every lane's
/// pick `u_lobe < t` is false whatever `u_lobe`, and the dimension is not drawn (skipping it
/// changes no other, so no bit of the image).
fn course_lobe_pick(it: &Integrator, scene: &Scene) -> bool {
    it.path.strategy == ImportanceSampling::Brdf
        && scene.materials.iter().any(|m| m.brdf == BrdfKind::Ggx || m.specular != glam::Vec3::ZERO)
}

/// +z in every lane.
const Z: Vec3x8 = Vec3x8 { x: F8::ZERO, y: F8::ZERO, z: F8::ONE };

/// One bounce of the wavefront: what shading a packet reads and where it writes (the next
/// bounce's paths, this bounce's shadow rays).
struct Bounce<'a> {
    it: &'a Integrator,
    smp: &'a Samples<'a>,
    scene: &'a Scene,
    v: u32,
    max_v: u32,
    dk: &'a [PathDim; 4],
    /// the sky's dimension of this vertex (with a sky)
    dsky: Option<PathDim>,
    keep_prev: bool,
    /// whether the course's BRDF mixture can pick its specular lobe ([`course_lobe_pick`])
    course_lobe_pick: bool,
    next: &'a mut Columns<PATH_COLS>,
    next_prev: &'a mut Columns<6>,
    shadow: &'a mut Columns<SHADOW_COLS>,
}

impl Bounce<'_> {
    /// Emission found at the vertex: materials always; area lights (quads, emissive triangles)
    /// by the NEE mode, weighted with MIS against the light-sampling pdf (`pdf` is the pdf the
    /// direction was sampled with, negative after a delta lobe: weight 1; `pp`, `pn` the previous
    /// vertex for a point-dependent choice).
    #[inline]
    fn emission<L: LobeSet>(&self, vx: &Vertex, pdf: F8, pp: Vec3x8, pn: Vec3x8) -> Vec3x8 {
        let (it, sh, v) = (self.it, vx.sh, self.v);
        let hit = sh.valid;
        let mut le = masked(sh.emitted, hit);
        let is_light = hit & F8::from_bits(!sh.light.simd_eq(U8::splat(u32::MAX)));
        // No light hit: the area-light term is zero (sh.le and the weight are zero off lights).
        if is_light.none() {
            return le;
        }
        let light_w = match it.path.nee {
            Nee::Off => F8::ONE,
            Nee::On => F8::splat(if v == 1 { 1.0 } else { 0.0 }),
            Nee::Mis if v == 1 => F8::ONE,
            Nee::Mis => {
                let _p = crate::profile::leaf(crate::profile::Phase::Mis);
                let pmf = if it.light_selection.picks_one() {
                    it.light_sampler.pmf_x8(pp, pn, sh.light, is_light)
                } else {
                    // N points on every light: multi-sample MIS against N p_light.
                    F8::splat(it.light_set.n().max(1) as f32)
                };
                let p_light = light_pdf_at_hit_pmf(it, self.scene, sh, vx.rh, is_light, pmf);
                power_heuristic_x8(pdf, p_light, is_light)
            }
        };
        // A direction from a delta lobe: no light sample could have found the light.
        let light_w = if <L::Bsdfs as BsdfSet>::FLAGS & lobe_flags::DELTA != 0 {
            pdf.simd_lt(F8::ZERO).select(F8::ONE, light_w)
        } else {
            light_w
        };
        le += masked(sh.le, hit).scale(light_w);
        le
    }

    /// NEE and the continuation at the vertex's shaded lanes (hits off the lights): shadow rays
    /// into `shadow`, surviving paths into `next`.
    #[inline]
    fn shade<L: LobeSet>(&mut self, vx: &Vertex) {
        let (it, scene, sh, v, max_v) = (self.it, self.scene, vx.sh, self.v, self.max_v);
        let (nee, n_lights) = (it.path.nee, scene.emitters.len() as u32);
        let is_light = F8::from_bits(!sh.light.simd_eq(U8::splat(u32::MAX)));
        // Shading frame: the normal faces wo, so wo.z > 0 in local coordinates.
        let shade = sh.valid & !is_light;
        let nee_here = nee != Nee::Off && scene.has_nee_lights() && v < max_v;
        // Delta lights are reached by next events only, whatever the NEE mode.
        let delta_here = !scene.delta.is_empty() && v < max_v;
        let bounce_here = match nee {
            Nee::On => v + 1 < max_v,
            _ => v < max_v,
        };
        if shade.none() || (!nee_here && !bounce_here && !delta_here) {
            return;
        }
        let (pixel, s, beta) = (vx.pixel, vx.s, vx.beta);
        let (frame, mat) = (shading_frame::<L>(scene, sh), &sh.mat);
        // Registry BSDFs that transmit: directions may cross the surface (compile-time).
        let transmits = <L::Bsdfs as BsdfSet>::FLAGS & lobe_flags::TRANSMISSION != 0;
        // The environment's and the delta lights' next events light transmitting lanes from
        // below too (the area lights' below; see `push`).
        let below = if transmits { transmitting_lanes::<L>(mat, shade) } else { F8::ZERO };
        let at = Shading::new(sh, &frame, it.path.strategy).with_below(below);
        let (frame, wo) = (at.frame, at.wo);
        let eps = scene.offset_eps(sh.p);
        // Offsets along the geometric normal (the shading one may point into the surface).
        let o = sh.ng.mul_add(eps, sh.p);
        // Smooth-shaded lanes: directions must also leave the geometric surface (on the side of
        // the shading normal they leave: transmitted ones below both).
        let leaves = |wi: Vec3x8| at.leaves(wi);
        let leaves_either = |wi: Vec3x8| {
            let (a, b) = (sh.ng.dot(wi), sh.n.dot(wi));
            !sh.smooth | (a.simd_gt(F8::ZERO) & b.simd_gt(F8::ZERO)) | (a.simd_lt(F8::ZERO) & b.simd_lt(F8::ZERO))
        };
        // The origin below the surface, for directions that cross it.
        let o_below = sh.ng.mul_add(-eps, sh.p);
        let general = if <L::Bsdfs as BsdfSet>::BITS != 0 { mat.general(shade) } else { F8::ZERO };
        // A light choice of its own: drawn only under `--light-choice dimension` with several
        // lights to pick from (skipping a dimension changes no other).
        let picks = it.light_selection.picks_one() && n_lights > 1;
        let own_choice = picks && it.light_choice == LightChoice::Dimension;

        // Shadow rays of directions below the geometric surface start below it.
        let from = (o, if transmits && below.any() { Some(o_below) } else { None });
        if nee_here {
            self.env_next_event::<L>(vx, &at, from, shade);
        }
        if delta_here {
            self.delta_next_events::<L>(vx, &at, from, shade);
        }
        let nee_lights = nee_here && n_lights > 0;
        // The light point and the bounce's direction, drawn by one call where both are used (the
        // layout may run the two points' chains side by side; the same bits either way).
        let (light_uw, bounce_u2) = if nee_lights && bounce_here {
            let [a, b] =
                self.smp.table_point_pair((&self.dk[0], true), (&self.dk[2], false), Phase::SamplerPath, pixel, s);
            (Some(a), Some(b))
        } else {
            (None, None)
        };
        if nee_lights {
            let u_choice = if own_choice {
                self.smp.table_point(&self.dk[1], true, Phase::SamplerPath, pixel, s).0
            } else {
                F8::ZERO
            };
            let (u, w) =
                light_uw.unwrap_or_else(|| self.smp.table_point(&self.dk[0], true, Phase::SamplerPath, pixel, s));
            let shadow = &mut *self.shadow;
            let mut push = |ls: &LightSample8, scale: Option<F8>, mis_n: Option<F8>, ok: Mask8| {
                let (y, l_rad, area, inv_pmf) = (ls.y, ls.radiance, ls.area, ls.inv_pmf);
                let PointTerm { wi, d2, inv_d, mut cos_i, cos_l, mut lit } = towards(sh, ls, ok);
                // Transmitting lanes: lights below the surface too.
                let below = if transmits && general.any() {
                    let below = ok & general & cos_i.simd_lt(F8::ZERO) & cos_l.simd_gt(F8::ZERO) & d2.simd_gt(F8::ZERO);
                    let below = below & leaves_either(wi);
                    lit |= below;
                    cos_i = cos_i.abs();
                    below
                } else {
                    F8::ZERO
                };
                if lit.none() {
                    return;
                }
                let (f, pdf_b) = at.eval::<L>(frame.to_local(wi), lit);
                // No shadow ray where a registry BSDF has no value (delta lobes only).
                let lit = if <L::Bsdfs as BsdfSet>::BITS != 0 {
                    lit & !(general & f.max_elem().simd_le(F8::ZERO))
                } else {
                    lit
                };
                if lit.none() {
                    return;
                }
                // L f cos_i / p_light with p_light = pmf d^2 / (A cos_l) (solid angle).
                let mut g = cos_i * cos_l * area * inv_pmf * inv_d * inv_d;
                if let Some(k) = scale {
                    g *= k;
                }
                // (The NEE side's weight is a few flops per lane: cheaper than a scope, so it
                // stays in `other`; the light-hit side is timed as `mis weights`.)
                let w_light = if nee == Nee::Mis {
                    let p_light = d2 / (area * cos_l * inv_pmf);
                    let p_light = if let Some(k) = mis_n { p_light * k } else { p_light };
                    power_heuristic_x8(p_light, pdf_b, lit)
                } else {
                    F8::ONE
                };
                let c = beta.mul_elem(f).mul_elem(l_rad).scale(g * w_light);
                let o = if transmits { Vec3x8::select(below, o_below, o) } else { o };
                let (d, tfar) = point_shadow(scene, o, y, inv_d);
                // The lit lanes, left-packed onto the bounce's shadow rays.
                let pack = Pack::of(lit);
                shadow.write(S_SLOT, &pack, &[bits(vx.slot), o.x, o.y, o.z, d.x, d.y, d.z, tfar, c.x, c.y, c.z]);
                shadow.advance(&pack);
            };
            if it.light_sampler.certain() {
                // The one light (pmf 1), a point on it uniform in area.
                let mut ls = LightSample8::ZERO;
                let ok = area_sample(it, scene, sh, shade, AreaChoice::Certain, (u, w), &mut ls);
                push(&ls, None, None, ok)
            } else if !it.light_selection.picks_one() {
                // Every light, N points each (a lattice rotated by (u, w)), each weighted 1/N
                // and, with MIS, against N p_light.
                {
                    let n_all = it.light_set.n().max(1);
                    let (scale, mis_n) = if n_all > 1 {
                        (Some(F8::splat(1.0 / n_all as f32)), Some(F8::splat(n_all as f32)))
                    } else {
                        (None, None)
                    };
                    for (e, row) in scene.emitters.list.iter().zip(&scene.emitters.warp_rows) {
                        for j in 0..n_all {
                            let (uj, wj) = lattice_point(u, w, j, n_all);
                            // (The sample stays where it is made: a block returning it copied its
                            // 448 bytes out.) The warp reads the light's row from the table.
                            let p = crate::profile::leaf(crate::profile::Phase::Emitter);
                            let mut ls = e.sample_x8(uj, wj);
                            row.warp_x8(it.light_warp, &mut ls, sh.p, shade);
                            drop(p);
                            push(&ls, scale, mis_n, shade);
                        }
                    }
                }
            } else {
                // One light from the light sampler (uniform 1/N over quads and triangles alike,
                // power or spatial), the choice reused from u or drawn on its own.
                let choice = if own_choice { AreaChoice::Drawn(u_choice) } else { AreaChoice::Reuse };
                let mut ls = LightSample8::ZERO;
                let ok = area_sample(it, scene, sh, shade, choice, (u, w), &mut ls);
                push(&ls, None, None, ok);
            }
        }

        // Continue the path: sample the BSDF, then Russian roulette.
        if bounce_here {
            // (Russian roulette, lobe choice): drawn only where one of them is used.
            // Registry BSDFs pick their lobe whatever the strategy.
            let lobe_pick = self.course_lobe_pick || <L::Bsdfs as BsdfSet>::BITS != 0;
            let (u_rr, u_lobe) = if it.path.russian_roulette || lobe_pick {
                self.smp.table_point(&self.dk[3], false, Phase::SamplerPath, pixel, s)
            } else {
                (F8::ZERO, F8::ZERO)
            };
            let u2 =
                bounce_u2.unwrap_or_else(|| self.smp.table_point(&self.dk[2], false, Phase::SamplerPath, pixel, s));
            let sampled = {
                let _p = crate::profile::leaf(crate::profile::Phase::BsdfSample);
                mat.sample_bsdf_k::<L>(it.path.strategy, wo, [u2.0, u2.1], u_lobe, shade)
            };
            let (wi_l, mut pdf, f) = (sampled.wi, sampled.pdf, sampled.f);
            let cos = wi_l.z;
            let wi = frame.to_world(wi_l);
            let mut ok =
                shade & pdf.simd_gt(F8::ZERO) & cos.simd_gt(F8::ZERO) & f.max_elem().simd_gt(F8::ZERO) & leaves(wi);
            let mut nb = beta.mul_elem(f).scale(ok.select(cos / pdf, F8::ZERO));
            let mut o = o;
            if <L::Bsdfs as BsdfSet>::BITS != 0 && sampled.general.any() {
                // Registry BSDF lanes: their weight f |cos| / pdf, either side of the surface.
                let (g, b) = (sampled.general, &sampled.bsdf);
                let g_ok = g & b.pdf.simd_gt(F8::ZERO) & b.weight.max_elem().simd_gt(F8::ZERO) & leaves_either(wi);
                ok = (ok & !g) | g_ok;
                nb = Vec3x8::select(g, beta.mul_elem(b.weight), nb);
                nb = Vec3x8::select(ok, nb, Vec3x8::ZERO);
                if transmits {
                    o = Vec3x8::select(g & sh.ng.dot(wi).simd_lt(F8::ZERO), o_below, o);
                }
                // A delta lobe's direction: the next hit's emission gets weight 1 (pdf < 0).
                pdf = (g & b.has(lobe_flags::DELTA)).select(F8::splat(-1.0), pdf);
            }
            let mut alive = ok & nb.max_elem().simd_gt(F8::ZERO) & nb.is_finite();
            if it.path.russian_roulette && v >= it.path.rr_depth {
                let q = nb.max_elem().min(F8::ONE);
                alive &= u_rr.simd_lt(q);
                nb = nb.scale(alive.select(F8::ONE / q, F8::ZERO));
            }
            if alive.any() {
                // The surviving lanes, left-packed onto the next bounce's paths.
                let pack = Pack::of(alive);
                let row = [bits(vx.slot), bits(pixel), bits(s), o.x, o.y, o.z, wi.x, wi.y, wi.z, nb.x, nb.y, nb.z, pdf];
                self.next.write(SLOT, &pack, &row);
                self.next.advance(&pack);
                if self.keep_prev {
                    let (p, n) = (sh.p, sh.n);
                    self.next_prev.write(PREV_P, &pack, &[p.x, p.y, p.z, n.x, n.y, n.z]);
                    self.next_prev.advance(&pack);
                }
            }
        }
    }
}

impl Bounce<'_> {
    /// The delta lights' next events at the shaded lanes `shade` of `vx`
    /// ([`Shading::delta_events`], from below too on `at.below` lanes), pushed as shadow rays
    /// from `from` (kept out of line: scenes without delta lights never run it).
    #[inline(never)]
    fn delta_next_events<L: LobeSet>(&mut self, vx: &Vertex, at: &Shading, from: From, shade: Mask8) {
        let shadow = &mut *self.shadow;
        at.delta_events::<L>(self.scene, vx.beta, shade, |lit, wi, tfar, c| {
            push_shadow(shadow, vx, origin(vx.sh, from, wi), wi, tfar, c, lit)
        });
    }

    /// The environment's next event at the shaded lanes `shade` of `vx` (the sky's own
    /// distribution or the envmap's, [`Shading::env_event`]), MIS-weighted against the BSDF and
    /// pushed as a shadow ray to infinity from `from`. The sky's samples cover the hemisphere
    /// above the shading normal; on `at.below` lanes (a transmitting BSDF) the same sample
    /// mirrored below is a second next event, of the same pdf `1 / (2 pi)` in its hemisphere, so
    /// an escaped ray's weight against `Sky::PDF` holds on either side. The envmap's cover the
    /// sphere.
    #[inline]
    fn env_next_event<L: LobeSet>(&mut self, vx: &Vertex, at: &Shading, from: From, shade: Mask8) {
        let Some(dim) = self.dsky.as_ref() else { return };
        let uw = self.smp.table_point(dim, true, Phase::SamplerPath, vx.pixel, vx.s);
        let Some(e) = env_sample(self.scene, SkySampling::Sky, at.frame, uw, shade) else { return };
        let mis = self.it.path.nee == Nee::Mis;
        let weight = |pdf_b: F8, lit: Mask8| match self.scene.sky {
            Some(_) => Sky::nee_weight_x8(mis, pdf_b, lit),
            None if mis => power_heuristic_x8(e.pdf, pdf_b, lit),
            None => F8::ONE,
        };
        if let Some((lit, wi, c)) = at.env_event::<L>(&e, vx.beta, shade, weight) {
            push_shadow(self.shadow, vx, origin(vx.sh, from, wi), wi, F8::splat(f32::INFINITY), c, lit);
        }
        let below = shade & at.below;
        if self.scene.sky.is_some() && below.any() {
            let wi_l = Vec3x8::new(e.wi_l.x, e.wi_l.y, -e.wi_l.z);
            let m = EnvSample { wi: at.frame.to_world(wi_l), wi_l, pdf: e.pdf, le: e.le };
            if let Some((lit, wi, c)) = at.env_event::<L>(&m, vx.beta, below, weight) {
                push_shadow(self.shadow, vx, origin(vx.sh, from, wi), wi, F8::splat(f32::INFINITY), c, lit);
            }
        }
    }
}

/// Where a next event's shadow rays start: above the surface, and (on kernels with transmitting
/// lanes) below it.
type From = (Vec3x8, Option<Vec3x8>);

/// The shadow-ray origins of the hits `sh` for directions `wi`: below the surface where `wi` goes
/// below the geometric normal and `from` has a point there, else above.
#[inline]
fn origin(sh: &SurfaceHit8, from: From, wi: Vec3x8) -> Vec3x8 {
    match from {
        (o, Some(o_below)) => Vec3x8::select(sh.ng.dot(wi).simd_lt(F8::ZERO), o_below, o),
        (o, None) => o,
    }
}

/// The `shade` lanes whose registry BSDF transmits and has a lobe a next event can find (diffuse
/// or glossy; per-lane kinds of the kernel's set `L::Bsdfs`): the smooth dielectrics' and the
/// null lobe's lanes would only trace shadow rays of value 0.
#[inline]
fn transmitting_lanes<L: LobeSet>(mat: &crate::bsdf::Material8, shade: Mask8) -> Mask8 {
    use lobe_flags::{DIFFUSE, GLOSSY, TRANSMISSION};
    let kinds = mat.bsdf.kind.to_array();
    let t = kinds.map(|k| {
        let f = <L::Bsdfs as BsdfSet>::flags_of(k);
        f & TRANSMISSION != 0 && f & (DIFFUSE | GLOSSY) != 0
    });
    shade & crate::simd::mask_from_bools(t)
}

/// A next event's shadow rays from `o` along `wi` up to `tfar`, adding `c` to the pixel samples
/// of `vx` if clear: the lit lanes, left-packed onto the bounce's shadow rays.
#[inline]
fn push_shadow(shadow: &mut Columns<SHADOW_COLS>, vx: &Vertex, o: Vec3x8, wi: Vec3x8, tfar: F8, c: Vec3x8, lit: Mask8) {
    let pack = Pack::of(lit);
    let row = [bits(vx.slot), o.x, o.y, o.z, wi.x, wi.y, wi.z, tfar, c.x, c.y, c.z];
    shadow.write(S_SLOT, &pack, &row);
    shadow.advance(&pack);
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

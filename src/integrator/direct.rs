//! `direct` (hw2, and Mitsuba 3's `direct`): direct lighting by light sampling with shadow rays
//! and, when `Integrator::direct` asks for them, BSDF samples (`direct_bsdf.rs`: every lobe,
//! delta and transmission included), the two weighted by the power heuristic of their pdfs times
//! their sample counts, as Mitsuba's `direct` ([`Mis`]). `.test` and OBJ scenes draw no BSDF
//! sample unless `--bsdf-samples` asks (their light-sampling code and bits are unchanged); XML
//! scenes take Mitsuba's `emitter_samples`/`bsdf_samples` (default one of each).
//!
//! The emitters are visited in one loop, one sampling group at a time: each quad light is its own
//! group (sampler dimension `DIM_LIGHT_BASE + index`, a point uniform in area), and the emissive
//! triangles form one more group after the quads (dimension `DIM_LIGHT_BASE + #quads`; each sample
//! picks a triangle by power, `Integrator::triangle_sampler`, and a point on it). Each group adds the mean
//! over the `lightsamples` samples of L f cos(th_i) cos(th_l) / (d^2 pdf_area) where the shadow ray
//! is clear. A quad group's radiance and area are constant, so they scale its sum once at the end.
//! f is the path tracer's material code (`bsdf::Material8::eval_pdf_k` in the local shading frame):
//! diffuse, Phong and GGX alike.
//!
//! That loop is `--light-selection all` (the default for `.test` scenes). With `uniform`, `power`
//! or `spatial` each of the `lightsamples` samples instead picks one light from the integrator's
//! [`crate::light::select::LightSampler`] (dimension `DIM_LIGHT_BASE + 1` for the choice) and a
//! point on it (dimension `DIM_LIGHT_BASE`), and adds L f cos(th_i) cos(th_l) / (d^2 pmf pdf_area)
//! / `lightsamples`: one shadow ray per sample whatever the number of lights, as Mitsuba's
//! `direct` does with one emitter sample. `uniform` is then truly 1/#lights (quads and triangles
//! alike).

use super::context::{masked, shading_frame, TileCtx, Tracer};
use super::estimator::Estimator;
use super::light_term::{area_sample, point_shadow, towards, AreaChoice, PointTerm, Shading};
use super::primary::{self, Wave};
use super::samples::{Dim, Samples, Source, CAMERA};
use super::settings::Integrator;
use crate::accel::Ray8;
use crate::bsdf::{BsdfSet, LobeSet};
use crate::camera::PixelPacket;
use crate::light::emitters::{Emitter, LightSample8};
use crate::light::select::LightChoice;
use crate::light::warp::LightWarp;
use crate::profile::Phase;
use crate::sampler::{PathDim, Stream};
use crate::sampling::power_heuristic_x8;
use crate::scene::build::Scene;
use crate::scene::desc::{ImportanceSampling, IntegratorKind};
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Mask8, Vec3x8, F8, U8};

#[path = "direct_bsdf.rs"]
mod bsdf_samples;
#[path = "direct_each.rs"]
mod each;
#[path = "direct_env.rs"]
mod env;

/// First sampler dimension of light sampling (see [`LIGHT_POINT`]).
pub const DIM_LIGHT_BASE: u32 = 16;

/// The light point (2D, uniform in area): under `all` one dimension per sampling group (the
/// quads, then the triangles); under a one-light selection the chosen light's, whose u also
/// picks the light under `--light-choice reuse`.
pub const LIGHT_POINT: Dim = Dim { name: "light point", first: DIM_LIGHT_BASE, stride: 1, source: Source::Light };
/// The light choice (x), only under `--light-choice dimension` with several lights.
pub const LIGHT_CHOICE: Dim = Dim { name: "light choice", first: DIM_LIGHT_BASE + 1, stride: 0, source: Source::Light };

/// The `direct` integrator: the camera-hit wavefront, shaded by light sampling.
pub struct Direct;

/// `direct`'s per-thread buffers: the camera-hit wavefront and the light-sampling batches.
#[derive(Default)]
pub struct DirectScratch {
    wave: Wave,
    buf: Buffers,
    bsdf: bsdf_samples::BsdfBuffers,
}

/// Per-thread buffers of `direct`'s light sampling, reused across samples and tiles.
#[derive(Default)]
struct Buffers {
    lanes: Lanes,
    acc: Vec<Vec3x8>,
    batch: Batch,
    streams: Vec<Stream<U8>>,
    /// one light per sample, `--light-choice dimension`: the light-choice streams
    choice_streams: Vec<Stream<U8>>,
    /// packet by packet ([`Each`]): the light points of the sample's packets, N per packet
    uv: Vec<(F8, F8)>,
    /// the light table's streams of the tile's packets (one light point dimension): packet by
    /// packet ([`Each`]) made once per batch of samples, under `all` once per sample and light
    table_streams: Vec<Stream<U8>>,
}

/// Per camera packet of the tile: the lanes to shade and the shadow-ray origin offsets.
#[derive(Default)]
pub(super) struct Lanes {
    shade: Vec<Mask8>,
    eps: Vec<F8>,
}

impl Estimator for Direct {
    const KIND: IntegratorKind = IntegratorKind::Direct;
    const DIMS: &'static [Dim] =
        &[CAMERA, LIGHT_POINT, LIGHT_CHOICE, env::ENVIRONMENT, bsdf_samples::BSDF_DIRECTION, bsdf_samples::BSDF_LOBE];
    type Scratch = DirectScratch;

    fn tile<L: LobeSet>(
        it: &Integrator,
        ctx: &mut TileCtx,
        sc: &mut DirectScratch,
        samples: std::ops::Range<u32>,
        out: &mut Vec<Vec3x8>,
    ) {
        let DirectScratch { wave, buf, bsdf } = sc;
        if each::each_packet(it, ctx.scene) {
            let mut each = each::Each::<L>::new(it, buf, samples.len());
            return primary::tile_each(ctx, wave, samples, out, &mut each);
        }
        primary::tile(ctx, wave, samples, out, |ctx, hits, s, out| shade::<L>(it, ctx, hits, buf, bsdf, s, out));
    }
}

/// One sampling group of `direct`.
#[derive(Clone, Copy)]
enum Group<'a> {
    /// one quad light
    Quad(&'a Emitter),
    /// all emissive triangles, chosen by power
    Triangles,
}

impl Group<'_> {
    /// A point on the group's light(s) for the unit-square sample `uv` at the hits `sh`, written
    /// into `ls` (in place: a returned 448-byte sample was copied out); returns the `active`
    /// lanes that got one.
    #[inline(always)]
    fn sample(
        self,
        it: &Integrator,
        scene: &Scene,
        sh: &SurfaceHit8,
        uv: (F8, F8),
        active: Mask8,
        ls: &mut LightSample8,
    ) -> Mask8 {
        match self {
            Group::Quad(e) => {
                let _p = crate::profile::leaf(crate::profile::Phase::Emitter);
                *ls = e.sample_x8(uv.0, uv.1);
                e.warp_x8(it.light_warp, ls, sh.p, active);
                active
            }
            // The triangle chosen by power from u, u remapped within its interval (`reuse`).
            Group::Triangles => {
                let _p = crate::profile::leaf(crate::profile::Phase::Emitter);
                let ok = it.triangle_sampler.sample_point_reuse_x8(&scene.emitters, sh.p, sh.n, active, uv, ls);
                scene.emitters.warp_x8(it.light_warp, ls, sh.p, ok);
                ok
            }
        }
    }
}

/// The groups of `scene` in sampler-dimension order: the quad lights, then the triangles if any.
fn groups(scene: &Scene) -> impl Iterator<Item = Group<'_>> {
    let quads = scene.emitters.list[..scene.emitters.n_quads].iter().map(Group::Quad);
    quads.chain((scene.emitters.n_triangles() > 0).then_some(Group::Triangles))
}

/// The strategy `direct` samples and weighs the course's materials with when it draws BSDF
/// samples (the course's BRDF sampling: cosine for diffuse, the Phong lobe for specular; registry
/// BSDFs sample their own lobes whatever it is). Light sampling alone evaluates under cosine.
pub(super) const MIS_STRATEGY: ImportanceSampling = ImportanceSampling::Brdf;

/// Mitsuba's `direct` weights: the power heuristic of the two strategies' pdfs, each times its
/// sample count (`n_e` light samples, `n_b` BSDF samples per shading point).
#[derive(Clone, Copy)]
pub(super) struct Mis {
    n_e: F8,
    n_b: F8,
    inv_b: F8,
}

impl Mis {
    /// The weights of `n_e` light samples (0: no emitter sampling) and `n_b` BSDF samples.
    pub(super) fn new(n_e: u32, n_b: u32) -> Self {
        Self { n_e: F8::splat(n_e as f32), n_b: F8::splat(n_b as f32), inv_b: F8::splat(1.0 / n_b.max(1) as f32) }
    }

    /// A light sample's weight (the 1 / N of its average apart): its pdf `p_e` against the BSDF's
    /// `p_b` for the same direction.
    #[inline]
    pub(super) fn light(&self, p_e: F8, p_b: F8, active: Mask8) -> F8 {
        power_heuristic_x8(p_e * self.n_e, p_b * self.n_b, active)
    }

    /// A BSDF sample's weight, its 1 / n_b included: `p_b` against light sampling's `p_e`.
    #[inline]
    pub(super) fn bsdf(&self, p_b: F8, p_e: F8, active: Mask8) -> F8 {
        power_heuristic_x8(p_b * self.n_b, p_e * self.n_e, active) * self.inv_b
    }
}

/// Adds direct lighting at the camera hits `hits` of the tile for pixel sample `s` to `out`: the
/// light samples (unless the scene turned emitter sampling off), then the BSDF samples (if any),
/// weighted against each other when both are drawn.
fn shade<L: LobeSet>(
    it: &Integrator,
    ctx: &mut TileCtx,
    hits: &[SurfaceHit8],
    sc: &mut Buffers,
    bsdf: &mut bsdf_samples::BsdfBuffers,
    s: u32,
    out: &mut [Vec3x8],
) {
    shading_lanes(ctx.scene, hits, &mut sc.lanes);
    let d = it.direct;
    let mis = d.mis().then(|| Mis::new(it.light_set.n(), d.bsdf_samples));
    if d.emitter_sampling {
        // No area light (only lights outside the selection): nothing to choose from.
        if !ctx.scene.emitters.is_empty() {
            if it.light_selection.picks_one() {
                shade_one::<L>(it, ctx, hits, sc, s, out, mis);
            } else {
                shade_all::<L>(it, ctx, hits, sc, s, out, mis);
            }
        }
        if ctx.scene.sky.is_some() || ctx.scene.envmap.is_some() || !ctx.scene.delta.is_empty() {
            env::shade_outside::<L>(it, ctx, hits, &sc.lanes, s, out, mis);
        }
    }
    if d.bsdf_samples > 0 {
        bsdf_samples::shade::<L>(it, ctx, hits, &sc.lanes, bsdf, s, out);
    }
}

/// The fewest light samples per pixel sample for which `direct` under `all` draws a light's
/// points from per-packet streams of the light table (a stream costs a few points' hashing):
/// hw2 `sphere.test` (25 light samples, 4 spp, 1 thread) 1.532 -> 1.445 CPU s with the default
/// `multijitter`, 0.948 -> 0.921 with `sobol`; hw4 dragon (`pmj02`) 2.743 -> 2.674 (stop 42).
const TABLE_STREAM_POINTS: u32 = 4;

/// `direct` under `all`: every area light, group by group (see the module docs).
fn shade_all<L: LobeSet>(
    it: &Integrator,
    ctx: &mut TileCtx,
    hits: &[SurfaceHit8],
    sc: &mut Buffers,
    s: u32,
    out: &mut [Vec3x8],
    mis: Option<Mis>,
) {
    let TileCtx { scene, pks, tracer, samples: smp } = ctx;
    let n_light = it.light_set.n();
    let inv_n = F8::splat(1.0 / n_light as f32);
    let streams = it.light_streams();
    // Solid-angle points carry their own 1 / pdf_area per sample (`ls.area`); area ones share
    // the quad's area, applied once per group.
    let warped = it.light_warp == LightWarp::SolidAngle;
    let Buffers { lanes, batch, acc, streams: st, table_streams, .. } = sc;
    for (gi, group) in groups(scene).enumerate() {
        let dim = LIGHT_POINT.at(gi as u32);
        let table = LightTable::new(it, smp, dim, s);
        acc.clear();
        acc.resize(pks.len(), Vec3x8::ZERO);
        st.clear();
        if streams {
            smp.light_streams(pks, &lanes.shade, s, dim, true, st);
        }
        // Other layouts: the light table's points from per-packet streams when the sample draws
        // enough of them to repay a stream's hashing.
        let tabled = !streams && n_light >= TABLE_STREAM_POINTS && table.streams(smp, pks, table_streams);
        for k in 0..n_light {
            let point_k = it.light_set.point_k(k);
            // Point k of the shading packet's stream (stream j is the j-th shading packet's), of
            // packet i's table stream, or of the light table.
            let point = |i: usize, j: u32| {
                if streams {
                    smp.light_stream_point(&st[j as usize], j, k, &point_k)
                } else if tabled {
                    table.stream_point(smp, &table_streams[i], i, k)
                } else {
                    table.point(smp, pks[i].pixel, k)
                }
            };
            let sample = |sh: &SurfaceHit8, shade: Mask8, _: usize, _: u32, uv: (F8, F8), ls: &mut LightSample8| {
                group.sample(it, scene, sh, uv, shade, ls)
            };
            // f cos_i cos_l / d^2: a quad's sum is scaled once below; the triangles' terms are
            // complete.
            let weigh = |ls: &LightSample8, f: Vec3x8, g: F8, lit: Mask8| match group {
                Group::Quad(_) if warped => f.scale(g * ls.area),
                Group::Quad(_) => f.scale(g),
                Group::Triangles => masked(f.mul_elem(ls.radiance).scale(g * ls.area * ls.inv_pmf * inv_n), lit),
            };
            let target = if let Group::Quad(_) = group { &mut acc[..] } else { &mut *out };
            sample_batch::<L>(scene, tracer, hits, lanes, batch, point, sample, weigh, target, mis);
        }
        if let Group::Quad(light) = group {
            let area = if warped { F8::ONE } else { F8::splat(light.area) };
            let scale = Vec3x8::splat(light.radiance).scale(inv_n * area);
            for (o, acc) in out.iter_mut().zip(acc.iter()) {
                *o += acc.mul_elem(scale);
            }
        }
    }
}

/// Per camera packet of the tile: the hit lanes of `hits` to shade (lights shade nothing
/// themselves: black, one-sided emitters), and the shadow-ray origin offsets.
fn shading_lanes(scene: &Scene, hits: &[SurfaceHit8], lanes: &mut Lanes) {
    lanes.shade.clear();
    lanes.shade.extend(hits.iter().map(|sh| sh.valid & F8::from_bits(sh.light.simd_eq(U8::splat(u32::MAX)))));
    lanes.eps.clear();
    lanes.eps.extend(hits.iter().map(|sh| scene.offset_eps(sh.p)));
}

/// One light dimension of pixel sample `s` drawn from the integrator's light table, over all
/// spp x N light samples of the pixel (light sample k of pixel sample s is the table's sample
/// `s N + k`): used unless the layout is a per-sample grid ([`Integrator::light_streams`]).
pub(super) struct LightTable {
    dim: PathDim,
    first: u32,
}

impl LightTable {
    /// Dimension `dim` for pixel sample `s`.
    pub(super) fn new(it: &Integrator, smp: &Samples, dim: u32, s: u32) -> Self {
        let n = it.light_table.set().n();
        Self { dim: smp.table_dim(true, n, dim), first: s.wrapping_mul(it.light_set.n()) }
    }

    /// Light sample `k` of the pixels `pixel`.
    #[inline]
    pub(super) fn point(&self, smp: &Samples, pixel: U8, k: u32) -> (F8, F8) {
        let index = U8::splat(self.first.wrapping_add(k));
        smp.table_point(&self.dim, true, Phase::SamplerLight, pixel, index)
    }

    /// The streams of this dimension for the packets `pks` into `out` (false, `out` empty, for a
    /// grid layout), for [`LightTable::stream_point`]; the same for every pixel sample.
    pub(super) fn streams(&self, smp: &Samples, pks: &[PixelPacket], out: &mut Vec<Stream<U8>>) -> bool {
        smp.table_streams(&self.dim, true, pks, out)
    }

    /// [`LightTable::point`] from stream `j` of [`LightTable::streams`] (`stream`, the pixels'):
    /// the same point, bit for bit, without the per-pixel hashing.
    #[inline]
    pub(super) fn stream_point(&self, smp: &Samples, stream: &Stream<U8>, j: usize, k: u32) -> (F8, F8) {
        smp.table_stream_point(Phase::SamplerLight, stream, j as u32, self.first.wrapping_add(k))
    }
}

/// `direct` with one light per light sample, chosen by `it.light_sampler` (see the module docs).
#[inline(never)]
fn shade_one<L: LobeSet>(
    it: &Integrator,
    ctx: &mut TileCtx,
    hits: &[SurfaceHit8],
    sc: &mut Buffers,
    s: u32,
    out: &mut [Vec3x8],
    mis: Option<Mis>,
) {
    let TileCtx { scene, pks, tracer, samples: smp } = ctx;
    let n_light = it.light_set.n();
    let inv_n = F8::splat(1.0 / n_light as f32);
    // One light picked for certain: the choice is light 0 with pmf 1 whatever its sample, so the
    // choice dimension is not drawn (every sample is a pure function of its own dimension: the
    // others are unchanged).
    let one_light = it.light_sampler.certain();
    // The choice from a dimension of its own, or reused from the light point's u (Mitsuba's).
    let own_choice = !one_light && it.light_choice == LightChoice::Dimension;
    let streams = it.light_streams();
    let table = LightTable::new(it, smp, LIGHT_POINT.first, s);
    let choice_table = LightTable::new(it, smp, LIGHT_CHOICE.first, s);
    let Buffers { lanes, batch, streams: st, choice_streams, .. } = sc;
    st.clear();
    choice_streams.clear();
    if streams {
        smp.light_streams(pks, &lanes.shade, s, LIGHT_POINT.first, true, st);
        if own_choice {
            smp.light_streams(pks, &lanes.shade, s, LIGHT_CHOICE.first, false, choice_streams);
        }
    }
    // Streams (and choice streams) j are the j-th shading packet's.
    let n_shading = st.len() as u32;
    for k in 0..n_light {
        let point_k = it.light_set.point_k(k);
        let point = |i: usize, j: u32| {
            if streams {
                smp.light_stream_point(&st[j as usize], j, k, &point_k)
            } else {
                table.point(smp, pks[i].pixel, k)
            }
        };
        let sample = |sh: &SurfaceHit8, shade: Mask8, i: usize, j: u32, uv: (F8, F8), ls: &mut LightSample8| {
            let choice = if one_light {
                AreaChoice::Certain
            } else if own_choice {
                let (uc, _) = if streams {
                    smp.light_stream_point(&choice_streams[j as usize], n_shading + j, k, &point_k)
                } else {
                    choice_table.point(smp, pks[i].pixel, k)
                };
                AreaChoice::Drawn(uc)
            } else {
                AreaChoice::Reuse
            };
            area_sample(it, scene, sh, shade, choice, uv, ls)
        };
        let weigh = |ls: &LightSample8, f: Vec3x8, g: F8, lit: Mask8| {
            let g = g * ls.area * ls.inv_pmf * inv_n;
            masked(f.mul_elem(ls.radiance).scale(g), lit)
        };
        sample_batch::<L>(scene, tracer, hits, lanes, batch, point, sample, weigh, out, mis);
    }
}

/// Light sample k of every shading packet of the tile: its unit-square point (`point(packet,
/// shading packet)`), a light point from it (`sample(hits, shading lanes, packet, shading packet,
/// point, sample to fill)`, returning the lanes that got one), the light term ([`towards`], the
/// BSDF value) and what it adds if the shadow ray is clear (`weigh(sample, f, cos_i cos_l / d^2,
/// lit lanes)`, f times the sample's MIS weight against the BSDF samples when `mis` is given),
/// traced as one batch into `target`.
#[allow(clippy::too_many_arguments)]
#[inline]
fn sample_batch<L: LobeSet>(
    scene: &Scene,
    tracer: &mut Tracer,
    hits: &[SurfaceHit8],
    lanes: &Lanes,
    batch: &mut Batch,
    mut point: impl FnMut(usize, u32) -> (F8, F8),
    mut sample: impl FnMut(&SurfaceHit8, Mask8, usize, u32, (F8, F8), &mut LightSample8) -> Mask8,
    weigh: impl Fn(&LightSample8, Vec3x8, F8, Mask8) -> Vec3x8,
    target: &mut [Vec3x8],
    mis: Option<Mis>,
) {
    batch.clear();
    // Per shading packet: the point, the light point, the light term and the shadow packet, in
    // one pass (the sampler and emitter calls are leaf spans).
    let (mut j, mut ls) = (0, LightSample8::ZERO);
    for (i, sh) in hits.iter().enumerate() {
        let shade = lanes.shade[i];
        if shade.none() {
            continue;
        }
        let uv = point(i, j);
        let ok = sample(sh, shade, i, j, uv, &mut ls);
        j += 1;
        if let Some((contrib, ray)) = light_event::<L>(scene, sh, lanes.eps[i], &ls, ok, &weigh, mis) {
            batch.contrib.push(contrib);
            batch.push(ray, i);
        }
    }
    batch.trace(tracer, target);
}

/// The light term of the light sample `ls` (lanes `ok`) at the hits `sh`: what it adds if its
/// shadow ray is clear (`weigh(sample, f, cos_i cos_l / d^2, lit lanes)`, f times its MIS weight
/// when `mis` is given) and that shadow ray (from the hits offset by `eps`, with its lanes), or
/// None where no lane is lit.
#[inline(always)]
fn light_event<L: LobeSet>(
    scene: &Scene,
    sh: &SurfaceHit8,
    eps: F8,
    ls: &LightSample8,
    ok: Mask8,
    weigh: impl Fn(&LightSample8, Vec3x8, F8, Mask8) -> Vec3x8,
    mis: Option<Mis>,
) -> Option<(Vec3x8, (Ray8, Mask8))> {
    let strategy = if mis.is_some() { MIS_STRATEGY } else { ImportanceSampling::Cosine };
    // Shade before visibility: f cos_i cos_l / d^2, kept if the shadow ray is clear.
    let PointTerm { wi, d2, inv_d, cos_i, cos_l, lit } = towards(sh, ls, ok);
    if lit.none() {
        return None;
    }
    let frame = shading_frame::<L>(scene, sh);
    let mat = &sh.mat;
    let at = Shading::new(sh, &frame, strategy);
    let (mut f, pdf_b) = at.eval::<L>(at.frame.to_local(wi), lit);
    // No shadow ray where a registry BSDF has no value (delta lobes only: Mitsuba samples
    // no emitter there).
    let lit =
        if <L::Bsdfs as BsdfSet>::BITS != 0 { lit & !(mat.general(lit) & f.max_elem().simd_le(F8::ZERO)) } else { lit };
    if lit.none() {
        return None;
    }
    if let Some(mis) = &mis {
        // The light sample's solid-angle pdf: d^2 / (cos_l A inv_pmf), A the light's area
        // (or `light::warp`'s 1 / pdf per area).
        let p_e = d2 / (ls.area * cos_l * ls.inv_pmf);
        f = f.scale(mis.light(p_e, pdf_b, lit));
    }
    let contrib = weigh(ls, f, cos_i * cos_l * inv_d * inv_d, lit);
    // Shadow packet from the offset point towards the light sample, stopping short.
    let o = sh.ng.mul_add(eps, sh.p);
    let (d, tfar) = point_shadow(scene, o, ls.y, inv_d);
    Some((contrib, Ray8::new(o, d, F8::ZERO, tfar, lit)))
}

/// Shadow packets of a batch and what each adds to its owner's radiance if unoccluded.
#[derive(Default)]
pub(super) struct Batch {
    shadow: Vec<(Ray8, Mask8)>,
    contrib: Vec<Vec3x8>,
    owner: Vec<u32>,
}

impl Batch {
    /// Empty.
    pub(super) fn clear(&mut self) {
        self.shadow.clear();
        self.contrib.clear();
        self.owner.clear();
    }

    /// A shadow packet (its ray and lit lanes) of the camera packet `owner`; its contribution is
    /// pushed onto `contrib` before.
    pub(super) fn push(&mut self, ray: (Ray8, Mask8), owner: usize) {
        self.shadow.push(ray);
        self.owner.push(owner as u32);
    }

    /// Traces the packets back to back and adds `contrib[j]` to `acc[owner[j]]` on the lanes of
    /// packet j whose shadow ray reached the light.
    #[inline]
    pub(super) fn trace(&mut self, tracer: &mut Tracer, acc: &mut [Vec3x8]) {
        let _p = crate::profile::scope(crate::profile::Phase::EmbreeOccluded);
        for (j, (ray, lit)) in self.shadow.iter_mut().enumerate() {
            let occluded = tracer.occluded(ray, *lit);
            acc[self.owner[j] as usize] += masked(self.contrib[j], *lit & !occluded);
        }
    }
}

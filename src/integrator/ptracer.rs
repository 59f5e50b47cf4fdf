//! `ptracer`: the particle tracer (Mitsuba's `ptracer`). Light paths start on the emitters (one
//! chosen by emitted power, a ray sampled by its kind: `light/emission.rs`), bounce through the
//! scene by BSDF sampling and Russian roulette, and every vertex is connected to the sensor: the
//! contribution `alpha f |cos| / d^2 W` lands on the pixel the vertex projects to (box filter),
//! not on the pixel the path was started for. Emitters seen directly are the path's vertex 0
//! (the emitter point connected to the sensor), unless `hide_emitters`.
//!
//! **Why a render loop of its own.** A light path's contributions land anywhere on the image, so
//! the per-pixel [`Estimator::tile`] shape cannot hold them: `render.rs` runs the particle tracer
//! in two steps. First every (sample s, tile) block traces one light path per pixel of the tile
//! ([`Integrator::splat_tile`], so a pass of `spp` samples traces `spp x pixels` paths, as
//! Mitsuba's) and returns its splats in a fixed order; the blocks run in parallel and their splats
//! are summed into sample s's image in block order (never float atomics), so the image is
//! bit-identical whatever the thread count. Then the images go through the film's per-pixel
//! accumulation as sample s of every pixel: image s is an unbiased estimate of the pixel values
//! by itself, so the film's mean and variance per pixel keep their meaning, and since image s is
//! a pure function of (s, seed), passes, checkpoints and shards stay bit-identical.
//! [`Estimator::tile`] is registered (kind, dimensions) but yields nothing per pixel.
//!
//! Measurement: for pixel j of a `W x H` image with image-plane coordinates `(a, b)` in
//! [-1, 1]^2 (`scene::build::Lens::Perspective`: direction `p = base + a ax + b ay`), the pixel
//! value is the mean of the radiance over the pixel's `(a, b)` square, so a direction's
//! importance is `|p|^3 / (|det M| da db)` with `M = [ax ay base]`; averaged over `W H` paths per
//! sample, each splat is `alpha f cos / d^2 |p|^3 / (4 |det M|)`.
//!
//! Shading normals: a BSDF evaluated for light flowing from the light towards the sensor is
//! corrected as Veach's adjoint BSDF (`|n_s . w_l| |n_g . w_o| / (|n_g . w_l| |n_s . w_o|)`).
//! Lights' geometry reflects with its shape's material, as Mitsuba's area lights do (the `.test`
//! quad lights are black). Emitters with a bitmap `radiance` (their texture at the sampled
//! point's uv) are rendered by this integrator only.
//!
//! Sampler dimensions of a light path (light layout for the emitter, path layout after): the
//! emitter choice and point (2D, the choice reusing u as `--light-choice reuse` does), the
//! emission direction (2D), then at surface vertex k (1..) the BSDF direction at
//! `DIM_PT_BASE + 2 + 2 (k - 1)` and (roulette, lobe choice) one after, each over the pixel's spp
//! samples of the pixel the path is started for.

use super::context::{shading_frame, TileCtx};
use super::estimator::Estimator;
use super::samples::{Dim, Source};
use super::settings::Integrator;
use super::stats::{Counters, RayKind};
use crate::accel::{Hits8, Ray8, RayHit8};
use crate::bsdf::LobeSet;
use crate::camera::PixelPacket;
use crate::light::emission::EmissionSample;
use crate::profile::Phase;
use crate::scene::build::{Lens, Scene};
use crate::scene::desc::IntegratorKind;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{mask_from_bools, mask_to_bools, Vec3x8, F8, U8};
use glam::{Mat3, Vec3};

/// First sampler dimension of a light path.
pub const DIM_PT_BASE: u32 = 64;
/// Hard cap on surface vertices when `max_depth` is -1.
pub const MAX_VERTICES: u32 = 4096;

/// The emitter choice and the point on it (2D; u picks the emitter and is remapped).
pub const EMITTER_POINT: Dim =
    Dim { name: "emitter choice, point", first: DIM_PT_BASE, stride: 0, source: Source::Light };
/// The emission direction (2D).
pub const EMISSION_DIR: Dim =
    Dim { name: "emission direction", first: DIM_PT_BASE + 1, stride: 0, source: Source::Light };
/// The BSDF direction at surface vertex k (2D).
pub const DIRECTION: Dim = Dim { name: "BSDF direction", first: DIM_PT_BASE + 2, stride: 2, source: Source::Path };
/// (Russian roulette, lobe choice) at surface vertex k.
pub const ROULETTE_LOBE: Dim =
    Dim { name: "roulette, lobe choice", first: DIM_PT_BASE + 3, stride: 2, source: Source::Path };

/// The `ptracer` integrator (see the module docs).
pub struct ParticleTracer;

impl Estimator for ParticleTracer {
    const KIND: IntegratorKind = IntegratorKind::ParticleTracer;
    const DIMS: &'static [Dim] = &[EMITTER_POINT, EMISSION_DIR, DIRECTION, ROULETTE_LOBE];
    type Scratch = ();

    /// Nothing per pixel: the particle tracer's estimate is its splats ([`Integrator::splat_tile`],
    /// run by `render.rs`'s light loop). Zero radiance for every packet and sample.
    fn tile<L: LobeSet>(
        _: &Integrator,
        ctx: &mut TileCtx,
        _: &mut (),
        samples: std::ops::Range<u32>,
        out: &mut Vec<Vec3x8>,
    ) {
        out.clear();
        out.resize(ctx.pks.len() * samples.len(), Vec3x8::ZERO);
    }
}

/// One contribution of a light path: `rgb` added to pixel `pixel` (linear index).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Splat {
    /// linear pixel index `y * width + x`
    pub pixel: u32,
    /// the contribution to that pixel's sample
    pub rgb: [f32; 3],
}

/// The sensor as the particle tracer connects to it: the pinhole and the inverse of the lens map.
#[derive(Clone, Copy, Debug)]
struct Sensor {
    origin: Vec3,
    inv: Mat3,
    /// 1 / (4 |det M|)
    norm: f32,
    near: f32,
    width: u32,
    height: u32,
}

impl Sensor {
    fn of(scene: &Scene) -> Option<Self> {
        let c = &scene.camera;
        let Lens::Perspective { origin, base, ax, ay, near } = c.lens else { return None };
        let m = Mat3::from_cols(ax, ay, base);
        let det = m.determinant();
        (det.is_finite() && det != 0.0).then(|| Self {
            origin,
            inv: m.inverse(),
            norm: 1.0 / (4.0 * det.abs()),
            near,
            width: c.width,
            height: c.height,
        })
    }

    /// The pixel `y` projects to and the importance of the direction (see the module docs), or
    /// None outside the image or before the near plane.
    fn project(&self, y: Vec3) -> Option<(u32, f32)> {
        let v = y - self.origin;
        let q = self.inv * v;
        if !(q.z > self.near && q.z > 0.0) {
            return None;
        }
        let (a, b) = (q.x / q.z, q.y / q.z);
        let (x, yy) = ((a + 1.0) * 0.5 * self.width as f32, (b + 1.0) * 0.5 * self.height as f32);
        if !(x >= 0.0 && yy >= 0.0 && x < self.width as f32 && yy < self.height as f32) {
            return None;
        }
        let (px, py) = ((x as u32).min(self.width - 1), (yy as u32).min(self.height - 1));
        let p = v / q.z;
        Some((py * self.width + px, p.length().powi(3) * self.norm))
    }
}

/// Where a light path starts: an area light (index into `Scene::emitters`) or a delta light
/// (index into `Scene::delta`).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source0 {
    Area(u32),
    Delta(u32),
}

/// The emitters of a scene with their choice probabilities (by emitted power), and the sensor:
/// what every block of a render shares. Built once per pass by [`LightPaths::new`].
#[derive(Clone, Debug)]
pub struct LightPaths {
    sources: Vec<Source0>,
    /// cumulative probabilities, last = 1
    cdf: Vec<f32>,
    pmf: Vec<f32>,
    sensor: Option<Sensor>,
}

impl LightPaths {
    /// The emitters of `scene` (area and delta lights of positive power) and its sensor.
    pub fn new(scene: &Scene) -> Self {
        let mut sources = Vec::new();
        let mut power = Vec::new();
        for (i, e) in scene.emitters.list.iter().enumerate() {
            sources.push(Source0::Area(i as u32));
            power.push(e.emitted_power());
        }
        for (i, d) in scene.delta.iter().enumerate() {
            sources.push(Source0::Delta(i as u32));
            power.push(d.emitted_power());
        }
        let total: f64 = power.iter().map(|&p| f64::from(p.max(0.0))).sum();
        let mut acc = 0.0f64;
        let (mut cdf, mut pmf) = (Vec::with_capacity(power.len()), Vec::with_capacity(power.len()));
        for &p in &power {
            let p = if total > 0.0 { f64::from(p.max(0.0)) / total } else { 0.0 };
            acc += p;
            cdf.push(acc as f32);
            pmf.push(p as f32);
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        Self { sources, cdf, pmf, sensor: Sensor::of(scene) }
    }

    /// The source picked by `u` with its pmf and `u` remapped to [0, 1) within its interval.
    fn pick(&self, u: f32) -> Option<(Source0, f32, f32)> {
        let i = self.cdf.partition_point(|&c| c <= u).min(self.cdf.len().checked_sub(1)?);
        let pmf = self.pmf[i];
        if pmf <= 0.0 {
            return None;
        }
        let lo = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        Some((self.sources[i], pmf, ((u - lo) / pmf).clamp(0.0, 1.0 - f32::EPSILON / 2.0)))
    }
}

impl Integrator {
    /// The splats of sample `s` of the light paths started for the pixels of `pks` (one path
    /// per pixel in the image), appended to `splats` in a fixed order: packet by packet, then by
    /// vertex, then by lane.
    pub fn splat_tile(
        &self,
        scene: &Scene,
        paths: &LightPaths,
        pks: &[PixelPacket],
        s: u32,
        splats: &mut Vec<Splat>,
        c: &mut Counters,
    ) {
        let samples = super::samples::Samples::new(self, self.camera(scene));
        let mut ctx = TileCtx { scene, samples, pks, tracer: super::context::Tracer::new(scene, c, None) };
        super::kernel::with_lobe_set!(self.kernel.lobes, L => trace_tile::<L>(self, &mut ctx, paths, s, splats))
    }
}

/// Per-lane state of 8 light paths.
struct Lanes {
    alive: [bool; 8],
    /// emitted flux / (pmf, pdfs): the path's weight before any bounce
    power: [Vec3; 8],
    /// product of BSDF weights since the emitter (roulette looks at it)
    beta: [Vec3; 8],
}

fn trace_tile<L: LobeSet>(it: &Integrator, ctx: &mut TileCtx, paths: &LightPaths, s: u32, splats: &mut Vec<Splat>) {
    let Some(sensor) = paths.sensor else { return };
    if paths.sources.is_empty() {
        return;
    }
    let TileCtx { scene, samples: smp, pks, tracer } = ctx;
    let idx = U8::splat(s);
    let d_point = smp.table_dim(true, it.spp, EMITTER_POINT.first);
    let d_dir = smp.table_dim(true, it.spp, EMISSION_DIR.first);
    let max_k = if it.max_depth < 0 { MAX_VERTICES } else { it.max_depth as u32 };
    let mut sh = Box::new(SurfaceHit8::MISS);
    let mut conn: Vec<(usize, Vec3, Vec3, f32, u32, Vec3)> = Vec::with_capacity(8);
    for pk in pks.iter() {
        let (u0, u1) = smp.table_point(&d_point, true, Phase::SamplerLight, pk.pixel, idx);
        let (v0, v1) = smp.table_point(&d_dir, true, Phase::SamplerLight, pk.pixel, idx);
        let (u0, u1, v0, v1) = (u0.to_array(), u1.to_array(), v0.to_array(), v1.to_array());
        let on = mask_to_bools(pk.active);
        let mut st = Lanes { alive: [false; 8], power: [Vec3::ZERO; 8], beta: [Vec3::ONE; 8] };
        let mut org = [Vec3::ZERO; 8];
        let mut dir = [Vec3::Z; 8];
        conn.clear();
        {
            let _p = crate::profile::leaf(Phase::Emitter);
            for i in (0..8).filter(|&i| on[i]) {
                let Some((src, pmf, u)) = paths.pick(u0[i]) else { continue };
                let es: Option<EmissionSample> = match src {
                    Source0::Area(e) => {
                        let em = &scene.emitters.list[e as usize];
                        let tex = emitted_texture(scene, e, (u, u1[i]));
                        let es = em.sample_emission((u, u1[i]), (v0[i], v1[i]));
                        let es = es.map(|es| EmissionSample { weight: es.weight * tex, ..es });
                        // Vertex 0: the emitter point seen by the sensor.
                        if let (Some(es), false) = (es, scene.desc.hide_emitters) {
                            if let Some((px, w)) = sensor.project(es.p) {
                                let to = sensor.origin - es.p;
                                let d2 = to.length_squared();
                                let cos = es.n.dot(to) / d2.sqrt();
                                if cos > 0.0 && d2 > 0.0 {
                                    let (_, pdf_a) = em.sample_position((u, u1[i]));
                                    let rgb = em.radiance * tex * (cos / (d2 * pdf_a * pmf) * w);
                                    conn.push((i, es.p, es.n, 0.0, px, rgb));
                                }
                            }
                        }
                        es
                    }
                    Source0::Delta(d) => scene.delta[d as usize].sample_emission((u, u1[i])),
                };
                let Some(es) = es else { continue };
                st.alive[i] = true;
                st.power[i] = es.weight / pmf;
                // Off an area light's surface (delta lights start exactly at the light).
                org[i] = if es.n == Vec3::ZERO { es.p } else { es.p + es.n * scalar_eps(scene, es.p) };
                dir[i] = es.dir;
            }
        }
        connect(scene, tracer, &sensor, &conn, splats);
        let mut k = 1u32;
        while st.alive.iter().any(|&a| a) && k <= max_k {
            let mut rh = RayHit8::default();
            let o8 = Vec3x8::from_lanes(org);
            // Origins off the surface they leave (delta lights start exactly at the light).
            let active = mask_from_bools(st.alive);
            let traced = {
                let _ = rh.ray.set(o8, Vec3x8::from_lanes(dir), F8::ZERO, F8::splat(f32::INFINITY), active);
                tracer.intersect(&mut rh, RayKind::Bounce, active)
            };
            scene.gather_into(rh.ray.org(), rh.ray.dir(), &Hits8::from_rayhit(&rh, traced), &mut sh);
            // Lights' geometry reflects with its material too (Mitsuba's area lights; black for
            // the `.test` quad lights, which end the path).
            let shade = sh.valid;
            let shade_b = mask_to_bools(shade);
            for (a, &hit) in st.alive.iter_mut().zip(&shade_b) {
                *a &= hit;
            }
            if shade.none() {
                break;
            }
            let (frame, mat) = (shading_frame::<L>(scene, &sh), &sh.mat);
            let wo = frame.to_local(sh.wo);
            let eps = scene.offset_eps(sh.p);
            // The connection to the sensor of every shaded lane.
            conn.clear();
            let p_l = sh.p.to_lanes();
            let mut wc = [Vec3::Z; 8];
            let mut d2s = [0.0f32; 8];
            let mut pix = [(0u32, 0.0f32); 8];
            let mut seen = [false; 8];
            for i in (0..8).filter(|&i| shade_b[i]) {
                if let Some(pw) = sensor.project(p_l[i]) {
                    let to = sensor.origin - p_l[i];
                    let d2 = to.length_squared();
                    if d2 > 0.0 {
                        (wc[i], d2s[i], pix[i], seen[i]) = (to / d2.sqrt(), d2, pw, true);
                    }
                }
            }
            let seen_m = mask_from_bools(seen);
            if seen_m.any() {
                let wc8 = Vec3x8::from_lanes(wc);
                let (f, _) = {
                    let _p = crate::profile::leaf(Phase::BsdfEval);
                    mat.eval_pdf_k::<L>(it.path.strategy, wo, frame.to_local(wc8), seen_m)
                };
                let (f, ns, ng, wl) = (f.to_lanes(), sh.n.to_lanes(), sh.ng.to_lanes(), sh.wo.to_lanes());
                let eps_l = eps.to_array();
                for i in (0..8).filter(|&i| seen[i]) {
                    let (cs, cg) = (ns[i].dot(wc[i]), ng[i].dot(wc[i]));
                    // Reflection only towards the sensor: both normals face it.
                    if !(cs > 0.0 && cg > 0.0) || f[i].max_element() <= 0.0 {
                        continue;
                    }
                    let corr = ns[i].dot(wl[i]).abs() / ng[i].dot(wl[i]).abs().max(1e-12);
                    let a = st.power[i] * st.beta[i];
                    let rgb = a * f[i] * (cg * corr / d2s[i] * pix[i].1);
                    if rgb.is_finite() && rgb.max_element() > 0.0 {
                        conn.push((i, p_l[i], ng[i], eps_l[i], pix[i].0, rgb));
                    }
                }
            }
            connect(scene, tracer, &sensor, &conn, splats);
            if k == max_k {
                break;
            }
            // Continue: sample the BSDF (the light's direction as wo), then roulette.
            let dk = smp.table_dim(false, it.spp, DIRECTION.at(k - 1));
            let dr = smp.table_dim(false, it.spp, ROULETTE_LOBE.at(k - 1));
            let (u_rr, u_lobe) = smp.table_point(&dr, false, Phase::SamplerPath, pk.pixel, idx);
            let u2 = smp.table_point(&dk, false, Phase::SamplerPath, pk.pixel, idx);
            let sampled = {
                let _p = crate::profile::leaf(Phase::BsdfSample);
                mat.sample_bsdf_k::<L>(it.path.strategy, wo, [u2.0, u2.1], u_lobe, shade)
            };
            let wi = frame.to_world(sampled.wi).to_lanes();
            let (pdf, f, cos) = (sampled.pdf.to_array(), sampled.f.to_lanes(), sampled.wi.z.to_array());
            let general =
                if <L::Bsdfs as crate::bsdf::BsdfSet>::BITS != 0 { mask_to_bools(sampled.general) } else { [false; 8] };
            let gw = sampled.bsdf.weight.to_lanes();
            let (ns, ng, wl) = (sh.n.to_lanes(), sh.ng.to_lanes(), sh.wo.to_lanes());
            let (eps_l, u_rr) = (eps.to_array(), u_rr.to_array());
            for i in 0..8 {
                if !st.alive[i] {
                    continue;
                }
                let w = if general[i] {
                    gw[i]
                } else if pdf[i] > 0.0 && cos[i] > 0.0 {
                    f[i] * (cos[i] / pdf[i])
                } else {
                    Vec3::ZERO
                };
                let (gs, gg) = (ns[i].dot(wi[i]), ng[i].dot(wi[i]));
                // The direction must leave on the side of both normals (or cross both).
                let ok = (gs > 0.0 && gg > 0.0) || (general[i] && gs < 0.0 && gg < 0.0);
                let corr = ns[i].dot(wl[i]).abs() * gg.abs() / (ng[i].dot(wl[i]).abs() * gs.abs()).max(1e-12);
                let mut nb = st.beta[i] * w * corr;
                if !ok || !nb.is_finite() || nb.max_element() <= 0.0 {
                    st.alive[i] = false;
                    continue;
                }
                if it.path.russian_roulette && k >= it.path.rr_depth {
                    let q = nb.max_element().min(1.0);
                    if u_rr[i] >= q {
                        st.alive[i] = false;
                        continue;
                    }
                    nb /= q;
                }
                st.beta[i] = nb;
                dir[i] = wi[i];
                org[i] = p_l[i] + ng[i] * if gg > 0.0 { eps_l[i] } else { -eps_l[i] };
            }
            k += 1;
        }
    }
}

/// The radiance texture of emitter `e` at the point placed by the unit-square sample `u` (as
/// `Emitter::point` places it: a triangle folds `u + v > 1`), or 1 for an untextured emitter.
fn emitted_texture(scene: &Scene, e: u32, u: (f32, f32)) -> Vec3 {
    let Some(Some((image, uv))) = scene.emitter_textures.get(e as usize) else { return Vec3::ONE };
    let Some(im) = scene.desc.emission_images.get(*image as usize) else { return Vec3::ONE };
    let (a, b) = if u.0 + u.1 > 1.0 { (1.0 - u.0, 1.0 - u.1) } else { u };
    let t = uv[0] * (1.0 - a - b) + uv[1] * a + uv[2] * b;
    im.eval(t.x, t.y)
}

/// [`Scene::offset_eps`] at one point.
fn scalar_eps(scene: &Scene, p: Vec3) -> f32 {
    scene.offset_eps(Vec3x8::splat(p)).to_array()[0]
}

/// Traces the sensor connections `conn` (lane, point, normal to offset along, offset, pixel,
/// contribution) as one shadow packet and appends the unoccluded ones to `splats` in lane order.
fn connect(
    scene: &Scene,
    tracer: &mut super::context::Tracer,
    sensor: &Sensor,
    conn: &[(usize, Vec3, Vec3, f32, u32, Vec3)],
    splats: &mut Vec<Splat>,
) {
    if conn.is_empty() {
        return;
    }
    let mut o = [Vec3::ZERO; 8];
    let mut d = [Vec3::Z; 8];
    let mut tfar = [0.0f32; 8];
    let mut on = [false; 8];
    for (j, &(_, p, n, eps, _, _)) in conn.iter().enumerate() {
        // Off the surface on the side facing the sensor; a light's own point offset likewise.
        let eps = if eps > 0.0 { eps } else { scalar_eps(scene, p) };
        o[j] = p + n * eps;
        d[j] = sensor.origin - o[j];
        tfar[j] = 1.0 - eps / d[j].length().max(1e-30);
        on[j] = true;
    }
    let mut ray = Ray8::default();
    let lit = ray.set(Vec3x8::from_lanes(o), Vec3x8::from_lanes(d), F8::ZERO, F8::new(tfar), mask_from_bools(on));
    let blocked = mask_to_bools(tracer.occluded(&mut ray, lit));
    let lit = mask_to_bools(lit);
    for (j, &(_, _, _, _, px, rgb)) in conn.iter().enumerate() {
        if lit[j] && !blocked[j] {
            splats.push(Splat { pixel: px, rgb: rgb.to_array() });
        }
    }
}

#[cfg(test)]
#[path = "ptracer_tests.rs"]
mod tests;

//! The camera-hit wavefront shared by the direct-lighting integrators (`raytracer`,
//! `analyticdirect`, `direct`): for each pixel sample, all camera packets of the tile are traced,
//! then gathered (emission counted), then shaded by the integrator's closure.

use super::context::{masked, TileCtx};
use super::stats::RayKind;
use crate::accel::{Hits8, RayHit8};
use crate::sampler::Stream;
use crate::scene::build::Scene;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Mask8, Vec3x8, F8, U8};

/// Per-thread buffers of the camera-hit wavefront, reused across samples and tiles.
#[derive(Default)]
pub struct Wave {
    rh: Vec<(RayHit8, Mask8)>,
    hits: Vec<SurfaceHit8>,
    cam_streams: Vec<Stream<U8>>,
}

/// What [`tile_each`] asks of an integrator's shading, per pixel sample `s`: `begin` sees the
/// traced camera packets (with their lanes traced) before any is gathered, `shade` adds to a
/// packet's radiance (holding its emission) at its hits (packets with no hit lane are not shaded),
/// and `end` adds what it deferred (shadow rays traced back to back) to the sample's radiances.
pub(super) trait EachPacket {
    /// Pixel sample `s`'s camera packets were traced.
    fn begin(&mut self, ctx: &mut TileCtx, s: u32, packets: &[(RayHit8, Mask8)]);
    /// Adds to `o` the radiance of packet `i` at its hits `sh`.
    fn shade(&mut self, ctx: &mut TileCtx, sh: &SurfaceHit8, i: usize, o: &mut Vec3x8);
    /// Adds what `shade` deferred to the sample's radiances `out` (one per packet).
    fn end(&mut self, ctx: &mut TileCtx, out: &mut [Vec3x8]);
}

/// [`tile`] with the packets gathered and shaded one by one into a single hit record that stays in
/// cache, instead of a wavefront of the tile's records (2 KiB each, 70 KiB a tile, written and
/// read back per sample); the camera rays and Embree calls stay back to back. Packets with no hit
/// lane are not gathered. The same radiance, bit for bit, when `sh` adds to a packet what
/// [`tile`]'s closure adds to its entry, in the same order.
#[inline(always)]
pub(super) fn tile_each(
    ctx: &mut TileCtx,
    wave: &mut Wave,
    samples: std::ops::Range<u32>,
    out: &mut Vec<Vec3x8>,
    sh: &mut impl EachPacket,
) {
    out.clear();
    camera_streams(ctx, wave, &samples);
    // One record, reused (the gather writes what the kernels read).
    wave.hits.truncate(1);
    wave.hits.resize(1, SurfaceHit8::MISS);
    let scene = ctx.scene;
    let hide = scene.desc.hide_emitters;
    let outside = !hide && (scene.sky.is_some() || scene.envmap.is_some());
    for s in samples {
        trace_camera(ctx, wave, s);
        sh.begin(ctx, s, &wave.rh);
        let first = out.len();
        let rec = &mut wave.hits[0];
        for (i, (rh, traced)) in wave.rh.iter().enumerate() {
            let hits = Hits8::from_rayhit(rh, *traced);
            let mut o = Vec3x8::ZERO;
            let hit = hits.hit.any();
            if hit {
                scene.gather_into(rh.ray.org(), rh.ray.dir(), &hits, rec);
                if !hide {
                    o = masked(rec.emitted + rec.le, rec.valid);
                }
            }
            // Camera rays that leave the scene see the environment (none in `.test` scenes).
            let missed = *traced & !hits.hit;
            if outside && missed.any() {
                o += background(scene, rh.ray.dir(), missed);
            }
            if hit {
                sh.shade(ctx, rec, i, &mut o);
            }
            out.push(o);
        }
        sh.end(ctx, &mut out[first..]);
    }
}

/// The camera's pixel-sample streams of the tile's packets into `wave.cam_streams`, hashed once
/// for the batch `samples` (none when no sample of it draws a camera point).
#[inline(always)]
fn camera_streams(ctx: &TileCtx, wave: &mut Wave, samples: &std::ops::Range<u32>) {
    wave.cam_streams.clear();
    if samples.clone().any(|s| ctx.samples.camera_draws(s)) {
        ctx.samples.camera_streams(ctx.pks, &mut wave.cam_streams);
    }
}

/// What camera rays in direction `dir` that left the scene see on lanes `missed`: the sky's or the
/// environment map's radiance (zero in scenes with neither, as in `.test` scenes).
#[inline(always)]
fn background(scene: &Scene, dir: Vec3x8, missed: Mask8) -> Vec3x8 {
    match (&scene.sky, &scene.envmap) {
        (Some(sky), _) => masked(Vec3x8::splat(sky.radiance), missed),
        (None, Some(env)) => env.radiance_pdf_x8(dir, missed).0,
        (None, None) => Vec3x8::ZERO,
    }
}

/// The camera packets of pixel sample `s` into `wave.rh`, traced (each mask: the lanes traced).
#[inline(always)]
fn trace_camera(ctx: &mut TileCtx, wave: &mut Wave, s: u32) {
    let n = ctx.pks.len();
    wave.rh.truncate(n);
    wave.rh.resize(n, (RayHit8::default(), ctx.pks[0].active));
    let k = ctx.samples.camera_k(s);
    let at = if wave.cam_streams.is_empty() { None } else { ctx.samples.camera_point_k(s) };
    for (i, (pk, (rh, active))) in ctx.pks.iter().zip(wave.rh.iter_mut()).enumerate() {
        let (org, dir) = match wave.cam_streams.get(i) {
            Some(stream) => ctx.samples.camera_rays_in(pk, i as u32, stream, k, at.as_ref()),
            None => ctx.samples.camera_rays(pk, s),
        };
        *active = rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), pk.active);
    }
    ctx.tracer.intersect_all(&mut wave.rh, RayKind::Camera);
}

/// Radiance of pixel samples `samples` of the tile's packets into `out` (sample-major, as
/// `Estimator::tile`): emission at the camera hits plus what `shade(ctx, hits, s, radiance)`
/// adds to `radiance` (one entry per packet, holding the emission) at the hits of sample `s`.
/// Inlined into each integrator's `tile` (and so into `integrator::run`), with the shading closure.
#[inline(always)]
pub(super) fn tile(
    ctx: &mut TileCtx,
    wave: &mut Wave,
    samples: std::ops::Range<u32>,
    out: &mut Vec<Vec3x8>,
    mut shade: impl FnMut(&mut TileCtx, &[SurfaceHit8], u32, &mut [Vec3x8]),
) {
    out.clear();
    camera_streams(ctx, wave, &samples);
    let n = ctx.pks.len();
    for s in samples {
        // Sample s's entries of `out`, pushed and shaded in place (no copy per sample).
        let first = out.len();
        camera_hits(ctx, wave, s, out);
        debug_assert_eq!(out.len(), first + n);
        shade(ctx, &wave.hits, s, &mut out[first..]);
    }
}

/// The camera hits of pixel sample `s` of every packet into `wave.hits`, their emission pushed
/// onto `out` (one entry per packet).
fn camera_hits(ctx: &mut TileCtx, wave: &mut Wave, s: u32, out: &mut Vec<Vec3x8>) {
    let n = ctx.pks.len();
    // Packets and records are written in place (the buffers keep their length across samples;
    // Embree resets a packet's hit ids itself). Camera packets: coherent primary rays from 4x2
    // pixel blocks; the point drawn and its per-k work found once for all packets.
    trace_camera(ctx, wave, s);
    wave.hits.truncate(n);
    wave.hits.resize(n, SurfaceHit8::MISS);
    // Gather: hit records to SoA shading records; emission (none seen under `hide_emitters`).
    let hide = ctx.scene.desc.hide_emitters;
    let first = out.len();
    for ((rh, traced), sh) in wave.rh.iter().zip(wave.hits.iter_mut()) {
        ctx.scene.gather_into(rh.ray.org(), rh.ray.dir(), &Hits8::from_rayhit(rh, *traced), sh);
        out.push(if hide { Vec3x8::ZERO } else { masked(sh.emitted + sh.le, sh.valid) });
    }
    // Camera rays that leave the scene see the environment (none in `.test` scenes).
    let scene = ctx.scene;
    if !hide && (scene.sky.is_some() || scene.envmap.is_some()) {
        for ((rh, traced), (sh, o)) in wave.rh.iter().zip(wave.hits.iter().zip(out[first..].iter_mut())) {
            let missed = *traced & !sh.valid;
            if missed.none() {
                continue;
            }
            *o += background(scene, rh.ray.dir(), missed);
        }
    }
}

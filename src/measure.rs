//! Throughput measurement: the whole renderer's rays per second next to Embree's raw rate on the
//! very same ray packets, measured in the same run on one thread.
//!
//! Clock: the CPU time of the one thread doing the work (so time the machine spends on other
//! processes is not charged), and each part is run [`REPEATS`] times, interleaved, keeping the
//! fastest: on a shared machine the minimum is the least disturbed estimate of the same work.

use crate::film::Film;
use crate::integrator::{Counters, Integrator, RayLog, Scratch};
use crate::render::{self, TILE};
use crate::scene::build::Scene;
use cpu_time::ThreadTime;
use serde::Serialize;

/// Times each part (renderer, camera, bounce and shadow replays) is run; the fastest counts.
pub const REPEATS: usize = 3;

/// CPU seconds the calling thread spends in `f`.
pub fn thread_seconds(f: impl FnOnce()) -> f64 {
    let t = ThreadTime::now();
    f();
    t.elapsed().as_secs_f64()
}

/// Rays per second of the renderer and of Embree alone on the same packets (millions per second).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RayRates {
    /// camera rays traced
    pub camera_rays: u64,
    /// shadow rays traced
    pub shadow_rays: u64,
    /// bounce rays traced
    pub bounce_rays: u64,
    /// whole renderer (ray generation, sampling, shading, accumulation, tracing), 1 thread
    pub renderer_mrays: f64,
    /// Embree alone, camera packets (coherent flag as in the renderer)
    pub raw_camera_mrays: f64,
    /// Embree alone, shadow packets
    pub raw_shadow_mrays: f64,
    /// Embree alone, bounce packets (incoherent)
    pub raw_bounce_mrays: f64,
    /// Embree alone, the same mix: all rays / (camera time + shadow time)
    pub raw_mixed_mrays: f64,
    /// renderer_mrays / raw_mixed_mrays
    pub ratio: f64,
}

/// Renders samples `0..spp` single-threaded and times it, then replays every packet the renderer
/// traced through Embree alone and times that. FTZ/DAZ are set on the calling thread for both.
pub fn ray_rates(scene: &Scene, integrator: &Integrator, spp: u32) -> RayRates {
    crate::accel::set_ftz_daz();
    let pool = render::thread_pool(1).expect("one-thread pool");
    // The packets the renderer traces, logged, for the replays through Embree alone.
    let log = log_rays(scene, integrator, spp);
    let lanes = |m: &crate::simd::Mask8| m.to_bitmask().count_ones() as u64;
    let camera_rays: u64 = log.camera.iter().map(|(_, m)| lanes(m)).sum();
    let shadow_rays: u64 = log.shadow.iter().map(|(_, m)| lanes(m)).sum();
    let bounce_rays: u64 = log.bounce.iter().map(|(_, m)| lanes(m)).sum();
    let (mut t_render, mut t_cam, mut t_bounce, mut t_sh) =
        (f64::INFINITY, f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut total_rays = 0;
    for _ in 0..REPEATS {
        // Whole renderer on the pool's one worker (nested `install` runs inline there).
        let (t, rays) = pool.install(|| {
            let mut film = Film::new(scene.desc.width, scene.desc.height);
            let mut rays = 0;
            let t = thread_seconds(|| {
                rays = render::render(scene, integrator, &mut film, 0..spp, &pool).counters.total_rays()
            });
            (t, rays)
        });
        t_render = t_render.min(t);
        total_rays = rays;
        // Fresh copies each time: a replay writes its hits into the packets.
        let (mut cam, mut bounce, mut shadow) = (log.camera.clone(), log.bounce.clone(), log.shadow.clone());
        t_cam = t_cam.min(thread_seconds(|| replay_camera(scene, &mut cam)));
        t_bounce = t_bounce.min(thread_seconds(|| replay_bounce(scene, &mut bounce)));
        t_sh = t_sh.min(thread_seconds(|| replay_shadow(scene, &mut shadow)));
    }
    let renderer_mrays = total_rays as f64 / t_render.max(1e-12) / 1e6;
    let mr = |n: u64, t: f64| n as f64 / t.max(1e-12) / 1e6;
    let raw_mixed_mrays = mr(camera_rays + shadow_rays + bounce_rays, t_cam + t_sh + t_bounce);
    RayRates {
        camera_rays,
        shadow_rays,
        bounce_rays,
        renderer_mrays,
        raw_camera_mrays: mr(camera_rays, t_cam),
        raw_shadow_mrays: mr(shadow_rays, t_sh),
        raw_bounce_mrays: mr(bounce_rays, t_bounce),
        raw_mixed_mrays,
        ratio: renderer_mrays / raw_mixed_mrays,
    }
}

/// Every packet the renderer traces for samples `0..spp`, in the renderer's order (tile by tile).
pub fn log_rays(scene: &Scene, integrator: &Integrator, spp: u32) -> RayLog {
    let mut log = RayLog::default();
    let mut c = Counters::default();
    let mut sc = Scratch::default();
    let mut out = Vec::new();
    let (w, h) = (scene.desc.width, scene.desc.height);
    for ty in (0..h).step_by(TILE as usize) {
        for tx in (0..w).step_by(TILE as usize) {
            let pks = render::tile_packets(tx, ty, TILE.min(w - tx), TILE.min(h - ty), w, h);
            let mut start = 0;
            while start < spp {
                let batch = start..spp.min(start + render::SAMPLE_BATCH);
                integrator.radiance_tile(scene, &pks, batch.clone(), &mut out, &mut sc, &mut c, Some(&mut log));
                start = batch.end;
            }
        }
    }
    log
}

/// Traces logged camera packets (closest hit, coherent flag as the renderer sets it), in place.
pub fn replay_camera(scene: &Scene, packets: &mut [(crate::accel::RayHit8, crate::simd::Mask8)]) {
    for (rh, m) in packets.iter_mut() {
        scene.accel.intersect8(rh, true, *m);
    }
}

/// Traces logged bounce packets (closest hit, incoherent), in place.
pub fn replay_bounce(scene: &Scene, packets: &mut [(crate::accel::RayHit8, crate::simd::Mask8)]) {
    for (rh, m) in packets.iter_mut() {
        scene.accel.intersect8(rh, false, *m);
    }
}

/// Traces logged shadow packets (any hit), in place.
pub fn replay_shadow(scene: &Scene, packets: &mut [(crate::accel::Ray8, crate::simd::Mask8)]) {
    for (r, m) in packets.iter_mut() {
        scene.accel.occluded8(r, *m);
    }
}

//! Throughput measurement: the whole renderer's rays per second next to Embree's raw rate on the
//! very same ray packets, measured in the same run on one thread.

use crate::film::Film;
use crate::integrator::{Counters, Integrator, RayLog, Scratch};
use crate::render::{self, TILE};
use crate::scene::build::Scene;
use serde::Serialize;
use std::time::Instant;

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
    crate::simd::set_ftz_daz();
    // Whole renderer, one thread.
    let pool = render::thread_pool(1).expect("one-thread pool");
    let mut film = Film::new(scene.desc.width, scene.desc.height);
    let stats = render::render(scene, integrator, &mut film, 0..spp, &pool);
    let renderer_mrays = stats.mrays_per_sec();


    // The same packets, logged, then replayed through Embree alone.
    let mut log = log_rays(scene, integrator, spp);
    let lanes = |m: &crate::simd::Mask8| m.to_bitmask().count_ones() as u64;
    let camera_rays: u64 = log.camera.iter().map(|(_, m)| lanes(m)).sum();
    let shadow_rays: u64 = log.shadow.iter().map(|(_, m)| lanes(m)).sum();
    let bounce_rays: u64 = log.bounce.iter().map(|(_, m)| lanes(m)).sum();
    let t0 = Instant::now();
    replay_camera(scene, &mut log.camera);
    let t_cam = t0.elapsed().as_secs_f64();
    let tb = Instant::now();
    replay_bounce(scene, &mut log.bounce);
    let t_bounce = tb.elapsed().as_secs_f64();
    let t1 = Instant::now();
    replay_shadow(scene, &mut log.shadow);
    let t_sh = t1.elapsed().as_secs_f64();
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

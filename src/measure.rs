//! Throughput measurement: the whole renderer's rays per second next to Embree's raw rate on the
//! very same ray packets, measured in the same run on one thread.
//!
//! Clock: the CPU time of the one thread doing the work (so time the machine spends on other
//! processes is not charged), and each part is run [`REPEATS`] times, interleaved, keeping the
//! fastest: on a shared machine the minimum is the least disturbed estimate of the same work.

use crate::accel::{Ray8, RayHit1, RayHit16, Valid16, RAY_WORDS};
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
    /// Embree alone through its 16-wide entry points, camera rays (each kind's traced lanes packed
    /// 16 at a time in the renderer's order)
    pub raw16_camera_mrays: f64,
    /// 16-wide, bounce rays
    pub raw16_bounce_mrays: f64,
    /// 16-wide, shadow rays
    pub raw16_shadow_mrays: f64,
    /// 16-wide, the same mix
    pub raw16_mixed_mrays: f64,
    /// Embree alone, one ray per call (`rtcIntersect1`/`rtcOccluded1`), camera rays
    pub raw1_camera_mrays: f64,
    /// one by one, bounce rays
    pub raw1_bounce_mrays: f64,
    /// one by one, shadow rays
    pub raw1_shadow_mrays: f64,
    /// one by one, the same mix
    pub raw1_mixed_mrays: f64,
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
    // The same lanes for the 16-wide and one-by-one replays: [camera, bounce, shadow].
    let words = [
        lane_words(log.camera.iter().map(|(rh, m)| (&rh.ray, m))),
        lane_words(log.bounce.iter().map(|(rh, m)| (&rh.ray, m))),
        lane_words(log.shadow.iter().map(|(r, m)| (r, m))),
    ];
    let (mut t16, mut t1) = ([f64::INFINITY; 3], [f64::INFINITY; 3]);
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
        for (k, w) in words.iter().enumerate() {
            let (coherent, occluded) = (k == 0, k == 2);
            t16[k] = t16[k].min(replay16(scene, w, coherent, occluded).0);
            t1[k] = t1[k].min(replay1(scene, w, coherent, occluded).0);
        }
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
        raw16_camera_mrays: mr(camera_rays, t16[0]),
        raw16_bounce_mrays: mr(bounce_rays, t16[1]),
        raw16_shadow_mrays: mr(shadow_rays, t16[2]),
        raw16_mixed_mrays: mr(camera_rays + shadow_rays + bounce_rays, t16.iter().sum()),
        raw1_camera_mrays: mr(camera_rays, t1[0]),
        raw1_bounce_mrays: mr(bounce_rays, t1[1]),
        raw1_shadow_mrays: mr(shadow_rays, t1[2]),
        raw1_mixed_mrays: mr(camera_rays + shadow_rays + bounce_rays, t1.iter().sum()),
    }
}

/// The traced lanes of logged packets, in order, as Embree ray words.
pub fn lane_words<'a>(packets: impl Iterator<Item = (&'a Ray8, &'a crate::simd::Mask8)>) -> Vec<[u32; RAY_WORDS]> {
    let mut out = Vec::new();
    for (ray, m) in packets {
        let bits = m.to_bitmask();
        out.extend((0..8).filter(|j| bits & (1 << j) != 0).map(|j| ray.lane_words(j)));
    }
    out
}

/// Traces `rays` through Embree's 16-wide entry point, 16 at a time (closest hit, or any hit
/// when `occluded`): the thread seconds of the calls alone, and each ray's `tfar` after it.
pub fn replay16(scene: &Scene, rays: &[[u32; RAY_WORDS]], coherent: bool, occluded: bool) -> (f64, Vec<f32>) {
    let mut blocks: Vec<(RayHit16, Valid16)> = rays.chunks(16).map(RayHit16::new).collect();
    let t = thread_seconds(|| {
        for (b, valid) in blocks.iter_mut() {
            if occluded {
                scene.accel.occluded16(b, valid);
            } else {
                scene.accel.intersect16(b, valid, coherent);
            }
        }
    });
    (t, (0..rays.len()).map(|i| blocks[i / 16].0.tfar(i % 16)).collect())
}

/// Traces `rays` one per call (closest hit, or any hit when `occluded`): the thread seconds of
/// the calls alone, and each ray's `tfar` after it.
pub fn replay1(scene: &Scene, rays: &[[u32; RAY_WORDS]], coherent: bool, occluded: bool) -> (f64, Vec<f32>) {
    let mut one: Vec<RayHit1> = rays.iter().map(RayHit1::new).collect();
    let t = thread_seconds(|| {
        for r in one.iter_mut() {
            if occluded {
                scene.accel.occluded1(r);
            } else {
                scene.accel.intersect1(r, coherent);
            }
        }
    });
    (t, one.iter().map(RayHit1::tfar).collect())
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

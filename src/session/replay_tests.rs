//! The sampler replay: it makes exactly the render's sampler calls (counted by the sampler API
//! itself, independently of the log), its capped log is the same whatever the thread count, and a
//! slow test-only sampler dominates both the profile and the replay.

use super::*;
use crate::sampler::replay::take_api_calls;
use crate::scene::desc::IntegratorKind;
use crate::session::{prepare, run_profile, RenderOptions};

fn opts(kind: IntegratorKind, pixel: Option<SamplerKind>) -> RenderOptions {
    RenderOptions {
        size: Some((40, 24)),
        spp: Some(3),
        seed: 11,
        threads: 2,
        integrator: Some(kind),
        // Every dimension (the light dimensions of raytracer and analyticdirect do not exist:
        // `--light-sampler` would be refused there).
        sampler: pixel,
        ..Default::default()
    }
}

/// Sampler API calls made on the threads of `pool` since the last take.
fn pool_calls(pool: &rayon::ThreadPool) -> u64 {
    pool.broadcast(|_| take_api_calls()).iter().sum()
}

/// On every integrator (`direct` also with one light per sample, packet by packet at 8 spp, and
/// with enough light samples that every light's points come from per-packet streams of the light
/// table) and with a
/// sequence and a grid sampler: the log holds every sampler call
/// the render made (the render's count comes from a counter inside the sampler API, not from the
/// log), the replay makes exactly that many calls, and recording leaves the image bit-identical.
#[test]
fn replay_calls_the_sampler_exactly_as_often_as_the_render() {
    let _g = crate::profile::TEST_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    use crate::light::select::LightSelection;
    use IntegratorKind::*;
    let power = Some(LightSelection::named("power"));
    // (integrator, light selection, light samples, spp, scene; the built-in Cornell box when
    // none): `direct` with one light per sample in a scene without spheres shades packet by
    // packet, from per-packet streams at 8 spp or more.
    let no_spheres = Some(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/three_lights.test"));
    let cases = [
        (RayTracer, None, None, 3, None),
        (AnalyticDirect, None, None, 3, None),
        (Direct, None, None, 3, None),
        (Direct, power, None, 3, None),
        (Direct, power, None, 16, no_spheres),
        (Direct, None, Some(4), 3, None),
        (PathTracer, None, None, 3, None),
    ];
    for (kind, selection, light_samples, spp, scene) in cases {
        for sampler in [None, Some(SamplerKind::SOBOL)] {
            let o = RenderOptions {
                scene: scene.map(std::path::PathBuf::from),
                light_selection: selection,
                light_samples,
                spp: Some(spp),
                ..opts(kind, sampler)
            };
            let (scene, it) = prepare(&o).unwrap();
            let pool = render::thread_pool(2).unwrap();
            let mut film = Film::new(scene.desc.width, scene.desc.height);
            pool_calls(&pool);
            render::render(&scene, &it, &mut film, 0..it.spp, &pool);
            let plain = film.mean();
            let render_calls = pool_calls(&pool);
            let (rec, img) = record(&scene, &it, &pool, replay::DEFAULT_CAP_WORDS);
            assert_eq!(pool_calls(&pool), render_calls, "{kind:?}: the recording render makes the same calls");
            assert_eq!(
                rec.calls(),
                render_calls,
                "{kind:?} {sampler:?} {selection:?} {light_samples:?} {spp} spp: calls counted while recording"
            );
            assert_eq!(rec.recorded_calls(), render_calls, "{kind:?}: nothing capped");
            assert!(!rec.is_subset());
            take_api_calls();
            let (n, sum_a) = rec.replay(&replay_sets(&it), ReplayMode::Sample);
            assert_eq!(n, render_calls, "{kind:?}: the replay's own count");
            assert_eq!(take_api_calls(), render_calls, "{kind:?}: sampler API calls of the replay");
            let (_, sum_b) = rec.replay(&replay_sets(&it), ReplayMode::Sample);
            assert_eq!(sum_a, sum_b, "a replay is deterministic");
            // Another kind's replay (a grid, which has no table streams: their points one by
            // one) counts the calls it makes.
            take_api_calls();
            let (n, _) = rec.replay(&replay_sets(&it).with_kind(SamplerKind::STRATIFIED), ReplayMode::Sample);
            assert_eq!(take_api_calls(), n, "{kind:?} {sampler:?}: calls of a replay as stratified");
            rec.replay(&replay_sets(&it), ReplayMode::DecodeOnly);
            assert_eq!(take_api_calls(), 0, "decoding makes no sampler call");
            assert!(plain.iter().flatten().zip(img.iter().flatten()).all(|(a, b)| a.to_bits() == b.to_bits()));
            if kind != RayTracer {
                assert!(render_calls > 0, "{kind:?}");
            }
        }
    }
}

/// A log capped to a fraction of the render keeps the same tiles (the same words) with one
/// thread or two, counts every call of the render, and replays only the kept calls.
#[test]
fn a_capped_log_is_a_deterministic_subset_whatever_the_thread_count() {
    let _g = crate::profile::TEST_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let o = RenderOptions { size: Some((96, 80)), ..opts(IntegratorKind::PathTracer, None) };
    let (scene, it) = prepare(&o).unwrap();
    let full = record(&scene, &it, &render::thread_pool(2).unwrap(), replay::DEFAULT_CAP_WORDS).0;
    let cap = full.words() / 5;
    let one = record(&scene, &it, &render::thread_pool(1).unwrap(), cap).0;
    let two = record(&scene, &it, &render::thread_pool(2).unwrap(), cap).0;
    assert_eq!(one, two, "the kept tiles do not depend on the schedule");
    assert!(one.is_subset() && one.words() <= cap && one.tiles() > 0 && one.level() > 0);
    assert_eq!(one.calls(), full.calls(), "every call is counted");
    assert!(one.recorded_calls() < full.calls());
    assert_eq!(one.replay(&replay_sets(&it), ReplayMode::Sample).0, one.recorded_calls());
}

/// With the slow test-only sampler at the camera, the pixel sampler phase is the largest phase of
/// the profile, and the replay of the render costs more than a replay with any registered kind.
/// (Margins: the slow sampler spins about 25 us a call, several times the rest of the render.)
#[test]
fn a_slow_sampler_is_the_dominant_phase_and_the_dearest_replay() {
    let _g = crate::profile::TEST_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let o = RenderOptions { size: Some((64, 64)), spp: Some(4), ..opts(IntegratorKind::PathTracer, None) };
    let o = RenderOptions { pixel_sampler: Some(SamplerKind::SLOW_TEST), ..o };
    let p = run_profile(&o, 1).unwrap();
    let top = p.phases.iter().max_by(|a, b| a.seconds.total_cmp(&b.seconds)).unwrap();
    assert_eq!(top.name, "sampler: pixel/camera", "{:?}", p.phases);
    assert!(top.share > 0.5, "{}", top.share);
    let r = p.sampler_replay.as_ref().expect("strata profile replays the sampler");
    assert!(r.layouts.starts_with("pixel slow-test, "), "{}", r.layouts);
    assert_eq!(r.by_kind.len(), SamplerKind::ALL.len());
    for k in &r.by_kind {
        assert!(r.ns_per_sample > 3.0 * k.ns_per_sample, "{} vs {}: {}", r.ns_per_sample, k.kind, k.ns_per_sample);
    }
}

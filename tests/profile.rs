//! `strata profile`: the phase split covers the measured tile time, the right phases show up for
//! each integrator, and profiling never changes the image.

use strata::film::Film;
use strata::scene::desc::IntegratorKind;
use strata::session::{prepare, run_profile, RenderOptions};

/// Profiling is a process-wide switch: the tests of this file take turns.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn opts(kind: IntegratorKind) -> RenderOptions {
    RenderOptions {
        size: Some((48, 40)),
        spp: Some(4),
        seed: 5,
        threads: 2,
        integrator: Some(kind),
        ..Default::default()
    }
}

fn share(p: &strata::session::Profile, prefix: &str) -> f64 {
    p.phases.iter().filter(|r| r.name.starts_with(prefix)).map(|r| r.seconds).sum()
}

/// On every integrator: the phases (timed with the TSC) sum to the tiles' time measured
/// independently with `Instant` within 2%, the profiled image is bit-identical to the unprofiled
/// one, and the phases each integrator must spend time in are non-zero.
#[test]
fn phases_sum_to_the_total_on_every_integrator_and_images_match() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    use IntegratorKind::*;
    for kind in [RayTracer, AnalyticDirect, Direct, PathTracer] {
        let p = run_profile(&opts(kind), 1).unwrap();
        assert!(p.total_seconds > 0.0, "{kind:?}");
        assert!((0.98..=1.02).contains(&p.phase_sum_ratio), "{kind:?}: phases sum to {}", p.phase_sum_ratio);
        assert!(p.bit_identical, "{kind:?}: profiling changed the image");
        let shares: f64 = p.phases.iter().map(|r| r.share).sum();
        assert!((shares - p.phase_sum_ratio).abs() < 1e-9);
        assert!(share(&p, "embree intersect") > 0.0, "{kind:?}");
        assert!(share(&p, "hit gather") > 0.0, "{kind:?}");
        assert!(share(&p, "sampler: pixel") > 0.0 || kind == RayTracer, "{kind:?}");
        assert_eq!(p.samples, 48 * 40 * 4);
        match kind {
            Direct => {
                assert!(share(&p, "sampler: light") > 0.0 && share(&p, "emitter") > 0.0);
                assert!(share(&p, "embree occluded") > 0.0);
            }
            PathTracer => assert!(share(&p, "sampler: path") > 0.0),
            _ => {}
        }
    }
}

/// Profiling on or off: the same pixels, bit for bit (checked here directly on the films).
#[test]
fn profiling_on_or_off_gives_bit_identical_pixels() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let o = opts(IntegratorKind::PathTracer);
    let (scene, it) = prepare(&o).unwrap();
    let pool = strata::render::thread_pool(2).unwrap();
    let image = |on: bool| {
        strata::profile::set_enabled(on);
        let mut film = Film::new(scene.desc.width, scene.desc.height);
        let st = strata::render::render(&scene, &it, &mut film, 0..it.spp, &pool);
        strata::profile::set_enabled(false);
        (film.mean().iter().flatten().map(|v| v.to_bits()).collect::<Vec<u32>>(), st)
    };
    let (off, st_off) = image(false);
    let (on, st_on) = image(true);
    assert_eq!(off, on);
    assert_eq!(st_off.phase_ns, [0; strata::profile::N_PHASES], "profiling off records nothing");
    assert!(st_on.phase_ns.iter().sum::<u64>() > 0);
    assert_eq!(st_off.counters.total_rays(), st_on.counters.total_rays());
}

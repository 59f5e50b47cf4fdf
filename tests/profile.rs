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

/// `strata profile --json`: `sampler_replay` has this render's replayed ns per sample and one
/// `by_kind` entry per registered sampler, in registry order, each replaying the same calls; the
/// table prints them.
#[test]
fn cli_json_has_the_sampler_replay_with_one_entry_per_registered_kind() {
    let dir = std::env::temp_dir().join(format!("strata-profile-replay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("p.json");
    let r = std::process::Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(["profile", "--size", "32x24", "--spp", "2", "--threads", "2", "--repeats", "1"])
        .args(["--pixel-sampler", "sobol", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let out = String::from_utf8_lossy(&r.stdout);
    assert!(out.contains("sampler replay (pixel sobol, "), "{out}");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let rep = &j["sampler_replay"];
    assert!(rep["ns_per_sample"].as_f64().is_some_and(|v| v > 0.0), "{rep}");
    let calls = rep["calls"].as_u64().unwrap();
    assert!(calls > 0);
    assert_eq!(rep["samples"], 32 * 24 * 2);
    assert_eq!(rep["recorded_calls"].as_u64(), Some(calls), "a small render is replayed whole");
    assert_eq!(rep["subset"], false);
    let by_kind = rep["by_kind"].as_array().unwrap();
    let names: Vec<&str> = by_kind.iter().map(|k| k["kind"].as_str().unwrap()).collect();
    let registry: Vec<&str> = strata::sampler::SAMPLERS.iter().map(|s| s.name).collect();
    assert_eq!(names, registry);
    for k in by_kind {
        assert!(k["ns_per_sample"].as_f64().is_some_and(|v| v > 0.0), "{k}");
        assert_eq!(k["calls"].as_u64(), Some(calls));
        assert!(out.contains(k["kind"].as_str().unwrap()));
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A log capped below the render's size replays a subset of the tiles, says so, and still
/// counts every call of the render.
#[test]
fn a_capped_replay_says_it_is_a_scaled_subset() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let o = RenderOptions { size: Some((96, 64)), ..opts(IntegratorKind::PathTracer) };
    let full = strata::session::run_profile(&o, 1).unwrap().sampler_replay;
    let capped = strata::session::run_profile_capped(&o, 1, 2000).unwrap().sampler_replay;
    assert!(!full.subset && capped.subset);
    assert_eq!(capped.calls, full.calls);
    assert!(capped.recorded_calls < full.calls && capped.log_bytes <= 8000);
    assert!(capped.ns_per_sample.is_finite() && capped.ns_per_sample > 0.0);
    assert!(strata::session::replay::replay_table(&capped).contains("log capped"));
}

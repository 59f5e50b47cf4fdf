//! `strata profile`: the phase split covers the measured tile time, the right phases show up for
//! each integrator, and profiling never changes the image; `--svg`, and `--profile` on `render`,
//! `reference` and `compare`.

use crate::common;

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
        // The path tracer with every technique the phases name: NEE with MIS, BRDF sampling.
        nee: (kind == IntegratorKind::PathTracer).then_some(strata::scene::desc::Nee::Mis),
        importance_sampling: (kind == IntegratorKind::PathTracer)
            .then_some(strata::scene::desc::ImportanceSampling::Brdf),
        ..Default::default()
    }
}

fn share(p: &strata::session::Profile, prefix: &str) -> f64 {
    p.phases.iter().filter(|r| r.name.starts_with(prefix)).map(|r| r.seconds).sum()
}

/// On every integrator: the phases (timed with the TSC) sum to the tiles' time measured
/// independently with `Instant` within 2%, the profiled image is bit-identical to the unprofiled
/// one, and the phases each integrator must spend time in are non-zero (the built-in Cornell box
/// has a sphere and an ellipsoid, so the user-geometry callbacks run under every integrator).
#[test]
fn phases_sum_to_the_total_on_every_integrator_and_images_match() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    use IntegratorKind::*;
    for kind in [RayTracer, AnalyticDirect, Direct, PathTracer] {
        let p = run_profile(&opts(kind), 1).unwrap();
        assert!(p.total_seconds > 0.0, "{kind:?}");
        assert!((0.98..=1.02).contains(&p.phase_sum_ratio), "{kind:?}: phases sum to {}", p.phase_sum_ratio);
        assert_eq!(p.bit_identical, Some(true), "{kind:?}: profiling changed the image");
        assert!(p.overhead.is_some() && p.cpu_seconds_unprofiled.is_some());
        let shares: f64 = p.phases.iter().map(|r| r.share).sum();
        assert!((shares - p.phase_sum_ratio).abs() < 1e-9);
        assert!(share(&p, "embree intersect") > 0.0, "{kind:?}");
        assert!(share(&p, "hit gather") > 0.0, "{kind:?}");
        assert!(share(&p, "sampler: pixel") > 0.0 || kind == RayTracer, "{kind:?}");
        assert!(share(&p, "user geometry") > 0.0, "{kind:?}");
        assert!(share(&p, "film") > 0.0, "{kind:?}");
        assert_eq!(share(&p, "output encode"), 0.0, "strata profile writes no image");
        assert_eq!(p.samples, 48 * 40 * 4);
        match kind {
            Direct => {
                assert!(share(&p, "sampler: light") > 0.0 && share(&p, "emitter") > 0.0);
                assert!(share(&p, "embree occluded") > 0.0 && share(&p, "bsdf eval") > 0.0);
            }
            PathTracer => {
                for phase in ["sampler: path", "bsdf sampling", "bsdf eval", "mis weights", "embree occluded"] {
                    assert!(share(&p, phase) > 0.0, "path tracer: no time in {phase}");
                }
            }
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

/// Every phase of the table appears once, new ones included, with the names scripts match on.
#[test]
fn phase_names_are_the_documented_ones() {
    let names: Vec<&str> = strata::profile::PHASES.iter().map(|p| p.name()).collect();
    assert_eq!(names.len(), strata::profile::N_PHASES);
    for want in [
        "sampler: pixel/camera",
        "sampler: light",
        "embree intersect",
        "embree occluded",
        "user geometry (sphere/ellipsoid callbacks)",
        "hit gather",
        "bsdf sampling (lobe choice, warp)",
        "bsdf eval (value, pdf)",
        "mis weights",
        "accumulate",
        "film (tile copy and merge)",
        "output encode (exr, png)",
        "emitter sampling",
    ] {
        assert_eq!(names.iter().filter(|n| **n == want).count(), 1, "{want}");
    }
    assert!(names.iter().any(|n| n.starts_with("other")));
}

/// A scene without spheres or ellipsoids spends no time at all in user geometry: the nested phase
/// is only what the callbacks measured, never a share of Embree's time.
#[test]
fn user_geometry_is_zero_without_spheres() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/light_large.test");
    let o = RenderOptions { scene: Some(scene), ..opts(IntegratorKind::Direct) };
    let p = run_profile(&o, 1).unwrap();
    assert_eq!(share(&p, "user geometry"), 0.0);
    assert!(share(&p, "embree intersect") > 0.0);
    assert!((0.98..=1.02).contains(&p.phase_sum_ratio));
}

/// Minimal well-formedness check of an SVG: tags nest and close (comments, the XML declaration
/// skipped); returns the element names in order.
fn xml_elements(svg: &str) -> Vec<String> {
    let (mut stack, mut names, mut rest) = (Vec::<String>::new(), Vec::new(), svg);
    while let Some(i) = rest.find('<') {
        rest = &rest[i..];
        if let Some(r) = rest.strip_prefix("<!--") {
            rest = &r[r.find("-->").expect("unclosed comment") + 3..];
            continue;
        }
        let end = rest.find('>').expect("unclosed tag");
        let tag = &rest[1..end];
        rest = &rest[end + 1..];
        if tag.starts_with('?') {
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(name.trim()), "mismatched </{name}>");
            continue;
        }
        let name = tag.split_whitespace().next().unwrap_or("").trim_end_matches('/').to_string();
        names.push(name.clone());
        if !tag.ends_with('/') {
            stack.push(name);
        }
    }
    assert!(stack.is_empty(), "unclosed elements {stack:?}");
    names
}

fn run_ok(cmd: &mut std::process::Command) -> String {
    let out = cmd.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// `strata profile --svg`: a well-formed SVG with one bar and a legend entry per phase (shares in
/// %); `--json` has the documented keys, and the phases listed there are those of the chart.
#[test]
fn profile_cli_writes_svg_and_json() {
    let d = common::tmpdir("profile-svg");
    let (svg, json) = (d.join("p.svg"), d.join("p.json"));
    let table = run_ok(
        common::strata()
            .args(["profile", "--size", "32x24", "--spp", "2", "--threads", "1", "--repeats", "1"])
            .arg("--svg")
            .arg(&svg)
            .arg("--json")
            .arg(&json),
    );
    assert!(table.contains("bsdf eval") && table.contains("user geometry"), "{table}");
    let text = std::fs::read_to_string(&svg).unwrap();
    let names = xml_elements(&text);
    assert_eq!(names.first().map(String::as_str), Some("svg"));
    assert_eq!(text.matches("<g class=\"bar\">").count(), 1);
    assert_eq!(text.matches("<g class=\"legend-entry\">").count(), strata::profile::N_PHASES);
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for key in ["total_seconds", "phases", "overhead", "phase_sum_ratio", "bit_identical", "samples"] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    for ph in v["phases"].as_array().unwrap() {
        let name = ph["name"].as_str().unwrap();
        assert!(text.contains(&format!(">{} ", name.replace('&', "&amp;"))), "legend lacks {name}");
        for key in ["seconds", "share", "ns_per_sample", "ns_per_ray"] {
            assert!(ph.get(key).is_some(), "{name}: missing {key}");
        }
    }
}

/// `render --profile` and `reference --profile`: the images are bit-identical to the same render
/// without it, the profile JSON has the phases (output encode included: the command writes the
/// images) summing to its total, and the fields only `strata profile` measures are null.
#[test]
fn render_and_reference_profile_keep_images_bit_identical() {
    let d = common::tmpdir("render-profile");
    let base = ["--size", "40x32", "--spp", "4", "--threads", "2", "--integrator", "pathtracer", "-q"];
    for cmd in ["render", "reference"] {
        let (plain, profiled, json) =
            (d.join(format!("{cmd}-plain")), d.join(format!("{cmd}-prof")), d.join(format!("{cmd}.json")));
        run_ok(common::strata().arg(cmd).args(base).arg("-o").arg(&plain));
        run_ok(common::strata().arg(cmd).args(base).arg("-o").arg(&profiled).arg("--profile").arg(&json));
        let a = strata::film::read_exr(&plain.with_extension("exr")).unwrap();
        let b = strata::film::read_exr(&profiled.with_extension("exr")).unwrap();
        let bits = |img: &strata::film::ExrImage| img.rgb.iter().flatten().map(|v| v.to_bits()).collect::<Vec<u32>>();
        assert_eq!(bits(&a), bits(&b), "{cmd}: --profile changed the EXR pixels");
        let var_bits = |img: &strata::film::ExrImage| {
            img.variance.iter().flatten().flatten().map(|v| v.to_bits()).collect::<Vec<u32>>()
        };
        assert_eq!(var_bits(&a), var_bits(&b), "{cmd}: --profile changed the variance layer");
        assert_eq!(
            std::fs::read(plain.with_extension("png")).unwrap(),
            std::fs::read(profiled.with_extension("png")).unwrap()
        );
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let phases = v["phases"].as_array().unwrap();
        assert_eq!(phases.len(), strata::profile::N_PHASES);
        let secs = |prefix: &str| {
            phases
                .iter()
                .filter(|p| p["name"].as_str().unwrap().starts_with(prefix))
                .map(|p| p["seconds"].as_f64().unwrap())
                .sum::<f64>()
        };
        assert!(secs("output encode") > 0.0, "{cmd}: the image encoding is a phase");
        assert!(secs("sampler") > 0.0 && secs("embree intersect") > 0.0);
        let total = v["total_seconds"].as_f64().unwrap();
        let sum: f64 = phases.iter().map(|p| p["seconds"].as_f64().unwrap()).sum();
        assert!((sum / total - 1.0).abs() < 0.02, "{cmd}: phases sum to {sum} of {total}");
        assert_eq!(v["samples"].as_u64(), Some(40 * 32 * 4));
        assert!(v["overhead"].is_null() && v["bit_identical"].is_null());
    }
}

/// `compare --profile --profile-svg`: one profile per variant (JSON list with `variant`), one bar
/// per variant in the chart, and the comparison's own outputs as before.
#[test]
fn compare_profile_has_one_entry_and_bar_per_variant() {
    let d = common::tmpdir("compare-profile");
    let base = ["--size", "24x16", "--threads", "1", "-q", "--integrator", "direct"];
    run_ok(common::strata().args(["reference", "--spp", "16"]).args(base).arg("-o").arg(d.join("ref")));
    let (json, svg) = (d.join("cmp.json"), d.join("cmp.svg"));
    run_ok(
        common::strata()
            .args(["compare", "--reference"])
            .arg(d.join("ref.exr"))
            .args(["--variant", "strat=--light-sampler=stratified --integrator direct"])
            .args(["--variant", "indep=--light-sampler=independent --integrator direct"])
            .args(["--runs", "2", "--spp-ladder", "1,2", "--threads", "1", "--size", "24x16", "--out"])
            .arg(d.join("cmp"))
            .arg("--profile")
            .arg(&json)
            .arg("--profile-svg")
            .arg(&svg),
    );
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let list = v.as_array().unwrap();
    assert_eq!(list.iter().map(|e| e["variant"].as_str().unwrap()).collect::<Vec<_>>(), ["strat", "indep"]);
    for e in list {
        // The runs are timed unprofiled; one profiled render per step (at its spp below 16):
        // 1 + 2 samples per pixel in all.
        assert_eq!(e["samples"].as_u64(), Some(24 * 16 * 3));
        // What the profiler costs against the runs, and the runs' share outside the tiles.
        assert!(e["overhead"].as_f64().is_some() && e["cpu_seconds_unprofiled"].as_f64().unwrap() > 0.0, "{e}");
        assert!((0.0..1.0).contains(&e["overhead_share"].as_f64().unwrap()), "{e}");
        assert!(e["phases"]
            .as_array()
            .unwrap()
            .iter()
            .any(|p| p["name"] == "sampler: light" && p["seconds"].as_f64().unwrap() > 0.0));
    }
    let text = std::fs::read_to_string(&svg).unwrap();
    xml_elements(&text);
    assert_eq!(text.matches("<g class=\"bar\">").count(), 2);
    assert!(text.contains(">strat<") && text.contains(">indep<"));
    assert_eq!(text.matches("<g class=\"legend-entry\">").count(), strata::profile::N_PHASES);
    // The comparison's tables carry the sampler's cost of each row (2 variants x 2 ladder steps).
    let md = std::fs::read_to_string(d.join("cmp/table.md")).unwrap();
    assert!(md.lines().next().unwrap().contains("| sampler ns/sample | % of render in sampler |"), "{md}");
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("cmp/rows.json")).unwrap()).unwrap();
    assert_eq!(rows.as_array().unwrap().len(), 4);
    for r in rows.as_array().unwrap() {
        assert!(r["sampler_ns_per_sample"].as_f64().unwrap() > 0.0, "{r}");
        assert!((0.0..1.0).contains(&r["sampler_share"].as_f64().unwrap()), "{r}");
        assert!(r["seconds"].as_f64().unwrap() > 0.0);
    }
    let csv = std::fs::read_to_string(d.join("cmp/rows.csv")).unwrap();
    assert!(csv.lines().next().unwrap().contains(",sampler_ns_per_sample,sampler_share"));
}

/// An unwritable `--svg`/`--json` (profile), `--profile` (render) or `--profile-svg` (compare)
/// directory is a clear error before anything renders.
#[test]
fn unwritable_profile_outputs_fail_before_rendering() {
    let bad = std::path::Path::new("/nonexistent-strata-dir/p.svg");
    for args in [vec!["profile", "--svg"], vec!["profile", "--json"], vec!["render", "--profile"]] {
        let out = common::strata().args(&args).arg(bad).args(["--size", "8x8", "--spp", "1", "-q"]).output().unwrap();
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("/nonexistent-strata-dir: cannot write there"), "{args:?}: {err}");
    }
    let out = common::strata()
        .args(["compare", "--reference", "/nonexistent-ref.exr", "--variant", "a=--spp 1", "--spp-ladder", "1"])
        .arg("--profile-svg")
        .arg(bad)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("cannot write there"), "{err}");
}

/// `strata profile --json`: `sampler_replay` has this render's replayed ns per sample and one
/// `by_kind` entry per registered sampler, in registry order, each replaying the same calls; the
/// table prints them.
#[test]
fn cli_json_has_the_sampler_replay_with_one_entry_per_registered_kind() {
    let dir = crate::common::tmpdir("profile-replay");
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
}

/// A log capped below the render's size replays a subset of the tiles, says so, and still
/// counts every call of the render.
#[test]
fn a_capped_replay_says_it_is_a_scaled_subset() {
    let _g = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let o = RenderOptions { size: Some((96, 64)), ..opts(IntegratorKind::PathTracer) };
    let full = strata::session::run_profile(&o, 1).unwrap().sampler_replay.unwrap();
    let capped = strata::session::run_profile_capped(&o, 1, 2000).unwrap().sampler_replay.unwrap();
    assert!(!full.subset && capped.subset);
    assert_eq!(capped.calls, full.calls);
    assert!(capped.recorded_calls < full.calls && capped.log_bytes <= 8000);
    assert!(capped.ns_per_sample.is_finite() && capped.ns_per_sample > 0.0);
    assert!(strata::session::replay::replay_table(&capped).contains("log capped"));
}

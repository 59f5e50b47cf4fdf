//! The `strata` command line as other checks call it: flags, outputs, JSON keys, errors.

mod common;

use common::{strata, tmpdir};

#[test]
fn render_default_scene_writes_exr_png_and_stats() {
    let d = tmpdir("default");
    let out = d.join("img");
    let stats = d.join("stats.json");
    let r = strata()
        .args(["render", "--spp", "2", "--size", "64x48", "--seed", "3", "--threads", "2", "--light-sampler", "halton"])
        .arg("-o")
        .arg(&out)
        .arg("--stats")
        .arg(&stats)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let line = String::from_utf8_lossy(&r.stdout);
    assert!(line.contains("Mrays/s") && line.contains("64x48"), "summary: {line}");
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    for key in ["seconds", "spp", "width", "height", "rays", "mrays_per_sec", "threads"] {
        assert!(j.get(key).is_some(), "missing {key} in {j}");
    }
    assert_eq!(j["spp"], 2);
    assert_eq!(j["width"], 64);
    assert_eq!(j["height"], 48);
    assert_eq!(j["threads"], 2);
    assert_eq!(j["light_sampler"], "halton");
    assert_eq!(j["rays"]["camera"], 64 * 48 * 2);
    assert!(j["rays"]["shadow"].as_u64().unwrap() > 0);
    assert_eq!(j["nonfinite_samples"], 0);
    let img = strata::film::read_exr(&d.join("img.exr")).unwrap();
    assert_eq!((img.width, img.height), (64, 48));
    assert!(img.variance.is_some());
    let meta: std::collections::HashMap<_, _> = img.meta.into_iter().collect();
    assert_eq!(meta["strata.spp"], "2");
    assert_eq!(meta["strata.seed"], "3");
    assert_eq!(meta["strata.light_sampler"], "halton");
    assert!(meta.contains_key("strata.render_seconds") && meta.contains_key("strata.version"));
    assert!(std::fs::metadata(d.join("img.png")).unwrap().len() > 100);
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn bad_scene_is_a_clear_error_with_file_and_line() {
    let d = tmpdir("bad");
    let scene = d.join("bad.test");
    std::fs::write(&scene, "size 64 48\ncamera 0 0 5 0 0 0 0 1 0 45\nvertex 0 0 0\ntri 0 1 2\n").unwrap();
    let r = strata().arg("render").arg(&scene).arg("-o").arg(d.join("x")).output().unwrap();
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("bad.test:4:"), "stderr: {err}");
    assert!(!d.join("x.exr").exists());
    let r = strata().args(["render", "--size", "10x0"]).output().unwrap();
    assert!(!r.status.success());
    let r = strata().args(["render", "--light-sampler", "nonsense"]).output().unwrap();
    assert!(!r.status.success());
    assert!(String::from_utf8_lossy(&r.stderr).contains("nonsense"));
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn rays_reports_renderer_next_to_embree() {
    let r = strata().args(["rays", "--size", "48x48", "--spp", "1", "--json"]).output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let j: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    for key in ["renderer_mrays", "raw_camera_mrays", "raw_shadow_mrays", "raw_mixed_mrays", "ratio"] {
        assert!(j[key].as_f64().is_some_and(|v| v > 0.0), "{key} in {j}");
    }
    assert_eq!(j["camera_rays"], 48 * 48);
}

#[test]
fn reference_then_compare_writes_tables_and_plot() {
    let d = tmpdir("compare");
    let reference = d.join("ref");
    let r =
        strata().args(["reference", "--size", "32x24", "--spp", "16", "-q", "-o"]).arg(&reference).output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let img = strata::film::read_exr(&d.join("ref.exr")).unwrap();
    assert!(img.variance.is_some(), "a reference carries its variance layer");
    let out = d.join("cmp");
    let r = strata()
        .args(["compare", "--size", "32x24", "--runs", "2", "--spp-ladder", "1,2"])
        .arg("--reference")
        .arg(d.join("ref.exr"))
        .args([
            "--variant",
            "random=--light-sampler=independent",
            "--variant",
            "strat=--light-sampler=stratified --light-samples 4",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let csv = std::fs::read_to_string(out.join("rows.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 4, "header + 2 variants x 2 ladder steps:\n{csv}");
    let svg = std::fs::read_to_string(out.join("error.svg")).unwrap();
    assert!(svg.matches("<polyline").count() >= 3, "two series and the guide");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("rows.json")).unwrap()).unwrap();
    assert!(j.as_array().unwrap().iter().all(|r| r["mse"].as_f64().unwrap() > 0.0));
    // Bad variant options are a clear error.
    let r = strata()
        .args(["compare", "--runs", "2", "--spp-ladder", "1", "--reference"])
        .arg(d.join("ref.exr"))
        .args(["--variant", "x=--no-such-flag"])
        .output()
        .unwrap();
    assert!(!r.status.success());
    assert!(String::from_utf8_lossy(&r.stderr).contains("--variant x"));
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn path_tracer_flags_override_the_scene_and_reject_unknown_names() {
    let d = tmpdir("is");
    let stats = d.join("stats.json");
    let r = strata()
        .args(["render", "--integrator", "pathtracer", "--spp", "1", "--size", "16x16", "--threads", "2", "-q"])
        .args([
            "--importance-sampling",
            "cosine",
            "--nee",
            "mis",
            "--russian-roulette",
            "on",
            "--max-depth",
            "-1",
            "-o",
        ])
        .arg(d.join("img"))
        .arg("--stats")
        .arg(&stats)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(j["importance_sampling"], "cosine");
    assert_eq!(
        (j["nee"].as_str(), j["russian_roulette"].as_bool(), j["max_depth"].as_i64()),
        (Some("mis"), Some(true), Some(-1))
    );
    for (flag, value, msg) in [
        ("--nee", "always", "unknown next event estimation `always`"),
        ("--russian-roulette", "yes", "expected on or off"),
        ("--max-depth", "-2", "--max-depth -2 is outside"),
    ] {
        let bad = strata().args(["render", "--size", "8x8", flag, value]).output().unwrap();
        assert!(!bad.status.success(), "{flag} {value}");
        let err = String::from_utf8_lossy(&bad.stderr);
        assert!(err.contains(msg), "{flag} {value}: {err}");
    }
    let bad = strata().args(["render", "--importance-sampling", "phong"]).output().unwrap();
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("unknown importance sampling `phong`"), "{err}");
}

/// `strata profile` prints the phase table and writes the JSON contract's keys.
#[test]
fn profile_prints_phases_and_writes_json() {
    let d = tmpdir("profile");
    let json = d.join("profile.json");
    let r = strata()
        .args(["profile", "--size", "40x32", "--spp", "2", "--threads", "2", "--repeats", "1", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let out = String::from_utf8_lossy(&r.stdout);
    assert!(out.contains("embree intersect") && out.contains("ns/sample") && out.contains("overhead"), "{out}");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for key in ["total_seconds", "phases", "overhead", "phase_sum_ratio", "bit_identical", "samples", "rays"] {
        assert!(j.get(key).is_some(), "missing {key}");
    }
    assert_eq!(j["samples"], 40 * 32 * 2);
    assert_eq!(j["bit_identical"], true);
    let phases = j["phases"].as_array().unwrap();
    assert!(phases.iter().any(|p| p["name"].as_str().unwrap().starts_with("sampler")));
    for p in phases {
        for key in ["name", "seconds", "share", "ns_per_sample", "ns_per_ray"] {
            assert!(p.get(key).is_some(), "phase without {key}: {p}");
        }
    }
    let sum: f64 = phases.iter().map(|p| p["seconds"].as_f64().unwrap()).sum();
    let total = j["total_seconds"].as_f64().unwrap();
    assert!((sum / total - 1.0).abs() < 0.02, "phases {sum} of {total}");
}

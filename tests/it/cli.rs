//! The `strata` command line as other checks call it: flags, outputs, JSON keys, errors.

use crate::common;

use common::{strata, tmpdir};
use std::path::Path;

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
    // Issue 31: the process's CPU time over the passes and the share of it outside the tiles.
    let (process, tiles) = (j["process_cpu_seconds"].as_f64().unwrap(), j["cpu_seconds"].as_f64().unwrap());
    assert!(process > 0.0 && tiles > 0.0, "{j}");
    let share = j["overhead_share"].as_f64().unwrap();
    assert!((0.0..1.0).contains(&share), "{j}");
    let img = strata::film::read_exr(&d.join("img.exr")).unwrap();
    assert_eq!((img.width, img.height), (64, 48));
    assert!(img.variance.is_some());
    let meta: std::collections::HashMap<_, _> = img.meta.into_iter().collect();
    assert_eq!(meta["strata.spp"], "2");
    assert_eq!(meta["strata.seed"], "3");
    assert_eq!(meta["strata.light_sampler"], "halton");
    assert!(meta.contains_key("strata.render_seconds") && meta.contains_key("strata.version"));
    assert!(std::fs::metadata(d.join("img.png")).unwrap().len() > 100);
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
}

#[test]
fn rays_reports_renderer_next_to_embree() {
    let r = strata().args(["rays", "--size", "48x48", "--spp", "1", "--json"]).output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let j: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    for key in [
        "renderer_mrays",
        "raw_camera_mrays",
        "raw_shadow_mrays",
        "raw_mixed_mrays",
        "ratio",
        "raw16_mixed_mrays",
        "raw1_mixed_mrays",
    ] {
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
        ("--max-depth", "-2", "expected -1 (unbounded) or a depth >= 0, got `-2`"),
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
    // The JSON agrees with itself. How close the phases (tick clock) come to the total
    // (`Instant`) depends on the machine and its load, so no test bounds it here: that the phases
    // cover the tile exactly is `profile::tests`' (a clock the test drives).
    let sum: f64 = phases.iter().map(|p| p["seconds"].as_f64().unwrap()).sum();
    let total = j["total_seconds"].as_f64().unwrap();
    assert!(total > 0.0 && sum > 0.0, "phases {sum} of {total}");
    let ratio = j["phase_sum_ratio"].as_f64().unwrap();
    assert!((ratio - sum / total).abs() <= 1e-9 * ratio, "phase_sum_ratio {ratio}, phases {sum} of {total}");
    for p in phases {
        let (s, share) = (p["seconds"].as_f64().unwrap(), p["share"].as_f64().unwrap());
        assert!((share - s / total).abs() <= 1e-9, "{p}");
    }
}

// ---- One command-line grammar: one test per refusal, and the aliases. ----

/// Runs strata with `args`; asserts a usage error (exit status 2) whose stderr contains `msg`.
fn refused(args: &[&str], msg: &str) {
    let r = strata().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains(msg), "{args:?}: {err}");
}

const NO_IMAGE: &str = "measures and writes no image or checkpoint";

#[test]
fn rays_refuses_an_output_stem() {
    refused(&["rays", "-o", "x"], &format!("`strata rays` does not use -o/--out: it {NO_IMAGE}"));
}

#[test]
fn rays_refuses_a_checkpoint() {
    refused(&["rays", "--checkpoint", "x.ckpt"], "`strata rays` does not use --checkpoint");
}

#[test]
fn rays_refuses_a_time_budget() {
    refused(&["rays", "--time-budget", "3"], "`strata rays` does not use --time-budget");
}

#[test]
fn rays_refuses_a_sample_range() {
    refused(&["rays", "--samples", "0..4"], "`strata rays` does not use --samples");
}

#[test]
fn profile_refuses_an_output_stem() {
    refused(&["profile", "--out", "x"], &format!("`strata profile` does not use -o/--out: it {NO_IMAGE}"));
}

#[test]
fn profile_refuses_a_checkpoint() {
    refused(&["profile", "--checkpoint", "x.ckpt"], "`strata profile` does not use --checkpoint");
}

#[test]
fn profile_refuses_a_time_budget() {
    refused(&["profile", "--time-budget", "3"], "`strata profile` does not use --time-budget");
}

#[test]
fn profile_refuses_a_sample_range() {
    refused(&["profile", "--samples", "0..4"], "`strata profile` does not use --samples");
}

#[test]
fn reference_without_spp_is_an_error() {
    let d = tmpdir("ref-nospp");
    let out = d.join("ref");
    refused(&["reference", "-o", out.to_str().unwrap()], "`strata reference` needs --spp N");
    assert!(!d.join("ref.exr").exists() && !Path::new("cornell.exr").exists());
}

#[test]
fn a_negative_spp_says_what_is_allowed() {
    refused(&["render", "--spp", "-1"], "invalid value '-1' for '--spp <SPP>': expected a whole number >= 1");
}

#[test]
fn a_negative_count_says_what_is_allowed() {
    refused(&["render", "--threads", "-2"], "expected a whole number >= 0, got `-2`");
    refused(&["render", "--seed", "-3"], "expected a whole number >= 0, got `-3`");
    refused(&["render", "--light-samples", "-1"], "expected a whole number >= 1, got `-1`");
}

#[test]
fn a_negative_max_depth_says_what_is_allowed() {
    refused(&["render", "--max-depth", "-5"], "expected -1 (unbounded) or a depth >= 0, got `-5`");
}

#[test]
fn a_negative_budget_says_what_is_allowed() {
    refused(&["render", "--time-budget", "-1"], "expected a positive number of seconds, got `-1`");
    refused(&["compare", "--reference", "r.exr", "--variant", "a=", "--budget", "-1"], "expected a positive number");
}

/// Aliases that keep every existing flag: `--nthreads`, `--outfile`, `-o NAME.exr`, `--json` for
/// `--stats`, `--wall-budget` and `--cpu-budget`, centre/center, `rays --json` as a switch or with
/// `=FILE`.
#[test]
fn aliases_and_spellings_are_accepted() {
    let d = tmpdir("aliases");
    let stats = d.join("stats.json");
    let r = strata()
        .args(["render", "--nthreads", "2", "--spp", "1", "--size", "8x8", "-q", "--first-sample", "center"])
        .args(["--pixel-sampler", "grid-centre", "--json"])
        .arg(&stats)
        .arg("--outfile")
        .arg(d.join("img.exr"))
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    // `--outfile img.exr` is the stem `img`: img.exr and img.png, no img.exr.exr.
    assert!(d.join("img.exr").is_file() && d.join("img.png").is_file() && !d.join("img.exr.exr").exists());
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(j["threads"], 2, "{j}");
    // The budgets say which seconds they count.
    let help = String::from_utf8_lossy(&strata().args(["render", "--help"]).output().unwrap().stdout).into_owned();
    assert!(help.contains("--time-budget <WALL_SECONDS>") && help.contains("[alias: --wall-budget]"), "{help}");
    let help = String::from_utf8_lossy(&strata().args(["compare", "--help"]).output().unwrap().stdout).into_owned();
    assert!(help.contains("--budget <CPU_SECONDS>") && help.contains("--cpu-budget"), "{help}");
    // rays: `--json` alone prints JSON (as before), `--json=FILE` writes it and prints the table.
    let rays_json = d.join("rays.json");
    let r = strata()
        .args(["rays", "--size", "16x16", "--spp", "1"])
        .arg(format!("--json={}", rays_json.display()))
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(String::from_utf8_lossy(&r.stdout).contains("renderer / raw"));
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&rays_json).unwrap()).unwrap();
    assert_eq!(j["camera_rays"], 16 * 16);
}

/// The render flags are grouped under headings.
#[test]
fn render_help_groups_flags_under_headings() {
    let help = String::from_utf8_lossy(&strata().args(["render", "--help"]).output().unwrap().stdout).into_owned();
    let mut at = 0;
    for heading in ["Scene and camera:", "Sampling:", "Lights:", "Integrator:", "Output:", "Checkpoints:", "Limits:"] {
        let i = help.find(heading).unwrap_or_else(|| panic!("no {heading} in {help}"));
        assert!(i > at, "{heading} out of order");
        at = i;
    }
    let lights = &help[help.find("Lights:").unwrap()..help.find("Integrator:").unwrap()];
    for flag in ["--light-sampler", "--light-samples", "--light-selection", "--sky", "--no-default-light"] {
        assert!(lights.contains(flag), "{flag} not under Lights: {lights}");
    }
}

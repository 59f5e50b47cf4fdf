//! `strata compare` checks its inputs and is unbiased by default (issue 23): a reference of
//! another scene, size or camera is refused (naming both) unless `--force`; flags compare owns
//! and duplicate names are refused; variant flags take shell quoting; caps apply to the ladder;
//! variants that render the same image are said to and not ranked; `reference` and `compare`
//! default to the jittered first sample, so an unbiased technique's bias interval covers 0; the
//! convergence slope of independent light samples on direct9 is -1/2; compare runs on the XML
//! material preview (glass and metal, issue 30).
//!
//! Needs `../shared/cse168` (CI always has it: a missing corpus fails these tests), except the XML
//! test, whose scene is in the repository (`scenes/materials.xml`).
//! `STRATA_BIN` runs them against another build of `strata` (e.g. the one before this issue).

use crate::common;

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn strata() -> Command {
    Command::new(std::env::var_os("STRATA_BIN").unwrap_or_else(|| env!("CARGO_BIN_EXE_strata").into()))
}

/// Runs `cmd`, killing it after `limit` (a test must not hang on an uncapped render).
fn run(cmd: &mut Command, limit: Duration) -> Output {
    let mut child =
        cmd.stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped()).spawn().expect("strata starts");
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > limit {
            child.kill().ok();
            let out = child.wait_with_output().unwrap();
            panic!("still running after {limit:?}: {}", String::from_utf8_lossy(&out.stderr));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn ok(cmd: &mut Command) -> Output {
    let out = run(cmd, Duration::from_secs(300));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    out
}

fn reference(scene: &Path, size: &str, spp: u32, extra: &[&str], out: &Path) {
    ok(strata()
        .arg("reference")
        .arg(scene)
        .args(["--size", size, "--spp", &spp.to_string(), "-q"])
        .args(extra)
        .arg("-o")
        .arg(out));
}

fn compare(scene: &Path, reference: &Path, size: &str, args: &[&str], out: &Path) -> Output {
    run(
        strata()
            .arg("compare")
            .arg(scene)
            .arg("--reference")
            .arg(reference)
            .args(["--size", size, "--threads", "2"])
            .args(args)
            .arg("--out")
            .arg(out),
        Duration::from_secs(300),
    )
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn rows(dir: &Path) -> Vec<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("rows.json")).unwrap();
    serde_json::from_str::<serde_json::Value>(&text).unwrap().as_array().unwrap().clone()
}

#[test]
fn a_reference_of_another_scene_or_camera_is_refused_naming_both_unless_forced() {
    let (c, d) = (common::corpus_required(), common::tmpdir("cmp-ref"));
    let (sphere, direct9) = (c.join("hw2/sphere.test"), c.join("hw2/direct9.test"));
    reference(&direct9, "32x24", 8, &[], &d.join("d9"));
    let v = ["--runs", "2", "--spp-ladder", "1", "--variant", "a=--light-sampler independent"];
    let o = compare(&sphere, &d.join("d9.exr"), "32x24", &v, &d.join("c1"));
    let e = stderr(&o);
    assert!(!o.status.success(), "a reference of direct9 must not be accepted for sphere");
    assert!(e.contains("direct9.test") && e.contains("scene") && e.contains("--force"), "{e}");
    // --force compares anyway, and the outputs say so.
    let o = compare(&sphere, &d.join("d9.exr"), "32x24", &[&["--force"][..], &v].concat(), &d.join("c2"));
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(d.join("c2/table.md")).unwrap();
    assert!(md.contains("--force: compared anyway") && md.contains("direct9.test"), "{md}");
    assert!(std::fs::read_to_string(d.join("c2/report.html")).unwrap().contains("--force: compared anyway"));
    // Another size is refused even with --force.
    let o = compare(&direct9, &d.join("d9.exr"), "40x30", &[&["--force"][..], &v].concat(), &d.join("c3"));
    assert!(!o.status.success() && stderr(&o).contains("32x24") && stderr(&o).contains("40x30"), "{}", stderr(&o));
    // Another camera: refused naming both; a variant flag with shell quoting gives the same camera.
    let cam = "0.0001 0 -3 0 0 0 0 1 0 40";
    reference(&direct9, "32x24", 8, &["--camera", cam], &d.join("cam"));
    let o = compare(&direct9, &d.join("cam.exr"), "32x24", &v, &d.join("c4"));
    let e = stderr(&o);
    assert!(!o.status.success() && e.contains("camera") && e.contains("0.0001 0 -3 0 0 0 0 1 0 40"), "{e}");
    let quoted = format!("a=--light-sampler independent --camera '{cam}'");
    let o = compare(
        &direct9,
        &d.join("cam.exr"),
        "32x24",
        &["--runs", "2", "--spp-ladder", "1", "--variant", &quoted],
        &d.join("c5"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn owned_flags_duplicate_names_and_uncapped_ladders_are_refused_with_the_reason() {
    let (c, d) = (common::corpus_required(), common::tmpdir("cmp-flags"));
    let sphere = c.join("hw2/sphere.test");
    reference(&sphere, "24x18", 4, &[], &d.join("ref"));
    let r = d.join("ref.exr");
    for (flags, want) in [("--spp 4", "--spp"), ("--size 24x18", "--size"), ("-o elsewhere", "-o")] {
        let v = format!("a={flags}");
        let o = compare(&sphere, &r, "24x18", &["--runs", "2", "--spp-ladder", "1", "--variant", &v], &d.join("x"));
        assert!(!o.status.success(), "{flags} must be refused");
        assert!(stderr(&o).contains("--variant a") && stderr(&o).contains(want), "{flags}: {}", stderr(&o));
    }
    let o = compare(
        &sphere,
        &r,
        "24x18",
        &[
            "--runs",
            "2",
            "--spp-ladder",
            "1",
            "--variant",
            "a=--light-sampler independent",
            "--variant",
            "a=--light-sampler stratified",
        ],
        &d.join("x"),
    );
    assert!(!o.status.success() && stderr(&o).contains("given twice"), "{}", stderr(&o));
    // The spp cap applies to every ladder step: refused at once, not rendered until killed.
    let o = compare(
        &sphere,
        &r,
        "24x18",
        &["--runs", "2", "--spp-ladder", "1,4294967295", "--variant", "a=--light-samples 1"],
        &d.join("x"),
    );
    assert!(!o.status.success() && stderr(&o).contains("max_spp"), "{}", stderr(&o));
}

#[test]
fn variants_that_render_the_same_image_are_named_and_not_ranked() {
    let (c, d) = (common::corpus_required(), common::tmpdir("cmp-same"));
    let sphere = c.join("hw2/sphere.test");
    reference(&sphere, "24x18", 8, &[], &d.join("ref"));
    let o = compare(
        &sphere,
        &d.join("ref.exr"),
        "24x18",
        &[
            "--runs",
            "2",
            "--spp-ladder",
            "1,2",
            "--variant",
            "a=--light-sampler independent",
            "--variant",
            "b=--light-sampler independent --russian-roulette on",
            "--variant",
            "c=--light-sampler stratified",
            "--baseline",
            "c",
        ],
        &d.join("out"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(d.join("out/table.md")).unwrap();
    assert!(
        md.contains(
            "variants a and b render the same image: flag --russian-roulette on has no effect on this integrator"
        ),
        "{md}"
    );
    let rows = rows(&d.join("out"));
    for r in &rows {
        match r["variant"].as_str().unwrap() {
            "b" => assert!(r["same_as"] == "a" && r["eff_vs_baseline"].is_null(), "{r}"),
            // The baseline is 1 at every spp step; integer spp.
            "c" => assert_eq!(r["eff_vs_baseline"].as_f64(), Some(1.0), "{r}"),
            _ => assert!(r["same_as"].is_null() && r["eff_vs_baseline"].as_f64().unwrap() > 0.0, "{r}"),
        }
    }
    assert!(md.contains("same image as a"), "{md}");
    // Progress: stderr is not a terminal here, so a plain line per run (3 variants x 2 steps x 2 runs).
    let lines: Vec<String> = stderr(&o).lines().filter(|l| l.starts_with("compare: run ")).map(String::from).collect();
    assert_eq!(lines.len(), 12, "{}", stderr(&o));
    assert!(lines[0].starts_with("compare: run 1/12 (a at 1 spp)") && lines[11].contains("ETA"), "{lines:?}");
}

/// The direct9 case: `--runs 4 --spp-ladder 1,4,16`, independent against stratified light
/// samples. With the defaults (jittered first sample) neither shows a bias interval excluding 0,
/// and the variance falls as the spp grows; the fitted slope of independent light samples (pixel
/// jitter independent too, so every sample is i.i.d.) is -1/2 within its interval.
#[test]
fn defaults_are_unbiased_and_independent_samples_converge_at_slope_minus_one_half() {
    let (c, d) = (common::corpus_required(), common::tmpdir("cmp-d9"));
    let direct9 = c.join("hw2/direct9.test");
    reference(&direct9, "64x48", 512, &[], &d.join("ref"));
    let meta = strata::film::read_exr(&d.join("ref.exr")).unwrap().meta;
    assert!(meta.contains(&("strata.first_sample".into(), "jittered".into())), "reference default: {meta:?}");
    let o = compare(
        &direct9,
        &d.join("ref.exr"),
        "64x48",
        &[
            "--runs",
            "4",
            "--spp-ladder",
            "1,4,16",
            "--variant",
            "independent=--light-sampler independent --pixel-sampler independent",
            "--variant",
            "stratified=--light-sampler stratified --pixel-sampler independent",
        ],
        &d.join("out"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = rows(&d.join("out"));
    assert_eq!(rows.len(), 6);
    for r in &rows {
        let ci = r["bias_ci"].as_array().unwrap();
        let (lo, hi) = (ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap());
        assert!(lo <= 0.0 && 0.0 <= hi, "an unbiased variant's bias interval must cover 0: {r}");
        assert_eq!(r["first_sample"], "jittered");
    }
    for v in [0, 3] {
        let var = |i: usize| rows[v + i]["variance"].as_f64().unwrap();
        assert!(var(0) > var(1) && var(1) > var(2), "variance must fall with spp: {:?}", &rows[v..v + 3]);
    }
    let md = std::fs::read_to_string(d.join("out/table.md")).unwrap();
    let line = md.lines().find(|l| l.starts_with("| independent | ") && l.matches('[').count() == 2).unwrap();
    let nums: Vec<f64> = line.split(['|', '[', ']', ',']).filter_map(|s| s.trim().parse().ok()).collect();
    let (slope, lo, hi) = (nums[0], nums[1], nums[2]);
    assert!(lo <= -0.5 && -0.5 <= hi, "slope of independent vs spp {slope} [{lo}, {hi}] must cover -0.5: {md}");
    assert!(hi - lo < 0.3, "the interval must be informative: [{lo}, {hi}]");
    let runs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("out/runs.json")).unwrap()).unwrap();
    assert_eq!(runs.as_array().unwrap().len(), 2 * 3 * 4, "one row per run");
    assert_eq!(std::fs::read_to_string(d.join("out/runs.csv")).unwrap().lines().count(), 1 + 24);
}

/// A noisy reference (few spp): its variance layer enters the bias test and the noise-corrected
/// MSE. Without it the bias interval of an unbiased variant, from the runs' spread alone, would
/// exclude 0 here (the reference's own error dominates); with it the interval covers 0.
#[test]
fn the_references_variance_layer_enters_the_bias_test_and_the_corrected_mse() {
    let (c, d) = (common::corpus_required(), common::tmpdir("cmp-noisyref"));
    let direct9 = c.join("hw2/direct9.test");
    reference(&direct9, "32x24", 2, &[], &d.join("ref"));
    let img = strata::film::read_exr(&d.join("ref.exr")).unwrap();
    let var = img.variance.expect("a reference has a variance layer");
    let ref_var = var.iter().flatten().map(|&v| f64::from(v)).sum::<f64>() / (3 * var.len()) as f64;
    let o = compare(
        &direct9,
        &d.join("ref.exr"),
        "32x24",
        &["--runs", "8", "--spp-ladder", "64", "--variant", "independent=--light-sampler independent"],
        &d.join("out"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let row = &rows(&d.join("out"))[0];
    let (mse, corrected) = (row["mse"].as_f64().unwrap(), row["mse_corrected"].as_f64().unwrap());
    assert!((mse - corrected - ref_var).abs() <= 1e-9 * mse.max(1e-30) + 1e-12, "{mse} - {corrected} vs {ref_var}");
    let ci = row["bias_ci"].as_array().unwrap();
    let (lo, hi) = (ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap());
    assert!(lo <= 0.0 && 0.0 <= hi, "with the reference's noise the interval covers 0: [{lo}, {hi}]");
    // From the runs' spread alone (runs.json), the interval would exclude 0.
    let runs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("out/runs.json")).unwrap()).unwrap();
    let e: Vec<f64> = runs.as_array().unwrap().iter().map(|r| r["mean_error"].as_f64().unwrap()).collect();
    let k = e.len() as f64;
    let mean = e.iter().sum::<f64>() / k;
    let se = (e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0) / k).sqrt();
    let t = strata::report::student_t_quantile(0.975, k - 1.0);
    assert!(mean.abs() > t * se, "this case must need the reference's noise: {mean} +- {}", t * se);
}

/// Issue 31: `--budget 0.005,0.01,0.02` is a budget ladder: one row per budget and variant, a slope
/// against CPU seconds for each variant, and the efficiency column headed "same budget" (the
/// variants reach different spp). Before, a list of budgets was refused.
#[test]
fn a_budget_ladder_gives_slopes_against_time() {
    let (c, d) = (common::corpus_required(), common::tmpdir("cmp-budgets"));
    let direct9 = c.join("hw2/direct9.test");
    reference(&direct9, "32x24", 4096, &[], &d.join("ref"));
    let o = compare(
        &direct9,
        &d.join("ref.exr"),
        "32x24",
        &[
            "--runs",
            "3",
            "--budget",
            "0.005,0.01,0.02",
            "--variant",
            "independent=--light-sampler independent",
            "--variant",
            "sobol=--light-sampler sobol",
        ],
        &d.join("out"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let rows = rows(&d.join("out"));
    assert_eq!(rows.len(), 6, "one row per variant and budget");
    let table = std::fs::read_to_string(d.join("out/table.md")).unwrap();
    assert!(table.contains("eff. vs baseline, same budget"), "{table}");
    for v in ["independent", "sobol"] {
        let line = table.lines().find(|l| l.starts_with(&format!("| {v} |")) && l.matches('|').count() == 4).unwrap();
        let vs_seconds = line.split('|').nth(3).unwrap().trim();
        assert!(vs_seconds.starts_with('-'), "{v}: slope against CPU seconds {vs_seconds} ({table})");
    }
    let runs: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(d.join("out/runs.json")).unwrap()).unwrap();
    let budgets: std::collections::BTreeSet<String> = runs.iter().map(|r| r["budget"].to_string()).collect();
    assert_eq!(budgets.len(), 3, "{budgets:?}");
}

/// Issue 30: `compare` runs on a Mitsuba XML scene with glass and metal (`scenes/materials.xml`:
/// dielectric, roughdielectric, conductor, roughconductor, plastic, roughplastic, diffuse) with
/// three samplers against a `strata reference`, loads it without warnings, and writes its table:
/// every variant at every spp step, finite positive errors, the slopes and the provenance.
#[test]
fn compare_runs_on_an_xml_scene_with_glass_and_metal_and_writes_its_table() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/materials.xml");
    let text = std::fs::read_to_string(&scene).unwrap_or_else(|e| panic!("{}: {e}", scene.display()));
    for bsdf in ["dielectric", "roughdielectric", "conductor", "roughconductor"] {
        assert!(text.contains(&format!("<bsdf type=\"{bsdf}\"")), "{} has no {bsdf}", scene.display());
    }
    let d = common::tmpdir("cmp-xml");
    reference(&scene, "48x27", 16, &[], &d.join("ref"));
    let o = compare(
        &scene,
        &d.join("ref.exr"),
        "48x27",
        &[
            "--runs",
            "2",
            "--spp-ladder",
            "1,4",
            "--variant",
            "independent=--sampler independent",
            "--variant",
            "stratified=--sampler stratified",
            "--variant",
            "sobol=--sampler sobol",
            "--baseline",
            "independent",
        ],
        &d.join("out"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "the scene must load without warnings: {}", stderr(&o));
    let rows = rows(&d.join("out"));
    assert_eq!(rows.len(), 3 * 2, "{rows:?}");
    for (r, (variant, spp)) in
        rows.iter().zip(["independent", "stratified", "sobol"].iter().flat_map(|v| [(*v, 1.0), (*v, 4.0)]))
    {
        assert_eq!((r["variant"].as_str(), r["spp"].as_f64()), (Some(variant), Some(spp)), "{r}");
        let mse = r["mse"].as_f64().unwrap();
        assert!(mse.is_finite() && mse > 0.0, "{r}");
    }
    let md = std::fs::read_to_string(d.join("out/table.md")).unwrap();
    for v in ["independent", "stratified", "sobol"] {
        assert_eq!(md.lines().filter(|l| l.starts_with(&format!("| {v} "))).count(), 3, "2 rows + 1 slope: {md}");
    }
    assert!(md.contains("materials.xml") && md.contains("Provenance"), "{md}");
    // The provenance prints its numbers as a person would write them (was "0.10000000000000009%").
    assert!(md.contains("the largest 0.1% of squared errors dropped"), "{md}");
}

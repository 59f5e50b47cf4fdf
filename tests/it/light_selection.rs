//! Light selection is a sampling technique: `all`, `uniform`, `power` and `spatial` estimate the
//! same image. Per-pixel z-tests between independent renders (fixed seeds, the film's variance
//! of the mean) on hw4 `mis.test`, on the many-light scene and on a scene with emissive OBJ
//! triangles next to quad lights; NEE with MIS agrees with NEE alone for every strategy (each
//! strategy's own pmf in the MIS weights); and `strata compare` runs the strategies as variants.

use crate::common;

use common::*;
use std::path::{Path, PathBuf};
use strata::integrator::LightSelection;
use strata::scene::desc::Nee;
use strata::session::RenderOptions;

/// Clamp of the negative control in `strategies_agree_on_many_lights`.
const CLAMP: f32 = 30.0;

/// Every registered light-selection rule, in registry order (`all` first).
fn rules() -> Vec<LightSelection> {
    LightSelection::every().collect()
}

/// Per-pixel mean and variance of the mean of one render.
struct Est {
    name: String,
    w: u32,
    mean: Vec<[f64; 3]>,
    var: Vec<[f64; 3]>,
}

/// Renders `scene` at `w`x`h`, `spp`, `seed` with light selection `sel` and NEE `nee` (None: the
/// scene's), jittered sample 0 (so that sample 0 is not shared by all renders).
fn estimate(scene: &Path, (w, h): (u32, u32), spp: u32, seed: u64, sel: LightSelection, nee: Option<Nee>) -> Est {
    let o = RenderOptions {
        seed,
        light_selection: Some(sel),
        nee,
        first_sample: Some(strata::camera::FirstSample::Jittered),
        ..opts(scene.to_path_buf(), w, h, spp)
    };
    let out = strata::session::render_to_film(&o).unwrap_or_else(|e| panic!("{}: {e}", scene.display()));
    assert_eq!(out.stats.counters.nonfinite, 0, "{sel}: non-finite samples");
    let name = format!("{sel}{}", nee.map_or(String::new(), |n| format!("/{n:?}")));
    Est { name, w, mean: means(&out.film), var: var_of_mean(&out.film) }
}

/// [`estimate`] with the `direct` integrator and `n` light samples.
fn estimate_direct(scene: &Path, (w, h): (u32, u32), spp: u32, n: u32, seed: u64, sel: LightSelection) -> (Est, u64) {
    let o = RenderOptions {
        seed,
        light_selection: Some(sel),
        integrator: Some(strata::scene::desc::IntegratorKind::Direct),
        light_samples: Some(n),
        first_sample: Some(strata::camera::FirstSample::Jittered),
        ..opts(scene.to_path_buf(), w, h, spp)
    };
    let out = strata::session::render_to_film(&o).unwrap_or_else(|e| panic!("{}: {e}", scene.display()));
    assert_eq!(out.stats.counters.nonfinite, 0, "direct {sel}: non-finite samples");
    assert_eq!(strata::session::stats_json(&out)["light_selection"], sel.name());
    assert!(strata::session::summary(&out).contains(&format!("lights {sel}")));
    let est = Est { name: format!("direct {sel}"), w, mean: means(&out.film), var: var_of_mean(&out.film) };
    (est, out.stats.counters.shadow)
}

/// Agreement of two independent estimates of the same image.
#[derive(Debug)]
struct Agreement {
    /// z of the difference of the two image sums (all pixel channels)
    z_mean: f64,
    /// fraction of block channels (with variance) where |z| > 3
    frac_3: f64,
    /// channels compared
    channels: usize,
}

/// z-tests of the difference of two independent renders over `block`x`block` pixel blocks (1: per
/// pixel), channel by channel, with the films' variances of the mean.
fn agreement(a: &Est, b: &Est, block: usize) -> Agreement {
    let (w, h) = (a.w as usize, a.mean.len() / a.w as usize);
    let (mut d, mut v, mut out, mut n) = (0.0, 0.0, 0usize, 0usize);
    for by in (0..h).step_by(block) {
        for bx in (0..w).step_by(block) {
            for c in 0..3 {
                // Block sums of the pixel means and of their variances (pixels are independent).
                let (mut diff, mut var) = (0.0, 0.0);
                for y in by..(by + block).min(h) {
                    for x in bx..(bx + block).min(w) {
                        let i = y * w + x;
                        diff += a.mean[i][c] - b.mean[i][c];
                        var += a.var[i][c] + b.var[i][c];
                    }
                }
                if var == 0.0 {
                    // Both estimators constant here (background, a light seen directly): equal.
                    assert!(
                        diff.abs() <= 1e-5,
                        "{} vs {}: zero-variance block ({bx}, {by}) differs by {diff}",
                        a.name,
                        b.name
                    );
                    continue;
                }
                n += 1;
                out += usize::from((diff / var.sqrt()).abs() > 3.0);
                d += diff;
                v += var;
            }
        }
    }
    Agreement { z_mean: if v > 0.0 { d / v.sqrt() } else { 0.0 }, frac_3: out as f64 / n.max(1) as f64, channels: n }
}

/// Asserts that every pair of `ests` agrees: image-sum |z| < 4.5 (Gaussian false alarm 7e-6 per
/// pair) and at most `max_frac` of the (block) channels beyond |z| = 3 (0.27% for Gaussian z; the
/// bound leaves room for the heavy tails of per-pixel variance estimates).
fn assert_all_agree(scene: &str, ests: &[Est], block: usize, max_frac: f64) {
    for (i, a) in ests.iter().enumerate() {
        for b in &ests[i + 1..] {
            let g = agreement(a, b, block);
            eprintln!(
                "{scene}: {} vs {}: z(mean) = {:+.2}, |z| > 3 in {:.2}% of {} channels",
                a.name,
                b.name,
                g.z_mean,
                100.0 * g.frac_3,
                g.channels
            );
            assert!(g.channels > 0, "{scene}: nothing to compare");
            assert!(g.z_mean.abs() < 4.5, "{scene}: {} and {} disagree on the image mean: {g:?}", a.name, b.name);
            assert!(g.frac_3 <= max_frac, "{scene}: {} and {} disagree per pixel: {g:?}", a.name, b.name);
        }
    }
}

fn scene_dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes"))
}

/// hw4 `mis.test` (direct lighting of glossy panels by five lights: the big overhead light carries
/// 99.9% of the power, four small panel lights 1/4247 each): all four strategies agree, with MIS
/// (the scene's) and with NEE alone (on panels roughened to 0.07..0.15: light sampling of the
/// near-mirror panels, roughness 0.0005, is too heavy-tailed for any z-test).
#[test]
fn strategies_agree_on_mis_test() {
    let c = corpus_required();
    let scene = c.join("hw4/mis.test");
    let size = (96, 64);
    let mut mis = Vec::new();
    for (k, sel) in rules().into_iter().enumerate() {
        // `all` samples five lights per vertex: fewer samples for similar noise and time.
        let spp = if sel == LightSelection::ALL { 128 } else { 256 };
        mis.push(estimate(&scene, size, spp, 10 + k as u64, sel, None));
    }
    let power = mis.remove(2);
    assert_all_agree("mis.test", &mis, 1, 0.02);
    // `power` picks a panel light once in ~1000 samples although the four of them give about a
    // fifth of the floor's light (they are ten times closer than the overhead light): per pixel
    // at 256 spp its estimate is heavy-tailed (most pixels never sampled them), so 8x8 blocks.
    for other in &mis {
        let g = agreement(&power, other, 8);
        eprintln!("mis.test: power vs {} (8x8 blocks): {g:?}", other.name);
        assert!(g.z_mean.abs() < 4.5, "mis.test: power and {} disagree on the image mean: {g:?}", other.name);
        assert!(g.frac_3 <= 0.1, "mis.test: power and {} disagree per block: {g:?}", other.name);
    }
    let (_rough_dir, rough) = scene_variant(&scene, "mis-rough", &[], "");
    let text = std::fs::read_to_string(&rough)
        .unwrap()
        .replace("roughness 0.0005", "roughness 0.15")
        .replace("roughness 0.008", "roughness 0.1");
    std::fs::write(&rough, text).unwrap();
    for (k, sel) in rules().into_iter().enumerate() {
        let spp = if sel == LightSelection::ALL { 128 } else { 256 };
        let block = if sel == LightSelection::named("power") { 8 } else { 1 };
        let on = estimate(&rough, size, spp, 20 + k as u64, sel, Some(Nee::On));
        let with_mis = estimate(&rough, size, spp, 30 + k as u64, sel, Some(Nee::Mis));
        let g = agreement(&on, &with_mis, block);
        eprintln!("mis.test (rough panels) {sel}: NEE on vs MIS: {g:?}");
        assert!(g.z_mean.abs() < 4.5, "mis.test {sel}: NEE on and MIS disagree: {g:?}");
        assert!(
            g.frac_3 <= if block == 1 { 0.02 } else { 0.1 },
            "mis.test {sel}: NEE on and MIS disagree per pixel: {g:?}"
        );
    }
}

/// `base` (a scene file) with the lines starting with one of the `drop` keywords removed and
/// `extra` appended, written to a scratch file named `name`.
fn scene_variant(base: &Path, name: &str, drop: &[&str], extra: &str) -> (common::Scratch, PathBuf) {
    let text = std::fs::read_to_string(base).unwrap();
    let mut out: String = text
        .lines()
        .filter(|l| !drop.iter().any(|k| l.trim_start().starts_with(k)))
        .map(|l| format!("{l}\n"))
        .collect();
    out += extra;
    let d = tmpdir("lightsel");
    let p = d.join(format!("{name}.test"));
    std::fs::write(&p, out).unwrap();
    (d, p)
}

/// The many-light scene (2500 quads of mixed power and size over a glossy floor, two bounces),
/// seen from below the lights looking down at the floor: every light is reached through NEE or
/// a BSDF sample (MIS), none directly through a pixel (a light covering 1% of a pixel would make
/// the low-spp `all` renders' pixel variance estimates meaningless). All four strategies agree, and
/// MIS agrees with NEE alone for every strategy. A different light transport (one bounce less)
/// fails the same test, so it has power.
#[test]
fn strategies_agree_on_many_lights() {
    let (_dir, scene) =
        scene_variant(&scene_dir().join("manylights.test"), "many", &["camera"], "camera 0 1.5 3  0 0 -1  0 1 0  30\n");
    let size = (32, 24);
    let mut mis = Vec::new();
    for (k, sel) in rules().into_iter().enumerate() {
        // `all` traces 2500 shadow rays per vertex. One light of 2500 per sample is heavy-tailed:
        // at 512 spp the per-pixel variance estimates still miss the rare large contributions
        // (image-mean |z| up to ~5 between unbiased strategies), hence 2048.
        let spp = if sel == LightSelection::ALL { 16 } else { 2048 };
        mis.push(estimate(&scene, size, spp, 30 + k as u64, sel, None));
    }
    // One light of 2500 per sample is heavy-tailed per pixel (the few lights that matter at a
    // point are picked rarely), so 2x2-pixel blocks and a 5% bound (Gaussian: 0.27%).
    assert_all_agree("manylights", &mis, 2, 0.05);
    // NEE alone at 2048 spp too: at 512 the per-pixel variance estimates of the one-light rules
    // miss rare large contributions as the MIS renders' did, and the share of |z| > 3 pixels
    // ranged 3-8 % over seeds for every sampler (independent, stratified, multijitter); at 2048
    // it is 0-1.7 % over 4 seeds of each.
    for (k, sel) in rules().into_iter().enumerate() {
        let spp = if sel == LightSelection::ALL { 16 } else { 2048 };
        let on = estimate(&scene, size, spp, 40 + k as u64, sel, Some(Nee::On));
        let g = agreement(&on, &mis[k], 2);
        eprintln!("manylights {sel}: NEE on vs MIS: {g:?}");
        assert!(g.z_mean.abs() < 4.5, "manylights {sel}: NEE on and MIS disagree: {g:?}");
        assert!(g.frac_3 <= 0.05, "manylights {sel}: NEE on and MIS disagree per pixel: {g:?}");
    }
    // Power: a 2% darkening (a clamp of the brightest samples) is caught by the same test.
    let o = RenderOptions {
        seed: 50,
        clamp: Some(CLAMP),
        light_selection: Some(LightSelection::named("spatial")),
        first_sample: Some(strata::camera::FirstSample::Jittered),
        ..opts(scene, size.0, size.1, 512)
    };
    let out = strata::session::render_to_film(&o).unwrap();
    let biased = Est { name: "clamped".into(), w: size.0, mean: means(&out.film), var: var_of_mean(&out.film) };
    let g = agreement(&biased, &mis[0], 2);
    let sum = |e: &Est| e.mean.iter().flatten().sum::<f64>();
    eprintln!(
        "manylights: clamped spatial vs all: {g:?}, darker by {:.2}%",
        100.0 * (1.0 - sum(&biased) / sum(&mis[0]))
    );
    assert!(g.z_mean.abs() > 4.5 || g.frac_3 > 0.05, "a biased estimate should be detected: {g:?}");
}

/// The OBJ Cornell box (two emissive triangles) with two quad lights added, path traced to depth 3.
fn triangles_and_quads() -> (common::Scratch, PathBuf) {
    common::cornell_obj_with(
        "lightsel-tri",
        "quadLight -0.9 1.2 -0.98  0 0.2 0  0.2 0 0  40 10 10\nquadLight -0.98 0.3 0.6  0 0.6 0  0 0 -0.6  0.5 0.5 1.5\n",
    )
}

/// A scene with emissive OBJ triangles (the OBJ Cornell box's ceiling patch) and two quad lights
/// of very different power: quads and triangles share one index space in every strategy.
#[test]
fn strategies_agree_with_emissive_triangles() {
    let (_dir, scene) = triangles_and_quads();
    let mut mis = Vec::new();
    for (k, sel) in rules().into_iter().enumerate() {
        mis.push(estimate(&scene, (32, 32), 256, 60 + k as u64, sel, None));
    }
    assert_all_agree("emissive triangles", &mis, 1, 0.02);
    for (k, sel) in rules().into_iter().enumerate() {
        let on = estimate(&scene, (32, 32), 256, 70 + k as u64, sel, Some(Nee::On));
        let g = agreement(&on, &mis[k], 1);
        eprintln!("emissive triangles {sel}: NEE on vs MIS: {g:?}");
        assert!(g.z_mean.abs() < 4.5, "emissive triangles {sel}: NEE on and MIS disagree: {g:?}");
        assert!(g.frac_3 <= 0.02, "emissive triangles {sel}: NEE on and MIS disagree per pixel: {g:?}");
    }
}

/// `strata compare` runs the four strategies as variants (`--light-selection` in the variant
/// flags) and reports one row per strategy.
#[test]
fn compare_runs_light_selections_as_variants() {
    let d = tmpdir("lightsel-compare");
    let scene = scene_dir().join("manylights.test");
    let st = strata()
        .args(["reference"])
        .arg(&scene)
        .args(["--size", "16x12", "--spp", "16", "--light-selection", "power", "-q", "-o"])
        .arg(d.join("ref"))
        .status()
        .unwrap();
    assert!(st.success());
    let mut cmd = strata();
    cmd.arg("compare").arg(&scene).arg("--reference").arg(d.join("ref.exr"));
    cmd.args(["--size", "16x12", "--runs", "2", "--spp-ladder", "2", "--threads", "2", "--out"]).arg(d.join("cmp"));
    for sel in ["uniform", "power", "spatial", "all"] {
        cmd.arg("--variant").arg(format!("{sel}=--light-selection={sel} --max-depth=1"));
    }
    let out = cmd.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("cmp/rows.json")).unwrap()).unwrap();
    let names: Vec<&str> = rows.as_array().unwrap().iter().map(|r| r["variant"].as_str().unwrap()).collect();
    assert_eq!(names, ["uniform", "power", "spatial", "all"]);
    // `all` samples every one of the 2500 lights: far less noise per sample than one light.
    let mse = |i: usize| rows[i]["mse"].as_f64().unwrap();
    assert!(mse(3) < mse(0), "all {} vs uniform {}", mse(3), mse(0));
    let bad = strata()
        .arg("compare")
        .arg(&scene)
        .arg("--reference")
        .arg(d.join("ref.exr"))
        .args(["--size", "16x12", "--runs", "2", "--spp-ladder", "1", "--variant", "x=--light-selection=nearest"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("nearest") && err.contains("spatial"), "{err}");
}

/// The `.test` keyword `lightselection` picks the strategy (stats and summary say so), and
/// `--light-selection` overrides it; a bad value is refused with file and line.
#[test]
fn scene_keyword_and_flag_override() {
    let pt = "integrator pathtracer\nnexteventestimation on\nlightselection power\n";
    let (_dir, scene) = scene_variant(&scene_dir().join("cornell.test"), "kw", &["integrator"], pt);
    let o = opts(scene.clone(), 8, 8, 1);
    let out = strata::session::render_to_film(&o).unwrap();
    assert_eq!(strata::session::stats_json(&out)["light_selection"], "power");
    assert!(strata::session::summary(&out).contains("lights power"), "{}", strata::session::summary(&out));
    let o = RenderOptions { light_selection: Some(LightSelection::UNIFORM), ..opts(scene, 8, 8, 1) };
    let out = strata::session::render_to_film(&o).unwrap();
    assert_eq!(strata::session::stats_json(&out)["light_selection"], "uniform");
    let (_bad_dir, bad) = scene_variant(&scene_dir().join("cornell.test"), "kw-bad", &[], "lightselection nearest\n");
    let lines = std::fs::read_to_string(&bad).unwrap().lines().count();
    let e = strata::session::render_to_film(&opts(bad, 8, 8, 1)).err().expect("refused").to_string();
    assert!(e.contains(&format!("kw-bad.test:{lines}")) && e.contains("all|uniform|power|spatial"), "{e}");
}

/// `direct` with `uniform`, `power` or `spatial` picks one light per light sample (one shadow ray
/// per sample, however many lights) and agrees with its loop over every light (`all`), on quads
/// and emissive triangles together; stats and summary name the strategy.
#[test]
fn direct_picks_one_light_per_sample() {
    let (_dir, scene) = triangles_and_quads();
    let (size, n) = ((32, 32), 2);
    let (all, all_rays) = estimate_direct(&scene, size, 64, n, 80, LightSelection::ALL);
    let mut ests = vec![all];
    for (k, sel) in rules().into_iter().enumerate().filter(|(_, s)| s.picks_one()) {
        let (e, rays) = estimate_direct(&scene, size, 256, n, 81 + k as u64, sel);
        // One shadow ray per light sample at most (4 lights: `all` traces up to 4 per sample).
        assert!(rays <= u64::from(size.0 * size.1 * 256 * n), "direct {sel}: {rays} shadow rays");
        assert!(rays * 64 < all_rays * 256, "direct {sel}: {rays} shadow rays vs all's {all_rays} at 1/4 the spp");
        ests.push(e);
    }
    assert_all_agree("direct", &ests, 1, 0.02);
}

//! Point-set files as samplers (`file:PATH`): a file holding a registry layout's points renders
//! the bit-identical image, the file's content is in the checkpoint identity, refusals reach the
//! command line with file, set and point, and `strata pointset` exports and measures.

use crate::common;

use common::*;
use std::path::{Path, PathBuf};
use strata::camera::FirstSample;
use strata::integrator::DIM_LIGHT_BASE;
use strata::pointset::command::{layout_sets, Args};
use strata::pointset::{formats, spec::resolve_sampler};
use strata::sampler::SamplerKind;
use strata::session::RenderOptions;

/// A one-light `direct` scene written for this test: a floor under a quad light.
const ONE_LIGHT: &str = "size 24 16\ncamera 0 0.6 2.2  0 0 0  0 1 0  30\nintegrator direct\nlightsamples 4\n\
    vertex -3 0 -3\nvertex 3 0 -3\nvertex 3 0 3\nvertex -3 0 3\ndiffuse 0.5 0.5 0.5\ntri 0 2 1\ntri 0 3 2\n\
    quadLight -0.5 1 -0.5  0 0 1  1 0 0  2 2 2\n";

fn scene(dir: &Path) -> PathBuf {
    let p = dir.join("one_light.test");
    std::fs::write(&p, ONE_LIGHT).unwrap();
    p
}

fn base(scene: &Path, spp: u32) -> RenderOptions {
    RenderOptions {
        scene: Some(scene.to_path_buf()),
        spp: Some(spp),
        threads: 2,
        first_sample: Some(FirstSample::Jittered),
        ..Default::default()
    }
}

/// Exports `kind`'s sets of the render (set j = pixel j's points) to `file` and returns the
/// `file:` kind that reads them back unscrambled, one set per pixel.
fn exported(kind: SamplerKind, file: &Path, points: u32, dim: u32, seed: u64) -> SamplerKind {
    let args = Args { sets: 24 * 16, points, dim, width: 24, seed, ..Args::default() };
    formats::write(file, &layout_sets(kind, &args).unwrap()).unwrap();
    resolve_sampler(&format!("file:{}?scramble=none&sets=pixel&shuffle=none", file.display())).unwrap()
}

#[test]
fn a_file_of_a_layouts_points_renders_that_layouts_image_bit_for_bit() {
    let dir = tmpdir("pointset-identity");
    let sc = scene(&dir);
    let (spp, seed) = (8, 5);
    for (i, kind) in SamplerKind::ALL.into_iter().enumerate() {
        // Pixel sampler: each format in turn.
        let ext = ["npy", "txt", "bin"][i % 3];
        let file = exported(kind, &dir.join(format!("{}.{ext}", kind.name())), spp, 0, seed);
        let mut o = base(&sc, spp);
        o.seed = seed;
        o.pixel_sampler = Some(kind);
        let want = film(&o);
        o.pixel_sampler = Some(file);
        let got = film(&o);
        assert!(got.sum == want.sum && got.sum_sq == want.sum_sq, "pixel sampler {kind:?} from .{ext}");
    }
    // Light sampler (one light, so one light dimension): a sequence layout's 4 x spp points.
    for kind in [SamplerKind::SOBOL, SamplerKind::PMJ02, SamplerKind::HALTON] {
        let file = exported(kind, &dir.join(format!("light-{}.npy", kind.name())), 4 * spp, DIM_LIGHT_BASE, seed);
        let mut o = base(&sc, spp);
        o.seed = seed;
        o.light_sampler = Some(kind);
        let want = film(&o);
        o.light_sampler = Some(file);
        let got = film(&o);
        assert!(got.sum == want.sum, "light sampler {kind:?}");
        // And the file sampler is not trivially the registry one: another seed changes the registry
        // render but not the unscrambled file's light points.
        o.seed = seed + 1;
        o.light_sampler = Some(kind);
        assert!(film(&o).sum != want.sum);
    }
}

#[test]
fn the_files_content_is_in_the_checkpoint_identity() {
    let dir = tmpdir("pointset-ckpt");
    let sc = scene(&dir);
    let pts = dir.join("pts.txt");
    let write = |v: f64| std::fs::write(&pts, format!("0.1 0.2\n0.6 {v}\n0.3 0.9\n0.8 0.4\n")).unwrap();
    write(0.7);
    let out = strata()
        .args(["render", sc.to_str().unwrap(), "--spp", "4", "-q", "--samples", "0..2", "--pixel-sampler"])
        .arg(format!("file:{}", pts.display()))
        .arg("-o")
        .arg(dir.join("part"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // Same path, other points: the checkpoint is refused.
    write(0.75);
    let out = strata()
        .args(["render", sc.to_str().unwrap(), "--spp", "4", "-q", "--pixel-sampler"])
        .arg(format!("file:{}", pts.display()))
        .arg("--resume")
        .arg(dir.join("part.ckpt"))
        .arg("-o")
        .arg(dir.join("part"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("pixel_sampler_digest"), "{err}");
}

#[test]
fn refusals_reach_the_command_line() {
    let dir = tmpdir("pointset-refusals");
    let sc = scene(&dir);
    let run = |flag: &str, spec: String, extra: &[&str]| {
        let out = strata()
            .args(["render", sc.to_str().unwrap(), "-q", "--spp", "8", flag, &spec])
            .args(extra)
            .arg("-o")
            .arg(dir.join("r"))
            .output()
            .unwrap();
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    let bad = dir.join("bad.txt");
    std::fs::write(&bad, "0.1 0.2\n0.3 0.4\n#\n0.5 1.5\n0.6 0.7\n").unwrap();
    let e = run("--pixel-sampler", format!("file:{}", bad.display()), &[]);
    assert!(e.contains(&format!("{}:4: set 1, point 0, coordinate 1: 1.5 is outside [0, 1)", bad.display())), "{e}");
    let few = dir.join("few.npy");
    formats::write(&few, &strata::pointset::PointSets::new("few", 1, 4, 2, vec![0.5; 8]).unwrap()).unwrap();
    let e = run("--pixel-sampler", format!("file:{}", few.display()), &[]);
    assert!(e.contains("its sets have 4 points, but 8 spp are drawn per pixel"), "{e}");
    assert!(e.contains("lower --spp, or give sets of at least 8 points"), "{e}");
    let e = run("--light-sampler", format!("file:{}", few.display()), &["--light-samples", "2"]);
    assert!(e.contains("8 spp x 2 light samples = 16 points are drawn per pixel"), "{e}");
    assert!(e.contains("lower --spp or --light-samples"), "{e}");
    let one = dir.join("one.txt");
    std::fs::write(&one, "0.1\n0.2\n").unwrap();
    let e = run("--pixel-sampler", format!("file:{}", one.display()), &[]);
    assert!(e.contains("1 coordinate per point; a sampler dimension takes 2 (add ?pad=sobol"), "{e}");
    let e = run("--pixel-sampler", format!("file:{}?scramble=rotate", one.display()), &[]);
    assert!(e.contains("expected shift, owen, xor or none"), "{e}");
}

#[test]
fn pointset_command_exports_and_measures() {
    let dir = tmpdir("pointset-cmd");
    let out = strata()
        .args(["pointset", "pmj02", "--points", "64", "--sets", "2", "--trials", "32", "--export"])
        .arg(dir.join("pmj.txt"))
        .arg("--out")
        .arg(dir.join("report"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("integration error, disk") && text.contains("slope"), "{text}");
    let sets = formats::read(&dir.join("pmj.txt")).unwrap();
    assert_eq!((sets.sets, sets.points, sets.dims), (2, 64, 2));
    for f in ["spectrum.csv", "spectrum.svg", "integration.csv", "integration.svg", "pointset.json"] {
        assert!(dir.join("report").join(f).is_file(), "{f}");
    }
    // The exported file measures like the layout itself (same sets).
    let again = strata().args(["pointset", dir.join("pmj.txt").to_str().unwrap(), "--trials", "32"]).output().unwrap();
    let t2 = String::from_utf8_lossy(&again.stdout);
    let rows =
        |t: &str| t.lines().filter(|l| l.trim_start().starts_with(['0', '1'])).map(String::from).collect::<Vec<_>>();
    assert_eq!(rows(&text), rows(&t2), "{text}\n{t2}");
}

#[test]
fn file_samplers_work_in_shards_and_profile() {
    let dir = tmpdir("pointset-shards");
    let sc = scene(&dir);
    let pts = dir.join("pts.npy");
    let data: Vec<f64> = (0..2 * 32 * 2).map(|i| ((i * 37 % 64) as f64 + 0.5) / 64.0).collect();
    formats::write(&pts, &strata::pointset::PointSets::new("pts", 2, 32, 2, data).unwrap()).unwrap();
    let spec = format!("file:{}", pts.display());
    let render = |extra: &[&str], out: &str| {
        let o = strata()
            .args([
                "render",
                sc.to_str().unwrap(),
                "-q",
                "--spp",
                "8",
                "--light-sampler",
                &spec,
                "--pixel-sampler",
                &spec,
            ])
            .args(extra)
            .arg("-o")
            .arg(dir.join(out))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    render(&["--samples", "0..3"], "a");
    render(&["--samples", "3..8"], "b");
    render(&[], "whole");
    let m = strata()
        .arg("merge")
        .arg(dir.join("a.ckpt"))
        .arg(dir.join("b.ckpt"))
        .arg("-q")
        .arg("-o")
        .arg(dir.join("merged"))
        .output()
        .unwrap();
    assert!(m.status.success(), "{}", String::from_utf8_lossy(&m.stderr));
    let read = |n: &str| strata::film::read_exr(&dir.join(format!("{n}.exr"))).unwrap().rgb;
    assert!(read("merged") == read("whole"), "shards of a file-sampler render merge bit-identically");
    let p = strata()
        .args(["profile", sc.to_str().unwrap(), "-q", "--spp", "8", "--repeats", "1", "--light-sampler", &spec])
        .arg("--json")
        .arg(dir.join("p.json"))
        .output()
        .unwrap();
    assert!(p.status.success(), "{}", String::from_utf8_lossy(&p.stderr));
    let json = std::fs::read_to_string(dir.join("p.json")).unwrap();
    assert!(json.contains(&format!("light {spec}")), "the replay names the file sampler");
}

/// Mean over a variant's runs of `mse_corrected * spp` (the error of one sample's worth: equal
/// for every spp at the Monte Carlo rate, lower is better).
fn error_per_sample(runs: &[serde_json::Value], variant: &str) -> f64 {
    let mine: Vec<f64> = runs
        .iter()
        .filter(|r| r["variant"] == variant)
        .map(|r| r["mse_corrected"].as_f64().unwrap() * r["spp"].as_f64().unwrap())
        .collect();
    mine.iter().sum::<f64>() / mine.len() as f64
}

/// Issue 31: a 144-point Fibonacci lattice (not progressive) at equal time runs whole sets of 144
/// spp (never a prefix), says so, and ranks against independent samples as it does at exactly
/// 144 spp (within its noise). Before, a budget stopped wherever it ran out (70-101 spp of 144),
/// and the lattice's prefix (a strip of the square) ranked it far below independent.
#[test]
fn a_lattice_at_equal_time_runs_whole_sets_and_ranks_as_at_its_size() {
    let dir = tmpdir("pointset-equal-time");
    let scene = scene(&dir);
    let fib = dir.join("fib144.txt");
    let text: String =
        (0..144).map(|i| format!("{} {}\n", f64::from(i) / 144.0, f64::from(i * 89 % 144) / 144.0)).collect();
    std::fs::write(&fib, text).unwrap();
    let st = strata().arg("reference").arg(&scene).args(["--spp", "8192", "-q", "-o"]).arg(dir.join("ref")).status();
    assert!(st.unwrap().success());
    let variants = [
        format!("fib=--integrator direct --light-samples 1 --sampler file:{}", fib.display()),
        "ind=--integrator direct --light-samples 1 --sampler independent".to_string(),
    ];
    let compare = |mode: &[&str], out: &str| -> Vec<serde_json::Value> {
        let mut c = strata();
        c.arg("compare").arg(&scene).arg("--reference").arg(dir.join("ref.exr"));
        c.args(["--runs", "6", "--threads", "2", "-q"]).args(mode).arg("--out").arg(dir.join(out));
        for v in &variants {
            c.arg("--variant").arg(v);
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("runs.json")).unwrap()).unwrap()
    };
    let at_144 = compare(&["--spp-ladder", "144"], "ladder");
    let eq = compare(&["--budget", "0.05"], "budget");
    for r in eq.iter().filter(|r| r["variant"] == "fib") {
        let spp = r["spp"].as_u64().unwrap();
        assert!(spp >= 144 && spp % 144 == 0, "an equal-time run ended partway through a set: {spp} spp");
    }
    let table = std::fs::read_to_string(dir.join("budget/table.md")).unwrap();
    assert!(table.contains("is not progressive") && table.contains("blocks of 144 spp"), "{table}");
    let (r144, req) = (
        error_per_sample(&at_144, "fib") / error_per_sample(&at_144, "ind"),
        error_per_sample(&eq, "fib") / error_per_sample(&eq, "ind"),
    );
    println!("error per sample, lattice / independent: at 144 spp {r144:.3}, at equal time {req:.3}");
    assert!(r144 < 0.5, "the lattice beats independent samples at its size: {r144}");
    assert!(req < 0.5 && req / r144 < 2.5 && r144 / req < 2.5, "equal time {req} against 144 spp {r144}");
}

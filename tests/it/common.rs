//! Shared helpers of the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;
use strata::film::Film;
use strata::session::RenderOptions;

/// A data set under `../shared` beside the checkout (or where the environment variable `var`
/// points), recognised by the file or directory `marker` in it. CI always has `../shared`, so a
/// missing data set fails the test with the path it looked at; no test skips for missing data.
pub fn shared_required(var: &str, rel: &str, marker: &str) -> PathBuf {
    let p = std::env::var_os(var)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared").join(rel));
    assert!(
        p.join(marker).exists(),
        "this test needs {} (no {marker} there): CI has ../shared/{rel} beside the checkout; set {var} to point elsewhere",
        p.display()
    );
    p
}

/// The CSE168 corpus (`../shared/cse168`, or `$STRATA_CSE168`); panics naming the path if missing.
pub fn corpus_required() -> PathBuf {
    shared_required("STRATA_CSE168", "cse168", "hw4")
}

/// Render options for `scene` at a small size.
pub fn opts(scene: PathBuf, w: u32, h: u32, spp: u32) -> RenderOptions {
    RenderOptions { scene: Some(scene), size: Some((w, h)), spp: Some(spp), threads: 2, ..Default::default() }
}

/// Renders to a film (no files written).
pub fn film(o: &RenderOptions) -> Film {
    strata::session::render_to_film(o).unwrap_or_else(|e| panic!("render failed: {e}")).film
}

/// Per-pixel channel means as f64.
pub fn means(f: &Film) -> Vec<[f64; 3]> {
    f.sum.iter().zip(&f.count).map(|(s, &n)| s.map(|v| v / f64::from(n.max(1)))).collect()
}

/// Per-pixel channel variances of the mean (unbiased), as f64.
pub fn var_of_mean(f: &Film) -> Vec<[f64; 3]> {
    f.sum
        .iter()
        .zip(&f.sum_sq)
        .zip(&f.count)
        .map(|((s, q), &n)| {
            let n = f64::from(n);
            std::array::from_fn(|c| if n < 2.0 { 0.0 } else { ((q[c] - s[c] * s[c] / n) / (n - 1.0)).max(0.0) / n })
        })
        .collect()
}

/// Ray-triangle distance (Moller-Trumbore in f64), if hit in front: the tests' independent tracer.
pub fn hit_triangle(o: glam::DVec3, d: glam::DVec3, v: [glam::DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-14 {
        return None;
    }
    let t0 = o - v[0];
    let u = t0.dot(p) / det;
    let q = t0.cross(e1);
    let w = d.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && w >= 0.0 && u + w <= 1.0 && t > 1e-9).then_some(t)
}

/// The `strata` binary of this build, as a command to run.
pub fn strata() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_strata"))
}

/// A fresh, empty scratch directory `strata-NAME-XXXXXX` under the system temp dir (a unique
/// suffix: tests that run at once, in one process or several, never share one), removed with
/// everything in it when the test drops it, so the test command leaves nothing behind. Keep it
/// bound (`let dir = tmpdir(..)`) for as long as the test uses its files.
pub fn tmpdir(name: &str) -> Scratch {
    let dir = tempfile::Builder::new().prefix(&format!("strata-{name}-")).tempdir();
    Scratch(dir.unwrap_or_else(|e| panic!("a scratch directory for {name}: {e}")))
}

/// A test's scratch directory ([`tmpdir`]): a path while it lives, removed when dropped.
pub struct Scratch(tempfile::TempDir);

impl std::ops::Deref for Scratch {
    type Target = std::path::Path;
    fn deref(&self) -> &std::path::Path {
        self.0.path()
    }
}

impl AsRef<std::path::Path> for Scratch {
    fn as_ref(&self) -> &std::path::Path {
        self.0.path()
    }
}

/// The OBJ Cornell box (`scenes/cornell_obj.test`: two emissive triangles under the ceiling) path
/// traced to depth 3 with the `.test` lines `lights` (quad lights) added, written to a scratch
/// directory named after `name`.
pub fn cornell_obj_with(name: &str, lights: &str) -> (Scratch, PathBuf) {
    let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes"));
    let text = std::fs::read_to_string(dir.join("cornell_obj.test")).unwrap();
    let text: String = text
        .lines()
        .filter(|l| !l.starts_with("obj ") && !l.starts_with("maxdepth"))
        .map(|l| format!("{l}\n"))
        .collect::<String>()
        + &format!("maxdepth 3\nobj {}\n", dir.join("cornell_box.obj").display())
        + lights;
    let d = tmpdir(name);
    let scene = d.join("tri.test");
    std::fs::write(&scene, text).unwrap();
    (d, scene)
}

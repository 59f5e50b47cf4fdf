//! Shared helpers of the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;
use strata::film::Film;
use strata::session::RenderOptions;

/// The CSE168 corpus beside the checkout (`../shared/cse168`), or None with a printed reason.
pub fn corpus() -> Option<PathBuf> {
    let p = std::env::var_os("STRATA_CSE168")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/cse168")));
    if p.join("hw2").is_dir() {
        Some(p)
    } else {
        eprintln!("skipped: CSE168 corpus not found at {} (set STRATA_CSE168)", p.display());
        None
    }
}

/// The CSE168 corpus, which CI always has: a missing corpus fails the test (with how to point at it).
pub fn corpus_required() -> PathBuf {
    corpus().unwrap_or_else(|| panic!("CSE168 corpus missing (CI has ../shared/cse168; set STRATA_CSE168)"))
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

/// A fresh, empty scratch directory `strata-NAME-PID` under the system temp dir (names are unique
/// within a test binary; the pid keeps binaries that run at once apart).
pub fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("strata-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

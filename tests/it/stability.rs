//! Numerical stability on stiff and extreme scenes (issue #6): tiny very bright lights and lights
//! almost touching a surface against the exact polygonal irradiance and a larger light of equal
//! power, scene scale 1e-3 .. 1e3, degenerate geometry and cameras, the non-finite sample counter,
//! and output files that survive failed writes.
//!
//! Statistical checks compare block means (b x b pixels) of two renders: per block and channel
//! z = (A - B - expected) / sqrt(var A + var B), with var the films' variance of the mean. The
//! renders use fixed seeds, so the checks are deterministic; the thresholds (chi-square per degree
//! of freedom within 5 standard deviations of 1, every |z| < 6, the image-wide mean within 5 sigma)
//! would fail by chance with probability < 1e-6 for independent seeds.

use crate::common;

use common::*;
use std::path::{Path, PathBuf};
use strata::scene::desc::IntegratorKind;
use strata::session::{self as app, RenderOptions};

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name)
}

/// A rendered image: per-pixel means and variances of the mean (f64), and the non-finite count.
struct Img {
    w: usize,
    h: usize,
    mean: Vec<[f64; 3]>,
    var: Vec<[f64; 3]>,
}

/// Renders `o`, asserting that the render rejected no sample as non-finite and that every pixel
/// is finite and non-negative.
fn render(o: &RenderOptions) -> Img {
    let out = app::render_to_film(o).unwrap_or_else(|e| panic!("render failed: {e}"));
    let what = format!("{:?} seed {}", o.scene, o.seed);
    assert_eq!(out.stats.counters.nonfinite, 0, "{what}: non-finite samples were rejected");
    let (mean, var) = (means(&out.film), var_of_mean(&out.film));
    assert!(mean.iter().flatten().all(|v| v.is_finite() && *v >= 0.0), "{what}: non-finite or negative pixel");
    Img { w: out.film.width as usize, h: out.film.height as usize, mean, var }
}

/// Block means and their variances, blocks of `b` x `b` pixels (the image must tile exactly).
fn blocks(img: &Img, b: usize) -> Vec<([f64; 3], [f64; 3])> {
    assert!(img.w.is_multiple_of(b) && img.h.is_multiple_of(b));
    let n = (b * b) as f64;
    let mut out = vec![];
    for by in 0..img.h / b {
        for bx in 0..img.w / b {
            let (mut m, mut v) = ([0.0; 3], [0.0; 3]);
            for y in by * b..(by + 1) * b {
                for x in bx * b..(bx + 1) * b {
                    for c in 0..3 {
                        m[c] += img.mean[y * img.w + x][c] / n;
                        v[c] += img.var[y * img.w + x][c] / (n * n);
                    }
                }
            }
            out.push((m, v));
        }
    }
    out
}

/// Result of a two-sample block comparison.
#[derive(Debug)]
struct Comparison {
    /// sum of z^2 over the blocks and channels with a nonzero variance
    chi2: f64,
    /// number of those
    dof: usize,
    /// largest |z|
    max_z: f64,
    /// z of the image-wide mean difference
    global_z: f64,
    /// blocks with zero variance whose values differ (must be 0)
    exact_mismatch: usize,
    /// image-wide mean of A, for the messages
    mean_a: f64,
}

impl Comparison {
    fn assert_ok(&self, what: &str) {
        eprintln!("{what}: {self:?}");
        let limit = 1.0 + 5.0 * (2.0 / self.dof.max(1) as f64).sqrt();
        assert!(self.dof > 0, "{what}: nothing to compare");
        assert_eq!(self.exact_mismatch, 0, "{what}: noiseless blocks differ");
        assert!(self.chi2 / (self.dof as f64) < limit, "{what}: chi2/dof {} >= {limit}", self.chi2 / self.dof as f64);
        assert!(self.max_z < 6.0, "{what}: a block is {} sigma off", self.max_z);
        assert!(self.global_z.abs() < 5.0, "{what}: the image mean is {} sigma off", self.global_z);
    }
}

/// Compares A - B with `expected` (per block and channel, e.g. an analytic difference; zero when
/// None), with sigma^2 = var A + var B per block.
fn compare(a: &Img, b: &Img, expected: Option<&[[f64; 3]]>, block: usize) -> Comparison {
    let (ba, bb) = (blocks(a, block), blocks(b, block));
    let mut c = Comparison { chi2: 0.0, dof: 0, max_z: 0.0, global_z: 0.0, exact_mismatch: 0, mean_a: 0.0 };
    let (mut sum_d, mut sum_v) = (0.0, 0.0);
    for (i, ((ma, va), (mb, vb))) in ba.iter().zip(&bb).enumerate() {
        for ch in 0..3 {
            let e = expected.map_or(0.0, |e| e[i][ch]);
            let d = ma[ch] - mb[ch] - e;
            let v = va[ch] + vb[ch];
            c.mean_a += ma[ch] / (3 * ba.len()) as f64;
            sum_d += d;
            sum_v += v;
            if v > 0.0 {
                let z = d / v.sqrt();
                c.chi2 += z * z;
                c.dof += 1;
                c.max_z = c.max_z.max(z.abs());
            } else if d.abs() > 1e-6 * ma[ch].abs().max(1e-6) {
                c.exact_mismatch += 1;
            }
        }
    }
    c.global_z = if sum_v > 0.0 { sum_d / sum_v.sqrt() } else { 0.0 };
    c
}

/// Per-block means of `a - b` (an expected difference from two noiseless renders).
fn block_diff(a: &Img, b: &Img, block: usize) -> Vec<[f64; 3]> {
    blocks(a, block)
        .iter()
        .zip(blocks(b, block))
        .map(|((ma, _), (mb, _))| std::array::from_fn(|c| ma[c] - mb[c]))
        .collect()
}

fn opts_for(path: PathBuf, integrator: IntegratorKind, seed: u64) -> RenderOptions {
    RenderOptions { scene: Some(path), integrator: Some(integrator), seed, threads: 2, ..Default::default() }
}

/// A copy of the scene at `path` path traced with NEE (MIS) and BRDF sampling, written to `dir`.
fn path_traced(path: &Path, dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(path).unwrap();
    let out = dir.join(path.file_name().unwrap());
    std::fs::write(&out, text + "\nintegrator pathtracer\nnexteventestimation mis\nimportancesampling brdf\n").unwrap();
    out
}

/// `direct` on the scene itself and the path tracer (NEE with MIS) on a copy.
fn integrators(path: &Path, dir: &Path) -> [(&'static str, RenderOptions); 2] {
    [
        ("direct", opts_for(path.to_path_buf(), IntegratorKind::Direct, 3)),
        ("pathtracer", opts_for(path_traced(path, dir), IntegratorKind::PathTracer, 3)),
    ]
}

// ---- tiny, very bright lights and lights almost touching a surface -------------------------------

/// `analyticdirect` renders the exact polygonal irradiance (src/light/polygonal.rs) times kd/pi
/// at the same pixel positions as the other integrators with the same seed (the pixel jitter is
/// a pure function of pixel, sample and seed), so its film is each pixel's expectation.
fn analytic(path: PathBuf, seed: u64) -> Img {
    render(&opts_for(path, IntegratorKind::AnalyticDirect, seed))
}

/// A 1e-6-area light of radiance 1e6 and a 1-area light of radiance 1 (equal power) one unit above
/// a floor: `direct` and the path tracer (NEE with MIS, BRDF sampling) match the exact irradiance of
/// each light, and the tiny light's image differs from the large one's by exactly the analytic
/// difference of their irradiance, within the films' noise. The tolerance is thus derived from the
/// variance of the mean plus the analytic difference between the two lights (printed), which is not
/// small: the large light subtends 0.6 sr, the tiny one is a point.
#[test]
fn tiny_bright_light_matches_a_large_light_of_equal_power() {
    let (tiny, large) = (scene("light_tiny.test"), scene("light_large.test"));
    let (at, al) = (analytic(tiny.clone(), 3), analytic(large.clone(), 3));
    let expected = block_diff(&at, &al, 4);
    let rel: f64 =
        expected.iter().flatten().map(|v| v.abs()).sum::<f64>() / blocks(&al, 4).iter().flat_map(|b| b.0).sum::<f64>();
    eprintln!("analytic |tiny - large| / large over the image: {rel:.3}");
    assert!(at.mean.iter().flatten().any(|&v| v > 0.1), "the tiny light lights the floor");
    let dir = tmpdir("tiny");
    for ((name, ot), (_, ol)) in integrators(&tiny, &dir).into_iter().zip(integrators(&large, &dir)) {
        let (t, l) = (render(&ot), render(&ol));
        compare(&t, &at, None, 4).assert_ok(&format!("{name}: tiny light vs its exact irradiance"));
        compare(&l, &al, None, 4).assert_ok(&format!("{name}: large light vs its exact irradiance"));
        compare(&t, &l, Some(&expected), 4).assert_ok(&format!("{name}: tiny - large vs the analytic difference"));
    }
}

/// A light whose edge is 0.002 above the floor (1/d^2 up to 2.5e5): finite samples, and `direct` and
/// the path tracer match the exact irradiance within the films' noise.
#[test]
fn light_almost_touching_a_surface_matches_its_exact_irradiance() {
    let near = scene("light_near.test");
    let a = analytic(near.clone(), 5);
    let peak = a.mean.iter().flatten().fold(0.0f64, |m, &v| m.max(v));
    assert!(peak > 0.1, "the floor in front of the light is lit (peak {peak})");
    let dir = tmpdir("near");
    for (name, o) in integrators(&near, &dir) {
        let r = render(&RenderOptions { spp: Some(256), seed: 5, ..o });
        compare(&r, &a, None, 4).assert_ok(&format!("{name}: near light vs its exact irradiance"));
    }
}

// ---- scene scale -----------------------------------------------------------------------------------

/// `scenes/cornell_scale.test` scaled by `s`: `scale s s s` before everything (the geometry
/// follows the transform stack), and the camera's eye and centre and the quad light's corner and
/// edges (which do not) multiplied by `s`. Radiance is scale-free, so the image is the same.
fn scaled_scene(s: f64, dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(scene("cornell_scale.test")).unwrap();
    let mut out = format!("scale {s:e} {s:e} {s:e}\n");
    for line in text.lines() {
        let tokens: Vec<&str> = line.split_whitespace().collect();
        let n = match tokens.first() {
            Some(&"camera") => 6,
            Some(&"quadLight") => 9,
            _ => 0,
        };
        if n == 0 {
            out += line;
        } else {
            let mut t: Vec<String> = tokens.iter().map(|t| t.to_string()).collect();
            for v in t.iter_mut().skip(1).take(n) {
                *v = format!("{:e}", v.parse::<f64>().unwrap() * s);
            }
            out += &t.join(" ");
        }
        out.push('\n');
    }
    let path = dir.join(format!("cornell_scale_{s:e}.test"));
    std::fs::write(&path, out).unwrap();
    path
}

/// The same Cornell box (path traced, NEE with MIS, a cube and a sphere resting on the floor, the
/// light 0.01 below the ceiling) at scale 1e-3 and 1e3 renders the image of scale 1 within the
/// films' noise (independent seeds): the self-intersection offsets scale with the geometry, so no
/// shadow acne (darkening) and no light leaking through contacts (brightening) at either scale.
#[test]
fn cornell_box_renders_the_same_at_scale_1e_minus_3_and_1e3() {
    let dir = tmpdir("scale");
    let reference = render(&opts_for(scaled_scene(1.0, &dir), IntegratorKind::PathTracer, 1));
    for (s, seed) in [(1e-3, 2), (1e3, 3)] {
        let img = render(&opts_for(scaled_scene(s, &dir), IntegratorKind::PathTracer, seed));
        compare(&img, &reference, None, 4).assert_ok(&format!("path tracer, scale {s:e} vs 1"));
        let d = render(&opts_for(scaled_scene(s, &dir), IntegratorKind::Direct, seed));
        let dref = render(&opts_for(scaled_scene(1.0, &dir), IntegratorKind::Direct, 1));
        compare(&d, &dref, None, 4).assert_ok(&format!("direct, scale {s:e} vs 1"));
    }
}

// ---- degenerate geometry and cameras ---------------------------------------------------------------

/// Writes `text` to `dir/name` and returns the path.
fn write_scene(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The template with `extra` lines inserted before the light.
fn cornell_with(extra: &str) -> String {
    let text = std::fs::read_to_string(scene("cornell_scale.test")).unwrap();
    text.replace("\nquadLight ", &format!("\n{extra}\nquadLight "))
}

/// Zero-area triangles (coincident vertices, collinear vertices), also far outside the box, leave the
/// image bit-identical to the scene without them, with the course's pixel-centre sample 0 (whose
/// centre ray runs exactly through the degenerate triangles at y = 1, x = 0) and with jittered
/// ones: they are dropped when the scene is built (counted, and announced once on stderr), so they
/// are never hit and do not count towards the scene extent that scales the ray offsets.
#[test]
fn zero_area_triangles_leave_the_image_unchanged() {
    let dir = tmpdir("degenerate");
    let degenerate = "vertex 0 1 0\nvertex 0.5 1 0\nvertex 1e6 1e6 1e6\nvertex 2e6 2e6 2e6\nvertex 3e6 3e6 3e6\n\
                      tri 16 16 16\ntri 16 17 17\ntri 18 19 20\ntri 18 18 20\ntri 16 17 16";
    let plain = write_scene(&dir, "plain.test", &cornell_with(""));
    let with = write_scene(&dir, "with.test", &cornell_with(degenerate));
    for integ in [IntegratorKind::Direct, IntegratorKind::PathTracer, IntegratorKind::RayTracer] {
        for first_sample in [None, Some(strata::integrator::FirstSample::Jittered)] {
            let o = |p: &PathBuf| RenderOptions { spp: Some(8), first_sample, ..opts_for(p.clone(), integ, 4) };
            let (a, b) = (render(&o(&plain)), render(&o(&with)));
            assert!(a.mean == b.mean, "{integ:?} {first_sample:?}: degenerate triangles changed the image");
        }
    }
    let (scene, _) = app::prepare(&opts_for(with.clone(), IntegratorKind::Direct, 4)).unwrap();
    assert_eq!(scene.degenerate_dropped, 5);
    let warned = |p: &Path| {
        let args = ["--spp", "1", "--size", "8x8", "-q", "-o"];
        let r = strata().arg("render").arg(p).args(args).arg(dir.join("out")).output().unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let err = String::from_utf8_lossy(&r.stderr).into_owned();
        err.lines().filter(|l| l.contains("degenerate")).map(str::to_string).collect::<Vec<_>>()
    };
    let lines = warned(&with);
    assert_eq!(lines.len(), 1, "one warning line: {lines:?}");
    assert_eq!(lines[0], format!("strata: warning: {}: dropped 5 degenerate (zero-area) triangles", with.display()));
    assert!(warned(&plain).is_empty());
}

/// A camera inside a closed cube and inside a sphere, both standing in the lit box: the rays hit
/// the inside of the object, which no light reaches, so the image is exactly black, never NaN (the
/// shading normal and the ray offsets face the incoming ray; offsets along the outward normal
/// would let shadow rays escape and light the inside).
#[test]
fn camera_inside_geometry_sees_a_black_interior() {
    let dir = tmpdir("inside");
    let text = std::fs::read_to_string(scene("cornell_scale.test")).unwrap();
    // Inside the cube (centre (0.35, 0.3, -0.2), half side 0.3) and inside the sphere.
    for (name, camera) in [
        ("cube", "camera 0.35 0.3 -0.05  0.35 0.3 -1  0 1 0  90"),
        ("sphere", "camera -0.45 0.35 0.2  0 1 -1  0 1 0  90"),
    ] {
        let p = write_scene(&dir, &format!("{name}.test"), &text.replace("camera 0 1 3.6  0 1 0  0 1 0  40", camera));
        for integ in [IntegratorKind::Direct, IntegratorKind::PathTracer] {
            let img = render(&RenderOptions { spp: Some(16), ..opts_for(p.clone(), integ, 6) });
            let max = img.mean.iter().flatten().fold(0.0f64, |m, &v| m.max(v));
            assert_eq!(max, 0.0, "{name} {integ:?}: the inside of a closed object is lit");
        }
    }
}

/// Degenerate lights and cameras are clear errors naming the file and line.
#[test]
fn degenerate_lights_and_cameras_are_errors_with_file_and_line() {
    let dir = tmpdir("degenerate-errors");
    let text = std::fs::read_to_string(scene("cornell_scale.test")).unwrap();
    let line_of = |needle: &str| text.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
    let cases = [
        (
            "quadLight -0.3 1.99 -0.3  0 0 0.6  0.6 0 0  12 10 8",
            "quadLight -0.3 1.99 -0.3  0 0 0.6  0 0 1.2  12 10 8",
            "area",
        ),
        (
            "quadLight -0.3 1.99 -0.3  0 0 0.6  0.6 0 0  12 10 8",
            "quadLight -0.3 1.99 -0.3  0 0 0  0.6 0 0  12 10 8",
            "area",
        ),
        ("camera 0 1 3.6  0 1 0  0 1 0  40", "camera 0 1 3.6  0 1 0  0 0 -3  40", "parallel"),
        ("camera 0 1 3.6  0 1 0  0 1 0  40", "camera 0 1 3.6  0 1 3.6  0 1 0  40", "coincide"),
        ("camera 0 1 3.6  0 1 0  0 1 0  40", "camera 0 1 3.6  0 1 0  0 0 0  40", "up vector"),
    ];
    for (i, (from, to, word)) in cases.into_iter().enumerate() {
        let line = line_of(from.split_whitespace().next().unwrap());
        let p = write_scene(&dir, &format!("bad{i}.test"), &text.replace(from, to));
        let e = app::render_to_film(&opts_for(p.clone(), IntegratorKind::PathTracer, 0))
            .err()
            .expect("an error")
            .to_string();
        let want = format!("{}:{line}: ", p.display());
        assert!(e.starts_with(&want) && e.contains(word), "`{to}`: error `{e}`, want `{want}...{word}...`");
    }
}

// ---- output files ----------------------------------------------------------------------------------

/// A render whose output cannot be written fails with an error naming the file, and leaves what was
/// there before: the final EXR name is a directory (the rename fails), the output's parent is a
/// file, or the scene fails to load after a good render wrote the files. No temporary file is left.
#[test]
fn failed_renders_keep_existing_outputs_and_leave_no_temporaries() {
    let dir = tmpdir("atomic");
    let stem = dir.join("img");
    let base =
        RenderOptions { size: Some((16, 16)), spp: Some(1), threads: 2, out: Some(stem.clone()), ..Default::default() };
    app::run_render(&base).expect("first render");
    let (exr, png) = (std::fs::read(dir.join("img.exr")).unwrap(), std::fs::read(dir.join("img.png")).unwrap());
    // A scene that fails to parse: nothing is touched.
    let bad = write_scene(&dir, "bad.test", "size 16 16\ncamera 0 0 1 0 0 0 0 1 0 45\nvertex 0 0\n");
    let e =
        app::run_render(&RenderOptions { scene: Some(bad), ..base.clone() }).err().expect("parse error").to_string();
    assert!(e.contains("bad.test:3:"), "{e}");
    // The EXR's final name is taken by a directory: the EXR write fails and the PNG is not written.
    std::fs::rename(dir.join("img.exr"), dir.join("old.exr")).unwrap();
    std::fs::create_dir(dir.join("img.exr")).unwrap();
    let e = app::run_render(&RenderOptions { seed: 9, ..base.clone() }).err().expect("write error").to_string();
    assert!(e.contains("img.exr"), "{e}");
    assert_eq!(std::fs::read(dir.join("img.png")).unwrap(), png, "the old PNG survives");
    assert_eq!(std::fs::read(dir.join("old.exr")).unwrap(), exr);
    // The output's parent is a regular file: refused before rendering, naming the parent.
    let e = app::run_render(&RenderOptions { out: Some(dir.join("old.exr").join("x")), ..base.clone() })
        .err()
        .expect("bad parent")
        .to_string();
    assert!(e.contains("old.exr") && e.contains("checked before rendering"), "{e}");
    let names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().all(|n| !n.contains(".tmp-")), "temporary files left: {names:?}");
}

/// An interrupted write (the process's file-size limit, RLIMIT_FSIZE, makes the write of the EXR
/// fail part-way with EFBIG) never leaves a truncated EXR or PNG under the final name: the files of
/// the previous render stay byte for byte, and the failing render reports the file.
#[test]
fn a_write_cut_short_never_truncates_the_final_files() {
    assert!(Path::new("/bin/sh").exists(), "this test needs /bin/sh (ulimit -f sets the file-size limit)");
    let dir = tmpdir("fsize");
    let stem = dir.join("img");
    let args = |seed: &str| {
        ["render", "--size", "64x64", "--spp", "2", "--threads", "1", "--quiet", "--seed", seed, "-o"]
            .iter()
            .map(|s| s.to_string())
            .chain([stem.display().to_string()])
            .collect::<Vec<_>>()
    };
    let bin = env!("CARGO_BIN_EXE_strata");
    let ok = std::process::Command::new(bin).args(args("1")).output().unwrap();
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let (exr, png) = (std::fs::read(dir.join("img.exr")).unwrap(), std::fs::read(dir.join("img.png")).unwrap());
    assert!(exr.len() > 8 * 1024, "the EXR must exceed the 4 KiB limit below ({} bytes)", exr.len());
    // 4 KiB file-size limit (ulimit -f counts 1024-byte blocks in sh/dash), SIGXFSZ ignored so
    // that write() fails with EFBIG instead of killing the process.
    let script = "trap '' XFSZ; ulimit -f 4 && exec \"$0\" \"$@\"";
    let cut = std::process::Command::new("/bin/sh").arg("-c").arg(script).arg(bin).args(args("2")).output().unwrap();
    let stderr = String::from_utf8_lossy(&cut.stderr);
    assert!(!cut.status.success(), "the write under a 4 KiB limit must fail");
    assert!(stderr.contains("img.exr"), "the error names the file: {stderr}");
    assert_eq!(std::fs::read(dir.join("img.exr")).unwrap(), exr, "the old EXR survives");
    assert_eq!(std::fs::read(dir.join("img.png")).unwrap(), png, "the old PNG survives");
    let names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().all(|n| !n.contains(".tmp-")), "temporary files left: {names:?}");
}

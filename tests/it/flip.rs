//! FLIP (`strata::report::flip`, through `nv-flip`) agrees with NVIDIA's reference implementation,
//! the `flip-evaluator` Python package (installed into target/py by scripts/setup.sh): the mean
//! FLIP of several image pairs within 1e-3. The pairs are written as 8-bit sRGB PNGs, which both
//! sides read as LDR images.

use crate::common;

use std::path::{Path, PathBuf};
use strata::report::flip;

fn write_png(path: &Path, w: u32, h: u32, rgb8: &[u8]) {
    let file = std::fs::File::create(path).unwrap();
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header().unwrap().write_image_data(rgb8).unwrap();
}

/// The reference implementation's mean FLIP of each (reference, test) PNG pair.
fn reference_means(pairs: &[(PathBuf, PathBuf)]) -> Vec<f64> {
    let py = std::env::var_os("STRATA_PYTHONPATH")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/target/py")));
    let script = "import sys, flip_evaluator as f\n\
                  a = sys.argv[1:]\n\
                  for r, t in zip(a[0::2], a[1::2]):\n    print(f.evaluate(r, t, 'LDR')[1])\n";
    let mut cmd = std::process::Command::new("python3");
    cmd.env("PYTHONPATH", &py).arg("-c").arg(script);
    for (r, t) in pairs {
        cmd.arg(r).arg(t);
    }
    let out = cmd.output().expect("python3 runs");
    assert!(
        out.status.success(),
        "flip-evaluator failed (scripts/setup.sh installs it into {}): {}",
        py.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).lines().map(|l| l.trim().parse().unwrap()).collect()
}

#[test]
fn mean_flip_agrees_with_nvidias_flip_evaluator() {
    let d = common::tmpdir("flip");
    let (w, h) = (96u32, 64u32);
    let n = (w * h) as usize;
    // Pairs: a gradient and its hue-shifted copy; a render of the built-in Cornell box at 1 spp
    // against one at 64 spp; a hashed noise texture against a 3x3 blur of it; a mid-grey against a
    // slightly brighter grey (a small difference).
    let gradient: Vec<[f32; 3]> =
        (0..n).map(|i| [(i as u32 % w) as f32 / w as f32, (i as u32 / w) as f32 / h as f32, 0.3]).collect();
    let shifted: Vec<[f32; 3]> = gradient.iter().map(|p| [p[1], p[2], p[0]]).collect();
    let render = |spp| {
        let o = strata::session::RenderOptions { size: Some((w, h)), spp: Some(spp), threads: 2, ..Default::default() };
        common::film(&o).mean()
    };
    let noise: Vec<[f32; 3]> = (0..n as u32)
        .map(|i| {
            let x = i.wrapping_mul(0x9e37_79b9) ^ (i >> 3).wrapping_mul(0x85eb_ca6b);
            [(x & 255) as f32 / 255.0, ((x >> 8) & 255) as f32 / 255.0, ((x >> 16) & 255) as f32 / 255.0]
        })
        .collect();
    let blur: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let (x, y) = ((i as u32 % w) as i64, (i as u32 / w) as i64);
            let mut s = [0.0f32; 3];
            for (dx, dy) in (-1..=1).flat_map(|a| (-1..=1).map(move |b| (a, b))) {
                let (u, v) = ((x + dx).clamp(0, w as i64 - 1), (y + dy).clamp(0, h as i64 - 1));
                let p = noise[(v * w as i64 + u) as usize];
                (0..3).for_each(|c| s[c] += p[c] / 9.0);
            }
            s
        })
        .collect();
    let grey = vec![[0.2f32; 3]; n];
    let brighter = vec![[0.23f32; 3]; n];
    let images = [(gradient, shifted), (render(64), render(1)), (noise, blur), (grey, brighter)];
    let mut pairs = Vec::new();
    let mut ours = Vec::new();
    for (i, (r, t)) in images.iter().enumerate() {
        let (r8, t8) = (flip::to_srgb8(r), flip::to_srgb8(t));
        let (pr, pt) = (d.join(format!("ref{i}.png")), d.join(format!("test{i}.png")));
        write_png(&pr, w, h, &r8);
        write_png(&pt, w, h, &t8);
        pairs.push((pr, pt));
        ours.push(flip::mean(&flip::flip_map_srgb8(&r8, &t8, w, h)));
    }
    let theirs = reference_means(&pairs);
    assert_eq!(theirs.len(), ours.len());
    for (i, (a, b)) in ours.iter().zip(&theirs).enumerate() {
        eprintln!("pair {i}: mean FLIP strata {a:.6}, flip-evaluator {b:.6}");
        assert!((a - b).abs() < 1e-3, "pair {i}: strata {a} vs flip-evaluator {b}");
        assert!(*b > 0.0, "pair {i}: the images differ, FLIP must see it");
    }
}

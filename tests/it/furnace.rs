//! The furnace test, over every registered unbiased sampler: a diffuse floor (albedo 0.5) inside a
//! box of five inward-facing quad lights of radiance 1. Every point of the floor sees lights over
//! its whole hemisphere, and the lights reflect nothing, so every pixel is exactly 0.5 for `direct`
//! and for the path tracer, whatever light is chosen and wherever its point lies. Each sampler
//! (every dimension from it: `--sampler`) must give images that pass a per-pixel and an 8x8-block
//! z-test against 0.5 (the film's iid variance of the mean, which over-estimates a
//! low-discrepancy layout's, so the test is conservative). A layout whose light choice follows
//! its light point within a pixel gives each pixel the wrong share of each light and fails.

use crate::common;

use strata::integrator::{FirstSample, LightSelection};
use strata::sampler::{SamplerKind, SAMPLERS};
use strata::scene::desc::{ImportanceSampling, IntegratorKind, Nee};
use strata::session::RenderOptions;

const SCENE: &str = "\
size 24 24
camera 0 1 0  0 0 0  0 0 1  60
integrator direct
lightsamples 1
output furnace
# top (emits -y) and the four sides (emit inwards)
quadLight -1 2 -1  0 0 2  2 0 0  1 1 1
quadLight -1 0 -1  0 0 2  0 2 0  1 1 1
quadLight 1 0 -1  0 2 0  0 0 2  1 1 1
quadLight -1 0 -1  0 2 0  2 0 0  1 1 1
quadLight -1 0 1  2 0 0  0 2 0  1 1 1
diffuse 0.5 0.5 0.5
specular 0 0 0
vertex -1 0 -1
vertex 1 0 -1
vertex 1 0 1
vertex -1 0 1
tri 0 1 2
tri 0 2 3
";

/// (largest per-pixel |z|, largest 8x8-block |z|, pixels with zero variance off 0.5).
fn z_against_half(o: &RenderOptions) -> (f64, f64, usize) {
    let f = common::film(o);
    let (m, v) = (common::means(&f), common::var_of_mean(&f));
    let (w, h) = (f.width as usize, f.height as usize);
    let (mut pixel, mut block, mut exact_off) = (0f64, 0f64, 0);
    for (mi, vi) in m.iter().zip(&v) {
        for c in 0..3 {
            if vi[c] > 0.0 {
                pixel = pixel.max((mi[c] - 0.5).abs() / vi[c].sqrt());
            } else if (mi[c] - 0.5).abs() > 1e-5 {
                exact_off += 1;
            }
        }
    }
    for by in (0..h).step_by(8) {
        for bx in (0..w).step_by(8) {
            let (mut d, mut var) = (0.0, 0.0);
            for y in by..(by + 8).min(h) {
                for x in bx..(bx + 8).min(w) {
                    // The channels' errors may be correlated (they are equal here): the variance
                    // of their sum is at most (sum of their standard deviations)^2.
                    d += (0..3).map(|c| m[y * w + x][c] - 0.5).sum::<f64>();
                    var += (0..3).map(|c| v[y * w + x][c].sqrt()).sum::<f64>().powi(2);
                }
            }
            if var > 0.0 {
                block = block.max(d.abs() / var.sqrt());
            }
        }
    }
    (pixel, block, exact_off)
}

#[test]
fn every_sampler_passes_the_furnace() {
    let dir = common::tmpdir("furnace");
    let scene = dir.join("furnace.test");
    std::fs::write(&scene, SCENE).unwrap();
    let base = RenderOptions {
        scene: Some(scene),
        spp: Some(64),
        threads: 2,
        first_sample: Some(FirstSample::Jittered),
        light_samples: Some(1),
        ..Default::default()
    };
    let configs: [(&str, RenderOptions); 4] = [
        ("direct uniform", RenderOptions { light_selection: Some(LightSelection::UNIFORM), ..base.clone() }),
        ("direct all", RenderOptions { light_selection: Some(LightSelection::ALL), ..base.clone() }),
        (
            "path mis power",
            RenderOptions {
                integrator: Some(IntegratorKind::PathTracer),
                nee: Some(Nee::Mis),
                importance_sampling: Some(ImportanceSampling::Cosine),
                max_depth: Some(3),
                light_selection: Some(LightSelection::named("power")),
                ..base.clone()
            },
        ),
        (
            "path mis spatial",
            RenderOptions {
                integrator: Some(IntegratorKind::PathTracer),
                nee: Some(Nee::Mis),
                importance_sampling: Some(ImportanceSampling::Brdf),
                max_depth: Some(3),
                light_selection: Some(LightSelection::named("spatial")),
                ..base.clone()
            },
        ),
    ];
    let mut failures = Vec::new();
    for info in SAMPLERS.iter().filter(|s| !s.biased) {
        let kind = SamplerKind::parse(info.name).expect("registered");
        for (name, o) in &configs {
            let (pixel, block, off) = z_against_half(&RenderOptions { sampler: Some(kind), ..o.clone() });
            eprintln!("{:<12} {name:<17} max pixel |z| {pixel:.2}, max block |z| {block:.2}", info.name);
            if !(pixel < 6.0 && block < 5.0 && off == 0) {
                failures.push(format!(
                    "{} {name}: pixel |z| {pixel:.2}, block |z| {block:.2}, {off} exact pixels off",
                    info.name
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

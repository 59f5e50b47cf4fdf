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

// ---------------------------------------------------------------------------------------------
// Every registered BSDF in the furnace.

/// A unit sphere filling most of a 16x16 image, black course material (its registry row is set
/// per case), paths unbounded (they end where they leave the convex sphere; no Russian roulette,
/// whose rare kills would make a lossless row's per-sample estimate other than exactly 1).
const SPHERE: &str = "\
size 16 16
integrator pathtracer
camera 0 0 3  0 0 0  0 1 0  40
maxdepth -1
russianroulette off
nexteventestimation mis
importancesampling brdf
ambient 0 0 0
diffuse 0 0 0
specular 0 0 0
sphere 0 0 0 1
";

/// What the furnace image of a registry row converges to, where it is known per model: a
/// closed object under a white constant environment of radiance 1 looks exactly 1 wherever
/// every scattering conserves energy. That holds for the smooth `dielectric` and `thindielectric`
/// with unit reflectance and transmittance (Fresnel reflection plus refraction, the radiance
/// scaling of refraction undone on the way out) and for a fully transparent row (opacity 0: the
/// ray passes). Every other model loses energy somewhere (conductors' Fresnel below 1,
/// single-scattering microfacets, plastic's absorbing base): its image is at most 1 and
/// converges to the BSDF-sampling-only render of the same row.
fn exact_value(name: &str, row: &strata::bsdf::BsdfParams) -> Option<f64> {
    let unit = row.color[0] == glam::Vec3::ONE && row.color[1] == glam::Vec3::ONE;
    match name {
        _ if row.opacity == 0.0 => Some(1.0),
        "dielectric" | "thindielectric" if unit && row.opacity == 1.0 => Some(1.0),
        _ => None,
    }
}

/// RMS over pixels and channels of (mean - reference), the reference's own variance of the mean
/// subtracted when given (noise-corrected, floored at 0).
fn rmse(m: &[[f64; 3]], r: &[[f64; 3]], rv: Option<&[[f64; 3]]>) -> f64 {
    let mut s = 0.0;
    for i in 0..m.len() {
        for c in 0..3 {
            let d = m[i][c] - r[i][c];
            s += d * d - rv.map_or(0.0, |v| v[i][c]);
        }
    }
    (s / (3 * m.len()) as f64).max(0.0).sqrt()
}

/// Least-squares slope of log y over log x.
fn slope(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0.ln()).sum::<f64>() / n, pts.iter().map(|p| p.1.ln()).sum::<f64>() / n);
    let sxy: f64 = pts.iter().map(|p| (p.0.ln() - mx) * (p.1.ln() - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0.ln() - mx).powi(2)).sum();
    sxy / sxx
}

/// The path tracer (NEE with MIS) on a sphere of every registered BSDF (every row of its
/// `test_params`, so a new BSDF is covered by its registry line) under a white constant
/// environment, with Sobol' samples at 16, 64 and 256 spp:
/// - no non-finite sample;
/// - where the model conserves energy ([`exact_value`]) every pixel is 1 (per-pixel z-test at 256
///   spp; a pixel without variance within 1e-5);
/// - elsewhere, every pixel of a 512-spp BSDF-sampling-only render (independent samples, another
///   seed) is at most 1 (z < 5) and the MIS render agrees with it (per-pixel and whole-image z);
/// - the error falls at the sampler's rate: an RMSE slope over 16, 64, 256 spp of -0.4 or
///   steeper (Monte Carlo's -0.5 or better; a plateau fits about 0), against the estimator's own
///   2048-spp image (rows whose every sample is exactly 1 are exempt: their error is rounding).
#[test]
fn every_bsdf_converges_in_the_furnace() {
    use std::sync::Arc;
    let dir = common::tmpdir("bsdf-furnace");
    let scene = dir.join("sphere.test");
    std::fs::write(&scene, SPHERE).unwrap();
    let base = strata::session::scene::parse_scene(&RenderOptions { scene: Some(scene), ..Default::default() })
        .expect("the furnace sphere parses");
    let mut members = Vec::new();
    <strata::bsdf::AllBsdfs as strata::bsdf::BsdfSet>::members(&mut members);
    let sobol = SamplerKind::parse("sobol").expect("registered");
    let indep = SamplerKind::parse("independent").expect("registered");
    let mut failures = Vec::new();
    for m in &members {
        for (r, row) in (m.test_params)().iter().enumerate() {
            let mut desc = base.clone();
            let k = desc.spheres[0].material as usize;
            desc.materials[k].bsdf = *row;
            desc.environment = Some(strata::scene::desc::EnvironmentDesc::Constant(glam::Vec3::ONE));
            let desc = Arc::new(desc);
            let run = |spp: u32, nee: Nee, sampler: SamplerKind, seed: u64| {
                let o = RenderOptions {
                    parsed: Some(desc.clone()),
                    spp: Some(spp),
                    seed,
                    threads: 2,
                    nee: Some(nee),
                    sampler: Some(sampler),
                    first_sample: Some(FirstSample::Jittered),
                    ..Default::default()
                };
                let out = strata::session::render_to_film(&o).unwrap_or_else(|e| panic!("render failed: {e}"));
                (common::means(&out.film), common::var_of_mean(&out.film), out.stats.counters.nonfinite)
            };
            let name = format!("{} row {r}", m.name);
            let runs: Vec<_> = [16u32, 64, 256].iter().map(|&n| (n, run(n, Nee::Mis, sobol, 1))).collect();
            if runs.iter().any(|(_, (_, _, bad))| *bad > 0) {
                failures.push(format!("{name}: non-finite samples"));
                continue;
            }
            let (m256, v256) = (&runs[2].1 .0, &runs[2].1 .1);
            let (want, want_var) = match exact_value(m.name, row) {
                Some(x) => (vec![[x; 3]; m256.len()], None),
                None => {
                    let (rm, rv, bad) = run(512, Nee::Off, indep, 7);
                    let over = rm
                        .iter()
                        .zip(&rv)
                        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - 1.0 - 1e-5) / b[c].sqrt().max(1e-9)));
                    let over = over.fold(f64::MIN, f64::max);
                    if bad > 0 || over > 5.0 {
                        failures.push(format!("{name}: the BSDF-sampled reference gains energy (z {over:.2} above 1)"));
                    }
                    (rm, Some(rv))
                }
            };
            // Per pixel and over the whole image, against the value or the reference.
            let (mut zmax, mut d, mut var, mut off) = (0f64, 0f64, 0f64, 0);
            for i in 0..m256.len() {
                for c in 0..3 {
                    let e = m256[i][c] - want[i][c];
                    let v = v256[i][c] + want_var.as_ref().map_or(0.0, |w| w[i][c]);
                    d += e;
                    var += v;
                    // (Errors within 1e-5 are rounding: lossless rows give 1 per sample.)
                    if e.abs() <= 1e-5 {
                    } else if v > 0.0 {
                        zmax = zmax.max(e.abs() / v.sqrt());
                    } else {
                        off += 1;
                    }
                }
            }
            let zsum = match d.abs() / (3 * m256.len()) as f64 {
                mean if mean <= 1e-6 => 0.0,
                _ if var > 0.0 => d.abs() / var.sqrt(),
                _ => f64::INFINITY,
            };
            // The rate against the limit of the same estimator (Sobol', MIS, another seed and 8x
            // the largest count: its own error is about a third of the 256-spp one's at
            // Monte Carlo's rate), not against the BSDF-sampled reference, whose noise would
            // hide the error at 256 spp.
            let exact = rmse(&runs[0].1 .0, &want, None) <= 1e-5;
            let limit = if exact { want.clone() } else { run(2048, Nee::Mis, sobol, 9).0 };
            let errs: Vec<(f64, f64)> =
                runs.iter().map(|(n, (mi, _, _))| (*n as f64, rmse(mi, &limit, None))).collect();
            let s = slope(&errs);
            eprintln!(
                "{name:<22} 256 spp: max pixel |z| {zmax:.2}, image |z| {zsum:.2}; RMSE {:.2e} {:.2e} {:.2e}, slope {s:.2}",
                errs[0].1, errs[1].1, errs[2].1
            );
            if !(zmax < 6.0 && zsum < 5.0 && off == 0) {
                failures
                    .push(format!("{name}: max pixel |z| {zmax:.2}, image |z| {zsum:.2}, {off} exact channels off"));
            }
            if !exact && !(s <= -0.4) {
                failures.push(format!("{name}: RMSE slope {s:.2} (RMSE {errs:?})"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

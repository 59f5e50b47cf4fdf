//! `direct` with BSDF samples, as Mitsuba 3's `direct`: emitter and BSDF samples combined by the
//! power heuristic, delta lobes (glass, mirror, plastic's coat) reached by BSDF samples alone.
//! - `scenes/direct_spheres.xml` (glass, gold mirror, plastic under an area light and a constant
//!   sky) against Mitsuba's own `direct` render of it, by Mitsuba's regression criterion at its
//!   budget; light sampling alone (`--bsdf-samples 0`, the code before BSDF samples, bit for bit)
//!   fails it;
//! - strata's own estimators agree per pixel: on smooth lobes (`scenes/direct_rough.xml`) emitter
//!   samples alone, BSDF samples alone and both; on delta lobes BSDF samples alone and both;
//! - a mask (`scenes/direct_mask.xml`) against Mitsuba's `direct` render of it;
//! - the error against Mitsuba's image falls with spp at the Monte Carlo rate.

use crate::common;

use common::*;
use std::path::PathBuf;
use strata::report::ztest::{mitsuba_ztest, ZTest};
use strata::session::RenderOptions;

fn scene(name: &str) -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes")).join(name)
}

/// Options for the scene at its own size, seed `seed`, with Mitsuba's `-D emitter_samples` and
/// `bsdf_samples`.
fn with(name: &str, spp: u32, seed: u64, (e, b): (u32, u32)) -> RenderOptions {
    RenderOptions {
        scene: Some(scene(name)),
        spp: Some(spp),
        seed,
        threads: 2,
        defines: vec![("emitter_samples".into(), e.to_string()), ("bsdf_samples".into(), b.to_string())],
        ..Default::default()
    }
}

/// Mitsuba's reference of `direct_spheres.xml` (`scenes/refs/`, 8192 spp of its `direct` in its
/// `moment` integrator) and its per-sample variance.
fn reference() -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    reference_of("direct_spheres.xml")
}

/// Mitsuba's reference of scene `name` and its per-sample variance.
fn reference_of(name: &str) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let (r, v) = strata::lab::mitsuba::reference_paths(&scene(name));
    let read = |p: PathBuf| strata::film::read_exr(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display())).rgb;
    (read(r), read(v))
}

/// Mitsuba's z-test of a render with options `o` (its spp) against its scene's reference.
fn ztest(o: &RenderOptions) -> ZTest {
    let out = strata::session::render_to_film(o).expect("renders");
    assert_eq!(out.stats.counters.nonfinite, 0, "non-finite samples");
    let name = o.scene.as_ref().and_then(|p| p.file_name()).and_then(|n| n.to_str()).unwrap();
    let (r, v) = reference_of(name);
    mitsuba_ztest(&out.film.mean(), o.spp.unwrap(), &r, &v)
}

/// Glass, mirror and plastic under `direct` pass Mitsuba's z-test against Mitsuba's own `direct`
/// (2,000,000 samples per image: 651 spp at 64 x 48); without BSDF samples (the delta lobes
/// black, as `direct` rendered them before) the same test fails.
#[test]
fn delta_bsdfs_pass_mitsubas_ztest_against_mitsubas_direct() {
    let spp = 2_000_000 / (64 * 48);
    let t = ztest(&with("direct_spheres.xml", spp, 0, (1, 1)));
    eprintln!(
        "direct_spheres vs Mitsuba: {:.3} % accepted, smallest p {:.2e} (level {:.2e})",
        100.0 * t.accepted,
        t.min_p,
        t.level
    );
    assert!(t.passed, "{t:?}");
    let lights_only = ztest(&RenderOptions { bsdf_samples: Some(0), ..with("direct_spheres.xml", spp, 0, (1, 1)) });
    eprintln!("  light samples alone: {:.3} % accepted", 100.0 * lights_only.accepted);
    assert!(!lights_only.passed && lights_only.accepted < 0.95, "{lights_only:?}");
}

/// A mask (opacity 0.4 around the plastic) under `direct`: its null lobe is a delta transmission
/// of the BSDF samples, and its nested lobe's MIS weights use the opacity-scaled pdf on both sides
/// (with the nested pdf alone on the BSDF side, 99.24 % of the channels passed: the weights summed
/// to more than 1). Mitsuba's z-test against Mitsuba's own `direct`.
#[test]
fn masks_pass_mitsubas_ztest_against_mitsubas_direct() {
    let spp = 2_000_000 / (64 * 48);
    let t = ztest(&with("direct_mask.xml", spp, 0, (1, 1)));
    eprintln!(
        "direct_mask vs Mitsuba: {:.3} % accepted, smallest p {:.2e} (level {:.2e})",
        100.0 * t.accepted,
        t.min_p,
        t.level
    );
    assert!(t.passed, "{t:?}");
}

/// Per-pixel means and variances of the mean, summed over `b` x `b` pixel blocks (per-pixel
/// variance estimates of BSDF samples that rarely find a small light have heavy tails).
fn blocks(o: &RenderOptions, b: usize) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let out = strata::session::render_to_film(o).expect("renders");
    assert_eq!(out.stats.counters.nonfinite, 0, "non-finite samples");
    let (w, h) = (out.film.width as usize, out.film.height as usize);
    let (m, v) = (means(&out.film), var_of_mean(&out.film));
    let (bw, bh) = (w / b, h / b);
    let (mut bm, mut bv) = (vec![[0.0; 3]; bw * bh], vec![[0.0; 3]; bw * bh]);
    for y in 0..bh * b {
        for x in 0..bw * b {
            let (i, j) = (y * w + x, (y / b) * bw + x / b);
            for c in 0..3 {
                bm[j][c] += m[i][c];
                bv[j][c] += v[i][c];
            }
        }
    }
    (bm, bv)
}

/// z-tests of two estimates block by block: the image sum's |z| < 4.5 and at most 2% of the
/// block channels beyond |z| = 3.
fn agree(name: &str, a: &(Vec<[f64; 3]>, Vec<[f64; 3]>), b: &(Vec<[f64; 3]>, Vec<[f64; 3]>)) {
    let (mut d, mut v, mut out, mut n) = (0.0, 0.0, 0usize, 0usize);
    for i in 0..a.0.len() {
        for c in 0..3 {
            let (diff, var) = (a.0[i][c] - b.0[i][c], a.1[i][c] + b.1[i][c]);
            if var == 0.0 {
                assert!(diff.abs() <= 1e-5, "{name}: zero-variance block {i} differs by {diff}");
                continue;
            }
            n += 1;
            out += usize::from((diff / var.sqrt()).abs() > 3.0);
            d += diff;
            v += var;
        }
    }
    let (z, frac) = (d / v.sqrt(), out as f64 / n.max(1) as f64);
    eprintln!("{name}: z(sum) = {z:+.2}, |z| > 3 in {:.2}% of {n} block channels", 100.0 * frac);
    assert!(n > 100, "{name}: nothing to compare");
    assert!(z.abs() < 4.5 && frac <= 0.02, "{name} disagree: z(sum) {z:.2}, |z| > 3 in {frac:.4}");
}

/// Emitter samples alone, BSDF samples alone and both (MIS, several counts) estimate the same
/// image where light sampling reaches every lit direction (rough conductor, rough plastic,
/// diffuse); on delta lobes BSDF samples alone and MIS agree.
#[test]
fn emitter_bsdf_and_mis_variants_agree() {
    let rough = |spp, seed, es| blocks(&with("direct_rough.xml", spp, seed, es), 4);
    let mis = rough(256, 1, (1, 1));
    agree("rough: emitter alone vs MIS", &rough(256, 2, (1, 0)), &mis);
    agree("rough: BSDF alone vs MIS", &rough(512, 3, (0, 2)), &mis);
    agree("rough: MIS 2+3 vs MIS 1+1", &rough(128, 4, (2, 3)), &mis);
    let delta = |spp, seed, es| blocks(&with("direct_spheres.xml", spp, seed, es), 4);
    agree("delta: BSDF alone vs MIS", &delta(512, 5, (0, 2)), &delta(256, 6, (1, 1)));
}

/// The mean squared error against Mitsuba's image (less the reference's own noise) falls about
/// 4x per 4x spp: 16 -> 64 -> 256 spp, each step at least 2.5x.
#[test]
fn direct_error_against_mitsuba_falls_with_spp() {
    let (r, v) = reference();
    let ref_noise: f64 = v.iter().map(|v| v.iter().map(|&x| f64::from(x) / 8192.0).sum::<f64>()).sum();
    let mse = |spp: u32| {
        let img =
            strata::session::render_to_film(&with("direct_spheres.xml", spp, 11, (1, 1))).expect("renders").film.mean();
        let e: f64 = img
            .iter()
            .zip(&r)
            .map(|(a, b)| (0..3).map(|c| (f64::from(a[c]) - f64::from(b[c])).powi(2)).sum::<f64>())
            .sum();
        (e - ref_noise) / (3 * img.len()) as f64
    };
    let e = [mse(16), mse(64), mse(256)];
    eprintln!("direct_spheres MSE at 16, 64, 256 spp: {:.3e} {:.3e} {:.3e}", e[0], e[1], e[2]);
    assert!(e[0] / e[1] > 2.5 && e[1] / e[2] > 2.5, "error does not fall with spp: {e:?}");
}

/// The path tracer's MIS at a mask (`scenes/direct_mask.xml` under the path tracer, depth 3): next
/// events and BSDF samples combined (`--nee mis`) estimate the image BSDF samples alone
/// (`--nee off`) do. A mask's nested sample must carry the masked pdf, the one next events weigh
/// against: with the nested pdf unscaled the two MIS weights summed to more than 1 on the masked
/// sphere.
#[test]
fn path_tracer_mis_at_a_mask_agrees_with_bsdf_sampling_alone() {
    use strata::scene::desc::{IntegratorKind, Nee};
    let path = |spp, seed, nee| {
        let o = RenderOptions {
            integrator: Some(IntegratorKind::PathTracer),
            nee: Some(nee),
            max_depth: Some(3),
            ..with("direct_mask.xml", spp, seed, (1, 1))
        };
        blocks(&o, 4)
    };
    agree("mask: path MIS vs BSDF alone", &path(128, 7, Nee::Mis), &path(512, 8, Nee::Off));
}

//! Direct lighting end to end on the CSE168 hw2 scenes: the exact integrator against an independent
//! quadrature, the sampled integrators against the exact one, stratification against random
//! sampling, and thread-count determinism.

use crate::common;

use common::*;
use strata::sampler::SamplerKind;
use strata::scene::desc::IntegratorKind;
use strata::scene::parse::{parse_file, Limits};

/// `analyticdirect` on hw2/analytic.test at pixel centres against an evaluation written here from
/// the format's definitions: our own camera rays and ray-triangle hits, and the irradiance as a
/// 400x400 midpoint quadrature of cos cos / d^2 over the one-sided light (not Arvo's formula).
#[test]
fn analyticdirect_matches_independent_quadrature() {
    let c = corpus_required();
    let path = c.join("hw2/analytic.test");
    let (w, h) = (160u32, 120u32);
    let mut o = opts(path.clone(), w, h, 1);
    o.pixel_sampler = Some(SamplerKind::GRID_CENTER);
    let img = means(&film(&o));
    let desc = parse_file(&path, &Limits::default()).unwrap();
    assert_eq!(desc.integrator, IntegratorKind::AnalyticDirect);
    let cam = desc.camera.unwrap();
    let (eye, center, upv) = (cam.eye.as_dvec3(), cam.center.as_dvec3(), cam.up.as_dvec3());
    let look = (center - eye).normalize();
    let right = look.cross(upv).normalize();
    let up = right.cross(look);
    let a = (f64::from(cam.fovy_deg).to_radians() / 2.0).tan();
    let light = desc.quad_lights[0];
    let (la, lab, lac) = (light.a.as_dvec3(), light.ab.as_dvec3(), light.ac.as_dvec3());
    let ln = lac.cross(lab).normalize();
    let area = lab.cross(lac).length();
    let mut checked = 0;
    for py in (3..h).step_by(9) {
        for px in (5..w).step_by(13) {
            let sx = (2.0 * (f64::from(px) + 0.5) / f64::from(w) - 1.0) * a * f64::from(w) / f64::from(h);
            let sy = (1.0 - 2.0 * (f64::from(py) + 0.5) / f64::from(h)) * a;
            let d = (look + right * sx + up * sy).normalize();
            let mut best: Option<(f64, usize)> = None;
            for (i, t) in desc.triangles.iter().enumerate() {
                if let Some(t) = hit_triangle(eye, d, t.v.map(|v| v.as_dvec3())) {
                    if best.is_none_or(|(b, _)| t < b) {
                        best = Some((t, i));
                    }
                }
            }
            // Pixels that see the light (or nothing) are not what this test is about.
            let lq = [la, la + lab, la + lab + lac, la + lac];
            let sees_light = [[0, 1, 2], [0, 2, 3]]
                .iter()
                .any(|t| hit_triangle(eye, d, t.map(|i| lq[i])).is_some_and(|tl| best.is_none_or(|(b, _)| tl < b)));
            let Some((t, i)) = best else { continue };
            if sees_light {
                continue;
            }
            let tri = desc.triangles[i];
            let x = eye + d * t;
            let v = tri.v.map(|v| v.as_dvec3());
            let mut n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
            if n.dot(d) > 0.0 {
                n = -n;
            }
            let m = 400;
            let mut g = 0.0;
            for j in 0..m {
                for k in 0..m {
                    let y =
                        la + lab * ((f64::from(j) + 0.5) / f64::from(m)) + lac * ((f64::from(k) + 0.5) / f64::from(m));
                    let to = y - x;
                    let d2 = to.length_squared();
                    let wi = to / d2.sqrt();
                    let (cx, cl) = (n.dot(wi), -ln.dot(wi));
                    if cx > 0.0 && cl > 0.0 {
                        g += cx * cl / d2;
                    }
                }
            }
            g *= area / f64::from(m * m);
            let kd = desc.materials[tri.material as usize].diffuse.as_dvec3();
            let expect = kd * light.radiance.as_dvec3() * g / std::f64::consts::PI;
            let got = img[(py * w + px) as usize];
            for ch in 0..3 {
                let rel = (got[ch] - expect[ch]).abs() / expect[ch].max(1e-6);
                assert!(rel < 2e-3, "pixel ({px},{py}) channel {ch}: strata {} vs quadrature {}", got[ch], expect[ch]);
            }
            checked += 1;
        }
    }
    assert!(checked >= 40, "only {checked} pixels hit the plane");
}

/// Per-pixel RGB values in f64.
type Rgb64 = Vec<[f64; 3]>;

/// Renders `scene` with the sampled `direct` integrator and with `analyticdirect` over identical
/// camera rays (same spp, pixel sampler and seed); returns (direct film means, its variance of the
/// mean, analytic means).
fn direct_and_exact(scene: std::path::PathBuf, spp: u32, sampler: Option<SamplerKind>) -> (Rgb64, Rgb64, Rgb64) {
    let mut o = opts(scene, 80, 60, spp);
    o.light_sampler = sampler;
    let f = film(&o);
    o.integrator = Some(IntegratorKind::AnalyticDirect);
    // (analyticdirect samples no light: a light sampler would be refused as changing nothing)
    o.light_sampler = None;
    let exact = means(&film(&o));
    (means(&f), var_of_mean(&f), exact)
}

/// The per-pixel z-test: direct - exact over sqrt(estimated variance of the mean). The camera rays
/// are identical, so the true variance of the difference is at most the film's variance (pixel
/// position variance cancels): the test is conservative. Pixels with zero variance (background,
/// the light itself) must match exactly. Returns (aggregate z over all pixels, count of |z| > 4).
fn z_test(d: &[[f64; 3]], var: &[[f64; 3]], exact: &[[f64; 3]]) -> (f64, usize) {
    let (mut sum, mut sum_var, mut outliers) = (0.0, 0.0, 0);
    for i in 0..d.len() {
        for c in 0..3 {
            if var[i][c] == 0.0 {
                assert!(
                    (d[i][c] - exact[i][c]).abs() <= 1e-6 * exact[i][c].abs().max(1.0),
                    "pixel {i}: {} vs {}",
                    d[i][c],
                    exact[i][c]
                );
                continue;
            }
            let z = (d[i][c] - exact[i][c]) / var[i][c].sqrt();
            outliers += usize::from(z.abs() > 4.0);
            sum += d[i][c] - exact[i][c];
            sum_var += var[i][c];
        }
    }
    (sum / sum_var.sqrt(), outliers)
}

/// `direct9` (9 random light samples) and `direct3x3` (3x3 stratified) have the geometry of
/// `analytic` with nothing occluding: both converge to the exact image. Aggregate |z| < 4.5 over all
/// 14400 pixel channels (false alarm ~7e-6 for a Gaussian), and at most 0.1% of pixel channels
/// beyond |z| = 4 (false alarm per channel ~6e-5 before the conservative variance).
#[test]
fn direct_converges_to_analytic() {
    let c = corpus_required();
    for name in ["direct9", "direct3x3"] {
        let (d, var, exact) = direct_and_exact(c.join(format!("hw2/{name}.test")), 16, None);
        let (z, outliers) = z_test(&d, &var, &exact);
        eprintln!("{name}: aggregate z = {z:.3}, pixels beyond 4 sigma: {outliers}");
        assert!(z.abs() < 4.5, "{name}: aggregate z = {z}");
        assert!(outliers <= d.len() * 3 / 1000, "{name}: {outliers} outliers");
    }
}

/// At equal samples (9 light samples, 16 spp), stratified (3x3 jittered) light samples have a far
/// lower error against the exact image than independent ones. The course's report measured a
/// variance ratio of 28.9 / 3.8 ~ 7.6; we require at least 3 (measured here: see the closing note).
/// Grid centres are deterministic (zero variance across runs) and Halton is unbiased too.
#[test]
fn stratified_beats_random_at_equal_samples() {
    let c = corpus_required();
    let mse = |sampler: SamplerKind| {
        let (d, _, exact) = direct_and_exact(c.join("hw2/direct9.test"), 16, Some(sampler));
        d.iter().zip(&exact).map(|(a, b)| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>()).sum::<f64>()
            / (3 * d.len()) as f64
    };
    let (random, strat, halton) =
        (mse(SamplerKind::INDEPENDENT), mse(SamplerKind::STRATIFIED), mse(SamplerKind::HALTON));
    eprintln!("MSE against exact: independent {random:.3e}, stratified {strat:.3e} (ratio {:.2}), halton {halton:.3e} (ratio {:.2})", random / strat, random / halton);
    assert!(random / strat > 3.0, "stratified should beat random by 3x: {random} vs {strat}");
    assert!(random / halton > 3.0, "halton should beat random by 3x: {random} vs {halton}");
}

/// Same input, same seed: bit-identical accumulation whatever the thread count.
#[test]
fn bit_identical_across_thread_counts() {
    let base = strata::session::RenderOptions { size: Some((72, 56)), spp: Some(3), seed: 7, ..Default::default() };
    let films: Vec<_> =
        [1usize, 2, 3].iter().map(|&t| film(&strata::session::RenderOptions { threads: t, ..base.clone() })).collect();
    for f in &films[1..] {
        assert_eq!(f.count, films[0].count);
        let bits = |f: &strata::film::Film| {
            f.sum.iter().chain(&f.sum_sq).flat_map(|p| p.map(f64::to_bits)).collect::<Vec<_>>()
        };
        assert_eq!(bits(f), bits(&films[0]));
    }
    // A different seed changes the image (the test can fail).
    let other = film(&strata::session::RenderOptions { threads: 2, seed: 8, ..base });
    assert_ne!(other.sum, films[0].sum);
}

/// Every hw2 scene renders at a small size with finite, non-trivial output.
#[test]
fn every_hw2_scene_renders() {
    let c = corpus_required();
    for name in ["analytic", "direct9", "direct3x3", "sphere", "cornell", "dragon"] {
        let mut o = opts(c.join(format!("hw2/{name}.test")), 64, 48, 1);
        o.light_samples = Some(4);
        let out = strata::session::render_to_film(&o).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(out.stats.counters.nonfinite, 0, "{name}");
        let m = means(&out.film);
        assert!(m.iter().all(|p| p.iter().all(|v| v.is_finite() && *v >= 0.0)), "{name}");
        let lit = m.iter().filter(|p| p.iter().sum::<f64>() > 1e-3).count();
        assert!(lit > m.len() / 10, "{name}: only {lit} lit pixels");
        assert_eq!(out.stats.counters.camera, 64 * 48, "{name}: one camera ray per pixel");
    }
}

/// Rendering in passes continues the same per-pixel running sums: 0..3 then 3..7 gives the very
/// bits of 0..7 (progressive rendering and, later, resume depend on it).
#[test]
fn passes_are_bit_identical_to_one_render() {
    let o = strata::session::RenderOptions {
        size: Some((40, 24)),
        spp: Some(7),
        seed: 5,
        threads: 2,
        ..Default::default()
    };
    let (scene, integ) = strata::session::prepare(&o).unwrap();
    let pool = strata::render::thread_pool(2).unwrap();
    let mut one = strata::film::Film::new(40, 24);
    strata::render::render(&scene, &integ, &mut one, 0..7, &pool);
    let mut parts = strata::film::Film::new(40, 24);
    strata::render::render(&scene, &integ, &mut parts, 0..3, &pool);
    strata::render::render(&scene, &integ, &mut parts, 3..7, &pool);
    assert_eq!(one.count, parts.count);
    let bits =
        |f: &strata::film::Film| f.sum.iter().chain(&f.sum_sq).flat_map(|p| p.map(f64::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&one), bits(&parts));
}

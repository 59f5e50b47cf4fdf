//! Tests of the warps: chi-square goodness of fit, normalization, sample pdf == pdf(), x8 == scalar per
//! lane, finiteness at the extremes of u, s and alpha.

#![allow(clippy::needless_range_loop)] // lane loops index several per-lane arrays

use super::chi2::{chi2_pvalue, chi2_test, ggx_core, phong_core, Grid, Rng, CHI2_TESTS, SIGNIFICANCE};
use super::*;
use crate::simd::{mask_from_bools, Vec3x8};

const SHININESS: [f32; 6] = [0.0, 1.0, 30.0, 1e3, 1e4, 1e6];
const ALPHAS: [f32; 5] = [1e-3, 1e-2, 0.1, 0.5, 1.0];
/// u values at and next to the ends of [0, 1] (1e-45 is the smallest subnormal).
const U_EDGES: [f32; 10] = [0.0, 1e-45, f32::MIN_POSITIVE, 1e-30, 1e-7, 0.25, 0.5, 0.999_999_9, 0.999_999_94, 1.0];
/// U_EDGES without the subnormal, for comparisons: `wide`'s `ln` flushes subnormals to zero where std's
/// does not, and a subnormal cosine carries too few bits to reproduce its pdf (both still finite).
const U_EDGES_NORMAL: [f32; 9] = [0.0, f32::MIN_POSITIVE, 1e-30, 1e-7, 0.25, 0.5, 0.999_999_9, 0.999_999_94, 1.0];

// ---- chi-square -----------------------------------------------------------------------------------

#[test]
fn chi2_uniform_hemisphere() {
    chi2_test(
        "uniform hemisphere",
        &Grid::uniform(20, 20),
        1,
        |r| sample_uniform_hemisphere(r.u2()).0,
        |w| uniform_hemisphere_pdf(w) as f64,
    );
}

#[test]
fn chi2_cosine_hemisphere() {
    chi2_test(
        "cosine hemisphere",
        &Grid::uniform(20, 20),
        2,
        |r| sample_cosine_hemisphere(r.u2()).0,
        |w| cosine_hemisphere_pdf(w) as f64,
    );
}

#[test]
fn chi2_phong_lobe() {
    for (k, s) in SHININESS.into_iter().enumerate() {
        let grid = Grid::lobe(Vec3::Z, phong_core(s as f64), 10, 10, 20);
        chi2_test(
            &format!("phong lobe s={s}"),
            &grid,
            10 + k as u64,
            |r| sample_phong_lobe(r.u2(), s).0,
            |w| phong_lobe_pdf(w, s) as f64,
        );
    }
}

#[test]
fn chi2_ggx_half_vector() {
    for (k, a) in ALPHAS.into_iter().enumerate() {
        let grid = Grid::lobe(Vec3::Z, ggx_core(a as f64), 10, 10, 20);
        chi2_test(
            &format!("ggx half vector alpha={a}"),
            &grid,
            20 + k as u64,
            |r| sample_ggx_half(r.u2(), a).0,
            |w| ggx_half_pdf(w, a) as f64,
        );
    }
}

/// The harness has power where it matters: a 3% error in a peaked exponent, or a GGX alpha off by 3%,
/// is rejected (these p-values are not part of the Bonferroni family: they must be tiny).
#[test]
fn chi2_rejects_slightly_wrong_lobes() {
    let alpha = SIGNIFICANCE / CHI2_TESTS as f64;
    let grid = Grid::lobe(Vec3::Z, phong_core(1e4), 10, 10, 20);
    let p = chi2_pvalue(
        "phong 1e4 vs 1.03e4",
        &grid,
        1_000_000,
        90,
        |r| sample_phong_lobe(r.u2(), 1e4).0,
        |w| phong_lobe_pdf(w, 1.03e4) as f64,
    );
    assert!(p < alpha, "p = {p}");
    let grid = Grid::lobe(Vec3::Z, ggx_core(1e-3), 10, 10, 20);
    let p = chi2_pvalue(
        "ggx 1e-3 vs 1.03e-3",
        &grid,
        1_000_000,
        91,
        |r| sample_ggx_half(r.u2(), 1e-3).0,
        |w| ggx_half_pdf(w, 1.03e-3) as f64,
    );
    assert!(p < alpha, "p = {p}");
}

/// Every warp's pdf integrates to 1 over the sphere, on a finer grid than the chi-square tests use.
#[test]
fn pdfs_integrate_to_one() {
    let check = |name: &str, g: Grid, pdf: &dyn Fn(Vec3) -> f64| {
        let i = g.integrate_sphere(pdf);
        assert!((i - 1.0).abs() < 2e-5, "{name}: integral {i}");
    };
    check("uniform", Grid::uniform(16, 8), &|w| uniform_hemisphere_pdf(w) as f64);
    check("cosine", Grid::uniform(16, 8), &|w| cosine_hemisphere_pdf(w) as f64);
    for s in SHININESS.into_iter().chain([0.5, 3e5]) {
        check(&format!("phong {s}"), Grid::lobe(Vec3::Z, phong_core(s as f64), 16, 16, 4), &|w| {
            phong_lobe_pdf(w, s) as f64
        });
    }
    for a in ALPHAS.into_iter().chain([1e-4, 0.3]) {
        check(&format!("ggx {a}"), Grid::lobe(Vec3::Z, ggx_core(a as f64), 16, 16, 4), &|w| ggx_half_pdf(w, a) as f64);
    }
}

// ---- sample pdf == pdf(), finiteness ---------------------------------------------------------------

fn close(a: f32, b: f32, rtol: f32) -> bool {
    (a - b).abs() <= rtol * a.abs().max(b.abs()) + 1e-30
}

/// A named warp: (name, sample, pdf of a direction).
type Warp = (String, Box<dyn Fn([f32; 2]) -> (Vec3, f32)>, Box<dyn Fn(Vec3) -> f32>);
/// A named x8 pdf with its scalar twin and the relative tolerance of their agreement.
type PdfTwin<'a> = (&'a str, F8, &'a dyn Fn(usize) -> f32, f32);

/// Every warp, with shininess and alpha across and beyond the tested ranges.
fn warps() -> Vec<Warp> {
    let mut v: Vec<Warp> = vec![
        ("uniform".into(), Box::new(sample_uniform_hemisphere), Box::new(uniform_hemisphere_pdf)),
        ("cosine".into(), Box::new(sample_cosine_hemisphere), Box::new(cosine_hemisphere_pdf)),
    ];
    for s in SHININESS.into_iter().chain([1e-3, 1e7]) {
        v.push((
            format!("phong {s}"),
            Box::new(move |u| sample_phong_lobe(u, s)),
            Box::new(move |w| phong_lobe_pdf(w, s)),
        ));
    }
    for a in ALPHAS.into_iter().chain([0.0, 1e-4, 3.0]) {
        v.push((format!("ggx {a}"), Box::new(move |u| sample_ggx_half(u, a)), Box::new(move |w| ggx_half_pdf(w, a))));
    }
    v
}

#[test]
fn sample_pdf_equals_pdf_of_the_sampled_direction() {
    let mut rng = Rng::new(3);
    let us: Vec<[f32; 2]> = (0..2000)
        .map(|_| rng.u2())
        .chain(U_EDGES_NORMAL.iter().flat_map(|&a| U_EDGES_NORMAL.iter().map(move |&b| [a, b])))
        .collect();
    for (name, sample, pdf) in warps() {
        for &u in &us {
            let (w, p) = sample(u);
            assert!(close(p, pdf(w), 2e-5), "{name} u={u:?}: sample pdf {p} vs pdf(w) {}", pdf(w));
        }
    }
}

#[test]
fn warps_are_finite_unit_at_the_extremes() {
    for (name, sample, pdf) in warps() {
        for &a in &U_EDGES {
            for &b in &U_EDGES {
                let (w, p) = sample([a, b]);
                assert!(w.is_finite() && (w.length() - 1.0).abs() < 1e-6, "{name} u=({a},{b}): w = {w}");
                assert!(p.is_finite() && p >= 0.0 && pdf(w).is_finite(), "{name} u=({a},{b}): pdf {p}");
                assert!(w.z >= 0.0, "{name} u=({a},{b}): below the lobe's horizon");
            }
        }
    }
    // pdfs of arbitrary directions, including the horizon, the axis and below
    for (name, _, pdf) in warps() {
        for w in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(1.0, 0.0, 1e-30),
            Vec3::new(1.0, 0.0, -1e-7),
            Vec3::new(1e-20, 0.0, 1.0),
        ] {
            let p = pdf(w);
            assert!(p.is_finite() && p >= 0.0, "{name} pdf({w}) = {p}");
        }
    }
}

/// The concentric map keeps strata compact: neighbouring u map to points at most ~pi/2 * 2|du| apart
/// (the square [-1,1]^2 has side 2; the ring's arc length is pi/4 per unit of the square's side),
/// unlike the polar map r = sqrt(u0) whose radial stretch diverges at the centre.
#[test]
fn concentric_map_has_bounded_distortion() {
    let n = 256;
    let p = |i: usize, j: usize| sample_cosine_hemisphere([i as f32 / n as f32, j as f32 / n as f32]).0.truncate();
    let mut worst = 0.0f32;
    for i in 0..n {
        for j in 0..n {
            worst = worst.max((p(i + 1, j) - p(i, j)).length()).max((p(i, j + 1) - p(i, j)).length());
        }
    }
    assert!(worst * n as f32 <= 2.0 * std::f32::consts::FRAC_PI_2 + 1e-3, "max stretch {}", worst * n as f32);
}

// ---- x8 == scalar ---------------------------------------------------------------------------------

/// Per-lane comparison of a vector with tolerance rtol relative to each component, plus `atol`.
fn close3(a: Vec3, b: Vec3, rtol: f32, atol: f32) -> bool {
    (a - b).abs().cmple(a.abs().max(b.abs()) * rtol + Vec3::splat(atol)).all()
}

/// Eight lanes of test inputs: lanes 0..6 random or edge values, lane 7 inactive with NaN inputs.
struct Lanes {
    u: [[f32; 2]; 8],
    mask: [bool; 8],
}

fn lanes(rng: &mut Rng, trial: usize) -> Lanes {
    let mut u = [[0.0f32; 2]; 8];
    for (i, l) in u.iter_mut().enumerate() {
        *l = if (trial + i).is_multiple_of(3) {
            let e = |k: u64| U_EDGES_NORMAL[(k % 9) as usize];
            [e(rng.next_u64()), e(rng.next_u64())]
        } else {
            rng.u2()
        };
    }
    u[7] = [f32::NAN, f32::NAN];
    Lanes { u, mask: [true, true, true, true, true, true, true, false] }
}

fn f8(a: [f32; 8]) -> F8 {
    F8::new(a)
}

fn u8x(l: &Lanes) -> [F8; 2] {
    [f8(l.u.map(|u| u[0])), f8(l.u.map(|u| u[1]))]
}

/// Checks an x8 warp against its scalar twin lane by lane, and that the inactive lane is zero.
fn check_warp(name: &str, l: &Lanes, x8: (Vec3x8, F8), scalar: impl Fn(usize) -> (Vec3, f32)) {
    let p8 = x8.1.to_array();
    for i in 0..8 {
        let (w8, pdf8) = (x8.0.lane(i), p8[i]);
        if !l.mask[i] {
            assert!(w8 == Vec3::ZERO && pdf8 == 0.0, "{name}: inactive lane {i} not zeroed");
            continue;
        }
        let (w, p) = scalar(i);
        // The pdf of a lobe is exp(s ln cos): its relative error is |s ln cos| times that of ln cos,
        // up to ~17 ulp for u >= 2^-24 (largest difference seen: < 4e-6).
        assert!(
            close3(w8, w, 2e-6, 1e-7) && close(pdf8, p, 2e-5),
            "{name} lane {i} u={:?}: x8 ({w8}, {pdf8}) scalar ({w}, {p})",
            l.u[i]
        );
    }
}

#[test]
fn warps_x8_match_scalar() {
    let mut rng = Rng::new(4);
    for trial in 0..500 {
        let l = lanes(&mut rng, trial);
        let m = mask_from_bools(l.mask);
        let u = u8x(&l);
        let s_l: [f32; 8] = std::array::from_fn(|i| SHININESS[(trial + i) % 6]);
        let a_l: [f32; 8] = std::array::from_fn(|i| [1e-4, 1e-3, 0.1, 0.5, 1.0][(trial + i) % 5]);
        check_warp("uniform", &l, sample_uniform_hemisphere_x8(u, m), |i| sample_uniform_hemisphere(l.u[i]));
        check_warp("cosine", &l, sample_cosine_hemisphere_x8(u, m), |i| sample_cosine_hemisphere(l.u[i]));
        check_warp("phong", &l, sample_phong_lobe_x8(u, f8(s_l), m), |i| sample_phong_lobe(l.u[i], s_l[i]));
        check_warp("ggx", &l, sample_ggx_half_x8(u, f8(a_l), m), |i| sample_ggx_half(l.u[i], a_l[i]));

        // pdfs of given directions: the scalar samples of the lanes, one below the horizon, one zero
        let mut ws: [Vec3; 8] = std::array::from_fn(|i| sample_phong_lobe([rng.f32(), rng.f32()], s_l[i]).0);
        ws[1].z = -ws[1].z;
        ws[2] = Vec3::X;
        let w8 = Vec3x8::from_lanes(ws);
        let pdfs: [PdfTwin; 4] = [
            ("uniform pdf", uniform_hemisphere_pdf_x8(w8, m), &|i| uniform_hemisphere_pdf(ws[i]), 0.0),
            ("cosine pdf", cosine_hemisphere_pdf_x8(w8, m), &|i| cosine_hemisphere_pdf(ws[i]), 0.0),
            ("phong pdf", phong_lobe_pdf_x8(w8, f8(s_l), m), &|i| phong_lobe_pdf(ws[i], s_l[i]), 2e-5),
            ("ggx pdf", ggx_half_pdf_x8(w8, f8(a_l), m), &|i| ggx_half_pdf(ws[i], a_l[i]), 0.0),
        ];
        for (name, p8, scalar, rtol) in pdfs {
            for (i, &p) in p8.to_array().iter().enumerate() {
                let want = if l.mask[i] { scalar(i) } else { 0.0 };
                assert!(close(p, want, rtol), "{name} lane {i}: x8 {p} scalar {want}");
            }
        }
    }
}

#[test]
fn parallelogram_and_solid_angle_x8_match_scalar_exactly() {
    let mut rng = Rng::new(5);
    let mut v = || Vec3::new(rng.f32() * 4.0 - 2.0, rng.f32() * 4.0 - 2.0, rng.f32() * 4.0 - 2.0);
    for trial in 0..200 {
        let a: [Vec3; 8] = std::array::from_fn(|_| v());
        let ab: [Vec3; 8] = std::array::from_fn(|_| v());
        let mut ac: [Vec3; 8] = std::array::from_fn(|_| v());
        ac[0] = ab[0] * 2.0; // degenerate
        let mut r2 = Rng::new(100 + trial);
        let l = lanes(&mut r2, trial as usize);
        let m = mask_from_bools(l.mask);
        let (p8, pdf8) =
            sample_parallelogram_x8(Vec3x8::from_lanes(a), Vec3x8::from_lanes(ab), Vec3x8::from_lanes(ac), u8x(&l), m);
        let dist2: [f32; 8] = std::array::from_fn(|i| [0.0, 1e-3, 1.0, 7.0, 1e30][(trial as usize + i) % 5]);
        let cos_l: [f32; 8] = std::array::from_fn(|i| [0.0, -0.5, 1e-30, 1.0, -1e-45, 0.3][(trial as usize + i) % 6]);
        let pa: [f32; 8] = std::array::from_fn(|i| if i == 3 { 0.0 } else { pdf8.to_array()[i] });
        let sa8 = pdf_area_to_solid_angle_x8(f8(pa), f8(dist2), f8(cos_l), m).to_array();
        for i in 0..8 {
            let (p, pdf) = if l.mask[i] { sample_parallelogram(a[i], ab[i], ac[i], l.u[i]) } else { (Vec3::ZERO, 0.0) };
            assert_eq!((p8.lane(i), pdf8.to_array()[i]), (p, pdf), "lane {i}");
            let sa = if l.mask[i] { pdf_area_to_solid_angle(pa[i], dist2[i], cos_l[i]) } else { 0.0 };
            assert_eq!(sa8[i], sa, "lane {i}");
            assert!(sa.is_finite() && sa >= 0.0);
            if l.mask[i] {
                let area = ab[i].cross(ac[i]).length();
                assert!(
                    i == 0 && pdf == 0.0 || (pdf * area - 1.0).abs() < 1e-5,
                    "lane {i}: pdf_area {pdf}, area {area}"
                );
                // the point lies in the parallelogram: its (u, v) coordinates are in [0, 1]
                let n = ab[i].cross(ac[i]);
                if n.length_squared() > 1e-6 {
                    let d = p - a[i];
                    let (uu, vv) =
                        (d.cross(ac[i]).dot(n) / n.length_squared(), ab[i].cross(d).dot(n) / n.length_squared());
                    assert!((-1e-4..=1.0001).contains(&uu) && (-1e-4..=1.0001).contains(&vv), "({uu}, {vv})");
                }
            }
        }
    }
    assert_eq!(pdf_area_to_solid_angle(0.25, 4.0, -0.5), 2.0);
    assert_eq!(pdf_area_to_solid_angle(0.25, 4.0, 0.0), 0.0);
    assert_eq!(pdf_area_to_solid_angle(0.0, 4.0, 1.0), 0.0);
    assert_eq!(pdf_area_to_solid_angle(1.0, 1e30, 1e-30), f32::MAX);
}

#[test]
fn power_heuristic_is_robust_and_x8_matches_exactly() {
    let vals = [0.0, 1e-45, 1e-30, 0.5, 1.0, 3.0, 1e30, f32::MAX, f32::INFINITY, f32::NAN, -1.0];
    for &a in &vals {
        for &b in &vals {
            let w = power_heuristic(a, b);
            assert!(w.is_finite() && (0.0..=1.0).contains(&w), "w({a}, {b}) = {w}");
            let ok = |x: f32| x.is_finite() && x > 0.0;
            if ok(a) || ok(b) {
                assert!((w + power_heuristic(b, a) - 1.0).abs() < 1e-6, "w({a},{b}) + w({b},{a}) != 1");
            }
            let w8 = power_heuristic_x8(
                F8::splat(a),
                F8::splat(b),
                mask_from_bools([true, false, true, true, true, true, true, true]),
            );
            assert_eq!(w8.to_array()[0].to_bits(), w.to_bits(), "({a}, {b})");
            assert_eq!(w8.to_array()[1], 0.0);
        }
    }
    assert_eq!(power_heuristic(1.0, 0.0), 1.0);
    assert_eq!(power_heuristic(0.0, 0.0), 0.0);
    assert_eq!(power_heuristic(f32::INFINITY, 1.0), 1.0);
    assert_eq!(power_heuristic(f32::INFINITY, f32::INFINITY), 0.5);
    assert!((power_heuristic(1.0, 2.0) - 0.2).abs() < 1e-7);
    assert!((power_heuristic(3e-30, 4e-30) - 0.36).abs() < 1e-6);
    assert!((power_heuristic(3e30, 4e30) - 0.36).abs() < 1e-6);
}

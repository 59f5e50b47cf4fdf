//! Tests of the microfacet distributions: the transcendentals against f64 references, x8 == scalar bit
//! for bit, D's normalization, G1 against the projected-area integral, chi-square of both samplers
//! against their pdf, and the stiff cases (alpha 1e-4 .. 1, anisotropy 1:100, grazing and lower-side
//! views, u on the square's edges) finite.

use super::real::{beckmann_a_lambda, erf, erfinv, exp, ln, sincos_2pi};
use super::{Distribution, Microfacet, V3};
use crate::sampling::chi2::{chi2_test, ggx_core, Grid, Rng};
use crate::simd::{Vec3x8, F8};
use glam::{DVec3, Vec3};
use std::f64::consts::PI;

const KINDS: [Distribution; 2] = [Distribution::Beckmann, Distribution::Ggx];

fn mf(kind: Distribution, au: f32, av: f32, visible: bool) -> Microfacet<f32> {
    Microfacet::new(kind, au, av, visible)
}

/// Direction at polar angle theta (degrees) and azimuth phi (degrees).
fn dir(theta: f64, phi: f64) -> Vec3 {
    let (t, p) = (theta.to_radians(), phi.to_radians());
    DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()).as_vec3()
}

fn v(w: Vec3) -> V3<f32> {
    w.into()
}

#[test]
fn transcendentals_match_f64() {
    let mut rng = Rng::new(1);
    for i in 0..200_000 {
        let x = if i < 1000 { -87.0 + 175.0 * i as f32 / 1000.0 } else { -87.0 + 175.0 * rng.f32() };
        let (got, want) = (exp(x) as f64, (x as f64).exp());
        assert!((got - want).abs() <= 2.5e-7 * want, "exp({x}) = {got}, want {want}");
        let y = f32::from_bits(0x0080_0000 + (rng.next_u64() % 0x7e00_0000) as u32);
        let (got, want) = (ln(y) as f64, (y as f64).ln());
        assert!((got - want).abs() <= 2.5e-7 * want.abs().max(1.0), "ln({y}) = {got}, want {want}");
        let z = 12.0 * rng.f32() - 6.0;
        let (got, want) = (erf(z) as f64, statrs::function::erf::erf(z as f64));
        assert!((got - want).abs() <= 3e-7, "erf({z}) = {got}, want {want}");
        let b = (2.0 * rng.f32() - 1.0) * (1.0 - 1e-6);
        let (got, want) = (erfinv(b) as f64, statrs::function::erf::erf_inv(b as f64));
        assert!((got - want).abs() <= 2e-6 * want.abs().max(1e-3), "erfinv({b}) = {got}, want {want}");
        let u = rng.f32();
        let (s, c) = sincos_2pi(u);
        let (ws, wc) = (2.0 * PI * u as f64).sin_cos();
        assert!((s as f64 - ws).abs() <= 3e-7 && (c as f64 - wc).abs() <= 3e-7, "sincos_2pi({u}) = {s} {c}");
        // a Lambda(a) = (e^-a^2/sqrt(pi) - a erfc(a))/2, in f64 from the complementary error function.
        let a = (10.0 * rng.f32()).powi(2) * 0.1;
        let a64 = a as f64;
        let want = 0.5 * ((-a64 * a64).exp() / PI.sqrt() - a64 * statrs::function::erf::erfc(a64));
        let got = beckmann_a_lambda(a) as f64;
        assert!((got - want).abs() <= 1e-5 * want + 1e-8, "a Lambda({a}) = {got}, want {want}");
    }
    assert_eq!((exp(-100.0f32), exp(f32::NEG_INFINITY)), (0.0, 0.0));
    assert_eq!((erf(f32::INFINITY), erf(f32::NEG_INFINITY), erf(0.0f32)), (1.0, -1.0, 0.0));
    assert!(erfinv(1.0f32).is_finite() && erfinv(-1.0f32) == -erfinv(1.0f32));
    assert_eq!(beckmann_a_lambda(f32::INFINITY), 0.0);
    assert!((beckmann_a_lambda(0.0f32) as f64 - 0.5 / PI.sqrt()).abs() < 1e-7);
}

/// Random distributions, views and normals: alphas log-uniform in [1e-4, 1] each (so anisotropy up to
/// 1:10^4), views anywhere on the sphere with a share exactly grazing.
fn random_case(rng: &mut Rng) -> (f32, f32, Vec3, Vec3, [f32; 2]) {
    let alpha = |rng: &mut Rng| 10f32.powf(-4.0 * rng.f32());
    let unit = |rng: &mut Rng| {
        let z = 2.0 * rng.f32() - 1.0;
        let p = std::f32::consts::TAU * rng.f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * p.cos(), r * p.sin(), if rng.f32() < 0.1 { 0.0 } else { z }).normalize()
    };
    let (au, av) = (alpha(rng), alpha(rng));
    let (wo, m) = (unit(rng), unit(rng));
    (au, av, wo, m, rng.u2())
}

#[test]
fn x8_matches_scalar_bit_for_bit() {
    let mut rng = Rng::new(2);
    for kind in KINDS {
        for visible in [true, false] {
            for _ in 0..4000 {
                let c: [_; 8] = std::array::from_fn(|_| random_case(&mut rng));
                let f8 = |f: &dyn Fn(usize) -> f32| F8::new(std::array::from_fn(f));
                let m8 = Microfacet::new(kind, f8(&|i| c[i].0), f8(&|i| c[i].1), visible);
                let wo8: V3<F8> = Vec3x8::from_lanes(c.map(|x| x.2)).into();
                let n8: V3<F8> = Vec3x8::from_lanes(c.map(|x| x.3)).into();
                let u8 = [f8(&|i| c[i].4[0]), f8(&|i| c[i].4[1])];
                let (d8, g8, a8, p8) = (m8.d(n8), m8.g1(wo8, n8), m8.projected_area(wo8), m8.pdf(wo8, n8));
                let (s8, sp8) = m8.sample(wo8, u8);
                let s8 = Vec3x8::from(s8);
                for (i, &(au, av, wo, n, u)) in c.iter().enumerate() {
                    let m = mf(kind, au, av, visible);
                    let (s, sp) = m.sample(v(wo), u);
                    let want = [m.d(v(n)), m.g1(v(wo), v(n)), m.projected_area(v(wo)), m.pdf(v(wo), v(n)), sp];
                    let got = [d8, g8, a8, p8, sp8].map(|x| x.to_array()[i]);
                    assert_eq!(
                        want.map(f32::to_bits),
                        got.map(f32::to_bits),
                        "{kind:?} lane {i}: {au} {av} {wo} {n} {u:?}"
                    );
                    assert_eq!(Vec3::from(s).to_array().map(f32::to_bits), s8.lane(i).to_array().map(f32::to_bits));
                }
            }
        }
    }
}

/// Lobe-adapted grid about +z for a distribution of largest alpha `a`.
fn grid(a: f32) -> Grid {
    Grid::lobe(Vec3::Z, ggx_core(a as f64), 24, 16, 48)
}

#[test]
fn d_cos_integrates_to_one() {
    for kind in KINDS {
        for (au, av) in [(1e-4, 1e-4), (0.01, 0.01), (0.3, 0.3), (1.0, 1.0), (0.005, 0.5), (0.5, 0.005), (1.0, 0.01)] {
            let m = mf(kind, au, av, true);
            let total = grid(au.max(av)).integrate_sphere(&|w| (m.d(v(w)) * w.z.max(0.0)) as f64);
            assert!((total - 1.0).abs() < 2e-4, "{kind:?} ({au}, {av}): integral of D cos = {total}");
        }
    }
}

/// Smith's G1 against its definition: the projected area of the microsurface seen from w,
/// integral of max(0, w.m) D(m) dm, equals A(w) = w.z / G1(w).
#[test]
fn g1_matches_the_projected_area_integral() {
    for kind in KINDS {
        for (au, av) in [(0.01, 0.01), (0.3, 0.3), (1.0, 1.0), (0.02, 1.0), (0.6, 0.1)] {
            for (theta, phi) in [(0.0, 0.0), (30.0, 10.0), (60.0, 45.0), (80.0, 100.0), (89.0, 200.0), (89.9, 300.0)] {
                let m = mf(kind, au, av, true);
                let w = dir(theta, phi);
                let area = grid(au.max(av)).integrate_sphere(&|n| (m.d(v(n)) * w.dot(n).max(0.0)) as f64);
                let want = w.z as f64 / area;
                let got = m.g1(v(w), v(Vec3::Z)) as f64;
                assert!(
                    (got - want).abs() < 2e-4 * want.max(1e-3),
                    "{kind:?} ({au}, {av}) theta {theta}: G1 = {got}, integral gives {want}"
                );
            }
        }
    }
}

fn chi2_case(kind: Distribution, au: f32, av: f32, visible: bool, wo: Vec3, seed: u64) {
    let m = mf(kind, au, av, visible);
    let name = format!("microfacet {kind:?} ({au}, {av}) visible={visible} wo={wo}");
    chi2_test(
        &name,
        &grid(au.max(av)),
        seed,
        |rng| loop {
            let (n, p) = m.sample(v(wo), rng.u2());
            if p > 0.0 {
                break n.into();
            }
        },
        |n| m.pdf(v(wo), v(n)) as f64,
    );
}

#[test]
fn chi2_visible_normals_ggx() {
    let g = Distribution::Ggx;
    chi2_case(g, 0.3, 0.3, true, dir(45.0, 20.0), 11);
    chi2_case(g, 1.0, 1.0, true, dir(0.0, 0.0), 12);
    chi2_case(g, 0.01, 1.0, true, dir(80.0, 30.0), 13);
    chi2_case(g, 0.5, 0.5, true, dir(89.9, 130.0), 14);
    chi2_case(g, 1e-4, 1e-4, true, dir(70.0, 0.0), 15);
    chi2_case(g, 0.4, 0.1, true, -dir(60.0, 250.0), 16);
}

#[test]
fn chi2_visible_normals_beckmann() {
    let b = Distribution::Beckmann;
    chi2_case(b, 0.3, 0.3, true, dir(45.0, 20.0), 21);
    chi2_case(b, 1.0, 1.0, true, dir(0.0, 0.0), 22);
    chi2_case(b, 0.01, 1.0, true, dir(80.0, 30.0), 23);
    chi2_case(b, 0.5, 0.5, true, dir(89.9, 130.0), 24);
    chi2_case(b, 1e-4, 1e-4, true, dir(70.0, 0.0), 25);
    chi2_case(b, 0.4, 0.1, true, -dir(60.0, 250.0), 26);
}

#[test]
fn chi2_all_normals() {
    chi2_case(Distribution::Ggx, 0.02, 0.6, false, dir(30.0, 0.0), 31);
    chi2_case(Distribution::Beckmann, 0.6, 0.02, false, dir(30.0, 0.0), 32);
}

#[test]
fn stiff_cases_stay_finite() {
    let alphas = [1e-4, 1e-3, 0.01, 0.1, 0.5, 1.0];
    let edge = [0.0, 1e-7, 0.5, 1.0 - 5.960_464_5e-8, 1.0];
    let views = [
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        Vec3::new(0.6, -0.8, 0.0),
        Vec3::new(1.0, 0.0, 1e-7).normalize(),
        Vec3::new(0.0, 1.0, -1e-6).normalize(),
        dir(89.99, 45.0),
        dir(45.0, 45.0),
    ];
    for kind in KINDS {
        for visible in [true, false] {
            for &au in &alphas {
                for av in [au, (au * 100.0f32).min(1.0), au / 100.0] {
                    let m = mf(kind, au, av, visible);
                    for &wo in &views {
                        for &u0 in &edge {
                            for &u1 in &edge {
                                let (n, p) = m.sample(v(wo), [u0, u1]);
                                let n: Vec3 = n.into();
                                let ctx = format!("{kind:?} ({au}, {av}) visible={visible} wo={wo} u=({u0}, {u1})");
                                assert!(n.is_finite() && p.is_finite() && p >= 0.0, "{ctx}: m {n} pdf {p}");
                                if p > 0.0 {
                                    assert!((n.length() - 1.0).abs() < 1e-5 && n.z >= 0.0, "{ctx}: m {n}");
                                }
                                let (d, g1) = (m.d(v(n)), m.g1(v(wo), v(n)));
                                assert!(d.is_finite() && d >= 0.0, "{ctx}: D {d}");
                                assert!((0.0..=1.0).contains(&g1), "{ctx}: G1 {g1}");
                                let a = m.projected_area(v(wo));
                                assert!(a.is_finite() && a > 0.0, "{ctx}: A {a}");
                            }
                        }
                    }
                }
            }
        }
    }
}

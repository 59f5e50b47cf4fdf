//! Masks around course and registry BSDFs, through [`Material8`]'s kernel entry points (what the
//! integrators call): eval scaled by the opacity, the null lobe's share and sample, the nested
//! directions against the nested pdf (chi-square), the white furnace.

use super::super::interface::{flags, BsdfParams, Params8};
use super::super::{roughconductor, AllLobes, ImportanceSampling, Material, Material8};
use crate::bsdf::microfacet::Distribution;
use crate::sampling::chi2::{chi2_pvalue, Grid, Rng, SIGNIFICANCE};
use crate::simd::{mask_all, Vec3x8, F8};
use glam::Vec3;

const S: ImportanceSampling = ImportanceSampling::Brdf;

/// A white Lambertian course material (kd = 1) or a registry row, masked by `opacity`.
fn material(row: Option<BsdfParams>, opacity: f32) -> Material8 {
    let lambert = Material { kd: Vec3::ONE, ks: Vec3::ZERO, shininess: 1.0, alpha: 1.0, kind: Default::default() };
    let mut m = Material8::from_lanes([lambert; 8]);
    let mut p = row.unwrap_or(BsdfParams::COURSE);
    p.opacity = opacity;
    m.bsdf = Params8::splat(&p);
    m
}

fn rough() -> BsdfParams {
    let (eta, k) = (Vec3::new(0.2, 0.92, 1.1), Vec3::new(3.9, 2.45, 2.14));
    roughconductor::params(Distribution::Ggx, 0.3, 0.3, true, eta, k, Vec3::ONE)
}

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// (wi, weight, pdf, flags, null) of one sample of lane 0.
fn sample1(m: &Material8, wo: Vec3, ul: f32, u: [f32; 2]) -> (Vec3, Vec3, f32, u32) {
    let s = m.sample_bsdf_k::<AllLobes>(S, Vec3x8::splat(wo), [F8::splat(u[0]), F8::splat(u[1])], F8::splat(ul), mask_all());
    let (wi, pdf) = (s.wi.lane(0), s.pdf.to_array()[0]);
    if s.general.to_bitmask() & 1 != 0 {
        (wi, s.bsdf.weight.lane(0), pdf, s.bsdf.flags.to_array()[0])
    } else {
        let w = if pdf > 0.0 { s.f.lane(0) * (wi.z / pdf) } else { Vec3::ZERO };
        (wi, w, pdf, flags::REFLECTION)
    }
}

fn eval1(m: &Material8, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
    let (f, pdf) = m.eval_pdf_k::<AllLobes>(S, Vec3x8::splat(wo), Vec3x8::splat(wi), mask_all());
    (f.lane(0), pdf.to_array()[0])
}

#[test]
fn eval_is_the_nested_eval_times_the_opacity() {
    for row in [None, Some(rough())] {
        let (opaque, half) = (material(row, 1.0), material(row, 0.4));
        for (a, b) in [(dir(30.0, 10.0), dir(40.0, 200.0)), (dir(60.0, 0.0), dir(55.0, 170.0))] {
            let ((f1, p1), (f2, p2)) = (eval1(&opaque, a, b), eval1(&half, a, b));
            assert!(f1.max_element() > 0.0 && p1 > 0.0);
            assert!((f2 - f1 * 0.4).abs().max_element() <= 1e-6 * f1.max_element());
            assert!((p2 - p1 * 0.4).abs() <= 1e-6 * p1);
        }
        assert_eq!(eval1(&material(row, 0.0), dir(30.0, 0.0), dir(30.0, 180.0)), (Vec3::ZERO, 0.0));
    }
}

/// The null lobe is drawn with probability 1 - opacity: `wi = -wo`, weight 1, pdf 1 - opacity,
/// flagged null, delta and transmission; the other samples are the nested BSDF's direction and
/// weight with the masked pdf (the opacity times the nested pdf, what `eval_pdf` gives there), as
/// Mitsuba 3.9.1's `mask` returns from `sample` (queried from the peer: opacity 0.4 around a
/// diffuse, nested pdf 0.2917, mask sample pdf 0.1167); with the nested pdf unscaled the MIS
/// weights of a next event and of a BSDF sample finding the same light sum to more than 1.
#[test]
fn null_lobe_share_and_sample() {
    let n = 20_000;
    for row in [None, Some(rough())] {
        for opacity in [0.0f32, 0.3, 0.9] {
            let (m, opaque) = (material(row, opacity), material(row, 1.0));
            let wo = dir(35.0, 40.0);
            let mut rng = Rng::new(17);
            let mut nulls = 0.0f64;
            for _ in 0..n {
                let (ul, u) = (rng.f32(), [rng.f32(), rng.f32()]);
                let (wi, w, pdf, fl) = sample1(&m, wo, ul, u);
                if fl & flags::NULL != 0 {
                    nulls += 1.0;
                    assert_eq!(fl, flags::NULL_TRANSMISSION);
                    assert!((wi + wo).length() < 1e-6 && w == Vec3::ONE && (pdf - (1.0 - opacity)).abs() < 1e-6);
                } else if pdf > 0.0 {
                    assert!(ul < opacity);
                    let (f, p) = eval1(&opaque, wo, wi);
                    let masked = eval1(&m, wo, wi).1;
                    assert!((pdf - masked).abs() <= 1e-5 * masked.max(1.0), "sample pdf {pdf} vs eval_pdf's {masked}");
                    let want = f * (wi.z / p);
                    assert!((w - want).abs().max_element() <= 1e-4 * want.max_element().max(1e-6));
                }
            }
            let share = nulls / n as f64;
            let q = f64::from(1.0 - opacity);
            let sd = (q * (1.0 - q) / n as f64).sqrt().max(1e-9);
            assert!((share - q).abs() <= 6.0 * sd + 1e-12, "opacity {opacity}: null share {share}");
        }
    }
}

/// The nested directions of a masked BSDF follow the nested pdf (its masked pdf / opacity).
#[test]
fn nested_directions_match_the_nested_pdf_chi_square() {
    const N: usize = 200_000;
    let grid = Grid::uniform(36, 72);
    for (k, row) in [None, Some(rough())].into_iter().enumerate() {
        let opacity = 0.6f32;
        let m = material(row, opacity);
        let wo = dir(40.0, 30.0);
        let total = grid.integrate_sphere(&|wi| eval1(&m, wo, wi).1 as f64);
        let mut pick = Rng::new(5);
        let sample = |rng: &mut Rng| loop {
            let (wi, _, pdf, fl) = sample1(&m, wo, pick.f32(), [rng.f32(), rng.f32()]);
            if fl & flags::NULL == 0 && pdf > 0.0 {
                return wi;
            }
        };
        let name = format!("mask row {k}");
        let pv = chi2_pvalue(&name, &grid, N, 9 + k as u64, sample, |wi| eval1(&m, wo, wi).1 as f64 / total);
        assert!(pv >= SIGNIFICANCE / 2.0, "{name}: chi-square rejects the nested sampler (p = {pv:.3e})");
        // The masked pdf integrates to the opacity times the nested BSDF's own share.
        let nested = grid.integrate_sphere(&|wi| eval1(&material(row, 1.0), wo, wi).1 as f64);
        assert!((total - f64::from(opacity) * nested).abs() < 1e-3, "{name}: {total} vs {opacity} x {nested}");
    }
}

/// White furnace: a mask around a white Lambertian returns every sample with weight 1 (the
/// nested ones f cos / pdf = 1, the null ones 1), so the mask neither gains nor loses energy; around
/// a conductor the mean is opacity x albedo + (1 - opacity) <= 1.
#[test]
fn white_furnace() {
    let wo = dir(50.0, 120.0);
    let mut rng = Rng::new(3);
    let m = material(None, 0.35);
    for _ in 0..4000 {
        let (_, w, pdf, _) = sample1(&m, wo, rng.f32(), [rng.f32(), rng.f32()]);
        assert!(pdf > 0.0 && (w - Vec3::ONE).abs().max_element() < 1e-5, "weight {w}");
    }
    let (masked, opaque) = (material(Some(rough()), 0.35), material(Some(rough()), 1.0));
    let mean = |m: &Material8, rng: &mut Rng| {
        let n = 100_000;
        (0..n).map(|_| sample1(m, wo, rng.f32(), [rng.f32(), rng.f32()]).1.max_element() as f64).sum::<f64>() / n as f64
    };
    let (a, albedo) = (mean(&masked, &mut Rng::new(4)), mean(&opaque, &mut Rng::new(4)));
    assert!(a <= 1.0 + 1e-3 && (a - (0.35 * albedo + 0.65)).abs() < 0.01, "furnace {a}, albedo {albedo}");
}

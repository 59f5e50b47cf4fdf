//! Tests generated from the BSDF registry: every entry of [`AllBsdfs`] with every row of its
//! `test_params`, so a new BSDF is covered by adding its registry line. Checked per entry: the
//! chi-square of `sample` against `eval_pdf`'s pdf over the whole sphere (transmission included;
//! the delta lobes' share against their reported probability), `sample`'s weight against
//! f |cos| / pdf, the white furnace (<= 1), reciprocity of reflection, lanes of one packet
//! independent of one another (bit for bit), and finite results and no energy gain in stiff
//! cases.

use super::interface::{flags, BsdfParams, BsdfSet, Member, Params8, Sample8};
use super::AllBsdfs;
use crate::sampling::chi2::{chi2_pvalue, Grid, Rng, SIGNIFICANCE};
use crate::simd::{mask_all, Vec3x8, F8};
use glam::Vec3;

fn members() -> Vec<Member> {
    let mut v = Vec::new();
    AllBsdfs::members(&mut v);
    v
}

/// One lane's (f, pdf) at (wo, wi) in the surface frame.
fn eval1(p: &BsdfParams, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
    let (f, pdf) = AllBsdfs::eval_pdf(
        &Params8::splat(p),
        Vec3x8::splat(wo),
        Vec3x8::splat(wi),
        mask_all(),
        (Vec3x8::ZERO, F8::ZERO),
    );
    (f.lane(0), pdf.to_array()[0])
}

/// One lane's sample, as (wi, weight, pdf, flags, eta).
fn sample1(p: &BsdfParams, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> (Vec3, Vec3, f32, u32, f32) {
    let s = AllBsdfs::sample(
        &Params8::splat(p),
        Vec3x8::splat(wo),
        F8::splat(u_lobe),
        [F8::splat(u[0]), F8::splat(u[1])],
        mask_all(),
        Sample8::NONE,
    );
    (s.wi.lane(0), s.weight.lane(0), s.pdf.to_array()[0], s.flags.to_array()[0], s.eta.to_array()[0])
}

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// The viewing directions every entry is tested from: above, grazing and (for BSDFs that see
/// their back) below.
fn views(m: &Member) -> Vec<Vec3> {
    let mut v = vec![dir(30.0, 20.0), dir(75.0, 200.0)];
    if m.flags & flags::TRANSMISSION != 0 {
        v.push(dir(140.0, 60.0));
    }
    v
}

#[test]
fn registry_ids_are_distinct_and_flags_declared() {
    let ms = members();
    assert!(!ms.is_empty());
    for (i, m) in ms.iter().enumerate() {
        assert!((1..24).contains(&m.id), "{}: id {} outside 1..24", m.name, m.id);
        assert!(ms[..i].iter().all(|o| o.id != m.id && o.name != m.name), "{}: id or name used twice", m.name);
        assert!(m.flags & (flags::REFLECTION | flags::TRANSMISSION) != 0, "{}: no side in its flags", m.name);
        assert!(m.flags & (flags::DIFFUSE | flags::GLOSSY | flags::DELTA) != 0, "{}: no lobe kind", m.name);
        assert!(!(m.test_params)().is_empty(), "{}: no test rows", m.name);
        assert!((m.test_params)().iter().all(|p| p.kind == m.id), "{}: a test row of another kind", m.name);
    }
}

/// Chi-square of the directions of the non-delta lobes against the pdf (conditioned on a
/// non-delta lobe), and a binomial check of the delta lobes' share against their reported
/// probabilities. Bonferroni over the tests run here.
#[test]
fn sample_matches_pdf_chi_square() {
    const N: usize = 200_000;
    let mut runs = Vec::new();
    for m in members() {
        for (r, p) in (m.test_params)().iter().enumerate() {
            for (k, &wo) in views(&m).iter().enumerate() {
                runs.push((m, *p, r, k, wo));
            }
        }
    }
    let n_chi2 = runs.iter().filter(|(m, ..)| m.flags & (flags::DIFFUSE | flags::GLOSSY) != 0).count().max(1);
    let alpha = SIGNIFICANCE / n_chi2 as f64;
    for (m, p, r, k, wo) in runs {
        let name = format!("{} row {r} view {k}", m.name);
        // The delta lobes: their share of samples against their probabilities.
        let mut rng = Rng::new(7 + r as u64 * 31 + k as u64);
        let mut n_delta = 0.0f64;
        for _ in 0..N / 10 {
            let (_, w, pdf, fl, _) = sample1(&p, wo, rng.f32(), [rng.f32(), rng.f32()]);
            assert!(w.is_finite() && pdf.is_finite(), "{name}: sample not finite");
            // A failed sample (a glossy reflection below the horizon) is in no lobe's share.
            if fl & flags::DELTA != 0 || fl == 0 {
                n_delta += 1.0;
            }
        }
        if m.flags & (flags::DIFFUSE | flags::GLOSSY) == 0 {
            // Only delta lobes: each sample's pdf is its lobe's probability; the lobes' shares.
            let mut rng = Rng::new(11 + r as u64);
            let (mut n_r, mut p_r, mut n) = (0.0f64, 0.0f64, 0.0f64);
            for _ in 0..N / 10 {
                let (_, _, pdf, fl, _) = sample1(&p, wo, rng.f32(), [rng.f32(), rng.f32()]);
                if fl == 0 {
                    continue;
                }
                n += 1.0;
                if fl & flags::REFLECTION != 0 {
                    n_r += 1.0;
                    p_r = pdf as f64;
                } else {
                    p_r = 1.0 - pdf as f64;
                }
            }
            if n > 0.0 {
                let sd = (n * p_r * (1.0 - p_r)).sqrt().max(1.0);
                assert!((n_r - n * p_r).abs() < 6.0 * sd, "{name}: {n_r} reflections of {n}, expected {}", n * p_r);
            }
            continue;
        }
        let grid = Grid::uniform(36, 72);
        let total = grid.integrate_sphere(&|wi| eval1(&p, wo, wi).1 as f64);
        // The share of the samples in non-delta lobes agrees with the pdf's integral.
        let share = 1.0 - n_delta / (N / 10) as f64;
        let sd = (total * (1.0 - total) / (N / 10) as f64).sqrt().max(1e-4);
        assert!((share - total).abs() < 6.0 * sd, "{name}: non-delta share {share}, pdf integrates to {total}");
        if total < 1e-3 {
            continue;
        }
        let mut rng = Rng::new(1000 + r as u64 * 31 + k as u64);
        let sample = |rng: &mut Rng| loop {
            let (wi, _, _, fl, _) = sample1(&p, wo, rng.f32(), [rng.f32(), rng.f32()]);
            if fl != 0 && fl & flags::DELTA == 0 {
                return wi;
            }
        };
        let pv = chi2_pvalue(&name, &grid, N, 0, |_| sample(&mut rng), |wi| eval1(&p, wo, wi).1 as f64 / total);
        assert!(pv >= alpha, "{name}: chi-square rejects the sampler (p = {pv:.3e} < {alpha:.1e})");
    }
}

/// Non-delta samples: weight == f |cos| / pdf of `eval_pdf`; delta samples: finite, >= 0.
#[test]
fn sample_weight_matches_eval_over_pdf() {
    for m in members() {
        for (r, p) in (m.test_params)().iter().enumerate() {
            for &wo in &views(&m) {
                let mut rng = Rng::new(3 + r as u64);
                for _ in 0..4000 {
                    let (wi, w, pdf, fl, _) = sample1(p, wo, rng.f32(), [rng.f32(), rng.f32()]);
                    assert!(w.is_finite() && w.min_element() >= 0.0, "{} row {r}: weight {w}", m.name);
                    if fl == 0 {
                        assert_eq!((w, pdf), (Vec3::ZERO, 0.0), "{}: a failed sample carries weight", m.name);
                        continue;
                    }
                    assert!(pdf > 0.0 && (wi.length() - 1.0).abs() < 1e-4, "{} row {r}: pdf {pdf} wi {wi}", m.name);
                    if fl & flags::DELTA != 0 {
                        continue;
                    }
                    let (f, pdf_e) = eval1(p, wo, wi);
                    assert!((pdf - pdf_e).abs() <= 1e-5 * pdf.max(1.0), "{} row {r}: pdf {pdf} vs {pdf_e}", m.name);
                    let want = f * (wi.z.abs() / pdf_e);
                    let tol = 1e-4 * want.max_element().max(1e-6);
                    assert!(
                        (w - want).abs().max_element() <= tol,
                        "{} row {r}: weight {w} vs f cos/pdf {want}",
                        m.name
                    );
                }
            }
        }
    }
}

/// The white furnace: E[weight] <= 1 (a model's [`super::interface::Bsdf::ALBEDO_BOUND`]) over the sampled lobes (transmission counted in importance
/// units, weight eta^2, so the 1/eta^2 radiance scaling does not count as a gain).
#[test]
fn white_furnace_gains_no_energy() {
    for m in members() {
        for (r, p) in (m.test_params)().iter().enumerate() {
            for &wo in &views(&m) {
                let mut rng = Rng::new(5 + r as u64);
                let n = 100_000;
                let (mut sum, mut sum2) = (0.0f64, 0.0f64);
                for _ in 0..n {
                    let (_, w, _, fl, eta) = sample1(p, wo, rng.f32(), [rng.f32(), rng.f32()]);
                    let k = if fl & flags::TRANSMISSION != 0 { eta * eta } else { 1.0 };
                    let x = (w.max_element() * k) as f64;
                    sum += x;
                    sum2 += x * x;
                }
                let mean = sum / n as f64;
                let sd = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
                let bound = f64::from(m.albedo_bound);
                assert!(mean <= bound + 5.0 * sd + 1e-4, "{} row {r} wo {wo}: furnace {mean} > {bound}", m.name);
            }
        }
    }
}

/// f(wo, wi) == f(wi, wo) for reflection.
#[test]
fn reflection_is_reciprocal() {
    for m in members() {
        for (r, p) in (m.test_params)().iter().enumerate() {
            let mut rng = Rng::new(9);
            for _ in 0..2000 {
                let a = dir(89.0 * rng.f32(), 360.0 * rng.f32());
                let b = dir(89.0 * rng.f32(), 360.0 * rng.f32());
                let (fab, fba) = (eval1(p, a, b).0, eval1(p, b, a).0);
                let tol = 1e-5 * fab.max_element().max(fba.max_element()).max(1e-6);
                assert!((fab - fba).abs().max_element() <= tol, "{} row {r}: f(a,b) {fab} != f(b,a) {fba}", m.name);
            }
        }
    }
}

/// A packet of eight lanes of different entries, rows and directions gives every lane exactly
/// what that lane alone gives (eval and sample, bit for bit).
#[test]
fn packet_lanes_are_independent() {
    let rows: Vec<BsdfParams> = members().iter().flat_map(|m| (m.test_params)()).collect();
    let mut rng = Rng::new(21);
    for round in 0..200 {
        let lane_rows: [BsdfParams; 8] = std::array::from_fn(|i| rows[(round * 3 + i * 5) % rows.len()]);
        let wo: [Vec3; 8] = std::array::from_fn(|_| dir(170.0 * rng.f32(), 360.0 * rng.f32()));
        let wi: [Vec3; 8] = std::array::from_fn(|_| dir(180.0 * rng.f32(), 360.0 * rng.f32()));
        let ul: [f32; 8] = std::array::from_fn(|_| rng.f32());
        let u: [[f32; 2]; 8] = std::array::from_fn(|_| [rng.f32(), rng.f32()]);
        let p8 = Params8::from_lanes(std::array::from_fn(|i| &lane_rows[i]));
        let (f, pdf) = AllBsdfs::eval_pdf(
            &p8,
            Vec3x8::from_lanes(wo),
            Vec3x8::from_lanes(wi),
            mask_all(),
            (Vec3x8::ZERO, F8::ZERO),
        );
        let s = AllBsdfs::sample(
            &p8,
            Vec3x8::from_lanes(wo),
            F8::new(ul),
            [F8::new(u.map(|u| u[0])), F8::new(u.map(|u| u[1]))],
            mask_all(),
            Sample8::NONE,
        );
        for i in 0..8 {
            let (f1, pdf1) = eval1(&lane_rows[i], wo[i], wi[i]);
            assert_eq!(f.lane(i).to_array().map(f32::to_bits), f1.to_array().map(f32::to_bits), "eval lane {i}");
            assert_eq!(pdf.to_array()[i].to_bits(), pdf1.to_bits(), "pdf lane {i}");
            let (wi1, w1, p1, fl1, eta1) = sample1(&lane_rows[i], wo[i], ul[i], u[i]);
            assert_eq!(s.wi.lane(i).to_array().map(f32::to_bits), wi1.to_array().map(f32::to_bits), "wi lane {i}");
            assert_eq!(s.weight.lane(i).to_array().map(f32::to_bits), w1.to_array().map(f32::to_bits), "w lane {i}");
            assert_eq!((s.pdf.to_array()[i].to_bits(), s.flags.to_array()[i]), (p1.to_bits(), fl1), "lane {i}");
            assert_eq!(s.eta.to_array()[i].to_bits(), eta1.to_bits(), "eta lane {i}");
        }
    }
}

/// The stiff directions: grazing, normal, back-side and, for the indices used, just at, above
/// and below the critical angle (from either side).
fn stiff_dirs() -> Vec<Vec3> {
    let mut zs: Vec<f32> = vec![1.0, 1e-7, -1e-7, 0.0, -1.0, 0.5, -0.5, 1e-3, -1e-3];
    for eta in [1.0001f32, 1.33, 1.5, 1.9, 2.4, 4.0] {
        let c = (1.0 - 1.0 / (eta * eta)).sqrt();
        zs.extend([c, c * (1.0 + 1e-6), c * (1.0 - 1e-6)].iter().flat_map(|&c| [c, -c]));
    }
    zs.iter()
        .map(|&z| {
            let s = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(s * 0.6, s * 0.8, z)
        })
        .collect()
}

/// Every row (extreme indices, large k) at grazing, normal, critical-angle and back-side
/// directions gains no energy: the white furnace E[weight] (transmission in importance units,
/// as [`white_furnace_gains_no_energy`]) is at most 1 (the model's `ALBEDO_BOUND`) from every stiff direction, over 2048
/// stratified samples per direction. (A microfacet projected area that lost its `abs` on the
/// side below the surface stays finite but gives G1 > 1 there: only this catches it.)
#[test]
fn stiff_cases_gain_no_energy() {
    let (nl, nu) = (8usize, 16usize);
    let mut gains = Vec::new();
    for m in members() {
        for (r, p) in (m.test_params)().iter().enumerate() {
            for &wo in &stiff_dirs() {
                let mut rng = Rng::new(31 + r as u64);
                let (mut sum, mut sum2, n) = (0.0f64, 0.0f64, (nl * nu * nu) as f64);
                for l in 0..nl {
                    for i in 0..nu * nu {
                        let ul = (l as f32 + rng.f32()) / nl as f32;
                        let u = [((i % nu) as f32 + rng.f32()) / nu as f32, ((i / nu) as f32 + rng.f32()) / nu as f32];
                        let (_, w, _, fl, eta) = sample1(p, wo, ul.min(0.999_999_9), u.map(|x| x.min(0.999_999_9)));
                        let k = if fl & flags::TRANSMISSION != 0 { eta * eta } else { 1.0 };
                        let x = (w.max_element() * k) as f64;
                        sum += x;
                        sum2 += x * x;
                    }
                }
                let mean = sum / n;
                let sd = ((sum2 / n - mean * mean).max(0.0) / n).sqrt();
                let bound = f64::from(m.albedo_bound);
                if !(mean <= bound + 5.0 * sd + 1e-4) {
                    gains.push(format!("{} row {r} wo {wo}: furnace {mean} (sd {sd}) > {bound}", m.name));
                }
            }
        }
    }
    assert!(gains.is_empty(), "{} cases gain energy:\n{}", gains.len(), gains.join("\n"));
}

/// Every row (extreme indices, large k) at grazing, normal, critical-angle and back-side
/// directions: eval and sample finite.
#[test]
fn stiff_cases_stay_finite() {
    let dirs = stiff_dirs();
    for m in members() {
        for (r, p) in (m.test_params)().iter().enumerate() {
            for &wo in &dirs {
                for &wi in &dirs {
                    let (f, pdf) = eval1(p, wo, wi);
                    assert!(f.is_finite() && pdf.is_finite() && pdf >= 0.0, "{} row {r}: eval at {wo} {wi}", m.name);
                }
                for ul in [0.0f32, 0.5, 0.999_999] {
                    for u in [[0.0f32, 0.0], [0.5, 0.5], [0.999_999, 0.25]] {
                        let (wi, w, pdf, _, eta) = sample1(p, wo, ul, u);
                        let ok = wi.is_finite() && w.is_finite() && pdf.is_finite() && eta.is_finite() && eta > 0.0;
                        assert!(ok, "{} row {r}: sample at {wo}: {wi} {w} {pdf} {eta}", m.name);
                    }
                }
            }
        }
    }
}

#[test]
fn smooth_dielectric_conserves_energy_and_refracts_by_snell() {
    let p = super::dielectric::params(1.5, Vec3::ONE, Vec3::ONE);
    for wo in [dir(30.0, 10.0), dir(150.0, 10.0), dir(89.9, 0.0)] {
        let mut rng = Rng::new(1);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let (wi, w, _, fl, eta) = sample1(&p, wo, rng.f32(), [0.5, 0.5]);
            if fl & flags::TRANSMISSION != 0 {
                // Snell: eta_i sin_i = eta_t sin_t, eta = eta_t / eta_i.
                let (si, st) = ((1.0 - wo.z * wo.z).sqrt(), (1.0 - wi.z * wi.z).sqrt());
                assert!((si - eta * st).abs() < 1e-4, "Snell: {si} vs {eta} {st}");
                assert!(wi.z * wo.z < 0.0);
            }
            let k = if fl & flags::TRANSMISSION != 0 { eta * eta } else { 1.0 };
            sum += (w.x * k) as f64;
        }
        assert!((sum / n as f64 - 1.0).abs() < 1e-5, "furnace {}", sum / n as f64);
    }
    // Total internal reflection: from inside past the critical angle everything reflects.
    let wo = dir(180.0 - 45.0, 0.0);
    for ul in [0.0f32, 0.5, 0.999] {
        let (wi, w, pdf, fl, _) = sample1(&p, wo, ul, [0.5, 0.5]);
        assert_eq!((fl, pdf, w), (flags::DELTA_REFLECTION, 1.0, Vec3::ONE));
        assert!((wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
    }
}

#[test]
fn one_sided_entries_are_black_from_the_back() {
    for m in members() {
        if m.flags & flags::TRANSMISSION != 0 {
            continue;
        }
        for p in (m.test_params)() {
            let wo = dir(120.0, 30.0);
            for ul in [0.1f32, 0.9] {
                let (_, w, pdf, fl, _) = sample1(&p, wo, ul, [0.3, 0.7]);
                assert_eq!((w, pdf, fl), (Vec3::ZERO, 0.0, 0), "{}: lit from the back", m.name);
            }
            assert_eq!(eval1(&p, wo, dir(40.0, 0.0)).0, Vec3::ZERO, "{}", m.name);
        }
    }
}

//! Chi-square goodness-of-fit test of a direction sampler against its claimed pdf (test-only), in the
//! manner of pbrt-v4's and Mitsuba's test suites, plus the deterministic generator the tests use.
//!
//! Method. N directions are drawn and binned on a fixed (theta, phi) partition of the whole sphere about
//! an axis. The expected count of a cell is N times the integral of the claimed pdf over the cell,
//! computed independently of the sampler by nested adaptive Simpson quadrature in theta and phi with the
//! sin theta Jacobian (in f64; the pdf itself is evaluated in f32 at the f32-rounded direction). The
//! sum of all cells doubles as the check that the pdf integrates to 1 over the sphere. Cells expected
//! to hold fewer than 5 samples are pooled (in increasing order, until the pool holds 5); cells with
//! expected count exactly 0 may hold at most N * 1e-5 strays (directions exactly on a cell edge such
//! as the horizon). The statistic sum (O - E)^2 / E over k cells has k - 1 degrees of freedom; its
//! p-value is the regularized upper incomplete gamma Q((k-1)/2, chi2/2), and the test rejects when
//! p < SIGNIFICANCE / CHI2_TESTS (Bonferroni over every chi-square test of the crate).
//!
//! Peaked lobes. A uniform theta grid cannot resolve a Phong lobe with s = 1e6 (width ~1e-3 rad) or a
//! GGX lobe with alpha = 1e-3: all samples land in one cell, which tests nothing. Because expected
//! counts come from integrating the claimed pdf over whatever cells are used, any fixed partition of
//! the sphere gives a valid test, so we use one adapted to the lobe ([`Grid::lobe`]): theta is measured
//! from the lobe's own axis (+z for the warps, the mirror direction for the BRDF mixtures); rows are
//! uniform in theta over a core [0, theta_core] chosen from the lobe parameter to hold all but ~1e-3
//! (Phong, [`phong_core`]) or ~2% (GGX's heavy tail, [`ggx_core`]) of the lobe's mass, then geometric
//! in theta from theta_core to pi, so the tail, the cosine part of a mixture and the lower hemisphere
//! are binned too; every row is split uniformly in phi. The partition depends only on the lobe
//! parameters, never on the samples. The quadrature resolves the lobe because the cells do.
//!
//! The GGX BRDF mixtures are binned in the half vector h rather than in wi (a bijection, with the
//! claimed density carried over by the Jacobian dw_wi/dw_h = 4 |wo.h|): at grazing wo the wi lobe is
//! a thin ridge ending in an integrable singularity at wi = -wo, the h lobe is smooth (see
//! `bsdf::tests::Coords`).

use glam::{DVec3, Vec3};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Number of chi-square tests in the crate, for the Bonferroni correction.
pub(crate) const CHI2_TESTS: usize = 53;
/// Family-wise significance level of all chi-square tests together.
pub(crate) const SIGNIFICANCE: f64 = 0.01;
/// Samples per chi-square test.
pub(crate) const SAMPLES: usize = 1_000_000;

/// SplitMix64: a small, fixed-seed generator so every test is deterministic.
pub(crate) struct Rng(u64);

impl Rng {
    /// Generator with a fixed seed.
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x9E37_79B9_7F4A_7C15)
    }
    /// Next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform f32 in [0, 1) with 24 random bits.
    pub(crate) fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / 16_777_216.0)
    }
    /// Two uniform f32 in [0, 1).
    pub(crate) fn u2(&mut self) -> [f32; 2] {
        [self.f32(), self.f32()]
    }
}

/// theta_core for a Phong lobe of exponent s: P(theta > theta_core) = cos^(s+1) ~ exp(-(s+1) theta^2/2)
/// = 1e-3, capped at pi/2.
pub(crate) fn phong_core(s: f64) -> f64 {
    (2.0 * 1e3f64.ln() / (s + 1.0)).sqrt().min(FRAC_PI_2)
}

/// theta_core for a GGX half vector: P(theta_h > atan(7 alpha)) = 1/(1 + 49) = 2%, capped at pi/2.
pub(crate) fn ggx_core(alpha: f64) -> f64 {
    (7.0 * alpha).atan().min(FRAC_PI_2)
}

/// A fixed partition of the sphere into (theta, phi) cells about an axis.
pub(crate) struct Grid {
    /// tangent, bitangent, axis
    frame: [DVec3; 3],
    /// row edges in theta, from 0 to pi
    theta: Vec<f64>,
    /// cells per row
    n_phi: usize,
}

impl Grid {
    /// Rows uniform in theta over [0, pi] about +z.
    pub(crate) fn uniform(n_theta: usize, n_phi: usize) -> Self {
        let theta = (0..=n_theta).map(|i| PI * i as f64 / n_theta as f64).collect();
        Self { frame: [DVec3::X, DVec3::Y, DVec3::Z], theta, n_phi }
    }

    /// Lobe-adapted rows about `axis`: `n_core` uniform in [0, theta_core], `n_tail` geometric in
    /// [theta_core, pi].
    pub(crate) fn lobe(axis: Vec3, theta_core: f64, n_core: usize, n_tail: usize, n_phi: usize) -> Self {
        let n = axis.as_dvec3().normalize();
        let (s, t) = if n == DVec3::Z { (DVec3::X, DVec3::Y) } else { n.any_orthonormal_pair() };
        let tc = theta_core.min(PI);
        let mut theta: Vec<f64> = (0..=n_core).map(|i| tc * i as f64 / n_core as f64).collect();
        let ratio = (PI / tc).powf(1.0 / n_tail as f64);
        theta.extend((1..=n_tail).map(|k| if k == n_tail { PI } else { tc * ratio.powi(k as i32) }));
        theta.dedup();
        Self { frame: [s, t, n], theta, n_phi }
    }

    fn cells(&self) -> usize {
        (self.theta.len() - 1) * self.n_phi
    }

    /// Direction at (theta, phi), rounded to f32.
    fn dir(&self, theta: f64, phi: f64) -> Vec3 {
        let [s, t, n] = self.frame;
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        (n * ct + (s * cp + t * sp) * st).as_vec3()
    }

    /// Cell of a direction; rows are (e_k, e_k+1] (the first includes theta = 0).
    fn cell(&self, w: Vec3) -> usize {
        let [s, t, n] = self.frame;
        let w = w.as_dvec3();
        let (x, y, z) = (w.dot(s), w.dot(t), w.dot(n));
        let theta = x.hypot(y).atan2(z);
        let phi = y.atan2(x).rem_euclid(TAU);
        let rows = self.theta.len() - 1;
        let i = self.theta[1..rows].partition_point(|&e| e < theta);
        let j = ((phi / TAU * self.n_phi as f64) as usize).min(self.n_phi - 1);
        i * self.n_phi + j
    }

    /// Integral of `f` (a density per unit solid angle) over each cell.
    pub(crate) fn integrate(&self, f: &dyn Fn(Vec3) -> f64) -> Vec<f64> {
        let dphi = TAU / self.n_phi as f64;
        let mut out = Vec::with_capacity(self.cells());
        for row in self.theta.windows(2) {
            for j in 0..self.n_phi {
                let (p0, p1) = (j as f64 * dphi, (j + 1) as f64 * dphi);
                let inner_eps = 1e-11 / (row[1] - row[0]);
                let mut g = |theta: f64| {
                    let st = theta.sin();
                    if st <= 0.0 {
                        return 0.0;
                    }
                    st * simpson(&mut |phi| f(self.dir(theta, phi)), p0, p1, inner_eps)
                };
                out.push(simpson(&mut g, row[0], row[1], 1e-11));
            }
        }
        out
    }

    /// Integral of `f` over the whole sphere.
    pub(crate) fn integrate_sphere(&self, f: &dyn Fn(Vec3) -> f64) -> f64 {
        self.integrate(f).iter().sum()
    }
}

/// Adaptive Simpson quadrature of f over [a, b] to absolute tolerance `eps` or 1e-4 relative to each
/// panel (at most 12 bisections), starting from 4 panels so a peak cannot hide between the first nodes.
/// The relative floor sits above the integrands' noise, below which bisection would never stop: they
/// are f32 pdfs at f32-rounded directions, and rounding a direction by 6e-8 moves the pdf of a Phong
/// lobe of exponent s by ~sqrt(s) 6e-8 relative, of a GGX lobe by ~1e-7/alpha, and at grazing wo
/// the GGX pdf's half vector normalize(wi + wo) loses a further factor 1/|wo.h|. The quadrature error
/// is far below the tolerance where the integrand is smooth, and 1e-4 of an expected count is well
/// below its Poisson noise (sqrt of the count) for every count up to 1e8.
fn simpson(f: &mut dyn FnMut(f64) -> f64, a: f64, b: f64, eps: f64) -> f64 {
    const PANELS: usize = 4;
    let h = (b - a) / PANELS as f64;
    let mut sum = 0.0;
    let mut x0 = a;
    let mut f0 = f(a);
    for k in 1..=PANELS {
        let x1 = if k == PANELS { b } else { a + h * k as f64 };
        let (fm, f1) = (f(0.5 * (x0 + x1)), f(x1));
        let whole = (x1 - x0) / 6.0 * (f0 + 4.0 * fm + f1);
        sum += simpson_step(f, x0, x1, f0, fm, f1, whole, eps / PANELS as f64, 12);
        (x0, f0) = (x1, f1);
    }
    sum
}

#[allow(clippy::too_many_arguments)]
fn simpson_step(
    f: &mut dyn FnMut(f64) -> f64,
    a: f64,
    b: f64,
    fa: f64,
    fm: f64,
    fb: f64,
    whole: f64,
    eps: f64,
    depth: u32,
) -> f64 {
    let m = 0.5 * (a + b);
    let (flm, frm) = (f(0.5 * (a + m)), f(0.5 * (m + b)));
    let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    let delta = left + right - whole;
    if depth == 0 || delta.abs() <= 15.0 * eps.max(1e-4 * (left + right).abs()) {
        left + right + delta / 15.0
    } else {
        simpson_step(f, a, m, fa, flm, fm, left, 0.5 * eps, depth - 1)
            + simpson_step(f, m, b, fm, frm, fb, right, 0.5 * eps, depth - 1)
    }
}

/// ln Gamma(x) for x >= 1/2 (Lanczos approximation, g = 7, 9 terms; ~1e-15 relative).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let t = x + 7.5;
    let s = C[1..].iter().enumerate().fold(C[0], |acc, (i, c)| acc + c / (x + 1.0 + i as f64));
    0.5 * TAU.ln() + (x + 0.5) * t.ln() - t + s.ln()
}

/// Regularized upper incomplete gamma Q(a, x) = Gamma(a, x) / Gamma(a), a >= 1/2: the series for P
/// below x = a + 1, the continued fraction for Q (modified Lentz) above.
pub(crate) fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let prefactor = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, a);
        while term.abs() > sum.abs() * 1e-16 {
            n += 1.0;
            term *= x / n;
            sum += term;
        }
        (1.0 - sum * prefactor).max(0.0)
    } else {
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let (mut c, mut d) = (1.0 / TINY, 1.0 / b);
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            d = if d.abs() < TINY { TINY } else { d };
            c = b + an / c;
            c = if c.abs() < TINY { TINY } else { c };
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        prefactor * h
    }
}

/// Pearson's statistic of `observed` counts against `expected` counts (of `n` samples), cells
/// expected below 5 pooled; returns (chi2, degrees of freedom).
pub(crate) fn statistic(observed: &[u64], expected: &[f64], n: usize, name: &str) -> (f64, usize) {
    let mut cells: Vec<(f64, f64)> = expected.iter().zip(observed).map(|(&e, &o)| (e, o as f64)).collect();
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut pool_e, mut pool_o, mut chi2, mut k) = (0.0, 0.0, 0.0, 0usize);
    for (e, o) in cells {
        if e <= 0.0 {
            assert!(o <= 1e-5 * n as f64, "{name}: {o} samples in a cell where the pdf is 0");
        } else if e < 5.0 || (pool_e > 0.0 && pool_e < 5.0) {
            pool_e += e;
            pool_o += o;
        } else {
            chi2 += (o - e) * (o - e) / e;
            k += 1;
        }
    }
    if pool_e > 0.0 {
        chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
        k += 1;
    }
    (chi2, k.saturating_sub(1).max(1))
}

/// Chi-square p-value of `n` directions from `sample` against `pdf` (per unit solid angle) on `grid`.
/// Also asserts that every sample is a finite unit vector and that the pdf integrates to 1.
pub(crate) fn chi2_pvalue(
    name: &str,
    grid: &Grid,
    n: usize,
    seed: u64,
    mut sample: impl FnMut(&mut Rng) -> Vec3,
    pdf: impl Fn(Vec3) -> f64,
) -> f64 {
    let prob = grid.integrate(&pdf);
    let total: f64 = prob.iter().sum();
    assert!((total - 1.0).abs() < 1e-4, "{name}: the pdf integrates to {total} over the sphere");
    let mut observed = vec![0u64; prob.len()];
    let mut rng = Rng::new(seed);
    for _ in 0..n {
        let w = sample(&mut rng);
        assert!(w.is_finite() && (w.length() - 1.0).abs() < 1e-5, "{name}: sample {w} is not a unit vector");
        observed[grid.cell(w)] += 1;
    }
    let expected: Vec<f64> = prob.iter().map(|p| p * n as f64).collect();
    let (chi2, dof) = statistic(&observed, &expected, n, name);
    let p = gamma_q(0.5 * dof as f64, 0.5 * chi2);
    eprintln!("chi2 {name}: chi2 = {chi2:.1}, dof = {dof}, p = {p:.4}, integral of pdf = {total:.7}");
    p
}

/// [`chi2_pvalue`] with the Bonferroni-corrected rejection.
pub(crate) fn chi2_test(
    name: &str,
    grid: &Grid,
    seed: u64,
    sample: impl FnMut(&mut Rng) -> Vec3,
    pdf: impl Fn(Vec3) -> f64,
) {
    let p = chi2_pvalue(name, grid, SAMPLES, seed, sample, pdf);
    let alpha = SIGNIFICANCE / CHI2_TESTS as f64;
    assert!(p >= alpha, "{name}: chi-square test rejects the sampler (p = {p:.3e} < {alpha:.1e})");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn incomplete_gamma_matches_known_values() {
        // Q(1, x) = exp(-x); chi-square upper quantiles from standard tables (p = 0.01 and 0.05).
        for x in [0.1, 1.0, 3.0, 20.0] {
            assert!((gamma_q(1.0, x) - (-x).exp()).abs() < 1e-12);
        }
        for (dof, x, p) in
            [(1.0, 6.634_897, 0.01), (10.0, 23.209_251, 0.01), (100.0, 135.806_723, 0.01), (3.0, 7.814_728, 0.05)]
        {
            let q = gamma_q(0.5 * dof, 0.5 * x);
            assert!((q - p).abs() < 1e-4 * p + 1e-9, "dof {dof}: Q = {q}, want {p}");
        }
        assert!((ln_gamma(0.5) - PI.sqrt().ln()).abs() < 1e-13 && (ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn grid_cells_cover_the_sphere() {
        let g = Grid::lobe(Vec3::new(0.3, -0.2, 0.9).normalize(), 0.05, 10, 10, 20);
        let total = g.integrate_sphere(&|_| 0.25 / std::f64::consts::PI);
        assert!((total - 1.0).abs() < 1e-9, "{total}");
        let mut rng = Rng::new(7);
        for _ in 0..1000 {
            let w = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5).normalize();
            assert!(g.cell(w) < g.cells());
        }
    }
}

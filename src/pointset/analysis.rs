//! Point-set quality: L2 star discrepancy (Warnock's closed form), minimum toroidal distance,
//! radial power spectrum, and the integration error on the standard test integrands with its
//! convergence slope (Christensen, Kensler and Kilpatrick 2018, "Progressive Multi-Jittered
//! Sample Sequences": a discontinuous quarter disk and a smooth Gaussian).

use crate::sampler::{PointSet, SamplerKind};
use std::f64::consts::PI;

/// L2 star discrepancy of `pts` in [0, 1)^2 by Warnock's formula:
/// `D^2 = 1/9 - (1/2N) sum_i prod_k (1 - x_ik^2) + (1/N^2) sum_ij prod_k (1 - max(x_ik, x_jk))`.
/// O(N^2).
pub fn l2_star_discrepancy(pts: &[[f64; 2]]) -> f64 {
    let n = pts.len() as f64;
    if pts.is_empty() {
        return f64::NAN;
    }
    let single: f64 = pts.iter().map(|p| (1.0 - p[0] * p[0]) * (1.0 - p[1] * p[1])).sum();
    let mut pairs = 0.0;
    for (i, a) in pts.iter().enumerate() {
        pairs += (1.0 - a[0]) * (1.0 - a[1]); // i == j
        let mut row = 0.0;
        for b in &pts[i + 1..] {
            row += (1.0 - a[0].max(b[0])) * (1.0 - a[1].max(b[1]));
        }
        pairs += 2.0 * row;
    }
    (1.0 / 9.0 - single / (2.0 * n) + pairs / (n * n)).max(0.0).sqrt()
}

/// Smallest toroidal distance between two points of `pts` (NaN for fewer than two points). O(N^2).
pub fn min_distance(pts: &[[f64; 2]]) -> f64 {
    let wrap = |d: f64| {
        let d = d.abs();
        d.min(1.0 - d)
    };
    let mut best = f64::INFINITY;
    for (i, a) in pts.iter().enumerate() {
        for b in &pts[i + 1..] {
            let (dx, dy) = (wrap(a[0] - b[0]), wrap(a[1] - b[1]));
            best = best.min(dx * dx + dy * dy);
        }
    }
    if pts.len() < 2 {
        f64::NAN
    } else {
        best.sqrt()
    }
}

/// The densest packing's minimum distance for `n` points on the unit torus (hexagonal):
/// `sqrt(2 / (sqrt(3) n))`; blue-noise sets are compared by `min_distance / this`.
pub fn max_min_distance(n: usize) -> f64 {
    (2.0 / (3f64.sqrt() * n as f64)).sqrt()
}

/// Radially averaged power spectrum of `sets` (averaged over the sets): for integer frequencies
/// `f` with `|f| < max_freq`, `P(f) = |sum_j exp(-2 pi i f.x_j)|^2 / N`, averaged in rings of
/// width 1; entry r is the ring `r <= |f| < r + 1` (ring 0 without the DC term). White noise is
/// 1 at every frequency.
pub fn radial_spectrum(sets: &[Vec<[f64; 2]>], max_freq: usize) -> Vec<f64> {
    let f = max_freq as i64;
    let mut sum = vec![0.0; max_freq];
    let mut count = vec![0usize; max_freq];
    for pts in sets {
        let n = pts.len() as f64;
        // exp(-2 pi i u x) for u = 0..f by recurrence per point would drift; direct is exact enough.
        for u in -f..=f {
            for v in 0..=f {
                // (u, v) and (-u, -v) have the same power: half the plane, v >= 0 (v = 0: u >= 0).
                if v == 0 && u < 0 {
                    continue;
                }
                let r = ((u * u + v * v) as f64).sqrt();
                let ring = r as usize;
                if ring >= max_freq || (u == 0 && v == 0) {
                    continue;
                }
                let (mut re, mut im) = (0.0, 0.0);
                for p in pts {
                    let phase = -2.0 * PI * (u as f64 * p[0] + v as f64 * p[1]);
                    re += phase.cos();
                    im += phase.sin();
                }
                sum[ring] += (re * re + im * im) / n;
                count[ring] += 1;
            }
        }
    }
    sum.iter().zip(&count).map(|(s, &c)| if c > 0 { s / c as f64 } else { f64::NAN }).collect()
}

/// Expected squared L2 star discrepancy of `n` independent uniform points in [0, 1)^2:
/// `(2^-2 - 3^-2) / n = 5 / (36 n)`.
pub fn random_discrepancy2(n: usize) -> f64 {
    5.0 / (36.0 * n as f64)
}

/// A prefix of a set is "as good as a fresh set of its size" when its RMS L2 star discrepancy
/// (over the sets measured) is at most this many times that of fresh independent random sets of
/// the same size: random sets (every prefix a random set) pass, a lattice's or a row-ordered
/// jittered set's prefixes (which cover a strip of the square) fail by 3x and more.
pub const PROGRESSIVE_MAX_RATIO: f64 = 1.5;

/// Prefix sizes the progressiveness test looks at: powers of two from 8 below `points`, at most
/// 2048 (the test is O(n^2) per set).
pub fn prefix_sizes(points: usize) -> Vec<usize> {
    (3..=11).map(|m| 1usize << m).filter(|&n| n < points).collect()
}

/// Whether sets are progressive, and why.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Progressiveness {
    /// (prefix size n, RMS discrepancy of the sets' first n points / fresh random sets' of n)
    pub prefixes: Vec<(usize, f64)>,
    /// every prefix within [`PROGRESSIVE_MAX_RATIO`] (false when no prefix of 8+ points exists:
    /// such a set is used whole, which costs nothing)
    pub progressive: bool,
}

/// Measures whether `sets` (all of one size) are progressive: each prefix of 8, 16, ... points
/// (below the sets' size) against fresh random sets of the same size ([`PROGRESSIVE_MAX_RATIO`]).
pub fn progressiveness(sets: &[Vec<[f64; 2]>]) -> Progressiveness {
    let points = sets.first().map_or(0, Vec::len);
    let prefixes: Vec<(usize, f64)> = prefix_sizes(points)
        .into_iter()
        .map(|n| {
            let d2 = sets.iter().map(|s| l2_star_discrepancy(&s[..n]).powi(2)).sum::<f64>() / sets.len() as f64;
            (n, (d2 / random_discrepancy2(n)).sqrt())
        })
        .collect();
    let progressive = !prefixes.is_empty() && prefixes.iter().all(|&(_, r)| r <= PROGRESSIVE_MAX_RATIO);
    Progressiveness { prefixes, progressive }
}

/// A test integrand on [0, 1)^2 with its exact integral.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrand {
    /// quarter disk `x^2 + y^2 < 2/pi` (area 1/2): discontinuous
    Disk,
    /// `exp(-x^2 - y^2)`: smooth
    Gaussian,
}

impl Integrand {
    /// Both, in report order.
    pub const ALL: [Integrand; 2] = [Integrand::Disk, Integrand::Gaussian];

    /// Name in tables ("disk", "gaussian").
    pub fn name(self) -> &'static str {
        match self {
            Self::Disk => "disk",
            Self::Gaussian => "gaussian",
        }
    }

    /// f(x, y).
    pub fn eval(self, x: f64, y: f64) -> f64 {
        match self {
            Self::Disk => f64::from(u8::from(x * x + y * y < 2.0 / PI)),
            Self::Gaussian => (-x * x - y * y).exp(),
        }
    }

    /// The exact integral over [0, 1)^2.
    pub fn exact(self) -> f64 {
        match self {
            Self::Disk => 0.5,
            // (integral_0^1 exp(-x^2) dx)^2 = (sqrt(pi)/2 erf(1))^2
            Self::Gaussian => {
                let e = (PI.sqrt() / 2.0) * ERF_1;
                e * e
            }
        }
    }
}

/// Slope of the RMSE of independent random points (the guide line of the plots).
pub const RANDOM_SLOPE: f64 = -0.5;

/// erf(1).
const ERF_1: f64 = 0.842_700_792_949_714_9;

/// RMSE of the estimate of `f` by point sets of `n` points of `kind` over `trials` randomizations
/// (trial t: the set of pixel t, sample 0, dimension 0, under `seed`, as a render draws it).
pub fn integration_rmse(kind: SamplerKind, f: Integrand, n: u32, trials: u32, seed: u64) -> f64 {
    let set = PointSet::new(kind, n);
    let exact = f.exact();
    let mut se = 0.0;
    for t in 0..trials {
        let est = (0..n)
            .map(|k| {
                let [x, y] = set.point(t, 0, 0, k, seed);
                f.eval(f64::from(x), f64::from(y))
            })
            .sum::<f64>()
            / f64::from(n);
        se += (est - exact) * (est - exact);
    }
    (se / f64::from(trials)).sqrt()
}

/// Least-squares slope of `log y` against `log x` (the convergence rate of error against N).
pub fn loglog_slope(points: &[(f64, f64)]) -> f64 {
    let pts: Vec<(f64, f64)> =
        points.iter().filter(|(x, y)| *x > 0.0 && *y > 0.0).map(|(x, y)| (x.ln(), y.ln())).collect();
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = pts.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = pts.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// One integrand's error curve: (N, RMSE) for each N, and the fitted slope.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Convergence {
    /// the integrand's name
    pub integrand: &'static str,
    /// (N, RMSE)
    pub points: Vec<(f64, f64)>,
    /// slope of log RMSE against log N (None with fewer than two N: a set that is not
    /// progressive is measured at its size only, its prefixes being no sets of their own)
    pub slope: Option<f64>,
}

/// Error curves of `kind` on both integrands for every N of `ns`.
pub fn convergence(kind: SamplerKind, ns: &[u32], trials: u32, seed: u64) -> Vec<Convergence> {
    Integrand::ALL
        .iter()
        .map(|&f| {
            let points: Vec<(f64, f64)> =
                ns.iter().map(|&n| (f64::from(n), integration_rmse(kind, f, n, trials, seed))).collect();
            let slope = (points.len() >= 2).then(|| loglog_slope(&points));
            Convergence { integrand: f.name(), slope, points }
        })
        .collect()
}

#[cfg(test)]
#[path = "analysis_tests.rs"]
mod tests;

//! Image error metrics, statistics over independent runs, and efficiency.
//!
//! All sums run in f64 over every channel of every pixel (M = 3 * pixels values). Inputs are
//! validated first: a NaN or infinite value, an empty reference or a size mismatch is an error,
//! so a returned metric is always a finite number.

use super::student_t::student_t_quantile;
use super::ReportError;
use crate::film;
use serde::Serialize;

/// The offset in the relative MSE's denominator, as in pbrt: `(v - r)^2 / (r + REL_EPS)^2`.
pub const REL_EPS: f64 = 0.01;

/// Mean squared error over all pixels and channels: mean of `(v - r)^2`.
pub fn mse(img: &[[f32; 3]], reference: &[[f32; 3]]) -> Result<f64, ReportError> {
    check_reference(reference)?;
    check_image(img, "image", reference.len())?;
    Ok(error_means(img, reference).sq)
}

/// Relative MSE in pbrt's form: mean over all pixels and channels of `(v - r)^2 / (r + 0.01)^2`.
/// A negative reference value (possible with negative-lobed filters) counts as 0 in the
/// denominator, which therefore never drops below `0.01^2`.
pub fn rel_mse(img: &[[f32; 3]], reference: &[[f32; 3]]) -> Result<f64, ReportError> {
    check_reference(reference)?;
    check_image(img, "image", reference.len())?;
    Ok(error_means(img, reference).rel)
}

/// The errors of one image against a reference: mean signed error, MSE and relative MSE.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ImageError {
    /// mean over values of `v - r`
    pub mean: f64,
    /// mean over values of `(v - r)^2`
    pub mse: f64,
    /// mean over values of `(v - r)^2 / (r + 0.01)^2` ([`rel_mse`])
    pub rel_mse: f64,
}

/// [`ImageError`] of `img` against `reference` (validated as [`mse`] does), in one pass.
pub fn image_error(img: &[[f32; 3]], reference: &[[f32; 3]]) -> Result<ImageError, ReportError> {
    check_reference(reference)?;
    check_image(img, "image", reference.len())?;
    let e = error_means(img, reference);
    Ok(ImageError { mean: e.err, mse: e.sq, rel_mse: e.rel })
}

/// Monte Carlo efficiency `1 / (mse * seconds)`. A zero product (zero error or zero time) gives
/// `f64::INFINITY`; a NaN, infinite or negative argument is an error, so the result is never NaN.
pub fn efficiency(mse: f64, seconds: f64) -> Result<f64, ReportError> {
    for (name, value) in [("mse", mse), ("seconds", seconds)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(ReportError::InvalidArgument { name, value });
        }
    }
    let cost = mse * seconds;
    Ok(if cost == 0.0 { f64::INFINITY } else { 1.0 / cost })
}

/// What is known of a reference besides its pixels, for [`RunStats::against`].
#[derive(Clone, Copy, Debug, Default)]
pub struct ReferenceInfo<'a> {
    /// per-value variance of the reference itself (its own noise); `None`: the reference is exact
    pub variance: Option<&'a [[f32; 3]]>,
    /// the PNG gamma: also compute the statistics of the 8-bit gamma-encoded values (what a PNG
    /// shows); `None`: skip them
    pub gamma: Option<f32>,
    /// degrees of freedom of each value of `variance` (a reference of R replicas: R - 1), for the
    /// interval of [`RunStats::mse_corrected`]; `None`: the layer is taken as exact
    pub variance_dof: Option<f64>,
}

/// Error statistics of the 8-bit gamma-encoded values 0..255 (see [`RunStats::eight_bit`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EightBit {
    /// mean over values of the unbiased across-run variance, in 8-bit units
    pub variance: f64,
    /// mean over runs of each run's MSE, in 8-bit units
    pub mse: f64,
}

/// Statistics of K >= 2 independent runs of one technique against a reference: the one set of
/// run statistics of `strata compare` and `strata experiments`.
///
/// With values `x[k][i]` (run k, value i over all pixels and channels, M values), reference
/// `r[i]` with its own per-value variance `v[i]` (0 for an exact reference), across-run mean
/// `m[i] = mean_k x[k][i]` and per-run mean error `e[k] = mean_i (x[k][i] - r[i])`:
/// - `bias = mean_i (m[i] - r[i]) = mean_k e[k]` (signed; errors of opposite sign cancel),
/// - `bias_se = sqrt(s_e^2 / K + sum_i v[i] / M^2)` with `s_e^2 = sum_k (e[k] - bias)^2 / (K - 1)`
///   (the runs' spread plus the reference's own noise, independent across values),
/// - `bias_ci = bias -/+ t(0.975, K - 1) * bias_se` (two-sided 95%, Student t),
/// - `z = bias / bias_se` (`+-inf` for a non-zero bias with no spread, 0 for none),
/// - `variance = mean_i s[i]^2` with the unbiased `s[i]^2 = sum_k (x[k][i] - m[i])^2 / (K - 1)`,
/// - `mse = mean_k mse(x[k], r)`, `rel_mse = mean_k rel_mse(x[k], r)`,
/// - `bias_sq = mean_i (m[i] - r[i])^2 - variance / K`, the unbiased estimate of the mean squared
///   per-value bias (it can come out slightly negative when the bias is small next to the noise),
/// - `rms_bias = sqrt(max(0, mean_i (m[i] - r[i])^2 - variance / K - mean_i v[i]))`, the root mean
///   squared per-value bias with the noise of the runs and of the reference removed,
/// - `bias_ratio = mean_i (m[i] - r[i])^2 / (variance / K + mean_i v[i])`: about 1 for an
///   unbiased technique (infinite when the denominator is 0),
/// - `ref_variance = mean_i v[i]`, and the noise-corrected MSE `mse - ref_variance`
///   ([`RunStats::mse_corrected`]) with its 95% interval `mse_corrected_ci`:
///   `-/+ t(0.975, K - 1) * sqrt(s_mse^2 / K + sum_i (2 v[i]^2 + 4 v[i] s[i]^2 / K + 2 v[i]^2 / d) / M^2)`
///   with `s_mse^2` the runs' spread of their MSE, and, for the reference's one realized error
///   `eps[i]` (common to every run): the spread of `mean_i eps[i]^2` around `mean_i v[i]` (`2 v^2`,
///   Gaussian), of the cross term `2 mean_i (m[i] - truth[i]) eps[i]` (`4 v s^2 / K`), and of the
///   layer's own estimate with `d` degrees of freedom ([`ReferenceInfo::variance_dof`]; `2 v^2 / d`).
///
/// Algebraically `mse = bias_sq + variance` exactly (per value,
/// `mean_k (x - r)^2 = (m - r)^2 + (K - 1)/K * s^2`); [`RunStats::decomposition_residual`]
/// returns what rounding leaves of that identity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RunStats {
    /// K, the number of runs
    pub runs: usize,
    /// mean signed error of the mean image
    pub bias: f64,
    /// standard error of `bias`: the spread of the per-run mean errors and the reference's noise
    pub bias_se: f64,
    /// two-sided 95% confidence interval of `bias`
    pub bias_ci: (f64, f64),
    /// `bias / bias_se`
    pub z: f64,
    /// unbiased estimate of the mean squared per-value bias
    pub bias_sq: f64,
    /// root mean squared per-value bias, the noise of runs and reference removed
    pub rms_bias: f64,
    /// mean squared error of the mean image over the variance it would have without bias
    pub bias_ratio: f64,
    /// mean over values of the unbiased across-run variance
    pub variance: f64,
    /// mean over runs of each run's MSE
    pub mse: f64,
    /// mean over runs of each run's relative MSE
    pub rel_mse: f64,
    /// the variance and MSE of the 8-bit gamma-encoded values, when a gamma was given
    pub eight_bit: Option<EightBit>,
    /// mean over values of the reference's own variance (0 for an exact reference)
    pub ref_variance: f64,
    /// two-sided 95% confidence interval of [`RunStats::mse_corrected`]
    pub mse_corrected_ci: (f64, f64),
}

impl RunStats {
    /// Computes the statistics of `runs` (K >= 2 images) against an exact `reference`; see
    /// [`RunStats`].
    pub fn from_runs(runs: &[Vec<[f32; 3]>], reference: &[[f32; 3]]) -> Result<Self, ReportError> {
        Self::against(runs, reference, ReferenceInfo::default())
    }

    /// Computes the statistics of `runs` (K >= 2 images) against `reference`, with what `info`
    /// knows of it (its own per-value variance, a gamma for the 8-bit statistics); see [`RunStats`].
    pub fn against(runs: &[Vec<[f32; 3]>], reference: &[[f32; 3]], info: ReferenceInfo) -> Result<Self, ReportError> {
        let k = runs.len();
        if k < 2 {
            return Err(ReportError::TooFewRuns(k));
        }
        check_reference(reference)?;
        for (i, run) in runs.iter().enumerate() {
            check_image(run, &format!("run {i}"), reference.len())?;
        }
        if let Some(v) = info.variance {
            check_image(v, "reference variance", reference.len())?;
        }
        let kf = k as f64;
        let per_run: Vec<ErrorMeans> = runs.iter().map(|run| error_means(run, reference)).collect();
        let over_runs = |f: fn(&ErrorMeans) -> f64| per_run.iter().map(f).sum::<f64>() / kf;
        let bias = over_runs(|e| e.err);
        let spread = per_run.iter().map(|e| (e.err - bias).powi(2)).sum::<f64>() / (kf - 1.0);

        let (mut mean_sq_err, mut var_sum, mut ref_var, mut ref_spread) = (0.0, 0.0, 0.0, 0.0);
        let (mut var8_sum, mut sq8_sum) = (0.0, 0.0);
        for (i, px) in reference.iter().enumerate() {
            for (c, &r) in px.iter().enumerate() {
                let mean = runs.iter().map(|run| run[i][c] as f64).sum::<f64>() / kf;
                let s2 = runs.iter().map(|run| (run[i][c] as f64 - mean).powi(2)).sum::<f64>();
                var_sum += s2;
                mean_sq_err += (mean - r as f64).powi(2);
                if let Some(v) = info.variance {
                    let v = f64::from(v[i][c]);
                    ref_var += v;
                    let estimate = info.variance_dof.map_or(0.0, |d| 2.0 * v * v / d);
                    ref_spread += 2.0 * v * v + 4.0 * v * s2 / (kf - 1.0) / kf + estimate;
                }
                if let Some(gamma) = info.gamma {
                    let q = |v: f32| f64::from(film::to_u8(v, gamma));
                    let mean8 = runs.iter().map(|run| q(run[i][c])).sum::<f64>() / kf;
                    var8_sum += runs.iter().map(|run| (q(run[i][c]) - mean8).powi(2)).sum::<f64>();
                    sq8_sum += runs.iter().map(|run| (q(run[i][c]) - q(r)).powi(2)).sum::<f64>();
                }
            }
        }
        let m = 3.0 * reference.len() as f64;
        let variance = var_sum / (kf - 1.0) / m;
        // Values' reference errors are independent: the variance of their mean is sum v / M^2.
        let bias_se = (spread / kf + ref_var / (m * m)).sqrt();
        let noise = variance / kf + ref_var / m;
        let mut stats = RunStats {
            runs: k,
            bias,
            bias_se,
            bias_ci: (bias, bias),
            z: if bias_se > 0.0 {
                bias / bias_se
            } else if bias == 0.0 {
                0.0
            } else {
                f64::INFINITY.copysign(bias)
            },
            bias_sq: mean_sq_err / m - variance / kf,
            rms_bias: (mean_sq_err / m - noise).max(0.0).sqrt(),
            bias_ratio: if noise > 0.0 { mean_sq_err / m / noise } else { f64::INFINITY },
            variance,
            mse: over_runs(|e| e.sq),
            rel_mse: over_runs(|e| e.rel),
            eight_bit: info.gamma.map(|_| EightBit { variance: var8_sum / (kf - 1.0) / m, mse: sq8_sum / kf / m }),
            ref_variance: ref_var / m,
            mse_corrected_ci: (0.0, 0.0),
        };
        stats.bias_ci = stats.bias_ci_at(0.95);
        let mse_spread = per_run.iter().map(|e| (e.sq - stats.mse).powi(2)).sum::<f64>() / (kf - 1.0);
        let half = student_t_quantile(0.975, kf - 1.0) * (mse_spread / kf + ref_spread / (m * m)).sqrt();
        stats.mse_corrected_ci = (stats.mse_corrected() - half, stats.mse_corrected() + half);
        Ok(stats)
    }

    /// Two-sided confidence interval of `bias` at `level` (e.g. 0.95), Student t with K - 1 dof.
    ///
    /// # Panics
    /// If `level` is not strictly between 0 and 1.
    pub fn bias_ci_at(&self, level: f64) -> (f64, f64) {
        let half = student_t_quantile(0.5 + 0.5 * level, (self.runs - 1) as f64) * self.bias_se;
        (self.bias - half, self.bias + half)
    }

    /// The MSE with the reference's own noise removed: `mse - ref_variance`. A noisy reference adds
    /// its variance to every run's expected squared error; this is the MSE against the exact image.
    pub fn mse_corrected(&self) -> f64 {
        self.mse - self.ref_variance
    }

    /// `mse - (bias_sq + variance)`: zero up to rounding, since the identity is exact.
    pub fn decomposition_residual(&self) -> f64 {
        self.mse - (self.bias_sq + self.variance)
    }
}

/// Means over all values of the signed, squared and relative squared error of one image.
struct ErrorMeans {
    err: f64,
    sq: f64,
    rel: f64,
}

/// Error means of a validated image against a validated reference of the same size.
fn error_means(img: &[[f32; 3]], reference: &[[f32; 3]]) -> ErrorMeans {
    let (mut err, mut sq, mut rel) = (0.0, 0.0, 0.0);
    for (p, q) in img.iter().zip(reference) {
        for (&v, &r) in p.iter().zip(q) {
            let d = v as f64 - r as f64;
            err += d;
            sq += d * d;
            rel += d * d / (r.max(0.0) as f64 + REL_EPS).powi(2);
        }
    }
    let m = 3.0 * img.len() as f64;
    ErrorMeans { err: err / m, sq: sq / m, rel: rel / m }
}

/// The reference must be non-empty and finite.
fn check_reference(reference: &[[f32; 3]]) -> Result<(), ReportError> {
    if reference.is_empty() {
        return Err(ReportError::Empty);
    }
    check_image(reference, "reference", reference.len())
}

/// `img` must have `pixels` pixels, all finite; `name` labels it in the error.
fn check_image(img: &[[f32; 3]], name: &str, pixels: usize) -> Result<(), ReportError> {
    if img.len() != pixels {
        return Err(ReportError::SizeMismatch { image: name.into(), pixels: img.len(), reference: pixels });
    }
    for (pixel, p) in img.iter().enumerate() {
        if let Some(channel) = p.iter().position(|v| !v.is_finite()) {
            return Err(ReportError::NonFinite { image: name.into(), pixel, channel, value: p[channel] });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const REF: [f32; 3] = [1.0, 1.0, 1.0];

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + b.abs())
    }

    /// K runs over `n` pixels of a constant-1 reference: run k, value j is
    /// `1 + b + d * (-1)^j + s * (-1)^k`: per-value bias `b +- d`, mean bias `b`, and a
    /// run-to-run offset `+-s` that is constant within a run (so the per-run means spread too).
    fn synthetic(k: usize, n: usize, b: f32, d: f32, s: f32) -> Vec<Vec<[f32; 3]>> {
        let sign = |i: usize| if i.is_multiple_of(2) { 1.0 } else { -1.0 };
        (0..k)
            .map(|run| (0..n).map(|p| std::array::from_fn(|c| 1.0 + b + d * sign(3 * p + c) + s * sign(run))).collect())
            .collect()
    }

    #[test]
    fn run_stats_recover_known_bias_variance_and_mse() {
        // Values chosen exactly representable so the expectations are exact up to f64 rounding.
        let (b, d, s) = (0.25f32, 0.125f32, 0.5f32);
        let (b, d, s, n) = (b as f64, d as f64, s as f64, 10);
        for k in [2usize, 4, 8, 16] {
            let kf = k as f64;
            let st = RunStats::from_runs(&synthetic(k, n, b as f32, d as f32, s as f32), &vec![REF; n]).unwrap();
            assert_eq!(st.runs, k);
            assert!(close(st.bias, b, 1e-12), "bias {}", st.bias);
            // Each value takes +-s equally often over an even K: unbiased variance = s^2 K/(K-1).
            assert!(close(st.variance, s * s * kf / (kf - 1.0), 1e-12), "variance {}", st.variance);
            // Every run: error b +- d +- s with the cross terms cancelling -> mse = b^2 + d^2 + s^2.
            assert!(close(st.mse, b * b + d * d + s * s, 1e-12), "mse {}", st.mse);
            // Mean image is exactly 1 + b +- d: bias_sq = b^2 + d^2 - variance/K.
            assert!(close(st.bias_sq, b * b + d * d - s * s / (kf - 1.0), 1e-12));
            assert!(st.decomposition_residual().abs() < 1e-12);
            // rel_mse: the reference is 1, denominator 1.01^2.
            assert!(close(st.rel_mse, st.mse / 1.01f64.powi(2), 1e-12));
            // Per-run mean errors are b +- s: s_e^2 = s^2 K/(K-1), half-width t * s / sqrt(K-1).
            let half = student_t_quantile(0.975, kf - 1.0) * s / (kf - 1.0).sqrt();
            assert!(close(st.bias_ci.0, b - half, 1e-9) && close(st.bias_ci.1, b + half, 1e-9));
            assert!(st.bias_ci.0 < b && b < st.bias_ci.1);
        }
    }

    #[test]
    fn reference_noise_and_eight_bit_statistics_have_the_known_answers() {
        let r = vec![[0.25f32, 0.5, 0.75]; 6];
        let zero = vec![[0.0f32; 3]; 6];
        fn with(var: &[[f32; 3]]) -> ReferenceInfo<'_> {
            ReferenceInfo { variance: Some(var), gamma: Some(1.0), variance_dof: None }
        }
        // Two runs at r - d and r + d: no bias, per-value variance 2 d^2, MSE d^2.
        let d = 0.125f32;
        let runs: Vec<Vec<[f32; 3]>> =
            vec![r.iter().map(|p| p.map(|v| v - d)).collect(), r.iter().map(|p| p.map(|v| v + d)).collect()];
        let s = RunStats::against(&runs, &r, with(&zero)).unwrap();
        assert_eq!(s.runs, 2);
        assert!((s.variance - 2.0 * f64::from(d * d)).abs() < 1e-12, "{}", s.variance);
        assert!((s.mse - f64::from(d * d)).abs() < 1e-12);
        assert_eq!((s.bias, s.z, s.rms_bias), (0.0, 0.0, 0.0));
        // 8-bit (gamma 1, x 255, rounded): 0.125/0.375 -> 32/96, 0.375/0.625 -> 96/159,
        // 0.625/0.875 -> 159/223; variance (a - b)^2 / 2 per channel.
        let want = (64.0f64.powi(2) + 63.0f64.powi(2) + 64.0f64.powi(2)) / 2.0 / 3.0;
        let e = s.eight_bit.unwrap();
        assert!((e.variance - want).abs() < 1e-9, "{} vs {want}", e.variance);
        assert!(RunStats::from_runs(&runs, &r).unwrap().eight_bit.is_none());
        // Identical runs offset by b: zero variance, all error is bias, z infinite.
        let b = 0.0625f32;
        let off: Vec<[f32; 3]> = r.iter().map(|p| p.map(|v| v + b)).collect();
        let s = RunStats::against(&[off.clone(), off.clone(), off], &r, with(&zero)).unwrap();
        assert_eq!(s.variance, 0.0);
        assert!((s.bias - f64::from(b)).abs() < 1e-12 && (s.rms_bias - f64::from(b)).abs() < 1e-9);
        assert_eq!((s.z, s.bias_ratio), (f64::INFINITY, f64::INFINITY));
        // The reference's own variance enters the standard error: M = 18 values of variance v
        // give a mean with variance v / 18.
        let v = 0.02f32;
        let noisy = vec![[v; 3]; 6];
        let runs: Vec<Vec<[f32; 3]>> = vec![r.clone(), r.clone()];
        let s = RunStats::against(&runs, &r, with(&noisy)).unwrap();
        assert!((s.bias_se - (f64::from(v) / 18.0).sqrt()).abs() < 1e-9, "{}", s.bias_se);
        assert!(s.bias_ratio < 1e-12, "no error at all: ratio 0");
        // A reference variance of the wrong size is an error, not a panic.
        let e = RunStats::against(&runs, &r, with(&noisy[..5])).unwrap_err();
        assert_eq!(e.to_string(), "size mismatch: reference variance has 5 pixels but the reference has 6");
    }

    #[test]
    fn confidence_interval_shrinks_like_inverse_sqrt_k() {
        let width = |k: usize| {
            let st = RunStats::from_runs(&synthetic(k, 4, 0.1, 0.0, 0.5), &[REF; 4]).unwrap();
            assert!(st.bias_ci.0 < 0.1 && 0.1 < st.bias_ci.1);
            st.bias_ci.1 - st.bias_ci.0
        };
        // Quadrupling K halves the width, up to the t quantile and (K-1)/K factors.
        let ratio = width(400) / width(100);
        assert!((ratio - 0.5).abs() < 0.01, "ratio {ratio}");
        assert!(width(4) > width(8) && width(8) > width(16));
    }

    /// splitmix64 -> uniform (0, 1) -> Box-Muller normal; deterministic.
    fn normals(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        let mut uniform = move || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 + 0.5 / (1u64 << 53) as f64
        };
        move || (-2.0 * uniform().ln()).sqrt() * (2.0 * std::f64::consts::PI * uniform()).cos()
    }

    #[test]
    fn confidence_interval_covers_95_percent_with_gaussian_noise() {
        // With K = 5 a normal quantile (1.96 instead of 2.776) would cover only ~88%.
        let (k, trials, bias) = (5, 4000, 0.3);
        let mut noise = normals(7);
        let reference = [REF; 3];
        let mut covered = 0;
        for _ in 0..trials {
            let runs: Vec<Vec<[f32; 3]>> = (0..k)
                .map(|_| reference.iter().map(|p| p.map(|r| r + bias as f32 + 0.2 * noise() as f32)).collect())
                .collect();
            let st = RunStats::from_runs(&runs, &reference).unwrap();
            covered += (st.bias_ci.0 <= bias && bias <= st.bias_ci.1) as usize;
            assert!(st.decomposition_residual().abs() < 1e-12);
        }
        let coverage = covered as f64 / trials as f64;
        assert!((coverage - 0.95).abs() < 0.012, "coverage {coverage}");
    }

    /// A reference noisier than the runs (a low-discrepancy variant against a replicated reference):
    /// `mse - ref_variance` then often comes out negative, but its interval holds the true MSE
    /// (the runs' own) about 95% of the time and is never wholly below 0 beyond that.
    #[test]
    fn noise_corrected_mse_interval_covers_the_true_mse() {
        let (k, replicas, values, trials) = (8usize, 8usize, 300usize, 400);
        let mut noise = normals(31);
        let (mut covered, mut negative_point, mut below_zero) = (0, 0, 0);
        for _ in 0..trials {
            let truth: Vec<[f32; 3]> = (0..values / 3).map(|i| [0.5 + 0.001 * i as f32; 3]).collect();
            // Per value: the reference's variance v (of its mean) and the runs' sigma^2 = v / 10.
            let v: Vec<[f64; 3]> = (0..truth.len()).map(|i| [1e-4 * (1.0 + (i % 10) as f64); 3]).collect();
            let (mut reference, mut layer) = (Vec::new(), Vec::new());
            for (t, vv) in truth.iter().zip(&v) {
                let (mut r, mut l) = ([0f32; 3], [0f32; 3]);
                for c in 0..3 {
                    let reps: Vec<f64> =
                        (0..replicas).map(|_| f64::from(t[c]) + (vv[c] * replicas as f64).sqrt() * noise()).collect();
                    let m = reps.iter().sum::<f64>() / replicas as f64;
                    let s2 = reps.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (replicas - 1) as f64;
                    (r[c], l[c]) = (m as f32, (s2 / replicas as f64) as f32);
                }
                reference.push(r);
                layer.push(l);
            }
            let runs: Vec<Vec<[f32; 3]>> = (0..k)
                .map(|_| {
                    let px = truth.iter().zip(&v);
                    px.map(|(t, vv)| std::array::from_fn(|c| t[c] + ((vv[c] / 10.0).sqrt() * noise()) as f32)).collect()
                })
                .collect();
            let true_mse = v.iter().flatten().map(|x| x / 10.0).sum::<f64>() / values as f64;
            let info = ReferenceInfo { variance: Some(&layer), gamma: None, variance_dof: Some((replicas - 1) as f64) };
            let st = RunStats::against(&runs, &reference, info).unwrap();
            let (lo, hi) = st.mse_corrected_ci;
            covered += (lo <= true_mse && true_mse <= hi) as usize;
            negative_point += (st.mse_corrected() < 0.0) as usize;
            below_zero += (hi < 0.0) as usize;
        }
        let coverage = covered as f64 / trials as f64;
        assert!(negative_point > trials / 10, "the case must make MSE - ref. var. negative often: {negative_point}");
        assert!(coverage >= 0.92, "coverage {coverage}");
        assert!(below_zero <= trials * 3 / 100, "interval wholly below 0 in {below_zero} of {trials}");
    }

    #[test]
    fn mse_and_rel_mse_known_values() {
        let reference = [[1.0, 0.0, 2.0], [0.5, 0.0, 0.0]];
        let img = [[1.5, 0.1, 2.0], [0.5, 0.0, -0.2]];
        assert_eq!(mse(&reference, &reference).unwrap(), 0.0);
        assert_eq!(rel_mse(&reference, &reference).unwrap(), 0.0);
        // Squared errors 0.25, 0.01, 0, 0, 0, 0.04 over 6 values (f32 inputs -> tolerance).
        assert!(close(mse(&img, &reference).unwrap(), 0.3 / 6.0, 1e-6));
        let rel = (0.25 / 1.01f64.powi(2) + 0.01 / 0.0001 + 0.04 / 0.0001) / 6.0;
        assert!(close(rel_mse(&img, &reference).unwrap(), rel, 1e-6));
        // A negative reference value counts as 0 in the denominator: never a division by zero.
        assert!(close(rel_mse(&[[0.0; 3]], &[[-0.01, 0.0, 0.0]]).unwrap(), 0.0001 / 0.0001 / 3.0, 1e-6));
    }

    #[test]
    fn efficiency_known_and_guarded() {
        assert_eq!(efficiency(0.01, 4.0).unwrap(), 25.0);
        assert_eq!(efficiency(0.0, 4.0).unwrap(), f64::INFINITY);
        assert_eq!(efficiency(0.5, 0.0).unwrap(), f64::INFINITY);
        assert_eq!(efficiency(1e-200, 1e-200).unwrap(), f64::INFINITY); // underflowing product
        assert_eq!(efficiency(-0.0, 1.0).unwrap(), f64::INFINITY); // not 1 / -0 = -inf
        for (m, s) in [(f64::NAN, 1.0), (1.0, f64::INFINITY), (-1.0, 1.0)] {
            assert!(matches!(efficiency(m, s), Err(ReportError::InvalidArgument { .. })));
        }
    }

    #[test]
    fn bad_inputs_are_errors() {
        let good = vec![REF; 4];
        let mut nan = good.clone();
        nan[2][1] = f32::NAN;
        let e = mse(&nan, &good).unwrap_err();
        assert!(
            matches!(e, ReportError::NonFinite { ref image, pixel: 2, channel: 1, value } if image == "image" && value.is_nan())
        );
        let mut inf = good.clone();
        inf[3][0] = f32::INFINITY;
        assert!(
            matches!(rel_mse(&good, &inf), Err(ReportError::NonFinite { ref image, pixel: 3, channel: 0, .. }) if image == "reference")
        );
        let small = vec![REF; 3];
        let e = mse(&small, &good).unwrap_err();
        assert_eq!(e, ReportError::SizeMismatch { image: "image".into(), pixels: 3, reference: 4 });
        assert!(e.to_string().contains('3') && e.to_string().contains('4'));
        assert_eq!(mse(&[], &[]), Err(ReportError::Empty));
        assert_eq!(RunStats::from_runs(std::slice::from_ref(&good), &good), Err(ReportError::TooFewRuns(1)));
        let e = RunStats::from_runs(&[good.clone(), inf.clone()], &good).unwrap_err();
        assert!(matches!(e, ReportError::NonFinite { ref image, .. } if image == "run 1"));
        let e = RunStats::from_runs(&[good.clone(), small], &good).unwrap_err();
        assert_eq!(e.to_string(), "size mismatch: run 1 has 3 pixels but the reference has 4");
    }

    #[test]
    fn t_quantiles() {
        for (dof, want) in [(1.0, 12.706), (4.0, 2.776), (30.0, 2.042), (1e9, 1.960), (f64::INFINITY, 1.960)] {
            let t = student_t_quantile(0.975, dof);
            assert!((t - want).abs() < 1e-3, "t(0.975, {dof}) = {t}, want {want}");
        }
        // Closed forms: dof 1 is Cauchy, dof 2 is (2p-1)/sqrt(2p(1-p)); also symmetry.
        for p in [0.01, 0.3, 0.6, 0.9, 0.975, 0.999] {
            let cauchy = (std::f64::consts::PI * (p - 0.5)).tan();
            assert!(close(student_t_quantile(p, 1.0), cauchy, 1e-9), "p={p}");
            let two = (2.0 * p - 1.0) / (2.0 * p * (1.0 - p)).sqrt();
            assert!(close(student_t_quantile(p, 2.0), two, 1e-9), "p={p}");
            assert!(close(student_t_quantile(1.0 - p, 7.5), -student_t_quantile(p, 7.5), 1e-9));
        }
        // More digits than the brief asks for (standard tables).
        assert!((student_t_quantile(0.975, 10.0) - 2.228139).abs() < 1e-6);
        assert!((student_t_quantile(0.995, 3.0) - 5.840909).abs() < 1e-6);
    }
}

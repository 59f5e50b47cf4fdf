//! Statistics a paper can quote over a handful of runs: a trimmed MSE (one firefly pixel must not
//! decide a ranking) and percentile-bootstrap confidence intervals over the runs (of the mean MSE,
//! the mean relMSE and the ratio of two variants' efficiencies).

/// The fraction of per-value squared errors a trimmed MSE keeps: the largest 0.1% are dropped.
pub const TRIM_KEEP: f64 = 0.999;

/// Bootstrap resamples per interval.
pub const RESAMPLES: usize = 2000;

/// The MSE of `img` against `reference` over the smallest `keep` fraction of the per-value
/// squared errors (the largest `1 - keep` dropped: fireflies); the plain MSE when `keep >= 1`.
/// Non-finite errors are the largest. NaN for empty images.
pub fn trimmed_mse(img: &[[f32; 3]], reference: &[[f32; 3]], keep: f64) -> f64 {
    let mut sq: Vec<f64> = img
        .iter()
        .zip(reference)
        .flat_map(|(a, b)| (0..3).map(move |c| (f64::from(a[c]) - f64::from(b[c])).powi(2)))
        .map(|e| if e.is_finite() { e } else { f64::INFINITY })
        .collect();
    if sq.is_empty() {
        return f64::NAN;
    }
    let n = ((sq.len() as f64 * keep.clamp(0.0, 1.0)).ceil() as usize).clamp(1, sq.len());
    if n < sq.len() {
        sq.select_nth_unstable_by(n - 1, f64::total_cmp);
    }
    sq[..n].iter().sum::<f64>() / n as f64
}

/// SplitMix64: the resampling's random indices (fixed seed: the same runs give the same interval).
struct SplitMix(u64);

impl SplitMix {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((u128::from(z ^ (z >> 31)) * n as u128) >> 64) as usize
    }
}

fn mean(x: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = x.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    s / n as f64
}

/// The 2.5% and 97.5% quantiles of `stats` (sorted in place; NaN dropped).
fn percentiles(mut stats: Vec<f64>) -> (f64, f64) {
    stats.retain(|v| !v.is_nan());
    if stats.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    stats.sort_by(f64::total_cmp);
    let q = |p: f64| stats[((p * (stats.len() - 1) as f64).round() as usize).min(stats.len() - 1)];
    (q(0.025), q(0.975))
}

/// 95% percentile-bootstrap interval of the mean of `x` (the runs resampled with replacement,
/// [`RESAMPLES`] times, seeded by `seed`); NaN with fewer than two values.
pub fn mean_ci(x: &[f64], seed: u64) -> (f64, f64) {
    if x.len() < 2 {
        return (f64::NAN, f64::NAN);
    }
    let mut rng = SplitMix(seed);
    let stats = (0..RESAMPLES).map(|_| mean((0..x.len()).map(|_| x[rng.below(x.len())]))).collect();
    percentiles(stats)
}

/// 95% percentile-bootstrap interval of the efficiency ratio of a variant to a baseline,
/// `(mean mse_b * mean secs_b) / (mean mse_v * mean secs_v)` (efficiency is `1 / (MSE s)`): each
/// side's runs are resampled as pairs (mse, seconds), independently of the other side's.
pub fn efficiency_ratio_ci(variant: &[(f64, f64)], baseline: &[(f64, f64)], seed: u64) -> (f64, f64) {
    if variant.len() < 2 || baseline.len() < 2 {
        return (f64::NAN, f64::NAN);
    }
    let mut rng = SplitMix(seed);
    let mut cost = |runs: &[(f64, f64)]| {
        let pick: Vec<(f64, f64)> = (0..runs.len()).map(|_| runs[rng.below(runs.len())]).collect();
        mean(pick.iter().map(|p| p.0)) * mean(pick.iter().map(|p| p.1))
    };
    let stats = (0..RESAMPLES).map(|_| cost(baseline) / cost(variant)).collect();
    percentiles(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_firefly_moves_the_mse_but_not_the_trimmed_mse() {
        // Issue 31 item 8: an image with error 0.01 everywhere but one firefly of 1.06 has a larger
        // MSE than one with error 0.011: MSE ranks them by luck, the trimmed MSE by their noise.
        let reference = vec![[0.5f32; 3]; 160 * 120];
        let at = |e: f32| reference.iter().map(|p| p.map(|v| v + e)).collect::<Vec<_>>();
        let (mut a, b) = (at(0.01), at(0.011));
        a[777] = [1.56; 3];
        let mse = |x: &[[f32; 3]]| trimmed_mse(x, &reference, 1.0);
        assert!(mse(&a) > mse(&b), "the firefly decides the plain MSE");
        let (ta, tb) = (trimmed_mse(&a, &reference, TRIM_KEEP), trimmed_mse(&b, &reference, TRIM_KEEP));
        assert!(ta < tb && (ta - 1e-4).abs() < 1e-6 && (tb - 1.21e-4).abs() < 1e-6, "{ta} {tb}");
        assert!(trimmed_mse(&[], &[], TRIM_KEEP).is_nan());
    }

    #[test]
    fn bootstrap_intervals_cover_at_about_their_level() {
        // Means of 8 exponential runs (skewed, as MSEs are): the interval covers the true mean 1 in
        // most of 400 trials (percentile bootstrap with 8 values undercovers a little: >= 85%).
        let mut rng = SplitMix(7);
        let mut u = || (rng.below(1 << 30) as f64 + 0.5) / f64::from(1u32 << 30);
        let (mut covered, mut ratio_covered) = (0, 0);
        for t in 0..400 {
            let x: Vec<f64> = (0..8).map(|_| -u().ln()).collect();
            let (lo, hi) = mean_ci(&x, t);
            assert!(lo <= hi);
            covered += usize::from(lo <= 1.0 && 1.0 <= hi);
            // Two variants of equal cost: the efficiency ratio's interval covers 1.
            let v: Vec<(f64, f64)> = (0..8).map(|_| (-u().ln(), 1.0)).collect();
            let b: Vec<(f64, f64)> = (0..8).map(|_| (-u().ln(), 1.0)).collect();
            let (lo, hi) = efficiency_ratio_ci(&v, &b, t);
            ratio_covered += usize::from(lo <= 1.0 && 1.0 <= hi);
        }
        assert!(covered >= 340, "mean: {covered} of 400");
        assert!(ratio_covered >= 340, "ratio: {ratio_covered} of 400");
        assert!(mean_ci(&[1.0], 0).0.is_nan());
        assert_eq!(mean_ci(&[2.0, 2.0, 2.0], 0), (2.0, 2.0));
    }
}

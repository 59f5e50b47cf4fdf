//! Convergence slopes: the least-squares line through `(ln x, ln y)` points (one point per run
//! and ladder step: `x` the spp or the seconds, `y` the RMSE), with a Student-t confidence
//! interval of its slope. An unbiased Monte Carlo estimator converges at slope -1/2 (RMSE
//! against samples or time); a stratified one can be steeper.

use super::student_t::student_t_quantile;
use serde::Serialize;

/// A fitted slope of `ln y` against `ln x` and its two-sided 95% confidence interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Slope {
    /// the least-squares slope
    pub slope: f64,
    /// lower end of the 95% interval
    pub lo: f64,
    /// upper end of the 95% interval
    pub hi: f64,
    /// the points fitted
    pub points: usize,
}

impl Slope {
    /// Whether `v` lies in the interval.
    pub fn covers(&self, v: f64) -> bool {
        self.lo <= v && v <= self.hi
    }
}

/// The least-squares slope of `ln y` on `ln x` over `points` with positive finite coordinates
/// (others are skipped), with a 95% interval from the residuals (`n - 2` degrees of freedom).
/// `None` with fewer than 3 usable points or fewer than 2 distinct `x`.
pub fn loglog_slope(points: &[(f64, f64)]) -> Option<Slope> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = pts.len() as f64;
    if pts.len() < 3 {
        return None;
    }
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 1e-12 * n {
        return None;
    }
    let slope = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    let sse: f64 = pts.iter().map(|p| (p.1 - my - slope * (p.0 - mx)).powi(2)).sum();
    let se = (sse / (n - 2.0) / sxx).sqrt();
    let half = student_t_quantile(0.975, n - 2.0) * se;
    Some(Slope { slope, lo: slope - half, hi: slope + half, points: pts.len() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_power_laws_have_their_slope_and_a_tight_interval() {
        let pts: Vec<(f64, f64)> = [1.0, 4.0, 16.0, 64.0].iter().map(|&x: &f64| (x, 3.0 * x.powf(-0.5))).collect();
        let s = loglog_slope(&pts).unwrap();
        assert!((s.slope + 0.5).abs() < 1e-12 && s.covers(-0.5) && s.hi - s.lo < 1e-9, "{s:?}");
        assert_eq!(loglog_slope(&pts[..2]), None);
        assert_eq!(loglog_slope(&[(2.0, 1.0), (2.0, 2.0), (2.0, 3.0)]), None);
    }

    #[test]
    fn noisy_points_give_an_interval_that_covers_the_true_slope() {
        // Deterministic +-5% wiggle around x^-0.75, four points per x.
        let mut pts = Vec::new();
        for (i, x) in [1.0f64, 2.0, 4.0, 8.0, 16.0].into_iter().enumerate() {
            for k in 0..4 {
                let wiggle = 1.0 + 0.05 * (((i * 4 + k) * 7919 % 13) as f64 / 6.0 - 1.0);
                pts.push((x, x.powf(-0.75) * wiggle));
            }
        }
        let s = loglog_slope(&pts).unwrap();
        assert!(s.covers(-0.75) && !s.covers(-0.5), "{s:?}");
        assert_eq!(s.points, 20);
    }

    #[test]
    fn t_quantiles_match_tables() {
        for (dof, want) in [(1.0, 12.706_205), (4.0, 2.776_445), (10.0, 2.228_139), (30.0, 2.042_272)] {
            assert!((student_t_quantile(0.975, dof) - want).abs() < 1e-5, "dof {dof}");
        }
    }
}

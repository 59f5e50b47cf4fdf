//! Filter importance sampling of the pixel jitter (`rfilter`): the offset of a pixel sample from
//! the pixel centre is drawn per axis in proportion to the 1D filter, so that the plain mean of
//! the samples' radiance is the filter-weighted pixel value Mitsuba's film computes by splatting
//! each sample with the filter weights and normalizing by their sum.
//!
//! Mitsuba's `gaussian` is `f(x) = max(0, exp(-x^2 / (2 s^2)) - exp(-r^2 / (2 s^2)))`, `r = 4 s`,
//! separable in x and y (and evaluated exactly in its JIT variants, which render the references).
//! Its film (no `sample_border`) only places samples inside the image, so a pixel near the border
//! sees the filter truncated to the image and renormalized: [`FilterWarp::sample`] takes the
//! interval of allowed offsets and draws from the truncated distribution by inverting the CDF
//! between its ends.
//!
//! The CDF is tabulated on `BINS` equal steps over `[-r, r]`, each step's mass the filter's exact
//! integral over it (Simpson, f64); within a step the density is constant. The sampled density is
//! then the step average of `f`: against the exact `f` its effect on a pixel's expected value is
//! second order in the step (`r / 256` pixels), far below any Monte Carlo error.

/// The pixel reconstruction filter (Mitsuba's `rfilter`), applied by filter importance sampling
/// of the pixel jitter ([`FilterWarp`]): a pixel sample lands at `centre + offset` with the offset drawn in
/// proportion to the filter (each axis on its own, truncated to the image as Mitsuba's film
/// without `sample_border` truncates it), so the expected pixel value equals Mitsuba's
/// splatted and weight-normalized one.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum PixelFilter {
    /// `box` of radius 0.5: uniform jitter over the pixel (every `.test` scene)
    #[default]
    Box,
    /// `gaussian`: `max(0, exp(-x^2 / (2 s^2)) - exp(-r^2 / (2 s^2)))` per axis with
    /// `r = 4 s` (Mitsuba's default filter, `stddev` 0.5)
    Gaussian {
        /// standard deviation in pixels (Mitsuba's `stddev`, default 0.5)
        stddev: f32,
    },
}

/// Steps of the tabulated CDF over `[-r, r]`.
const BINS: usize = 512;

/// The 1D warp of a pixel filter (the box filter needs none: its jitter is uniform).
#[derive(Clone, Debug, PartialEq)]
pub struct FilterWarp {
    /// filter radius in pixels
    radius: f32,
    /// CDF at the step edges `-r + 2 r i / BINS`, from 0 to 1
    cdf: Vec<f32>,
}

impl FilterWarp {
    /// The warp of `filter`, None for the box filter.
    pub fn new(filter: PixelFilter) -> Option<Self> {
        match filter {
            PixelFilter::Box => None,
            PixelFilter::Gaussian { stddev } => {
                let s = f64::from(stddev.max(1e-4));
                let r = 4.0 * s;
                let alpha = -1.0 / (2.0 * s * s);
                let bias = (alpha * r * r).exp();
                Some(Self::tabulate(r as f32, |x| ((alpha * x * x).exp() - bias).max(0.0)))
            }
        }
    }

    /// The warp of the 1D filter `f` over `[-radius, radius]`.
    fn tabulate(radius: f32, f: impl Fn(f64) -> f64) -> Self {
        let r = f64::from(radius);
        let h = 2.0 * r / BINS as f64;
        let mut cdf = Vec::with_capacity(BINS + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0);
        for i in 0..BINS {
            let a = -r + h * i as f64;
            // Composite Simpson over the step, 16 intervals.
            let m = 16;
            let g = h / m as f64;
            let mut s = f(a) + f(a + h);
            for j in 1..m {
                s += f(a + g * j as f64) * if j % 2 == 1 { 4.0 } else { 2.0 };
            }
            acc += s * g / 3.0;
            cdf.push(acc);
        }
        let total = acc;
        let cdf = cdf.into_iter().map(|c| (c / total) as f32).collect();
        Self { radius, cdf }
    }

    /// The filter radius in pixels.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The CDF at offset `x` (clamped to the support).
    #[inline]
    fn cdf_at(&self, x: f32) -> f32 {
        let t = ((x + self.radius) / (2.0 * self.radius) * BINS as f32).clamp(0.0, BINS as f32);
        let i = (t as usize).min(BINS - 1);
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        c0 + (t - i as f32) * (c1 - c0)
    }

    /// The offset for `u` in [0, 1), drawn in proportion to the filter restricted to the offsets
    /// `[lo, hi]` (the image around the pixel centre; the filter's support if wider).
    #[inline]
    pub fn sample(&self, u: f32, lo: f32, hi: f32) -> f32 {
        let (a, b) = (self.cdf_at(lo), self.cdf_at(hi));
        let t = a + u * (b - a);
        // The step holding t: the last edge <= t.
        let i = self.cdf.partition_point(|&c| c <= t).clamp(1, BINS) - 1;
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        let frac = if c1 > c0 { ((t - c0) / (c1 - c0)).clamp(0.0, 1.0) } else { 0.5 };
        let step = 2.0 * self.radius / BINS as f32;
        let x = -self.radius + (i as f32 + frac) * step;
        x.clamp(lo.max(-self.radius), hi.min(self.radius))
    }

    /// Density of [`FilterWarp::sample`]'s offsets at `x` for the interval `[lo, hi]`.
    pub fn pdf(&self, x: f32, lo: f32, hi: f32) -> f32 {
        if x < lo || x > hi || x.abs() > self.radius {
            return 0.0;
        }
        let mass = self.cdf_at(hi) - self.cdf_at(lo);
        let step = 2.0 * self.radius / BINS as f32;
        let i = (((x + self.radius) / step) as usize).min(BINS - 1);
        (self.cdf[i + 1] - self.cdf[i]) / step / mass
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{gamma_q, statistic, Rng, CHI2_TESTS, SIGNIFICANCE};

    fn gaussian(x: f64) -> f64 {
        let (s, r) = (0.5f64, 2.0f64);
        ((-x * x / (2.0 * s * s)).exp() - (-r * r / (2.0 * s * s)).exp()).max(0.0)
    }

    /// Integral of Mitsuba's gaussian (stddev 0.5) over [a, b], by fine Simpson in f64.
    fn integral(a: f64, b: f64) -> f64 {
        let m = 2000;
        let h = (b - a) / m as f64;
        let mut s = gaussian(a) + gaussian(b);
        for j in 1..m {
            s += gaussian(a + h * j as f64) * if j % 2 == 1 { 4.0 } else { 2.0 };
        }
        s * h / 3.0
    }

    #[test]
    fn box_filter_needs_no_warp() {
        assert_eq!(FilterWarp::new(PixelFilter::Box), None);
        assert_eq!(FilterWarp::new(PixelFilter::Gaussian { stddev: 0.5 }).unwrap().radius(), 2.0);
    }

    #[test]
    fn gaussian_offsets_follow_the_truncated_filter_chi_square() {
        // Whole support, then truncated at an image border on either side (a pixel centre 0.5
        // from the left edge; 1.5 from the right one).
        let w = FilterWarp::new(PixelFilter::Gaussian { stddev: 0.5 }).unwrap();
        for (lo, hi) in [(-2.0f32, 2.0f32), (-0.5, 2.0), (-2.0, 1.5), (-0.5, 0.5)] {
            let n = 1_000_000;
            let cells = 64;
            let (a, b) = (f64::from(lo), f64::from(hi));
            let total = integral(a, b);
            let edge = |k: usize| a + (b - a) * k as f64 / cells as f64;
            let expected: Vec<f64> = (0..cells).map(|k| n as f64 * integral(edge(k), edge(k + 1)) / total).collect();
            let mut observed = vec![0u64; cells];
            let mut rng = Rng::new(0x6669_6c74 + cells as u64);
            for _ in 0..n {
                let x = w.sample(rng.f32(), lo, hi);
                assert!(x >= lo && x <= hi, "{x} outside [{lo}, {hi}]");
                let k = ((f64::from(x) - a) / (b - a) * cells as f64) as usize;
                observed[k.min(cells - 1)] += 1;
            }
            let (chi2, dof) = statistic(&observed, &expected, n, "gaussian filter");
            let p = gamma_q(0.5 * dof as f64, 0.5 * chi2);
            eprintln!("chi2 gaussian filter [{lo}, {hi}]: chi2 = {chi2:.1}, dof = {dof}, p = {p:.4}");
            assert!(p >= SIGNIFICANCE / CHI2_TESTS as f64, "[{lo}, {hi}]: p = {p:.3e}");
        }
    }

    #[test]
    fn pdf_integrates_to_one_and_matches_the_filter_shape() {
        let w = FilterWarp::new(PixelFilter::Gaussian { stddev: 0.5 }).unwrap();
        let (lo, hi) = (-0.7f32, 2.0f32);
        let m = 20_000;
        let h = (hi - lo) / m as f32;
        let total: f32 = (0..m).map(|i| w.pdf(lo + (i as f32 + 0.5) * h, lo, hi) * h).sum();
        assert!((total - 1.0).abs() < 1e-3, "{total}");
        // Ratio of densities equals the ratio of the filter (to the step's resolution).
        let ratio = w.pdf(0.8, lo, hi) / w.pdf(0.1, lo, hi);
        let want = gaussian(0.8) / gaussian(0.1);
        assert!((f64::from(ratio) - want).abs() < 0.02 * want, "{ratio} vs {want}");
    }
}

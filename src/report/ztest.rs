//! Mitsuba 3's render-regression criterion (`src/render/tests/test_renders.py`), reimplemented:
//! per pixel channel, in CIE XYZ, `z = |image - reference| * sqrt(spp / max(variance, 1e-4))`
//! against the reference's per-sample variance, a two-sided normal p-value, a Sidak-corrected
//! significance level from alpha = 0.01 over the pixels, and the image passes when at least
//! 99.75 % of the pixel channels are accepted.

use statrs::function::erf::erfc;

/// Mitsuba's family-wise alpha.
pub const ALPHA: f64 = 0.01;
/// Fraction of pixel channels that must be accepted.
pub const PASS_FRACTION: f64 = 0.9975;
/// Floor of the reference variance.
pub const VARIANCE_FLOOR: f64 = 1e-4;

/// Linear sRGB to CIE XYZ (D65), the matrix Mitsuba's bitmaps convert with.
const SRGB_TO_XYZ: [[f64; 3]; 3] =
    [[0.412453, 0.357580, 0.180423], [0.212671, 0.715160, 0.072169], [0.019334, 0.119193, 0.950227]];

fn xyz(c: [f32; 3]) -> [f64; 3] {
    SRGB_TO_XYZ.map(|row| row.iter().zip(c).map(|(m, v)| m * f64::from(v)).sum())
}

/// The outcome of one image's test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZTest {
    /// fraction of pixel channels accepted
    pub accepted: f64,
    /// the smallest p-value over the pixel channels
    pub min_p: f64,
    /// the Sidak-corrected significance level a channel's p-value must reach
    pub level: f64,
    /// `accepted >= PASS_FRACTION`
    pub passed: bool,
}

/// Runs the test on `image` (rendered at `spp` samples per pixel) against `reference` and its
/// per-sample variance `variance` (all linear sRGB, row-major, the same length). The variance
/// image goes through the same XYZ matrix, as Mitsuba converts it.
pub fn mitsuba_ztest(image: &[[f32; 3]], spp: u32, reference: &[[f32; 3]], variance: &[[f32; 3]]) -> ZTest {
    assert!(image.len() == reference.len() && image.len() == variance.len(), "image sizes differ");
    let pixels = image.len();
    let level = 1.0 - (1.0 - ALPHA).powf(1.0 / pixels as f64);
    let (mut accepted, mut min_p) = (0usize, 1.0f64);
    for ((&a, &r), &v) in image.iter().zip(reference).zip(variance) {
        let (a, r, v) = (xyz(a), xyz(r), xyz(v));
        for k in 0..3 {
            let z = (a[k] - r[k]).abs() * (f64::from(spp) / v[k].max(VARIANCE_FLOOR)).sqrt();
            // Two-sided: 2 (1 - Phi(z)) = erfc(z / sqrt 2); NaN counts as rejected.
            let p = if z.is_nan() { 0.0 } else { erfc(z / std::f64::consts::SQRT_2) };
            min_p = min_p.min(p);
            accepted += usize::from(p >= level);
        }
    }
    let fraction = accepted as f64 / (3 * pixels).max(1) as f64;
    ZTest { accepted: fraction, min_p, level, passed: fraction >= PASS_FRACTION }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gaussian noise within the stated variance passes; a 20 % bias in the red channel fails.
    #[test]
    fn unbiased_noise_passes_and_a_small_bias_fails() {
        let n = 4096;
        let spp = 1024;
        let var = 0.04f32;
        let reference = vec![[0.5f32, 0.4, 0.3]; n];
        let variance = vec![[var; 3]; n];
        let mut state = 12345u64;
        let mut normal = move || {
            let mut u = || {
                state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
                let mut z = state;
                z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
                ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 + 1e-17
            };
            let (a, b) = (u(), u());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        };
        // Noise in RGB with the per-sample variance `var`, averaged over spp samples.
        let sd = (f64::from(var) / f64::from(spp)).sqrt() * 0.5;
        let image: Vec<[f32; 3]> = reference.iter().map(|r| r.map(|c| (f64::from(c) + sd * normal()) as f32)).collect();
        let t = mitsuba_ztest(&image, spp, &reference, &variance);
        assert!(t.passed, "{t:?}");
        let biased: Vec<[f32; 3]> = image.iter().map(|c| [c[0] * 1.2, c[1], c[2]]).collect();
        let t = mitsuba_ztest(&biased, spp, &reference, &variance);
        assert!(!t.passed && t.min_p < t.level, "{t:?}");
    }
}

//! FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"), the LDR
//! version, through the `nv-flip` crate (NVIDIA's C++ implementation). Images are linear RGB;
//! they are shown to FLIP as a display would show them: clamped to [0, 1], sRGB-encoded, 8 bits.
//! `tests/it/flip.rs` checks the mean against NVIDIA's Python package (`flip-evaluator`).

/// FLIP's default viewing condition: 0.7 m from a 0.7 m wide, 3840-pixel monitor (67 pixels per
/// degree), as in the paper and the reference tools.
pub const PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// The sRGB transfer function of one linear value, clamped to [0, 1] and rounded to 8 bits.
pub fn srgb8(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let e = if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
    (e * 255.0 + 0.5) as u8
}

/// A linear RGB image as 8-bit sRGB bytes (RGB, row-major).
pub fn to_srgb8(img: &[[f32; 3]]) -> Vec<u8> {
    img.iter().flat_map(|p| p.map(srgb8)).collect()
}

/// The per-pixel FLIP error map (values in [0, 1], row-major) of `test` against `reference`, both
/// 8-bit sRGB RGB bytes of a `width` x `height` image.
///
/// # Panics
/// If a buffer is not `3 * width * height` bytes long.
pub fn flip_map_srgb8(reference: &[u8], test: &[u8], width: u32, height: u32) -> Vec<f32> {
    let n = 3 * width as usize * height as usize;
    assert!(reference.len() == n && test.len() == n, "flip: buffers must be 3 x {width} x {height} bytes");
    let r = nv_flip::FlipImageRgb8::with_data(width, height, reference);
    let t = nv_flip::FlipImageRgb8::with_data(width, height, test);
    nv_flip::flip(r, t, PIXELS_PER_DEGREE).to_vec()
}

/// The per-pixel FLIP error map of linear `test` against linear `reference` (see the module).
///
/// # Panics
/// If an image does not have `width * height` pixels.
pub fn flip_map(reference: &[[f32; 3]], test: &[[f32; 3]], width: u32, height: u32) -> Vec<f32> {
    flip_map_srgb8(&to_srgb8(reference), &to_srgb8(test), width, height)
}

/// Mean of a FLIP error map (the number papers quote), summed in f64.
pub fn mean(map: &[f32]) -> f64 {
    map.iter().map(|&v| f64::from(v)).sum::<f64>() / map.len().max(1) as f64
}

/// The magma colour map (FLIP's error-map colours) at `v` in [0, 1].
pub fn magma(v: f32) -> [u8; 3] {
    thread_local! {
        static LUT: Vec<u8> = nv_flip::magma_lut().to_vec();
    }
    let i = (v.clamp(0.0, 1.0) * 255.0 + 0.5) as usize;
    LUT.with(|l| [l[3 * i], l[3 * i + 1], l[3 * i + 2]])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_zero_flip_and_different_ones_do_not() {
        let (w, h) = (24u32, 16u32);
        let a: Vec<[f32; 3]> =
            (0..w * h).map(|i| [(i % w) as f32 / w as f32, 0.5, (i / w) as f32 / h as f32]).collect();
        assert_eq!(mean(&flip_map(&a, &a, w, h)), 0.0);
        let b: Vec<[f32; 3]> = a.iter().map(|p| [1.0 - p[0], p[1], p[2]]).collect();
        let m = mean(&flip_map(&a, &b, w, h));
        assert!(m > 0.05 && m <= 1.0, "{m}");
        // The map is larger where the images differ more.
        let c: Vec<[f32; 3]> = a.iter().map(|p| [p[0] + 0.02, p[1], p[2]]).collect();
        assert!(mean(&flip_map(&a, &c, w, h)) < m);
    }

    #[test]
    fn srgb_encoding_known_values() {
        assert_eq!((srgb8(0.0), srgb8(1.0), srgb8(2.0), srgb8(-1.0), srgb8(f32::NAN)), (0, 255, 255, 0, 0));
        assert_eq!(srgb8(0.214_041_14), 128); // sRGB 0.5 is linear 0.2140
        assert_eq!(magma(0.0), [0, 0, 4]);
    }
}

//! `--sky RADIANCE`: a constant environment light. Every ray that leaves the scene sees the same
//! radiance `L`, from every direction.
//!
//! As a light it is sampled at every next-event vertex, in addition to (and independently of)
//! the area light the light selection picks: a direction uniform over the hemisphere of the
//! shading normal, pdf `1 / (2 pi)` per solid angle, traced as a shadow ray to infinity. The
//! estimate `L f cos / pdf` is weighted with the power heuristic against the BSDF's pdf of the
//! same direction, and a BSDF-sampled ray that escapes is weighted against `1 / (2 pi)` (its
//! direction lies in that hemisphere, or, after a transmitting BSDF, in the one below, where the
//! path tracer mirrors the sample as a second next event of the same pdf).
//! Because it is not one of the lights the selection chooses from, every `--light-selection`
//! mode treats it alike. Camera rays that escape see `L` directly (the background).

use crate::sampling::power_heuristic_x8;
use crate::sampling::sample_uniform_hemisphere_x8;

use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// A constant environment light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sky {
    /// radiance from every direction
    pub radiance: Vec3,
}

impl Sky {
    /// The sky of radiance `radiance`.
    pub fn new(radiance: Vec3) -> Self {
        Self { radiance }
    }

    /// Solid-angle pdf of a sky sample in the hemisphere it is drawn from.
    pub const PDF: f32 = 0.5 * std::f32::consts::FRAC_1_PI;

    /// Local directions (z along the shading normal) of 8 sky samples for unit-square points
    /// `(u, v)`, with their pdf per solid angle (0 on inactive lanes).
    #[inline]
    pub fn sample_x8(&self, u: F8, v: F8, active: Mask8) -> (Vec3x8, F8) {
        sample_uniform_hemisphere_x8([u, v], active)
    }

    /// MIS weight of a sky sample (next event) whose direction the BSDF would sample with
    /// `pdf_bsdf`: the power heuristic with `mis`, 1 without.
    #[inline]
    pub fn nee_weight_x8(mis: bool, pdf_bsdf: F8, active: Mask8) -> F8 {
        if mis {
            power_heuristic_x8(F8::splat(Self::PDF), pdf_bsdf, active)
        } else {
            F8::ONE
        }
    }

    /// Radiance (times its weight) that the escaped rays `missed` of path vertex `v` (1: camera
    /// rays) bring, by next-event mode: `nee` off counts it always, `nee` on only for camera rays
    /// (next events counted it after), MIS weights it against the sky's pdf (`pdf_bsdf` the
    /// pdf the direction was sampled with).
    #[inline]
    pub fn escaped_x8(&self, nee: bool, mis: bool, v: u32, pdf_bsdf: F8, missed: Mask8) -> Vec3x8 {
        Vec3x8::splat(self.radiance).scale(escaped_weight_x8(nee, mis, v, pdf_bsdf, F8::splat(Self::PDF), missed))
    }
}

/// The weight of an environment's radiance that the escaped rays `missed` of path vertex `v` (1:
/// camera rays) bring, by next-event mode: `nee` off counts it always, `nee` on only for camera
/// rays (next events counted it after), MIS weighs it with the power heuristic of `pdf_bsdf` (the
/// pdf the direction was sampled with) against the light's `p_light`. The sky's and the envmap's.
#[inline]
pub fn escaped_weight_x8(nee: bool, mis: bool, v: u32, pdf_bsdf: F8, p_light: F8, missed: Mask8) -> F8 {
    if v == 1 || !nee {
        missed.select(F8::ONE, F8::ZERO)
    } else if mis {
        power_heuristic_x8(pdf_bsdf, p_light, missed)
    } else {
        F8::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::mask_all;

    #[test]
    fn the_two_weights_of_one_direction_sum_to_one() {
        let pdf_b = F8::new([0.0, 0.01, 0.1, 0.159, 0.3, 1.0, 10.0, 1e6]);
        let nee = Sky::nee_weight_x8(true, pdf_b, mask_all());
        let sky = Sky::new(Vec3::ONE);
        let esc = sky.escaped_x8(true, true, 2, pdf_b, mask_all());
        for (a, b) in nee.to_array().iter().zip(esc.x.to_array()) {
            assert!((a + b - 1.0).abs() < 1e-6, "{a} + {b}");
        }
        // Camera rays and NEE off: full radiance; NEE on past the camera: none.
        assert_eq!(sky.escaped_x8(true, true, 1, pdf_b, mask_all()).x.to_array(), [1.0; 8]);
        assert_eq!(sky.escaped_x8(false, false, 3, pdf_b, mask_all()).x.to_array(), [1.0; 8]);
        assert_eq!(sky.escaped_x8(true, false, 3, pdf_b, mask_all()).x.to_array(), [0.0; 8]);
    }
}

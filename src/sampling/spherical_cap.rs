//! Uniform sampling of the solid angle a sphere subtends from a point outside it: the cone of
//! directions towards the sphere's visible cap (as pbrt and Mitsuba sample sphere lights).
//!
//! Seen from `o` at distance `d` from the centre `c`, a sphere of radius `r` fills the cone of half
//! angle `th_max` about `w = (c - o) / d`, `sin^2 th_max = (r / d)^2`. Its solid angle is
//! `S = 2 pi (1 - cos th_max)`, with `1 - cos th_max` written `sin^2 / (1 + cos)` so that it keeps its
//! digits for a small or far sphere (the difference `1 - cos` loses them all below `r / d ~ 3e-4`).
//! A direction uniform in the cone has `1 - cos th = u (1 - cos th_max)` and azimuth `2 pi v`.
//! Rather than intersecting that ray with the sphere (which cancels near the silhouette), the
//! point is placed by the angle `alpha` at the centre between `o - c` and the point: with
//! `sin beta = sin th / sin th_max` (the sine rule in the triangle o, c, y), `alpha = beta - th`,
//! and the point is `c + r n`, `n = -w cos alpha + (cos phi s + sin phi t) sin alpha` in the frame
//! (s, t, w). The ratio `sin^2 th / sin^2 th_max = u (2 - k) / (1 + cos th_max)`, `k = 1 - cos th`,
//! is formed without dividing two small numbers. The density is `1 / S` per unit solid angle.
//!
//! Only the x8 form does arithmetic; the scalar form is lane 0 of it on splatted input, so the two
//! are bit-identical. Lanes where `o` is inside the sphere (or on it) have `S = 0`: the caller
//! samples those by area (`light::warp`).

use crate::simd::{Frame8, Mask8, Vec3x8, F8};
use glam::Vec3;

/// The cone a sphere subtends from a point, for 8 lanes: what its sampling needs.
#[derive(Clone, Copy, Debug)]
pub struct SphericalCap8 {
    c: Vec3x8,
    r: F8,
    frame: Frame8,
    /// 1 - cos th_max
    omc: F8,
    cos_max: F8,
    outside: Mask8,
}

impl SphericalCap8 {
    /// The sphere of centre `c` and radius `r` seen from `o`, per lane.
    #[inline]
    pub fn new(o: Vec3x8, c: Vec3x8, r: F8) -> Self {
        let dc = c - o;
        let d = dc.length();
        let ratio = r / d;
        let sin2 = ratio * ratio;
        let outside = sin2.simd_lt(F8::ONE) & d.simd_gt(F8::ZERO) & sin2.is_finite();
        let sin2 = outside.select(sin2, F8::ZERO);
        let cos_max = (F8::ONE - sin2).sqrt();
        let omc = sin2 / (F8::ONE + cos_max);
        let w = dc.scale(outside.select(F8::ONE / d, F8::ZERO));
        let w = Vec3x8::select(outside, w, Vec3x8::new(F8::ZERO, F8::ZERO, F8::ONE));
        Self { c, r, frame: Frame8::from_normal(w), omc, cos_max, outside }
    }

    /// The solid angle S (0 where the point is not outside the sphere).
    #[inline]
    pub fn solid_angle(&self) -> F8 {
        let s = F8::splat(2.0 * std::f32::consts::PI) * self.omc;
        (self.outside & s.is_finite()).select(s, F8::ZERO)
    }

    /// The point of the visible cap for the unit-square sample `(u, v)` (uniform in solid angle
    /// about the reference point, density 1 / S) and the sphere's outward unit normal there.
    /// Lanes whose S is 0 give a point of no use.
    #[inline]
    pub fn sample(&self, u: F8, v: F8) -> (Vec3x8, Vec3x8) {
        let k = u * self.omc;
        let cos_t = F8::ONE - k;
        let sin_t = (k * (F8::splat(2.0) - k)).max(F8::ZERO).sqrt();
        let q = (u * (F8::splat(2.0) - k) / (F8::ONE + self.cos_max)).min(F8::ONE).max(F8::ZERO);
        let (sin_b, cos_b) = (q.sqrt(), (F8::ONE - q).sqrt());
        let cos_a = cos_b.mul_add(cos_t, sin_b * sin_t);
        let sin_a = (sin_b * cos_t - cos_b * sin_t).max(F8::ZERO);
        let (sin_p, cos_p) = (v * F8::splat(2.0 * std::f32::consts::PI)).sin_cos();
        let local = Vec3x8::new(sin_a * cos_p, sin_a * sin_p, -cos_a);
        let n = self.frame.to_world(local);
        (n.mul_add(self.r, self.c), n)
    }
}

/// Scalar [`SphericalCap8`] (lane 0 of the x8 form): the point and outward normal for `(u, v)`
/// on the sphere `(c, r)` seen from `o`, and its solid angle S (0 from inside).
pub fn sample_spherical_cap(o: Vec3, c: Vec3, r: f32, u: f32, v: f32) -> (Vec3, Vec3, f32) {
    let cap = SphericalCap8::new(Vec3x8::splat(o), Vec3x8::splat(c), F8::splat(r));
    let (y, n) = cap.sample(F8::splat(u), F8::splat(v));
    (y.lane(0), n.lane(0), cap.solid_angle().to_array()[0])
}

#[cfg(test)]
#[path = "spherical_cap_tests.rs"]
mod tests;

//! The Lambertian term kd/pi that every material of the format has, with its sampler, the cosine
//! hemisphere (pdf cos(theta)/pi). It is not a [`super::Lobe`]: it is always present and is the
//! base the specular lobe is added to (`kd/pi + f_spec`, one fused multiply-add).

use crate::sampling::{
    cosine_hemisphere_pdf, cosine_hemisphere_pdf_x8, mul_add3, sample_cosine_hemisphere, sample_cosine_hemisphere_x8,
};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

/// kd/pi + `spec` (local-frame evaluation).
#[inline]
pub fn eval_plus(kd: Vec3, spec: Vec3) -> Vec3 {
    mul_add3(kd, FRAC_1_PI, spec)
}
/// Eight-lane [`eval_plus`].
#[inline]
pub fn eval_plus_x8(kd: Vec3x8, spec: Vec3x8) -> Vec3x8 {
    kd.mul_add(F8::FRAC_1_PI, spec)
}

/// Density of [`sample`] per unit solid angle.
#[inline]
pub fn pdf(wi: Vec3) -> f32 {
    cosine_hemisphere_pdf(wi)
}
/// Eight-lane [`pdf`].
#[inline]
pub fn pdf_x8(wi: Vec3x8, active: Mask8) -> F8 {
    cosine_hemisphere_pdf_x8(wi, active)
}
/// Cosine-distributed wi for u in [0,1)^2.
#[inline]
pub fn sample(u: [f32; 2]) -> Vec3 {
    sample_cosine_hemisphere(u).0
}
/// Eight-lane [`sample`].
#[inline]
pub fn sample_x8(u: [F8; 2], active: Mask8) -> Vec3x8 {
    sample_cosine_hemisphere_x8(u, active).0
}

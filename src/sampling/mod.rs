//! Sampling warps from the unit square to directions and points, their densities, and the MIS power
//! heuristic. Every function has a scalar form (glam `Vec3`, `f32`) and an eight-lane twin (`_x8`).
//!
//! Conventions:
//! - Directions are unit vectors in a local frame whose axis is +z: the shading normal for the
//!   hemisphere warps, the lobe axis for the Phong lobe, the macro-normal for the GGX half vector. θ is
//!   measured from +z, φ from +x towards +y.
//! - Densities are per unit solid angle unless the name ends in `_area` (per unit area).
//! - Every u in [0,1]^2, both ends included, gives a finite direction and a finite pdf >= 0. A sample
//!   whose pdf is 0 (a degenerate direction, or a density that underflows f32) is to be dropped.
//! - x8 twins take `active: Mask8` last and return a zero vector and zero pdf in inactive lanes.
//! - Scalar twins mirror the x8 arithmetic operation by operation, fusing multiply-adds exactly where
//!   `wide` fuses them ([`fmadd`]), so twins without transcendentals agree bit for bit; `wide`'s
//!   polynomial `ln`, `exp`, `exp_m1`, `ln_1p`, `sin_cos` differ from std's by a few ulp.

pub mod filter;
pub mod spherical_cap;
pub mod spherical_rect;
pub mod spherical_tri;
mod warp;
pub use warp::*;

#[cfg(test)]
pub(crate) mod chi2;
#[cfg(test)]
mod tests;

use crate::simd::{Mask8, F8};
use glam::Vec3;

/// `a * b + c`, fused exactly when `wide`'s `f32x8::mul_add` is (x86 FMA, aarch64 NEON), so that a
/// scalar twin rounds like its x8 counterpart.
#[inline]
pub(crate) fn fmadd(a: f32, b: f32, c: f32) -> f32 {
    #[cfg(any(target_feature = "fma", all(target_arch = "aarch64", target_feature = "neon")))]
    {
        a.mul_add(b, c)
    }
    #[cfg(not(any(target_feature = "fma", all(target_arch = "aarch64", target_feature = "neon"))))]
    {
        a * b + c
    }
}

/// Scalar twin of `Vec3x8::dot` (same fused evaluation order).
#[inline]
pub(crate) fn dot(a: Vec3, b: Vec3) -> f32 {
    fmadd(a.x, b.x, fmadd(a.y, b.y, a.z * b.z))
}

/// Scalar twin of `Vec3x8::mul_add`: `v * s + o` per component, fused like `wide`.
#[inline]
pub(crate) fn mul_add3(v: Vec3, s: f32, o: Vec3) -> Vec3 {
    Vec3::new(fmadd(v.x, s, o.x), fmadd(v.y, s, o.y), fmadd(v.z, s, o.z))
}

/// Scalar twin of `Vec3x8::normalize_or_zero`.
#[inline]
pub(crate) fn normalize_or_zero(v: Vec3) -> Vec3 {
    let l2 = dot(v, v);
    v * if l2 > f32::MIN_POSITIVE { 1.0 / l2.sqrt() } else { 0.0 }
}

/// MIS power heuristic (exponent 2) weight of strategy a: pa^2 / (pa^2 + pb^2), for pdfs of the same
/// direction in the same measure. Robust: NaN and negative pdfs count as 0, +inf as `f32::MAX`; the
/// ratio is formed after dividing by max(pa, pb) so it neither overflows nor underflows. Returns a
/// finite weight in [0, 1], and 0 when both pdfs are 0.
#[inline]
#[allow(clippy::manual_clamp)] // max-then-min maps NaN to 0; clamp would keep it
pub fn power_heuristic(pa: f32, pb: f32) -> f32 {
    let (a, b) = (pa.max(0.0).min(f32::MAX), pb.max(0.0).min(f32::MAX));
    let m = a.max(b);
    let (x, y) = (a / m, b / m);
    if m > 0.0 {
        x * x / fmadd(x, x, y * y)
    } else {
        0.0
    }
}

/// Eight-lane [`power_heuristic`]; 0 in inactive lanes.
#[inline]
pub fn power_heuristic_x8(pa: F8, pb: F8, active: Mask8) -> F8 {
    let (a, b) = (pa.max(F8::ZERO).min(F8::MAX), pb.max(F8::ZERO).min(F8::MAX));
    let m = a.max(b);
    let (x, y) = (a / m, b / m);
    (active & m.simd_gt(F8::ZERO)).select(x * x / x.mul_add(x, y * y), F8::ZERO)
}

//! Warps u in [0,1]^2 -> (unit direction in a local frame with axis +z, pdf per unit solid angle), the
//! matching pdfs of a given direction, and the uniform parallelogram with its area-to-solid-angle
//! conversion. Scalar functions first, each x8 twin directly below it, mirroring it line by line.

use super::{dot, fmadd, mul_add3};
use crate::simd::{and_mask, Mask8, Vec3x8, F8};
use glam::Vec3;
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// 1/(2 pi).
pub(crate) const INV_2PI: f32 = 0.5 * FRAC_1_PI;

/// Smallest GGX alpha used: rougher-than-mirror clamp applied to every `alpha` argument, which keeps
/// D <= 1/(pi alpha^2) ~ 3.2e7 finite in f32.
pub const GGX_ALPHA_MIN: f32 = 1e-4;

/// Zero direction and pdf in inactive lanes.
#[inline]
fn finish(w: Vec3x8, pdf: F8, active: Mask8) -> (Vec3x8, F8) {
    (Vec3x8::select(active, w, Vec3x8::ZERO), and_mask(pdf, active))
}

/// (sin phi, cos phi) for phi = 2 pi u.
#[inline]
fn azimuth(u: f32) -> (f32, f32) {
    (TAU * u).sin_cos()
}
#[inline]
fn azimuth_x8(u: F8) -> (F8, F8) {
    (F8::TAU * u).sin_cos()
}

// ---------------------------------------------------------------------------------------------------
// Uniform hemisphere

/// Uniform direction on the hemisphere z >= 0 of the local frame; pdf 1/(2 pi) per unit solid angle.
/// cos theta = u0 (Archimedes' equal-area projection, so strata of u map to equal solid angles).
#[inline]
pub fn sample_uniform_hemisphere(u: [f32; 2]) -> (Vec3, f32) {
    let z = u[0];
    let r = ((1.0 - z) * (1.0 + z)).sqrt();
    let (sp, cp) = azimuth(u[1]);
    (Vec3::new(r * cp, r * sp, z), INV_2PI)
}
/// Eight-lane [`sample_uniform_hemisphere`].
#[inline]
pub fn sample_uniform_hemisphere_x8(u: [F8; 2], active: Mask8) -> (Vec3x8, F8) {
    let z = u[0];
    let r = ((F8::ONE - z) * (F8::ONE + z)).sqrt();
    let (sp, cp) = azimuth_x8(u[1]);
    finish(Vec3x8::new(r * cp, r * sp, z), F8::splat(INV_2PI), active)
}

/// Density of [`sample_uniform_hemisphere`] per unit solid angle at local `w`: 1/(2 pi) for w.z >= 0,
/// else 0.
#[inline]
pub fn uniform_hemisphere_pdf(w: Vec3) -> f32 {
    if w.z >= 0.0 {
        INV_2PI
    } else {
        0.0
    }
}
/// Eight-lane [`uniform_hemisphere_pdf`].
#[inline]
pub fn uniform_hemisphere_pdf_x8(w: Vec3x8, active: Mask8) -> F8 {
    (active & w.z.simd_ge(F8::ZERO)).select(F8::splat(INV_2PI), F8::ZERO)
}

// ---------------------------------------------------------------------------------------------------
// Cosine hemisphere (Shirley-Chiu concentric disk, lifted to the hemisphere by Malley's method)

/// Cosine-weighted direction on the hemisphere z >= 0 of the local frame; pdf cos(theta)/pi per unit
/// solid angle. The concentric map sends squares to rings with bounded distortion, so stratified u
/// stay stratified. At the rim (|2u - 1| = 1 on a side) the pdf is 0.
#[inline]
pub fn sample_cosine_hemisphere(u: [f32; 2]) -> (Vec3, f32) {
    let (a, b) = (2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
    let outer = a.abs() > b.abs();
    let (r, num) = if outer { (a, b) } else { (b, a) };
    let ratio = if r != 0.0 { num / r } else { 0.0 };
    let phi = if outer { FRAC_PI_4 * ratio } else { FRAC_PI_2 - FRAC_PI_4 * ratio };
    let (sp, cp) = phi.sin_cos();
    let ra = r.abs();
    let z = ((1.0 - ra) * (1.0 + ra)).sqrt();
    (Vec3::new(r * cp, r * sp, z), z * FRAC_1_PI)
}
/// Eight-lane [`sample_cosine_hemisphere`].
#[inline]
pub fn sample_cosine_hemisphere_x8(u: [F8; 2], active: Mask8) -> (Vec3x8, F8) {
    let two = F8::splat(2.0);
    let (a, b) = (two * u[0] - F8::ONE, two * u[1] - F8::ONE);
    let outer = a.abs().simd_gt(b.abs());
    let (r, num) = (outer.select(a, b), outer.select(b, a));
    let ratio = r.simd_ne(F8::ZERO).select(num / r, F8::ZERO);
    let phi = outer.select(F8::FRAC_PI_4 * ratio, F8::FRAC_PI_2 - F8::FRAC_PI_4 * ratio);
    let (sp, cp) = phi.sin_cos();
    let ra = r.abs();
    let z = ((F8::ONE - ra) * (F8::ONE + ra)).sqrt();
    finish(Vec3x8::new(r * cp, r * sp, z), z * F8::FRAC_1_PI, active)
}

/// Density of [`sample_cosine_hemisphere`] per unit solid angle at local `w`: max(w.z, 0)/pi.
#[inline]
pub fn cosine_hemisphere_pdf(w: Vec3) -> f32 {
    w.z.max(0.0) * FRAC_1_PI
}
/// Eight-lane [`cosine_hemisphere_pdf`].
#[inline]
pub fn cosine_hemisphere_pdf_x8(w: Vec3x8, active: Mask8) -> F8 {
    and_mask(w.z.max(F8::ZERO) * F8::FRAC_1_PI, active)
}

// ---------------------------------------------------------------------------------------------------
// Phong lobe

/// Phong lobe around +z with exponent s >= 0 (negative s is treated as 0): cos theta = u0^(1/(s+1)),
/// pdf (s+1)/(2 pi) cos^s theta per unit solid angle, on the hemisphere z >= 0.
///
/// f32 precision: ln cos = ln(u0)/(s+1) is exact to a few ulp; from it cos = exp(ln cos) and
/// 1 - cos = -expm1(ln cos) are both exact to a few ulp relative (no `1 - u0^(1/(s+1))` cancellation,
/// which would quantize a lobe of width ~1/s at large s, nor `1 - (1 - cos)`, which would flush
/// cos < 2^-24 near the horizon at small s); sin^2 = (1 - cos)(1 + cos); cos^s = exp(s ln cos). ln cos
/// is clamped to -f32::MAX so that u0 = 0 gives cos = 0 and pdf 1/(2 pi) at s = 0 (0^0 = 1), 0 for
/// s > 0.
#[inline]
pub fn sample_phong_lobe(u: [f32; 2], s: f32) -> (Vec3, f32) {
    let s = s.max(0.0);
    let lc = (u[0].ln() / (s + 1.0)).max(-f32::MAX);
    let (c, omc) = (lc.exp(), -lc.exp_m1());
    let sin = (omc * (1.0 + c)).sqrt();
    let (sp, cp) = azimuth(u[1]);
    (Vec3::new(sin * cp, sin * sp, c), (s + 1.0) * INV_2PI * (lc * s).exp())
}
/// Eight-lane [`sample_phong_lobe`] with a per-lane exponent.
#[inline]
pub fn sample_phong_lobe_x8(u: [F8; 2], s: F8, active: Mask8) -> (Vec3x8, F8) {
    let s = s.max(F8::ZERO);
    let lc = (u[0].ln() / (s + F8::ONE)).max(-F8::MAX);
    let (c, omc) = (lc.exp(), -lc.exp_m1());
    let sin = (omc * (F8::ONE + c)).sqrt();
    let (sp, cp) = azimuth_x8(u[1]);
    let pdf = (s + F8::ONE) * F8::splat(INV_2PI) * (lc * s).exp();
    finish(Vec3x8::new(sin * cp, sin * sp, c), pdf, active)
}

/// cos^s theta of a lobe from c = cos theta and sin2 = sin^2 theta, given separately because near the
/// axis sin^2 carries the precision that c has lost: cos^s = exp(s ln cos) with ln cos = ln1p(-sin2 /
/// (1 + c)) for c > 1/2 and ln c below. The lobe's support is c >= 0 (0 below; 0^0 = 1 at c = 0,
/// s = 0, through the clamp of ln 0 to -f32::MAX).
#[inline]
pub(crate) fn cos_pow(c: f32, sin2: f32, s: f32) -> f32 {
    let l = if c > 0.5 { (-sin2 / (1.0 + c)).ln_1p() } else { c.ln() }.max(-f32::MAX);
    if c >= 0.0 {
        (s * l).exp()
    } else {
        0.0
    }
}
/// Eight-lane [`cos_pow`].
#[inline]
pub(crate) fn cos_pow_x8(c: F8, sin2: F8, s: F8) -> F8 {
    let l = c.simd_gt(F8::HALF).select((-sin2 / (F8::ONE + c)).ln_1p(), c.ln()).max(-F8::MAX);
    c.simd_ge(F8::ZERO).select((s * l).exp(), F8::ZERO)
}

/// Density of [`sample_phong_lobe`] per unit solid angle at `w` in the lobe's frame (axis +z):
/// (s+1)/(2 pi) cos^s theta for w.z >= 0, else 0.
#[inline]
pub fn phong_lobe_pdf(w: Vec3, s: f32) -> f32 {
    let s = s.max(0.0);
    (s + 1.0) * INV_2PI * cos_pow(w.z, fmadd(w.x, w.x, w.y * w.y), s)
}
/// Eight-lane [`phong_lobe_pdf`].
#[inline]
pub fn phong_lobe_pdf_x8(w: Vec3x8, s: F8, active: Mask8) -> F8 {
    let s = s.max(F8::ZERO);
    and_mask((s + F8::ONE) * F8::splat(INV_2PI) * cos_pow_x8(w.z, w.x.mul_add(w.x, w.y * w.y), s), active)
}

// ---------------------------------------------------------------------------------------------------
// GGX (Trowbridge-Reitz) half vector

/// GGX D from cos^2, sin^2 of the half vector's angle to +z and alpha^2:
/// alpha^2 / (pi (alpha^2 cos^2 + sin^2)^2), which equals the format's
/// alpha^2 / (pi cos^4 (alpha^2 + tan^2)^2) without dividing by cos^4. 0 for the zero vector.
#[inline]
pub(crate) fn ggx_d(c2: f32, s2: f32, a2: f32) -> f32 {
    let k = fmadd(a2, c2, s2);
    let k2 = k * k;
    if k2 > 0.0 {
        a2 / (PI * k2)
    } else {
        0.0
    }
}
/// Eight-lane [`ggx_d`].
#[inline]
pub(crate) fn ggx_d_x8(c2: F8, s2: F8, a2: F8) -> F8 {
    let k = a2.mul_add(c2, s2);
    let k2 = k * k;
    k2.simd_gt(F8::ZERO).select(a2 / (F8::PI * k2), F8::ZERO)
}

/// alpha^2 after the [`GGX_ALPHA_MIN`] clamp.
#[inline]
pub(crate) fn ggx_a2(alpha: f32) -> f32 {
    let a = alpha.max(GGX_ALPHA_MIN);
    a * a
}
/// Eight-lane [`ggx_a2`].
#[inline]
pub(crate) fn ggx_a2_x8(alpha: F8) -> F8 {
    let a = alpha.max(F8::splat(GGX_ALPHA_MIN));
    a * a
}

/// GGX half vector h around +z (the macro-normal) with the format's theta_h = atan(alpha sqrt(u0) /
/// sqrt(1 - u0)); pdf D(h) cos theta_h per unit solid angle of h.
///
/// Without the atan: tan^2 = alpha^2 u0/(1 - u0), so with k = (1 - u0) + alpha^2 u0,
/// cos^2 = (1 - u0)/k and sin^2 = alpha^2 u0/k, both exact to a few ulp for every u0 in [0,1]
/// (u0 = 1 gives h on the horizon with pdf 0).
#[inline]
pub fn sample_ggx_half(u: [f32; 2], alpha: f32) -> (Vec3, f32) {
    let a2 = ggx_a2(alpha);
    let omu = 1.0 - u[0];
    let k = fmadd(a2, u[0], omu);
    let (c2, s2) = (omu / k, a2 * u[0] / k);
    let (c, sin) = (c2.sqrt(), s2.sqrt());
    let (sp, cp) = azimuth(u[1]);
    (Vec3::new(sin * cp, sin * sp, c), ggx_d(c2, s2, a2) * c)
}
/// Eight-lane [`sample_ggx_half`] with a per-lane alpha.
#[inline]
pub fn sample_ggx_half_x8(u: [F8; 2], alpha: F8, active: Mask8) -> (Vec3x8, F8) {
    let a2 = ggx_a2_x8(alpha);
    let omu = F8::ONE - u[0];
    let k = a2.mul_add(u[0], omu);
    let (c2, s2) = (omu / k, a2 * u[0] / k);
    let (c, sin) = (c2.sqrt(), s2.sqrt());
    let (sp, cp) = azimuth_x8(u[1]);
    finish(Vec3x8::new(sin * cp, sin * sp, c), ggx_d_x8(c2, s2, a2) * c, active)
}

/// Density of [`sample_ggx_half`] per unit solid angle of the half vector h (local frame, +z = the
/// macro-normal): D(h) max(h.z, 0).
#[inline]
pub fn ggx_half_pdf(h: Vec3, alpha: f32) -> f32 {
    ggx_d(h.z * h.z, fmadd(h.x, h.x, h.y * h.y), ggx_a2(alpha)) * h.z.max(0.0)
}
/// Eight-lane [`ggx_half_pdf`].
#[inline]
pub fn ggx_half_pdf_x8(h: Vec3x8, alpha: F8, active: Mask8) -> F8 {
    and_mask(ggx_d_x8(h.z * h.z, h.x.mul_add(h.x, h.y * h.y), ggx_a2_x8(alpha)) * h.z.max(F8::ZERO), active)
}

// ---------------------------------------------------------------------------------------------------
// Parallelogram lights

/// Uniform point a + u0 ab + u1 ac on a parallelogram (any frame, usually world); returns the point and
/// its pdf per unit area, 1/|ab x ac|, or 0 when the parallelogram is degenerate.
#[inline]
pub fn sample_parallelogram(a: Vec3, ab: Vec3, ac: Vec3, u: [f32; 2]) -> (Vec3, f32) {
    let n = ab.cross(ac);
    let area = dot(n, n).sqrt();
    let p = mul_add3(ac, u[1], mul_add3(ab, u[0], a));
    (p, if area >= f32::MIN_POSITIVE { 1.0 / area } else { 0.0 })
}
/// Eight-lane [`sample_parallelogram`] (one parallelogram per lane); zero point and pdf in inactive
/// lanes.
#[inline]
pub fn sample_parallelogram_x8(a: Vec3x8, ab: Vec3x8, ac: Vec3x8, u: [F8; 2], active: Mask8) -> (Vec3x8, F8) {
    let area = ab.cross(ac).length();
    let p = ac.mul_add(u[1], ab.mul_add(u[0], a));
    finish(p, area.simd_ge(F8::MIN_POSITIVE).select(F8::ONE / area, F8::ZERO), active)
}

/// Converts a pdf per unit area at a light point to per unit solid angle at the receiving point:
/// pdf_area d^2 / |cos_l|, with d^2 the squared distance and cos_l = n_l . w the cosine at the light
/// (for one light of area A, pdf_area = 1/A gives the format's d^2 / (A |n_l . w|)). Returns 0, not
/// inf, when cos_l or pdf_area is 0, and never more than f32::MAX.
#[inline]
pub fn pdf_area_to_solid_angle(pdf_area: f32, dist2: f32, cos_l: f32) -> f32 {
    let c = cos_l.abs();
    if c > 0.0 && pdf_area > 0.0 {
        (pdf_area * dist2 / c).min(f32::MAX)
    } else {
        0.0
    }
}
/// Eight-lane [`pdf_area_to_solid_angle`].
#[inline]
pub fn pdf_area_to_solid_angle_x8(pdf_area: F8, dist2: F8, cos_l: F8, active: Mask8) -> F8 {
    let c = cos_l.abs();
    let ok = active & c.simd_gt(F8::ZERO) & pdf_area.simd_gt(F8::ZERO);
    ok.select((pdf_area * dist2 / c).min(F8::MAX), F8::ZERO)
}

//! GGX microfacet lobe of the format, f_spec = F G D / (4 |n.wi| |n.wo|) with h = normalize(wi + wo),
//! Smith G = G1(wi) G1(wo), G1(v) = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta_v)), Schlick
//! F = ks + (1 - ks)(1 - wi.h)^5, and its sampler: h from the GGX half-vector warp, wi = reflect(wo, h),
//! pdf D(h) cos theta_h / (4 |wo.h|). Local shading frame, n = +z.
//!
//! Evaluated in product form: G1(v) = 2 v.z / lambda(v) with lambda(v) = v.z + sqrt(v.z^2 +
//! alpha^2 (v.x^2 + v.y^2)) (multiply the format's expression by v.z / v.z), so
//! f_spec = F D / (lambda(wi) lambda(wo)) with no division by a grazing cosine. This equals the format's
//! expression wherever it is defined (wi.z, wo.z > 0); elsewhere the caller sets f = 0.

use super::{Lobe, Material, Material8};
use crate::bsdf::desc::BrdfKind;
use crate::sampling::{
    dot, fmadd, ggx_a2, ggx_a2_x8, ggx_d, ggx_d_x8, mul_add3, normalize_or_zero, sample_ggx_half, sample_ggx_half_x8,
};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// lambda(v) = v.z + sqrt(v.z^2 + alpha^2 sin^2 theta_v): G1(v) = 2 v.z / lambda(v).
#[inline]
fn lambda(v: Vec3, a2: f32) -> f32 {
    v.z + fmadd(a2, fmadd(v.x, v.x, v.y * v.y), v.z * v.z).sqrt()
}
#[inline]
fn lambda_x8(v: Vec3x8, a2: F8) -> F8 {
    v.z + a2.mul_add(v.x.mul_add(v.x, v.y * v.y), v.z * v.z).sqrt()
}

/// (f_spec RGB, pdf of [`sample`]) at (wo, wi). The half vector may be taken with either sign: D and
/// |h.z|, |wo.h| are even in h, so reflections about a half vector facing away from wo get the same
/// density as the sampler gave them. wi = -wo (no half vector) has f_spec = pdf = 0.
#[inline]
pub(super) fn lobe(wo: Vec3, wi: Vec3, ks: Vec3, alpha: f32) -> (Vec3, f32) {
    let a2 = ggx_a2(alpha);
    let h = normalize_or_zero(wi + wo);
    let d = ggx_d(h.z * h.z, fmadd(h.x, h.x, h.y * h.y), a2);
    let woh = dot(wo, h).abs();
    let pdf = if woh > 0.0 { (d * h.z.abs() / (4.0 * woh)).min(f32::MAX) } else { 0.0 };
    let m = 1.0 - woh;
    let m2 = m * m;
    let fresnel = mul_add3(Vec3::ONE - ks, m2 * m2 * m, ks);
    (fresnel * (d / (lambda(wi, a2) * lambda(wo, a2))), pdf)
}
/// Eight-lane [`lobe`].
#[inline]
pub(super) fn lobe_x8(wo: Vec3x8, wi: Vec3x8, ks: Vec3x8, alpha: F8) -> (Vec3x8, F8) {
    let a2 = ggx_a2_x8(alpha);
    let h = (wi + wo).normalize_or_zero();
    let d = ggx_d_x8(h.z * h.z, h.x.mul_add(h.x, h.y * h.y), a2);
    let woh = wo.dot(h).abs();
    let pdf = woh.simd_gt(F8::ZERO).select((d * h.z.abs() / (F8::splat(4.0) * woh)).min(F8::MAX), F8::ZERO);
    let m = F8::ONE - woh;
    let m2 = m * m;
    let fresnel = (Vec3x8::splat(Vec3::ONE) - ks).mul_add(m2 * m2 * m, ks);
    (fresnel.scale(d / (lambda_x8(wi, a2) * lambda_x8(wo, a2))), pdf)
}

/// wi = 2 (wo.h) h - wo for a GGX half vector h (may lie below the horizon, where f = 0).
#[inline]
pub(super) fn sample(wo: Vec3, u: [f32; 2], alpha: f32) -> Vec3 {
    let h = sample_ggx_half(u, alpha).0;
    h * (2.0 * dot(wo, h)) - wo
}
/// Eight-lane [`sample`].
#[inline]
pub(super) fn sample_x8(wo: Vec3x8, u: [F8; 2], alpha: F8, active: Mask8) -> Vec3x8 {
    let h = sample_ggx_half_x8(u, alpha, active).0;
    h.scale(F8::splat(2.0) * wo.dot(h)) - wo
}

/// The GGX microfacet lobe (`brdf ggx`).
#[derive(Clone, Copy, Debug)]
pub struct Ggx;

impl Lobe for Ggx {
    const BIT: u32 = 2;
    const NAME: &'static str = "ggx";
    const KIND: BrdfKind = BrdfKind::Ggx;
    fn used_by(m: &crate::bsdf::desc::Material) -> bool {
        // Its Fresnel term makes a lobe even with ks = 0.
        m.brdf == BrdfKind::Ggx
    }
    #[inline]
    fn eval_pdf(m: &Material, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        lobe(wo, wi, m.ks, m.alpha)
    }
    #[inline]
    fn sample(m: &Material, wo: Vec3, u: [f32; 2]) -> Vec3 {
        sample(wo, u, m.alpha)
    }
    #[inline]
    fn lanes(m: &Material8) -> Mask8 {
        m.ggx
    }
    #[inline]
    fn eval_pdf_x8(m: &Material8, wo: Vec3x8, wi: Vec3x8) -> (Vec3x8, F8) {
        lobe_x8(wo, wi, m.ks, m.alpha)
    }
    #[inline]
    fn sample_x8(m: &Material8, wo: Vec3x8, u: [F8; 2], active: Mask8) -> Vec3x8 {
        sample_x8(wo, u, m.alpha, active)
    }
}

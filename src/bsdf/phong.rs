//! Modified Phong specular lobe, f_spec = ks (s+2)/(2 pi) max(0, r . wi)^s with r = 2 (n . wo) n - wo,
//! and its sampler, the Phong lobe warp (pdf (s+1)/(2 pi) max(0, r . wi)^s) rotated from +z to r.
//! Local shading frame, n = +z. max(0, x)^s is taken as 0 for x < 0 also at s = 0 (the lobe is then
//! the uniform hemisphere around r, matching the warp), where IEEE pow(0, 0) = 1 would make it
//! Lambertian over the whole hemisphere of n.

use super::{Lobe, Material, Material8};
use crate::bsdf::desc::BrdfKind;
use crate::sampling::{cos_pow, cos_pow_x8, dot, fmadd, sample_phong_lobe, sample_phong_lobe_x8, INV_2PI};
use crate::simd::{frame_from_normal, Frame8, Mask8, Vec3x8, F8};
use glam::Vec3;

/// Mirror direction r = 2 (n . wo) n - wo for n = +z.
#[inline]
fn mirror(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}
#[inline]
fn mirror_x8(wo: Vec3x8) -> Vec3x8 {
    Vec3x8::new(-wo.x, -wo.y, wo.z)
}

/// (f_spec RGB, pdf of [`sample`]) at (wo, wi). cos^s is evaluated from r . wi and the squared sine
/// taken in r's frame, so a 1e6 lobe keeps its precision.
#[inline]
pub(super) fn lobe(wo: Vec3, wi: Vec3, ks: Vec3, s: f32) -> (Vec3, f32) {
    let s = s.max(0.0);
    let r = mirror(wo);
    let (bs, bt) = frame_from_normal(r);
    let (x, y) = (dot(wi, bs), dot(wi, bt));
    let cs = cos_pow(dot(wi, r), fmadd(x, x, y * y), s);
    (ks * ((s + 2.0) * INV_2PI * cs), (s + 1.0) * INV_2PI * cs)
}
/// Eight-lane [`lobe`].
#[inline]
pub(super) fn lobe_x8(wo: Vec3x8, wi: Vec3x8, ks: Vec3x8, s: F8) -> (Vec3x8, F8) {
    let s = s.max(F8::ZERO);
    let r = mirror_x8(wo);
    let fr = Frame8::from_normal(r);
    let (x, y) = (wi.dot(fr.s), wi.dot(fr.t));
    let cs = cos_pow_x8(wi.dot(r), x.mul_add(x, y * y), s);
    let k = F8::splat(INV_2PI);
    (ks.scale((s + F8::splat(2.0)) * k * cs), (s + F8::ONE) * k * cs)
}

/// wi from the Phong lobe around r (may lie below the horizon, where f = 0).
#[inline]
pub(super) fn sample(wo: Vec3, u: [f32; 2], s: f32) -> Vec3 {
    let r = mirror(wo);
    let (bs, bt) = frame_from_normal(r);
    let l = sample_phong_lobe(u, s).0;
    bs * l.x + bt * l.y + r * l.z
}
/// Eight-lane [`sample`].
#[inline]
pub(super) fn sample_x8(wo: Vec3x8, u: [F8; 2], s: F8, active: Mask8) -> Vec3x8 {
    let r = mirror_x8(wo);
    Frame8::from_normal(r).to_world(sample_phong_lobe_x8(u, s, active).0)
}

/// The modified Phong lobe (`brdf phong`, the format's default).
#[derive(Clone, Copy, Debug)]
pub struct Phong;

impl Lobe for Phong {
    const BIT: u32 = 1;
    const NAME: &'static str = "phong";
    const KIND: BrdfKind = BrdfKind::Phong;
    fn used_by(m: &crate::bsdf::desc::Material) -> bool {
        m.brdf == BrdfKind::Phong && m.specular != Vec3::ZERO
    }
    #[inline]
    fn eval_pdf(m: &Material, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        lobe(wo, wi, m.ks, m.shininess)
    }
    #[inline]
    fn sample(m: &Material, wo: Vec3, u: [f32; 2]) -> Vec3 {
        sample(wo, u, m.shininess)
    }
    #[inline]
    fn lanes(m: &Material8) -> Mask8 {
        // Lanes without a specular term (ks = 0, finite shininess) get exactly nothing from the
        // lobe: f_spec = 0 cos^s, and its pdf enters weighted by specular_probability = 0. Leaving
        // them out lets a packet of diffuse hits skip the lobe.
        let no_spec = m.ks.x.simd_eq(F8::ZERO) & m.ks.y.simd_eq(F8::ZERO) & m.ks.z.simd_eq(F8::ZERO);
        !m.ggx & !(no_spec & m.shininess.is_finite())
    }
    #[inline]
    fn eval_pdf_x8(m: &Material8, wo: Vec3x8, wi: Vec3x8) -> (Vec3x8, F8) {
        lobe_x8(wo, wi, m.ks, m.shininess)
    }
    #[inline]
    fn sample_x8(m: &Material8, wo: Vec3x8, u: [F8; 2], active: Mask8) -> Vec3x8 {
        sample_x8(wo, u, m.shininess, active)
    }
}

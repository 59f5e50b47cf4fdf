//! `thindielectric`: a thin dielectric sheet (a window pane): the light reflected and transmitted
//! after any number of bounces between the sheet's two faces, with no refraction (the transmitted
//! direction is -wo, eta 1). With F the exact Fresnel reflectance of one face at |cos wo|, the
//! sheet reflects R = F + (1 - F)^2 F / (1 - F^2) and transmits 1 - R. Both sides alike. The lobe
//! is picked by `u_lobe` against R, so each lobe's weight is its tint alone.
//!
//! Slots: `scalar[0]` eta = int_ior / ext_ior, `color[0]` specular reflectance, `color[1]`
//! specular transmittance.

use super::fresnel::dielectric_x8;
use super::interface::{flags, flags_where, reflect_z, Bsdf, BsdfParams, Params8, Sample8};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// The thin dielectric sheet (see the module docs).
pub struct ThinDielectric;

impl Bsdf for ThinDielectric {
    const ID: u32 = 4;
    const NAME: &'static str = "thindielectric";
    const FLAGS: u32 = flags::DELTA_REFLECTION | flags::DELTA_TRANSMISSION;

    #[inline]
    fn eval_pdf(_: &Params8, _: Vec3x8, _: Vec3x8, _: Mask8) -> (Vec3x8, F8) {
        (Vec3x8::ZERO, F8::ZERO)
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, _: [F8; 2], active: Mask8) -> Sample8 {
        let active = active & wo.z.simd_ne(F8::ZERO);
        let f = dielectric_x8(wo.z.abs(), p.scalar[0]).0;
        let t = F8::ONE - f;
        // The geometric series of the inner bounces (F = 1: everything reflects).
        let r = f.simd_lt(F8::ONE).select(f + t * t * f / (F8::ONE - f * f), F8::ONE);
        let refl = u_lobe.simd_lt(r);
        let wi = Vec3x8::select(refl, reflect_z(wo), -wo);
        let pdf = refl.select(r, F8::ONE - r);
        let ok = active & pdf.simd_gt(F8::ZERO);
        Sample8 {
            wi: Vec3x8::select(ok, wi, Vec3x8::ZERO),
            weight: Vec3x8::select(ok, Vec3x8::select(refl, p.color[0], p.color[1]), Vec3x8::ZERO),
            pdf: ok.select(pdf, F8::ZERO),
            flags: flags_where(ok & refl, flags::DELTA_REFLECTION) | flags_where(ok & !refl, flags::DELTA_TRANSMISSION),
            eta: F8::ONE,
        }
    }

    fn test_params() -> Vec<BsdfParams> {
        [1.5f32, 1.0001, 4.0, 0.25].iter().map(|&eta| params(eta, Vec3::ONE, Vec3::ONE)).collect()
    }
}

/// A thin dielectric row: relative index, specular reflectance and transmittance.
pub fn params(eta: f32, reflectance: Vec3, transmittance: Vec3) -> BsdfParams {
    BsdfParams {
        kind: ThinDielectric::ID,
        twosided: false,
        color: [reflectance, transmittance, Vec3::ZERO],
        scalar: [eta, 0.0, 0.0, 0.0],
        opacity: 1.0,
    }
}

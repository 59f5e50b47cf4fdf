//! `dielectric`: a smooth boundary between two dielectrics (glass, water): delta reflection with
//! the exact Fresnel reflectance and delta refraction (Snell's law), total internal reflection
//! past the critical angle. Both sides: from the back (`wo.z < 0`) the relative index is inverted.
//! The lobe is picked by `u_lobe` against the Fresnel reflectance (Mitsuba's smooth dielectric),
//! so each lobe's weight is its reflectance or transmittance alone; the refracted weight carries
//! the radiance scaling 1/eta^2.
//!
//! Slots: `scalar[0]` eta = int_ior / ext_ior, `color[0]` specular reflectance, `color[1]` specular
//! transmittance.

use super::fresnel::dielectric_x8;
use super::interface::{flags, flags_where, reflect_z, refract_z, Bsdf, BsdfParams, Params8, Sample8};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// The smooth dielectric (see the module docs).
pub struct Dielectric;

impl Bsdf for Dielectric {
    const ID: u32 = 2;
    const NAME: &'static str = "dielectric";
    const FLAGS: u32 = flags::DELTA_REFLECTION | flags::DELTA_TRANSMISSION;

    #[inline]
    fn eval_pdf(_: &Params8, _: Vec3x8, _: Vec3x8, _: Mask8) -> (Vec3x8, F8) {
        (Vec3x8::ZERO, F8::ZERO)
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, _: [F8; 2], active: Mask8) -> Sample8 {
        let active = active & wo.z.simd_ne(F8::ZERO);
        let (r, cos_t, eta_it, eta_ti) = dielectric_x8(wo.z, p.scalar[0]);
        let refl = u_lobe.simd_lt(r);
        let wi = Vec3x8::select(refl, reflect_z(wo), refract_z(wo, cos_t, eta_ti));
        let weight = Vec3x8::select(refl, p.color[0], p.color[1].scale(eta_ti * eta_ti));
        let pdf = refl.select(r, F8::ONE - r);
        let ok = active & pdf.simd_gt(F8::ZERO);
        Sample8 {
            wi: Vec3x8::select(ok, wi, Vec3x8::ZERO),
            weight: Vec3x8::select(ok, weight, Vec3x8::ZERO),
            pdf: ok.select(pdf, F8::ZERO),
            flags: flags_where(ok & refl, flags::DELTA_REFLECTION) | flags_where(ok & !refl, flags::DELTA_TRANSMISSION),
            eta: (ok & !refl).select(eta_it, F8::ONE),
        }
    }

    fn test_params() -> Vec<BsdfParams> {
        [1.5f32, 1.0001, 4.0, 1.0 / 1.33, 0.25].iter().map(|&eta| params(eta, Vec3::ONE, Vec3::ONE)).collect()
    }
}

/// A dielectric row: relative index, specular reflectance and transmittance.
pub fn params(eta: f32, reflectance: Vec3, transmittance: Vec3) -> BsdfParams {
    BsdfParams { kind: Dielectric::ID, twosided: false, color: [reflectance, transmittance, Vec3::ZERO], scalar: [eta, 0.0, 0.0, 0.0], opacity: 1.0 }
}

//! `conductor`: a smooth metal, a delta reflection weighted by the conductor Fresnel term of the
//! complex index eta + i k (`bsdf::fresnel::conductor_x8`) and `specular_reflectance`. One-sided.
//!
//! Slots: `color[0]` eta, `color[1]` k, `color[2]` specular reflectance. Mitsuba's `material
//! none` is eta = 0, k = 0 (a perfect mirror, reflectance 1 at every angle).

use super::fresnel::conductor_x8;
use super::interface::{flags, reflect_z, Bsdf, BsdfParams, Params8, Sample8};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// The smooth conductor (see the module docs).
pub struct Conductor;

impl Bsdf for Conductor {
    const ID: u32 = 1;
    const NAME: &'static str = "conductor";
    const FLAGS: u32 = flags::DELTA_REFLECTION;

    #[inline]
    fn eval_pdf(_: &Params8, _: Vec3x8, _: Vec3x8, _: Mask8) -> (Vec3x8, F8) {
        (Vec3x8::ZERO, F8::ZERO)
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, _: F8, _: [F8; 2], active: Mask8) -> Sample8 {
        let ok = active & wo.z.simd_gt(F8::ZERO);
        let f = conductor_x8(wo.z, p.color[0], p.color[1]).mul_elem(p.color[2]);
        Sample8 {
            wi: Vec3x8::select(ok, reflect_z(wo), Vec3x8::ZERO),
            weight: Vec3x8::select(ok, f, Vec3x8::ZERO),
            pdf: ok.select(F8::ONE, F8::ZERO),
            flags: super::interface::flags_where(ok, flags::DELTA_REFLECTION),
            eta: F8::ONE,
        }
    }

    fn test_params() -> Vec<BsdfParams> {
        let row = |eta: Vec3, k: Vec3| BsdfParams {
            kind: Self::ID,
            twosided: false,
            color: [eta, k, Vec3::ONE],
            scalar: [0.0; 4],
            opacity: 1.0,
        };
        vec![
            row(Vec3::new(0.2, 0.92, 1.1), Vec3::new(3.9, 2.45, 2.14)),
            row(Vec3::ZERO, Vec3::ZERO),
            row(Vec3::splat(1.0001), Vec3::splat(1e4)),
            row(Vec3::splat(4.0), Vec3::ZERO),
        ]
    }
}

/// A conductor row: eta, k and specular reflectance.
pub fn params(eta: Vec3, k: Vec3, specular: Vec3) -> BsdfParams {
    BsdfParams { kind: Conductor::ID, twosided: false, color: [eta, k, specular], scalar: [0.0; 4], opacity: 1.0 }
}

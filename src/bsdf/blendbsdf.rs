//! `blendbsdf`: Mitsuba's blend of two BSDFs, `(1 - weight) f0 + weight f1` with the pdf blended
//! alike, for the pair strata blends: two Lambertian BSDFs (Mitsuba's `diffuse`, one-sided as
//! Mitsuba's), so the blend is the Lambertian of reflectance `(1 - w) r0 + w r1`, `weight` a float
//! or a texture per hit (clamped to [0, 1] as Mitsuba's `eval_weight`). Directions are
//! cosine-distributed whichever nested BSDF Mitsuba would pick, so `sample` returns the blend's
//! `f |cos| / pdf`: the same expectation as Mitsuba's weight of the nested BSDF it picked (only
//! the variance differs), and the interface's rule (weight = f |cos| / pdf) holds.
//!
//! Slots: `color[0]` r0 (weight 0), `color[1]` r1 (weight 1), `scalar[0]` the weight.

use super::interface::{flags, flags_where, Bsdf, BsdfParams, Params8, Sample8};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// The blend of two Lambertian BSDFs (see the module docs).
pub struct BlendBsdf;

impl Bsdf for BlendBsdf {
    const ID: u32 = 14;
    const NAME: &'static str = "blendbsdf";
    const FLAGS: u32 = flags::DIFFUSE_REFLECTION;

    #[inline]
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        let ok = active & wo.z.simd_gt(F8::ZERO) & wi.z.simd_gt(F8::ZERO);
        let w = p.scalar[0].max(F8::ZERO).min(F8::ONE);
        let r = p.color[0].scale(F8::ONE - w) + p.color[1].scale(w);
        let f = r.scale(F8::splat(std::f32::consts::FRAC_1_PI));
        (Vec3x8::select(ok, f, Vec3x8::ZERO), super::diffuse::pdf_x8(wi, ok))
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, _: F8, u: [F8; 2], active: Mask8) -> Sample8 {
        let active = active & wo.z.simd_gt(F8::ZERO);
        let wi = super::diffuse::sample_x8(u, active);
        let (f, pdf) = Self::eval_pdf(p, wo, wi, active);
        let ok = active & pdf.simd_gt(F8::ZERO);
        let weight = f.scale(ok.select(wi.z / ok.select(pdf, F8::ONE), F8::ZERO));
        Sample8 {
            wi: Vec3x8::select(ok, wi, Vec3x8::ZERO),
            weight: Vec3x8::select(ok, weight, Vec3x8::ZERO),
            pdf: ok.select(pdf, F8::ZERO),
            flags: flags_where(ok, flags::DIFFUSE_REFLECTION),
            eta: F8::ONE,
        }
    }

    fn test_params() -> Vec<BsdfParams> {
        vec![
            params(Vec3::new(0.0, 0.5, 0.5), Vec3::new(1.0, 1.0, 0.0), 0.3),
            params(Vec3::ONE, Vec3::ONE, 0.5),
            params(Vec3::ZERO, Vec3::ONE, 0.0),
            params(Vec3::ZERO, Vec3::ONE, 1.0),
            params(Vec3::splat(0.2), Vec3::splat(0.9), 7.0),
        ]
    }
}

/// A blend row: the reflectances at weight 0 and 1, and the weight.
pub fn params(r0: Vec3, r1: Vec3, weight: f32) -> BsdfParams {
    BsdfParams::new(BlendBsdf::ID, [r0, r1, Vec3::ZERO], [weight, 0.0, 0.0, 0.0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::mask_all;

    /// The blend is the Lambertian of the blended reflectance, and its white furnace is the
    /// blended albedo exactly (cosine sampling: every weight equals it).
    #[test]
    fn blend_is_the_lambertian_of_the_blended_reflectance() {
        let p = Params8::splat(&params(Vec3::new(0.0, 0.5, 0.5), Vec3::new(1.0, 1.0, 0.0), 0.25));
        let wo = Vec3x8::splat(Vec3::new(0.3, 0.1, 0.9).normalize());
        let want = Vec3::new(0.25, 0.625, 0.375);
        for k in 0..64 {
            let u = [F8::splat((k as f32 + 0.5) / 64.0), F8::splat(((k * 37) % 64) as f32 / 64.0 + 0.004)];
            let s = BlendBsdf::sample(&p, wo, F8::ZERO, u, mask_all());
            assert!((s.weight.lane(3) - want).abs().max_element() < 1e-5, "weight {}", s.weight.lane(3));
            let (f, pdf) = BlendBsdf::eval_pdf(&p, wo, s.wi, mask_all());
            assert!((f.lane(0) * std::f32::consts::PI - want).abs().max_element() < 1e-5);
            assert!((pdf.to_array()[0] - s.wi.z.to_array()[0] / std::f32::consts::PI).abs() < 1e-6);
        }
    }
}

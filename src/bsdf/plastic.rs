//! `plastic`: a smooth dielectric coating (index eta) over a Lambertian base (Mitsuba's smooth
//! plastic): delta specular reflection with the exact Fresnel reflectance F, plus the base seen
//! through the coating, f = diff (1 - F(wo)) (1 - F(wi)) / (eta^2 pi), where the base's
//! reflectance `d` is renormalized for the light bounced back by the coating's inside:
//! diff = d / (1 - Fdr) (linear) or d / (1 - d Fdr) (`nonlinear`), Fdr the diffuse internal
//! reflectance. The specular lobe is picked with probability
//! w F / (w F + (1 - w)(1 - F)), F = F(wo), w the specular sampling weight mean(specular) /
//! (mean(diffuse) + mean(specular)). One-sided.
//!
//! Slots: `color[0]` diffuse reflectance d, `color[1]` specular reflectance, `scalar[0]` eta =
//! int_ior / ext_ior, `scalar[1]` Fdr (the internal diffuse reflectance, from [`params`]),
//! `scalar[2]` the specular sampling weight w, `scalar[3]` 1 if `nonlinear` else 0.

use super::fresnel::dielectric_x8;
use super::interface::{flags, flags_where, reflect_z, Bsdf, BsdfParams, Params8, Sample8};
use crate::sampling::{cosine_hemisphere_pdf_x8, sample_cosine_hemisphere_x8};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// The smooth plastic (see the module docs).
pub struct Plastic;

/// The renormalized base reflectance diff / eta^2 of the lanes.
#[inline]
fn base(p: &Params8) -> Vec3x8 {
    let d = p.color[0];
    let fdr = p.scalar[1];
    let nonlinear = p.scalar[3].simd_gt(F8::ZERO);
    let one = F8::ONE;
    let lin = one / (one - fdr);
    let inv = |c: F8| nonlinear.select(one / (one - c * fdr), lin);
    let inv_eta2 = one / (p.scalar[0] * p.scalar[0]);
    Vec3x8::new(d.x * inv(d.x), d.y * inv(d.y), d.z * inv(d.z)).scale(inv_eta2)
}

/// The probability of the specular lobe at wo (F_o = F(wo)).
#[inline]
fn specular_probability(p: &Params8, f_o: F8) -> F8 {
    let w = p.scalar[2];
    let ps = f_o * w;
    let pd = (F8::ONE - f_o) * (F8::ONE - w);
    (ps + pd).simd_gt(F8::ZERO).select(ps / (ps + pd), F8::ZERO)
}

impl Bsdf for Plastic {
    const ID: u32 = 3;
    const NAME: &'static str = "plastic";
    const FLAGS: u32 = flags::DELTA_REFLECTION | flags::DIFFUSE_REFLECTION;

    #[inline]
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        let up = active & wo.z.simd_gt(F8::ZERO) & wi.z.simd_gt(F8::ZERO);
        let f_o = dielectric_x8(wo.z, p.scalar[0]).0;
        let f_i = dielectric_x8(wi.z, p.scalar[0]).0;
        let t = (F8::ONE - f_o) * (F8::ONE - f_i) * F8::FRAC_1_PI;
        let f = base(p).scale(up.select(t, F8::ZERO));
        let pdf = (F8::ONE - specular_probability(p, f_o)) * cosine_hemisphere_pdf_x8(wi, up);
        (f, up.select(pdf, F8::ZERO))
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8) -> Sample8 {
        let active = active & wo.z.simd_gt(F8::ZERO);
        let f_o = dielectric_x8(wo.z, p.scalar[0]).0;
        let ps = specular_probability(p, f_o);
        let spec = u_lobe.simd_lt(ps);
        let wd = sample_cosine_hemisphere_x8(u, active & !spec).0;
        let f_i = dielectric_x8(wd.z, p.scalar[0]).0;
        let pd = F8::ONE - ps;
        let wd_weight = base(p).scale((F8::ONE - f_o) * (F8::ONE - f_i) / pd);
        let spec_weight = p.color[1].scale(f_o / ps);
        let wi = Vec3x8::select(spec, reflect_z(wo), wd);
        let pdf = spec.select(ps, pd * cosine_hemisphere_pdf_x8(wd, active));
        let ok = active & pdf.simd_gt(F8::ZERO) & wi.z.simd_gt(F8::ZERO);
        Sample8 {
            wi: Vec3x8::select(ok, wi, Vec3x8::ZERO),
            weight: Vec3x8::select(ok, Vec3x8::select(spec, spec_weight, wd_weight), Vec3x8::ZERO),
            pdf: ok.select(pdf, F8::ZERO),
            flags: flags_where(ok & spec, flags::DELTA_REFLECTION) | flags_where(ok & !spec, flags::DIFFUSE_REFLECTION),
            eta: F8::ONE,
        }
    }

    fn test_params() -> Vec<BsdfParams> {
        vec![
            params(Vec3::new(0.1, 0.27, 0.36), Vec3::ONE, 1.9, false),
            params(Vec3::ONE, Vec3::ONE, 1.49, false),
            params(Vec3::ONE, Vec3::ONE, 1.49, true),
            params(Vec3::splat(0.5), Vec3::ONE, 1.0001, true),
            params(Vec3::splat(0.5), Vec3::ONE, 4.0, false),
            params(Vec3::ZERO, Vec3::ONE, 1.5, false),
        ]
    }
}

/// The diffuse reflectance of a dielectric boundary of relative index `eta` under uniform
/// (cosine-weighted) illumination: 2 int_0^1 F(mu) mu dmu, by 4096-point midpoint quadrature of
/// the exact Fresnel term (total internal reflection included).
pub fn diffuse_fresnel(eta: f32) -> f32 {
    let n = 4096;
    let sum: f64 = (0..n / 8)
        .map(|j| {
            let mu = F8::new(std::array::from_fn(|i| ((j * 8 + i) as f32 + 0.5) / n as f32));
            let r = dielectric_x8(mu, F8::splat(eta)).0;
            (r * mu).to_array().iter().map(|&x| x as f64).sum::<f64>()
        })
        .sum();
    (2.0 * sum / n as f64) as f32
}

/// A plastic row: diffuse and specular reflectance, relative index, `nonlinear`.
pub fn params(diffuse: Vec3, specular: Vec3, eta: f32, nonlinear: bool) -> BsdfParams {
    let (d, s) = (diffuse.element_sum() / 3.0, specular.element_sum() / 3.0);
    let w = if d + s > 0.0 { s / (d + s) } else { 0.0 };
    BsdfParams {
        kind: Plastic::ID,
        twosided: false,
        color: [diffuse, specular, Vec3::ZERO],
        scalar: [eta, diffuse_fresnel(1.0 / eta), w, if nonlinear { 1.0 } else { 0.0 }],
        opacity: 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diffuse_fresnel_matches_the_known_fits() {
        // d'Eon and Irving's fit for eta > 1 and Egan and Hilgeman's for eta < 1 (0.1 % accurate).
        let deon = |eta: f32| {
            let x = 1.0 / eta;
            0.919317 - 3.4793 * x + 6.75335 * x * x - 7.80989 * x.powi(3) + 4.98554 * x.powi(4) - 1.36881 * x.powi(5)
        };
        let egan = |eta: f32| -1.4399 * eta * eta + 0.7099 * eta + 0.6681 + 0.0636 / eta;
        for &eta in &[1.2f32, 1.5, 1.9] {
            assert!((diffuse_fresnel(eta) - deon(eta)).abs() < 2e-3, "{eta}: {} vs {}", diffuse_fresnel(eta), deon(eta));
            let inv = 1.0 / eta;
            assert!((diffuse_fresnel(inv) - egan(inv)).abs() < 5e-3, "{inv}: {} vs {}", diffuse_fresnel(inv), egan(inv));
        }
    }
}

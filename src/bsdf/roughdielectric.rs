//! `roughdielectric`: a rough boundary between two dielectrics (Mitsuba's `roughdielectric`;
//! Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces"). Both sides:
//! from the back (`wo.z < 0`) the relative index is inverted. A microfacet normal m is drawn from
//! the normals visible from sign(wo.z) wo (or from all normals); reflection about m is picked with
//! probability F(wo.m) (the exact dielectric Fresnel term, 1 under total internal reflection),
//! refraction through m otherwise. With eta the relative index on wo's side and
//! h = normalize(wo + eta' wi) (eta' = 1 for reflection, eta for refraction), h turned to +z:
//! - reflection: f = F D(h) G(wo, wi, h) / (4 |wo.z wi.z|) `specular_reflectance`,
//!   pdf = F pdf_m(h) / (4 |wo.h|);
//! - refraction: f = (1 - F) D G |wo.h| |wi.h| / (|wo.z wi.z| (wo.h + eta wi.h)^2)
//!   `specular_transmittance`, which includes the radiance scaling 1/eta^2 (Mitsuba's radiance
//!   mode), pdf = (1 - F) pdf_m(h) eta^2 |wi.h| / (wo.h + eta wi.h)^2.
//!
//! G / |wo.z wi.z| is evaluated as 1 / (A(wo) A(wi)) (projected areas, `bsdf::microfacet`), so no
//! grazing cosine is divided by.
//!
//! Slots: `scalar[0]` eta = int_ior / ext_ior, `scalar[1]` alpha_u, `scalar[2]` alpha_v,
//! `scalar[3]` the distribution's [`Distribution::code`], `color[0]` specular reflectance,
//! `color[1]` specular transmittance.

use super::fresnel::dielectric_x8;
use super::interface::{flags, flags_where, Bsdf, BsdfParams, Params8, Sample8};
use super::microfacet::{per_variant, Distribution, Microfacet, V3};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// The rough dielectric (see the module docs).
pub struct RoughDielectric;

/// What one distribution's lanes give at (wo, wi): (f as a scalar factor, pdf, reflected lanes).
type Terms = (F8, F8, Mask8);

#[inline]
fn terms(mf: &Microfacet<F8>, eta: F8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> Terms {
    let (zero, one) = (F8::ZERO, F8::ONE);
    let reflect = (wo.z * wi.z).simd_gt(zero);
    let eta_o = wo.z.simd_gt(zero).select(eta, one / eta);
    let h = (wo + wi.scale(reflect.select(one, eta_o))).normalize_or_zero();
    let h = Vec3x8::select(h.z.simd_lt(zero), Vec3x8::ZERO - h, h);
    let (o, i, m): (V3<F8>, V3<F8>, V3<F8>) = (wo.into(), wi.into(), h.into());
    let (wo_h, wi_h) = (o.dot(m), i.dot(m));
    let ok = active
        & (wo.z * wi.z).simd_ne(zero)
        & (wo_h * wo.z).simd_gt(zero)
        & (wi_h * wi.z).simd_gt(zero)
        & h.z.simd_gt(zero);
    // Reflection: wo.h = wi.h up to rounding; their mean keeps f reciprocal bit for bit.
    let r = dielectric_x8(reflect.select(F8::splat(0.5) * (wo_h + wi_h), wo_h), eta).0;
    let d = mf.d(m);
    let areas = mf.projected_area(o) * mf.projected_area(i);
    let pm = mf.pdf(o, m);
    // Reflection.
    let f_r = r * d / (F8::splat(4.0) * areas);
    let p_r = r * pm / (F8::splat(4.0) * wo_h.abs());
    // Refraction.
    let den = eta_o.mul_add(wi_h, wo_h);
    let den2 = den * den;
    let f_t = (one - r) * d * (wo_h * wi_h).abs() / (areas * den2);
    let p_t = (one - r) * pm * eta_o * eta_o * wi_h.abs() / den2;
    let good = ok & areas.simd_gt(zero) & den2.simd_gt(zero);
    let f = good.select(reflect.select(f_r, f_t), zero).min(F8::MAX);
    let pdf = good.select(reflect.select(p_r, p_t), zero).min(F8::MAX);
    let f = pdf.simd_gt(zero).select(f, zero);
    (f, pdf, reflect)
}

#[inline]
fn merge(m: Mask8, a: Terms, b: Terms) -> Terms {
    (m.select(a.0, b.0), m.select(a.1, b.1), m.select(a.2, b.2))
}

impl Bsdf for RoughDielectric {
    const ID: u32 = 11;
    const NAME: &'static str = "roughdielectric";
    const FLAGS: u32 = flags::GLOSSY_REFLECTION | flags::GLOSSY_TRANSMISSION;

    #[inline]
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        let none = (F8::ZERO, F8::ZERO, F8::ZERO);
        let eta = p.scalar[0];
        let (f, pdf, reflect) =
            per_variant(p.scalar[3], p.scalar[1], p.scalar[2], active, none, |mf, l| terms(mf, eta, wo, wi, l), merge);
        (Vec3x8::select(reflect, p.color[0], p.color[1]).scale(f), pdf)
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8) -> Sample8 {
        let zero = F8::ZERO;
        let active = active & wo.z.simd_ne(zero);
        let eta = p.scalar[0];
        let pick = |mf: &Microfacet<F8>, _: Mask8| {
            let m = Vec3x8::from(mf.sample(wo.into(), u).0);
            let wo_m = wo.dot(m);
            let (r, cos_t, _, eta_ti) = dielectric_x8(wo_m, eta);
            let refl = u_lobe.simd_lt(r);
            let wi_r = m.scale(F8::splat(2.0) * wo_m) - wo;
            let wi_t = m.scale(eta_ti.mul_add(wo_m, cos_t)) - wo.scale(eta_ti);
            (Vec3x8::select(refl, wi_r, wi_t).normalize_or_zero(), refl)
        };
        let (wi, refl) = per_variant(p.scalar[3], p.scalar[1], p.scalar[2], active, (Vec3x8::ZERO, zero), pick, |m, a, b| {
            (Vec3x8::select(m, a.0, b.0), m.select(a.1, b.1))
        });
        let (f, pdf) = Self::eval_pdf(p, wo, wi, active);
        // The sampled lobe must leave on its own side (reflection with wo, refraction across).
        let same = (wo.z * wi.z).simd_gt(zero);
        let ok = active & pdf.simd_gt(zero) & !(same ^ refl);
        let weight = f.scale(ok.select(wi.z.abs() / ok.select(pdf, F8::ONE), zero));
        let eta_it = wo.z.simd_gt(zero).select(eta, F8::ONE / eta);
        Sample8 {
            wi: Vec3x8::select(ok, wi, Vec3x8::ZERO),
            weight: Vec3x8::select(ok, weight, Vec3x8::ZERO),
            pdf: ok.select(pdf, zero),
            flags: flags_where(ok & refl, flags::GLOSSY_REFLECTION) | flags_where(ok & !refl, flags::GLOSSY_TRANSMISSION),
            eta: (ok & !refl).select(eta_it, F8::ONE),
        }
    }

    fn test_params() -> Vec<BsdfParams> {
        vec![
            params(Distribution::Beckmann, 0.3, 0.3, true, 1.5, Vec3::ONE, Vec3::ONE),
            params(Distribution::Ggx, 0.3, 0.3, true, 1.5, Vec3::ONE, Vec3::ONE),
            params(Distribution::Ggx, 0.05, 0.5, true, 1.33, Vec3::ONE, Vec3::ONE),
            params(Distribution::Beckmann, 0.6, 0.6, false, 1.2, Vec3::ONE, Vec3::ONE),
            params(Distribution::Ggx, 1.0, 1.0, true, 4.0, Vec3::ONE, Vec3::ONE),
            params(Distribution::Beckmann, 0.2, 0.2, true, 1.0 / 1.5, Vec3::splat(0.5), Vec3::ONE),
        ]
    }
}

/// A rough dielectric row: distribution, alphas, visible-normal sampling, relative index,
/// specular reflectance and transmittance.
pub fn params(
    kind: Distribution,
    alpha_u: f32,
    alpha_v: f32,
    sample_visible: bool,
    eta: f32,
    reflectance: Vec3,
    transmittance: Vec3,
) -> BsdfParams {
    BsdfParams {
        kind: RoughDielectric::ID,
        twosided: false,
        color: [reflectance, transmittance, Vec3::ZERO],
        scalar: [eta, alpha_u, alpha_v, kind.code(sample_visible)],
        opacity: 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::mask_all;

    /// Rows the registry's quadrature cannot resolve (an index of 1.0001 makes refraction a spike
    /// at -wo; alpha 1e-4 a spike at the mirror direction): eval and sample finite, weights >= 0,
    /// the furnace not above 1, at grazing, normal, back-side and critical-angle views.
    #[test]
    fn stiff_rows_stay_finite() {
        let mut zs: Vec<f32> = vec![1.0, 1e-7, -1e-7, 0.0, -1.0, 0.3, -0.3, 1e-3, -1e-3];
        for eta in [1.0001f32, 4.0] {
            let c = (1.0 - 1.0 / (eta * eta)).sqrt();
            zs.extend([c, c * (1.0 + 1e-6), c * (1.0 - 1e-6)].iter().flat_map(|&c| [c, -c]));
        }
        let dirs: Vec<Vec3> = zs.iter().map(|&z| {
            let s = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(s * 0.6, s * 0.8, z)
        }).collect();
        let mut rows = Vec::new();
        for kind in [Distribution::Beckmann, Distribution::Ggx] {
            for (au, av) in [(1e-4, 1e-4), (1e-4, 1e-2), (0.01, 1.0), (1.0, 1.0)] {
                for eta in [1.0001, 1.0 / 1.0001, 4.0, 0.25] {
                    rows.push(params(kind, au, av, true, eta, Vec3::ONE, Vec3::ONE));
                    rows.push(params(kind, au, av, false, eta, Vec3::ONE, Vec3::ONE));
                }
            }
        }
        let mut rng = crate::sampling::chi2::Rng::new(5);
        for row in &rows {
            let p = Params8::splat(row);
            for &wo in &dirs {
                let wo8 = Vec3x8::splat(wo);
                for &wi in &dirs {
                    let (f, pdf) = RoughDielectric::eval_pdf(&p, wo8, Vec3x8::splat(wi), mask_all());
                    assert!(f.is_finite().all() && pdf.is_finite().all() && pdf.simd_ge(F8::ZERO).all(), "{row:?} {wo} {wi}");
                }
                let (mut furnace, mut sq) = (0.0f64, 0.0f64);
                let n = 256;
                for _ in 0..n / 8 {
                    let u = [F8::new(std::array::from_fn(|_| rng.f32())), F8::new(std::array::from_fn(|_| rng.f32()))];
                    let ul = F8::new(std::array::from_fn(|_| rng.f32()));
                    let s = RoughDielectric::sample(&p, wo8, ul, u, mask_all());
                    assert!(s.wi.is_finite().all() && s.weight.is_finite().all() && s.pdf.is_finite().all(), "{row:?} {wo}");
                    assert!(s.weight.x.simd_ge(F8::ZERO).all() && s.eta.simd_gt(F8::ZERO).all(), "{row:?} {wo}");
                    let k = s.has(flags::TRANSMISSION).select(s.eta * s.eta, F8::ONE);
                    for x in (s.weight.x * k).to_array() {
                        furnace += x as f64;
                        sq += x as f64 * x as f64;
                    }
                }
                let mean = furnace / n as f64;
                let sd = ((sq / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
                // At eta = 1.0001 the refraction half vector wo + eta wi nearly cancels: its rounding
                // moves a weight by a few 1e-4.
                assert!(mean <= 1.0 + 5.0 * sd + 1e-3, "{row:?} {wo}: furnace {mean}");
            }
        }
    }
}

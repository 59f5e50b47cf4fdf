//! `roughconductor`: a rough metal (Mitsuba's `roughconductor`; Walter et al. 2007): the
//! microfacet reflection f = F(wi.h) D(h) G(wi, wo, h) / (4 wo.z wi.z) with the conductor Fresnel
//! term of eta + i k and `specular_reflectance`, h = normalize(wo + wi). Beckmann or GGX,
//! isotropic or anisotropic (`bsdf::microfacet`); directions from the normals visible from wo
//! (or all normals), wi reflected about them. One-sided.
//!
//! f is evaluated as F D / (4 A(wo) A(wi)) with the microsurface's projected areas A = cos / G1,
//! so no grazing cosine is divided by; the pdf is pdf_m(h) / (4 wo.h).
//!
//! Slots: `color[0]` eta, `color[1]` k, `color[2]` specular reflectance, `scalar[0]` alpha_u,
//! `scalar[1]` alpha_v, `scalar[2]` the distribution's [`Distribution::code`].

use super::fresnel::conductor_x8;
use super::interface::{flags, flags_where, Bsdf, BsdfParams, Params8, Sample8};
use super::microfacet::{per_variant, Distribution, Microfacet, V3};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// The rough conductor (see the module docs).
pub struct RoughConductor;

/// (f, pdf) of the lanes of one distribution at (wo, wi), h = normalize(wo + wi).
#[inline]
pub(super) fn reflection(mf: &Microfacet<F8>, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (F8, F8, F8) {
    // Returns (f without Fresnel, pdf, the cosine for the Fresnel term).
    let zero = F8::ZERO;
    let h = (wo + wi).normalize_or_zero();
    let (o, i, m): (V3<F8>, V3<F8>, V3<F8>) = (wo.into(), wi.into(), h.into());
    let (wo_h, wi_h) = (o.dot(m), i.dot(m));
    let ok = active & wo.z.simd_gt(zero) & wi.z.simd_gt(zero) & wo_h.simd_gt(zero) & wi_h.simd_gt(zero);
    let d = mf.d(m);
    let den = F8::splat(4.0) * mf.projected_area(o) * mf.projected_area(i);
    let f = ok.select(d / ok.select(den, F8::ONE), zero);
    let pdf = ok.select(mf.pdf(o, m) / (F8::splat(4.0) * ok.select(wo_h, F8::ONE)), zero);
    // wo.h = wi.h up to rounding; their mean keeps the Fresnel term reciprocal bit for bit.
    (f.min(F8::MAX), pdf.min(F8::MAX), F8::splat(0.5) * (wo_h + wi_h))
}

impl Bsdf for RoughConductor {
    const ID: u32 = 10;
    const NAME: &'static str = "roughconductor";
    const FLAGS: u32 = flags::GLOSSY_REFLECTION;

    #[inline]
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        let (f, pdf, wi_h) = per_variant(
            p.scalar[2],
            p.scalar[0],
            p.scalar[1],
            active,
            (F8::ZERO, F8::ZERO, F8::ZERO),
            |mf, lanes| reflection(mf, wo, wi, lanes),
            |m, a, b| (m.select(a.0, b.0), m.select(a.1, b.1), m.select(a.2, b.2)),
        );
        let fres = conductor_x8(wi_h, p.color[0], p.color[1]).mul_elem(p.color[2]);
        (fres.scale(f), pdf)
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, _: F8, u: [F8; 2], active: Mask8) -> Sample8 {
        let active = active & wo.z.simd_gt(F8::ZERO);
        let wi = per_variant(
            p.scalar[2],
            p.scalar[0],
            p.scalar[1],
            active,
            Vec3x8::ZERO,
            |mf, _| {
                let (m, _) = mf.sample(wo.into(), u);
                let m = Vec3x8::from(m);
                m.scale(F8::splat(2.0) * wo.dot(m)) - wo
            },
            Vec3x8::select,
        );
        let (f, pdf) = Self::eval_pdf(p, wo, wi, active);
        let ok = active & pdf.simd_gt(F8::ZERO) & wi.z.simd_gt(F8::ZERO);
        let weight = f.scale(ok.select(wi.z / ok.select(pdf, F8::ONE), F8::ZERO));
        Sample8 {
            wi: Vec3x8::select(ok, wi, Vec3x8::ZERO),
            weight: Vec3x8::select(ok, weight, Vec3x8::ZERO),
            pdf: ok.select(pdf, F8::ZERO),
            flags: flags_where(ok, flags::GLOSSY_REFLECTION),
            eta: F8::ONE,
        }
    }

    fn test_params() -> Vec<BsdfParams> {
        let (cu_eta, cu_k) = (Vec3::new(0.2, 0.92, 1.1), Vec3::new(3.9, 2.45, 2.14));
        vec![
            params(Distribution::Ggx, 0.3, 0.3, true, cu_eta, cu_k, Vec3::ONE),
            params(Distribution::Beckmann, 0.3, 0.3, true, cu_eta, cu_k, Vec3::ONE),
            params(Distribution::Ggx, 0.05, 0.5, true, Vec3::ZERO, Vec3::ZERO, Vec3::ONE),
            params(Distribution::Beckmann, 0.5, 0.05, false, Vec3::splat(1.0001), Vec3::splat(1e4), Vec3::ONE),
            params(Distribution::Ggx, 1.0, 1.0, false, Vec3::splat(4.0), Vec3::ZERO, Vec3::splat(0.5)),
            params(Distribution::Beckmann, 1.0, 1.0, true, Vec3::ZERO, Vec3::ZERO, Vec3::ONE),
        ]
    }
}

/// A rough conductor row: distribution, alphas, visible-normal sampling, eta, k, specular
/// reflectance.
pub fn params(
    kind: Distribution,
    alpha_u: f32,
    alpha_v: f32,
    sample_visible: bool,
    eta: Vec3,
    k: Vec3,
    specular: Vec3,
) -> BsdfParams {
    BsdfParams {
        kind: RoughConductor::ID,
        twosided: false,
        color: [eta, k, specular],
        scalar: [alpha_u, alpha_v, kind.code(sample_visible), 0.0],
        opacity: 1.0,
    }
}

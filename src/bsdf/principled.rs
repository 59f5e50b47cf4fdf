//! `principled`: Mitsuba 3's Disney principled BSDF (Burley 2012, 2015, as Mitsuba 3.9 writes it in
//! `principled.cpp`): a GGX specular lobe of alphas from `roughness` and `anisotropic` that
//! reflects and (weight `bsdf` = (1 - metallic) spec_trans) refracts through a dielectric of
//! index `eta`, a GTR1 clearcoat, the Disney diffuse (retro-reflection, `flatness`' fake
//! subsurface; weight `brdf` = (1 - metallic)(1 - spec_trans)) and sheen. Both sides: from the back
//! (`wo.z < 0`, inside the object) only the dielectric remains (its reflection weighted by
//! `bsdf`). With wo the viewer, wi the light, h = normalize(wo + wi eta') turned to +z (eta' = 1
//! for reflection, eta on wo's side for refraction):
//! - specular reflection: F D G / (4 |wo.z wi.z|), where F is (1 - metallic)(1 - spec_tint)
//!   F_diel(wo.h) plus metallic Schlick(base, wo.h) plus (1 - metallic) spec_tint Schlick(tint
//!   R0(eta), wo.h) in front, and `bsdf` F_diel from the back (`tint`: base over its luminance);
//! - specular transmission: sqrt(base) `bsdf` (1 - F_diel) D G |wo.h wi.h| / (|wo.z wi.z|
//!   (wo.h + eta' wi.h)^2) (the 1/eta^2 radiance scaling included);
//! - clearcoat (front): clearcoat / 4 Schlick(0.04, wo.h) D_GTR1(h) G_GGX(0.25) (Mitsuba's, without
//!   the 1 / (4 cos cos) of a microfacet BRDF);
//! - diffuse (front): `brdf` base `diffuse_shape`; sheen (front): sheen (1 - metallic)
//!   `sheen_color`.
//!
//! Sampling (Mitsuba's lobe probabilities, normalized): diffuse `brdf` r_d, clearcoat clearcoat / 4
//! r_c, transmission r_s `bsdf` (1 - F), reflection r_s (1 - `bsdf` (1 - F)) in front (F at the
//! sampled visible normal); F and 1 - F from the back. The r are the `*_sampling_rate`s. A lane
//! from the back whose `bsdf` is 0 has no sample and pdf 0 (Mitsuba reports a pdf there; its f
//! is 0).
//!
//! `diffuse_shape`, `sheen_color` and the parameter table are in `bsdf::microfacet::principled`.
//!
//! Slots: `color[0]` base_color, `color[1].x` the table entry;
//! the entry's parameters in the order of [`PARAMS`].

use super::fresnel::dielectric_x8;
use super::interface::{flags, flags_where, Bsdf, BsdfParams, Params8, Sample8};
use super::microfacet::principled::{
    diffuse_shape, gather, ggx, inv_areas, lerp, negate_where, r0_of_eta, rcp_or_zero, reflect, row,
    sample_visible, schlick, schlick3, schlick_cos_weight, sheen_color, sides_agree, tint, visible_pdf, Entry,
    defaults_entry, CONSTANT, N,
};
use super::microfacet::real::{exp, ln, sincos_2pi};
use crate::sampling::{cosine_hemisphere_pdf_x8, sample_cosine_hemisphere_x8};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// Mitsuba's scalar parameters (name, default, texture allowed) in table order: the entry's
/// `values[j]` is `PARAMS[j]`. `eta` is Mitsuba's `eta`, or the one its `specular` gives.
pub const PARAMS: [(&str, f32, bool); 14] = [
    ("roughness", 0.5, true),
    ("anisotropic", 0.0, true),
    ("metallic", 0.0, true),
    ("spec_trans", 0.0, true),
    ("eta", 1.5, false),
    ("spec_tint", 0.0, true),
    ("sheen", 0.0, true),
    ("sheen_tint", 0.0, true),
    ("flatness", 0.0, true),
    ("clearcoat", 0.0, true),
    ("clearcoat_gloss", 0.0, true),
    ("main_specular_sampling_rate", 1.0, false),
    ("clearcoat_sampling_rate", 1.0, false),
    ("diffuse_reflectance_sampling_rate", 1.0, false),
];

const ROUGHNESS: usize = 0;
const ANISOTROPIC: usize = 1;
const METALLIC: usize = 2;
const SPEC_TRANS: usize = 3;
const ETA: usize = 4;
const SPEC_TINT: usize = 5;
const SHEEN: usize = 6;
const SHEEN_TINT: usize = 7;
const FLATNESS: usize = 8;
const CLEARCOAT: usize = 9;
const CLEARCOAT_GLOSS: usize = 10;
const RATE_SPECULAR: usize = 11;
const RATE_CLEARCOAT: usize = 12;
const RATE_DIFFUSE: usize = 13;

/// The defaults, for lanes whose entry is missing.
const DEFAULTS: Entry = defaults_entry(&PARAMS);

/// The principled BSDF (see the module docs).
pub struct Principled;

/// One packet's parameters.
struct Lanes {
    q: [F8; N],
    base: Vec3x8,
}

impl Lanes {
    #[inline]
    fn of(p: &Params8) -> Self {
        Self { q: gather(p, &DEFAULTS), base: p.color[0] }
    }
    /// (brdf, bsdf) lobe weights.
    #[inline]
    fn weights(&self) -> (F8, F8) {
        let dielectric = F8::ONE - self.q[METALLIC];
        (dielectric * (F8::ONE - self.q[SPEC_TRANS]), dielectric * self.q[SPEC_TRANS])
    }
    /// Clearcoat GTR1 alpha: lerp(0.1, 0.001, clearcoat_gloss).
    #[inline]
    fn clearcoat_alpha(&self) -> F8 {
        lerp(F8::splat(0.1), F8::splat(0.001), self.q[CLEARCOAT_GLOSS])
    }
    /// Normalized lobe probabilities (diffuse, clearcoat, transmission, reflection) for the
    /// dielectric reflectance `fr`; all 0 where they sum to 0.
    #[inline]
    fn probabilities(&self, front: Mask8, fr: F8) -> [F8; 4] {
        let (zero, one) = (F8::ZERO, F8::ONE);
        let (brdf, bsdf) = self.weights();
        let rs = self.q[RATE_SPECULAR];
        let refl = front.select(rs * (one - bsdf * (one - fr)), fr);
        let trans = front.select(rs * bsdf * (one - fr), one - fr);
        let cc = front.select(F8::splat(0.25) * self.q[CLEARCOAT] * self.q[RATE_CLEARCOAT], zero);
        let diff = front.select(brdf * self.q[RATE_DIFFUSE], zero);
        let k = rcp_or_zero(refl + trans + cc + diff);
        [diff * k, cc * k, trans * k, refl * k]
    }
}

/// GTR1 D(m) of alpha `a` (Burley 2012's clearcoat; 0 where D cos_m is not above 1e-20).
#[inline]
fn gtr1_d(a: F8, m: Vec3x8) -> F8 {
    let a2 = a * a;
    let c = m.z;
    let d = (a2 - F8::ONE) / (F8::PI * ln(a2) * (a2 - F8::ONE).mul_add(c * c, F8::ONE));
    (d * c).simd_gt(F8::splat(1e-20)).select(d, F8::ZERO)
}

/// A GTR1 normal of alpha `a` for `u` (density D(m) m.z).
#[inline]
fn gtr1_sample(a: F8, u: [F8; 2]) -> Vec3x8 {
    let a2 = a * a;
    let (sp, cp) = sincos_2pi(u[0]);
    let cos2 = (F8::ONE - exp((F8::ONE - u[1]) * ln(a2))) / (F8::ONE - a2);
    let (sin_t, cos_t) = ((F8::ONE - cos2).max(F8::ZERO).sqrt(), cos2.max(F8::ZERO).sqrt());
    Vec3x8::new(cp * sin_t, sp * sin_t, cos_t)
}

/// The clearcoat's separable Smith G1 of GGX alpha 0.25 at `v`: 2 |v.z| / (|v.z| + sqrt(v.z^2 +
/// alpha^2 sin^2)) (1 at normal incidence), 0 where v sees m's back.
#[inline]
fn clearcoat_g1(v: Vec3x8, m: Vec3x8) -> F8 {
    let c = v.z.abs();
    let s = c + c.mul_add(c, F8::splat(0.0625) * (F8::ONE - c * c)).sqrt();
    (v.dot(m) * v.z).simd_gt(F8::ZERO).select(F8::splat(2.0) * c / s, F8::ZERO)
}

/// (f, pdf) at (wo, wi) on `active` lanes (see the module docs).
#[inline]
fn eval_pdf(l: &Lanes, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
    let (zero, one) = (F8::ZERO, F8::ONE);
    let q = &l.q;
    let (brdf, bsdf) = l.weights();
    let front = wo.z.simd_gt(zero);
    let active = active & wo.z.simd_ne(zero) & (front | bsdf.simd_gt(zero));
    let reflect = (wo.z * wi.z).simd_gt(zero);
    let refract = (wo.z * wi.z).simd_lt(zero);
    let eta = q[ETA];
    let eta_path = front.select(eta, one / eta);
    let mf = ggx(q[ANISOTROPIC], q[ROUGHNESS]);
    let h = (wo + wi.scale(reflect.select(one, eta_path))).normalize_or_zero();
    let h = negate_where(h.z.simd_lt(zero), h);
    let (wo_h, wi_h) = (wo.dot(h), wi.dot(h));
    // Reflection: wo.h = wi.h up to rounding; their mean keeps f reciprocal.
    let c_f = reflect.select(F8::splat(0.5) * (wo_h + wi_h), wo_h);
    let fr = dielectric_x8(c_f, eta).0;
    let refl_ok = reflect & sides_agree(h, wo, wi, true);
    let refr_ok = refract & sides_agree(h, wo, wi, false);
    let d = mf.d(h.into());
    let g = inv_areas(&mf, wo, wi);

    // Specular reflection.
    let metallic = q[METALLIC];
    let spec_tint = q[SPEC_TINT];
    let w = schlick_cos_weight(c_f, eta);
    let eta_it = c_f.simd_ge(zero).select(eta, one / eta);
    let f_front = schlick3(l.base, w).scale(metallic)
        + schlick3(tint(l.base).scale(r0_of_eta(eta_it)), w).scale((one - metallic) * spec_tint)
        + Vec3x8::splat(Vec3::ONE).scale((one - metallic) * (one - spec_tint) * fr);
    let f_spec = Vec3x8::select(front, f_front, Vec3x8::splat(Vec3::ONE).scale(bsdf * fr));
    let spec_on = active & refl_ok & fr.simd_gt(zero);
    let mut f = Vec3x8::select(spec_on, f_spec.scale(d * g * F8::splat(0.25)), Vec3x8::ZERO);

    // Specular transmission.
    let den = eta_path.mul_add(wi_h, wo_h);
    let trans_on = active & refr_ok & bsdf.simd_gt(zero) & fr.simd_lt(one);
    let t = bsdf * (one - fr) * d * g * (wo_h * wi_h).abs() * rcp_or_zero(den * den);
    let sqrt_base = Vec3x8::new(l.base.x.sqrt(), l.base.y.sqrt(), l.base.z.sqrt());
    f += Vec3x8::select(trans_on, sqrt_base.scale(t), Vec3x8::ZERO);

    // Clearcoat.
    let cc = q[CLEARCOAT];
    let a_cc = l.clearcoat_alpha();
    let cc_on = active & refl_ok & front & cc.simd_gt(zero);
    let f_cc = cc * F8::splat(0.25) * schlick(F8::splat(0.04), w) * gtr1_d(a_cc, h) * clearcoat_g1(wo, h) * clearcoat_g1(wi, h);
    f += Vec3x8::splat(Vec3::ONE).scale(cc_on.select(f_cc, zero));

    // Diffuse and sheen.
    let diff_on = active & reflect & front & brdf.simd_gt(zero);
    let shape = diffuse_shape(q[ROUGHNESS], q[FLATNESS], wo.z.abs(), wi.z.abs(), c_f);
    f += Vec3x8::select(diff_on, l.base.scale(brdf * shape), Vec3x8::ZERO);
    let sheen = q[SHEEN];
    let sheen_on = diff_on & sheen.simd_gt(zero) & (one - metallic).simd_gt(zero);
    let f_sheen = sheen_color(l.base, q[SHEEN_TINT], c_f).scale(sheen * (one - metallic));
    f += Vec3x8::select(sheen_on, f_sheen, Vec3x8::ZERO);

    // The pdf.
    let fr_p = dielectric_x8(wo_h, eta).0;
    let [p_d, p_c, p_t, p_r] = l.probabilities(front, fr_p);
    let dwh = reflect.select(rcp_or_zero(F8::splat(4.0) * wi_h.abs()), eta_path * eta_path * wi_h.abs() * rcp_or_zero(den * den));
    let vis = visible_pdf(&mf, wo, h) * dwh;
    let mut pdf = refl_ok.select(p_r * vis + p_c * gtr1_d(a_cc, h) * h.z.max(zero) * dwh, zero);
    pdf += reflect.select(p_d * cosine_hemisphere_pdf_x8(wi, reflect), zero);
    pdf += refr_ok.select(p_t * vis, zero);
    let pdf = active.select(pdf, zero).min(F8::MAX);
    let f = Vec3x8::select(active, f, Vec3x8::ZERO);
    (Vec3x8::new(f.x.min(F8::MAX), f.y.min(F8::MAX), f.z.min(F8::MAX)), pdf)
}

impl Bsdf for Principled {
    const ID: u32 = 15;
    const NAME: &'static str = "principled";
    const FLAGS: u32 = flags::DIFFUSE_REFLECTION | flags::GLOSSY_REFLECTION | flags::GLOSSY_TRANSMISSION;
    /// Mitsuba's (Burley's) diffuse lobe is not energy conserving: its retro-reflection factor
    /// `(1 + (F_D90 - 1)(1 - cos)^5)` per side exceeds 1 for rough surfaces at grazing angles.
    /// Measured by `registry_tests::stiff_cases_gain_no_energy`: 1.143 for the rough
    /// test_texturedprincipled1 row at `wo.z` = 1e-7 (1.055 for the transmitting row), below 1
    /// at the views the other furnace test takes.
    const ALBEDO_BOUND: f32 = 1.2;

    #[inline]
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        eval_pdf(&Lanes::of(p), wo, wi, active)
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8) -> Sample8 {
        let zero = F8::ZERO;
        let l = Lanes::of(p);
        let (_, bsdf) = l.weights();
        let front = wo.z.simd_gt(zero);
        let active = active & wo.z.simd_ne(zero) & (front | bsdf.simd_gt(zero));
        let eta = l.q[ETA];
        let mf = ggx(l.q[ANISOTROPIC], l.q[ROUGHNESS]);
        let m = sample_visible(&mf, wo, u);
        let wo_m = wo.dot(m);
        let (fr, cos_t, eta_it, eta_ti) = dielectric_x8(wo_m, eta);
        let [p_d, p_c, p_t, _] = l.probabilities(front, fr);
        let is_d = u_lobe.simd_lt(p_d);
        let is_c = !is_d & u_lobe.simd_lt(p_d + p_c);
        let is_t = !is_d & !is_c & u_lobe.simd_lt(p_d + p_c + p_t);
        let is_r = !is_d & !is_c & !is_t;
        let wi_r = reflect(wo, m);
        let wi_t = (m.scale(eta_ti.mul_add(wo_m, cos_t)) - wo.scale(eta_ti)).normalize_or_zero();
        let m_c = gtr1_sample(l.clearcoat_alpha(), u);
        let wi_c = reflect(wo, m_c);
        let wi_d = sample_cosine_hemisphere_x8(u, active & is_d).0;
        let wi = Vec3x8::select(is_d, wi_d, Vec3x8::select(is_c, wi_c, Vec3x8::select(is_t, wi_t, wi_r)));
        let same = (wo.z * wi.z).simd_gt(zero);
        let across = (wo.z * wi.z).simd_lt(zero);
        let ok_r = is_r & same & sides_agree(m, wo, wi, true);
        let ok_t = is_t & across & sides_agree(m, wo, wi, false);
        let ok_c = is_c & same & sides_agree(m_c, wo, wi, true);
        let ok_d = is_d & same;
        let lobe_ok = active & (ok_r | ok_t | ok_c | ok_d);
        let (f, pdf) = eval_pdf(&l, wo, wi, lobe_ok);
        let ok = lobe_ok & pdf.simd_gt(zero);
        let weight = f.scale(ok.select(wi.z.abs() / ok.select(pdf, F8::ONE), zero));
        let glossy = ok & (is_r | is_c);
        Sample8 {
            wi: Vec3x8::select(ok, wi, Vec3x8::ZERO),
            weight: Vec3x8::select(ok, weight, Vec3x8::ZERO),
            pdf: ok.select(pdf, zero),
            flags: flags_where(ok & is_d, flags::DIFFUSE_REFLECTION)
                | flags_where(glossy, flags::GLOSSY_REFLECTION)
                | flags_where(ok & is_t, flags::GLOSSY_TRANSMISSION),
            eta: (ok & is_t).select(eta_it, F8::ONE),
        }
    }

    fn test_params() -> Vec<BsdfParams> {
        let row = |base: Vec3, v: &[(usize, f32)]| {
            let mut values = DEFAULTS.values;
            for &(j, x) in v {
                values[j] = x;
            }
            params(base, Entry { values, slots: [CONSTANT; N] })
        };
        vec![
            // Mitsuba's defaults.
            row(Vec3::splat(0.5), &[]),
            // bsdf_spheres/test_texturedprincipled1 (the checkerboards' lighter squares).
            row(
                Vec3::new(0.2, 0.8, 0.1),
                &[(ROUGHNESS, 0.15), (ANISOTROPIC, 0.8), (METALLIC, 0.1), (CLEARCOAT, 0.9), (SHEEN, 0.2), (ETA, eta_of_specular(0.7))],
            ),
            // test_texturedprincipled2: transmission.
            row(
                Vec3::new(0.3, 0.6, 0.8),
                &[(ROUGHNESS, 0.15), (ANISOTROPIC, 0.7), (SPEC_TRANS, 0.7), (CLEARCOAT, 0.6), (SHEEN, 0.9), (ETA, eta_of_specular(0.4))],
            ),
            // Everything at once, rough, tinted, flat.
            row(
                Vec3::new(0.8, 0.4, 0.2),
                &[
                    (ROUGHNESS, 0.9),
                    (ANISOTROPIC, 0.5),
                    (METALLIC, 0.3),
                    (SPEC_TRANS, 0.4),
                    (SPEC_TINT, 0.6),
                    (SHEEN, 0.5),
                    (SHEEN_TINT, 0.7),
                    (FLATNESS, 0.8),
                    (CLEARCOAT, 1.0),
                    (CLEARCOAT_GLOSS, 0.9),
                    (RATE_CLEARCOAT, 0.5),
                    (RATE_DIFFUSE, 2.0),
                ],
            ),
            // Stiff: a smooth metal, full anisotropy; nearly index-matched glass; a dense one.
            row(Vec3::new(0.9, 0.6, 0.3), &[(ROUGHNESS, 0.0), (ANISOTROPIC, 1.0), (METALLIC, 1.0)]),
            row(Vec3::ONE, &[(ROUGHNESS, 0.3), (SPEC_TRANS, 1.0), (ETA, 1.001)]),
            row(Vec3::splat(0.7), &[(ROUGHNESS, 1.0), (SPEC_TRANS, 0.5), (ETA, 4.0), (FLATNESS, 1.0)]),
            row(Vec3::ZERO, &[(ROUGHNESS, 0.05), (SPEC_TRANS, 0.9), (ETA, 1.0 / 1.5), (SPEC_TINT, 1.0)]),
        ]
    }
}

/// Mitsuba's eta of `specular`: 2 / (1 - sqrt(0.08 specular)) - 1.
pub fn eta_of_specular(specular: f32) -> f32 {
    2.0 / (1.0 - (0.08 * specular).sqrt()) - 1.0
}

/// A principled row: the base colour and the scalar parameters of [`PARAMS`] (constants, or the
/// scalar slots textures give).
pub fn params(base_color: Vec3, entry: Entry) -> BsdfParams {
    row(Principled::ID, base_color, entry)
}

#[cfg(test)]
#[path = "principled_tests.rs"]
mod tests;

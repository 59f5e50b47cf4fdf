//! `principledthin`: Mitsuba 3's thin principled BSDF (Burley 2015's thin-surface model, as
//! Mitsuba 3.9 writes it in `principledthin.cpp`): a two-sided sheet with no interior. Seen from
//! either side (both directions are mirrored through the origin when `wo.z < 0`, so the sheet is
//! symmetric), with h = normalize(wo + wi') (wi' = wi with |z|) and F_diel the dielectric
//! Fresnel term of `eta` at wo.h:
//! - glossy reflection: spec_trans (lerp(F_diel, Schlick(tint R0(eta), wo.h), spec_tint)) D G /
//!   (4 |wo.z wi.z|), GGX alphas from `roughness` and `anisotropic`;
//! - glossy transmission (straight through, no bending): spec_trans base (1 - F_diel) D' G' /
//!   (4 |wo.z wi.z|), D' and G' of the roughness scaled by 0.65 eta - 0.35 (Burley 2015, fig. 15),
//!   evaluated at wi' (the transmitted direction mirrored back);
//! - diffuse reflection: (1 - spec_trans)(1 - diff_trans / 2) base `diffuse_shape` plus
//!   sheen (1 - spec_trans)(1 - diff_trans / 2) `sheen_color`;
//! - diffuse transmission: (1 - spec_trans) diff_trans / 2 base / pi.
//!
//! `diff_trans` runs over [0, 2] as in Mitsuba (halved here). Sampling picks the four lobes with
//! Mitsuba's probabilities: spec_trans r_sr / 2, spec_trans r_st / 2, (1 - spec_trans)(1 -
//! diff_trans / 2) r_dr, (1 - spec_trans) diff_trans / 2 r_dt, normalized (the r are the
//! `*_sampling_rate`s); the glossy lobes draw visible normals from wo. eta is 1 along every
//! sample (a sheet does not refract).
//!
//! `diffuse_shape`, `sheen_color` and the parameter table are in `bsdf::microfacet::principled`.
//!
//! Slots: `color[0]` base_color, `color[1].x` the table entry;
//! the entry's parameters in the order of [`PARAMS`].

use super::fresnel::dielectric_x8;
use super::interface::{flags, flags_where, Bsdf, BsdfParams, Params8, Sample8};
use super::microfacet::principled::{
    diffuse_shape, gather, ggx, inv_areas, lerp, negate_where, r0_of_eta, rcp_or_zero, reflect, row, sample_visible,
    schlick3, schlick_cos_weight, sheen_color, sides_agree, tint, visible_pdf, defaults_entry, Entry, CONSTANT, N,
};
use crate::sampling::{cosine_hemisphere_pdf_x8, sample_cosine_hemisphere_x8};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// Mitsuba's scalar parameters (name, default, texture allowed) in table order: the entry's
/// `values[j]` is `PARAMS[j]` (the unused tail stays at 0).
pub const PARAMS: [(&str, f32, bool); 13] = [
    ("roughness", 0.5, true),
    ("anisotropic", 0.0, true),
    ("spec_trans", 0.0, true),
    ("eta", 1.5, true),
    ("spec_tint", 0.0, true),
    ("sheen", 0.0, true),
    ("sheen_tint", 0.0, true),
    ("flatness", 0.0, true),
    ("diff_trans", 0.0, true),
    ("specular_reflectance_sampling_rate", 1.0, false),
    ("specular_transmittance_sampling_rate", 1.0, false),
    ("diffuse_transmittance_sampling_rate", 1.0, false),
    ("diffuse_reflectance_sampling_rate", 1.0, false),
];

const ROUGHNESS: usize = 0;
const ANISOTROPIC: usize = 1;
const SPEC_TRANS: usize = 2;
const ETA: usize = 3;
const SPEC_TINT: usize = 4;
const SHEEN: usize = 5;
const SHEEN_TINT: usize = 6;
const FLATNESS: usize = 7;
const DIFF_TRANS: usize = 8;
const RATE_SPEC_REFLECT: usize = 9;
const RATE_SPEC_TRANS: usize = 10;
const RATE_DIFF_TRANS: usize = 11;
const RATE_DIFF_REFLECT: usize = 12;

/// The defaults, for lanes whose entry is missing.
const DEFAULTS: Entry = defaults_entry(&PARAMS);

/// The thin principled BSDF (see the module docs).
pub struct PrincipledThin;

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
    /// diff_trans on Mitsuba's [0, 1] scale.
    #[inline]
    fn diff_trans(&self) -> F8 {
        self.q[DIFF_TRANS] * F8::splat(0.5)
    }
    /// Normalized lobe probabilities (glossy reflection, glossy transmission, diffuse reflection,
    /// diffuse transmission); all 0 where they sum to 0.
    #[inline]
    fn probabilities(&self) -> [F8; 4] {
        let (one, half) = (F8::ONE, F8::splat(0.5));
        let (st, dt) = (self.q[SPEC_TRANS], self.diff_trans());
        let sr = st * self.q[RATE_SPEC_REFLECT] * half;
        let stt = st * self.q[RATE_SPEC_TRANS] * half;
        let dr = self.q[RATE_DIFF_REFLECT] * (one - st) * (one - dt);
        let dtt = self.q[RATE_DIFF_TRANS] * (one - st) * dt;
        let k = rcp_or_zero(sr + stt + dr + dtt);
        [sr * k, stt * k, dr * k, dtt * k]
    }
    /// The transmission lobe's distribution: roughness scaled by 0.65 eta - 0.35.
    #[inline]
    fn transmission_ggx(&self) -> super::microfacet::Microfacet<F8> {
        let scaled = F8::splat(0.65).mul_add(self.q[ETA], F8::splat(-0.35)) * self.q[ROUGHNESS];
        ggx(self.q[ANISOTROPIC], scaled)
    }
}

/// (f, pdf) at (wo, wi) on `active` lanes (see the module docs).
#[inline]
fn eval_pdf(l: &Lanes, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
    let (zero, one) = (F8::ZERO, F8::ONE);
    let q = &l.q;
    let active = active & wo.z.simd_ne(zero);
    // The sheet is symmetric: both directions through the origin when wo is below.
    let back = wo.z.simd_lt(zero);
    let (wo, wi) = (negate_where(back, wo), negate_where(back, wi));
    let reflect = wi.z.simd_gt(zero);
    let refract = wi.z.simd_lt(zero);
    let wi_r = Vec3x8::new(wi.x, wi.y, wi.z.abs());
    let h = (wo + wi_r).normalize_or_zero();
    let (wo_h, wi_h) = (wo.dot(h), wi_r.dot(h));
    let c_f = F8::splat(0.5) * (wo_h + wi_h);
    let (st, dt) = (q[SPEC_TRANS], l.diff_trans());
    let refl_ok = reflect & sides_agree(h, wo, wi, true);
    let refr_ok = refract & sides_agree(h, wo, wi, false);
    let eta = q[ETA];
    let fr = dielectric_x8(c_f, eta).0;
    let mf = ggx(q[ANISOTROPIC], q[ROUGHNESS]);
    let mft = l.transmission_ggx();
    let (d, dt_d) = (mf.d(h.into()), mft.d(h.into()));

    // Glossy reflection.
    let spec_tint = q[SPEC_TINT];
    let f_schlick = schlick3(tint(l.base).scale(r0_of_eta(eta)), schlick_cos_weight(c_f, eta));
    let f_thin = Vec3x8::new(
        lerp(fr, f_schlick.x, spec_tint),
        lerp(fr, f_schlick.y, spec_tint),
        lerp(fr, f_schlick.z, spec_tint),
    );
    let spec_on = active & st.simd_gt(zero) & refl_ok;
    let g = inv_areas(&mf, wo, wi);
    let mut f = Vec3x8::select(spec_on, f_thin.scale(st * d * g * F8::splat(0.25)), Vec3x8::ZERO);

    // Glossy transmission.
    let trans_on = active & st.simd_gt(zero) & refr_ok;
    let gt = inv_areas(&mft, wo, wi);
    f += Vec3x8::select(trans_on, l.base.scale(st * (one - fr) * dt_d * gt * F8::splat(0.25)), Vec3x8::ZERO);

    // Diffuse reflection and sheen.
    let diff_on = active & reflect & st.simd_lt(one) & dt.simd_lt(one);
    let w = (one - st) * (one - dt);
    let shape = diffuse_shape(q[ROUGHNESS], q[FLATNESS], wo.z, wi.z.abs(), c_f);
    f += Vec3x8::select(diff_on, l.base.scale(w * shape), Vec3x8::ZERO);
    let sheen = q[SHEEN];
    let sheen_on = diff_on & sheen.simd_gt(zero);
    f += Vec3x8::select(sheen_on, sheen_color(l.base, q[SHEEN_TINT], c_f).scale(sheen * w), Vec3x8::ZERO);

    // Diffuse transmission.
    let dtrans_on = active & refract & st.simd_lt(one) & dt.simd_gt(zero);
    f += Vec3x8::select(dtrans_on, l.base.scale((one - st) * dt * F8::FRAC_1_PI), Vec3x8::ZERO);

    // The pdf.
    let [p_sr, p_st, p_dr, p_dt] = l.probabilities();
    let dwh = rcp_or_zero(F8::splat(4.0) * wi_h.abs());
    let mut pdf = refl_ok.select(p_sr * visible_pdf(&mf, wo, h) * dwh, zero);
    pdf += refr_ok.select(p_st * visible_pdf(&mft, wo, h) * dwh, zero);
    pdf += p_dr * cosine_hemisphere_pdf_x8(wi, reflect);
    pdf += p_dt * cosine_hemisphere_pdf_x8(-wi, refract);
    let pdf = active.select(pdf, zero).min(F8::MAX);
    let f = Vec3x8::select(active, f, Vec3x8::ZERO);
    (Vec3x8::new(f.x.min(F8::MAX), f.y.min(F8::MAX), f.z.min(F8::MAX)), pdf)
}

impl Bsdf for PrincipledThin {
    const ID: u32 = 16;
    const NAME: &'static str = "principledthin";
    const FLAGS: u32 = flags::DIFFUSE_REFLECTION
        | flags::GLOSSY_REFLECTION
        | flags::GLOSSY_TRANSMISSION
        | flags::DIFFUSE
        | flags::TRANSMISSION;

    #[inline]
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        eval_pdf(&Lanes::of(p), wo, wi, active)
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8) -> Sample8 {
        let zero = F8::ZERO;
        let l = Lanes::of(p);
        let active = active & wo.z.simd_ne(zero);
        let back = wo.z.simd_lt(zero);
        let wo_f = negate_where(back, wo);
        let [p_sr, p_st, p_dr, _] = l.probabilities();
        let is_sr = u_lobe.simd_lt(p_sr);
        let is_st = !is_sr & u_lobe.simd_lt(p_sr + p_st);
        let is_dr = !is_sr & !is_st & u_lobe.simd_lt(p_sr + p_st + p_dr);
        let is_dt = !is_sr & !is_st & !is_dr;
        let mf = ggx(l.q[ANISOTROPIC], l.q[ROUGHNESS]);
        let m_r = sample_visible(&mf, wo_f, u);
        let m_t = sample_visible(&l.transmission_ggx(), wo_f, u);
        let wi_r = reflect(wo_f, m_r);
        let wt = reflect(wo_f, m_t);
        let wi_t = Vec3x8::new(wt.x, wt.y, -wt.z);
        let wi_d = sample_cosine_hemisphere_x8(u, active & (is_dr | is_dt)).0;
        let wi_f = Vec3x8::select(
            is_sr,
            wi_r,
            Vec3x8::select(is_st, wi_t, Vec3x8::select(is_dr, wi_d, -wi_d)),
        );
        let ok_r = is_sr & wi_r.z.simd_gt(zero) & sides_agree(m_r, wo_f, wi_r, true);
        let ok_t = is_st & wi_t.z.simd_lt(zero) & sides_agree(m_t, wo_f, wi_t, false);
        let lobe_ok = active & (ok_r | ok_t | is_dr | is_dt);
        let wi = negate_where(back, wi_f);
        let (f, pdf) = eval_pdf(&l, wo, wi, lobe_ok);
        let ok = lobe_ok & pdf.simd_gt(zero);
        let weight = f.scale(ok.select(wi.z.abs() / ok.select(pdf, F8::ONE), zero));
        Sample8 {
            wi: Vec3x8::select(ok, wi, Vec3x8::ZERO),
            weight: Vec3x8::select(ok, weight, Vec3x8::ZERO),
            pdf: ok.select(pdf, zero),
            flags: flags_where(ok & is_sr, flags::GLOSSY_REFLECTION)
                | flags_where(ok & is_st, flags::GLOSSY_TRANSMISSION)
                | flags_where(ok & is_dr, flags::DIFFUSE_REFLECTION)
                | flags_where(ok & is_dt, flags::DIFFUSE | flags::TRANSMISSION),
            eta: F8::ONE,
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
            // bsdf_spheres/test_texturedprincipledthin (the checkerboards' lighter squares).
            row(
                Vec3::new(0.7, 0.1, 0.1),
                &[(ANISOTROPIC, 0.8), (SPEC_TRANS, 0.8), (DIFF_TRANS, 1.4), (SHEEN, 0.8), (ETA, 1.33)],
            ),
            // Everything at once, tinted and flat, uneven sampling rates.
            row(
                Vec3::new(0.8, 0.5, 0.3),
                &[
                    (ROUGHNESS, 0.8),
                    (ANISOTROPIC, 0.4),
                    (SPEC_TRANS, 0.3),
                    (SPEC_TINT, 0.7),
                    (SHEEN, 0.4),
                    (SHEEN_TINT, 0.5),
                    (FLATNESS, 0.6),
                    (DIFF_TRANS, 0.6),
                    (RATE_SPEC_TRANS, 2.0),
                    (RATE_DIFF_TRANS, 0.5),
                ],
            ),
            // Stiff: smooth, fully anisotropic, all glossy; a dense rough sheet; all diffuse
            // transmission.
            row(Vec3::ONE, &[(ROUGHNESS, 0.0), (ANISOTROPIC, 1.0), (SPEC_TRANS, 1.0), (ETA, 1.0001)]),
            row(Vec3::splat(0.6), &[(ROUGHNESS, 1.0), (SPEC_TRANS, 0.5), (ETA, 4.0), (FLATNESS, 1.0)]),
            row(Vec3::splat(0.9), &[(DIFF_TRANS, 2.0)]),
        ]
    }
}

/// A thin principled row: the base colour and the scalar parameters of [`PARAMS`] (constants,
/// or the scalar slots textures give).
pub fn params(base_color: Vec3, entry: Entry) -> BsdfParams {
    row(PrincipledThin::ID, base_color, entry)
}

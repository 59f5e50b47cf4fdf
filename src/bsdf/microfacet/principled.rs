//! What Mitsuba 3's two principled BSDFs share (`bsdf::principled`, `bsdf::principledthin`; the
//! model of Mitsuba's `principledhelpers.h`, after Burley's "Physically Based Shading at Disney"
//! 2012 and "Extending the Disney BRDF to a BSDF with Integrated Subsurface Scattering" 2015):
//! the roughness-to-alphas map, Schlick's Fresnel weights as Mitsuba blends them, the micro/macro
//! side checks, the Disney diffuse shape (retro-reflection, fake subsurface) and sheen, and the
//! parameter table.
//!
//! **Parameters.** A principled row has one colour (`base_color`, `color[0]`, which a texture may
//! give per hit) and up to 14 scalars, more than a row's four scalar slots. The scalars live in a
//! process-wide table of [`Entry`]s (each row's index in `color[1].x`, as `roughplastic` keeps its
//! tables): per parameter a constant, or the scalar slot a texture writes per hit. So up to four
//! parameters of a row are textured (Mitsuba's `eval_1` of the texture: `scene/texturing.rs`),
//! the rest constant; [`gather`] reads the lanes' values.

use super::{Microfacet, V3};
use crate::bsdf::interface::{BsdfParams, Params8, COLORS, SCALARS};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;
use std::sync::RwLock;

/// Scalar parameters an [`Entry`] holds.
pub const N: usize = 14;

/// The entry of a BSDF's constant defaults: `values[j]` is `params[j]`'s default (the tail past
/// `params` stays 0), every parameter a constant. For lanes whose entry is missing.
pub const fn defaults_entry(params: &[(&str, f32, bool)]) -> Entry {
    let mut values = [0.0; N];
    let mut j = 0;
    while j < params.len() {
        values[j] = params[j].1;
        j += 1;
    }
    Entry { values, slots: [CONSTANT; N] }
}
/// [`Entry::slots`] of a constant parameter.
pub const CONSTANT: u8 = u8::MAX;

/// One row's scalar parameters: constants, or (where `slots[j]` < 4) the row's scalar slot a
/// texture writes per hit (the row keeps the texture's mean there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    /// the parameters (for a textured one: its mean, not read at hits)
    pub values: [f32; N],
    /// per parameter: [`CONSTANT`], or the scalar slot its texture gives
    pub slots: [u8; N],
}

/// The process-wide table ([`row`] adds, [`gather`] reads).
static ENTRIES: RwLock<Vec<Entry>> = RwLock::new(Vec::new());

/// The row of BSDF `kind` for `base_color` and `entry` (interned in the table; a textured
/// parameter's slot starts at its mean).
pub fn row(kind: u32, base_color: Vec3, entry: Entry) -> BsdfParams {
    let id = {
        let mut list = ENTRIES.write().unwrap_or_else(|e| e.into_inner());
        list.iter()
            .position(|e| e.values.map(f32::to_bits) == entry.values.map(f32::to_bits) && e.slots == entry.slots)
            .unwrap_or_else(|| {
                list.push(entry);
                list.len() - 1
            })
    };
    let mut scalar = [0.0; SCALARS];
    for (j, &s) in entry.slots.iter().enumerate() {
        if (s as usize) < SCALARS {
            scalar[s as usize] = entry.values[j];
        }
    }
    let mut color = [Vec3::ZERO; COLORS];
    color[0] = base_color;
    color[1].x = id as f32;
    BsdfParams::new(kind, color, scalar)
}

/// The lanes' parameters (a lane whose id is not in the table reads `fallback`, so inactive
/// lanes of other kinds stay finite).
pub(crate) fn gather(p: &Params8, fallback: &Entry) -> [F8; N] {
    let ids = p.color[1].x.to_array();
    let slots = p.scalar.map(|s| s.to_array());
    let list = ENTRIES.read().unwrap_or_else(|e| e.into_inner());
    let mut out = [[0.0f32; 8]; N];
    for (lane, &id) in ids.iter().enumerate() {
        // NaN and negative ids saturate to 0: any entry keeps the lane finite.
        let e = list.get(id as usize).unwrap_or(fallback);
        for (j, o) in out.iter_mut().enumerate() {
            let s = e.slots[j] as usize;
            o[lane] = if s < SCALARS { slots[s][lane] } else { e.values[j] };
        }
    }
    out.map(F8::new)
}

/// Mitsuba's luminance of linear sRGB.
#[inline]
pub(crate) fn luminance(c: Vec3x8) -> F8 {
    c.x * F8::splat(0.212_671) + c.y * F8::splat(0.715_160) + c.z * F8::splat(0.072_169)
}

/// The base colour normalized by its luminance (1 for a black one): the tint.
#[inline]
pub(crate) fn tint(base: Vec3x8) -> Vec3x8 {
    let lum = luminance(base);
    let pos = lum.simd_gt(F8::ZERO);
    let inv = pos.select(F8::ONE / pos.select(lum, F8::ONE), F8::ZERO);
    Vec3x8::select(pos, base.scale(inv), Vec3x8::splat(Vec3::ONE))
}

/// a + t (b - a) as Dr.Jit's `lerp` rounds it: b t + (a - a t).
#[inline]
pub(crate) fn lerp(a: F8, b: F8, t: F8) -> F8 {
    b.mul_add(t, a - a * t)
}

/// Schlick's weight (1 - c)^5, c clamped to [0, 1].
#[inline]
pub(crate) fn schlick_weight(c: F8) -> F8 {
    let m = (F8::ONE - c).max(F8::ZERO).min(F8::ONE);
    let m2 = m * m;
    m2 * m2 * m
}

/// The Schlick weight Mitsuba's `calc_schlick` uses at the microfacet cosine `cos_i` and relative
/// index `eta`: at |cos_i| where the light comes from the less dense side, else at the
/// refracted cosine (1 under total internal reflection).
#[inline]
pub(crate) fn schlick_cos_weight(cos_i: F8, eta: F8) -> F8 {
    let outside = cos_i.simd_ge(F8::ZERO);
    let inv = F8::ONE / eta;
    let (eta_it, eta_ti) = (outside.select(eta, inv), outside.select(inv, eta));
    let sin2 = F8::ONE - cos_i * cos_i;
    let cos_t = (F8::ONE - sin2 * (eta_ti * eta_ti)).max(F8::ZERO).sqrt();
    eta_it.simd_gt(F8::ONE).select(schlick_weight(cos_i.abs()), schlick_weight(cos_t))
}

/// Schlick's F = r0 + (1 - r0) w for the weight `w` of [`schlick_cos_weight`].
#[inline]
pub(crate) fn schlick(r0: F8, w: F8) -> F8 {
    lerp(w, F8::ONE, r0)
}

/// [`schlick`] per colour channel.
#[inline]
pub(crate) fn schlick3(r0: Vec3x8, w: F8) -> Vec3x8 {
    Vec3x8::new(schlick(r0.x, w), schlick(r0.y, w), schlick(r0.z, w))
}

/// The normal-incidence reflectance of a dielectric of relative index `eta`.
#[inline]
pub(crate) fn r0_of_eta(eta: F8) -> F8 {
    let r = (eta - F8::ONE) / (eta + F8::ONE);
    r * r
}

/// GGX alphas (x, y) of Mitsuba's principled: roughness^2 stretched by the aspect
/// sqrt(1 - 0.9 anisotropic), at least 0.001. (An anisotropy above 1/0.9, outside Mitsuba's range,
/// is taken as 1/0.9 - 1e-4/0.9 so the alphas stay finite.)
#[inline]
pub(crate) fn alphas(anisotropic: F8, roughness: F8) -> (F8, F8) {
    let r2 = roughness * roughness;
    let aspect = (F8::ONE - F8::splat(0.9) * anisotropic).max(F8::splat(1e-4)).sqrt();
    let lo = F8::splat(0.001);
    ((r2 / aspect).max(lo), (r2 * aspect).max(lo))
}

/// The GGX distribution (visible normals) of [`alphas`].
#[inline]
pub(crate) fn ggx(anisotropic: F8, roughness: F8) -> Microfacet<F8> {
    let (ax, ay) = alphas(anisotropic, roughness);
    Microfacet::new(super::Distribution::Ggx, ax, ay, true)
}

/// Mitsuba's `mac_mic_compatibility`: with m turned to the side of `wo` (by the sign of
/// `wo.z`), `wo` sees it from the front, and `wi` too (reflection) or from the back
/// (transmission).
#[inline]
pub(crate) fn sides_agree(m: Vec3x8, wo: Vec3x8, wi: Vec3x8, reflection: bool) -> Mask8 {
    let up = wo.z.simd_ge(F8::ZERO);
    let ms = Vec3x8::select(up, m, -m);
    let (a, b) = (wo.dot(ms), wi.dot(ms));
    a.simd_gt(F8::ZERO) & if reflection { b.simd_gt(F8::ZERO) } else { b.simd_lt(F8::ZERO) }
}

/// The Disney diffuse shape at cosines `ci`, `co` (absolute) and `cos_d` (the half vector with
/// the light): Lambert's 1/pi times lerp(f_diff + f_retro, f_ss, flatness), Burley 2015's
/// retro-reflection and Hanrahan-Krueger fake subsurface, as Mitsuba writes them.
#[inline]
pub(crate) fn diffuse_shape(roughness: F8, flatness: F8, ci: F8, co: F8, cos_d: F8) -> F8 {
    let half = F8::splat(0.5);
    let (fo, fi) = (schlick_weight(co), schlick_weight(ci));
    let f_diff = (F8::ONE - half * fi) * (F8::ONE - half * fo);
    let rr = F8::splat(2.0) * roughness * (cos_d * cos_d);
    let f_retro = rr * (fo + fi + fo * fi * (rr - F8::ONE));
    let fss90 = rr * half;
    let fss = lerp(F8::ONE, fss90, fo) * lerp(F8::ONE, fss90, fi);
    let f_ss = F8::splat(1.25) * (fss * (F8::ONE / (co + ci) - half) + half);
    lerp(f_diff + f_retro, f_ss, flatness) * F8::FRAC_1_PI
}

/// The sheen colour: Schlick's weight at `cos_d` times lerp(1, tint, sheen_tint) (without the
/// sheen amount).
#[inline]
pub(crate) fn sheen_color(base: Vec3x8, sheen_tint: F8, cos_d: F8) -> Vec3x8 {
    let fd = schlick_weight(cos_d.abs());
    let c = tint(base);
    let one = F8::ONE;
    Vec3x8::new(lerp(one, c.x, sheen_tint), lerp(one, c.y, sheen_tint), lerp(one, c.z, sheen_tint)).scale(fd)
}

/// 1 / (A(wo) A(wi)) of `mf`: G(wo, wi) / |wo.z wi.z| where both see m from their own side
/// (the callers check the sides), never dividing by a grazing cosine.
#[inline]
pub(crate) fn inv_areas(mf: &Microfacet<F8>, wo: Vec3x8, wi: Vec3x8) -> F8 {
    let a = mf.projected_area(V3::from(wo)) * mf.projected_area(V3::from(wi));
    a.simd_gt(F8::ZERO).select(F8::ONE / a.max(F8::splat(f32::MIN_POSITIVE)), F8::ZERO)
}

/// `v` reflected about the unit `m`: 2 (v.m) m - v, renormalized.
#[inline]
pub(crate) fn reflect(v: Vec3x8, m: Vec3x8) -> Vec3x8 {
    (m.scale(F8::splat(2.0) * v.dot(m)) - v).normalize_or_zero()
}

/// The normal-space density `d` of the visible normals of `mf` seen from `w` at `m`.
#[inline]
pub(crate) fn visible_pdf(mf: &Microfacet<F8>, w: Vec3x8, m: Vec3x8) -> F8 {
    mf.pdf(V3::from(w), V3::from(m))
}

/// A visible normal of `mf` seen from `w` (either side) for `u`.
#[inline]
pub(crate) fn sample_visible(mf: &Microfacet<F8>, w: Vec3x8, u: [F8; 2]) -> Vec3x8 {
    Vec3x8::from(mf.sample(V3::from(w), u).0)
}

/// 1 / x where x > 0, else 0.
#[inline]
pub(crate) fn rcp_or_zero(x: F8) -> F8 {
    let pos = x.simd_gt(F8::ZERO);
    pos.select(F8::ONE / pos.select(x, F8::ONE), F8::ZERO)
}

/// `v` with every component negated on `m` lanes (Mitsuba's `mulsign` by a negative sign).
#[inline]
pub(crate) fn negate_where(m: Mask8, v: Vec3x8) -> Vec3x8 {
    Vec3x8::select(m, -v, v)
}

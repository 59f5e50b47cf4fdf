//! `mask`: Mitsuba's opacity mask around any BSDF. With probability `opacity` (a row's
//! [`BsdfParams::opacity`], a float or a texture per hit) a hit scatters by the nested BSDF;
//! otherwise the ray passes the surface unchanged: the null lobe ([`flags::NULL`], sampled with
//! `DELTA | TRANSMISSION`), `wi = -wo`, weight 1, pdf `1 - opacity`.
//!
//! As Mitsuba 3's `mask.cpp` (read, not copied):
//! - `eval_pdf` is the nested BSDF's (f, pdf) times the opacity: next event estimation at the
//!   vertex sees `opacity f` and weighs its MIS against `opacity pdf`;
//! - `sample` draws the nested BSDF when `u_lobe < opacity` (then `u_lobe / opacity` picks the
//!   nested lobe) and returns the nested sample's direction and weight (the opacity cancels)
//!   with the masked pdf, opacity times the nested one (Mitsuba 3.9.1's `sample` returns that
//!   pdf, queried from the peer; it is the pdf the MIS weight of the emitter the direction finds
//!   needs, since next events weigh against `eval_pdf`'s: with the nested pdf unscaled the two
//!   weights sum to more than 1);
//! - the null sample is a path vertex: Mitsuba's path tracer counts it towards `max_depth`
//!   (`depth` grows at every valid hit), and its MIS weight at the next emitter is 1 (Null is
//!   part of Mitsuba's Delta); shadow rays are blocked by masked surfaces (the path tracer's
//!   visibility test sees every surface).
//!
//! The mask is a modifier of a row, not a kind of its own: a masked row keeps its nested kind
//! (course or registry) and [`super::Material8`] applies [`eval_pdf_x8`] and [`sample_x8`] to
//! lanes whose opacity is below 1, compiled in only for kernels whose set includes [`Mask`]
//! (a scene's materials include it when one of them is masked, see [`masked`]). A row of the
//! kind [`Mask`] itself is a mask of opacity 0 (Mitsuba's `null` BSDF): the registry's generic
//! tests cover it; `mask_tests.rs` covers masks around the other entries.

use super::interface::{flags, Bsdf, BsdfParams, Params8, Sample8};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// The null surface (a mask of opacity 0), and the registry entry that compiles masks in.
pub struct Mask;

impl Bsdf for Mask {
    const ID: u32 = 13;
    const NAME: &'static str = "mask";
    const FLAGS: u32 = flags::NULL_TRANSMISSION;

    #[inline]
    fn eval_pdf(_: &Params8, _: Vec3x8, _: Vec3x8, _: Mask8) -> (Vec3x8, F8) {
        (Vec3x8::ZERO, F8::ZERO)
    }

    #[inline]
    fn sample(_: &Params8, wo: Vec3x8, _: F8, _: [F8; 2], active: Mask8) -> Sample8 {
        Sample8::select(active, null_sample(wo, F8::ONE), Sample8::NONE)
    }

    fn test_params() -> Vec<BsdfParams> {
        vec![BsdfParams { opacity: 0.0, ..BsdfParams::new(Self::ID, [Vec3::ZERO; 3], [0.0; 4]) }]
    }
}

/// Whether a row is masked (opacity below 1: its kernel must compile [`Mask`] in).
pub fn masked(p: &BsdfParams) -> bool {
    p.opacity < 1.0 || p.kind == Mask::ID
}

/// The null sample of pdf `pdf` in every lane: `wi = -wo`, weight 1, eta 1.
#[inline]
pub fn null_sample(wo: Vec3x8, pdf: F8) -> Sample8 {
    Sample8 { wi: -wo, weight: Vec3x8::splat(Vec3::ONE), pdf, flags: crate::simd::U8::splat(flags::NULL_TRANSMISSION), eta: F8::ONE }
}

/// The masked (f, pdf) of the nested `(f, pdf)` on the lanes `masked` (opacity below 1).
#[inline]
pub fn eval_pdf_x8(opacity: F8, masked: Mask8, (f, pdf): (Vec3x8, F8)) -> (Vec3x8, F8) {
    let o = masked.select(opacity, F8::ONE);
    (f.scale(o), pdf * o)
}

/// The lobe choice of a masked sample: `(nested, u_lobe')`, the lanes of `masked` that sample the
/// nested BSDF (`u_lobe < opacity`; every unmasked lane too) and `u_lobe / opacity` there (`u_lobe`
/// elsewhere) for the nested BSDF's own lobe choice.
#[inline]
pub fn choose_x8(opacity: F8, masked: Mask8, u_lobe: F8) -> (Mask8, F8) {
    let nested = !masked | u_lobe.simd_lt(opacity);
    let remapped = (masked & nested).select((u_lobe / opacity).min(F8::splat(ONE_MINUS)), u_lobe);
    (nested, remapped)
}

/// The null sample on the `null` lanes (see [`choose_x8`]: masked lanes that did not pick the
/// nested BSDF), the nested sample `s` elsewhere.
#[inline]
pub fn sample_x8(opacity: F8, null: Mask8, wo: Vec3x8, s: Sample8) -> Sample8 {
    Sample8::select(null, null_sample(wo, F8::ONE - opacity), s)
}

/// Largest f32 below 1.
const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

#[cfg(test)]
#[path = "mask_tests.rs"]
mod tests;

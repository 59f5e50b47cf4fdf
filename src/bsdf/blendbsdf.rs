//! `blendbsdf`: Mitsuba's blend of any two BSDFs, `(1 - w) f0 + w f1` with the pdf blended
//! alike, `w` the `weight` (a float or a texture per hit, clamped to [0, 1] as Mitsuba's
//! `eval_weight`). As Mitsuba 3's `blendbsdf.cpp` (read, not copied):
//! - `eval_pdf` blends the nested BSDFs' (f, pdf);
//! - `sample` picks the nested BSDF by `u_lobe` (the second when `u_lobe < w`, the first
//!   otherwise) and re-scales `u_lobe` to [0, 1) within the choice for the nested BSDF's own lobe
//!   choice. A delta (or null) sample keeps the nested weight, its pdf times the choice's
//!   probability. A smooth sample returns the blend's `f |cos| / pdf` with the blend's pdf at the
//!   direction. Mitsuba returns the nested BSDF's own pdf and weight: the same expectation for
//!   the BSDF sample alone, but its path tracer then weighs a BSDF-sampled light hit by the
//!   nested pdf and the next event by the blended one, so its MIS weights do not sum to one where
//!   the nested pdfs differ (measured: a blend of a rough conductor and a rough dielectric under
//!   an area light and a constant environment renders about 2 % brighter in Mitsuba than the
//!   same blend by strata's consistent estimator). With the blend's pdf the interface's rule
//!   `weight = f |cos| / pdf` and MIS stay exact.
//!
//! The nested rows (a process-wide list of pairs, one entry per distinct pair, as roughplastic's
//! tables: the row keeps the pair's index, so a blend costs nothing in the row layout of scenes
//! without blends; [`params`], [`nested`]) are any
//! registry rows (a nested `blendbsdf` included), with their own sides (`twosided` mirrors the
//! back, [`BsdfParams::twosided`]) and opacity (a nested `mask`, `bsdf::mask`), or a Lambertian
//! ([`lambert`]: Mitsuba's `diffuse`, a row of the course's kind with the reflectance in
//! `color[0]`). Lanes of different nested kinds are shaded together: each nested side is one
//! packet of rows, dispatched over the registry ([`super::AllBsdfs`]) like any packet, so only
//! kernels whose scene has a blend compile this code.
//!
//! Slots: `scalar[0]` the weight, `scalar[1]` the index of the nested pair.

use super::interface::{flags, flags_where, flip_z, Bsdf, BsdfParams, BsdfSet, Params8, Sample8, COURSE};
use super::{diffuse, mask, AllBsdfs};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;
use std::sync::RwLock;

/// The blend of two BSDFs (see the module docs).
pub struct BlendBsdf;

/// Largest f32 below 1.
const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

impl Bsdf for BlendBsdf {
    const ID: u32 = 14;
    const NAME: &'static str = "blendbsdf";
    /// Whatever the nested rows have: every lobe kind (see [`row_flags`] for one row's).
    const FLAGS: u32 =
        flags::REFLECTION | flags::TRANSMISSION | flags::DIFFUSE | flags::GLOSSY | flags::DELTA | flags::NULL;

    #[inline(never)]
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        let w = weight(p);
        let (f0, p0) = eval_side(&side(p, active, |_| false), wo, wi, active);
        let (f1, p1) = eval_side(&side(p, active, |_| true), wo, wi, active);
        let f = f0.scale(F8::ONE - w) + f1.scale(w);
        let pdf = (F8::ONE - w).mul_add(p0, w * p1);
        (Vec3x8::select(active, f, Vec3x8::ZERO), active.select(pdf, F8::ZERO))
    }

    #[inline(never)]
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8) -> Sample8 {
        let w = weight(p);
        let second = active & u_lobe.simd_lt(w);
        let ul = second.select(u_lobe / w, (u_lobe - w) / (F8::ONE - w)).max(F8::ZERO).min(F8::splat(ONE_MINUS));
        let picked = second.to_bitmask();
        let s = sample_side(&side(p, active, |i| picked & (1 << i) != 0), wo, ul, u, active);
        let prob = second.select(w, F8::ONE - w);
        // Delta and null samples: the nested weight, the lobe's probability in the blend.
        let delta = active & s.has(flags::DELTA);
        // Smooth samples: the blend's f and pdf at the direction.
        let smooth = active & !delta & s.pdf.simd_gt(F8::ZERO);
        let (f, pdf) = if smooth.any() { Self::eval_pdf(p, wo, s.wi, smooth) } else { (Vec3x8::ZERO, F8::ZERO) };
        let ok = smooth & pdf.simd_gt(F8::ZERO);
        let weight = f.scale(ok.select(s.wi.z.abs() / ok.select(pdf, F8::ONE), F8::ZERO));
        let blended = Sample8 { wi: s.wi, weight, pdf, flags: s.flags, eta: s.eta };
        let d = Sample8 { pdf: s.pdf * prob, ..s };
        Sample8::select(delta, d, Sample8::select(ok, blended, Sample8::NONE))
    }

    fn test_params() -> Vec<BsdfParams> {
        use super::microfacet::Distribution::{Beckmann, Ggx};
        let gold = (Vec3::new(0.143, 0.374, 1.442), Vec3::new(3.983, 2.385, 1.603));
        let rough_metal = super::roughconductor::params(Ggx, 0.3, 0.3, true, gold.0, gold.1, Vec3::ONE);
        let rough_glass = super::roughdielectric::params(Beckmann, 0.2, 0.2, true, 1.5, Vec3::ONE, Vec3::ONE);
        let plastic = super::plastic::params(Vec3::new(0.1, 0.3, 0.5), Vec3::ONE, 1.49, false);
        let glass = super::dielectric::params(1.5, Vec3::ONE, Vec3::ONE);
        let mirror = super::conductor::params(Vec3::ZERO, Vec3::ZERO, Vec3::ONE);
        let coat = BsdfParams {
            twosided: true,
            ..super::roughplastic::params(Ggx, 0.1, true, 1.5, Vec3::new(0.5, 0.2, 0.1), Vec3::ONE, true)
        };
        let thin = super::thindielectric::params(1.33, Vec3::ONE, Vec3::ONE);
        let masked = BsdfParams { opacity: 0.5, ..super::roughconductor::params(Ggx, 0.05, 0.4, true, gold.0, gold.1, Vec3::ONE) };
        let (r0, r1) = (lambert(Vec3::new(0.0, 0.5, 0.5)), lambert(Vec3::new(1.0, 1.0, 0.0)));
        vec![
            params(rough_metal, rough_glass, 0.4),
            params(plastic, r0, 0.7),
            params(glass, mirror, 0.5),
            params(coat, thin, 0.3),
            params(params(rough_metal, r1, 0.5), masked, 0.6),
            params(r0, r1, 0.3),
            params(rough_glass, r1, 0.0),
            params(rough_metal, rough_glass, 1.0),
            params(BsdfParams { twosided: true, ..r0 }, plastic, 7.0),
        ]
    }
}

/// A blend row: `(1 - weight)` of `first` plus `weight` of `second` (any rows: registry BSDFs
/// with their sides and opacity, [`lambert`] rows, blends).
pub fn params(first: BsdfParams, second: BsdfParams, weight: f32) -> BsdfParams {
    let id = intern([first, second]) as f32;
    BsdfParams::new(BlendBsdf::ID, [Vec3::ZERO; 3], [weight, id, 0.0, 0.0])
}

/// The two rows a blend row blends (`None` for other kinds).
pub fn nested(p: &BsdfParams) -> Option<[BsdfParams; 2]> {
    if p.kind != BlendBsdf::ID {
        return None;
    }
    PAIRS.read().unwrap_or_else(|e| e.into_inner()).get(p.scalar[1] as usize).copied()
}

/// Mitsuba's `diffuse` as a nested row: Lambertian of reflectance `r` (one-sided; a row of the
/// course's kind, only meaningful inside a blend).
pub fn lambert(r: Vec3) -> BsdfParams {
    BsdfParams::new(COURSE, [r, Vec3::ZERO, Vec3::ZERO], [0.0; 4])
}

/// The lobe flags a row can sample: a blend's are its nested rows' (a [`lambert`] row's diffuse
/// reflection, a masked row's with the null lobe).
pub fn row_flags(p: &BsdfParams) -> u32 {
    let own = match (p.kind, nested(p)) {
        (COURSE, _) => flags::DIFFUSE_REFLECTION,
        (BlendBsdf::ID, Some(n)) => row_flags(&n[0]) | row_flags(&n[1]),
        (kind, _) => AllBsdfs::flags_of(kind),
    };
    own | if mask::masked(p) { flags::NULL_TRANSMISSION } else { 0 }
}

/// The process-wide list of blended pairs ([`params`] adds each distinct pair once; shading
/// reads it).
static PAIRS: RwLock<Vec<[BsdfParams; 2]>> = RwLock::new(Vec::new());

/// The index of the pair in [`PAIRS`] (added once per distinct content).
fn intern(pair: [BsdfParams; 2]) -> usize {
    let found = PAIRS.read().unwrap_or_else(|e| e.into_inner()).iter().position(|q| *q == pair);
    found.unwrap_or_else(|| {
        let mut list = PAIRS.write().unwrap_or_else(|e| e.into_inner());
        list.iter().position(|q| *q == pair).unwrap_or_else(|| {
            list.push(pair);
            list.len() - 1
        })
    })
}

/// The weight per lane, clamped to [0, 1] (NaN to 0).
#[inline]
fn weight(p: &Params8) -> F8 {
    p.scalar[0].max(F8::ZERO).min(F8::ONE)
}

/// The nested rows of the `active` lanes, the second where `second(lane)`, the first elsewhere.
#[inline]
fn side(p: &Params8, active: Mask8, second: impl Fn(usize) -> bool) -> Params8 {
    let bits = active.to_bitmask();
    let ids = p.scalar[1].to_array();
    let list = PAIRS.read().unwrap_or_else(|e| e.into_inner());
    let rows: [BsdfParams; 8] = std::array::from_fn(|i| match list.get(ids[i] as usize) {
        Some(n) if bits & (1 << i) != 0 => n[usize::from(second(i))],
        _ => BsdfParams::COURSE,
    });
    drop(list);
    Params8::from_lanes(std::array::from_fn(|i| &rows[i]))
}

/// The lanes of nested rows `n` whose back is mirrored (two-sided rows seen from below).
#[inline]
fn mirrored(n: &Params8, wo: Vec3x8, active: Mask8) -> Mask8 {
    active & n.twosided & wo.z.simd_lt(F8::ZERO)
}

/// (f, pdf) of the nested rows `n` (one per lane) at (wo, wi) in the blend's surface frame.
#[inline]
fn eval_side(n: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
    let flip = mirrored(n, wo, active);
    let (wo, wi) = (flip_z(wo, flip), flip_z(wi, flip));
    let lam = active & n.lanes_of(COURSE);
    let mut r = AllBsdfs::eval_pdf(n, wo, wi, active & !lam, (Vec3x8::ZERO, F8::ZERO));
    if lam.any() {
        let up = lam & wo.z.simd_gt(F8::ZERO) & wi.z.simd_gt(F8::ZERO);
        let f = n.color[0].scale(F8::splat(std::f32::consts::FRAC_1_PI));
        r = (Vec3x8::select(up, f, r.0), lam.select(diffuse::pdf_x8(wi, up), r.1));
    }
    let masked = active & n.opacity.simd_lt(F8::ONE);
    if masked.any() {
        r = mask::eval_pdf_x8(n.opacity, masked, r);
    }
    r
}

/// A sample of the nested rows `n` (one per lane) in the blend's surface frame.
#[inline]
fn sample_side(n: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8) -> Sample8 {
    let flip = mirrored(n, wo, active);
    let wo = flip_z(wo, flip);
    let masked = active & n.opacity.simd_lt(F8::ONE);
    let (chose, u_lobe) = mask::choose_x8(n.opacity, masked, u_lobe);
    let nested = active & chose;
    let lam = nested & n.lanes_of(COURSE);
    let mut s = AllBsdfs::sample(n, wo, u_lobe, u, nested & !lam, Sample8::NONE);
    if lam.any() {
        let ok = lam & wo.z.simd_gt(F8::ZERO);
        let wi = diffuse::sample_x8(u, ok);
        let pdf = diffuse::pdf_x8(wi, ok);
        let ok = ok & pdf.simd_gt(F8::ZERO);
        let l = Sample8 {
            wi,
            weight: Vec3x8::select(ok, n.color[0], Vec3x8::ZERO),
            pdf,
            flags: flags_where(ok, flags::DIFFUSE_REFLECTION),
            eta: F8::ONE,
        };
        s = Sample8::select(lam, Sample8::select(ok, l, Sample8::NONE), s);
    }
    if masked.any() {
        s = mask::sample_x8(n.opacity, active & !chose, wo, s);
    }
    s.wi = flip_z(s.wi, flip);
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::mask_all;

    /// A blend of two Lambertians is the Lambertian of the blended reflectance; a blend's
    /// eval is the weighted sum of its nested rows' evals, whatever their kinds.
    #[test]
    fn blend_is_the_weighted_sum_of_its_rows() {
        let p = Params8::splat(&params(lambert(Vec3::new(0.0, 0.5, 0.5)), lambert(Vec3::new(1.0, 1.0, 0.0)), 0.25));
        let wo = Vec3x8::splat(Vec3::new(0.3, 0.1, 0.9).normalize());
        let want = Vec3::new(0.25, 0.625, 0.375);
        for k in 0..64 {
            let u = [F8::splat((k as f32 + 0.5) / 64.0), F8::splat(((k * 37) % 64) as f32 / 64.0 + 0.004)];
            let s = BlendBsdf::sample(&p, wo, F8::splat(((k * 13) % 64) as f32 / 64.0), u, mask_all());
            assert!((s.weight.lane(3) - want).abs().max_element() < 1e-5, "weight {}", s.weight.lane(3));
            let (f, pdf) = BlendBsdf::eval_pdf(&p, wo, s.wi, mask_all());
            assert!((f.lane(0) * std::f32::consts::PI - want).abs().max_element() < 1e-5);
            assert!((pdf.to_array()[0] - s.wi.z.to_array()[0] / std::f32::consts::PI).abs() < 1e-6);
        }
        let a = super::super::roughconductor::params(
            super::super::microfacet::Distribution::Ggx,
            0.3,
            0.3,
            true,
            Vec3::splat(0.2),
            Vec3::splat(3.0),
            Vec3::ONE,
        );
        let b = super::super::plastic::params(Vec3::new(0.1, 0.3, 0.5), Vec3::ONE, 1.49, false);
        let (wo, wi) = (Vec3x8::splat(Vec3::new(0.3, 0.1, 0.9).normalize()), Vec3x8::splat(Vec3::new(-0.2, 0.0, 0.9).normalize()));
        let one = |r: &BsdfParams| AllBsdfs::eval_pdf(&Params8::splat(r), wo, wi, mask_all(), (Vec3x8::ZERO, F8::ZERO));
        let ((fa, pa), (fb, pb), (f, pdf)) = (one(&a), one(&b), one(&params(a, b, 0.3)));
        let want = fa.lane(0) * 0.7 + fb.lane(0) * 0.3;
        assert!((f.lane(0) - want).abs().max_element() < 1e-5 * want.max_element());
        assert!((pdf.to_array()[0] - (0.7 * pa.to_array()[0] + 0.3 * pb.to_array()[0])).abs() < 1e-5);
    }
}

//! Microfacet distributions: Beckmann and GGX (Trowbridge-Reitz), isotropic or anisotropic (alpha_u
//! along the local x axis, alpha_v along y), with their normal distribution D, Smith's masking G1 and
//! G, and sampling of either all normals (density D(m) cos theta_m) or the normals visible from a
//! direction (density G1(wo) max(0, wo.m) D(m) / wo.z; Heitz 2018 for GGX, the conditional inversion
//! of Jakob's Beckmann note for Beckmann). The model of Mitsuba's `MicrofacetDistribution`, written
//! once against [`real::Real`], so the scalar (`f32`) and eight-lane (`F8`) instantiations give the
//! same bits (`tests.rs` checks it).
//!
//! Conventions (local shading frame, macro-normal +z, as the rest of `bsdf`):
//! - Microfacet normals m lie in the upper hemisphere; D(m) = 0 for m.z <= 0.
//! - Alphas are clamped to [`ALPHA_MIN`] = 1e-4 (Mitsuba's floor too), which keeps D finite in f32.
//! - Smith's G1 is written through the projected area of the microsurface A(v) = |v.z| (1 + Lambda(v)):
//!   G1(v, m) = |v.z| / A(v) where (v.m) v.z > 0, else 0. A(v) never divides by a grazing cosine:
//!   GGX: A = (|v.z| + sqrt(v.z^2 + alpha_u^2 v.x^2 + alpha_v^2 v.y^2)) / 2; Beckmann:
//!   A = |v.z| + s a Lambda(a), s = sqrt(alpha_u^2 v.x^2 + alpha_v^2 v.y^2), a = |v.z| / s. So the
//!   visible-normal pdf D(m) max(0, wo.m) / A(wo) is finite at wo.z = 0.
//! - [`Microfacet::sample`] and [`Microfacet::pdf`] take wo on either side; they use the normals
//!   visible from sign(wo.z) wo (Mitsuba's convention for transmission).
//! - A sample whose pdf is 0 (m on the horizon, reachable only at u on the unit square's edge) is to
//!   be dropped by the caller.

pub mod principled;
pub(crate) mod real;
#[cfg(test)]
mod tests;

use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;
use real::{beckmann_a_lambda, erf, erfinv, exp, ln, sincos_2pi, Real};
use std::f32::consts::FRAC_1_PI;

/// Smallest alpha: every alpha is clamped to at least this.
pub const ALPHA_MIN: f32 = 1e-4;

/// Newton-bisection steps of the Beckmann visible-normal inversion (converged to f32 well before).
const BECKMANN_STEPS: usize = 10;

/// The microfacet normal distribution (Mitsuba's `distribution` parameter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distribution {
    /// Beckmann: Gaussian slopes, D = exp(-tan^2 theta / alpha^2) / (pi alpha^2 cos^4 theta).
    Beckmann,
    /// GGX / Trowbridge-Reitz: D = 1 / (pi alpha^2 cos^4 theta (1 + tan^2 theta / alpha^2)^2).
    Ggx,
}

impl Distribution {
    /// Mitsuba's name of the distribution.
    pub fn name(self) -> &'static str {
        match self {
            Self::Beckmann => "beckmann",
            Self::Ggx => "ggx",
        }
    }
    /// The distribution called `name` in Mitsuba (`beckmann`, `ggx`).
    pub fn from_name(name: &str) -> Option<Self> {
        [Self::Beckmann, Self::Ggx].into_iter().find(|d| d.name() == name)
    }
    /// The BSDF parameter slot value of (distribution, sample_visible): 0/1 Beckmann, 2/3 GGX
    /// (+1 when sampling visible normals), read back by [`per_variant`].
    pub fn code(self, sample_visible: bool) -> f32 {
        (match self {
            Self::Beckmann => 0.0,
            Self::Ggx => 2.0,
        }) + if sample_visible { 1.0 } else { 0.0 }
    }
}

/// Eight lanes whose distribution comes from a [`Distribution::code`] slot: calls `f` once per
/// (distribution, sample_visible) pair present among the `active` lanes, with that distribution
/// (alphas per lane) and its lanes, and merges the results with `select(lanes, new, acc)` over
/// `none`. Lanes of one material take one call.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn per_variant<T: Copy>(
    code: F8,
    alpha_u: F8,
    alpha_v: F8,
    active: Mask8,
    none: T,
    f: impl Fn(&Microfacet<F8>, Mask8) -> T,
    select: impl Fn(Mask8, T, T) -> T,
) -> T {
    let mut acc = none;
    for (kind, visible) in [
        (Distribution::Ggx, true),
        (Distribution::Beckmann, true),
        (Distribution::Ggx, false),
        (Distribution::Beckmann, false),
    ] {
        let lanes = active & code.simd_eq(F8::splat(kind.code(visible)));
        if lanes.any() {
            acc = select(lanes, f(&Microfacet::new(kind, alpha_u, alpha_v, visible), lanes), acc);
        }
    }
    acc
}

/// A vector of [`Real`] lanes: `V3<f32>` is one vector, `V3<F8>` eight (structure of arrays).
#[derive(Clone, Copy, Debug)]
pub(crate) struct V3<R> {
    /// x lanes
    pub x: R,
    /// y lanes
    pub y: R,
    /// z lanes
    pub z: R,
}

impl<R: Real> V3<R> {
    /// The vector (x, y, z).
    #[inline]
    pub(crate) fn new(x: R, y: R, z: R) -> Self {
        Self { x, y, z }
    }
    /// Dot product, fused like `sampling::dot` and `Vec3x8::dot`.
    #[inline]
    pub(crate) fn dot(self, o: Self) -> R {
        self.x.fma(o.x, self.y.fma(o.y, self.z * o.z))
    }
    /// Every component times `s`.
    #[inline]
    pub(crate) fn scale(self, s: R) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }
    /// The unit vector along self, or zero when |self|^2 is below the smallest normal f32.
    #[inline]
    pub(crate) fn normalize_or_zero(self) -> Self {
        let l2 = self.dot(self);
        let ok = l2.gt(R::splat(f32::MIN_POSITIVE));
        self.scale(R::select(ok, R::splat(1.0) / l2.sqrt(), R::splat(0.0)))
    }
}

impl From<Vec3> for V3<f32> {
    #[inline]
    fn from(v: Vec3) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}
impl From<V3<f32>> for Vec3 {
    #[inline]
    fn from(v: V3<f32>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}
impl From<Vec3x8> for V3<F8> {
    #[inline]
    fn from(v: Vec3x8) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}
impl From<V3<F8>> for Vec3x8 {
    #[inline]
    fn from(v: V3<F8>) -> Self {
        Vec3x8::new(v.x, v.y, v.z)
    }
}

/// One microfacet distribution per lane: the kind (shared by the lanes), alpha_u, alpha_v (per lane)
/// and whether [`Microfacet::sample`] draws visible normals.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Microfacet<R> {
    /// Beckmann or GGX.
    pub kind: Distribution,
    /// Roughness along the local x axis (clamped to [`ALPHA_MIN`]).
    pub alpha_u: R,
    /// Roughness along the local y axis (clamped to [`ALPHA_MIN`]).
    pub alpha_v: R,
    /// Sample the normals visible from wo (Mitsuba's `sample_visible`, default true).
    pub sample_visible: bool,
}

impl<R: Real> Microfacet<R> {
    /// The distribution with alphas clamped to [`ALPHA_MIN`] (NaN alphas become [`ALPHA_MIN`]).
    #[inline]
    pub(crate) fn new(kind: Distribution, alpha_u: R, alpha_v: R, sample_visible: bool) -> Self {
        let lo = R::splat(ALPHA_MIN);
        Self { kind, alpha_u: alpha_u.maxr(lo), alpha_v: alpha_v.maxr(lo), sample_visible }
    }

    /// D(m) per unit solid angle of m (0 for m.z <= 0): integrates D(m) m.z over the hemisphere to 1.
    #[inline]
    pub(crate) fn d(&self, m: V3<R>) -> R {
        let zero = R::splat(0.0);
        let (sx, sy) = (m.x / self.alpha_u, m.y / self.alpha_v);
        let z2 = m.z * m.z;
        let inv_pi_a = R::splat(FRAC_1_PI) / (self.alpha_u * self.alpha_v);
        match self.kind {
            Distribution::Ggx => {
                let k = sx.fma(sx, sy.fma(sy, z2));
                let k2 = k * k;
                R::select(R::and(m.z.gt(zero), k2.gt(zero)), inv_pi_a / k2, zero)
            }
            Distribution::Beckmann => {
                let z4 = z2 * z2;
                let ok = R::and(m.z.gt(zero), z4.gt(zero));
                let t = sx.fma(sx, sy * sy) / R::select(ok, z2, R::splat(1.0));
                R::select(ok, exp(-t) * inv_pi_a / R::select(ok, z4, R::splat(1.0)), zero)
            }
        }
    }

    /// The projected area of the microsurface seen from v, A(v) = |v.z| (1 + Lambda(v)) = |v.z| / G1(v)
    /// (the module docs give it per distribution); > 0 for every nonzero v.
    #[inline]
    pub(crate) fn projected_area(&self, v: V3<R>) -> R {
        let (ax, ay) = (self.alpha_u * v.x, self.alpha_v * v.y);
        let s2 = ax.fma(ax, ay * ay);
        let c = v.z.abs();
        match self.kind {
            Distribution::Ggx => R::splat(0.5) * (c + c.fma(c, s2).sqrt()),
            Distribution::Beckmann => {
                let s = s2.sqrt();
                let pos = s.gt(R::splat(0.0));
                let a = R::select(pos, c / R::select(pos, s, R::splat(1.0)), R::splat(f32::INFINITY));
                c + R::select(pos, s * beckmann_a_lambda(a), R::splat(0.0))
            }
        }
    }

    /// Smith's G1(v, m): |v.z| / A(v) where (v.m) v.z > 0, else 0 (the BSDFs use the projected
    /// areas directly; the tests check this against its integral definition).
    #[cfg(test)]
    pub(crate) fn g1(&self, v: V3<R>, m: V3<R>) -> R {
        let zero = R::splat(0.0);
        let area = self.projected_area(v);
        let ok = R::and((v.dot(m) * v.z).gt(zero), area.gt(zero));
        R::select(ok, v.z.abs() / R::select(ok, area, R::splat(1.0)), zero)
    }

    /// Density of [`Microfacet::sample`] per unit solid angle of m: D(m) max(0, w.m) / A(w) with
    /// w = sign(wo.z) wo for visible normals, D(m) m.z otherwise.
    #[inline]
    pub(crate) fn pdf(&self, wo: V3<R>, m: V3<R>) -> R {
        let d = self.d(m);
        if self.sample_visible {
            let zero = R::splat(0.0);
            let w = flip_up(wo);
            let area = self.projected_area(w);
            let ok = area.gt(zero);
            R::select(ok, d * w.dot(m).maxr(zero) / R::select(ok, area, R::splat(1.0)), zero)
        } else {
            d * m.z.maxr(R::splat(0.0))
        }
    }

    /// A microfacet normal for u in [0, 1]^2 and its density ([`Microfacet::pdf`]).
    #[inline]
    pub(crate) fn sample(&self, wo: V3<R>, u: [R; 2]) -> (V3<R>, R) {
        let m = if self.sample_visible {
            let w = flip_up(wo);
            match self.kind {
                Distribution::Ggx => self.sample_visible_ggx(w, u),
                Distribution::Beckmann => self.sample_visible_beckmann(w, u),
            }
        } else {
            self.sample_all(u)
        };
        (m, self.pdf(wo, m))
    }

    /// A normal with density D(m) m.z: the slope distribution of alpha = 1 (GGX: radius
    /// sqrt(u/(1 - u)); Beckmann: sqrt(-ln(1 - u))), stretched by (alpha_u, alpha_v).
    #[inline]
    fn sample_all(&self, u: [R; 2]) -> V3<R> {
        let one = R::splat(1.0);
        let (sp, cp) = sincos_2pi(u[1]);
        // m is proportional to (-slope, 1), scaled here by a positive factor to stay finite at u0 = 1.
        let (r, z) = match self.kind {
            Distribution::Ggx => (u[0].sqrt(), (one - u[0]).maxr(R::splat(0.0)).sqrt()),
            Distribution::Beckmann => {
                let l = -ln((one - u[0]).maxr(R::splat(f32::MIN_POSITIVE)));
                (l.maxr(R::splat(0.0)).sqrt(), one)
            }
        };
        V3::new(-(self.alpha_u * r * cp), -(self.alpha_v * r * sp), z).normalize_or_zero()
    }

    /// GGX visible normals (Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 2018): the
    /// view stretched to alpha = 1, a point on the projected hemisphere, back to the ellipsoid.
    #[inline]
    fn sample_visible_ggx(&self, w: V3<R>, u: [R; 2]) -> V3<R> {
        let (zero, one) = (R::splat(0.0), R::splat(1.0));
        let vh = V3::new(self.alpha_u * w.x, self.alpha_v * w.y, w.z).normalize_or_zero();
        let len2 = vh.x.fma(vh.x, vh.y * vh.y);
        let pos = len2.gt(zero);
        let inv = R::select(pos, one / R::select(pos, len2, one).sqrt(), zero);
        let (t1x, t1y) = (R::select(pos, -vh.y * inv, one), vh.x * inv);
        // T2 = vh x T1 with T1.z = 0.
        let t2 = V3::new(-(vh.z * t1y), vh.z * t1x, vh.x.fma(t1y, -(vh.y * t1x)));
        let r = u[0].sqrt();
        let (sp, cp) = sincos_2pi(u[1]);
        let p1 = r * cp;
        let s = R::splat(0.5) * (one + vh.z);
        let p2 = (one - s).fma((one - p1 * p1).maxr(zero).sqrt(), s * (r * sp));
        let pz = (one - p1.fma(p1, p2 * p2)).maxr(zero).sqrt();
        let nh = V3::new(
            p1.fma(t1x, p2.fma(t2.x, pz * vh.x)),
            p1.fma(t1y, p2.fma(t2.y, pz * vh.y)),
            p2.fma(t2.z, pz * vh.z),
        );
        V3::new(self.alpha_u * nh.x, self.alpha_v * nh.y, nh.z.maxr(zero)).normalize_or_zero()
    }

    /// Beckmann visible normals: the view stretched to alpha = 1 and rotated into the xz plane, where
    /// the visible slopes factor into x with density proportional to (cot theta - x) e^(-x^2) on
    /// x < cot theta and y standard normal / sqrt(2). x inverts its conditional CDF, written in
    /// b = erf(x) as C(b) = n (1 + b + tan theta e^(-x^2) / sqrt(pi)) with n = 1 / C(erf(cot theta)),
    /// by Newton steps (dC/db = n (1 - x tan theta)) kept inside a bisection bracket; y = erfinv(2 u1 - 1).
    #[inline]
    fn sample_visible_beckmann(&self, w: V3<R>, u: [R; 2]) -> V3<R> {
        let (zero, one) = (R::splat(0.0), R::splat(1.0));
        let sp = R::splat(0.564_189_6);
        let ws = V3::new(self.alpha_u * w.x, self.alpha_v * w.y, w.z).normalize_or_zero();
        let sin2 = ws.x.fma(ws.x, ws.y * ws.y);
        let sin_t = sin2.sqrt();
        let pos = sin_t.gt(zero);
        let inv_sin = one / R::select(pos, sin_t, one);
        let (cphi, sphi) = (R::select(pos, ws.x * inv_sin, one), ws.y * inv_sin);
        let cos_t = ws.z.maxr(R::splat(1e-7));
        let tan_t = sin_t / cos_t;
        let cot_t = R::select(pos, cos_t * inv_sin, R::splat(f32::INFINITY));
        let c = erf(cot_t);
        let k = tan_t * sp;
        let n = one / (one + c + k * exp(-(cot_t * cot_t)));
        let target = u[0];
        let (mut lo, mut hi) = (R::splat(-1.0), c);
        let mut b = (one + c).fma(target, -one);
        for _ in 0..BECKMANN_STEPS {
            let x = erfinv(b);
            let g = n * (one + b + k * exp(-(x * x))) - target;
            let above = g.gt(zero);
            hi = R::select(above, b, hi);
            lo = R::select(above, lo, b);
            let dg = n * (one - x * tan_t);
            let step = b - g / R::select(dg.gt(zero), dg, one);
            let inside = R::and(step.ge(lo), step.le(hi));
            b = R::select(inside, step, R::splat(0.5) * (lo + hi));
        }
        let sx = erfinv(b);
        let sy = erfinv(R::splat(2.0).fma(u[1], -one));
        let (rx, ry) = (cphi.fma(sx, -(sphi * sy)), sphi.fma(sx, cphi * sy));
        V3::new(-(self.alpha_u * rx), -(self.alpha_v * ry), one).normalize_or_zero()
    }
}

/// sign(w.z) w (w itself at w.z = 0).
#[inline]
fn flip_up<R: Real>(w: V3<R>) -> V3<R> {
    let neg = w.z.lt(R::splat(0.0));
    V3::new(R::select(neg, -w.x, w.x), R::select(neg, -w.y, w.y), R::select(neg, -w.z, w.z))
}

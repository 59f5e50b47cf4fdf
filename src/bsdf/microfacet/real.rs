//! The float lanes the microfacet code is written against once: [`Real`] for `f32` (one lane) and
//! `F8` (eight), and the transcendentals it needs (exp, ln, erf, erfinv, the Beckmann Smith term, the
//! sine and cosine of 2 pi u) built from operations both instantiations perform identically:
//! IEEE +, -, *, /, sqrt, the fused multiply-add exactly where `wide` fuses it
//! ([`crate::sampling::fmadd`]), compares and selects, and exponent bit manipulation. So a function
//! written against [`Real`] gives the same bits in a scalar call and in every lane of an x8 call
//! (`std`'s and `wide`'s own `exp`/`ln`/`sin_cos` differ by an ulp or so, which is why they are not
//! used here).
//!
//! Accuracy (checked against f64 references in `tests.rs`): exp and ln within 2 ulp; erf within 3e-7
//! absolute; erfinv within 2e-6 relative on (-1 + 1e-6, 1 - 1e-6); sin/cos within 3e-7 absolute. The
//! polynomial coefficients were fitted for this file (Chebyshev least squares against f64 `erf`,
//! `erfc`), except erfinv's, which are Giles' single-precision ones ("Approximating the erfinv
//! function", GPU Computing Gems, 2011).

use crate::sampling::fmadd;
use crate::simd::{i32x8, Mask8, F8};
use std::ops::{Add, Div, Mul, Neg, Sub};
use wide::bytemuck::cast;

/// One or eight f32 lanes with the operations the microfacet code uses.
pub(crate) trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// Per-lane condition (`bool` or a lane mask).
    type M: Copy;
    /// Every lane `v`.
    fn splat(v: f32) -> Self;
    /// `self * b + c`, fused exactly when `wide` fuses.
    fn fma(self, b: Self, c: Self) -> Self;
    /// IEEE square root.
    fn sqrt(self) -> Self;
    /// |self|.
    fn abs(self) -> Self;
    /// self < o per lane.
    fn lt(self, o: Self) -> Self::M;
    /// self <= o per lane.
    fn le(self, o: Self) -> Self::M;
    /// `a` where `m`, else `b`.
    fn select(m: Self::M, a: Self, b: Self) -> Self;
    /// Both conditions.
    fn and(a: Self::M, b: Self::M) -> Self::M;
    /// 2^n for integer-valued n in [-126, 127].
    fn pow2i(n: Self) -> Self;
    /// (m, e) with x = m 2^e, m in [1, 2), for positive normal x.
    fn split_exp(x: Self) -> (Self, Self);
    /// self > o per lane.
    #[inline]
    fn gt(self, o: Self) -> Self::M {
        o.lt(self)
    }
    /// self >= o per lane.
    #[inline]
    fn ge(self, o: Self) -> Self::M {
        o.le(self)
    }
    /// The larger of the two (`o` if either is NaN), the same on every instantiation.
    #[inline]
    fn maxr(self, o: Self) -> Self {
        Self::select(self.gt(o), self, o)
    }
    /// The smaller of the two (`o` if either is NaN).
    #[inline]
    fn minr(self, o: Self) -> Self {
        Self::select(self.lt(o), self, o)
    }
}

impl Real for f32 {
    type M = bool;
    #[inline]
    fn splat(v: f32) -> Self {
        v
    }
    #[inline]
    fn fma(self, b: Self, c: Self) -> Self {
        fmadd(self, b, c)
    }
    #[inline]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
    #[inline]
    fn and(a: bool, b: bool) -> bool {
        a & b
    }
    #[inline]
    fn pow2i(n: Self) -> Self {
        f32::from_bits(((n as i32 + 127) as u32) << 23)
    }
    #[inline]
    fn split_exp(x: Self) -> (Self, Self) {
        let b = x.to_bits();
        (f32::from_bits((b & 0x007f_ffff) | 0x3f80_0000), ((b >> 23) as i32 - 127) as f32)
    }
}

impl Real for F8 {
    type M = Mask8;
    #[inline]
    fn splat(v: f32) -> Self {
        F8::splat(v)
    }
    #[inline]
    fn fma(self, b: Self, c: Self) -> Self {
        self.mul_add(b, c)
    }
    #[inline]
    fn sqrt(self) -> Self {
        F8::sqrt(self)
    }
    #[inline]
    fn abs(self) -> Self {
        F8::abs(self)
    }
    #[inline]
    fn lt(self, o: Self) -> Mask8 {
        self.simd_lt(o)
    }
    #[inline]
    fn le(self, o: Self) -> Mask8 {
        self.simd_le(o)
    }
    #[inline]
    fn select(m: Mask8, a: Self, b: Self) -> Self {
        m.select(a, b)
    }
    #[inline]
    fn and(a: Mask8, b: Mask8) -> Mask8 {
        a & b
    }
    #[inline]
    fn pow2i(n: Self) -> Self {
        // n is integer-valued, so the conversion is exact whatever its rounding mode.
        cast((n.round_int() + i32x8::splat(127)) << 23)
    }
    #[inline]
    fn split_exp(x: Self) -> (Self, Self) {
        let b: i32x8 = cast(x);
        let m: F8 = cast((b & i32x8::splat(0x007f_ffff)) | i32x8::splat(0x3f80_0000));
        (m, F8::from_i32x8((b >> 23) - i32x8::splat(127)))
    }
}

/// Horner evaluation of c[0] + c[1] x + ... with fused steps.
#[inline]
fn poly<R: Real>(x: R, c: &[f32]) -> R {
    let mut acc = R::splat(c[c.len() - 1]);
    for &k in c[..c.len() - 1].iter().rev() {
        acc = acc.fma(x, R::splat(k));
    }
    acc
}

/// Round to the nearest integer, ties to even, for |x| < 2^22 (adding and removing 1.5 2^23).
#[inline]
fn round<R: Real>(x: R) -> R {
    let magic = R::splat(12_582_912.0);
    (x + magic) - magic
}

const LN2_HI: f32 = 0.693_145_75;
const LN2_LO: f32 = 1.428_606_8e-6;

/// e^x: 0 below -87 (no subnormal results), +inf never (x is clamped to 88).
#[inline]
pub(crate) fn exp<R: Real>(x: R) -> R {
    let xc = x.minr(R::splat(88.0)).maxr(R::splat(-87.0));
    let n = round(xc * R::splat(std::f32::consts::LOG2_E));
    let r = n.fma(R::splat(-LN2_HI), xc);
    let r = n.fma(R::splat(-LN2_LO), r);
    // Taylor to degree 7 on |r| <= ln(2)/2: truncation 5e-9 relative.
    let p = poly(r, &[1.0, 1.0, 0.5, 1.0 / 6.0, 1.0 / 24.0, 1.0 / 120.0, 1.0 / 720.0, 1.0 / 5040.0]);
    R::select(x.lt(R::splat(-87.0)), R::splat(0.0), p * R::pow2i(n))
}

/// ln x for positive normal x (the callers never pass 0 or a subnormal).
#[inline]
pub(crate) fn ln<R: Real>(x: R) -> R {
    let (m, e) = R::split_exp(x);
    // m in [sqrt(2)/2, sqrt(2)): ln m = 2 atanh(f), f = (m - 1)/(m + 1), |f| <= 0.172.
    let big = m.gt(R::splat(std::f32::consts::SQRT_2));
    let m = R::select(big, m * R::splat(0.5), m);
    let e = R::select(big, e + R::splat(1.0), e);
    let f = (m - R::splat(1.0)) / (m + R::splat(1.0));
    let s = f * f;
    let t = poly(s, &[2.0 / 3.0, 2.0 / 5.0, 2.0 / 7.0, 2.0 / 9.0, 2.0 / 11.0]) * s;
    let lnm = (f * t).fma(R::splat(1.0), f + f);
    e.fma(R::splat(LN2_HI), e.fma(R::splat(LN2_LO), lnm))
}

/// erf(x)/x as a polynomial in x^2 on [0, 1] (1.2e-7 relative).
const ERF_SMALL: [f32; 6] =
    [std::f32::consts::FRAC_2_SQRT_PI, -0.376_123_2, 0.112_801_31, -0.026_709_95, 0.004_916_023_5, -0.000_562_539_6];
/// e^(x^2) erfc(x) on [1, 5] as a polynomial in z - 1/3, z = 1/(1 + x) (1.7e-7 relative).
const ERFC_SCALED: [f32; 9] = [
    0.255_395_68,
    0.961_168_17,
    0.502_518_65,
    -0.394_819_8,
    -0.269_518_26,
    0.585_399_4,
    -0.142_790_39,
    -0.738_218_4,
    1.010_875_5,
];
const FRAC_1_SQRT_PI: f32 = 0.564_189_6;

/// e^(x^2) erfc(x) for x in [1, 5] (the fit), and its asymptotic series beyond 5 (relative error
/// below 2e-7 there too).
#[inline]
fn erfc_scaled<R: Real>(x: R) -> R {
    let z = R::splat(1.0) / (x + R::splat(1.0));
    let fit = poly(z - R::splat(1.0 / 3.0), &ERFC_SCALED);
    let t = R::splat(1.0) / x;
    let t2 = t * t;
    let asym = poly(t2, &[1.0, -0.5, 0.75, -1.875, 6.5625, -29.531_25, 162.421_88]) * t * R::splat(FRAC_1_SQRT_PI);
    R::select(x.lt(R::splat(5.0)), fit, asym)
}

/// erf(x) for every x (odd; +-1 beyond |x| = 5 up to 1e-12).
#[inline]
pub(crate) fn erf<R: Real>(x: R) -> R {
    let a = x.abs();
    let small = a * poly(a * a, &ERF_SMALL);
    // Keep the large branch finite for every input (a = 0 or inf): erfc_scaled at a clamped to [1, 1e15].
    let ac = a.maxr(R::splat(1.0)).minr(R::splat(1e15));
    let large = R::splat(1.0) - exp(-(ac * ac)) * erfc_scaled(ac);
    let r = R::select(a.lt(R::splat(1.0)), small, large);
    R::select(x.lt(R::splat(0.0)), -r, r)
}

/// erf^-1(x) on [-1, 1] (Giles' single-precision fit); x is clamped to +-(1 - 2^-24), so +-1 give
/// about +-3.83 and the result is always finite.
#[inline]
#[allow(clippy::excessive_precision)] // Giles' coefficients as published
pub(crate) fn erfinv<R: Real>(x: R) -> R {
    let lim = R::splat(1.0 - 5.960_464_5e-8);
    let x = x.minr(lim).maxr(-lim);
    let w = -ln((R::splat(1.0) - x) * (R::splat(1.0) + x));
    let central = poly(
        w - R::splat(2.5),
        &[
            1.501_409_4,
            0.246_640_73,
            -0.004_177_681_6,
            -0.001_253_725,
            0.000_218_580_87,
            -4.391_506_5e-6,
            -3.523_387_7e-6,
            3.432_739_4e-7,
            2.810_226_4e-8,
        ],
    );
    let tail = poly(
        w.sqrt() - R::splat(3.0),
        &[
            2.832_976_8,
            1.001_674_1,
            0.009_438_870_5,
            -0.007_622_461_3,
            0.005_739_507_7,
            -0.003_673_428_4,
            0.001_349_343_2,
            0.000_100_950_56,
            -0.000_200_214_26,
        ],
    );
    R::select(w.lt(R::splat(5.0)), central, tail) * x
}

/// a Lambda(a) of the Beckmann distribution for a = 1/(alpha tan theta) >= 0 (inf allowed):
/// (e^(-a^2)/sqrt(pi) - a erfc(a)) / 2, finite everywhere (1/(2 sqrt(pi)) at a = 0, 0 at a = inf).
/// Smith's G1 = 1/(1 + Lambda) = a / (a + a Lambda(a)). Beyond a = 5 the asymptotic series is summed
/// without the cancellation of the two terms.
#[inline]
pub(crate) fn beckmann_a_lambda<R: Real>(a: R) -> R {
    let half = R::splat(0.5);
    let g = exp(-(a * a));
    let sp = R::splat(FRAC_1_SQRT_PI);
    // a < 1: a erfc(a) = a - a erf(a).
    let ac = a.minr(R::splat(1.0));
    let small = half * (g * sp - ac + ac * ac * poly(ac * ac, &ERF_SMALL));
    // 1 <= a < 5: the scaled erfc fit.
    let am = a.maxr(R::splat(1.0)).minr(R::splat(5.0));
    let mid = half * g * (sp - am * erfc_scaled(am));
    // a >= 5: 1/sqrt(pi) - a e^(a^2) erfc(a) = t^2 (1/2 - 3/4 t^2 + ...)/sqrt(pi), t = 1/a.
    let t = R::splat(1.0) / a.maxr(R::splat(5.0));
    let t2 = t * t;
    let far = half * g * sp * t2 * poly(t2, &[0.5, -0.75, 1.875, -6.5625, 29.531_25, -162.421_88]);
    R::select(a.lt(R::splat(1.0)), small, R::select(a.lt(R::splat(5.0)), mid, far))
}

/// (sin 2 pi u, cos 2 pi u) for u in [0, 1] (any finite u works; accuracy 3e-7 absolute for |u| < 2^20).
#[inline]
pub(crate) fn sincos_2pi<R: Real>(u: R) -> (R, R) {
    // Quarter turns q = round(4u); the rest is x = 2 pi (u - q/4) in [-pi/4, pi/4].
    let q = round(u * R::splat(4.0));
    let x = (u - q * R::splat(0.25)) * R::splat(std::f32::consts::TAU);
    let x2 = x * x;
    let s = x * poly(x2, &[1.0, -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0]);
    let c = poly(x2, &[1.0, -0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0, -1.0 / 3_628_800.0]);
    // q mod 4 in {0, 1, 2, 3}.
    let k = q - R::splat(4.0) * round((q - R::splat(1.5)) * R::splat(0.25));
    let odd = R::and(k.gt(R::splat(0.5)), k.lt(R::splat(1.5)));
    let odd3 = k.gt(R::splat(2.5));
    let swap_s = R::select(odd, c, R::select(odd3, -c, s));
    let swap_c = R::select(odd, -s, R::select(odd3, s, c));
    let neg = R::and(k.gt(R::splat(1.5)), k.lt(R::splat(2.5)));
    (R::select(neg, -s, swap_s), R::select(neg, -c, swap_c))
}

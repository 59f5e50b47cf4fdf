//! Eight-lane functions with fewer divisions for the light warps, whose time is their divisions
//! and square roots (one unit of the core runs both).
//!
//! - [`atan2`]: one division where `wide`'s `f32x8::atan2` chains two (`t = y / x`, then
//!   `(t - 1) / (t + 1)`); the same octant reduction and polynomial (Cephes' `atanf`, as in Agner
//!   Fog's vector class library), the middle octant's argument formed as `(y - x) / (y + x)`
//!   directly, which rounds once where the two divisions rounded twice.
//! - [`pow2_recip`]: `2^-e` for `x = m 2^e`, from the exponent bits alone: a scale that keeps
//!   products in range like `1 / x` does, but exactly (multiplying by it rounds nothing) and
//!   without a division.

use super::{F8, U8};

/// `atan2(y, x)` per lane, in `[-pi, pi]`, for finite `y`, `x` (a NaN or infinite input gives NaN
/// in its lane; `(+-0, +-0)` gives `+-0` or `+-pi` by the signs, as the C function). Measured error
/// against f64 (`math::tests::atan2_is_within_two_ulp_of_f64`): at most 2 ulp of pi.
#[inline(always)]
pub fn atan2(y: F8, x: F8) -> F8 {
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    // The first octant's angle atan(lo / hi) in [0, pi/4]: lo / hi below tan(pi/8), else pi/4 +
    // atan((lo - hi) / (lo + hi)).
    let mid = lo.simd_ge(hi * F8::splat(std::f32::consts::SQRT_2 - 1.0));
    let z = mid.select(lo - hi, lo) / mid.select(lo + hi, hi);
    let zz = z * z;
    let p = F8::splat(8.053_744_5e-2)
        .mul_add(zz, F8::splat(-1.387_768_6e-1))
        .mul_add(zz, F8::splat(1.997_771_1e-1))
        .mul_add(zz, F8::splat(-3.333_295e-1));
    let r = p.mul_add(zz * z, z) + (mid & F8::FRAC_PI_4);
    // Back to the quadrant: y > x swaps, x < 0 mirrors, y's sign last.
    let r = ay.simd_gt(ax).select(F8::FRAC_PI_2 - r, r);
    // 0 / 0 is NaN above; both zero gives angle 0 (then pi for x = -0, as the C function).
    let r = (ax | ay).simd_eq(F8::ZERO).select(F8::ZERO, r);
    let r = x.is_sign_negative().select(F8::PI - r, r);
    // min and max drop a NaN: `0 x + 0 y` is +-0 for finite input (r >= +0 keeps its bits) and
    // NaN for a NaN or infinite one.
    (r + x.mul_add(F8::ZERO, y * F8::ZERO)).copysign(y)
}

/// `2^-e` per lane for `x` of exponent `e` (`x = m 2^e`, `1 <= |m| < 2`): `1 / x` to within a factor
/// of 2, exact to multiply by. Zero and subnormal `x` give `2^127`; `|x| >= 2^127` gives 0; infinite
/// or NaN `x` gives a non-finite or zero lane.
#[inline(always)]
pub fn pow2_recip(x: F8) -> F8 {
    let e = x.to_bits() & U8::splat(0x7f80_0000);
    F8::from_bits(U8::splat(254 << 23) - e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atan2_is_within_two_ulp_of_f64() {
        // Every quadrant and octant, both signs of zero, tiny and huge ratios, and the octant
        // boundaries (tan(pi/8), 1) where the reduction switches.
        let mut vals = vec![0.0f32, -0.0, 1e-30, -1e-30, 1e30, -1e30, 0.414_213_55, 0.414_213_6, 1.0, -1.0];
        let mut s = 0x2545_f491u32;
        for _ in 0..4000 {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            let m = (s >> 8) as f32 / (1 << 24) as f32 * 2.0 - 1.0;
            vals.push(m * 10f32.powi((s % 9) as i32 - 4));
        }
        let ulp = f32::EPSILON * std::f32::consts::PI;
        let mut worst = 0f64;
        for c in vals.chunks(8).filter(|c| c.len() == 8) {
            for (k, &yv) in vals.iter().enumerate().take(200) {
                let y = F8::splat(yv);
                let x = F8::new(std::array::from_fn(|i| c[i]));
                let got = atan2(y, x).to_array();
                for i in 0..8 {
                    let want = (yv as f64).atan2(c[i] as f64);
                    let err = (got[i] as f64 - want).abs();
                    worst = worst.max(err);
                    assert!(err <= 2.0 * ulp as f64, "atan2({yv}, {}) = {} vs {want} (k {k})", c[i], got[i]);
                    // The C function's signs at the axes.
                    if yv == 0.0 {
                        assert_eq!(got[i].is_sign_negative(), yv.is_sign_negative(), "atan2({yv:?}, {})", c[i]);
                    }
                }
            }
        }
        eprintln!("atan2: worst error {worst:.3e} ({:.2} ulp of pi)", worst / ulp as f64);
        for (y, x) in [(f32::NAN, 1.0), (1.0, f32::NAN), (f32::INFINITY, 1.0), (0.0, f32::NEG_INFINITY)] {
            assert!(atan2(F8::splat(y), F8::splat(x)).is_nan().all(), "atan2({y}, {x})");
        }
    }

    #[test]
    fn pow2_recip_is_the_power_of_two_below_the_reciprocal() {
        for x in [1.0f32, 1.5, 1.999_999_9, 2.0, 3.0, -5.0, 1e-30, 7e30, f32::MIN_POSITIVE, 1.6e38] {
            let r = pow2_recip(F8::splat(x)).to_array()[0];
            let e = x.abs().log2().floor();
            assert_eq!(r, (-e).exp2(), "{x}");
            // Exact: a power of two, and |x| r in [1, 2).
            assert_eq!(r.to_bits() & 0x007f_ffff, 0, "{x}");
            assert!((1.0..2.0).contains(&(x.abs() * r)), "{x}: {}", x * r);
        }
        assert_eq!(pow2_recip(F8::ZERO).to_array()[0], 2f32.powi(127));
        assert_eq!(pow2_recip(F8::splat(f32::MAX)).to_array()[0], 0.0);
    }
}

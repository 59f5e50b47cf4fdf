//! The scalar/x8 lane abstraction every generator is written against. All arithmetic wraps modulo
//! 2^32, so the `u32` and the [`U8`] instantiation of one generic generator agree bit for bit.

use crate::simd::{i32x8, F8, U8};

/// A 2D point function with a scalar and an 8-lane form that agree bit for bit: what a generic
/// generator calls through [`Lanes::dyn_point`] when the function is chosen at run time (file
/// padding draws a registry layout this way: `layout::SetLayout`).
pub trait PointFn {
    /// The point of (pixel, sample, dim, k) under seed, one lane.
    fn point_1(&self, pixel: u32, sample: u32, dim: u32, k: u32, seed: u64) -> (f32, f32);
    /// The point of (pixel, sample, dim, k) under seed, eight lanes.
    fn point_8(&self, pixel: U8, sample: U8, dim: u32, k: U8, seed: u64) -> (F8, F8);
}

/// Unsigned 32-bit lanes: `u32` (one lane) or `U8` (eight). Every generator is written once against
/// this trait, so the scalar and the x8 instantiation run the same integer operations.
pub trait Lanes: Copy {
    /// Matching float lanes (`f32` or `F8`).
    type F;
    /// Every lane `x`.
    fn splat(x: u32) -> Self;
    /// Wrapping add.
    fn add(self, o: Self) -> Self;
    /// Wrapping subtract.
    fn sub(self, o: Self) -> Self;
    /// Wrapping multiply (low word).
    fn mul(self, o: Self) -> Self;
    /// Bitwise xor.
    fn xor(self, o: Self) -> Self;
    /// Bitwise or.
    fn or(self, o: Self) -> Self;
    /// Bitwise and.
    fn and(self, o: Self) -> Self;
    /// Logical shift right by a lane-uniform amount.
    fn shr(self, s: u32) -> Self;
    /// Shift left by a lane-uniform amount.
    fn shl(self, s: u32) -> Self;
    /// Full 64-bit product as (low word, high word).
    fn mul_wide(self, o: Self) -> (Self, Self);
    /// Per lane `if self < o { a } else { b }`, unsigned compare.
    fn lt_select(self, o: Self, a: Self, b: Self) -> Self;
    /// Per lane `self * 2^-24` as f32; exact for self < 2^24.
    fn unit24(self) -> Self::F;
    /// `f` applied to every lane (table look-ups).
    fn map(self, f: impl Fn(u32) -> u32) -> Self;
    /// High word of the 64-bit product.
    fn mulhi(self, o: Self) -> Self {
        self.mul_wide(o).1
    }
    /// Per lane all ones if `self < o` (unsigned), else 0.
    fn lt_mask(self, o: Self) -> Self {
        self.lt_select(o, Self::splat(u32::MAX), Self::splat(0))
    }
    /// Per lane all ones if the top bit is set, else 0 (an arithmetic shift right by 31).
    fn sign_mask(self) -> Self;
    /// Per lane `self >> s` with a per-lane count `s < 32`.
    fn shr_var(self, s: Self) -> Self;
    /// Per lane `table[self % 8]`: an 8-entry table look-up.
    fn lookup8(self, table: [u32; 8]) -> Self;
    /// Per lane both words of `table[self mod N]` (N a power of two: the index is masked, so
    /// there is no bounds check per lane).
    fn gather2<const N: usize>(self, table: &[[u32; 2]; N]) -> (Self, Self);
    /// Per lane `table[self & (N - 2)]` widened to u32 (`N - 1` a power of two; the last entry
    /// is padding), by the hardware gather where `hardware` (`accel::gather_u16`: the value of
    /// `accel::hardware_gather`, read once by the caller for its look-ups).
    fn gather16<const N: usize>(self, table: &[u16; N], hardware: bool) -> Self;
    /// The largest lane.
    fn max_lane(self) -> u32;
    /// `f`'s point for these lanes (a run-time point function inside a generic one: file padding).
    fn dyn_point<P: PointFn + ?Sized>(
        f: &P,
        pixel: Self,
        sample: Self,
        dim: u32,
        k: Self,
        seed: u64,
    ) -> (Self::F, Self::F);
}

const INV_2_24: f32 = 1.0 / 16_777_216.0;

impl Lanes for u32 {
    type F = f32;
    fn splat(x: u32) -> Self {
        x
    }
    fn add(self, o: Self) -> Self {
        self.wrapping_add(o)
    }
    fn sub(self, o: Self) -> Self {
        self.wrapping_sub(o)
    }
    fn mul(self, o: Self) -> Self {
        self.wrapping_mul(o)
    }
    fn xor(self, o: Self) -> Self {
        self ^ o
    }
    fn or(self, o: Self) -> Self {
        self | o
    }
    fn and(self, o: Self) -> Self {
        self & o
    }
    fn shr(self, s: u32) -> Self {
        self >> s
    }
    fn shl(self, s: u32) -> Self {
        self << s
    }
    fn mul_wide(self, o: Self) -> (Self, Self) {
        let p = u64::from(self) * u64::from(o);
        (p as u32, (p >> 32) as u32)
    }
    fn lt_select(self, o: Self, a: Self, b: Self) -> Self {
        if self < o {
            a
        } else {
            b
        }
    }
    fn unit24(self) -> f32 {
        self as f32 * INV_2_24
    }
    fn map(self, f: impl Fn(u32) -> u32) -> Self {
        f(self)
    }
    fn sign_mask(self) -> Self {
        ((self as i32) >> 31) as u32
    }
    fn shr_var(self, s: Self) -> Self {
        self >> s
    }
    fn lookup8(self, table: [u32; 8]) -> Self {
        table[self as usize & 7]
    }
    fn gather2<const N: usize>(self, table: &[[u32; 2]; N]) -> (Self, Self) {
        const { assert!(N.is_power_of_two()) };
        let [x, y] = table[self as usize & (N - 1)];
        (x, y)
    }
    fn gather16<const N: usize>(self, table: &[u16; N], _: bool) -> Self {
        const { assert!(N >= 2 && (N - 1).is_power_of_two()) };
        u32::from(table[self as usize & (N - 2)])
    }
    fn max_lane(self) -> u32 {
        self
    }
    fn dyn_point<P: PointFn + ?Sized>(f: &P, pixel: u32, sample: u32, dim: u32, k: u32, seed: u64) -> (f32, f32) {
        f.point_1(pixel, sample, dim, k, seed)
    }
}

impl Lanes for U8 {
    type F = F8;
    #[inline]
    fn splat(x: u32) -> Self {
        U8::splat(x)
    }
    #[inline]
    fn add(self, o: Self) -> Self {
        self + o
    }
    #[inline]
    fn sub(self, o: Self) -> Self {
        self - o
    }
    #[inline]
    fn mul(self, o: Self) -> Self {
        self * o
    }
    #[inline]
    fn xor(self, o: Self) -> Self {
        self ^ o
    }
    #[inline]
    fn or(self, o: Self) -> Self {
        self | o
    }
    #[inline]
    fn and(self, o: Self) -> Self {
        self & o
    }
    #[inline]
    fn shr(self, s: u32) -> Self {
        self >> s
    }
    #[inline]
    fn shl(self, s: u32) -> Self {
        self << s
    }
    #[inline]
    fn mul_wide(self, o: Self) -> (Self, Self) {
        self.mul_keep_low_high(o)
    }
    #[inline]
    fn lt_select(self, o: Self, a: Self, b: Self) -> Self {
        self.simd_lt(o).select(a, b)
    }
    #[inline]
    fn unit24(self) -> F8 {
        // Lanes are < 2^24, so the signed conversion is exact.
        F8::from_i32x8(wide::bytemuck::cast::<U8, i32x8>(self)) * F8::splat(INV_2_24)
    }
    #[inline]
    fn map(self, f: impl Fn(u32) -> u32) -> Self {
        U8::new(self.to_array().map(f))
    }
    #[inline]
    fn lt_mask(self, o: Self) -> Self {
        self.simd_lt(o)
    }
    #[inline]
    fn sign_mask(self) -> Self {
        wide::bytemuck::cast::<i32x8, U8>(wide::bytemuck::cast::<U8, i32x8>(self) >> 31)
    }
    #[inline]
    fn shr_var(self, s: Self) -> Self {
        self >> s
    }
    #[inline]
    fn lookup8(self, table: [u32; 8]) -> Self {
        crate::simd::permute_lanes(U8::new(table), self)
    }
    #[inline]
    fn gather2<const N: usize>(self, table: &[[u32; 2]; N]) -> (Self, Self) {
        const { assert!(N.is_power_of_two()) };
        let (mut x, mut y) = ([0u32; 8], [0u32; 8]);
        for (l, i) in self.to_array().into_iter().enumerate() {
            [x[l], y[l]] = table[i as usize & (N - 1)];
        }
        (U8::new(x), U8::new(y))
    }
    #[inline(always)]
    fn gather16<const N: usize>(self, table: &[u16; N], hardware: bool) -> Self {
        crate::accel::gather_u16(table, self, hardware)
    }
    #[inline]
    fn max_lane(self) -> u32 {
        self.to_array().into_iter().fold(0, u32::max)
    }
    #[inline]
    fn dyn_point<P: PointFn + ?Sized>(f: &P, pixel: U8, sample: U8, dim: u32, k: U8, seed: u64) -> (F8, F8) {
        f.point_8(pixel, sample, dim, k, seed)
    }
}

/// Two independent sets of lanes run as one: every operation applies to both halves, so a
/// generator instantiated on `Pair<U8>` computes two 8-lane points with their instructions
/// interleaved. A point is a long chain of dependent multiplies (hashes and permutation rounds);
/// two chains side by side fill the pipeline that one leaves idle. Each half gets exactly the
/// bits the generator gives it alone, provided the generator's lane-uniform branches
/// (`max_lane`) only choose between forms that agree on every lane (as a reduction that is the
/// identity below its modulus does).
#[derive(Clone, Copy, Debug)]
pub struct Pair<L>(pub L, pub L);

/// `Lanes` methods of one other operand, applied half by half.
macro_rules! halves {
    ($($op:ident),*) => {$(
        #[inline(always)]
        fn $op(self, o: Self) -> Self {
            Pair(self.0.$op(o.0), self.1.$op(o.1))
        }
    )*};
}

impl<L: Lanes> Lanes for Pair<L> {
    type F = (L::F, L::F);
    #[inline(always)]
    fn splat(x: u32) -> Self {
        Pair(L::splat(x), L::splat(x))
    }
    halves!(add, sub, mul, xor, or, and, mulhi, lt_mask, shr_var);
    #[inline(always)]
    fn shr(self, s: u32) -> Self {
        Pair(self.0.shr(s), self.1.shr(s))
    }
    #[inline(always)]
    fn shl(self, s: u32) -> Self {
        Pair(self.0.shl(s), self.1.shl(s))
    }
    #[inline(always)]
    fn mul_wide(self, o: Self) -> (Self, Self) {
        let ((l0, h0), (l1, h1)) = (self.0.mul_wide(o.0), self.1.mul_wide(o.1));
        (Pair(l0, l1), Pair(h0, h1))
    }
    #[inline(always)]
    fn lt_select(self, o: Self, a: Self, b: Self) -> Self {
        Pair(self.0.lt_select(o.0, a.0, b.0), self.1.lt_select(o.1, a.1, b.1))
    }
    #[inline(always)]
    fn unit24(self) -> Self::F {
        (self.0.unit24(), self.1.unit24())
    }
    #[inline(always)]
    fn map(self, f: impl Fn(u32) -> u32) -> Self {
        Pair(self.0.map(&f), self.1.map(&f))
    }
    #[inline(always)]
    fn sign_mask(self) -> Self {
        Pair(self.0.sign_mask(), self.1.sign_mask())
    }
    #[inline(always)]
    fn lookup8(self, table: [u32; 8]) -> Self {
        Pair(self.0.lookup8(table), self.1.lookup8(table))
    }
    #[inline(always)]
    fn gather2<const N: usize>(self, table: &[[u32; 2]; N]) -> (Self, Self) {
        let ((x0, y0), (x1, y1)) = (self.0.gather2(table), self.1.gather2(table));
        (Pair(x0, x1), Pair(y0, y1))
    }
    #[inline(always)]
    fn gather16<const N: usize>(self, table: &[u16; N], hardware: bool) -> Self {
        Pair(self.0.gather16(table, hardware), self.1.gather16(table, hardware))
    }
    #[inline(always)]
    fn max_lane(self) -> u32 {
        self.0.max_lane().max(self.1.max_lane())
    }
    #[inline]
    fn dyn_point<P: PointFn + ?Sized>(
        f: &P,
        pixel: Self,
        sample: Self,
        dim: u32,
        k: Self,
        seed: u64,
    ) -> (Self::F, Self::F) {
        let (x0, y0) = L::dyn_point(f, pixel.0, sample.0, dim, k.0, seed);
        let (x1, y1) = L::dyn_point(f, pixel.1, sample.1, dim, k.1, seed);
        ((x0, x1), (y0, y1))
    }
}

//! Exact division by a lane-uniform divisor.

use super::lanes::Lanes;

/// Division of any u32 by a fixed `d >= 1` with one high multiply (Granlund & Montgomery 1994,
/// Fig. 4.1: `m = floor(2^32 (2^l - d) / d) + 1`, `l = ceil(log2 d)`), exact for all dividends.
#[derive(Clone, Copy, Debug)]
pub(super) struct Divisor {
    /// the divisor, >= 1
    pub(super) d: u32,
    m: u32,
    s1: u32,
    s2: u32,
}

impl Divisor {
    /// Divisor `d`; 0 acts as 1.
    pub(super) const fn new(d: u32) -> Self {
        let d = if d == 0 { 1 } else { d };
        let l = 32 - (d - 1).leading_zeros();
        let m = ((1u64 << 32) * ((1u64 << l) - d as u64) / d as u64 + 1) as u32;
        Self { d, m, s1: if l > 0 { 1 } else { 0 }, s2: l.saturating_sub(1) }
    }

    /// x / d.
    #[inline]
    pub(super) fn div<L: Lanes>(self, x: L) -> L {
        let t = x.mulhi(L::splat(self.m));
        t.add(x.sub(t).shr(self.s1)).shr(self.s2)
    }

    /// (x / d, x % d).
    #[inline]
    pub(super) fn div_rem<L: Lanes>(self, x: L) -> (L, L) {
        let q = self.div(x);
        (q, x.sub(q.mul(L::splat(self.d))))
    }

    /// x % d.
    #[inline]
    pub(super) fn rem<L: Lanes>(self, x: L) -> L {
        self.div_rem(x).1
    }
}

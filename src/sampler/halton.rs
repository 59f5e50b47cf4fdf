//! `halton`: bases 2 and 3, nested (Owen) scrambled per (pixel, dim, seed), at global index
//! `i = sample * n + k` (wrapping in u32), shuffled per (pixel, dim, seed) by a permutation that
//! keeps every prefix [0, 2^m) (so the first 2^m points of a stream are the first 2^m Halton
//! points, and dims are decorrelated): the n points of one pixel sample are consecutive Halton
//! points and successive samples continue the sequence, so for the camera `n = spp, k = s,
//! sample = 0` and `n = 1, k = 0, sample = s` give the same points.
//!
//! Precision: Halton uses the low 24 base-2 digits and the low 15 base-3 digits of the index (the
//! coordinates repeat with periods 2^24 and 3^15 ~ 1.4e7 points per (pixel, dim)); the
//! 2^a x 3^b elementary-interval property holds exactly for a <= 24, b <= 15.

use super::divisor::Divisor;
use super::hash::{fmix, mix, stream_key, SPREAD};
use super::lanes::Lanes;
use super::layout::{Layout, SetShape, StreamKey};
use super::sobol::{prefix_shuffle, reverse_bits};

const TAG_HALTON: u32 = 0x51a7_0003;

/// Owen-scrambled Halton points (bases 2, 3) at index `sample * n + k`.
#[derive(Clone, Copy, Debug)]
pub struct Halton;

/// Its entry in the registry [`super::SAMPLERS`].
pub(super) const INFO: super::SamplerInfo =
    super::SamplerInfo::new("halton", &[], "Owen-scrambled Halton (bases 2, 3)", &Halton).period(1 << 24);

impl Layout for Halton {
    #[inline]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        let s = self.stream(set, pixel, sample, dim, seed);
        halton_point(s.prefix, s.base.add(k), dim)
    }

    #[inline]
    fn stream<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        let prefix = mix(L::splat(stream_key(TAG_HALTON, seed, dim)), pixel);
        StreamKey { prefix, base: sample.mul(L::splat(set.n())), sample, dim, seed }
    }

    #[inline]
    fn stream_point<L: Lanes>(&self, _: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        halton_point(s.prefix, s.base.add(L::splat(k)), s.dim)
    }
}

/// Point `index` of the stream keyed `key` in dimension `dim`: outside dimension 0 the index is
/// shuffled per stream (keeping every prefix [0, 2^m), `sobol::prefix_shuffle`), then both
/// radical inverses are taken, each nested-scrambled. Without the shuffle every dim of a pixel
/// would draw the same index of the same two bases, and nested scrambling flips the top digits by
/// a constant per stream, so two dims' points were tied to each other (a pixel's light choice
/// followed its light point). Dimension 0 (the camera) keeps the classic sequence, with its
/// 2^a x 3^b elementary intervals for every prefix; shuffled dims keep them for prefixes of 2^m.
#[inline]
fn halton_point<L: Lanes>(key: L, index: L, dim: u32) -> (L::F, L::F) {
    let index = if dim == 0 { index } else { prefix_shuffle(index, mix(key, L::splat(4))) };
    let x = owen2(index, mix(key, L::splat(2)));
    let y = RADIX3.to_fixed24(owen3(index, mix(key, L::splat(3))));
    (x.unit24(), y.unit24())
}

/// `RADIX2.inverse(index, Some(key))`, bit for bit, in about a third of the instructions: in
/// base 2 the nested permutation of digit j is a flip by bit 31 ^ bit 30 of
/// `mix(key, index mod 2^j + 2^j)` (a reflection and a cyclic shift by `floor(2 (h << 1) / 2^32)`,
/// i.e. bit 30), so the result is the bit-reversed index XOR 24 flip bits, and the fixed-point map
/// of base 2 is the identity.
#[inline]
fn owen2<L: Lanes>(index: L, key: L) -> L {
    let mut flips = L::splat(0);
    for j in 0..24 {
        // mix(key, w) with w = (index mod 2^j) | 2^j (= index mod 2^j + 2^j).
        let w = index.and(L::splat((1u32 << j) - 1)).or(L::splat(1 << j));
        let h = fmix(key.xor(w.mul(L::splat(SPREAD))));
        // Output digit 23 - j first: flips collects bit 31 of h ^ (h << 1) = h_31 ^ h_30.
        flips = flips.shl(1).or(h.xor(h.shl(1)).shr(31));
    }
    reverse_bits(index).shr(8).xor(flips)
}

/// 3^j * SPREAD (wrapping) for j < 15: the step of `(index mod 3^j + 3^j) * SPREAD` per digit.
const POW3_SPREAD: [u32; 15] = {
    let (mut t, mut j, mut p) = ([0u32; 15], 0, 1u32);
    while j < 15 {
        t[j] = p.wrapping_mul(SPREAD);
        p *= 3;
        j += 1;
    }
    t
};

/// The digit integer of `RADIX3.inverse(index, Some(key))` before its fixed-point map, bit for
/// bit: the 15 base-3 digits come from three 5-digit chunks (two exact divisions by 243, one
/// remainder), each digit of a chunk by a small multiply (`x / 3 = (x * 171) >> 9` for x < 243);
/// `mix(key, index mod 3^j + 3^j)` is kept incrementally as `prefix * SPREAD`; the reflection is a
/// sign mask, the cyclic shift `floor(3 (h << 1) / 2^32)` two compares; the digits are summed by
/// Horner's rule (digit j has weight 3^(14 - j)).
#[inline]
fn owen3<L: Lanes>(index: L, key: L) -> L {
    const D243: Divisor = Divisor::new(243);
    let (q1, c0) = D243.div_rem(index);
    let (q2, c1) = D243.div_rem(q1);
    let c2 = D243.rem(q2);
    // floor(3 x / 2^32) >= 1 iff x >= ceil(2^32 / 3); >= 2 iff x >= ceil(2^33 / 3).
    const T1: u32 = ((1u64 << 32).div_ceil(3)) as u32;
    const T2: u32 = ((1u64 << 33).div_ceil(3)) as u32;
    let (mut acc, mut spread) = (L::splat(0), L::splat(0));
    let mut j = 0;
    for chunk in [c0, c1, c2] {
        let mut x = chunk;
        for _ in 0..5 {
            let q = x.mul(L::splat(171)).shr(9);
            let a = x.sub(q.add(q.shl(1)));
            x = q;
            let h = fmix(key.xor(spread.add(L::splat(POW3_SPREAD[j]))));
            spread = spread.add(a.mul(L::splat(POW3_SPREAD[j])));
            // Reflection (top bit of h): a -> 2 - a.
            let neg = h.sign_mask();
            let r = a.xor(neg.and(a.xor(L::splat(2).sub(a))));
            // Cyclic shift: 2 - [x < T1] - [x < T2] with lt masks of all ones.
            let x2 = h.shl(1);
            let d = r.add(L::splat(2)).add(x2.lt_mask(L::splat(T1))).add(x2.lt_mask(L::splat(T2)));
            let d = d.lt_select(L::splat(3), d, d.sub(L::splat(3)));
            acc = acc.add(acc.shl(1)).add(d);
            j += 1;
        }
    }
    acc
}

/// Unscrambled radical inverse of `index` in base 2 or 3 (`None` for other bases), in [0, 1): the
/// 24-bit fixed-point value in the same base^-D cell as the exact value, with D = 24 digits for base
/// 2 (exact) and D = 15 for base 3 (within 2^-24 above); index digits beyond D are ignored.
pub fn radical_inverse(base: u32, index: u32) -> Option<f32> {
    let radix = match base {
        2 => &RADIX2,
        3 => &RADIX3,
        _ => return None,
    };
    Some(radix.inverse(index, None).unit24())
}

/// One Halton axis: `digits` base-`base` digits, and the map from the digit integer
/// R < base^digits to 24-bit fixed point: `y = floor((R * scale + offset) / 2^31)`.
pub(super) struct Radix {
    base: u32,
    digits: u32,
    div: Divisor,
    scale: u32,
    offset: u32,
}

/// Base 2: 24 digits are already 24-bit fixed point (scale 1, offset 1/2 => y = R).
pub(super) const RADIX2: Radix = Radix { base: 2, digits: 24, div: Divisor::new(2), scale: 1 << 31, offset: 1 << 30 };

pub(super) const POW3_15: u64 = 14_348_907;
/// round(2^31 * alpha), alpha = 2^24 / 3^15 ~ 1.169 (grid points per finest base-3 cell).
const RADIX3_SCALE: u64 = ((1u64 << 55) + POW3_15 / 2) / POW3_15;
/// Base 3: 15 digits (3^15 < 2^24). With offset beta = (1 + alpha) / 2, floor(R alpha + beta) lies in
/// [R alpha, (R + 1) alpha), i.e. inside R's cell, with margin (alpha - 1) / 2 ~ 0.085 on both
/// sides, far above the fixed-point error R * 2^-32 <= 2^-8 (checked exhaustively in the tests).
pub(super) const RADIX3: Radix = Radix {
    base: 3,
    digits: 15,
    div: Divisor::new(3),
    scale: RADIX3_SCALE as u32,
    offset: ((1u64 << 31) + RADIX3_SCALE).div_ceil(2) as u32,
};

impl Radix {
    /// Digit-reversed `index` (its low `digits` digits) as 24-bit fixed point. With a `key`, output
    /// digit j is a random permutation of index digit j chosen by hash(key, j, index mod base^j):
    /// nested uniform scrambling, a bijection on every level, so base^-j intervals are preserved.
    pub(super) fn inverse<L: Lanes>(&self, index: L, key: Option<L>) -> L {
        let b = self.base;
        let (mut rest, mut prefix, mut acc) = (index, L::splat(0), L::splat(0));
        let (mut pow, mut weight) = (1u32, b.pow(self.digits - 1));
        for _ in 0..self.digits {
            let (q, a) = self.div.div_rem(rest);
            let d = match key {
                None => a,
                Some(key) => {
                    // prefix + b^j is unique per (level j, prefix < b^j).
                    let h = mix(key, prefix.add(L::splat(pow)));
                    // Permutation = optional reflection (top hash bit), then a cyclic shift by
                    // floor(b * bits30..0 / 2^31); for b <= 3 this reaches all b! permutations evenly.
                    let r = h.lt_select(L::splat(1 << 31), a, L::splat(b - 1).sub(a));
                    let d = r.add(h.shl(1).mulhi(L::splat(b)));
                    d.lt_select(L::splat(b), d, d.sub(L::splat(b)))
                }
            };
            acc = acc.add(d.mul(L::splat(weight)));
            prefix = prefix.add(a.mul(L::splat(pow)));
            rest = q;
            pow *= b;
            weight /= b;
        }
        self.to_fixed24(acc)
    }

    /// `floor((r * scale + offset) / 2^31)` via a 64-bit product with carry; 0 stays 0.
    #[inline]
    pub(super) fn to_fixed24<L: Lanes>(&self, r: L) -> L {
        let (lo, hi) = r.mul_wide(L::splat(self.scale));
        let lo = lo.add(L::splat(self.offset));
        let hi = lo.lt_select(L::splat(self.offset), hi.add(L::splat(1)), hi);
        let y = hi.shl(1).or(lo.shr(31));
        r.lt_select(L::splat(1), L::splat(0), y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::U8;

    /// The fast scrambles equal the digit-by-digit reference `Radix::inverse`, bit for bit, scalar
    /// and 8-wide, on low indices, random ones and the ends of the range.
    #[test]
    fn fast_scrambles_equal_the_reference() {
        let mut st = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            st = st.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (st >> 32) as u32
        };
        let mut indices: Vec<u32> = (0..3000).chain([u32::MAX, u32::MAX - 1, 1 << 31, POW3_15 as u32]).collect();
        indices.extend((0..20_000).map(|_| next()));
        for t in 0..40 {
            let key = if t == 0 { 0 } else { next() };
            for &i in &indices {
                assert_eq!(owen2(i, key), RADIX2.inverse(i, Some(key)), "base 2, key {key:#x}, index {i}");
                assert_eq!(
                    RADIX3.to_fixed24(owen3(i, key)),
                    RADIX3.inverse(i, Some(key)),
                    "base 3, key {key:#x}, index {i}"
                );
            }
            for c in indices.chunks_exact(8).step_by(97) {
                let (i8, k8) = (U8::new(c.try_into().unwrap()), U8::splat(key) ^ U8::new([0, 1, 2, 3, 4, 5, 6, 7]));
                let (a, b) = (owen2(i8, k8).to_array(), owen3(i8, k8).to_array());
                for l in 0..8 {
                    assert_eq!(a[l], owen2(c[l], key ^ l as u32));
                    assert_eq!(b[l], owen3(c[l], key ^ l as u32));
                }
            }
        }
        // The small division of a base-3 chunk is exact on its whole range.
        assert!((0..243u32).all(|x| (x * 171) >> 9 == x / 3));
    }
}

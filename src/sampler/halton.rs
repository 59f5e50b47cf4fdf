//! `halton`: bases 2 and 3 at global index `i = sample * n + k` (wrapping in u32), scrambled per
//! (pixel, dim, seed) and shuffled per (pixel, dim, seed) by a permutation that keeps every prefix
//! [0, 2^m) (so the first 2^m points of a stream are the first 2^m Halton points, and dims are
//! decorrelated): the n points of one pixel sample are consecutive Halton points and successive
//! samples continue the sequence, so for the camera `n = spp, k = s, sample = 0` and
//! `n = 1, k = 0, sample = s` give the same points.
//!
//! Scrambles (issue 33: the cheapest scrambles that keep the quality; they replaced a hashed
//! nested (Owen) scramble of both bases, one 32-bit hash per digit, 4x Sobol's cost):
//! - base 2: nested (Owen) scrambling by the Laine-Karras-style hash `sobol::lk_permute` on the
//!   index before the bit reversal (Burley 2020), as Sobol's x axis;
//! - base 3: random digit permutations (pbrt-v4's `DigitPermutation` strategy, "PermuteDigits"):
//!   digit j of the index goes through a permutation of {0, 1, 2} chosen per stream, the same for
//!   every index. The 15 digits are read in five chunks of three; chunk c of a stream is mapped by
//!   one of the [`TABLES3`] = 6^3 precomputed tables (27 entries each: the chunk's three digits
//!   permuted and reversed; one table per choice of the three permutations), picked per
//!   (stream, chunk) by a hash: the digits' permutations are independent and uniform over all six
//!   (the last chunks' picks share fewer hash bits), so each output digit is uniform, each point
//!   is uniform on the 3^-15 grid (unbiased), and base-3 intervals map to base-3 intervals (the
//!   2^a x 3^b elementary intervals are kept). A 36-table variant over five-digit chunks (three
//!   look-ups) failed the registry's chi-square test: its top digits were not jointly uniform.
//!
//! Precision: Halton uses the low 24 base-2 digits and the low 15 base-3 digits of the index (the
//! coordinates repeat with periods 2^24 and 3^15 ~ 1.4e7 points per (pixel, dim)); the
//! 2^a x 3^b elementary-interval property holds exactly for a <= 24, b <= 15.

use super::divisor::Divisor;
use super::hash::{mix, stream_key};
use super::lanes::Lanes;
use super::layout::{Layout, SetShape, StreamKey};
use super::sobol::{lk_permute, prefix_shuffle, reverse_bits};

const TAG_HALTON: u32 = 0x51a7_0003;

/// Scrambled Halton points (base 2 Owen, base 3 random digit permutations) at `sample * n + k`.
#[derive(Clone, Copy, Debug)]
pub struct Halton;

/// Its entry in the registry [`super::SAMPLERS`].
pub(super) const INFO: super::SamplerInfo =
    super::SamplerInfo::new("halton", &[], "scrambled Halton (bases 2, 3)", &Halton).period(1 << 24);

impl Layout for Halton {
    #[inline]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        let s = self.stream(set, pixel, sample, dim, seed);
        halton_point(s.prefix, s.base.add(k), dim)
    }

    #[inline]
    fn stream<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        let prefix = mix(L::splat(stream_key(TAG_HALTON, seed, dim)), pixel);
        StreamKey::new(prefix, sample.mul(L::splat(set.n())), sample, dim, seed)
    }

    #[inline]
    fn stream_point<L: Lanes>(&self, _: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        halton_point(s.prefix, s.base.add(L::splat(k)), s.dim)
    }
}

/// Point `index` of the stream keyed `key` in dimension `dim`: outside dimension 0 the index is
/// shuffled per stream (keeping every prefix [0, 2^m), `sobol::prefix_shuffle`), then both
/// radical inverses are taken and scrambled. Without the shuffle every dim of a pixel would draw
/// the same index of the same two bases, and both scrambles map the top digits by a constant per
/// stream, so two dims' points were tied to each other (a pixel's light choice followed its light
/// point). Dimension 0 (the camera) keeps the classic sequence, with its 2^a x 3^b elementary
/// intervals for every prefix; shuffled dims keep them for prefixes of 2^m.
#[inline]
fn halton_point<L: Lanes>(key: L, index: L, dim: u32) -> (L::F, L::F) {
    let index = if dim == 0 { index } else { prefix_shuffle(index, key) };
    // Owen in base 2: output digit j (from the top) is index bit j - 1 flipped by a keyed function
    // of the lower index bits (the digits above it); the reversal makes it a radical inverse.
    let x = reverse_bits(lk_permute(index, mix(key, L::splat(2)))).shr(8);
    let y = RADIX3.to_fixed24(permute3(index, mix(key, L::splat(3))));
    (x.unit24(), y.unit24())
}

/// Precomputed digit-permutation tables for base 3: 6^3, one per choice of the three digits'
/// permutations.
pub(super) const TABLES3: u32 = 216;
/// Entries per table: the 3^3 values of a three-digit chunk.
const CHUNK: u32 = 27;

/// The six permutations of {0, 1, 2}.
const PERMS3: [[u16; 3]; 6] = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];

/// Permutation of digit `p` (0..3, 0 least significant) of a chunk under table `t`: base-6 digit
/// p of t, so over a uniform t the three permutations are independent and uniform over all six.
const fn digit_perm(t: usize, p: usize) -> &'static [u16; 3] {
    &PERMS3[t / [1, 6, 36][p] % 6]
}

/// Entries of [`DIGIT_TABLES`]: the 216 x 27 = 5,832 table entries, padded with zeros to a power
/// of two plus one (the form `accel::gather_u16` reads with one mask, no bounds check).
const DIGIT_TABLES_LEN: usize = 8193;

/// Table t at entries `t * 27 ..`: chunk value c (three base-3 digits d_0..d_2, d_0 least
/// significant) to `sum_p perm_{t,p}(d_p) 3^(2 - p)`: permuted and digit-reversed.
static DIGIT_TABLES: [u16; DIGIT_TABLES_LEN] = {
    assert!(((TABLES3 * CHUNK) as usize) < DIGIT_TABLES_LEN);
    let mut out = [0u16; DIGIT_TABLES_LEN];
    let mut t = 0;
    while t < TABLES3 as usize {
        let mut c = 0;
        while c < CHUNK as usize {
            let (mut rest, mut v, mut p) = (c, 0u16, 0);
            while p < 3 {
                v = v * 3 + digit_perm(t, p)[rest % 3];
                rest /= 3;
                p += 1;
            }
            out[t * CHUNK as usize + c] = v;
            c += 1;
        }
        t += 1;
    }
    out
};

/// The digit integer of the base-3 radical inverse of `index` (its low 15 digits) with random
/// digit permutations, before the fixed-point map: five chunks of three digits (exact divisions
/// by 27), chunk c through table t_c, the base-216 digits of the stream's hash `h` (t = floor(216 u)
/// for successive fractions u of h; the last chunks, the least significant output digits, share
/// fewer random bits), weighted 27^(4 - c) (Horner's rule). The look-ups are hardware gathers
/// where `accel::hardware_gather` says so; each form is compiled on its own (no branch per
/// look-up).
#[inline]
fn permute3<L: Lanes>(index: L, h: L) -> L {
    if crate::accel::hardware_gather() {
        permute3_with::<L, true>(index, h)
    } else {
        permute3_with::<L, false>(index, h)
    }
}

/// [`permute3`] with its look-ups by the hardware gather if `HW`.
#[inline(always)]
fn permute3_with<L: Lanes, const HW: bool>(index: L, h: L) -> L {
    const D27: Divisor = Divisor::new(CHUNK);
    let n = L::splat(TABLES3);
    let (mut rest, mut r, mut acc) = (index, h, L::splat(0));
    for c in 0..5 {
        let (q, chunk) = D27.div_rem(rest);
        let t = r.mulhi(n);
        let v = t.mul(L::splat(CHUNK)).add(chunk).gather16(&DIGIT_TABLES, HW);
        acc = if c == 0 { v } else { acc.mul(L::splat(CHUNK)).add(v) };
        r = r.mul(n);
        rest = q;
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
    Some(radix.inverse(index).unit24())
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
    /// Digit-reversed `index` (its low `digits` digits) as 24-bit fixed point, unscrambled.
    pub(super) fn inverse<L: Lanes>(&self, index: L) -> L {
        let (mut rest, mut acc, mut weight) = (index, L::splat(0), self.base.pow(self.digits - 1));
        for _ in 0..self.digits {
            let (q, a) = self.div.div_rem(rest);
            acc = acc.add(a.mul(L::splat(weight)));
            rest = q;
            weight /= self.base;
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

    /// Reference: the base-3 scramble digit by digit (digit j of the index through the
    /// permutation of its chunk's table, weight 3^(14 - j)).
    fn permute3_reference(index: u32, h: u32) -> u32 {
        let mut t = [0usize; 5];
        let mut r = h;
        for tc in &mut t {
            *tc = ((u64::from(r) * u64::from(TABLES3)) >> 32) as usize;
            r = r.wrapping_mul(TABLES3);
        }
        let (mut rest, mut acc) = (index, 0u32);
        for j in 0..15 {
            let d = u32::from(digit_perm(t[j / 3], j % 3)[(rest % 3) as usize]);
            acc += d * 3u32.pow(14 - j as u32);
            rest /= 3;
        }
        acc
    }

    /// The table scramble equals the digit-by-digit reference, scalar and 8-wide; the x axis is
    /// the bit-reversed index XOR a nested scramble.
    #[test]
    fn base3_tables_equal_the_digit_reference() {
        let mut st = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            st = st.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (st >> 32) as u32
        };
        let mut indices: Vec<u32> = (0..3000).chain([u32::MAX, u32::MAX - 1, 1 << 31, POW3_15 as u32]).collect();
        indices.extend((0..5000).map(|_| next()));
        for t in 0..40 {
            let h = if t == 0 { 0 } else { next() };
            for &i in &indices {
                assert_eq!(permute3(i, h), permute3_reference(i, h), "h {h:#x}, index {i}");
            }
            for c in indices.chunks_exact(8).step_by(97) {
                let (i8, h8) = (U8::new(c.try_into().unwrap()), U8::splat(h) ^ U8::new([0, 1, 2, 3, 4, 5, 6, 7]));
                let got = permute3(i8, h8).to_array();
                for l in 0..8 {
                    assert_eq!(got[l], permute3(c[l], h ^ l as u32));
                }
            }
        }
    }

    /// Every table is a bijection of the 27 chunks, and the 216 tables are all 6^3 choices of
    /// the three digits' permutations (so over a uniform pick they are independent and uniform).
    #[test]
    fn digit_tables_are_all_choices_of_digit_permutations() {
        let mut choices = std::collections::HashSet::new();
        for t in 0..TABLES3 as usize {
            let mut seen = [false; CHUNK as usize];
            for &v in &DIGIT_TABLES[t * CHUNK as usize..(t + 1) * CHUNK as usize] {
                assert!(!std::mem::replace(&mut seen[v as usize], true), "table {t}");
            }
            choices.insert([0, 1, 2].map(|p| *digit_perm(t, p)));
        }
        assert_eq!(choices.len(), 216);
    }

    /// Base 2's scramble is nested: flipping index bit q (a digit of the radical inverse) never
    /// changes the digits above it.
    #[test]
    fn base2_scramble_is_nested() {
        let x = |i: u32, key: u32| reverse_bits(lk_permute(i, key)) >> 8;
        for key in [0, 7, 0xdead_beef] {
            for i in (0..5000u32).map(|i| i.wrapping_mul(2_654_435_761)) {
                for q in 0..24 {
                    let (a, b) = (x(i, key), x(i ^ 1 << q, key));
                    assert_eq!(a >> (24 - q), b >> (24 - q), "key {key} i {i} q {q}");
                    assert_ne!(a >> (23 - q) & 1, b >> (23 - q) & 1);
                }
            }
        }
    }
}

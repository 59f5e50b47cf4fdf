//! Owen-scrambled Sobol' points in 2D, after Burley 2020, "Practical Hash-based Owen Scrambling"
//! (JCGT 9(4)).
//!
//! Point k of the n-point set of stream (pixel, sample, dim) is point `i = sample * n + k` (wrapping
//! in u32; n == 0 acts as 1) of the first two Sobol' dimensions, like Halton in `mod.rs`: the n
//! points of one pixel sample are consecutive and successive samples continue the sequence. Three
//! independent nested uniform (Owen) scrambles, keyed by (pixel, dim, seed), are applied:
//! - to the index, `i' = nus(i)` (Burley's shuffle): a permutation of u32 that maps every aligned
//!   block of 2^m indices onto an aligned block of 2^m indices. It decorrelates the `dim`s of one
//!   pixel, whose points would otherwise all come from the same index i;
//! - to x = vdc(i') and to y = sobol1(i'), with one key per axis.
//!
//! Dimension 0 is the van der Corput sequence, `vdc(i)` = the bits of i reversed. Dimension 1 has
//! primitive polynomial x + 1 and m_1 = 1, so m_j = m_{j-1} XOR 2 m_{j-1}: its generator matrix is
//! Pascal's triangle mod 2, entry (r, c) = binom(c, r) mod 2, which by Lucas' theorem is 1 iff the
//! bits of r are a subset of those of c. The matrix-vector product is therefore a superset-XOR
//! transform over the 5-bit bit positions: 5 shift/mask/XOR steps instead of 32 conditional XORs
//! (checked against the direction numbers from the recurrence in the tests).
//!
//! `nus(v)` is Burley's construction: reverse the bits, apply a Laine-Karras-style keyed
//! permutation in which every step maps bit j to bit j XOR a function of the bits below j, reverse
//! back. Output digit j is input digit j flipped by a function of the digits above it: a nested
//! scramble, so the elementary-interval structure of the unscrambled points is kept. Dimensions 0
//! and 1 of Sobol' form a (0, 2)-sequence, so every aligned block of 2^m indices, in particular the
//! first 2^m points of a stream and the n = 2^m points of any pixel sample, is a (0, m, 2)-net:
//! one point in every 2^-a x 2^-b box with a + b = m, before and after scrambling.
//!
//! Scramble quality: a 32-bit key cannot randomize every level independently, and the hash only
//! approximates a uniform nested scramble. Measured over 2^21 keys: the digit flips of the top 2
//! levels are uniform, those of the top 3 levels take all 128 possible patterns (non-uniformly),
//! the top 4 levels 6720 of 32768 (Burley's fixed-multiplier hash: 4, 8 and 16 patterns). The
//! integration variance equals that of an exact hashed Owen scramble within 2% (tests).
//!
//! Precision: coordinates are the top 24 bits of the 32-bit scrambled value, `y * 2^-24` with
//! `y < 2^24`, exactly representable, in [0, 1). The index wraps modulo 2^32; elementary intervals
//! are exact for a, b <= 24 (below that the 2^-24 grid, not the sequence, limits resolution).
//!
//! Scalar and 8-lane versions run the same generic code , so they agree bit for
//! bit (trait [`Lanes`]). The hash is `hash::combine` (murmur3's public-domain `fmix32` finalizer),
//! shared with `pmj`, under this module's own domain tag.

use super::hash::{combine, combine_key};
use super::lanes::Lanes;
use super::layout::{Layout, SetShape, StreamKey};
use crate::simd::{F8, U8};

/// Point k of the n-point Owen-scrambled Sobol' set of stream (pixel, sample, dim) under seed:
/// index `sample * n + k` (wrapping; n == 0 acts as 1). Any inputs; both coordinates in [0, 1), on
/// the 2^-24 grid.
pub fn sobol_owen_2d(pixel: u32, sample: u32, dim: u32, k: u32, n: u32, seed: u64) -> [f32; 2] {
    let (x, y) = sobol_owen(pixel, sample, dim, k, n, seed);
    [x, y]
}

/// Eight lanes of [`sobol_owen_2d`], lane i = sobol_owen_2d(pixel[i], sample[i], dim, k[i], n,
/// seed), bit-identical to it; coordinates in [0, 1).
pub fn sobol_owen_2d_x8(pixel: U8, sample: U8, dim: u32, k: U8, n: u32, seed: u64) -> (F8, F8) {
    sobol_owen(pixel, sample, dim, k, n, seed)
}

const TAG_SOBOL: u32 = 0x50b0_1002;

/// Owen-scrambled Sobol' (dimensions 0, 1; hash-based nested scrambling) at `sample * n + k`.
#[derive(Clone, Copy, Debug)]
pub struct Sobol;

/// Its entry in the registry [`super::SAMPLERS`].
pub(super) const INFO: super::SamplerInfo =
    super::SamplerInfo::new("sobol", &[], "Owen-scrambled Sobol'", &Sobol).period(1 << 32);

impl Layout for Sobol {
    #[inline]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        sobol_owen(pixel, sample, dim, k, set.n(), seed)
    }

    /// The stream's key (hash of pixel, dim and seed) in `prefix` and its first index
    /// `sample * n` in `base`, hashed once for all the points of the stream.
    #[inline]
    fn stream<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        StreamKey::new(stream_key(pixel, dim, seed), sample.mul(L::splat(set.n().max(1))), sample, dim, seed)
    }

    #[inline]
    fn stream_point<L: Lanes>(&self, _: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        keyed_point(s.prefix, s.base.add(L::splat(k)))
    }
}

/// The scramble key of the streams of `pixel` in dimension `dim` under `seed`.
#[inline]
fn stream_key<L: Lanes>(pixel: L, dim: u32, seed: u64) -> L {
    combine(L::splat(combine_key(TAG_SOBOL, seed, dim)), pixel)
}

fn sobol_owen<L: Lanes>(pixel: L, sample: L, dim: u32, k: L, n: u32, seed: u64) -> (L::F, L::F) {
    keyed_point(stream_key(pixel, dim, seed), sample.mul(L::splat(n.max(1))).add(k))
}

/// Point `index` of the sequence scrambled with stream key `key` (also `zsobol`'s point, with its
/// own key and index).
#[inline]
pub(super) fn keyed_point<L: Lanes>(key: L, index: L) -> (L::F, L::F) {
    // The index shuffle i' = nus(index) = rev(lk(rev(index))).
    let i = reverse_bits(lk_permute(reverse_bits(index), combine(key, L::splat(1))));
    let (x, y) = scrambled_point(i, key);
    (x.unit24(), y.unit24())
}

/// A keyed permutation of u32 that keeps every prefix `[0, 2^m)` (and every block
/// `[2^m, 2^(m+1))`) as a set: the highest set bit of `i` stays, and each bit below it is flipped
/// by a keyed function of the bits above it (a nested, top-down scramble of the index). Two
/// dimensions that draw index i of the same base-2 construction (pmj02's tables, Halton's radical
/// inverse, ZSobol's pixel block) are correlated however each is scrambled; shuffling the index
/// per dimension with this permutation decorrelates them, while the first 2^m indices of a stream
/// are still exactly the first 2^m points of the sequence (so nets and stratification of prefixes
/// are kept, and the sequence stays progressive).
///
/// It is Burley's `nus` (bit reversal, Laine-Karras-style hash, bit reversal) with the hash's two
/// key additions left out ([`lk_shift_free`]): the multiplications alone keep the lowest set bit of
/// the reversed index and the zeros below it, i.e. the highest set bit of the index and the zeros
/// above it, so no correction is needed. Until issue 33 it was `nus(i) ^ (nus(0) & top)` (two
/// hashes, four reversals); this is one hash and two reversals.
#[inline]
pub(super) fn prefix_shuffle<L: Lanes>(i: L, key: L) -> L {
    prefix_shuffle_with(i, &prefix_shuffle_key(key))
}

/// The multipliers [`prefix_shuffle`] derives from its key: what every index shuffled under one
/// key shares (a stream computes them once, [`prefix_shuffle_with`] uses them).
#[inline]
pub(super) fn prefix_shuffle_key<L: Lanes>(key: L) -> [L; 3] {
    [rotl(key, 11).shl(1), rotl(key, 22).or(L::splat(1)), rotl(key, 27).shl(1)]
}

/// [`prefix_shuffle`] of `i` under the key whose [`prefix_shuffle_key`] is `m`: the same bits.
#[inline]
pub(super) fn prefix_shuffle_with<L: Lanes>(i: L, m: &[L; 3]) -> L {
    reverse_bits(lk_shift_free(reverse_bits(i), m))
}

/// [`lk_permute`] without its key additions: bit j of the result is bit j of `x` XOR a keyed
/// function of the bits below j, and that function is 0 while those bits are all 0 (every step is
/// a multiplication by an odd number or an XOR with `x` times an even number), so 0 stays 0 and
/// the lowest set bit stays.
#[inline]
fn lk_shift_free<L: Lanes>(x: L, m: &[L; 3]) -> L {
    let x = x.xor(x.mul(m[0]));
    let x = x.mul(m[1]);
    let x = x.xor(x.mul(L::splat(0x6d4e_1c2a)));
    x.xor(x.mul(m[2]))
}

/// Sobol' point `i` (dimensions 0, 1), Owen-scrambled with the axis keys `combine(key, 2)` and
/// `combine(key, 3)`, as 24-bit fixed point (no index shuffle: callers choose the index). A
/// building block for layouts that order the sequence themselves (`zsobol`).
#[inline]
pub(super) fn scrambled_point<L: Lanes>(i: L, key: L) -> (L, L) {
    // x = nus(vdc(i')) = rev(lk(rev(rev(i')))) = rev(lk(i')); y = nus(rev(pascal(i'))) = rev(lk(pascal(i'))).
    let x = reverse_bits(lk_permute(i, combine(key, L::splat(2))));
    let y = reverse_bits(lk_permute(pascal(i), combine(key, L::splat(3))));
    (x.shr(8), y.shr(8))
}

/// Sobol' dimension 1 before the final bit reversal: bit r of the result is the XOR of the bits c
/// of `i` with r a subset of c (binom(c, r) odd), i.e. the reversed value `sum_c i_c v_{c+1}`.
#[inline]
fn pascal<L: Lanes>(i: L) -> L {
    let mut e = i;
    for (s, m) in [(1, 0x5555_5555), (2, 0x3333_3333), (4, 0x0f0f_0f0f), (8, 0x00ff_00ff), (16, 0x0000_ffff)] {
        e = e.xor(e.shr(s).and(L::splat(m)));
    }
    e
}

/// Laine-Karras-style keyed permutation of u32: each step maps bit j to bit j XOR a function of
/// bits 0..j-1 (of x and the key): adding, multiplying by an odd number and XOR with x times an
/// even number only carry upwards. Key-dependent multipliers (rotations of the key) make the flips
/// depend on the key non-linearly, which Burley's fixed multipliers do not.
#[inline]
pub(super) fn lk_permute<L: Lanes>(x: L, key: L) -> L {
    let x = x.add(key);
    let x = x.xor(x.mul(rotl(key, 11).shl(1)));
    let x = x.mul(rotl(key, 22).or(L::splat(1)));
    let x = x.xor(x.mul(L::splat(0x6d4e_1c2a)));
    let x = x.add(rotl(key, 7));
    x.xor(x.mul(rotl(key, 27).shl(1)))
}

#[inline]
fn rotl<L: Lanes>(x: L, s: u32) -> L {
    x.shl(s).or(x.shr(32 - s))
}

/// Nested uniform (Owen) scramble of the 24-bit fixed-point coordinate `x` under `key`: digit j
/// (from the top) is flipped by a keyed function of the digits above it.
#[inline]
pub(super) fn owen24<L: Lanes>(x: L, key: L) -> L {
    reverse_bits(lk_permute(reverse_bits(x.shl(8)), key)).shr(8)
}

/// Reverses the 32 bits of every lane.
#[inline]
pub(super) fn reverse_bits<L: Lanes>(x: L) -> L {
    let mut x = x.shr(16).or(x.shl(16));
    for (s, m) in [(8, 0x00ff_00ff), (4, 0x0f0f_0f0f), (2, 0x3333_3333), (1, 0x5555_5555)] {
        x = x.shr(s).and(L::splat(m)).or(x.and(L::splat(m)).shl(s));
    }
    x
}

// ------------------------------------------------------------------------------------------------
// Tests
// ------------------------------------------------------------------------------------------------

#[cfg(test)]
pub(super) mod tests {
    use super::super::hash::fmix;
    use super::*;

    /// Small deterministic generator for test inputs.
    pub(in crate::sampler) fn lcg(state: &mut u64) -> u32 {
        *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (*state >> 32) as u32
    }

    /// 24-bit fixed-point value of a coordinate (exact).
    pub(in crate::sampler) fn fixed(x: f32) -> u32 {
        let y = f64::from(x) * 16_777_216.0;
        assert!(y.fract() == 0.0 && (0.0..16_777_216.0).contains(&y), "{x} is not on the 2^-24 grid in [0, 1)");
        y as u32
    }

    /// Panics unless the 2^m points are a (0, m, 2)-net: one point in each 2^-a x 2^-(m-a) box.
    pub(in crate::sampler) fn assert_net(pts: &[[f32; 2]], what: &str) {
        let m = pts.len().trailing_zeros();
        assert_eq!(pts.len(), 1 << m);
        let mut seen = vec![0u32; pts.len()];
        for a in 0..=m {
            let stamp = a + 1;
            for p in pts {
                let (cx, cy) = (fixed(p[0]) >> (24 - a), fixed(p[1]) >> (24 - (m - a)));
                let c = ((cy << a) | cx) as usize;
                assert_ne!(seen[c], stamp, "{what}: box 2^-{a} x 2^-{} ({cx}, {cy}) hit twice", m - a);
                seen[c] = stamp;
            }
        }
    }

    /// The 32 direction numbers v_1..v_32 of Sobol' dimension 1 as 32-bit binary fractions
    /// (`v_j = m_j * 2^(32 - j)`, from x + 1 and m_1 = 1): 0x8000_0000, 0xc000_0000, 0xa000_0000, ...
    const fn direction_numbers() -> [u32; 32] {
        let (mut v, mut m, mut j) = ([0u32; 32], 1u32, 0);
        while j < 32 {
            v[j] = m << (31 - j);
            m ^= m << 1; // m_{j+1} = m_j XOR 2 m_j (m_j < 2^j, so only the unused m_33 overflows)
            j += 1;
        }
        v
    }

    #[test]
    fn fast_transform_matches_direction_numbers() {
        let v = direction_numbers();
        assert_eq!(
            &v[..8],
            &[0x8000_0000, 0xc000_0000, 0xa000_0000, 0xf000_0000, 0x8800_0000, 0xcc00_0000, 0xaa00_0000, 0xff00_0000]
        );
        let reference = |i: u32| (0..32).filter(|&c| i >> c & 1 == 1).fold(0, |acc, c| acc ^ v[c]);
        let mut st = 3u64;
        let idx = (0..1u32 << 16).chain((0..100_000).map(|_| lcg(&mut st))).chain([u32::MAX, 1 << 31]);
        for i in idx {
            assert_eq!(reverse_bits(pascal(i)), reference(i), "i = {i}");
            assert_eq!(reverse_bits(i), i.reverse_bits());
        }
        // Natural-order Sobol' points 0..8: x = van der Corput, y = dimension 1.
        let y: Vec<f64> = (0..8u32).map(|i| f64::from(reverse_bits(pascal(i))) / 2f64.powi(32)).collect();
        assert_eq!(y, [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875]);
    }

    #[test]
    fn prefix_shuffle_keeps_every_prefix_and_moves_low_bits() {
        let mut st = 5u64;
        for _ in 0..40 {
            let key = lcg(&mut st);
            for m in 0..=12u32 {
                let mut seen = vec![false; 1 << m];
                for i in 0..1u32 << m {
                    let j = prefix_shuffle(i, key);
                    assert!(j < 1 << m, "key {key:#x} m {m}: {i} -> {j}");
                    assert!(!std::mem::replace(&mut seen[j as usize], true), "not a permutation");
                    if i > 0 {
                        assert_eq!(31 - j.leading_zeros(), 31 - i.leading_zeros(), "highest bit moved");
                    }
                }
            }
            for i in [u32::MAX, 1 << 31, 0x1234_5678] {
                assert_eq!(prefix_shuffle(i, key).leading_zeros(), i.leading_zeros());
            }
        }
        // Two keys: the lowest index bit (the top digit of a radical inverse) agrees for about
        // half of the indices, not for all of them (what made dimensions correlated).
        let same = (0..4096u32).filter(|&i| (prefix_shuffle(i, 17) ^ prefix_shuffle(i, 99)) & 1 == 0).count();
        assert!((1600..2500).contains(&same), "{same}");
    }

    #[test]
    fn lk_permute_is_a_nested_scramble() {
        // Flipping input bit q flips output bit q and leaves bits below q unchanged: bit j of the
        // output is bit j of the input XOR a function of the lower bits (and a bijection).
        let mut st = 11u64;
        for _ in 0..20_000 {
            let (x, key, q) = (lcg(&mut st), lcg(&mut st), lcg(&mut st) % 32);
            let d = lk_permute(x, key) ^ lk_permute(x ^ (1 << q), key);
            assert_eq!(d & ((2u64 << q) - 1) as u32, 1 << q, "x {x:#x} key {key:#x} q {q}");
        }
    }

    /// Histogram over 2^21 keys of the digit flips of the top `levels` levels (one flip per level
    /// and prefix of higher digits: 2^levels - 1 bits): (distinct patterns, chi-square z-score).
    fn flip_patterns(levels: u32) -> (usize, f64) {
        let keys = 1u32 << 21;
        let cells = 1usize << ((1 << levels) - 1);
        let mut hist = vec![0u32; cells];
        for s in 0..keys {
            let key = fmix(s ^ 0x1234_5678);
            let mut pattern = 0usize;
            for r in 0..levels {
                for p in 0..1u32 << r {
                    pattern = pattern << 1 | ((lk_permute(p, key) ^ p) >> r & 1) as usize;
                }
            }
            hist[pattern] += 1;
        }
        let e = f64::from(keys) / cells as f64;
        let chi2: f64 = hist.iter().map(|&c| (f64::from(c) - e).powi(2) / e).sum();
        let df = (cells - 1) as f64;
        (hist.iter().filter(|&&c| c > 0).count(), (chi2 - df) / (2.0 * df).sqrt())
    }

    // Measured: levels 1, 2 uniform (z 1.9, 0.1); level 3: all 128 patterns, z ~ 3.3e4;
    // level 4: 6720 of 32768 patterns. (Burley's fixed-multiplier hash: 4, 8 and 16 patterns.)
    #[test]
    fn lk_permute_top_levels() {
        for levels in 1..=4 {
            let (distinct, z) = flip_patterns(levels);
            println!("lk_permute flips of the top {levels} levels: {distinct} patterns, z {z:.1}");
            match levels {
                1 | 2 => assert!(z.abs() < 5.0, "levels {levels}: z {z}"),
                3 => assert_eq!(distinct, 128),
                _ => assert!(distinct >= 4096, "{distinct}"),
            }
        }
    }

    /// Exact nested uniform scramble (reference): bit r of the reversed value flipped by a hash
    /// of (key, r, bits 0..r-1).
    fn owen_reference(x: u32, key: u32) -> u32 {
        (0..32u32).fold(x, |out, r| {
            let below = x & ((1u64 << r) - 1) as u32;
            out ^ (combine(combine(key, r), below) >> 31) << r
        })
    }

    // Measured (20 000 pixels): variance(exact) / variance(lk) = 0.984 at n = 16 and at n = 64.
    #[test]
    fn lk_scramble_variance_matches_exact_owen_scramble() {
        let pixels = 20_000;
        for n in [16u32, 64] {
            let (_, var) = estimate_stats(n, pixels, |p, k| sobol_owen_2d(p, 0, 0, k, n, 5));
            let (_, var_ref) = estimate_stats(n, pixels, |p, k| {
                let key = fmix(p ^ 0x0e1f_2a3b);
                let x = reverse_bits(owen_reference(k, combine(key, 2)));
                let y = reverse_bits(owen_reference(pascal(k), combine(key, 3)));
                [(x >> 8).unit24(), (y >> 8).unit24()]
            });
            println!("n {n}: variance exact Owen / LK hash = {:.3}", var_ref / var);
            assert!((0.8..1.25).contains(&(var_ref / var)), "n {n}: {var_ref} vs {var}");
        }
    }

    /// A 2D generator's x8 and scalar forms agree bit for bit over random and extreme inputs.
    pub(in crate::sampler) fn assert_x8_matches_scalar(
        scalar: fn(u32, u32, u32, u32, u32, u64) -> [f32; 2],
        x8: fn(U8, U8, u32, U8, u32, u64) -> (F8, F8),
        mut st: u64,
    ) {
        for round in 0..4000 {
            let pick = |st: &mut u64| match lcg(st) % 4 {
                0 => lcg(st) % 8,
                1 => u32::MAX - lcg(st) % 8,
                _ => lcg(st),
            };
            let (px, sa, kk): ([u32; 8], [u32; 8], [u32; 8]) = (
                std::array::from_fn(|_| pick(&mut st)),
                std::array::from_fn(|_| pick(&mut st)),
                std::array::from_fn(|_| pick(&mut st)),
            );
            let (dim, n) = (pick(&mut st), if round % 3 == 0 { 0 } else { pick(&mut st) % 300 });
            let seed = u64::from(lcg(&mut st)) << 32 | u64::from(pick(&mut st));
            let (xs, ys) = x8(U8::new(px), U8::new(sa), dim, U8::new(kk), n, seed);
            for i in 0..8 {
                let p = scalar(px[i], sa[i], dim, kk[i], n, seed);
                assert_eq!([xs.to_array()[i].to_bits(), ys.to_array()[i].to_bits()], p.map(f32::to_bits));
                fixed(p[0]);
                fixed(p[1]);
            }
        }
    }

    #[test]
    fn scalar_and_x8_agree_bit_for_bit() {
        assert_x8_matches_scalar(sobol_owen_2d, sobol_owen_2d_x8, 5);
    }

    #[test]
    fn index_conventions() {
        for k in 0..12 {
            // n == 0 acts as 1; k >= n continues into the next pixel sample.
            assert_eq!(sobol_owen_2d(4, k, 2, 0, 0, 9), sobol_owen_2d(4, 0, 2, k, 1, 9));
            assert_eq!(sobol_owen_2d(4, 3, 2, k, 6, 9), sobol_owen_2d(4, 2, 2, k + 6, 6, 9));
        }
    }

    #[test]
    fn nets_after_scrambling() {
        for (pixel, dim, seed) in [(0, 0, 0), (1, 1, 7), (77, 5, 3), (123_456, 13, u64::MAX), (u32::MAX, 2, 42)] {
            for m in 0..=10 {
                let n = 1u32 << m;
                // The first 2^m points of the pixel's sequence, and the n-point sets of samples 1 and 9.
                for sample in [0, 1, 9] {
                    let pts: Vec<_> = (0..n).map(|k| sobol_owen_2d(pixel, sample, dim, k, n, seed)).collect();
                    assert_net(&pts, &format!("pixel {pixel} dim {dim} m {m} sample {sample}"));
                }
            }
        }
        // Finer: 2^16 points, checked at the levels a + b = 16.
        let pts: Vec<_> = (0..1 << 16).map(|k| sobol_owen_2d(31, 0, 4, k, 1 << 16, 5)).collect();
        assert_net(&pts, "m 16");
    }

    #[test]
    fn scrambled_per_pixel_dim_and_seed() {
        let base: Vec<_> = (0..16).map(|k| sobol_owen_2d(1, 0, 0, k, 16, 0)).collect();
        for (pixel, dim, seed) in [(2, 0, 0), (1, 1, 0), (1, 0, 1)] {
            let other: Vec<_> = (0..16).map(|k| sobol_owen_2d(pixel, 0, dim, k, 16, seed)).collect();
            assert!(base.iter().zip(&other).all(|(a, b)| a != b), "{pixel} {dim} {seed}");
        }
        // First points of many pixels are spread out (no shared unscrambled origin).
        let mut firsts: Vec<_> = (0..1000).map(|p| sobol_owen_2d(p, 0, 0, 0, 16, 0).map(f32::to_bits)).collect();
        firsts.sort_unstable();
        firsts.dedup();
        assert_eq!(firsts.len(), 1000);
    }

    pub(in crate::sampler) fn integrand(u: f64, v: f64) -> f64 {
        (-((u - 0.3).powi(2) + (v - 0.6).powi(2)) * 8.0).exp()
    }

    /// Exact integral of [`integrand`] over the unit square: product of two 1D Gaussian integrals,
    /// by composite Simpson with 20 000 intervals.
    pub(in crate::sampler) fn exact_integral() -> f64 {
        let simpson = |c: f64| {
            let (m, h) = (20_000, 1.0 / 20_000.0);
            let f = |u: f64| (-8.0 * (u - c).powi(2)).exp();
            let inner: f64 = (1..m).map(|i| f(f64::from(i) * h) * if i % 2 == 1 { 4.0 } else { 2.0 }).sum();
            (f(0.0) + f(1.0) + inner) * h / 3.0
        };
        simpson(0.3) * simpson(0.6)
    }

    /// Mean and variance over `pixels` of the n-point estimate of [`integrand`] with `point(pixel, k)`.
    pub(in crate::sampler) fn estimate_stats(n: u32, pixels: u32, point: impl Fn(u32, u32) -> [f32; 2]) -> (f64, f64) {
        let est: Vec<f64> = (0..pixels)
            .map(|p| {
                (0..n).map(|k| point(p, k)).map(|[u, v]| integrand(f64::from(u), f64::from(v))).sum::<f64>()
                    / f64::from(n)
            })
            .collect();
        let mean = est.iter().sum::<f64>() / est.len() as f64;
        let var = est.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (est.len() - 1) as f64;
        (mean, var)
    }

    /// Independent uniform points for the reference variance.
    pub(in crate::sampler) fn random_point(pixel: u32, k: u32, seed: u32) -> [f32; 2] {
        let h = combine(combine(fmix(seed ^ 0x7a3d_0001), pixel), k);
        [(h >> 8).unit24(), (fmix(h ^ 0x5bd1_e995) >> 8).unit24()]
    }

    // Measured (n = 16, 2000 pixels): Var(random) / Var(sobol) = 23.6 (seed 2024), 21.5 (seed 7).
    #[test]
    fn integration_is_unbiased_with_low_variance() {
        let exact = exact_integral();
        let (n, pixels) = (16, 2000);
        for seed in [2024u32, 7] {
            let (mean, var) = estimate_stats(n, pixels, |p, k| sobol_owen_2d(p, 0, 3, k, n, u64::from(seed)));
            let (rmean, rvar) = estimate_stats(n, pixels, |p, k| random_point(p, k, seed));
            let se = (var / f64::from(pixels)).sqrt();
            let rse = (rvar / f64::from(pixels)).sqrt();
            println!(
                "sobol seed {seed}: mean {mean:.6} vs exact {exact:.6}; variance ratio random/sobol {:.1}",
                rvar / var
            );
            assert!((mean - exact).abs() < 4.0 * se, "mean {mean} exact {exact} se {se}");
            assert!((rmean - exact).abs() < 4.0 * rse, "random mean {rmean} exact {exact} se {rse}");
            assert!(rvar / var >= 8.0, "ratio {}", rvar / var);
        }
    }
}

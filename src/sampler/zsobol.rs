//! `zsobol`: Owen-scrambled Sobol' points indexed in Morton (Z) order over the pixels, after Ahmed
//! and Wonka 2020, "Screen-space blue-noise diffusion of Monte Carlo sampling error via
//! hierarchical ordering of pixels" (SIGGRAPH Asia), as pbrt-v4's ZSobolSampler describes it.
//!
//! All pixels share one Owen-scrambled Sobol' sequence (keyed by seed, dim and pixel sample, not
//! by pixel). Pixel (x, y) owns the aligned index block `[m' 2^b, (m' + 1) 2^b)`, with
//! `b = ceil(log2 n)` and `m'` its Morton index with every base-4 digit (a 2x2 quadrant choice)
//! replaced by a random permutation of the four quadrants keyed by the digits above it and by
//! (seed, dim). The permutation is nested, so every aligned 2^l x 2^l block of pixels still owns
//! one aligned index block of 4^l 2^b indices, whose points form a (0, 2l + b, 2)-net: neighbouring
//! pixels get complementary points, and the error is spread like blue noise over the image, while
//! each pixel's n = 2^b points are a (0, b, 2)-net, as with `sobol`.
//!
//! Point k of the set of (pixel, sample, dim) is index `m' 2^b + P(k mod 2^b)` of the sequence
//! scrambled for pixel sample `sample + k / 2^b` (so k >= 2^b continues in a fresh scramble), P a
//! per-(pixel, dim) shuffle keeping every prefix [0, 2^m) (`sobol::prefix_shuffle`), which
//! decorrelates the dims of one pixel. For
//! the camera use `n = spp, k = s, sample = 0`. Pixel coordinates come from the set's image width
//! ([`SetShape::pixel_xy`], `pixel = y * width + x`); with an unknown width (0) the linear pixel id
//! itself is used as the Morton index. Coordinates use 16 bits each (images up to 65536 wide), and
//! `m' 2^b` wraps in u32: distant pixels of images with more than 2^32 / 2^b pixels share blocks.

use super::hash::{combine, combine_key};
use super::lanes::Lanes;
use super::layout::{Layout, SetShape, StreamKey};
use super::sobol::{prefix_shuffle, scrambled_point};

const TAG_ZSOBOL: u32 = 0x50b0_1005;

/// Owen-scrambled Sobol' in Morton order over pixels, with hashed quadrant permutations.
#[derive(Clone, Copy, Debug)]
pub struct ZSobol;

/// Its entry in the registry [`super::SAMPLERS`].
pub(super) const INFO: super::SamplerInfo =
    super::SamplerInfo::new("zsobol", &["z-sobol"], "Sobol' in Morton order over pixels", &ZSobol).needs_count();

/// The 24 permutations of the four quadrants, lexicographic: entry `4 p + d` is digit d under
/// permutation p.
const PERMS: [u32; 96] = {
    let (mut t, mut i, mut a) = ([0u32; 96], 0, 0);
    while a < 4 {
        let mut b = 0;
        while b < 4 {
            let mut c = 0;
            while c < 4 {
                if a != b && a != c && b != c {
                    let d = 6 - a - b - c; // the remaining quadrant
                    t[4 * i] = a;
                    t[4 * i + 1] = b;
                    t[4 * i + 2] = c;
                    t[4 * i + 3] = d;
                    i += 1;
                }
                c += 1;
            }
            b += 1;
        }
        a += 1;
    }
    t
};

/// [`PERMS`] packed for [`perm4`]: permutation p is byte `p % 4` of word `p / 4`, digit d's image
/// in bits 2d..2d+1 of that byte (words 6 and 7 unused).
const PACKED: [u32; 8] = {
    let mut t = [0u32; 8];
    let mut i = 0;
    while i < 96 {
        let (p, d) = (i / 4, i % 4);
        t[p / 4] |= PERMS[i] << (8 * (p % 4) + 2 * d);
        i += 1;
    }
    t
};

/// `PERMS[4 p + d]` per lane (p < 24, d < 4) without a per-lane memory look-up: one 8-entry lane
/// look-up of [`PACKED`] and a per-lane shift.
#[inline]
fn perm4<L: Lanes>(p: L, d: L) -> L {
    p.shr(2).lookup8(PACKED).shr_var(p.and(L::splat(3)).shl(3).or(d.shl(1))).and(L::splat(3))
}

/// log2 of the per-pixel index block: ceil(log2 n), n >= 1.
fn block_bits(set: &SetShape) -> u32 {
    32 - (set.n() - 1).leading_zeros()
}

/// Spreads the low 16 bits of x to the even bit positions.
#[inline]
fn part1by1<L: Lanes>(x: L) -> L {
    let mut x = x.and(L::splat(0xffff));
    for (s, m) in [(8, 0x00ff_00ff), (4, 0x0f0f_0f0f), (2, 0x3333_3333), (1, 0x5555_5555)] {
        x = x.or(x.shl(s)).and(L::splat(m));
    }
    x
}

/// The permuted Morton index `m'` of `pixel`, shifted to its block: `m' 2^b` (wrapping).
#[inline]
fn block_start<L: Lanes>(set: &SetShape, pixel: L, dim: u32, seed: u64) -> L {
    let b = block_bits(set);
    if b >= 32 {
        return L::splat(0);
    }
    let m = if set.width() == 0 {
        pixel
    } else {
        let (x, y) = set.pixel_xy(pixel);
        part1by1(x).or(part1by1(y).shl(1))
    };
    // Only the digits that survive the shift by b matter.
    let levels = (33 - b) / 2;
    let key_1 = combine_key(TAG_ZSOBOL, seed, dim);
    let key = L::splat(key_1);
    // Levels at and above the highest digit of every lane's m have digit 0 and no digit above:
    // their prefix, permutation and output digit are the same for every lane (computed once, in
    // scalar code; in an image the top levels are all such).
    let top = m.max_lane();
    let (mut uniform, mut out) = (0u32, L::splat(0));
    for l in (0..levels).rev() {
        let above = levels - 1 - l;
        if top >> (2 * l) == 0 {
            let perm = combine(key_1, 1u32 << (2 * above)).mulhi(24);
            uniform |= PERMS[4 * perm as usize] << (2 * l);
            continue;
        }
        // Higher digits plus a marker bit: unique per (level, prefix).
        let prefix = m.shr(2 * l + 2).and(L::splat((1 << (2 * above)) - 1)).or(L::splat(1 << (2 * above)));
        let perm = combine(key, prefix).mulhi(L::splat(24));
        let digit = m.shr(2 * l).and(L::splat(3));
        out = out.or(perm4(perm, digit).shl(2 * l));
    }
    out.or(L::splat(uniform)).shl(b)
}

/// Point `k` of the stream whose block starts at `start`.
#[inline]
fn block_point<L: Lanes>(set: &SetShape, start: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
    let b = block_bits(set);
    let (low, high) = if b >= 32 { (k, L::splat(0)) } else { (k.and(L::splat((1 << b) - 1)), k.shr(b)) };
    let key = combine(L::splat(combine_key(TAG_ZSOBOL, seed, dim)), sample.add(high));
    // The pixel's own indices shuffled per (pixel, dim), keeping every prefix [0, 2^m) (so the
    // pixel's first 2^m points stay a net): otherwise every dim of a pixel draws the same index
    // and their top digits are tied (a light choice follows the light point).
    let low = prefix_shuffle(low, combine(key, start.or(L::splat(1 << 31))));
    let (x, y) = scrambled_point(start.or(low), key);
    (x.unit24(), y.unit24())
}

impl Layout for ZSobol {
    #[inline]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        block_point(set, block_start(set, pixel, dim, seed), sample, dim, k, seed)
    }

    #[inline]
    fn stream<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        StreamKey { prefix: block_start(set, pixel, dim, seed), base: L::splat(0), sample, dim, seed }
    }

    #[inline]
    fn stream_point<L: Lanes>(&self, set: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        block_point(set, s.prefix, s.sample, s.dim, L::splat(k), s.seed)
    }
}

#[cfg(test)]
mod tests {
    use super::super::sobol::tests::{assert_net, estimate_stats, exact_integral, random_point};
    use super::super::{PointSet, SamplerKind};

    fn zsobol(n: u32, width: u32) -> PointSet {
        PointSet::for_image(SamplerKind::parse("zsobol").expect("registered"), n, width)
    }

    #[test]
    fn packed_permutations_equal_the_table() {
        use crate::simd::U8;
        for p in 0..24u32 {
            for d in 0..4u32 {
                assert_eq!(super::perm4(p, d), super::PERMS[(4 * p + d) as usize], "p {p} d {d}");
            }
            let d8 = U8::new([0, 1, 2, 3, 3, 2, 1, 0]);
            let got = super::perm4(U8::splat(p), d8).to_array();
            let want = d8.to_array().map(|d| super::PERMS[(4 * p + d) as usize]);
            assert_eq!(got, want, "p {p}");
        }
    }

    #[test]
    fn permutations_are_all_distinct() {
        let mut perms: Vec<_> = super::PERMS.chunks(4).collect();
        assert!(perms.iter().all(|p| (0..4).all(|d| p.contains(&d))));
        perms.sort_unstable();
        perms.dedup();
        assert_eq!(perms.len(), 24);
    }

    #[test]
    fn every_pixel_set_is_a_net() {
        for width in [0, 1, 7, 640] {
            for (pixel, dim, seed) in [(0, 0, 0), (1, 1, 7), (77, 5, 3), (123_456, 13, u64::MAX), (u32::MAX, 2, 42)] {
                for m in 0..=10 {
                    let set = zsobol(1 << m, width);
                    for sample in [0, 1, 9] {
                        let pts: Vec<_> = (0..1 << m).map(|k| set.point(pixel, sample, dim, k, seed)).collect();
                        assert_net(&pts, &format!("width {width} pixel {pixel} dim {dim} m {m} sample {sample}"));
                    }
                }
            }
        }
    }

    /// The Morton property behind the blue noise: the points of every aligned 2^l x 2^l pixel block
    /// together form a (0, 2l + b, 2)-net.
    #[test]
    fn aligned_pixel_blocks_are_nets() {
        let width = 64;
        for (b, l) in [(0, 1), (0, 2), (0, 3), (2, 1), (2, 2), (1, 2), (3, 1)] {
            let set = zsobol(1 << b, width);
            for (dim, seed) in [(0, 0), (3, 9), (17, u64::MAX)] {
                for (bx, by) in [(0, 0), (1, 0), (2, 3), (7, 7)] {
                    let side = 1u32 << l;
                    let (x0, y0) = (bx * side % width, by * side % width);
                    let mut pts = Vec::new();
                    for y in y0..y0 + side {
                        for x in x0..x0 + side {
                            pts.extend((0..1 << b).map(|k| set.point(y * width + x, 0, dim, k, seed)));
                        }
                    }
                    assert_net(&pts, &format!("b {b} l {l} block ({bx}, {by}) dim {dim}"));
                }
            }
        }
    }

    #[test]
    fn neighbours_differ_across_dims_and_samples() {
        let set = zsobol(16, 32);
        let first = |pixel, sample, dim| set.point(pixel, sample, dim, 0, 5);
        assert_ne!(first(0, 0, 0), first(1, 0, 0));
        assert_ne!(first(0, 0, 0), first(0, 0, 1));
        assert_ne!(first(0, 0, 0), first(0, 1, 0));
        // k >= 2^b continues in the next pixel sample's scramble.
        for k in 0..16 {
            assert_eq!(set.point(9, 2, 3, k + 16, 5), set.point(9, 3, 3, k, 5));
        }
    }

    // Measured (n = 16, 2000 pixels): Var(random) / Var(zsobol) = 34.0 (seed 2024, width 0), 31.7 (seed 7, width 45).
    #[test]
    fn integration_is_unbiased_with_low_variance() {
        let exact = exact_integral();
        let (n, pixels) = (16, 2000);
        for (seed, width) in [(2024u32, 0), (7, 45)] {
            let set = zsobol(n, width);
            let (mean, var) = estimate_stats(n, pixels, |p, k| set.point(p, 0, 3, k, u64::from(seed)));
            let (_, rvar) = estimate_stats(n, pixels, |p, k| random_point(p, k, seed));
            let se = (var / f64::from(pixels)).sqrt();
            println!(
                "zsobol seed {seed}: mean {mean:.6} vs exact {exact:.6}; variance ratio random/zsobol {:.1}",
                rvar / var
            );
            assert!((mean - exact).abs() < 4.0 * se, "mean {mean} exact {exact} se {se}");
            assert!(rvar / var >= 8.0, "ratio {}", rvar / var);
        }
    }
}

//! `zsobol`: Owen-scrambled Sobol' points indexed in Morton (Z) order over the pixels, after Ahmed
//! and Wonka 2020, "Screen-space blue-noise diffusion of Monte Carlo sampling error via
//! hierarchical ordering of pixels" (SIGGRAPH Asia), as pbrt-v4's ZSobolSampler describes it.
//!
//! All pixels share one Owen-scrambled Sobol' sequence (keyed by seed, dim and pixel sample, not
//! by pixel). Pixel (x, y) owns the aligned index block `[m 2^b, (m + 1) 2^b)` of the sequence
//! *before* its index shuffle, with `b = ceil(log2 n)` and `m` its Morton index: point k of the
//! set of (pixel, sample, dim) is `sobol`'s keyed point (`sobol::keyed_point`: Burley's nested
//! index shuffle `nus`, then the Owen-scrambled x and y) of index `m 2^b + (k mod 2^b)` under the
//! key of (seed, dim, pixel sample `sample + k / 2^b`), so k >= 2^b continues in a fresh scramble.
//!
//! The index shuffle is a nested scramble of the whole index (bit j flipped by a keyed function of
//! the bits above it), so it does at once what the layout needs:
//! - the Morton index is scrambled level by level (every base-4 digit, a 2x2 quadrant choice,
//!   goes through a permutation of the quadrants chosen by the digits above it), and every aligned
//!   2^l x 2^l block of pixels still owns one aligned index block of 4^l 2^b indices, whose points
//!   form a (0, 2l + b, 2)-net: neighbouring pixels get complementary points, and the error is
//!   spread like blue noise over the image;
//! - a pixel's own 2^b indices are permuted by a function of its Morton bits and the dim's key,
//!   keeping aligned blocks (so the pixel's n = 2^b points, and its first 2^j, are nets, as with
//!   `sobol`), which decorrelates the dims of one pixel.
//!
//! Issue 33: until then each Morton digit took one of all 24 quadrant permutations from a hash of
//! the digits above it, as pbrt-v4's ZSobolSampler does (one 32-bit hash per level and lane), and
//! the pixel's indices a separate shuffle: 2.3x Sobol's cost. The base-2 nested scramble draws
//! each digit's permutation from the 8 that keep the two quadrants of one Morton x bit together,
//! and costs one hash for every level; a point now costs a Sobol' point plus the Morton index.
//!
//! For the camera use `n = spp, k = s, sample = 0`. Pixel coordinates come from the set's image
//! width ([`SetShape::pixel_xy`], `pixel = y * width + x`); with an unknown width (0) the linear
//! pixel id itself is used as the Morton index. Coordinates use 16 bits each (images up to 65536
//! wide), and `m 2^b` wraps in u32: distant pixels of images with more than 2^32 / 2^b pixels share
//! blocks.

use super::hash::{combine, combine_key};
use super::lanes::Lanes;
use super::layout::{Layout, SetShape, StreamKey};
use super::sobol::keyed_point;

const TAG_ZSOBOL: u32 = 0x50b0_1005;

/// Owen-scrambled Sobol' in Morton order over pixels (one nested scramble of pixel and sample bits).
#[derive(Clone, Copy, Debug)]
pub struct ZSobol;

/// Its entry in the registry [`super::SAMPLERS`].
pub(super) const INFO: super::SamplerInfo =
    super::SamplerInfo::new("zsobol", &["z-sobol"], "Sobol' in Morton order over pixels", &ZSobol).needs_count();

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

/// The Morton index `m` of `pixel`, shifted to its block: `m 2^b` (wrapping).
#[inline]
fn block_start<L: Lanes>(set: &SetShape, pixel: L) -> L {
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
    m.shl(b)
}

/// The scramble key of pixel sample `sample` in dimension `dim` (every pixel's).
#[inline]
fn sample_key<L: Lanes>(sample: L, dim: u32, seed: u64) -> L {
    combine(L::splat(combine_key(TAG_ZSOBOL, seed, dim)), sample)
}

/// `(k mod 2^b, k / 2^b)`.
#[inline]
fn split_k<L: Lanes>(set: &SetShape, k: L) -> (L, L) {
    let b = block_bits(set);
    if b >= 32 {
        (k, L::splat(0))
    } else {
        (k.and(L::splat((1 << b) - 1)), k.shr(b))
    }
}

impl Layout for ZSobol {
    #[inline]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        let (low, high) = split_k(set, k);
        keyed_point(sample_key(sample.add(high), dim, seed), block_start(set, pixel).or(low))
    }

    /// The block start in `prefix` and the key of pixel sample `sample` in `base` (that of points
    /// k < 2^b).
    #[inline]
    fn stream<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        StreamKey::new(block_start(set, pixel), sample_key(sample, dim, seed), sample, dim, seed)
    }

    #[inline]
    fn stream_point<L: Lanes>(&self, set: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        let (low, high) = split_k(set, k);
        let key = if high == 0 { s.base } else { sample_key(s.sample.add(L::splat(high)), s.dim, s.seed) };
        keyed_point(key, s.prefix.or(L::splat(low)))
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

//! A tile's samples into its pixels' dyadic blocks (see `film`), 8 pixels (a packet) at once.
//!
//! The block list is the same for every pixel, so a pass's carries ([`PassBlocks`]) are worked
//! out once per pass. During a tile, each packet keeps its pixels' block stack in the worker's
//! scratch, `[level][moment][lane]`: loaded from the tile's moments once before the tile's first
//! batch ([`load`]), run through every batch in place ([`add_batch`]: a leaf per sample, combined
//! with its carries, lane-wise in vector registers) and stored once after the last ([`store`]).
//! The f64 additions are the ones `Film::add_sample` makes, in the same order, so the values are
//! bit-identical to it.

use crate::camera::PixelPacket;
use crate::film::{leaf_moments8, push_block, Block, Moments};
use crate::integrator::Counters;
use crate::simd::{i32x8, Vec3x8, F8};
use std::ops::Range;

/// The moments of one dyadic level for the 8 lanes of a packet: `[moment][lane]`.
pub(crate) type Moments8 = [[f64; 8]; 6];

/// How a pass's samples join the live blocks: the same for every pixel (the block list depends
/// only on the sample range).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct PassBlocks {
    /// live blocks before the pass
    pub depth: usize,
    /// per sample of the pass, how many blocks its leaf combines with ([`push_block`]'s count)
    pub carries: Vec<u8>,
    /// most blocks live at once during the pass: the height of a packet's stack
    pub height: usize,
    /// live blocks after the pass
    pub levels: usize,
}

impl PassBlocks {
    /// Pushes the leaves of `samples` onto `blocks` (which they must continue), recording how
    /// each combined.
    pub(crate) fn push(blocks: &mut Vec<Block>, samples: Range<u32>) -> Self {
        let depth = blocks.len();
        let mut height = depth;
        let carries = samples
            .map(|s| {
                let c = push_block(blocks, Block::leaf(s));
                height = height.max(blocks.len());
                c as u8 // at most 32: one per bit of a u32 sample index
            })
            .collect();
        Self { depth, carries, height, levels: blocks.len() }
    }
}

/// The index in the tile at `(x0, y0)`, `tw` pixels wide, of each lane's pixel (only active lanes
/// are meaningful: their coordinates are small whole numbers).
#[inline]
fn lane_pixels(pk: &PixelPacket, (x0, y0, tw): (u32, u32, u32)) -> [usize; 8] {
    let (x, y) = (pk.x.fast_trunc_int(), pk.y.fast_trunc_int());
    let j = ((y - i32x8::splat(y0 as i32)) * i32x8::splat(tw as i32) + (x - i32x8::splat(x0 as i32))).to_array();
    j.map(|j| j as usize)
}

/// Loads the blocks `0..stack.len()` of packet `pk`'s pixels from the tile's moments
/// (`data[level * tn + pixel in the tile]`, the tile at `origin` = `(x0, y0, tw)`). Only active
/// lanes are loaded: an inactive lane's values are never stored back.
pub(crate) fn load(stack: &mut [Moments8], data: &[Moments], tn: usize, pk: &PixelPacket, origin: (u32, u32, u32)) {
    let active = pk.active.to_bitmask();
    let j = lane_pixels(pk, origin);
    for (l, level) in stack.iter_mut().enumerate() {
        for i in (0..8).filter(|i| active & (1 << i) != 0) {
            let m = &data[l * tn + j[i]];
            for q in 0..6 {
                level[q][i] = m[q];
            }
        }
    }
}

/// Stores the blocks `0..stack.len()` of packet `pk`'s active pixels into the tile's moments (as
/// [`load`] reads them).
pub(crate) fn store(stack: &[Moments8], data: &mut [Moments], tn: usize, pk: &PixelPacket, origin: (u32, u32, u32)) {
    let active = pk.active.to_bitmask();
    let j = lane_pixels(pk, origin);
    for (l, level) in stack.iter().enumerate() {
        for i in (0..8).filter(|i| active & (1 << i) != 0) {
            data[l * tn + j[i]] = std::array::from_fn(|q| level[q][i]);
        }
    }
}

/// Adds a batch of samples to one packet's stack, which holds `top` live blocks: sample k's value
/// is `radiance.0[k * radiance.1]`, its leaf combined with the top `carries[k]` blocks (as
/// [`PassBlocks::push`] recorded). Leaves `top + carries.len() - sum(carries)` live blocks. A
/// non-finite lane value is counted in `counters.nonfinite` (active lanes only, as the bits of
/// `active`) and replaced by zero in every channel, so no NaN or Inf ever reaches the image.
#[inline]
pub(crate) fn add_batch(
    stack: &mut [Moments8],
    mut top: usize,
    carries: &[u8],
    (radiance, stride): (&[Vec3x8], usize),
    active: u32,
    counters: &mut Counters,
) {
    for (k, &c) in carries.iter().enumerate() {
        let l = &radiance[k * stride];
        let finite = l.is_finite();
        counters.nonfinite += u64::from((active & !finite.to_bitmask()).count_ones());
        // A non-finite lane is zero in every channel.
        let zero = F8::ZERO;
        let rgb = [finite.select(l.x, zero), finite.select(l.y, zero), finite.select(l.z, zero)].map(|c| c.to_array());
        let mut acc: Moments8 = leaf_moments8(rgb);
        for _ in 0..c {
            top -= 1;
            let left = &stack[top];
            for q in 0..6 {
                for i in 0..8 {
                    acc[q][i] += left[q][i];
                }
            }
        }
        stack[top] = acc;
        top += 1;
    }
}

/// Live blocks after a batch with `carries` on a stack of `top`.
pub(crate) fn top_after(top: usize, carries: &[u8]) -> usize {
    top + carries.len() - carries.iter().map(|&c| usize::from(c)).sum::<usize>()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Film;

    /// Passes of batches accumulated as the tile loop does (a packet's stack loaded once per pass,
    /// run through every batch of the pass in place, stored once) give the block moments of
    /// `Film::add_sample` one sample at a time, bit for bit, for passes that start and end
    /// anywhere in the binary counter; a clipped packet's inactive lanes are never stored.
    #[test]
    fn passes_of_batches_match_the_scalar_film() {
        let (tw, th) = (3u32, 2u32); // a 4x2 packet clipped to 3 columns
        let pk = PixelPacket::new(0, 0, tw, th);
        let tn = (tw * th) as usize;
        let mut st = 11u64;
        let mut next = || {
            st = st.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((st >> 40) as f32 / 16_777_216.0) * 5.0 - 1.0
        };
        let mut film = Film::new(tw, th);
        let (mut blocks, mut data, mut stack) = (Vec::new(), Vec::<Moments>::new(), Vec::<Moments8>::new());
        let mut c = Counters::default();
        let mut s = 0u32;
        // (pass length, batch size): passes ending at 37, 53, 64, 71, 100 samples
        for (n, batch) in [(37u32, 16u32), (16, 5), (11, 16), (7, 1), (29, 16)] {
            let pass = PassBlocks::push(&mut blocks, s..s + n);
            stack.resize(pass.height, [[f64::NAN; 8]; 6]);
            load(&mut stack[..pass.depth], &data, tn, &pk, (0, 0, tw));
            let mut top = pass.depth;
            let mut k = 0;
            while k < n {
                let b = batch.min(n - k);
                let vals: Vec<Vec3x8> = (0..b)
                    .map(|_| Vec3x8::new(F8::new(std::array::from_fn(|_| next())), F8::splat(next()), F8::splat(0.25)))
                    .collect();
                for (i, v) in vals.iter().enumerate() {
                    let (x, y) = (v.x.to_array(), v.y.to_array());
                    let px: Vec<[f32; 3]> = [0, 1, 2, 4, 5, 6].iter().map(|&l| [x[l], y[l], 0.25]).collect();
                    film.add_sample(s + k + i as u32, &px);
                }
                let carries = &pass.carries[k as usize..(k + b) as usize];
                add_batch(&mut stack, top, carries, (&vals, 1), pk.active.to_bitmask(), &mut c);
                top = top_after(top, carries);
                k += b;
            }
            assert_eq!(top, pass.levels);
            data = vec![[f64::NAN; 6]; pass.levels * tn];
            store(&stack[..pass.levels], &mut data, tn, &pk, (0, 0, tw));
            s += n;
            assert_eq!(blocks, film.blocks(), "after {s} samples");
            let bits = |d: &[Moments]| d.iter().flatten().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&data), bits(film.block_data()), "after {s} samples");
        }
        assert_eq!(c.nonfinite, 0);
    }

    /// A pass's steps are `push_block`'s, and its stack height the most blocks live at once.
    #[test]
    fn pass_blocks_follow_the_binary_counter() {
        let mut blocks = crate::film::canonical_blocks(0..5); // [0, 4) and 4
        let pass = PassBlocks::push(&mut blocks, 5..8);
        assert_eq!(pass, PassBlocks { depth: 2, carries: vec![1, 0, 3], height: 3, levels: 1 });
        assert_eq!(blocks, crate::film::canonical_blocks(0..8));
    }
}

//! `multijitter`: correlated multi-jittered points (Kensler 2013, "Correlated Multi-Jittered
//! Sampling", Pixar Technical Memo 13-01), the default sampler.
//!
//! The n points of a set lie on the `nx x ny = strata_shape(n)` grid, one per cell (as
//! `stratified`), and at the same time one per column of the n x 1 grid and one per row of the
//! 1 x n grid (n-rooks: every 1D projection is stratified into n strata, where `stratified`'s has
//! only nx or ny). Point `s` (after the index shuffle below) sits in cell `(c, r) = (s % nx,
//! s / nx)`; inside its cell, its x lies in the sub-column `sy(r)` of the cell's ny sub-columns
//! and its y in the sub-row `sx(c)` of its nx sub-rows, where `sy` and `sx` are keyed
//! permutations of the rows and of the columns. As x's fine stratum `c ny + sy(r)` depends on
//! the row only through one permutation shared by every column (the "correlated" shuffle), the
//! fine strata of neighbouring cells are offset alike, which keeps the 2D pattern even; each fine
//! stratum is then jittered uniformly. In 24-bit fixed point, x lies in `grid::cell_span` of fine
//! cell `c ny + sy(r)` of the n-cell axis, y in that of `r nx + sx(c)`: exact, as `stratified`'s.
//!
//! Padding (decorrelation between dimensions): every (pixel, sample, dim, seed) hashes its own key,
//! which keys the three permutations (`permute::permute_lanes`, with a uniform rotation per key)
//! and the jitter, and the point index k itself goes through a keyed permutation of 0..n first.
//! So the dimensions of one pixel are stratified independently of one another (sample k falls in
//! an unrelated cell of each), and every point is uniform over the square whatever the others.
//! Dimension 0, the camera's (`camera::DIM_CAMERA`), skips the index permutation (every other
//! dimension is shuffled against it, which is all padding needs): point k stays in coarse cell
//! `(k % nx, k / nx)`, as `stratified`'s, so `--first-sample centre` swaps sample 0 with the
//! sample of the centre's cell as it does for `stratified` (`camera::centre_stratum`); inside
//! that cell the point is uniform (its fine cell is drawn by the keyed permutations), so the
//! swap's bias is `stratified`'s.
//!
//! The set needs its count n in advance (`needs_count`: equal-time runs refuse it by name, and a
//! default becomes `sobol`); k >= n wraps modulo n.

use super::divisor::Divisor;
use super::grid::{cell_span, jittered, Grid, FIXED_ONE};
use super::hash::{hash, mix, stream_key};
use super::lanes::{Lanes, Pair};
use super::layout::{Layout, SetShape, StreamKey};
use super::permute::{permute_lanes, PermDomain};

const TAG_MULTIJITTER: u32 = 0x51a7_0006;
/// Key offsets of the index shuffle and of the two sub-stratum permutations (hashed keys offset
/// by constants: `permute::permute_lanes` derives its round keys from them the same way).
const KEY_INDEX: u32 = 0x51633e2d;
const KEY_COLUMNS: u32 = 0x68bc21eb;
const KEY_ROWS: u32 = 0x02e5be93;
/// Key offset of y's jitter.
const KEY_JITTER_Y: u32 = 0x7a3f_d1c5;

/// Correlated multi-jittered points (Kensler 2013), padded per (pixel, sample, dim).
#[derive(Clone, Copy, Debug)]
pub struct MultiJitter;

/// Its registry entry (see [`super::SAMPLERS`]).
pub(super) const INFO: super::SamplerInfo = super::SamplerInfo::new(
    "multijitter",
    &["cmj", "correlated-multijitter"],
    "correlated multi-jittered points (Kensler 2013): strata cells and n-rooks",
    &MultiJitter,
)
.needs_count();

/// The fixed-point span of fine cell `c` of the n-cell axis: by shifts when n is a power of two
/// (the common spp; bit-identical to `grid::cell_span`, whose cells are then exact), else by
/// `grid::cell_span`'s long division.
#[inline(always)]
fn fine_span<L: Lanes>(c: L, n: Divisor) -> (L, L) {
    let d = n.d;
    if d.is_power_of_two() && d <= FIXED_ONE {
        let shift = 24 - d.trailing_zeros();
        let lo = c.shl(shift);
        return (lo, lo.add(L::splat(1 << shift)));
    }
    cell_span(c, n)
}

/// The camera's dimension (`camera::DIM_CAMERA`), whose point k keeps its coarse cell.
const DIM_CAMERA: u32 = 0;

/// Point k of the set keyed by `key` (the per-(pixel, sample, dim, seed) hash) of dimension `dim`.
/// Power-of-two sets of 4 to 256 points (the usual spp) run [`grid_point`] on a constant
/// [`Grid`], so that the compiler folds their domains, shifts, masks and table layouts into the
/// code (the same operations on the same values as the run-time grid, so the same bits: the
/// set-up of three permutations was a fifth of the instructions of a point). So do `direct`'s
/// light tables of the course's 9 and 25 light samples at 16 to 256 spp (144 to 6400 points: at
/// 64 spp with 25, hw2's scenes, `keyed_point` 245.9 -> 192.9 M instructions) and the square
/// non-power-of-two spp 9, 25, 36 and 100.
#[inline]
fn keyed_point<L: Lanes>(set: &SetShape, key: L, dim: u32, k: L) -> (L::F, L::F) {
    macro_rules! grids {
        ($($n:literal)*) => {
            match set.grid().n.d {
                $($n => grid_point(const { &Grid::new($n) }, key, dim, k),)*
                _ => grid_point(set.grid(), key, dim, k),
            }
        };
    }
    grids!(4 8 16 32 64 128 256 9 25 36 100 144 288 576 1152 2304 400 800 1600 3200 6400)
}

/// [`keyed_point`] on the set's grid `grid`.
#[inline(always)]
fn grid_point<L: Lanes>(grid: &Grid, key: L, dim: u32, k: L) -> (L::F, L::F) {
    let k = if k.max_lane() < grid.n.d { k } else { grid.n.rem(k) };
    let [pn, pnx, pny] = &grid.perm;
    let s = if dim == DIM_CAMERA { k } else { permute_lanes(k, pn, key.xor(L::splat(KEY_INDEX))) };
    let (r, c) = grid.nx.div_rem(s);
    let sx = side(c, pnx, key.xor(L::splat(KEY_COLUMNS)));
    let sy = side(r, pny, key.xor(L::splat(KEY_ROWS)));
    let fx = c.mul(L::splat(grid.ny.d)).add(sy);
    let fy = r.mul(L::splat(grid.nx.d)).add(sx);
    // The two jitters hash under two keys (side by side, not one hash of the other: no chain).
    let (hx, hy) = (mix(key, s), mix(key.xor(L::splat(KEY_JITTER_Y)), s));
    (jittered(fine_span(fx, grid.n), hx), jittered(fine_span(fy, grid.n), hy))
}

/// [`permute_lanes`] of a grid side (the column or row permutation), on a compile-time
/// [`PermDomain`] for the sides of the usual sets: spp x light samples points of `direct`'s light
/// tables (hw2's 25 light samples at 64 spp: 1600 points, a 40 x 40 grid), non-power-of-two spp.
/// Their rounds' widths, table offsets and divisors then fold into the code: the same operations
/// on the same values as on the run-time domain, so the same bits (the light tables' sides of
/// 40: `keyed_point` 370.6 -> 245.9 M instructions on hw2 sphere, 40 x 30, 64 spp). Sides of the
/// compile-time grids fold to their arm.
#[inline(always)]
fn side<L: Lanes>(i: L, d: &PermDomain, key: L) -> L {
    macro_rules! sides {
        ($($m:literal)*) => {
            match d.m() {
                $($m => permute_lanes(i, const { &PermDomain::new($m) }, key),)*
                _ => permute_lanes(i, d, key),
            }
        };
    }
    sides!(3 5 6 8 9 10 12 16 18 20 24 25 32 36 40 48 50 64 72 80 96 100 128 160 200 256)
}

impl Layout for MultiJitter {
    #[inline]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        keyed_point(set, hash(TAG_MULTIJITTER, seed, dim, [pixel, sample]), dim, k)
    }

    /// Both points' chains (the key's hash, the three permutations, the jitter) side by side on
    /// [`Pair`] lanes: the same bits as two [`Layout::point`] calls.
    #[inline]
    fn point_pair<L: Lanes>(
        &self,
        set: &SetShape,
        pixel: L,
        sample: L,
        dims: [u32; 2],
        k: [L; 2],
        seed: u64,
    ) -> [(L::F, L::F); 2] {
        // The camera's dimension skips the index permutation: not one chain's code for both.
        if dims.contains(&DIM_CAMERA) {
            let point = |i: usize| self.point(set, pixel, sample, dims[i], k[i], seed);
            return [point(0), point(1)];
        }
        let [a, b] = dims.map(|d| L::splat(stream_key(TAG_MULTIJITTER, seed, d)));
        let key = [Pair(pixel, pixel), Pair(sample, sample)].into_iter().fold(Pair(a, b), mix);
        let (x, y) = keyed_point(set, key, dims[0], Pair(k[0], k[1]));
        [(x.0, y.0), (x.1, y.1)]
    }

    #[inline]
    fn stream<L: Lanes>(&self, _: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        StreamKey::hashed(TAG_MULTIJITTER, pixel, sample, dim, seed)
    }

    #[inline]
    fn stream_point<L: Lanes>(&self, set: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        keyed_point(set, s.prefix, s.dim, L::splat(k))
    }
}

#[cfg(test)]
#[path = "multijitter_tests.rs"]
mod tests;

//! `stratified` and `grid-center`: one point in each cell of the `nx x ny = strata_shape(n)` grid;
//! point `k` lies in cell `(k % nx, k / nx)`, jittered uniformly (stratified) or at the cell centre
//! (grid-center, identical for every pixel, sample, dim and seed: biased on purpose). Also the
//! [`GridTable`] of precomputed cell spans.

use super::divisor::Divisor;
use super::grid::{cell_centre, cell_span, jittered, Grid};
use super::hash::{hash, mix, stream_key};
use super::lanes::Lanes;
use super::layout::{Layout, SetShape, StreamKey};
use super::PointSet;
use crate::simd::{F8, U8};

const TAG_STRATIFIED: u32 = 0x51a7_0002;

/// One point per cell of the `strata_shape(n)` grid: jittered (`jitter`) or at the cell centre.
#[derive(Clone, Copy, Debug)]
pub struct Stratified {
    /// true: uniform jitter inside the cell; false: the cell centre
    pub jitter: bool,
}

/// Its registry entry as jittered strata (see [`super::SAMPLERS`]).
pub(super) const JITTERED: super::SamplerInfo = super::SamplerInfo::new(
    "stratified",
    &["jittered"],
    "one jittered point per strata cell",
    &Stratified { jitter: true },
);

/// Its registry entry as strata cell centres (see [`super::SAMPLERS`]).
pub(super) const CENTRES: super::SamplerInfo =
    super::SamplerInfo::new("grid-center", &["grid", "center"], "strata cell centres", &Stratified { jitter: false })
        .biased();

/// Point in the 24-bit fixed-point span `[x lo, x hi, y lo, y hi]` picked by the stratified jitter
/// hash of (pixel, sample, dim, k, seed); a zero-width span gives its lower edge.
#[inline]
pub(super) fn jitter_in<L: Lanes>(span: [L; 4], pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
    let h = hash(TAG_STRATIFIED, seed, dim, [pixel, sample, k]);
    (jittered((span[0], span[1]), h), jittered((span[2], span[3]), mix(h, L::splat(1))))
}

impl Layout for Stratified {
    #[inline]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        let grid = set.grid();
        let k = grid.n.rem(k);
        let (cy, cx) = grid.nx.div_rem(k);
        if self.jitter {
            let h = hash(TAG_STRATIFIED, seed, dim, [pixel, sample, k]);
            let (x, y) = (cell_span(cx, grid.nx), cell_span(cy, grid.ny));
            (jittered(x, h), jittered(y, mix(h, L::splat(1))))
        } else {
            let (x, y) = (cell_centre(cx, grid.nx), cell_centre(cy, grid.ny));
            (x.unit24(), y.unit24())
        }
    }

    #[inline]
    fn stream<L: Lanes>(&self, _: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        let prefix = mix(mix(L::splat(stream_key(TAG_STRATIFIED, seed, dim)), pixel), sample);
        StreamKey { prefix, base: L::splat(0), sample, dim, seed }
    }

    #[inline]
    fn stream_point<L: Lanes>(&self, set: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        // k is lane-uniform: its cell is found once, in scalar code.
        let grid = set.grid();
        let k = grid.n.rem(k);
        let (cy, cx) = grid.nx.div_rem(k);
        if self.jitter {
            let h = mix(s.prefix, L::splat(k));
            let span = |c: u32, m: Divisor| {
                let (lo, hi) = cell_span(c, m);
                (L::splat(lo), L::splat(hi))
            };
            (jittered(span(cx, grid.nx), h), jittered(span(cy, grid.ny), mix(h, L::splat(1))))
        } else {
            (L::splat(cell_centre(cx, grid.nx)).unit24(), L::splat(cell_centre(cy, grid.ny)).unit24())
        }
    }

    #[inline]
    fn stream_point_span<L: Lanes>(
        &self,
        set: &SetShape,
        s: &StreamKey<L>,
        k: u32,
        span: Option<[u32; 4]>,
    ) -> (L::F, L::F) {
        let Some([xl, xh, yl, yh]) = span else {
            return self.stream_point(set, s, k);
        };
        if self.jitter {
            let h = mix(s.prefix, L::splat(set.grid().n.rem(k)));
            (jittered((L::splat(xl), L::splat(xh)), h), jittered((L::splat(yl), L::splat(yh)), mix(h, L::splat(1))))
        } else {
            (L::splat(xl).unit24(), L::splat(yl).unit24())
        }
    }

    fn cell_span(&self, set: &SetShape, k: u32) -> Option<[u32; 4]> {
        let grid: Grid = set.grid();
        let (cy, cx) = grid.nx.div_rem(grid.n.rem(k));
        Some(if self.jitter {
            let ((xl, xh), (yl, yh)) = (cell_span(cx, grid.nx), cell_span(cy, grid.ny));
            [xl, xh, yl, yh]
        } else {
            let (x, y) = (cell_centre(cx, grid.nx), cell_centre(cy, grid.ny));
            [x, x, y, y]
        })
    }
}

/// A [`PointSet`] with every cell's 24-bit span precomputed for grid layouts (stratified and grid
/// centres) of at most [`GridTable::MAX_CELLS`] cells, so points with a lane-varying k cost one
/// table look-up per lane instead of exact fixed-point divisions. `point`/`point_x8` equal the
/// set's `point`/`point_x8` bit for bit for every layout (other layouts and larger sets simply
/// call the set).
#[derive(Clone, Debug)]
pub struct GridTable {
    set: PointSet,
    /// per cell k: [x lo, x hi, y lo, y hi] in 24-bit fixed point (grid centres: lo == hi)
    spans: Vec<[u32; 4]>,
}

impl GridTable {
    /// Largest set with a table (16 bytes a cell: 1 MiB).
    pub const MAX_CELLS: u32 = 1 << 16;

    /// The table of `set` (empty unless `set` is a grid layout of at most `MAX_CELLS` cells).
    pub fn new(set: PointSet) -> Self {
        let (layout, shape) = (set.kind().layout(), set.shape());
        let spans = if set.n() <= Self::MAX_CELLS && layout.cell_span(&shape, 0).is_some() {
            (0..set.n()).map(|k| layout.cell_span(&shape, k).expect("a grid layout has every cell")).collect()
        } else {
            Vec::new()
        };
        Self { set, spans }
    }

    /// The point set this table belongs to.
    pub fn set(&self) -> &PointSet {
        &self.set
    }

    /// As [`PointSet::point`], bit for bit; coordinates in [0, 1).
    pub fn point(&self, pixel: u32, sample: u32, dim: u32, k: u32, seed: u64) -> [f32; 2] {
        if self.spans.is_empty() {
            return self.set.point(pixel, sample, dim, k, seed);
        }
        #[cfg(test)]
        super::replay::count_api_call();
        let k = k % self.set.n();
        let (x, y) = jitter_in(self.spans[k as usize], pixel, sample, dim, k, seed);
        [x, y]
    }

    /// As [`PointSet::point_x8`], bit for bit per lane; coordinates in [0, 1).
    #[inline]
    pub fn point_x8(&self, pixel: U8, sample: U8, dim: u32, k: U8, seed: u64) -> (F8, F8) {
        if self.spans.is_empty() {
            return self.set.point_x8(pixel, sample, dim, k, seed);
        }
        #[cfg(test)]
        super::replay::count_api_call();
        let k = self.set.shape().grid().n.rem(k);
        let ks = k.to_array();
        let cells: [[u32; 4]; 8] = std::array::from_fn(|i| self.spans[ks[i] as usize]);
        let col = |j: usize| U8::new(std::array::from_fn(|i| cells[i][j]));
        jitter_in([col(0), col(1), col(2), col(3)], pixel, sample, dim, k, seed)
    }
}

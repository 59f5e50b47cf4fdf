//! `stratified` and `grid-center`: one point in each cell of the `nx x ny = strata_shape(n)` grid;
//! point `k` lies in cell `(k % nx, k / nx)`, jittered uniformly (stratified) or at the cell centre
//! (grid-center, identical for every pixel, sample, dim and seed: biased on purpose). Also the
//! [`GridTable`] of precomputed cell spans.

use super::divisor::Divisor;
use super::grid::{cell_centre, cell_span, jittered};
use super::hash::{hash, mix, stream_key};
use super::lanes::Lanes;
use super::layout::{Layout, SetShape, StreamKey};
use super::permute::ShuffleKey;
use super::{PointSet, Stream};
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
)
.needs_count();

/// Its registry entry as strata cell centres (see [`super::SAMPLERS`]).
pub(super) const CENTRES: super::SamplerInfo =
    super::SamplerInfo::new("grid-center", &["grid", "center", "grid-centre", "centre"], "strata cell centres", &Stratified { jitter: false })
        .biased()
        .needs_count();

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
        StreamKey::hashed(TAG_STRATIFIED, pixel, sample, dim, seed)
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
        let grid = set.grid();
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
    /// the same spans per axis when both axes have at most 8 cells (and the spans are a product
    /// of the axes): looked up by lane permutes instead of per-lane loads
    axes: Option<Axes>,
    /// a grid layout (its points lie in fixed cells: `Layout::cell_span` is `Some`)
    grid: bool,
}

/// The spans of a grid of at most 8 x 8 cells per axis: [x lo, x hi, y lo, y hi] of column or
/// row c in lane c.
#[derive(Clone, Copy, Debug)]
struct Axes {
    nx: Divisor,
    spans: [U8; 4],
}

impl Axes {
    /// The axes of `spans` (cells of `grid`), if both have at most 8 cells and every cell's span
    /// is that of its column and row.
    fn of(spans: &[[u32; 4]], grid: super::grid::Grid) -> Option<Self> {
        let (nx, ny) = (grid.nx.d as usize, grid.ny.d as usize);
        if spans.is_empty() || nx > 8 || ny > 8 || spans.len() != nx * ny {
            return None;
        }
        let lane = |j: usize, c: usize, stride: usize| spans.get(c * stride).map_or(0, |s| s[j]);
        let col = |j: usize, n: usize, stride: usize| {
            U8::new(std::array::from_fn(|c| if c < n { lane(j, c, stride) } else { 0 }))
        };
        let a = Self { nx: grid.nx, spans: [col(0, nx, 1), col(1, nx, 1), col(2, ny, nx), col(3, ny, nx)] };
        let product = spans.iter().enumerate().all(|(k, s)| {
            let (cx, cy) = (k % nx, k / nx);
            let ax = |j: usize, c: usize| a.spans[j].to_array()[c];
            *s == [ax(0, cx), ax(1, cx), ax(2, cy), ax(3, cy)]
        });
        product.then_some(a)
    }

    /// The spans of cells `k` (each below the set's n).
    #[inline]
    fn spans(&self, k: U8) -> [U8; 4] {
        let (cy, cx) = self.nx.div_rem(k);
        let p = crate::simd::permute_lanes;
        [p(self.spans[0], cx), p(self.spans[1], cx), p(self.spans[2], cy), p(self.spans[3], cy)]
    }
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
        let axes = Axes::of(&spans, *shape.grid());
        let grid = layout.cell_span(&shape, 0).is_some();
        Self { set, spans, axes, grid }
    }

    /// The point set this table belongs to.
    pub fn set(&self) -> &PointSet {
        &self.set
    }

    /// A grid layout: [`GridTable::path_point_x8`] shuffles its strata per (pixel, dim).
    pub fn is_grid(&self) -> bool {
        self.grid
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
        jitter_in(self.cell_spans(k), pixel, sample, dim, k, seed)
    }

    /// The spans [x lo, x hi, y lo, y hi] of cells `k` (each below the set's n): by lane permutes
    /// from the axes where the grid has them, else one table load per lane.
    #[inline(always)]
    fn cell_spans(&self, k: U8) -> [U8; 4] {
        if let Some(a) = &self.axes {
            return a.spans(k);
        }
        let ks = k.to_array();
        let cells: [[u32; 4]; 8] = std::array::from_fn(|i| self.spans[ks[i] as usize]);
        std::array::from_fn(|j| U8::new(std::array::from_fn(|i| cells[i][j])))
    }
}

/// One dimension of the path tracer's points ([`GridTable::path_point_x8`]): its lane-uniform work
/// (the shuffle's key and domain, the jitter hash's (tag, seed, dim) prefix) done once, for every
/// packet of a bounce that draws the dimension.
#[derive(Clone, Copy, Debug)]
pub struct PathDim {
    dim: u32,
    seed: u64,
    shuffle: ShuffleKey,
    /// `stream_key(TAG_STRATIFIED, seed, dim)`: the hash state before (pixel, sample, k)
    key: u32,
    /// every shuffled index is below the set's n (the cell index needs no reduction)
    in_range: bool,
}

impl PathDim {
    /// The dimension.
    pub fn dim(&self) -> u32 {
        self.dim
    }
}

impl GridTable {
    /// Dimension `dim` of the path tracer's points over `spp` pixel samples under `seed`.
    pub fn path_dim(&self, spp: u32, dim: u32, seed: u64) -> PathDim {
        let shuffle = ShuffleKey::new(spp, dim, seed);
        let key = stream_key(TAG_STRATIFIED, seed, dim);
        PathDim { dim, seed, shuffle, key, in_range: shuffle.n() <= self.set.n() }
    }

    /// The points of dimension `d` of pixels `pixel` as a stream, for a layout that is not a grid
    /// (`None` for a grid: its indices are shuffled per pixel): `path_stream_x8(d, pixel)?.point(s)`
    /// equals [`GridTable::path_point_x8`]`(d, pixel, U8::splat(s))` bit for bit, with the hashing
    /// of (pixel, dim) done once for every index s.
    #[inline]
    pub fn path_stream_x8(&self, d: &PathDim, pixel: U8) -> Option<Stream<U8>> {
        (!self.grid).then(|| self.set.stream_x8(pixel, U8::splat(0), d.dim, d.seed))
    }

    /// [`GridTable::path_point_x8`] of `d` here and of `e` in table `other` for the same pixel
    /// samples `s`, bit for bit: where both tables draw from one set of a layout that is not a
    /// grid, in one [`PointSet::point_pair_x8`] call (two chains interleaved); else two calls.
    #[inline(always)]
    pub fn path_point_pair_x8(&self, d: &PathDim, other: &GridTable, e: &PathDim, pixel: U8, s: U8) -> [(F8, F8); 2] {
        let (a, b) = (&self.set, &other.set);
        let shared = !self.grid
            && !other.grid
            && a.kind() == b.kind()
            && a.n() == b.n()
            && a.shape().width() == b.shape().width()
            && d.seed == e.seed;
        if shared {
            return a.point_pair_x8(pixel, U8::splat(0), [d.dim, e.dim], [s, s], d.seed);
        }
        [self.path_point_x8(d, pixel, s), other.path_point_x8(e, pixel, s)]
    }

    /// The path tracer's point of dimension `d` for pixel samples `s`: for grid layouts bit for
    /// bit `point_x8(pixel, 0, dim, shuffled_index_x8(s, spp, pixel, dim, seed), seed)` (strata
    /// shuffled per (pixel, dim): padded stratified sampling), for the others (sequences, which
    /// decorrelate their dims themselves and must keep the index's prefixes)
    /// `point_x8(pixel, 0, dim, s, seed)`.
    #[inline(always)]
    pub fn path_point_x8(&self, d: &PathDim, pixel: U8, s: U8) -> (F8, F8) {
        if !self.grid {
            return self.set.point_x8(pixel, U8::splat(0), d.dim, s, d.seed);
        }
        let k = d.shuffle.index_x8(s, pixel);
        if self.spans.is_empty() {
            return self.set.point_x8(pixel, U8::splat(0), d.dim, k, d.seed);
        }
        #[cfg(test)]
        super::replay::count_api_call();
        let k = if d.in_range { k } else { self.set.shape().grid().n.rem(k) };
        let [xl, xh, yl, yh] = self.cell_spans(k);
        // `hash(TAG_STRATIFIED, seed, dim, [pixel, 0, k])` from its hoisted prefix.
        let h = mix(mix(mix(U8::splat(d.key), pixel), U8::splat(0)), k);
        (jittered((xl, xh), h), jittered((yl, yh), mix(h, U8::splat(1))))
    }
}

//! The one trait a 2D point-set layout implements, and its object-safe form the registry stores.
//!
//! A layout writes its generator once, generic over [`Lanes`]; the blanket [`DynLayout`] impl
//! instantiates it for `u32` (scalar) and [`U8`] (8 lanes), so the two agree bit for bit, and
//! [`PointSet`](super::PointSet) dispatches once per call through a `&'static dyn DynLayout`.

use super::divisor::Divisor;
use super::grid::Grid;
use super::hash::hash;
use super::lanes::{Lanes, PointFn};
use crate::simd::{F8, U8};

/// What one point set is prepared for: built once per (layout, n, width) by
/// [`PointSet`](super::PointSet) and handed to every call, so layouts need no per-set state.
#[derive(Clone, Copy, Debug)]
pub struct SetShape {
    n: u32,
    width: u32,
    width_div: Divisor,
    grid: Grid,
}

impl SetShape {
    /// Sets of `n` points (0 acts as 1) for an image `width` pixels wide (0: unknown).
    pub fn new(n: u32, width: u32) -> Self {
        let n = n.max(1);
        Self { n, width, width_div: Divisor::new(width), grid: Grid::new(n) }
    }

    /// Points per set, >= 1.
    pub fn n(&self) -> u32 {
        self.n
    }

    /// Image width the pixel ids refer to (`pixel = y * width + x`); 0 when not known.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Pixel coordinates (x, y) of linear pixel ids `y * width + x` per lane; `(pixel, 0)` when the
    /// width is not known.
    #[inline]
    pub fn pixel_xy<L: Lanes>(&self, pixel: L) -> (L, L) {
        if self.width == 0 {
            return (pixel, L::splat(0));
        }
        let (y, x) = self.width_div.div_rem(pixel);
        (x, y)
    }

    /// The `strata_shape(n)` grid with its divisors.
    pub(super) fn grid(&self) -> &Grid {
        &self.grid
    }
}

/// The per-stream words of one (pixel, sample, dim, seed), hashed once by [`Layout::stream`] and
/// reused for every point k of the set. `prefix` and `base` mean what the layout makes them mean
/// (by default `prefix = pixel`, `base = 0`).
#[derive(Clone, Copy, Debug)]
pub struct StreamKey<L> {
    /// layout-defined key words (hash state after pixel[, sample]; by default the pixel)
    pub prefix: L,
    /// layout-defined second word (e.g. the first sequence index `sample * n`)
    pub base: L,
    /// pixel sample index
    pub sample: L,
    /// sampling dimension
    pub dim: u32,
    /// base seed
    pub seed: u64,
    /// layout-defined further words of the stream (pmj02: its scramble); zero by default
    pub words: [L; 5],
}

impl<L: Lanes> StreamKey<L> {
    /// The stream with these words and no further ones (`words` zero).
    #[inline]
    pub fn new(prefix: L, base: L, sample: L, dim: u32, seed: u64) -> Self {
        Self { prefix, base, sample, dim, seed, words: [L::splat(0); 5] }
    }

    /// The stream of a layout that hashes (tag, seed, dim, pixel, sample) before its point index:
    /// that hash as `prefix`, `base` zero (independent, stratified, multijitter).
    #[inline]
    pub(super) fn hashed(tag: u32, pixel: L, sample: L, dim: u32, seed: u64) -> Self {
        Self::new(hash(tag, seed, dim, [pixel, sample]), L::splat(0), sample, dim, seed)
    }
}

/// A 2D point-set layout: point k (0 <= k < n) of the n-point set of stream (pixel, sample, dim)
/// under seed, both coordinates in [0, 1), as a pure function of its inputs. Write each method once
/// against [`Lanes`]; scalar and x8 then agree bit for bit. Any inputs are valid (k >= n wraps or
/// continues the sequence, as the layout documents).
pub trait Layout: Send + Sync + 'static {
    /// Point k of the set of (pixel, sample, dim) under seed, per lane.
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F);

    /// The points of two dimensions `dims` of (pixel, sample) at indices `k`: bit for bit
    /// `[point(.., dims[0], k[0], ..), point(.., dims[1], k[1], ..)]`. The default makes the two
    /// calls; a layout whose point is a long dependent chain overrides it to run the two chains
    /// interleaved (on [`Pair`](super::Pair) lanes), which a caller drawing two dimensions at once gains from.
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
        [self.point(set, pixel, sample, dims[0], k[0], seed), self.point(set, pixel, sample, dims[1], k[1], seed)]
    }

    /// The hash work the points of one (pixel, sample, dim) share. Override together with
    /// [`Layout::stream_point`]; the default keeps the inputs.
    #[inline]
    fn stream<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        let _ = set;
        StreamKey::new(pixel, L::splat(0), sample, dim, seed)
    }

    /// Point k (lane-uniform) of a stream; must equal `point` with `k` splatted, bit for bit.
    #[inline]
    fn stream_point<L: Lanes>(&self, set: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        self.point(set, s.prefix, s.sample, s.dim, L::splat(k), s.seed)
    }

    /// [`Layout::stream_point`] with the per-k work done in advance: `span` is
    /// [`Layout::cell_span`] of k (the same for every stream of the set, so a caller drawing
    /// point k of many streams finds its cell once). Must equal `stream_point`, bit for bit; the
    /// default ignores `span`.
    #[inline]
    fn stream_point_span<L: Lanes>(
        &self,
        set: &SetShape,
        s: &StreamKey<L>,
        k: u32,
        span: Option<[u32; 4]>,
    ) -> (L::F, L::F) {
        let _ = span;
        self.stream_point(set, s, k)
    }

    /// For [`GridTable`](super::GridTable): `Some([x lo, x hi, y lo, y hi])` (24-bit fixed point)
    /// if point k is always `grid::jitter_in` of that span for every pixel, sample, dim and seed;
    /// `None` (the default) otherwise.
    fn cell_span(&self, set: &SetShape, k: u32) -> Option<[u32; 4]> {
        let _ = (set, k);
        None
    }

    /// Builds what the layout builds on first use (pmj02's tables), so that a render's timed tile
    /// loop does not: integrators call it when they choose their layouts. The default has
    /// nothing to build.
    fn prepare(&self) {}
}

/// Object-safe form of [`Layout`] with the scalar and x8 instantiations, implemented for every
/// `Layout` (never by hand); what the registry stores.
pub trait DynLayout: Send + Sync {
    /// `Layout::point` for one lane.
    fn point_1(&self, set: &SetShape, pixel: u32, sample: u32, dim: u32, k: u32, seed: u64) -> (f32, f32);
    /// `Layout::point` for eight lanes.
    fn point_8(&self, set: &SetShape, pixel: U8, sample: U8, dim: u32, k: U8, seed: u64) -> (F8, F8);
    /// `Layout::point_pair` for eight lanes.
    fn point_pair_8(
        &self,
        set: &SetShape,
        pixel: U8,
        sample: U8,
        dims: [u32; 2],
        k: [U8; 2],
        seed: u64,
    ) -> [(F8, F8); 2];
    /// `Layout::stream` for one lane.
    fn stream_1(&self, set: &SetShape, pixel: u32, sample: u32, dim: u32, seed: u64) -> StreamKey<u32>;
    /// `Layout::stream` for eight lanes.
    fn stream_8(&self, set: &SetShape, pixel: U8, sample: U8, dim: u32, seed: u64) -> StreamKey<U8>;
    /// `Layout::stream_point` for one lane.
    fn stream_point_1(&self, set: &SetShape, s: &StreamKey<u32>, k: u32) -> (f32, f32);
    /// `Layout::stream_point` for eight lanes.
    fn stream_point_8(&self, set: &SetShape, s: &StreamKey<U8>, k: u32) -> (F8, F8);
    /// `Layout::stream_point_span` for eight lanes.
    fn stream_point_span_8(&self, set: &SetShape, s: &StreamKey<U8>, k: u32, span: Option<[u32; 4]>) -> (F8, F8);
    /// `Layout::cell_span`.
    fn cell_span(&self, set: &SetShape, k: u32) -> Option<[u32; 4]>;
    /// `Layout::prepare`.
    fn prepare(&self);
}

impl<T: Layout> DynLayout for T {
    fn point_1(&self, set: &SetShape, pixel: u32, sample: u32, dim: u32, k: u32, seed: u64) -> (f32, f32) {
        self.point(set, pixel, sample, dim, k, seed)
    }
    fn point_8(&self, set: &SetShape, pixel: U8, sample: U8, dim: u32, k: U8, seed: u64) -> (F8, F8) {
        self.point(set, pixel, sample, dim, k, seed)
    }
    fn point_pair_8(
        &self,
        set: &SetShape,
        pixel: U8,
        sample: U8,
        dims: [u32; 2],
        k: [U8; 2],
        seed: u64,
    ) -> [(F8, F8); 2] {
        self.point_pair(set, pixel, sample, dims, k, seed)
    }
    fn stream_1(&self, set: &SetShape, pixel: u32, sample: u32, dim: u32, seed: u64) -> StreamKey<u32> {
        self.stream(set, pixel, sample, dim, seed)
    }
    fn stream_8(&self, set: &SetShape, pixel: U8, sample: U8, dim: u32, seed: u64) -> StreamKey<U8> {
        self.stream(set, pixel, sample, dim, seed)
    }
    fn stream_point_1(&self, set: &SetShape, s: &StreamKey<u32>, k: u32) -> (f32, f32) {
        self.stream_point(set, s, k)
    }
    fn stream_point_8(&self, set: &SetShape, s: &StreamKey<U8>, k: u32) -> (F8, F8) {
        self.stream_point(set, s, k)
    }
    fn stream_point_span_8(&self, set: &SetShape, s: &StreamKey<U8>, k: u32, span: Option<[u32; 4]>) -> (F8, F8) {
        self.stream_point_span(set, s, k, span)
    }
    fn cell_span(&self, set: &SetShape, k: u32) -> Option<[u32; 4]> {
        Layout::cell_span(self, set, k)
    }
    fn prepare(&self) {
        Layout::prepare(self)
    }
}

/// A run-time layout with the set it draws from: the [`PointFn`] a generic layout hands to
/// [`Lanes::dyn_point`] (file padding draws the registry's layout this way).
pub struct SetLayout<'a> {
    /// the layout
    pub layout: &'a dyn DynLayout,
    /// the set it draws from
    pub set: &'a SetShape,
}

impl PointFn for SetLayout<'_> {
    #[inline]
    fn point_1(&self, pixel: u32, sample: u32, dim: u32, k: u32, seed: u64) -> (f32, f32) {
        self.layout.point_1(self.set, pixel, sample, dim, k, seed)
    }
    #[inline]
    fn point_8(&self, pixel: U8, sample: U8, dim: u32, k: U8, seed: u64) -> (F8, F8) {
        self.layout.point_8(self.set, pixel, sample, dim, k, seed)
    }
}

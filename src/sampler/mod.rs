//! Sample generators: every value is a pure function of (pixel, sample, dim, k, seed).
//!
//! Vocabulary: `pixel` is the linear pixel index, `sample` the pixel sample index `s` (0..spp), `dim`
//! names one sampling decision (camera jitter, light `l`, bounce `b`, ...) and `k` (0 <= k < n)
//! picks one point of the n-point 2D set that belongs to (pixel, sample, dim). Each such set is a
//! fresh, independent set. Nothing depends on thread count, tile order or call order, so renders
//! are bit-identical however they are scheduled.
//!
//! Layouts: each is one file implementing [`Layout`] and exporting its `SamplerInfo` const(s),
//! plus one line of the `registry!` list here (which declares the module and adds its entries to
//! [`SAMPLERS`]), the registry that the `.test` parser, the CLI (`--pixel-sampler`,
//! `--light-sampler`, their help text) and the tests read; [`SamplerKind`] is a handle into it.
//! Stratification is across `k` *within one set*: to stratify the camera jitter over a pixel's spp
//! samples, call with `n = spp, k = s, sample = 0`. Sequence layouts (halton, sobol, pmj02) use
//! the global index `sample * n + k`.
//!
//! Precision: every coordinate is a 24-bit fixed-point value `y * 2^-24` with `y < 2^24`, computed
//! with exact integer arithmetic, so it lies in [0, 1) and is exactly representable as f32. Grid
//! points lie exactly (in real arithmetic) inside their cells whenever `n <= 2^24`; for larger `n`
//! cells are narrower than 2^-24 and points snap down to the 2^-24 grid.
//!
//! Scalar and 8-lane versions are the same generic code instantiated for `u32` and [`U8`] (see
//! [`Lanes`]), so they agree bit for bit; the tests check it anyway for every registered layout.
//!
//! Files: `layout.rs` (the trait), `lanes.rs`, `hash.rs`, `divisor.rs`, `grid.rs` (helpers),
//! `permute.rs`, one file per layout, `tests.rs` (generic tests over the registry), `replay.rs`
//! (the call log of a render and its replay, for `strata profile`).

use crate::simd::{F8, U8};

mod divisor;
pub mod file;
mod grid;
mod hash;
mod lanes;
mod layout;
mod permute;
pub mod replay;

#[cfg(test)]
mod slow_test;

pub use grid::strata_shape;
pub use halton::radical_inverse;
pub use lanes::{Lanes, Pair, PointFn};
pub use layout::{DynLayout, Layout, SetLayout, SetShape, StreamKey};
pub use permute::{permute, permute_x8, shuffled_index_x8, ShuffleKey};
pub use stratified::{GridTable, PathDim};

use hash::{hash, unit};

// ------------------------------------------------------------------------------------------------
// The registry: one line per layout
// ------------------------------------------------------------------------------------------------

/// Declares the layout modules and lists their registry entries ([`SAMPLERS`]), in this order:
/// `MODULE: [ENTRY, ...]` names the module's `SamplerInfo` consts.
macro_rules! registry {
    ($($vis:vis $module:ident: [$($entry:ident),+]),+ $(,)?) => {
        $($vis mod $module;)+

        /// Every sampler, in the order the CLI lists them. A name or alias is spelled only in its
        /// layout's file (its `SamplerInfo` const).
        pub const SAMPLERS: &[SamplerInfo] = &[$($($module::$entry),+),+];
    };
}

registry! {
    independent: [INFO],
    stratified: [JITTERED, CENTRES],
    multijitter: [INFO],
    halton: [INFO],
    pub sobol: [INFO],
    pub pmj: [INFO],
    zsobol: [INFO],
}

/// One registered sampler: its names, what it declares about itself, and its layout.
pub struct SamplerInfo {
    /// canonical name (what `name()`, JSON and EXR metadata print)
    pub name: &'static str,
    /// other accepted spellings (parsing is case-insensitive and ignores surrounding spaces)
    pub aliases: &'static [&'static str],
    /// one line for documentation
    pub description: &'static str,
    /// a word shown in parentheses after the name in the CLI help ("random", "biased")
    pub note: Option<&'static str>,
    /// estimates are deterministic and biased (grid centres)
    pub biased: bool,
    /// distinct points per (pixel, dim) before the sequence repeats, if it does
    pub period: Option<u64>,
    /// sample s is the same whatever the pixel's sample count (a sequence): equal-time runs,
    /// whose count is not known in advance, can continue it pass after pass
    pub progressive: bool,
    /// the generator
    pub layout: &'static dyn DynLayout,
}

impl SamplerInfo {
    /// An unbiased sampler without period or help note.
    pub const fn new(
        name: &'static str,
        aliases: &'static [&'static str],
        description: &'static str,
        layout: &'static dyn DynLayout,
    ) -> Self {
        Self { name, aliases, description, note: None, biased: false, period: None, progressive: true, layout }
    }

    /// Marks the sampler biased (its note becomes "biased").
    pub const fn biased(mut self) -> Self {
        self.biased = true;
        self.note = Some("biased");
        self
    }

    /// Sets the help note.
    pub const fn note(mut self, note: &'static str) -> Self {
        self.note = Some(note);
        self
    }

    /// Marks the layout as needing the pixel's sample count in advance (not progressive).
    pub const fn needs_count(mut self) -> Self {
        self.progressive = false;
        self
    }

    /// Sets the period (distinct points per (pixel, dim)).
    pub const fn period(mut self, points: u64) -> Self {
        self.period = Some(points);
        self
    }
}

/// Which 2D point-set layout to use for a set of `n` samples: a handle into [`SAMPLERS`].
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct SamplerKind(u8);

impl SamplerKind {
    /// Independent uniform points (a hash of all inputs).
    pub const INDEPENDENT: Self = Self::named("independent");
    /// One uniformly jittered point per cell of the `strata_shape(n)` grid.
    pub const STRATIFIED: Self = Self::named("stratified");
    /// Cell centres of the `strata_shape(n)` grid; deterministic, biased.
    pub const GRID_CENTER: Self = Self::named("grid-center");
    /// Correlated multi-jittered points (Kensler 2013): strata cells and n-rooks, padded per dim.
    pub const MULTIJITTER: Self = Self::named("multijitter");
    /// The sampler of every dimension a scene and the flags leave unset: [`SamplerKind::MULTIJITTER`]
    /// (issue 33: lower error per sample than `stratified`; dearer per point, so at equal time it
    /// leads on the Cornell box and trails on direct lighting with many light samples:
    /// `docs/performance.md`).
    pub const DEFAULT: Self = Self::MULTIJITTER;
    /// Scrambled Halton points (base 2 Owen, base 3 random digit permutations) at `sample * n + k`.
    pub const HALTON: Self = Self::named("halton");
    /// Owen-scrambled Sobol' (dimensions 0, 1; hash-based nested scrambling) at `sample * n + k`.
    pub const SOBOL: Self = Self::named("sobol");
    /// Progressive multi-jittered (0,2) sequence (table-based, XOR-scrambled) at `sample * n + k`.
    pub const PMJ02: Self = Self::named("pmj02");

    /// Test builds only: a stratified layout spinning in every call (not in the registry).
    #[cfg(test)]
    pub(crate) const SLOW_TEST: Self = SamplerKind(u8::MAX);

    /// Every registered kind, in registry order.
    pub const ALL: [SamplerKind; SAMPLERS.len()] = {
        let mut all = [SamplerKind(0); SAMPLERS.len()];
        let mut i = 0;
        while i < all.len() {
            all[i] = SamplerKind(i as u8);
            i += 1;
        }
        all
    };

    /// The registered kind with canonical name `name` (compile-time error in consts if absent).
    pub const fn named(name: &str) -> Self {
        let mut i = 0;
        while i < SAMPLERS.len() {
            if crate::registry::same_name(SAMPLERS[i].name, name) {
                return SamplerKind(i as u8);
            }
            i += 1;
        }
        panic!("no sampler of that name is registered")
    }

    /// Kind for a name or alias of the registry (case-insensitive, surrounding spaces ignored):
    /// e.g. "independent" | "random", "stratified" | "jittered", "grid" | "grid-center" | "center",
    /// "halton", "sobol", "pmj02" | "pmj"; `None` otherwise.
    pub fn parse(name: &str) -> Option<Self> {
        let name = name.trim().to_ascii_lowercase();
        Self::ALL.into_iter().find(|k| k.info().name == name || k.info().aliases.contains(&name.as_str()))
    }

    /// Canonical name (accepted by `parse`).
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// True for layouts whose estimates are deterministic and biased (grid centres).
    pub fn is_biased(self) -> bool {
        self.info().biased
    }

    /// Its registry entry (for a loaded point set, the entry [`file::register`] made).
    pub fn info(self) -> &'static SamplerInfo {
        #[cfg(test)]
        if self.0 == u8::MAX {
            return &slow_test::INFO;
        }
        match self.loaded_index() {
            Some(j) => file::info(j),
            None => &SAMPLERS[self.0 as usize],
        }
    }

    /// The kind of loaded point set `j` (made by [`file::register`] only).
    const fn loaded(j: usize) -> Self {
        SamplerKind((SAMPLERS.len() + j) as u8)
    }

    /// For a loaded point set (`file:PATH`, a Python array), its index among them.
    pub fn loaded_index(self) -> Option<usize> {
        let i = self.0 as usize;
        (i >= SAMPLERS.len() && self.0 != u8::MAX).then(|| i - SAMPLERS.len())
    }

    /// Its generator.
    pub fn layout(self) -> &'static dyn DynLayout {
        self.info().layout
    }

    /// The canonical names, comma-separated ("independent, stratified, ...").
    pub fn names() -> String {
        SAMPLERS.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
    }

    /// The canonical names with their notes, for help text ("independent (random), stratified, ...").
    pub fn help_list() -> String {
        let entry = |s: &SamplerInfo| match s.note {
            Some(note) => format!("{} ({note})", s.name),
            None => s.name.to_string(),
        };
        SAMPLERS.iter().map(entry).collect::<Vec<_>>().join(", ")
    }
}

impl std::fmt::Debug for SamplerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

// ------------------------------------------------------------------------------------------------
// Points
// ------------------------------------------------------------------------------------------------

const TAG_UNIFORM: u32 = 0x51a7_0004;

/// Point k (0 <= k < n) of the n-point 2D set for stream (pixel, sample, dim) under seed. Both
/// coordinates in [0, 1). Any inputs are valid: n == 0 acts as 1; k >= n wraps modulo n for
/// Stratified/GridCenter and continues the sequence for Halton. Builds a [`PointSet`] per call;
/// hoist one out of hot loops (its setup is a divisor search for grid kinds).
pub fn point_2d(kind: SamplerKind, pixel: u32, sample: u32, dim: u32, k: u32, n: u32, seed: u64) -> [f32; 2] {
    PointSet::new(kind, n).point(pixel, sample, dim, k, seed)
}

/// Eight lanes of `point_2d`, lane i = point_2d(kind, pixel[i], sample[i], dim, k[i], n, seed),
/// bit-identical to the scalar function; coordinates in [0, 1).
pub fn point_2d_x8(kind: SamplerKind, pixel: U8, sample: U8, dim: u32, k: U8, n: u32, seed: u64) -> (F8, F8) {
    PointSet::new(kind, n).point_x8(pixel, sample, dim, k, seed)
}

/// One independent uniform value in [0, 1) for (pixel, sample, dim, k) under seed (a hash; any
/// inputs valid). Independent of the values `point_2d` returns for the same arguments.
pub fn uniform_1d(pixel: u32, sample: u32, dim: u32, k: u32, seed: u64) -> f32 {
    unit(hash(TAG_UNIFORM, seed, dim, [pixel, sample, k]))
}

/// Eight lanes of `uniform_1d`, bit-identical to it per lane; values in [0, 1).
pub fn uniform_1d_x8(pixel: U8, sample: U8, dim: u32, k: U8, seed: u64) -> F8 {
    unit(hash(TAG_UNIFORM, seed, dim, [pixel, sample, k]))
}

/// A 2D layout prepared once per (kind, n, width), so per-point calls skip the grid-shape and
/// divisor setup; `point`/`point_x8` equal `point_2d`/`point_2d_x8` for the same kind and n.
#[derive(Clone, Copy, Debug)]
pub struct PointSet {
    kind: SamplerKind,
    shape: SetShape,
}

impl PointSet {
    /// Layout of `kind` for sets of `n` points; n == 0 acts as 1 (any n is valid). The image width
    /// is unknown (screen-space layouts such as `zsobol` then order pixels by their linear id).
    pub fn new(kind: SamplerKind, n: u32) -> Self {
        Self::for_image(kind, n, 0)
    }

    /// Layout of `kind` for sets of `n` points whose pixel ids are `y * width + x`.
    pub fn for_image(kind: SamplerKind, n: u32, width: u32) -> Self {
        Self { kind, shape: SetShape::new(n, width) }
    }

    /// The same kind and image width for sets of `n` points.
    pub fn with_n(&self, n: u32) -> Self {
        Self::for_image(self.kind, n, self.shape.width())
    }

    /// The layout kind.
    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// Points per set, >= 1.
    pub fn n(&self) -> u32 {
        self.shape.n()
    }

    /// What the set is prepared for (n, image width, grid).
    pub fn shape(&self) -> SetShape {
        self.shape
    }

    /// Point k of the set for (pixel, sample, dim) under seed, as [`point_2d`]; coordinates in [0, 1).
    #[inline]
    pub fn point(&self, pixel: u32, sample: u32, dim: u32, k: u32, seed: u64) -> [f32; 2] {
        #[cfg(test)]
        replay::count_api_call();
        let (x, y) = self.kind.layout().point_1(&self.shape, pixel, sample, dim, k, seed);
        [x, y]
    }

    /// Eight lanes of [`PointSet::point`], bit-identical per lane; coordinates in [0, 1).
    #[inline]
    pub fn point_x8(&self, pixel: U8, sample: U8, dim: u32, k: U8, seed: u64) -> (F8, F8) {
        #[cfg(test)]
        replay::count_api_call();
        self.kind.layout().point_8(&self.shape, pixel, sample, dim, k, seed)
    }

    /// [`PointSet::point_x8`] of two dimensions `dims` at indices `k`, bit for bit: one call
    /// (`Layout::point_pair`), which a layout may run as two interleaved chains.
    #[inline]
    pub fn point_pair_x8(&self, pixel: U8, sample: U8, dims: [u32; 2], k: [U8; 2], seed: u64) -> [(F8, F8); 2] {
        // (Two points: two calls in the count the replay tests compare with the log.)
        #[cfg(test)]
        for _ in 0..2 {
            replay::count_api_call();
        }
        self.kind.layout().point_pair_8(&self.shape, pixel, sample, dims, k, seed)
    }

    /// The set of (pixel, sample, dim) for 8 lanes, with the hash work its points share done once:
    /// `stream_x8(..).point(k)` equals `point_x8(pixel, sample, dim, U8::splat(k), seed)` bit for
    /// bit and is much cheaper (the cell of a lane-uniform k is found in scalar code).
    #[inline]
    pub fn stream_x8(&self, pixel: U8, sample: U8, dim: u32, seed: u64) -> Stream<U8> {
        #[cfg(test)]
        replay::count_api_call();
        let layout = self.kind.layout();
        Stream { layout, shape: self.shape, key: layout.stream_8(&self.shape, pixel, sample, dim, seed) }
    }

    /// The per-k part of point k of every stream of this set ([`Stream::point_k`]), found once.
    #[inline]
    pub fn point_k(&self, k: u32) -> PointK {
        PointK { k, span: self.kind.layout().cell_span(&self.shape, k) }
    }

    /// Scalar twin of [`PointSet::stream_x8`].
    #[inline]
    pub fn stream_1(&self, pixel: u32, sample: u32, dim: u32, seed: u64) -> Stream<u32> {
        #[cfg(test)]
        replay::count_api_call();
        let layout = self.kind.layout();
        Stream { layout, shape: self.shape, key: layout.stream_1(&self.shape, pixel, sample, dim, seed) }
    }
}

/// The n-point set of one (pixel, sample, dim) per lane, prepared by [`PointSet::stream_x8`].
#[derive(Clone, Copy)]
pub struct Stream<L> {
    layout: &'static dyn DynLayout,
    shape: SetShape,
    key: StreamKey<L>,
}

impl<L: std::fmt::Debug> std::fmt::Debug for Stream<L> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Stream").field("shape", &self.shape).field("key", &self.key).finish()
    }
}

impl Stream<U8> {
    /// Point k of the set, coordinates in [0, 1); equal to `PointSet::point_x8` for the same k.
    #[inline]
    pub fn point(&self, k: u32) -> (F8, F8) {
        #[cfg(test)]
        replay::count_api_call();
        self.layout.stream_point_8(&self.shape, &self.key, k)
    }
}

/// Point k of a set with its lane- and stream-independent work done ([`PointSet::point_k`]):
/// for grid layouts, the cell's span.
#[derive(Clone, Copy, Debug)]
pub struct PointK {
    k: u32,
    span: Option<[u32; 4]>,
}

impl PointK {
    /// The point index k.
    pub fn k(&self) -> u32 {
        self.k
    }
}

impl Stream<U8> {
    /// [`Stream::point`] of `pk`'s k, bit for bit (`pk` from the same set's
    /// [`PointSet::point_k`]); cheaper when many streams draw the same k.
    #[inline]
    pub fn point_k(&self, pk: &PointK) -> (F8, F8) {
        #[cfg(test)]
        replay::count_api_call();
        self.layout.stream_point_span_8(&self.shape, &self.key, pk.k, pk.span)
    }
}

impl Stream<u32> {
    /// Point k of the set, coordinates in [0, 1); equal to `PointSet::point` for the same k.
    #[inline]
    pub fn point(&self, k: u32) -> (f32, f32) {
        #[cfg(test)]
        replay::count_api_call();
        self.layout.stream_point_1(&self.shape, &self.key, k)
    }
}

#[cfg(test)]
mod tests;

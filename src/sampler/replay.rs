//! Sampler replay, the sampler's twin of `strata rays`: a recording render appends every sampler
//! call it makes to a compact per-thread log, and [`Recording::replay`] makes exactly those calls
//! again on the sampler alone, with the render's layouts ([`ReplaySets`]) or with every call
//! switched to another registered kind ([`ReplaySets::with_kind`]). `strata profile` times the
//! replay on one thread (`session::replay`).
//!
//! The render reports its calls here from one place, the integrators' sample handle
//! (`integrator/samples.rs`: [`pixel_point`], or [`camera_streams`] and [`camera_point`];
//! [`light_streams`], [`light_point`]; [`path_point`], or [`table_streams`] and [`table_point`]),
//! and `render.rs` brackets each
//! tile with [`tile_begin`]/[`tile_end`]. Off (the default), each report is one relaxed atomic
//! load; recording only observes, so images are bit-identical either way.
//!
//! **Log.** One `u32` op word per call (opcode, flags, the dimension in the high 24 bits),
//! followed only by what changed since the tile's previous call: the 8 pixel ids (2 words when
//! they form a 4x2 packet block), the sample indices (1 word when lane-uniform), k (1 word when
//! lane-uniform). A camera call costs about 3 words, a path-tracer bounce chunk 17 words for its
//! first call and 1 for each further dimension.
//!
//! **Cap.** At most `cap_words` words are kept, chosen deterministically whatever the thread
//! count: each tile gets a level (the trailing zeros of a hash of its index, so level >= L for a
//! fraction 2^-L of the tiles); the kept tiles are exactly those of level >= T for the smallest T
//! that fits the cap. Every call of every tile is still counted ([`Recording::calls`]), so a
//! replay of the kept tiles scales by `calls / recorded_calls`.

use super::{GridTable, PathDim, PointSet, SamplerKind, Stream};
use crate::simd::U8;
use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Mutex;

/// Log words a recording keeps by default (64 MiB).
pub const DEFAULT_CAP_WORDS: usize = 1 << 24;

// Opcodes (low 2 bits of the op word).
const OP_POINT: u32 = 0;
const OP_STREAM: u32 = 1;
const OP_STREAM_POINT: u32 = 2;
const OP_PATH: u32 = 3;
// Flags.
const F_PIXEL: u32 = 1 << 2;
const F_PIXEL_BLOCK: u32 = 1 << 3;
const F_SAMPLE: u32 = 1 << 4;
const F_SAMPLE_SPLAT: u32 = 1 << 5;
const F_K_SPLAT: u32 = 1 << 6;
const F_RESET: u32 = 1 << 7;
/// On `OP_STREAM` / `OP_STREAM_POINT` (which have no k word): the camera's stream table, not the
/// light streams' (the bit is `F_K_SPLAT` of `OP_POINT`).
const F_CAMERA: u32 = 1 << 6;
/// On `OP_PATH` (which has no k word): the light table, not the path table.
const F_LIGHT_TABLE: u32 = 1 << 6;
/// On `OP_PATH`: a table stream (`GridTable::path_stream_x8` of the pixels), appended to the
/// table-stream list, not a point.
const F_TABLE_STREAM: u32 = 1 << 7;
/// On `OP_STREAM_POINT`: a point of the table-stream list (not the light or camera streams').
const F_TABLE: u32 = 1 << 7;
/// On `OP_STREAM_POINT | F_TABLE`: no call, a marker that a fresh table-stream list follows (the
/// op word alone).
const F_TABLE_RESET: u32 = 1 << 2;
/// On `OP_STREAM_POINT | F_TABLE`: no call, a marker that the next two `OP_PATH` points are
/// drawn by one call (`GridTable::path_point_pair_x8`: two chains side by side).
const F_TABLE_PAIR: u32 = 1 << 3;
const DIM_SHIFT: u32 = 8;
/// Dimensions from here on take a word of their own (escape: the op word's dim field is all ones).
const DIM_WIDE: u32 = (1 << (32 - DIM_SHIFT)) - 1;

static RECORDING: AtomicBool = AtomicBool::new(false);
static THRESHOLD: AtomicU32 = AtomicU32::new(0);
static SHARED: Mutex<Shared> =
    Mutex::new(Shared { cap_words: DEFAULT_CAP_WORDS, words: 0, calls: 0, tiles: Vec::new() });

struct Shared {
    cap_words: usize,
    words: usize,
    calls: u64,
    tiles: Vec<TileLog>,
}

/// The log of one tile.
#[derive(Clone, Debug, PartialEq, Eq)]
struct TileLog {
    tile: u32,
    level: u32,
    calls: u64,
    words: Vec<u32>,
}

struct ThreadLog {
    /// this thread records (the threads of the recording render's pool, see [`arm`])
    armed: bool,
    /// this tile's calls are counted (a recording runs and the thread is armed)
    counting: bool,
    /// this tile's calls are logged (its level is not below the threshold)
    active: bool,
    tile: u32,
    level: u32,
    /// calls of this tile (logged or not)
    calls: u64,
    words: Vec<u32>,
    last_pixel: [u32; 8],
    last_sample: [u32; 8],
    fresh: bool,
}

thread_local! {
    static LOG: RefCell<ThreadLog> = const {
        RefCell::new(ThreadLog {
            armed: false,
            counting: false,
            active: false,
            tile: 0,
            level: 0,
            calls: 0,
            words: Vec::new(),
            last_pixel: [0; 8],
            last_sample: [0; 8],
            fresh: true,
        })
    };
}

/// Whether a recording is running.
#[inline]
pub fn recording() -> bool {
    RECORDING.load(Ordering::Relaxed)
}

/// Starts recording (set it before a render, not during one), keeping at most `cap_words` log
/// words (at least 1).
pub fn start(cap_words: usize) {
    let mut sh = SHARED.lock().unwrap_or_else(|e| e.into_inner());
    *sh = Shared { cap_words: cap_words.max(1), words: 0, calls: 0, tiles: Vec::new() };
    THRESHOLD.store(0, Ordering::SeqCst);
    RECORDING.store(true, Ordering::SeqCst);
}

/// Arms (or disarms) this thread: only armed threads record, so that renders on other threads
/// (other pools, tests running at the same time) stay out of the log. Call it on every worker of
/// the recording render's pool (`rayon::ThreadPool::broadcast`).
pub fn arm(on: bool) {
    LOG.with_borrow_mut(|l| l.armed = on);
}

/// Stops recording and returns what the tiles logged, in tile order.
pub fn finish() -> Recording {
    RECORDING.store(false, Ordering::SeqCst);
    let mut sh = SHARED.lock().unwrap_or_else(|e| e.into_inner());
    let mut tiles = std::mem::take(&mut sh.tiles);
    tiles.sort_by_key(|t| t.tile);
    Recording { tiles, calls: sh.calls, level: THRESHOLD.load(Ordering::SeqCst) }
}

/// The level of tile `tile`: level >= L for a fraction 2^-L of the tiles.
fn level(tile: u32) -> u32 {
    let mut h = tile ^ 0x5bd1_e995;
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    h.trailing_zeros()
}

/// Starts the log of tile number `tile` on this thread (nothing unless recording).
#[inline]
pub fn tile_begin(tile: u32) {
    if !recording() {
        return;
    }
    LOG.with_borrow_mut(|l| {
        l.counting = l.armed;
        if !l.armed {
            return;
        }
        l.tile = tile;
        l.level = level(tile);
        l.active = l.level >= THRESHOLD.load(Ordering::Relaxed);
        l.calls = 0;
        l.words.clear();
        l.fresh = true;
    });
}

/// Ends this thread's tile: its calls are counted, and its log kept if it still fits the cap.
#[inline]
pub fn tile_end() {
    if !recording() {
        return;
    }
    let (tile, level, calls, active, words) = LOG.with_borrow_mut(|l| {
        let words = if l.active { std::mem::take(&mut l.words) } else { Vec::new() };
        let counting = std::mem::replace(&mut l.counting, false);
        (l.tile, l.level, if counting { l.calls } else { 0 }, std::mem::replace(&mut l.active, false), words)
    });
    if calls == 0 && !active {
        return;
    }
    let mut sh = SHARED.lock().unwrap_or_else(|e| e.into_inner());
    sh.calls += calls;
    if !active {
        return;
    }
    let threshold = THRESHOLD.load(Ordering::Relaxed);
    if level < threshold {
        return;
    }
    sh.words += words.len();
    sh.tiles.push(TileLog { tile, level, calls, words });
    let mut t = threshold;
    while sh.words > sh.cap_words && t <= 32 {
        t += 1;
        sh.tiles.retain(|x| x.level >= t);
        sh.words = sh.tiles.iter().map(|x| x.words.len()).sum();
    }
    THRESHOLD.store(t, Ordering::Relaxed);
}

impl ThreadLog {
    /// Logs one call: op word, then the lanes that changed and k.
    fn push(&mut self, op: u32, pixel: U8, sample: U8, dim: u32, k: Option<U8>) {
        if !self.counting {
            return;
        }
        self.calls += 1;
        if !self.active {
            return;
        }
        let (p, s) = (pixel.to_array(), sample.to_array());
        let mut op = op | dim.min(DIM_WIDE) << DIM_SHIFT;
        let new_p = self.fresh || p != self.last_pixel;
        let block = new_p && is_block(&p);
        let new_s = self.fresh || s != self.last_sample;
        let s_splat = s.iter().all(|&x| x == s[0]);
        let k = k.map(|k| k.to_array());
        let k_splat = k.is_some_and(|k| k.iter().all(|&x| x == k[0]));
        for (on, flag) in [
            (new_p, F_PIXEL),
            (block, F_PIXEL_BLOCK),
            (new_s, F_SAMPLE),
            (new_s && s_splat, F_SAMPLE_SPLAT),
            (k_splat, F_K_SPLAT),
        ] {
            if on {
                op |= flag;
            }
        }
        self.words.push(op);
        if dim >= DIM_WIDE {
            self.words.push(dim);
        }
        if block {
            self.words.extend([p[0], p[4]]);
        } else if new_p {
            self.words.extend(p);
        }
        if new_s {
            if s_splat {
                self.words.push(s[0]);
            } else {
                self.words.extend(s);
            }
        }
        match k {
            Some(k) if k_splat => self.words.push(k[0]),
            Some(k) => self.words.extend(k),
            None => {}
        }
        (self.last_pixel, self.last_sample, self.fresh) = (p, s, false);
    }
}

/// Pixel ids of a 4x2 block: lane i = p0 + i % 4 + (i / 4) (p4 - p0).
fn is_block(p: &[u32; 8]) -> bool {
    let row = p[4].wrapping_sub(p[0]);
    (0..8u32).all(|i| p[i as usize] == p[0].wrapping_add(i % 4).wrapping_add((i / 4).wrapping_mul(row)))
}

fn block(p0: u32, p4: u32) -> [u32; 8] {
    let row = p4.wrapping_sub(p0);
    std::array::from_fn(|i| p0.wrapping_add(i as u32 % 4).wrapping_add((i as u32 / 4).wrapping_mul(row)))
}

/// Reports `pixel_set.point_x8(pixel, sample, dim, k, seed)` (the camera's pixel jitter).
#[inline]
pub fn pixel_point(pixel: U8, sample: U8, dim: u32, k: U8) {
    if recording() {
        LOG.with_borrow_mut(|l| l.push(OP_POINT, pixel, sample, dim, Some(k)));
    }
}

/// Reports a table point of dimension `dim` for pixel samples `sample`
/// ([`GridTable::path_point_x8`]): from the light table (`light`: light points and choices of
/// either integrator) or the path table (the path tracer's other dimensions).
#[inline]
pub fn path_point(pixel: U8, sample: U8, dim: u32, light: bool) {
    if recording() {
        let op = if light { OP_PATH | F_LIGHT_TABLE } else { OP_PATH };
        LOG.with_borrow_mut(|l| l.push(op, pixel, sample, dim, None));
    }
}

/// Reports the two points of [`path_point`] (dimension and table each) for the same pixels
/// and samples drawn by one call (`Samples::table_point_pair`).
#[inline]
pub fn path_point_pair(pixel: U8, sample: U8, dims: [(u32, bool); 2]) {
    if recording() {
        LOG.with_borrow_mut(|l| {
            if l.counting && l.active {
                l.words.push(OP_STREAM_POINT | F_TABLE | F_TABLE_PAIR);
            }
            for (dim, light) in dims {
                l.push(if light { OP_PATH | F_LIGHT_TABLE } else { OP_PATH }, pixel, sample, dim, None);
            }
        });
    }
}

/// Reports a fresh table of light streams, `light_set.stream_x8(pixel, sample, dim, seed)` for
/// each of `pixels` in order (stream i of the table is the i-th).
#[inline]
pub fn light_streams(pixels: impl IntoIterator<Item = U8>, sample: U8, dim: u32) {
    if recording() {
        LOG.with_borrow_mut(|l| {
            for (i, p) in pixels.into_iter().enumerate() {
                l.push(OP_STREAM | if i == 0 { F_RESET } else { 0 }, p, sample, dim, None);
            }
        });
    }
}

/// Reports more light streams appended to the table of the last [`light_streams`] (stream
/// `len + i` of the table is the i-th of `pixels`): a second stream per packet, such as the light
/// choice of `direct` with one light per sample.
#[inline]
pub fn light_streams_append(pixels: impl IntoIterator<Item = U8>, sample: U8, dim: u32) {
    if recording() {
        LOG.with_borrow_mut(|l| {
            for p in pixels {
                l.push(OP_STREAM, p, sample, dim, None);
            }
        });
    }
}

/// Reports `streams[stream].point(k)` of the last table of [`light_streams`].
#[inline]
pub fn light_point(stream: u32, k: u32) {
    stream_point(OP_STREAM_POINT, stream, k);
}

/// Logs one stream-point call `op` (`OP_STREAM_POINT`, with `F_CAMERA` for the camera table).
#[inline]
fn stream_point(op: u32, stream: u32, k: u32) {
    if recording() {
        LOG.with_borrow_mut(|l| {
            if !l.counting {
                return;
            }
            l.calls += 1;
            if l.active {
                l.words.extend([op, stream, k]);
            }
        });
    }
}

/// Reports a fresh list of table streams, `table.path_stream_x8(d, pixel)` of dimension `dim` for
/// each of `pixels` in order, from the light table (`light`) or the path table
/// (`integrator/samples.rs`: `Samples::table_streams`).
#[inline]
pub fn table_streams(pixels: impl IntoIterator<Item = U8>, light: bool, dim: u32) {
    if recording() {
        LOG.with_borrow_mut(|l| {
            if l.counting && l.active {
                l.words.push(OP_STREAM_POINT | F_TABLE | F_TABLE_RESET);
            }
            let op = OP_PATH | F_TABLE_STREAM | if light { F_LIGHT_TABLE } else { 0 };
            for p in pixels {
                l.push(op, p, U8::splat(0), dim, None);
            }
        });
    }
}

/// Reports `streams[stream].point(k)` of the last list of [`table_streams`].
#[inline]
pub fn table_point(stream: u32, k: u32) {
    stream_point(OP_STREAM_POINT | F_TABLE, stream, k);
}

/// Reports a fresh table of camera streams, `pixel_set.stream_x8(pixel, sample, dim, seed)` for
/// each of `pixels` in order (the pixel jitter of a batch of samples, see `integrator/samples.rs`).
#[inline]
pub fn camera_streams(pixels: impl IntoIterator<Item = U8>, sample: U8, dim: u32) {
    if recording() {
        LOG.with_borrow_mut(|l| {
            for (i, p) in pixels.into_iter().enumerate() {
                l.push(OP_STREAM | F_CAMERA | if i == 0 { F_RESET } else { 0 }, p, sample, dim, None);
            }
        });
    }
}

/// Reports `streams[stream].point(k)` of the last table of [`camera_streams`].
#[inline]
pub fn camera_point(stream: u32, k: u32) {
    stream_point(OP_STREAM_POINT | F_CAMERA, stream, k);
}

/// The layouts a replay draws from, one per call site: what the render had (the integrator's
/// `pixel_set`, `light_set` and `path_set`, with its spp and seed), or one kind everywhere
/// ([`ReplaySets::with_kind`]).
#[derive(Clone, Debug)]
pub struct ReplaySets {
    /// the camera's pixel jitter layout
    pub pixel: PointSet,
    /// the light sample layout of `direct`
    pub light: PointSet,
    /// the light dimensions drawn over all of a pixel's light samples (both integrators)
    pub light_table: GridTable,
    /// the path tracer's layout of its other path dimensions
    pub path: GridTable,
    /// samples per pixel the path tracer shuffles strata over
    pub path_n: u32,
    /// base seed
    pub seed: u64,
}

impl ReplaySets {
    /// The same sets (sizes and image width) with every call site drawing from `kind`.
    pub fn with_kind(&self, kind: SamplerKind) -> Self {
        let re = |s: &PointSet| PointSet::for_image(kind, s.n(), s.shape().width());
        Self {
            pixel: re(&self.pixel),
            light: re(&self.light),
            light_table: GridTable::new(re(self.light_table.set())),
            path: GridTable::new(re(self.path.set())),
            path_n: self.path_n,
            seed: self.seed,
        }
    }
}

/// What a replay does with each logged call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayMode {
    /// make the sampler call
    Sample,
    /// decode the call only (its cost is subtracted from a timed [`ReplayMode::Sample`] run)
    DecodeOnly,
}

/// What a recording render logged: the kept tiles' calls, and the count of every call.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Recording {
    tiles: Vec<TileLog>,
    calls: u64,
    level: u32,
}

impl Recording {
    /// Sampler calls the render made (every tile, logged or not).
    pub fn calls(&self) -> u64 {
        self.calls
    }

    /// Calls in the log (all of them unless the cap kept a subset of the tiles).
    pub fn recorded_calls(&self) -> u64 {
        self.tiles.iter().map(|t| t.calls).sum()
    }

    /// The log holds a subset of the render's calls (the cap was reached).
    pub fn is_subset(&self) -> bool {
        self.recorded_calls() < self.calls
    }

    /// Tiles in the log.
    pub fn tiles(&self) -> usize {
        self.tiles.len()
    }

    /// Log words kept.
    pub fn words(&self) -> usize {
        self.tiles.iter().map(|t| t.words.len()).sum()
    }

    /// Kept tiles are those of level >= this (0: every tile; a fraction about 2^-level otherwise).
    pub fn level(&self) -> u32 {
        self.level
    }
}

#[path = "replay_play.rs"]
mod play;

#[cfg(test)]
thread_local! {
    static API_CALLS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Test builds: counts one sampler API call on this thread (the counter the replay tests compare
/// with the log, independent of it).
#[cfg(test)]
#[inline]
pub(crate) fn count_api_call() {
    API_CALLS.with(|c| c.set(c.get() + 1));
}

/// Test builds: this thread's sampler API calls since the last take.
#[cfg(test)]
pub(crate) fn take_api_calls() -> u64 {
    API_CALLS.with(|c| c.replace(0))
}

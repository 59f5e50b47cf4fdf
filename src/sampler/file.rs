//! `file:PATH` (and Python arrays): a layout over 2D point sets loaded at run time, and the
//! run-time part of the registry that holds them.
//!
//! A loaded [`PointTable`] has `sets` sets of `points` points (24-bit fixed point, as every
//! layout's output). Point k of the n-point set of stream (pixel, sample, dim) under seed is point
//! `i mod points` of one set of the table, `i = sample * n + k`, randomized per (pixel, dim, block
//! `i / points`); renders of a fixed spp are refused when they would need a block past the first
//! (the session's check), equal-time runs go on with freshly randomized blocks:
//!
//! - **which set** ([`SetMap`]): `hash` (the default) picks set `floor(h * sets / 2^32)` with
//!   `h = hash(TAG_FILE, seed, dim, pixel, block)` (murmur3 `fmix32` folding, see `hash.rs`), so
//!   one set can serve a whole image; `pixel` takes set `pixel mod sets` (a file holding one set
//!   per pixel, e.g. a layout exported by `strata pointset --export`).
//! - **how it is randomized** ([`Scramble`], keyed by `h`): `shift` (the default), a
//!   Cranley-Patterson rotation `x + s mod 1` per axis; `owen`, a nested uniform (Owen) digit
//!   scramble in base 2; `xor`, a random digital shift; `none` (deterministic, biased).
//!
//! Why `shift` is the default: it keeps every toroidal property of the set (a rank-1 lattice stays
//! a lattice, a blue-noise set keeps its minimum toroidal distance and power spectrum), which is
//! what most hand-made sets (lattices, BNOT, LDBN, Lloyd, dart throwing) are built for, and it makes
//! every point uniform over [0, 1)^2, so estimates are unbiased whatever the set. Digital nets
//! (Sobol', pmj02) keep their elementary-interval stratification only under a digit scramble: use
//! `owen` for those (it also gives scrambled nets their n^-1.5 variance rate on smooth integrands).
//!
//! A table with one coordinate per point (`dims == 1`) is refused unless a registry layout pads
//! it ([`FileLayout::pad`]): its points' second coordinate then comes from that layout.
//!
//! Registry: [`SamplerKind`] is a `u8` index; indices past the static [`SAMPLERS`] name loaded
//! layouts ([`register`]), leaked once per distinct (content, options), so kinds stay `Copy` and
//! every call site (camera, lights, replay, compare) works unchanged. At most [`MAX_LOADED`]
//! distinct tables per process.

use super::hash::{hash, mix};
use super::lanes::Lanes;
use super::layout::{Layout, SetLayout, SetShape};
use super::{SamplerInfo, SamplerKind, SAMPLERS};
use std::sync::{Mutex, OnceLock};

const TAG_FILE: u32 = 0x51a7_0005;

/// Distinct loaded layouts a process can hold (the `u8` kinds left after the registry and the
/// test-only kind).
pub const MAX_LOADED: usize = 255 - SAMPLERS.len();

/// Largest table accepted: points over all sets (8 bytes each in memory).
pub const MAX_TABLE_POINTS: u64 = 1 << 27;

/// Which set of the table serves a (pixel, dimension).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SetMap {
    /// a keyed hash of (seed, dimension, pixel) picks the set (default)
    Hash,
    /// set `pixel mod sets` (files exported per pixel)
    Pixel,
}

/// How a set's points are randomized per (pixel, dimension).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scramble {
    /// Cranley-Patterson rotation (default): keeps toroidal structure, unbiased
    Shift,
    /// nested uniform (Owen) scramble of the base-2 digits: keeps digital nets nets, unbiased
    Owen,
    /// random digital shift (XOR of the digits): keeps nets, cheaper, less random than Owen
    Xor,
    /// the points as given: deterministic and biased
    None,
}

impl SetMap {
    /// "hash" | "pixel".
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "hash" => Some(Self::Hash),
            "pixel" => Some(Self::Pixel),
            _ => None,
        }
    }
    /// Canonical name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Hash => "hash",
            Self::Pixel => "pixel",
        }
    }
}

impl Scramble {
    /// "shift" | "owen" | "xor" | "none".
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "shift" | "cp" => Some(Self::Shift),
            "owen" => Some(Self::Owen),
            "xor" => Some(Self::Xor),
            "none" => Some(Self::None),
            _ => None,
        }
    }
    /// Canonical name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Shift => "shift",
            Self::Owen => "owen",
            Self::Xor => "xor",
            Self::None => "none",
        }
    }
}

/// Loaded point sets as 24-bit fixed point: set s, point i at `xy[s * points + i]`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct PointTable {
    sets: u32,
    points: u32,
    xy: Vec<[u32; 2]>,
}

impl PointTable {
    /// A table of `sets` sets of `points` points from 24-bit fixed-point coordinates (each below
    /// 2^24; `xy.len() == sets * points`); None if the shape does not match or is empty.
    pub fn new(sets: u32, points: u32, xy: Vec<[u32; 2]>) -> Option<Self> {
        let ok = sets > 0
            && points > 0
            && xy.len() as u64 == u64::from(sets) * u64::from(points)
            && xy.len() as u64 <= MAX_TABLE_POINTS
            && xy.iter().flatten().all(|&c| c < 1 << 24);
        ok.then_some(Self { sets, points, xy })
    }

    /// Number of sets.
    pub fn sets(&self) -> u32 {
        self.sets
    }

    /// Points per set.
    pub fn points(&self) -> u32 {
        self.points
    }
}

/// 24-bit fixed point of a coordinate in [0, 1): `floor(x * 2^24)` (exact for the registry's
/// outputs, which are multiples of 2^-24).
pub fn fixed24(x: f64) -> u32 {
    ((x * 16_777_216.0).floor() as u32).min((1 << 24) - 1)
}

/// The layout of a loaded [`PointTable`] (see the module docs).
#[derive(Debug)]
pub struct FileLayout {
    /// the points
    pub table: PointTable,
    /// which set serves a (pixel, dimension)
    pub map: SetMap,
    /// randomization per (pixel, dimension)
    pub scramble: Scramble,
    /// for a table of one coordinate per point: the registry layout whose second coordinate
    /// pads it (None: the table has two)
    pub pad: Option<SamplerKind>,
}

impl Layout for FileLayout {
    #[inline]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        let t = &self.table;
        let points = t.points;
        let i = sample.mul(L::splat(set.n())).add(k);
        // Block `i / points` of an index past the set (equal-time runs, whose spp is not known in
        // advance) gets its own set and randomization: blocks of `points` points, each unbiased.
        let (block, i) = (i.map(|i| i / points), i.map(|i| i % points));
        let h = hash(TAG_FILE, seed, dim, [pixel, block]);
        let s = match self.map {
            SetMap::Hash => h.mulhi(L::splat(t.sets)),
            SetMap::Pixel => pixel.map(|p| p % t.sets),
        };
        let slot = s.mul(L::splat(points)).add(i);
        let (x, y) = (slot.map(|j| t.xy[j as usize][0]), slot.map(|j| t.xy[j as usize][1]));
        let (kx, ky) = (mix(h, L::splat(1)), mix(h, L::splat(2)));
        let scramble = |v: L, key: L| match self.scramble {
            Scramble::Shift => v.add(key.shr(8)).and(L::splat(0xff_ffff)),
            Scramble::Xor => v.xor(key.shr(8)),
            Scramble::Owen => super::sobol::owen24(v, key),
            Scramble::None => v,
        };
        let x = scramble(x, kx).unit24();
        match self.pad {
            None => (x, scramble(y, ky).unit24()),
            Some(kind) => (x, L::dyn_point(&SetLayout { layout: kind.layout(), set }, pixel, sample, dim, k, seed).1),
        }
    }
}

/// A loaded layout's registry data beside its [`SamplerInfo`].
struct Loaded {
    info: SamplerInfo,
    digest: &'static str,
    points: u32,
    sets: u32,
}

static LOADED: [OnceLock<Loaded>; MAX_LOADED] = [const { OnceLock::new() }; MAX_LOADED];
/// (content digest and options, kind) of every registered table, in registration order.
static KEYS: Mutex<Vec<(String, SamplerKind)>> = Mutex::new(Vec::new());

/// Why a table could not be registered.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum RegisterError {
    /// the process holds [`MAX_LOADED`] distinct tables already
    #[error("{MAX_LOADED} distinct point sets are loaded in this process already (restart it to load more)")]
    Full,
}

/// Registers `layout` under `name` (e.g. `file:pts.npy`) with content `digest` (a hash of the
/// points and options: equal digests give the same kind, so loading a file twice costs nothing).
pub fn register(name: &str, digest: &str, layout: FileLayout) -> Result<SamplerKind, RegisterError> {
    let key =
        format!("{digest}/{}/{}/{}", layout.map.name(), layout.scramble.name(), layout.pad.map_or("-", |k| k.name()));
    let mut keys = KEYS.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((_, kind)) = keys.iter().find(|(k, _)| *k == key) {
        return Ok(*kind);
    }
    let j = keys.len();
    if j >= MAX_LOADED {
        return Err(RegisterError::Full);
    }
    let leak = |s: String| -> &'static str { Box::leak(s.into_boxed_str()) };
    let (points, sets) = (layout.table.points, layout.table.sets);
    let description = leak(format!(
        "{sets} sets of {points} points, {} scramble, set by {}",
        layout.scramble.name(),
        layout.map.name()
    ));
    let biased = layout.scramble == Scramble::None;
    let layout: &'static FileLayout = Box::leak(Box::new(layout));
    let mut info = SamplerInfo::new(leak(name.to_string()), &[], description, layout).period(u64::from(points));
    if biased {
        info = info.biased();
    }
    let loaded = Loaded { info, digest: leak(digest.to_string()), points, sets };
    if LOADED[j].set(loaded).is_err() {
        unreachable!("slot {j} is filled only here, under the lock");
    }
    let kind = SamplerKind::loaded(j);
    keys.push((key, kind));
    Ok(kind)
}

/// The registry entry of loaded table `j` (a kind made by [`register`]).
pub(super) fn info(j: usize) -> &'static SamplerInfo {
    &loaded(j).info
}

fn loaded(j: usize) -> &'static Loaded {
    LOADED[j].get().expect("a loaded kind exists only after its slot is set")
}

/// The loaded kind registered under `name` (arrays are named `array:NAME:DIGEST`), if any.
pub fn loaded_named(name: &str) -> Option<SamplerKind> {
    let keys = KEYS.lock().unwrap_or_else(|p| p.into_inner());
    keys.iter().map(|(_, k)| *k).find(|k| name.starts_with("array:") && k.name() == name)
}

/// For a loaded kind: its content digest, sets and points per set; None for registry kinds.
pub fn file_info(kind: SamplerKind) -> Option<(&'static str, u32, u32)> {
    kind.loaded_index().map(|j| {
        let l = loaded(j);
        (l.digest, l.sets, l.points)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::PointSet;

    fn table(sets: u32, points: u32) -> PointTable {
        let xy = (0..sets * points).map(|j| [(j * 7919) % (1 << 24), (j * 104_729) % (1 << 24)]).collect();
        PointTable::new(sets, points, xy).unwrap()
    }

    fn kind(map: SetMap, scramble: Scramble, digest: &str) -> SamplerKind {
        kind_of(table(3, 16), map, scramble, digest)
    }

    fn kind_of(table: PointTable, map: SetMap, scramble: Scramble, digest: &str) -> SamplerKind {
        register("file:test", digest, FileLayout { table, map, scramble, pad: None }).unwrap()
    }

    #[test]
    fn unscrambled_pixel_map_returns_the_table() {
        let k = kind(SetMap::Pixel, Scramble::None, "unscrambled");
        let t = table(3, 16);
        let set = PointSet::new(k, 16);
        for pixel in 0..7 {
            for i in 0..16 {
                let want = t.xy[((pixel % 3) * 16 + i) as usize].map(|c| c as f32 / 16_777_216.0);
                assert_eq!(set.point(pixel, 0, 5, i, 99), want);
            }
        }
        // Sample s of an n-point draw is point s * n + k (mod points), as the sequence layouts.
        assert_eq!(PointSet::new(k, 4).point(1, 2, 0, 3, 0), set.point(1, 0, 0, 11, 0));
        assert_eq!(set.point(1, 1, 0, 3, 0), set.point(1, 0, 0, 3, 0));
        // Scrambled, the next block of `points` indices is a fresh randomization of a set.
        let shifted = PointSet::new(kind(SetMap::Hash, Scramble::Shift, "blocks"), 16);
        let block = |b: u32| (0..16).map(|i| shifted.point(1, b, 0, i, 0)).collect::<Vec<_>>();
        assert_ne!(block(0), block(1));
        assert_eq!(block(1), (0..16).map(|i| shifted.point(1, 0, 0, 16 + i, 0)).collect::<Vec<_>>());
        assert!(k.is_biased() && k.info().period == Some(16));
    }

    #[test]
    fn registering_twice_gives_the_same_kind() {
        let a = kind(SetMap::Hash, Scramble::Shift, "twice");
        assert_eq!(a, kind(SetMap::Hash, Scramble::Shift, "twice"));
        assert_ne!(a, kind(SetMap::Hash, Scramble::Owen, "twice"));
        assert_eq!(file_info(a), Some(("twice", 3, 16)));
        assert_eq!(file_info(SamplerKind::SOBOL), None);
    }

    #[test]
    fn scrambles_keep_their_structure() {
        // Shift: differences mod 1 between points of one set are kept; xor: XOR differences kept;
        // owen: points sharing their top digits still share them (nested); every scramble varies
        // with pixel, dim and seed.
        let t = table(1, 16);
        for scramble in [Scramble::Shift, Scramble::Xor, Scramble::Owen] {
            let k = kind_of(t.clone(), SetMap::Hash, scramble, "structure: one set");
            let set = PointSet::new(k, 16);
            let p = |pixel, dim, seed, i| set.point(pixel, 0, dim, i, seed).map(fixed24_f32);
            let a: Vec<_> = (0..16).map(|i| p(3, 1, 7, i)).collect();
            let b: Vec<_> = (0..16).map(|i| p(4, 1, 7, i)).collect();
            assert_ne!(a, b, "{scramble:?}");
            assert_ne!(a, (0..16).map(|i| p(3, 2, 7, i)).collect::<Vec<_>>());
            assert_ne!(a, (0..16).map(|i| p(3, 1, 8, i)).collect::<Vec<_>>());
            for (got, raw) in a.iter().zip(&t.xy) {
                for ax in 0..2 {
                    let (g, g0, r, r0) = (got[ax], a[0][ax], raw[ax], t.xy[0][ax]);
                    match scramble {
                        Scramble::Shift => assert_eq!(g.wrapping_sub(g0) & 0xff_ffff, r.wrapping_sub(r0) & 0xff_ffff),
                        Scramble::Xor => assert_eq!(g ^ g0, r ^ r0),
                        _ => {
                            for d in 1..8 {
                                assert_eq!(g >> (24 - d) == g0 >> (24 - d), r >> (24 - d) == r0 >> (24 - d));
                            }
                        }
                    }
                }
            }
        }
    }

    fn fixed24_f32(x: f32) -> u32 {
        fixed24(f64::from(x))
    }

    #[test]
    fn scalar_and_x8_agree() {
        use crate::simd::U8;
        for scramble in [Scramble::Shift, Scramble::Xor, Scramble::Owen, Scramble::None] {
            let k = kind(SetMap::Hash, scramble, "x8");
            let set = PointSet::for_image(k, 5, 9);
            let pixel = U8::new([0, 1, 2, 3, 100, 1000, 77, 5]);
            let kk = U8::new([0, 1, 2, 3, 4, 0, 1, 2]);
            let (x, y) = set.point_x8(pixel, U8::splat(2), 3, kk, 11);
            let (x, y) = (x.to_array(), y.to_array());
            for l in 0..8 {
                assert_eq!(set.point(pixel.to_array()[l], 2, 3, kk.to_array()[l], 11), [x[l], y[l]]);
            }
        }
    }

    #[test]
    fn scrambled_points_are_uniform() {
        // Unbiased: per-pixel estimates of f(x, y) = x + y^2 average to 1/2 + 1/3 within 4 standard
        // errors (the table's points are clustered, so only the randomization makes this hold).
        for scramble in [Scramble::Shift, Scramble::Owen, Scramble::Xor] {
            let k = kind(SetMap::Hash, scramble, "uniform");
            let set = PointSet::new(k, 16);
            let pixels = 20_000;
            let est: Vec<f64> = (0..pixels)
                .map(|pixel| {
                    let f = |[x, y]: [f32; 2]| f64::from(x) + f64::from(y) * f64::from(y);
                    (0..16).map(|i| f(set.point(pixel, 0, 0, i, 5))).sum::<f64>() / 16.0
                })
                .collect();
            let mean = est.iter().sum::<f64>() / f64::from(pixels);
            let var = est.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / f64::from(pixels - 1);
            let se = (var / f64::from(pixels)).sqrt();
            assert!((mean - (0.5 + 1.0 / 3.0)).abs() < 4.0 * se, "{scramble:?}: mean {mean} se {se}");
        }
    }
}

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
//! **The point index is shuffled per dimension** ([`FileLayout::shuffle`], the default; `none`
//! keeps one index for every dimension, a deliberate correlation): otherwise the pixel and the
//! light dimension of a sample take the same point of one set, and a 2D lattice becomes a
//! correlated 4D pattern (pbrt-v4's padded samplers shuffle for the same reason). The key is
//! `h` again, so each (pixel, dimension, block) has its own order. How depends on the set
//! ([`FileLayout::progressive`], measured when the set is loaded: `pointset::analysis`):
//!
//! - a set that is not progressive is used whole (equal-time runs take whole blocks), so its
//!   index is a keyed pseudo-random permutation of `0..points` ([`permute_lanes`]);
//! - a progressive set is used by prefixes, so its index is XORed with a key below the largest
//!   power of two `m <= points` (indices `>= m` are kept): the first 2^k indices become another
//!   aligned block of 2^k, which for a (0, 2)-sequence (Sobol', pmj02) is again a net.
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
    /// shuffle the point index per (pixel, dimension, block) (default; see the module docs)
    pub shuffle: bool,
    /// the sets' prefixes are sets as good as fresh ones of their size (measured on loading):
    /// used by prefixes; otherwise used whole (equal time runs whole sets)
    pub progressive: bool,
}

/// A keyed pseudo-random permutation of `0..n` per lane (`i < n`): bijective rounds on the
/// smallest power-of-two domain `>= n` (xor with the key, odd multiplies, xorshifts, a keyed add),
/// walked back into `0..n` (the same round again until the value lands inside: a cycle of the
/// bijection through `i` returns to `0..n`), then a keyed rotation `(x + r) mod n` so every
/// image is equally likely whatever the rounds' bias. Lanes walk together and keep their first
/// value inside, so one lane and eight agree bit for bit.
pub fn permute_lanes<L: Lanes>(i: L, n: u32, key: L) -> L {
    if n <= 1 {
        return L::splat(0);
    }
    let bits = 32 - (n - 1).leading_zeros();
    let m = L::splat(if bits == 32 { u32::MAX } else { (1u32 << bits) - 1 });
    let half = (bits / 2).max(1);
    let nn = L::splat(n);
    let (zero, one) = (L::splat(0), L::splat(1));
    let round = |x: L| {
        let x = x.xor(key.and(m)).mul(L::splat(0x2c1b_3c6d)).and(m);
        let x = x.xor(x.shr(half));
        let x = x.add(key.shr(11)).and(m).mul(key.shr(3).or(one).mul(L::splat(0x297a_2d39)).or(one)).and(m);
        x.xor(x.shr(half))
    };
    let (mut x, mut out, mut done) = (i, i, zero);
    loop {
        x = round(x);
        // Not done yet and inside: this lane's value.
        out = done.lt_select(one, x.lt_select(nn, x, out), out);
        done = done.or(x.lt_select(nn, one, zero));
        let all = std::cell::Cell::new(true);
        done.map(|d| {
            if d == 0 {
                all.set(false);
            }
            d
        });
        if all.get() {
            break;
        }
    }
    let r = mix(key, L::splat(7)).mulhi(nn);
    let y = out.add(r);
    y.lt_select(nn, y, y.sub(nn))
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
        let i = match (self.shuffle, self.progressive) {
            (false, _) => i,
            (true, false) => permute_lanes(i, points, mix(h, L::splat(3))),
            (true, true) => {
                let m = 1u32 << (31 - points.leading_zeros());
                i.lt_select(L::splat(m), i.xor(mix(h, L::splat(3)).and(L::splat(m - 1))), i)
            }
        };
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
    progressive: bool,
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
    let key = format!(
        "{digest}/{}/{}/{}/{}",
        layout.map.name(),
        layout.scramble.name(),
        layout.pad.map_or("-", |k| k.name()),
        if layout.shuffle { "shuffle" } else { "in-order" }
    );
    let mut keys = KEYS.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((_, kind)) = keys.iter().find(|(k, _)| *k == key) {
        return Ok(*kind);
    }
    let j = keys.len();
    if j >= MAX_LOADED {
        return Err(RegisterError::Full);
    }
    let leak = |s: String| -> &'static str { Box::leak(s.into_boxed_str()) };
    let (points, sets, progressive) = (layout.table.points, layout.table.sets, layout.progressive);
    let description = leak(format!(
        "{sets} sets of {points} points ({}), {} scramble, set by {}, index {}",
        if progressive { "progressive" } else { "not progressive: used in whole sets" },
        layout.scramble.name(),
        layout.map.name(),
        if layout.shuffle { "shuffled per dimension" } else { "shared by every dimension" }
    ));
    let biased = layout.scramble == Scramble::None;
    let layout: &'static FileLayout = Box::leak(Box::new(layout));
    let mut info = SamplerInfo::new(leak(name.to_string()), &[], description, layout).period(u64::from(points));
    if biased {
        info = info.biased();
    }
    let loaded = Loaded { info, digest: leak(digest.to_string()), points, sets, progressive };
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

/// For a loaded kind whose sets are not progressive: its points per set (a run must use whole
/// sets of them, never a prefix); None for progressive sets and registry kinds.
pub fn whole_set_points(kind: SamplerKind) -> Option<u32> {
    kind.loaded_index().map(loaded).filter(|l| !l.progressive).map(|l| l.points)
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
        let layout = FileLayout { table, map, scramble, pad: None, shuffle: false, progressive: true };
        register("file:test", digest, layout).unwrap()
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

    /// Eight lanes of kind `k`'s points (mixed pixels and point indices) equal its scalar points.
    fn assert_x8_is_scalar(k: SamplerKind) {
        use crate::simd::U8;
        let set = PointSet::for_image(k, 5, 9);
        let pixel = U8::new([0, 1, 2, 3, 100, 1000, 77, 5]);
        let kk = U8::new([0, 1, 2, 3, 4, 0, 1, 2]);
        let (x, y) = set.point_x8(pixel, U8::splat(2), 3, kk, 11);
        let (x, y) = (x.to_array(), y.to_array());
        for l in 0..8 {
            assert_eq!(set.point(pixel.to_array()[l], 2, 3, kk.to_array()[l], 11), [x[l], y[l]]);
        }
    }

    #[test]
    fn scalar_and_x8_agree() {
        for scramble in [Scramble::Shift, Scramble::Xor, Scramble::Owen, Scramble::None] {
            let k = kind(SetMap::Hash, scramble, "x8");
            assert_x8_is_scalar(k);
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

    /// The 144-point Fibonacci lattice (i / 144, frac(i * 89 / 144)) as one set.
    fn fibonacci144() -> PointTable {
        let xy =
            (0..144u32).map(|i| [fixed24(f64::from(i) / 144.0), fixed24(f64::from(i * 89 % 144) / 144.0)]).collect();
        PointTable::new(1, 144, xy).unwrap()
    }

    #[test]
    fn permutation_is_a_bijection_and_lanes_agree() {
        use crate::simd::U8;
        for n in [2u32, 3, 7, 16, 144, 1000] {
            for key in [0u32, 1, 0xdead_beef, 77] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let j = permute_lanes(i, n, key);
                    assert!(j < n && !seen[j as usize], "n {n} key {key}: {i} -> {j}");
                    seen[j as usize] = true;
                }
                let i8 = U8::new(std::array::from_fn(|l| (l as u32 * 5 + 1) % n));
                let k8 = U8::new(std::array::from_fn(|l| key.wrapping_add(l as u32 * 0x9e37)));
                let got = permute_lanes(i8, n, k8).to_array();
                for (l, &g) in got.iter().enumerate() {
                    assert_eq!(g, permute_lanes(i8.to_array()[l], n, k8.to_array()[l]));
                }
            }
        }
    }

    #[test]
    fn shuffle_gives_each_dimension_its_own_index() {
        // One lattice for every dimension, unscrambled: in order, sample k takes lattice point k in
        // dimension 0 and in dimension 1 (a correlated 4D pattern); shuffled, each dimension still
        // uses every point of the set once, but pairs them at random.
        let t = fibonacci144();
        let index = |p: [f32; 2]| t.xy.iter().position(|q| *q == p.map(fixed24_f32)).unwrap();
        for (shuffle, digest) in [(false, "fib in order"), (true, "fib shuffled")] {
            let layout = FileLayout {
                table: t.clone(),
                map: SetMap::Hash,
                scramble: Scramble::None,
                pad: None,
                shuffle,
                progressive: false,
            };
            let set = PointSet::new(register("file:fib", digest, layout).unwrap(), 144);
            for pixel in [0, 9, 1234] {
                let d0: Vec<usize> = (0..144).map(|k| index(set.point(pixel, 0, 0, k, 3))).collect();
                let d1: Vec<usize> = (0..144).map(|k| index(set.point(pixel, 0, 1, k, 3))).collect();
                for d in [&d0, &d1] {
                    let mut sorted = d.clone();
                    sorted.sort_unstable();
                    assert_eq!(sorted, (0..144).collect::<Vec<_>>(), "every point once per dimension");
                }
                let same = d0.iter().zip(&d1).filter(|(a, b)| a == b).count();
                if shuffle {
                    assert!(same <= 6, "pixel {pixel}: {same} of 144 samples share their point");
                } else {
                    assert_eq!(same, 144);
                }
            }
        }
    }

    #[test]
    fn progressive_sets_keep_aligned_prefixes() {
        // A progressive set of 256 is shuffled by an XOR below 256: the first 2^k indices of a
        // dimension are an aligned block of 2^k points of the set, in some order.
        let t = table(1, 256);
        let layout = FileLayout {
            table: t.clone(),
            map: SetMap::Hash,
            scramble: Scramble::None,
            pad: None,
            shuffle: true,
            progressive: true,
        };
        let set = PointSet::new(register("file:prog", "progressive xor", layout).unwrap(), 256);
        let index = |p: [f32; 2]| t.xy.iter().position(|q| *q == p.map(fixed24_f32)).unwrap();
        for dim in 0..4 {
            for k in [1usize, 4, 16, 64] {
                let mut got: Vec<usize> = (0..k as u32).map(|i| index(set.point(5, 0, dim, i, 1))).collect();
                got.sort_unstable();
                assert_eq!(got[k - 1] - got[0], k - 1, "dim {dim}, prefix {k}: {got:?}");
                assert_eq!(got[0] % k, 0);
            }
        }
        assert_eq!(
            whole_set_points(
                register(
                    "file:prog",
                    "progressive xor",
                    FileLayout {
                        table: t,
                        map: SetMap::Hash,
                        scramble: Scramble::None,
                        pad: None,
                        shuffle: true,
                        progressive: true
                    }
                )
                .unwrap()
            ),
            None
        );
    }

    #[test]
    fn shuffled_lanes_agree() {
        for progressive in [false, true] {
            let layout = FileLayout {
                table: table(3, 16),
                map: SetMap::Hash,
                scramble: Scramble::Shift,
                pad: None,
                shuffle: true,
                progressive,
            };
            let k = register("file:x8", if progressive { "x8 shuffled p" } else { "x8 shuffled" }, layout).unwrap();
            assert_eq!(whole_set_points(k), (!progressive).then_some(16));
            assert_x8_is_scalar(k);
        }
    }
}

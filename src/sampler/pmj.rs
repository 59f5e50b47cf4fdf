//! Progressive multi-jittered (0, 2) sequences (pmj02), after Christensen, Kensler and Kilpatrick
//! 2018, "Progressive Multi-Jittered Sample Sequences" (EGSR).
//!
//! A pmj02 sequence is ordered so that for every m its first 2^m points form a (0, m, 2)-net: one
//! point in every 2^-a x 2^-b elementary interval with a + b = m (which includes the 1D strata of
//! both axes), and its intermediate prefixes are progressively jittered: point 2^(2k) + s shares the
//! 2^-k x 2^-k cell of point s (diagonally opposite quadrant), and points 2^(2k+1) + s and
//! 2^(2k+1) + 4^k + s fill the two other quadrants of that cell, in random order.
//!
//! Construction. Going from 2^m to 2^(m+1) points, the cells of the new points at resolution
//! 2^-(m+1) on both axes are *forced*: the old points form a (0, m, 2)-net, so every level-m box
//! holds one old point, and a new point must take the other half of it in each shape. Indexing the
//! new points by the top m bits of y (they must differ: each 2^-m row gets one new point), bit
//! m+1 of y is the complement of that of the old point in the same row, and x bit a (a = 1..m+1) is
//! the complement of x bit a of the old point in the level-m box (x bits 1..a-1, y bits 1..m+1-a).
//! Two new points never share a box: say their y prefixes first differ at bit d. A common box of
//! shape 2^-a x 2^-(m+1-a) needs equal y bits 1..m+1-a, so a > m+1-d, and equal x bits 1..a. But
//! if x bits 1..m-d agree, the two old points that force x bit m+1-d lie in one level-(m-1) box
//! (x bits 1..m-d, y bits 1..d-1), one in each of its x halves, so x bit m+1-d differs. Hence
//! every (0, m, 2)-net extends to a (0, m+1, 2)-net, uniquely up to the positions inside the
//! 2^-(m+1) cells, which pmj02 draws uniformly. That is what Christensen et al.'s random search
//! with rejection finds; here it is computed directly, O(m) per point, never failing. The pairing
//! of new with old points then follows the progressive order above.
//!
//! Use. [`TABLES`] tables of [`TABLE_POINTS`] points are built once (first call, `OnceLock`;
//! integrators build them before rendering: `Layout::prepare`) from a fixed hash, so
//! they are identical on every run and machine. Stream (pixel, dim, seed) picks one table and an
//! axis swap (see below) and XORs the 24-bit fixed-point coordinates with a hashed 24-bit
//! constant per axis (a random digital shift: it maps every dyadic interval onto a
//! dyadic interval of the same size, so nets stay nets, and it makes each point uniform on the
//! 2^-24 grid, so estimates are unbiased). Point k of the n-point set of (pixel, sample, dim) is
//! sequence point `shuffle(i)`, `i = (sample * n + k) mod 4096` (wrapping u32 arithmetic; n == 0
//! acts as 1; `shuffle` keeps every prefix, see below).
//!
//! Limitations: the sequence repeats after 4096 points per (pixel, dim) (use Sobol' beyond
//! 4096 samples per pixel). Only prefixes [0, 2^m) and blocks [2^m, 2^(m+1)) are guaranteed nets;
//! other aligned blocks (the set of pixel sample s >= 1 for n = 2^m, say) are stratified on the
//! coarser levels only. Digital shifts randomize less than Owen scrambling, and there are only 128
//! base sequences (64 tables x axis swap). Dimensions of one pixel are decorrelated twice: the
//! base sequence of dim d is (a per-pixel hash + d) mod 128, so dims less than 128 apart never share
//! one, and the index is shuffled per (pixel, dim) by `sobol::prefix_shuffle`, which keeps every
//! prefix [0, 2^m) (the net property of prefixes and the progressive order of whole prefixes).
//! Without the shuffle, all tables come from the same forced construction, so two dims drawing
//! the same index were correlated whatever table each used.

use std::sync::OnceLock;

use super::hash::{combine, combine_key, fmix};
use super::lanes::Lanes;
use super::layout::{Layout, SetShape, StreamKey};
use super::sobol::{prefix_shuffle_key, prefix_shuffle_with};
use crate::simd::{F8, U8};

/// Points per table: the period of every pmj02 stream (a power of two, 2^12).
pub const TABLE_POINTS: u32 = 1 << LOG_POINTS;
/// Number of independently constructed tables.
pub const TABLES: u32 = 1 << LOG_TABLES;

const LOG_POINTS: u32 = 12;
const LOG_TABLES: u32 = 6;
const TAG_PMJ: u32 = 0x50b0_1003;
const TAG_TABLE: u32 = 0x50b0_1004;

/// Progressive multi-jittered (0,2) sequence (table-based, XOR-scrambled) at `sample * n + k`.
#[derive(Clone, Copy, Debug)]
pub struct Pmj02;

/// Its entry in the registry [`super::SAMPLERS`].
pub(super) const INFO: super::SamplerInfo =
    super::SamplerInfo::new("pmj02", &["pmj"], "progressive multi-jittered (0,2)", &Pmj02).period(TABLE_POINTS as u64);

impl Layout for Pmj02 {
    #[inline]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        pmj02(pixel, sample, dim, k, set.n(), seed)
    }

    /// The stream's key (`prefix`) and, packed in `base`, the low 12 bits of its first index
    /// `sample * n` and above them its base sequence (table and axis swap, 7 bits): only the
    /// index mod 4096 matters.
    #[inline]
    fn stream<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        let (key, pick) = stream_words(pixel, dim, seed);
        let first = sample.mul(L::splat(set.n().max(1))).and(L::splat(TABLE_POINTS - 1));
        let words = Scramble::new(key).words();
        StreamKey { prefix: key, base: first.or(pick.shl(LOG_POINTS)), sample, dim, seed, words }
    }

    /// The stream's [`Scramble`] is in its `words`, computed once.
    #[inline]
    fn stream_point<L: Lanes>(&self, _: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        let index = s.base.add(L::splat(k)).and(L::splat(TABLE_POINTS - 1));
        table_point(&Scramble::of(&s.words), index, s.base.shr(LOG_POINTS))
    }

    /// The tables (tens of milliseconds, built once per process).
    fn prepare(&self) {
        tables();
    }
}

/// Point k of the n-point pmj02 set of stream (pixel, sample, dim) under seed: sequence point
/// `(sample * n + k) mod 4096` (wrapping; n == 0 acts as 1). Any inputs; both coordinates in
/// [0, 1), on the 2^-24 grid. The first call builds the tables (tens of milliseconds).
pub fn pmj02_2d(pixel: u32, sample: u32, dim: u32, k: u32, n: u32, seed: u64) -> [f32; 2] {
    let (x, y) = pmj02(pixel, sample, dim, k, n, seed);
    [x, y]
}

/// Eight lanes of [`pmj02_2d`], lane i = pmj02_2d(pixel[i], sample[i], dim, k[i], n, seed),
/// bit-identical to it (table entries are gathered per lane); coordinates in [0, 1).
pub fn pmj02_2d_x8(pixel: U8, sample: U8, dim: u32, k: U8, n: u32, seed: u64) -> (F8, F8) {
    pmj02(pixel, sample, dim, k, n, seed)
}

fn pmj02<L: Lanes>(pixel: L, sample: L, dim: u32, k: L, n: u32, seed: u64) -> (L::F, L::F) {
    let (key, pick) = stream_words(pixel, dim, seed);
    let index = sample.mul(L::splat(n.max(1))).add(k).and(L::splat(TABLE_POINTS - 1));
    table_point(&Scramble::new(key), index, pick)
}

/// The words of stream (pixel, dim, seed): its key and its base sequence `pick` (table and axis
/// swap) = (the pixel's offset + dim) mod 128, so dims less than 128 apart never share a base
/// sequence within a pixel.
#[inline]
fn stream_words<L: Lanes>(pixel: L, dim: u32, seed: u64) -> (L, L) {
    let key = combine(L::splat(combine_key(TAG_PMJ, seed, dim)), pixel);
    let offset = combine(L::splat(combine_key(TAG_TABLE, seed, 0)), pixel).shr(32 - LOG_TABLES - 1);
    (key, offset.add(L::splat(dim)).and(L::splat((TABLES << 1) - 1)))
}

/// What every point of one stream key shares: the index shuffle's multipliers
/// (`sobol::prefix_shuffle_key`) and the axes' 24-bit digital shifts.
#[derive(Clone, Copy)]
struct Scramble<L> {
    shuffle: [L; 3],
    sx: L,
    sy: L,
}

impl<L: Lanes> Scramble<L> {
    /// The scramble of stream key `key`.
    #[inline]
    fn new(key: L) -> Self {
        let (sx, sy) = (combine(key, L::splat(2)).shr(8), combine(key, L::splat(3)).shr(8));
        Self { shuffle: prefix_shuffle_key(key), sx, sy }
    }

    /// As a stream's words ([`StreamKey::words`]).
    #[inline]
    fn words(&self) -> [L; 5] {
        let [a, b, c] = self.shuffle;
        [a, b, c, self.sx, self.sy]
    }

    /// From a stream's words.
    #[inline]
    fn of(w: &[L; 5]) -> Self {
        Self { shuffle: [w[0], w[1], w[2]], sx: w[3], sy: w[4] }
    }
}

/// Sequence point `index` (< 4096) of base sequence `pick` under the stream key's scramble `sc`.
#[inline]
fn table_point<L: Lanes>(sc: &Scramble<L>, index: L, pick: L) -> (L::F, L::F) {
    // The index, shuffled per (pixel, dim) keeping every prefix [0, 2^m) (so prefixes stay nets):
    // without it two dims drawing the same index of tables built by the same forced construction
    // are correlated (a pixel's light choice then follows its light point).
    let index = prefix_shuffle_with(index, &sc.shuffle).and(L::splat(TABLE_POINTS - 1));
    // Table from the high bits, axis swap from the lowest bit (as an all-ones/all-zeros mask).
    let slot = pick.shr(1).shl(LOG_POINTS).or(index);
    let swap = pick.and(L::splat(1)).mul(L::splat(u32::MAX));
    let (x, y) = slot.gather2(tables());
    let d = x.xor(y).and(swap);
    let (x, y) = (x.xor(d), y.xor(d));
    (x.xor(sc.sx).unit24(), y.xor(sc.sy).unit24())
}

/// All tables, table t at entries t * 4096 .. (t + 1) * 4096, as 24-bit fixed-point [x, y].
fn tables() -> &'static [[u32; 2]; TABLE_LEN] {
    static TABLES_CELL: OnceLock<Box<[[u32; 2]; TABLE_LEN]>> = OnceLock::new();
    TABLES_CELL.get_or_init(|| {
        let all: Box<[[u32; 2]]> = (0..TABLES).flat_map(build_table).collect();
        all.try_into().expect("TABLES tables of TABLE_POINTS points")
    })
}

/// Points in all the tables (a power of two: `gather2` masks its indices into them; `slot` in
/// `table_point` is below it by construction).
const TABLE_LEN: usize = (TABLES * TABLE_POINTS) as usize;

/// 24 hashed bits for (table, point, what).
fn rand24(table: u32, point: u32, what: u32) -> u32 {
    [table, point, what].into_iter().fold(fmix(TAG_TABLE), combine) >> 8
}

/// Table `t`: the first 4096 points of a pmj02 sequence, 24-bit fixed point.
fn build_table(t: u32) -> Vec<[u32; 2]> {
    const B: u32 = 24;
    let bit = |v: u32, j: u32| v >> (B - j) & 1; // bit j (1 = most significant) of a coordinate
    let mut pts = vec![[0u32; 2]; TABLE_POINTS as usize];
    pts[0] = [rand24(t, 0, 0), rand24(t, 0, 1)];
    let mut occ = Vec::new();
    let (mut owner, mut seen) = (Vec::new(), Vec::new());
    for m in 0..LOG_POINTS {
        let (half, l) = (1u32 << m, m + 1);
        // occ[a][box]: the old point in each box of shape 2^-a x 2^-(m-a), box = x prefix, y prefix.
        occ.clear();
        occ.resize(((m + 1) << m) as usize, 0u32);
        let boxed = |a: u32, xp: u32, yp: u32| ((a << m) | (xp << (m - a)) | yp) as usize;
        for (i, p) in pts[..half as usize].iter().enumerate() {
            for a in 0..=m {
                occ[boxed(a, p[0] >> (B - a), p[1] >> (B - (m - a)))] = i as u32;
            }
        }
        // Progressive order: the 4^c cells of side 2^-c (c = floor(m/2)) belong to points 0..4^c.
        let c = m / 2;
        owner.clear();
        owner.resize(1 << (2 * c), 0);
        seen.clear();
        seen.resize(1 << (2 * c), false);
        for (s, p) in pts[..1 << (2 * c)].iter().enumerate() {
            owner[((p[0] >> (B - c)) << c | p[1] >> (B - c)) as usize] = s as u32;
        }
        for yp in 0..half {
            // The forced 2^-l cell (xc, yc) of the new point in row yp.
            let yc = yp << 1 | (1 ^ bit(pts[occ[boxed(0, 0, yp)] as usize][1], l));
            let mut xc = 0;
            for a in 1..=l {
                let q = occ[boxed(a - 1, xc, yp >> (a - 1))];
                xc = xc << 1 | (1 ^ bit(pts[q as usize][0], a));
            }
            let cell = ((xc >> (l - c)) << c | yc >> (l - c)) as usize;
            let s = owner[cell];
            let index = if m % 2 == 0 {
                half + s // diagonal step: the one new point in s's cell
            } else {
                // Two new points per cell: half + s and half + 4^c + s, in hashed order.
                let first = !std::mem::replace(&mut seen[cell], true);
                let high_first = rand24(t, s, 2) & 1 != 0;
                half + s + if first == high_first { 1 << (2 * c) } else { 0 }
            };
            pts[index as usize] = [xc << (B - l) | rand24(t, index, 0) >> l, yc << (B - l) | rand24(t, index, 1) >> l];
        }
    }
    pts
}

#[cfg(test)]
mod tests {
    use super::super::sobol::tests::{
        assert_net, assert_x8_matches_scalar, estimate_stats, exact_integral, fixed, random_point,
    };
    use super::*;

    fn table_point(t: u32, i: u32) -> [f32; 2] {
        tables()[(t * TABLE_POINTS + i) as usize].map(|v| v.unit24())
    }

    // Measured: 22 ms for all 64 tables (release, best of 3; up to 64 ms with the 2 cores loaded).
    #[test]
    fn build_time() {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let start = std::time::Instant::now();
            let built: Vec<_> = (0..TABLES).map(build_table).collect();
            best = best.min(start.elapsed().as_secs_f64());
            assert_eq!(built.concat(), tables());
        }
        println!("pmj02: built {TABLES} tables of {TABLE_POINTS} points in {:.1} ms (best of 3)", best * 1e3);
    }

    #[test]
    fn every_table_prefix_is_a_net() {
        for t in 0..TABLES {
            let pts: Vec<_> = (0..TABLE_POINTS).map(|i| table_point(t, i)).collect();
            for m in 0..=LOG_POINTS {
                assert_net(&pts[..1 << m], &format!("table {t}, first 2^{m}"));
                if m < LOG_POINTS {
                    assert_net(&pts[1 << m..2 << m], &format!("table {t}, block [2^{m}, 2^{})", m + 1));
                }
            }
        }
    }

    #[test]
    fn every_table_prefix_is_1d_stratified() {
        for t in 0..TABLES {
            for m in 0..=LOG_POINTS {
                let (mut sx, mut sy) = (vec![false; 1 << m], vec![false; 1 << m]);
                for i in 0..1 << m {
                    let [x, y] = table_point(t, i);
                    assert!(!std::mem::replace(&mut sx[(fixed(x) >> (24 - m)) as usize], true), "t {t} m {m} x");
                    assert!(!std::mem::replace(&mut sy[(fixed(y) >> (24 - m)) as usize], true), "t {t} m {m} y");
                }
            }
        }
    }

    #[test]
    fn progressive_order() {
        for t in [0, 1, 33, TABLES - 1] {
            for c in 0..LOG_POINTS / 2 {
                let q = 1u32 << (2 * c);
                let cell = |i: u32| table_point(t, i).map(|v| fixed(v) >> (24 - c));
                let quadrant = |i: u32| table_point(t, i).map(|v| fixed(v) >> (23 - c) & 1);
                for s in 0..q {
                    // s, q + s, 2q + s, 3q + s share a 2^-c cell, one point per quadrant, q + s opposite s.
                    let group = [s, q + s, 2 * q + s, 3 * q + s];
                    assert!(group.iter().all(|&i| cell(i) == cell(s)), "t {t} c {c} s {s}");
                    let mut quads: Vec<_> = group.iter().map(|&i| quadrant(i)).collect();
                    assert_eq!(quadrant(q + s), quadrant(s).map(|b| 1 - b));
                    quads.sort_unstable();
                    quads.dedup();
                    assert_eq!(quads.len(), 4);
                }
            }
        }
    }

    #[test]
    fn streams_are_nets_and_in_range() {
        for (pixel, dim, seed) in [(0, 0, 0), (1, 1, 7), (77, 5, 3), (123_456, 13, u64::MAX), (u32::MAX, 2, 42)] {
            for m in 0..=LOG_POINTS {
                let n = 1u32 << m;
                let pts: Vec<_> = (0..n).map(|k| pmj02_2d(pixel, 0, dim, k, n, seed)).collect();
                assert_net(&pts, &format!("pixel {pixel} dim {dim} m {m}"));
            }
        }
    }

    #[test]
    fn scalar_and_x8_agree_bit_for_bit() {
        assert_x8_matches_scalar(pmj02_2d, pmj02_2d_x8, 9);
    }

    #[test]
    fn index_conventions_and_period() {
        for k in 0..12 {
            assert_eq!(pmj02_2d(4, k, 2, 0, 0, 9), pmj02_2d(4, 0, 2, k, 1, 9));
            assert_eq!(pmj02_2d(4, 3, 2, k, 6, 9), pmj02_2d(4, 2, 2, k + 6, 6, 9));
            assert_eq!(pmj02_2d(4, 3, 2, k, 6, 9), pmj02_2d(4, 3 + TABLE_POINTS, 2, k, 6, 9));
            assert_eq!(pmj02_2d(4, 0, 2, k, 16, 9), pmj02_2d(4, 256, 2, k, 16, 9));
        }
    }

    #[test]
    fn streams_differ_and_use_all_tables() {
        let base: Vec<_> = (0..16).map(|k| pmj02_2d(1, 0, 0, k, 16, 0)).collect();
        for (pixel, dim, seed) in [(2, 0, 0), (1, 1, 0), (1, 0, 1)] {
            let other: Vec<_> = (0..16).map(|k| pmj02_2d(pixel, 0, dim, k, 16, seed)).collect();
            assert!(base.iter().zip(&other).all(|(a, b)| a != b), "{pixel} {dim} {seed}");
        }
        let mut used = [[false; 2]; TABLES as usize];
        for p in 0..2000u32 {
            let pick = combine(combine_key(TAG_TABLE, 0, 0), p) >> (32 - LOG_TABLES - 1);
            used[(pick >> 1) as usize][(pick & 1) as usize] = true;
        }
        assert!(used.iter().flatten().all(|&u| u));
    }

    // Measured (n = 16, 2000 pixels): Var(random) / Var(pmj02) = 26.7 (seed 2024), 26.1 (seed 7).
    #[test]
    fn integration_is_unbiased_with_low_variance() {
        let exact = exact_integral();
        let (n, pixels) = (16, 2000);
        for seed in [2024u32, 7] {
            let (mean, var) = estimate_stats(n, pixels, |p, k| pmj02_2d(p, 0, 3, k, n, u64::from(seed)));
            let (_, rvar) = estimate_stats(n, pixels, |p, k| random_point(p, k, seed));
            let se = (var / f64::from(pixels)).sqrt();
            println!(
                "pmj02 seed {seed}: mean {mean:.6} vs exact {exact:.6}; variance ratio random/pmj02 {:.1}",
                rvar / var
            );
            assert!((mean - exact).abs() < 4.0 * se, "mean {mean} exact {exact} se {se}");
            assert!(rvar / var >= 8.0, "ratio {}", rvar / var);
        }
    }
}

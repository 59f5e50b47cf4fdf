//! Keyed pseudo-random permutations of 0..n (shuffled strata for padded stratified sampling).

use super::divisor::Divisor;
use super::hash::fmix;
use super::lanes::Lanes;
use crate::simd::U8;

/// A keyed pseudo-random permutation of 0..n: `permute(i, n, key)` for i in 0..n visits every
/// value of 0..n once. Used to shuffle strata independently per sampling dimension (so that the
/// sample in stratum s of one dimension lands in an unrelated stratum of the next, as a padded
/// stratified sampler does). Built from xorshift-multiply rounds that are bijections on the
/// smallest power-of-two domain >= n, with cycle walking back into 0..n (expected < 2 rounds).
/// i >= n is reduced modulo n first; n == 0 acts as 1.
pub fn permute(i: u32, n: u32, key: u32) -> u32 {
    let n = n.max(1);
    if n == 1 {
        return 0;
    }
    let (mask, half) = permute_domain(n);
    let key = fmix(key ^ 0x6a09_e667);
    let r = rotation(key, n);
    let mut x = i % n;
    loop {
        x = permute_round(x, key, mask, half);
        if x < n {
            let y = x + r;
            return if y >= n { y - n } else { y };
        }
    }
}

/// The domain of [`permute_lanes`] for one m: 0..m embedded in Z_a x Z_b (x = l * b + r, l < a,
/// r < b), with a * b >= m as small as a search near sqrt(m) finds (b from floor(sqrt m) down, at
/// most 64 tries): a * b == m whenever m has a factor pair there (12 = 4 x 3, 25, 64, 100), so no
/// cycle walking; otherwise a * b - m < a (7 in 4 x 2, 13 in 7 x 2), where a power-of-two domain
/// (7 in 8, 10 in 16, 100 in 128) made eight lanes walk in lockstep for 2-5 passes.
#[derive(Clone, Copy, Debug)]
pub(super) struct PermDomain {
    /// m, >= 1
    m: u32,
    /// a: the range of l
    a: u32,
    /// b: the range of r
    b: Divisor,
    /// a * b == m: no cycle walking
    exact: bool,
    /// a and b are powers of two: split by a shift, rounds add by XOR
    pow2: bool,
    /// log2 b when `pow2`
    shift: u32,
    /// the round functions as tables of hashed bits, where they fit (see [`RoundTables`])
    tables: Option<RoundTables>,
}

impl PermDomain {
    /// m: the domain is 0..m.
    pub(super) const fn m(&self) -> u32 {
        self.m
    }

    /// The domain of 0..m (m == 0 acts as 1). A `const fn`, so that the domains of the common set
    /// sizes can be constants (`multijitter`'s specialised points).
    pub(super) const fn new(m: u32) -> Self {
        let m = if m == 0 { 1 } else { m };
        let (a, b) = if m > 1 << 31 {
            // Z_2^16 x Z_2^16: all of u32 (x = l * b + r stays exact in wrapping arithmetic).
            (1 << 16, 1 << 16)
        } else if m <= 2 {
            (m, 1)
        } else {
            let root = m.isqrt();
            let root = if root < 2 { 2 } else { root };
            let mut best = (m.div_ceil(2), 2u32);
            // b from the root down, at most 64 steps.
            let (mut b, mut steps) = (root, 0);
            while b >= 2 && steps < 64 {
                let a = m.div_ceil(b);
                // An exact pair near the root also replaces the starting (m / 2, 2), exact for
                // even m: the most balanced exact pair wins.
                if (a as u64) * (b as u64) < (best.0 as u64) * (best.1 as u64) || a * b == m {
                    best = (a, b);
                }
                if a * b == m {
                    break;
                }
                b -= 1;
                steps += 1;
            }
            best
        };
        let exact = (a as u64) * (b as u64) == m as u64;
        let pow2 = a.is_power_of_two() && b.is_power_of_two();
        let tables = RoundTables::new(a, b, pow2 && exact);
        Self { m, a, b: Divisor::new(b), exact, pow2, shift: b.trailing_zeros(), tables }
    }

    /// The hashed words its rounds take from a key, if they are tables.
    #[cfg(test)]
    pub(super) fn words(&self) -> Option<u32> {
        self.tables.map(|t| t.words)
    }

    /// (a, b): 0..m lies in Z_a x Z_b.
    #[cfg(test)]
    pub(super) fn shape(&self) -> (u32, u32) {
        (self.a, self.b.d)
    }
}

/// The rounds of a small domain (Z_a x Z_b whose round tables fit in a word each: m <= 64 on
/// powers of two, 9 = 3 x 3, 25 = 5 x 5, 36 = 6 x 6...; two words for 128 and 256) as tables:
/// round j's function of the other half h is entry h of a table of b (or a) values of
/// ceil(log2 a) (or ceil(log2 b)) bits, packed from bit `at[j].1` of hashed word `at[j].0`. The
/// words hash the key alone, not the half, so they are computed side by side before the rounds,
/// which are then a shift, a mask and an XOR (an add mod a or b) each; the `fmix` per round sat on
/// the index's chain. On powers of two the entries are uniform and the rotation's log2 m bits
/// share the words (8 points: one word where the hashed rounds took five hashes; 64: four);
/// otherwise an entry e >= a counts as e - a (the round stays a bijection; its values are no
/// longer uniform, which the decorrelation test bounds) and the rotation takes a word of its own
/// (uniform to 2^-32, as [`rotation`]).
///
/// 128 = 16 x 8 and 256 = 16 x 16 points (`wide`: a table of up to 64 bits, each half of its
/// entries fitting a word) take one hashed word per round, its entries' first half from the word
/// and the second half from the word's xorshift (a bijection of the word: each half uniform, the
/// two halves linearly related, which the decorrelation test at n = 128 and 256 bounds), and a
/// fifth hashed word for the rotation: five hashes, as the hashed rounds (four rounds and the
/// rotation), but side by side instead of chained through the index. Cornell's path sampler at 256
/// spp 71.9 -> 64.8 ns/sample (`strata profile`). Nine hashed words (two a table) measured no faster
/// than the hashed rounds; hashed once per stream of a light table, tables cost more instructions
/// than they saved (callgrind); deriving every word of a permutation from one hash by xorshift
/// steps saved no measurable time (0.4 %) and was left out.
#[derive(Clone, Copy, Debug)]
struct RoundTables {
    /// hashed words used (<= 5)
    words: u32,
    /// two-word tables (128 and 256 points): round j's table is hashed word `at[j].0` (its first
    /// half of the entries) and that word's xorshift (the second half); the rotation is word
    /// `rot.0`
    wide: bool,
    /// (word, first bit) of each round's table
    at: [(u32, u32); 4],
    /// entry width of even rounds (they change l < a) and of odd ones (r < b)
    width: [u32; 2],
    /// (word, first bit) of the rotation: its low log2 m bits where m is a power of two, else the word
    rot: (u32, u32),
}

impl RoundTables {
    /// The tables of Z_a x Z_b (`pow2_m`: both powers of two and m = a b), if every round's table
    /// fits in a word and all of them (with the rotation) in four.
    const fn new(a: u32, b: u32, pow2_m: bool) -> Option<Self> {
        let width = [bits_for(a), bits_for(b)];
        // Even rounds: b entries of width[0] bits; odd rounds: a entries of width[1] bits.
        let size = [b * width[0], a * width[1]];
        if size[0] > 32 || size[1] > 32 {
            // Two words a table where each half of its entries fits a word (powers of two).
            if !(pow2_m && size[0] <= 64 && size[1] <= 64) {
                return None;
            }
            return Some(Self { words: 5, wide: true, at: [(0, 0), (1, 0), (2, 0), (3, 0)], width, rot: (4, 0) });
        }
        // First fit: each table (and then the rotation) in the first word with room.
        let mut used = [0u32; 6];
        let mut at = [(0u32, 0u32); 4];
        let mut j = 0;
        while j < 4 {
            at[j] = place(&mut used, size[j % 2]);
            j += 1;
        }
        let rot = place(&mut used, if pow2_m { width[0] + width[1] } else { 32 });
        let (mut words, mut w) = (0, 0);
        while w < used.len() {
            words += (used[w] > 0) as u32;
            w += 1;
        }
        if words <= 4 {
            Some(Self { words, wide: false, at, width, rot })
        } else {
            None
        }
    }
}

/// Bits of an entry below n (n == 0 acts as 1).
const fn bits_for(n: u32) -> u32 {
    32 - (if n == 0 { 0 } else { n - 1 }).leading_zeros()
}

/// [`RoundTables::new`]'s first fit: `bits` bits in the first of the six words with room (the
/// last one if none has), as (word, first bit).
const fn place(used: &mut [u32; 6], bits: u32) -> (u32, u32) {
    let mut w = 0;
    while w < 5 && used[w] + bits > 32 {
        w += 1;
    }
    let at = (w as u32, used[w]);
    used[w] += bits;
    at
}

/// A keyed permutation of 0..m (`d`'s m; lane-uniform, per-lane keys) that is close to a
/// uniformly random one, unlike [`permute`]: a four-round alternating Feistel network on
/// [`PermDomain`]'s Z_a x Z_b (rounds add, mod a or mod b, a keyed `fmix` hash of the other
/// half to l, then to r, then l, then r: each round a bijection of Z_a x Z_b; XOR instead of
/// addition when a and b are powers of two), cycle-walked back
/// into 0..m where a * b > m, then [`permute`]'s keyed uniform rotation. [`permute`]'s
/// xorshift-multiply round is a small family for small n (128 distinct permutations of 8
/// elements in 200,000 keys; two rounds 768): two dimensions shuffled by it pair their indices by
/// related permutations, which correlates the dimensions (issue 33: a function coupling two padded
/// dimensions of a 16-point `multijitter` set had 1.17-1.18x the variance it has under uniformly
/// random pairings, with one round or two). The Feistel network is level with random pairings
/// (`multijitter_tests.rs`). Small domains take their round functions from [`RoundTables`]
/// (the same network, its rounds looking up tables of hashed bits). The indices must be below m
/// (callers reduce them first).
///
/// `key` must be a hash (all 32 bits uniform: callers pass `mix` outputs, offset by a constant per
/// use): round j hashes `key ^ ROUND[j] ^ half`, so the round keys cost nothing (they were one
/// `fmix` each, and one more to whiten the key: 6 of the 10 hashes of a permutation).
#[inline(always)]
pub(super) fn permute_lanes<L: Lanes>(i: L, d: &PermDomain, key: L) -> L {
    /// Per-round key offsets: they differ in the bits above any half's width, so no two rounds
    /// (of one key, or of keys differing by the callers' offsets) hash the same word.
    const ROUND: [u32; 4] = [0x3c6e_f372, 0xa54f_f53a, 0x510e_527f, 0x9b05_688c];
    let n = d.m;
    if n == 1 {
        return L::splat(0);
    }
    if let Some(t) = &d.tables {
        return permute_tables(i, d, t, key);
    }
    let keys = ROUND.map(|c| key.xor(L::splat(c)));
    let (ma, mb, a, b) = (L::splat(d.a - 1), L::splat(d.b.d - 1), L::splat(d.a), L::splat(d.b.d));
    // Round j's value: the hash's low bits (powers of two, the group Z_2^k: bits of the hash
    // instead of a high multiply), else its high multiply by a or b.
    let round = |j: usize, h: L| {
        let v = fmix(keys[j].xor(h));
        match (j.is_multiple_of(2), d.pow2) {
            (true, true) => v.and(ma),
            (false, true) => v.and(mb),
            (true, false) => v.mulhi(a),
            (false, false) => v.mulhi(b),
        }
    };
    feistel(i, d, round, rotation(key, n))
}

/// The network both kinds of round share: 0..m in `d`'s Z_a x Z_b, four alternating rounds
/// (l += `round(0, r)`, r += `round(1, l)`, ...; `round(j, h)` below a for even j, below b for
/// odd; XOR instead of addition when a and b are powers of two), cycle-walked back into 0..m
/// where a * b > m, then the rotation `(x + r) mod m` (r < m, or any r when m is a power of two:
/// its bits above drop under the mask).
#[inline(always)]
fn feistel<L: Lanes>(i: L, d: &PermDomain, round: impl Fn(usize, L) -> L, r: L) -> L {
    let (n, a, b) = (d.m, d.a, d.b.d);
    // (x + y) mod m for x, y < m.
    let add_mod = |x: L, y: L, m: u32| {
        let m = L::splat(m);
        let s = x.add(y);
        s.lt_select(m, s, s.sub(m))
    };
    let nn = L::splat(n);
    let (mut x, mut out, mut todo) = (i, L::splat(0), L::splat(u32::MAX));
    loop {
        let (mut hi, mut lo) = if d.pow2 { (x.shr(d.shift), x.and(L::splat(b - 1))) } else { d.b.div_rem(x) };
        for j in 0..4 {
            match (j % 2 == 0, d.pow2) {
                (true, true) => hi = hi.xor(round(j, lo)),
                (false, true) => lo = lo.xor(round(j, hi)),
                (true, false) => hi = add_mod(hi, round(j, lo), a),
                (false, false) => lo = add_mod(lo, round(j, hi), b),
            }
        }
        x = if d.pow2 { hi.shl(d.shift).or(lo) } else { hi.mul(L::splat(b)).add(lo) };
        if d.exact {
            // The domain is 0..n: every lane is in range after one pass.
            out = x;
            break;
        }
        // Cycle walking: the first pass in range wins; lanes already done keep their value.
        let inside = x.lt_mask(nn).and(todo);
        out = out.or(x.and(inside));
        todo = todo.and(inside.xor(L::splat(u32::MAX)));
        if todo.max_lane() == 0 {
            break;
        }
    }
    if d.pow2 && d.exact {
        return out.add(r).and(L::splat(n - 1));
    }
    // (x + r) mod n for x, r < n, without overflow (n may exceed 2^31).
    let t = nn.sub(r);
    out.lt_select(t, out.add(r), out.sub(t))
}

/// [`permute_lanes`] on a domain `d` with [`RoundTables`] `t`.
#[inline(always)]
fn permute_tables<L: Lanes>(i: L, d: &PermDomain, t: &RoundTables, key: L) -> L {
    /// Per-word key offsets (distinct from the hashed rounds' and the rotation's).
    const WORD: [u32; 5] = [0x1f83_d9ab, 0x5be0_cd19, 0x428a_2f98, 0xb5c0_fbcf, 0x7137_4491];
    let mut words = [L::splat(0); 5];
    for (w, c) in words.iter_mut().zip(WORD).take(t.words as usize) {
        *w = fmix(key.xor(L::splat(c)));
    }
    if t.wide {
        // Round j: entries [0, e/2) in word j, [e/2, e) in its xorshift (a bijection of the word).
        let xs = |w: L| {
            let w = w.xor(w.shl(13));
            let w = w.xor(w.shr(17));
            w.xor(w.shl(5))
        };
        let first: [L; 4] = std::array::from_fn(|j| words[t.at[j].0 as usize]);
        let second = first.map(xs);
        let half = [d.b.d / 2, d.a / 2];
        let round = |j: usize, h: L| {
            let (width, half) = (t.width[j % 2], half[j % 2]);
            let upper = L::splat(0).sub(h.shr(half.trailing_zeros()));
            let w = first[j].xor(first[j].xor(second[j]).and(upper));
            let at = times(h.and(L::splat(half - 1)), width);
            w.shr_var(at).and(L::splat((1 << width) - 1))
        };
        return feistel(i, d, round, words[t.rot.0 as usize]);
    }
    // Entry h of round j's table: bits at + h width.. of its word (h width by shifts and adds),
    // off powers of two reduced below a (or b): an entry e >= a counts as e - a.
    let round = |j: usize, h: L| {
        let ((w, at), width) = (t.at[j], t.width[j % 2]);
        let e = words[w as usize].shr_var(times(h, width).add(L::splat(at))).and(L::splat((1 << width) - 1));
        if d.pow2 {
            return e;
        }
        let m = L::splat(if j.is_multiple_of(2) { d.a } else { d.b.d });
        e.lt_select(m, e, e.sub(m))
    };
    let (w, at) = t.rot;
    // The rotation: its log2 m bits of the shared words when m is a power of two, else a word of
    // its own times m.
    let r = if d.pow2 && d.exact { words[w as usize].shr(at) } else { words[w as usize].mulhi(L::splat(d.m)) };
    feistel(i, d, round, r)
}

/// `h * width` for a lane-uniform table entry width: shifts and adds below 8 (off the multiplier).
#[inline(always)]
fn times<L: Lanes>(h: L, width: u32) -> L {
    match width {
        0 => L::splat(0),
        1 => h,
        2 => h.shl(1),
        3 => h.shl(1).add(h),
        4 => h.shl(2),
        5 => h.shl(2).add(h),
        6 => h.shl(2).add(h.shl(1)),
        7 => h.shl(3).sub(h),
        _ => h.mul(L::splat(width)),
    }
}

/// Keyed rotation r in 0..n applied after the rounds: `(x + r) mod n`. The rounds alone are a
/// small, correlated family for small n (two keys give related permutations), so the strata two
/// dimensions give one sample index were not jointly uniform over pixels, which biases an
/// estimator; an independent uniform rotation per key makes each dimension's stratum uniform
/// whatever the other's, which is exactly the joint uniformity unbiasedness needs.
#[inline]
fn rotation<L: Lanes>(key: L, n: u32) -> L {
    fmix(key.xor(L::splat(0xbb67_ae85))).mulhi(L::splat(n))
}

/// Eight lanes of [`permute`] with a lane-uniform n and per-lane keys, bit-identical to it per
/// lane: the rounds run on all lanes until every lane has walked back into 0..n.
pub fn permute_x8(i: U8, n: u32, key: U8) -> U8 {
    Domain::new(n).permute_x8(i, key)
}

/// The lane-uniform part of [`permute_x8`] for one n: its divisor and power-of-two domain, found
/// once (a 64-bit division and a leading-zero count) for every packet permuted over n.
#[derive(Clone, Copy, Debug)]
struct Domain {
    n: Divisor,
    mask: u32,
    half: u32,
}

impl Domain {
    /// The domain of n (n == 0 acts as 1).
    fn new(n: u32) -> Self {
        let n = n.max(1);
        let (mask, half) = if n == 1 { (0, 1) } else { permute_domain(n) };
        Self { n: Divisor::new(n), mask, half }
    }

    /// [`permute_x8`] over this domain's n.
    #[inline]
    fn permute_x8(&self, i: U8, key: U8) -> U8 {
        let n = self.n.d;
        if n == 1 {
            return U8::splat(0);
        }
        let (mask, half) = (self.mask, self.half);
        let key = fmix(key ^ U8::splat(0x6a09_e667));
        let r = rotation(key, n);
        let nn = U8::splat(n);
        // (Pixel sample indices are below n: the reduction is then the identity.)
        let mut x = if i.simd_lt(nn).all() { i } else { self.n.rem(i) };
        let mut out = U8::splat(0);
        let mut done = U8::splat(0);
        loop {
            x = permute_round(x, key, mask, half);
            // First round in range wins: lanes already done keep their value.
            let inside = x.simd_lt(nn) & !done;
            out = inside.select(x, out);
            done |= inside;
            if done.all() {
                let y = out + r;
                return y.simd_lt(nn).select(y, y - nn);
            }
        }
    }
}

/// Power-of-two domain of [`permute`] for n >= 2: (mask 2^bits - 1, xorshift amount).
fn permute_domain(n: u32) -> (u32, u32) {
    let bits = 32 - (n - 1).leading_zeros();
    let mask = if bits == 32 { u32::MAX } else { (1u32 << bits) - 1 };
    (mask, (bits / 2).max(1))
}

/// One bijective round of [`permute`] on [0, 2^bits): xor with the key, multiply by an odd
/// constant, xorshift right, multiply by an odd key-dependent constant, xorshift, xor.
#[inline]
fn permute_round<L: Lanes>(x: L, key: L, mask: u32, half: u32) -> L {
    let m = L::splat(mask);
    let x = x.xor(key.and(m));
    let x = x.mul(L::splat(0x9e37_79b9 | 1)).and(m);
    let x = x.xor(x.shr(half));
    let x = x.mul(key.or(L::splat(1)).mul(L::splat(0x85eb_ca6b)).or(L::splat(1))).and(m);
    let x = x.xor(x.shr(half));
    x.xor(key.shr(16).and(m))
}

/// The path tracer's stratum for pixel samples `s` of dimension `dim`: [`permute_x8`] of `s` over
/// `n` (the spp) keyed by (seed, dim, pixel), so strata are shuffled per (pixel, dimension) and
/// dimensions are stratified independently of one another.
#[inline]
pub fn shuffled_index_x8(s: U8, n: u32, pixel: U8, dim: u32, seed: u64) -> U8 {
    ShuffleKey::new(n, dim, seed).index_x8(s, pixel)
}

/// [`shuffled_index_x8`] for one (n, dim, seed) with its lane-uniform work (key, divisor, domain)
/// done once, for every packet that draws dimension `dim`.
#[derive(Clone, Copy, Debug)]
pub struct ShuffleKey {
    key_base: u32,
    domain: Domain,
}

impl ShuffleKey {
    /// The key of dimension `dim` of a set of n samples under `seed`.
    pub fn new(n: u32, dim: u32, seed: u64) -> Self {
        let key_base = (seed as u32) ^ ((seed >> 32) as u32).rotate_left(16) ^ dim.wrapping_mul(0x85eb_ca77);
        Self { key_base, domain: Domain::new(n) }
    }

    /// The permutation's n (>= 1): every index is below it.
    pub fn n(&self) -> u32 {
        self.domain.n.d
    }

    /// `shuffled_index_x8(s, n, pixel, dim, seed)`, bit for bit.
    #[inline]
    pub fn index_x8(&self, s: U8, pixel: U8) -> U8 {
        self.domain.permute_x8(s, U8::splat(self.key_base) ^ (pixel * U8::splat(0x9e37_79b1)))
    }
}

//! Hashing shared by the generators: murmur3's `fmix32` finalizer and two ways of folding words
//! into a state (`mix` for the grid, Halton and uniform streams, `combine` for Sobol' and pmj02).
//! Each generator keys its streams with its own domain tag (a `TAG_*` constant in its file), so
//! different generators never share a hash stream; pick an unused tag for a new one.

use super::lanes::Lanes;

/// Multipliers of the murmur3 `fmix32` finalizer (a bijection with full avalanche).
const FMIX1: u32 = 0x85eb_ca6b;
const FMIX2: u32 = 0xc2b2_ae35;
/// Odd multiplier (2^32 / golden ratio) spreading a word before it is folded into the state.
pub(super) const SPREAD: u32 = 0x9e37_79b9;

/// murmur3 finalizer: xorshift-multiply twice, then xorshift.
#[inline]
pub(super) fn fmix<L: Lanes>(h: L) -> L {
    let h = h.xor(h.shr(16)).mul(L::splat(FMIX1));
    let h = h.xor(h.shr(13)).mul(L::splat(FMIX2));
    h.xor(h.shr(16))
}

/// Folds word `w` into state `h`; a bijection in `h` for fixed `w` and in `w` for fixed `h`.
#[inline]
pub(super) fn mix<L: Lanes>(h: L, w: L) -> L {
    fmix(h.xor(w.mul(L::splat(SPREAD))))
}

/// Scalar part of every hash: (tag, seed, dim), identical for all lanes.
pub(super) fn stream_key(tag: u32, seed: u64, dim: u32) -> u32 {
    [seed as u32, (seed >> 32) as u32, dim].into_iter().fold(tag, mix)
}

/// Hash of (tag, seed, dim, words...), 32 bits per lane.
#[inline]
pub(super) fn hash<L: Lanes, const N: usize>(tag: u32, seed: u64, dim: u32, words: [L; N]) -> L {
    words.into_iter().fold(L::splat(stream_key(tag, seed, dim)), mix)
}

/// 32-bit hash to [0, 1): `(h >> 8) * 2^-24`.
#[inline]
pub(super) fn unit<L: Lanes>(h: L) -> L::F {
    h.shr(8).unit24()
}

/// Folds word `w` into hash state `h` (Sobol' and pmj02); a bijection in each argument when the
/// other is fixed.
#[inline]
pub(super) fn combine<L: Lanes>(h: L, w: L) -> L {
    fmix(h.mul(L::splat(0x2c1b_3c6d)).add(w))
}

/// Lane-uniform part of a `combine` stream key: hash of (tag, seed, dim).
pub(super) fn combine_key(tag: u32, seed: u64, dim: u32) -> u32 {
    [seed as u32, (seed >> 32) as u32, dim].into_iter().fold(fmix(tag), combine)
}

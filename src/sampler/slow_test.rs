//! Test builds only: `slow-test`, a stratified layout that spins a fixed number of iterations in
//! every call, so that sample generation dominates a render (the profiler's tests). Not in the
//! registry: reachable only as [`SamplerKind::SLOW_TEST`](super::SamplerKind) in `cfg(test)`.

use super::layout::{Layout, SetShape};
use super::stratified::Stratified;
use super::{Lanes, SamplerInfo};

/// Dependent multiply steps per call (about 3 cycles each).
pub(super) const SPINS: u32 = 20_000;

/// Stratified points, slowly.
pub(super) struct Slow;

impl Layout for Slow {
    #[inline(never)]
    fn point<L: Lanes>(&self, set: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        let mut x = std::hint::black_box(seed as u32 | 1);
        for _ in 0..SPINS {
            x = std::hint::black_box(x.wrapping_mul(0x9e37_79b9).rotate_left(7));
        }
        std::hint::black_box(x);
        Stratified { jitter: true }.point(set, pixel, sample, dim, k, seed)
    }
}

/// Its registry-style entry.
pub(super) static INFO: SamplerInfo = SamplerInfo::new("slow-test", &[], "stratified, spinning in every call", &Slow);

//! `independent`: two hashed uniforms per point, independent across every input.

use super::hash::{hash, mix, unit};
use super::lanes::Lanes;
use super::layout::{Layout, SetShape, StreamKey};

const TAG_INDEPENDENT: u32 = 0x51a7_0001;

/// Independent uniform points (a hash of all inputs); k is only another hash input.
#[derive(Clone, Copy, Debug)]
pub struct Independent;

/// Its entry in the registry [`super::SAMPLERS`].
pub(super) const INFO: super::SamplerInfo =
    super::SamplerInfo::new("independent", &["random"], "independent uniform points", &Independent).note("random");

impl Layout for Independent {
    #[inline]
    fn point<L: Lanes>(&self, _: &SetShape, pixel: L, sample: L, dim: u32, k: L, seed: u64) -> (L::F, L::F) {
        let h = hash(TAG_INDEPENDENT, seed, dim, [pixel, sample, k]);
        (unit(h), unit(mix(h, L::splat(1))))
    }

    #[inline]
    fn stream<L: Lanes>(&self, _: &SetShape, pixel: L, sample: L, dim: u32, seed: u64) -> StreamKey<L> {
        StreamKey::hashed(TAG_INDEPENDENT, pixel, sample, dim, seed)
    }

    #[inline]
    fn stream_point<L: Lanes>(&self, _: &SetShape, s: &StreamKey<L>, k: u32) -> (L::F, L::F) {
        let h = mix(s.prefix, L::splat(k));
        (unit(h), unit(mix(h, L::splat(1))))
    }
}

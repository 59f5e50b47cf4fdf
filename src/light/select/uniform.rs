//! `uniform`: one light, `floor(u N)`, pmf `1/N` (quads and triangles alike).

use super::{LightRule, RuleInfo, ONE_MINUS};
use crate::light::emitters::Emitter;
use crate::simd::{mask_to_bools, Mask8, Vec3x8, F8, U8};
use glam::Vec3;

/// Its entry in the registry [`super::RULES`].
pub(super) const INFO: RuleInfo = RuleInfo::new("uniform", "one light, equal odds: pmf 1/N", build);

fn build(emitters: &[Emitter]) -> Box<dyn LightRule> {
    Box::new(Uniform::new(emitters.len()))
}

/// One of `n` lights with equal odds.
#[derive(Clone, Copy, Debug)]
pub(super) struct Uniform {
    n: u32,
    inv_n: f32,
}

impl Uniform {
    /// The rule over `n > 0` lights.
    pub(super) fn new(n: usize) -> Self {
        Self { n: n as u32, inv_n: 1.0 / n as f32 }
    }
}

impl LightRule for Uniform {
    #[inline]
    fn sample(&self, u: f32, _: Vec3, _: Vec3) -> Option<(u32, f32)> {
        Some((((u * self.n as f32) as u32).min(self.n - 1), self.inv_n))
    }

    #[inline]
    fn sample_remap(&self, u: f32, _: Vec3, _: Vec3) -> Option<(u32, f32, f32)> {
        let x = u * self.n as f32;
        let i = (x as u32).min(self.n - 1);
        Some((i, self.inv_n, (x - i as f32).clamp(0.0, ONE_MINUS)))
    }

    #[inline]
    fn pmf(&self, _: Vec3, _: Vec3, _: u32) -> f32 {
        self.inv_n
    }

    fn needs_point(&self) -> bool {
        false
    }

    /// The scalar arithmetic, lane-wise: x = u * N rounds the same way.
    fn sample_x8(&self, u: F8, _: Vec3x8, _: Vec3x8, active: Mask8) -> (U8, F8) {
        let on = mask_to_bools(active);
        let x = (u * F8::splat(self.n as f32)).to_array();
        let idx = std::array::from_fn(|l| if on[l] { (x[l] as u32).min(self.n - 1) } else { 0 });
        (U8::new(idx), active.select(F8::splat(self.inv_n), F8::ZERO))
    }

    /// The scalar arithmetic, lane-wise (inactive lanes get a light too, with pmf 0).
    fn sample_remap_x8(&self, u: F8, _: Vec3x8, _: Vec3x8, active: Mask8) -> (U8, F8, F8) {
        let x = u * F8::splat(self.n as f32);
        let i = x.to_array().map(|x| (x as u32).min(self.n - 1));
        let fi = F8::new(i.map(|i| i as f32));
        let rest = (x - fi).max(F8::ZERO).min(F8::splat(ONE_MINUS));
        (U8::new(i), active.select(F8::splat(self.inv_n), F8::ZERO), rest)
    }

    fn pmf_x8(&self, _: Vec3x8, _: Vec3x8, _: U8, active: Mask8) -> F8 {
        active.select(F8::splat(self.inv_n), F8::ZERO)
    }
}

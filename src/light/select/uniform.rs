//! `uniform`: one light, `floor(u N)`, pmf `1/N` (quads and triangles alike).

use super::{LightRule, RuleInfo, ONE_MINUS};
use crate::light::emitters::Emitter;
use crate::simd::{Mask8, Vec3x8, F8, U8};
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

    /// The scalar `(x as u32).min(n - 1)` of each lane, as integers and as floats.
    #[inline]
    fn index_x8(&self, x: F8) -> (U8, F8) {
        if self.n > 1 << 24 {
            let i = x.to_array().map(|x| (x as u32).min(self.n - 1));
            return (U8::new(i), F8::new(i.map(|i| i as f32)));
        }
        // Clamped to [0, n - 1] first (NaN to 0, as the cast does), then truncated: n - 1 and
        // every light number are exact in f32 here.
        let t = x.max(F8::ZERO).min(F8::splat((self.n - 1) as f32)).trunc_int();
        (wide::bytemuck::cast(t), F8::from_i32x8(t))
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
        let (i, _) = self.index_x8(u * F8::splat(self.n as f32));
        (active.to_bits() & i, active.select(F8::splat(self.inv_n), F8::ZERO))
    }

    /// The scalar arithmetic, lane-wise (inactive lanes get a light too, with pmf 0).
    fn sample_remap_x8(&self, u: F8, _: Vec3x8, _: Vec3x8, active: Mask8) -> (U8, F8, F8) {
        let x = u * F8::splat(self.n as f32);
        let (i, fi) = self.index_x8(x);
        let rest = (x - fi).max(F8::ZERO).min(F8::splat(ONE_MINUS));
        (i, active.select(F8::splat(self.inv_n), F8::ZERO), rest)
    }

    fn pmf_x8(&self, _: Vec3x8, _: Vec3x8, _: U8, active: Mask8) -> F8 {
        active.select(F8::splat(self.inv_n), F8::ZERO)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{mask_all, mask_first};

    /// The x8 forms give the scalar answers bit for bit, at the ends of [0, 1) and outside it.
    #[test]
    fn x8_choice_equals_the_scalar_cast_at_the_edges() {
        // (-0.0 is left out, and NaN's remainder: the scalar clamp keeps -0.0 and NaN, the x8 max
        // gives +0.0 for both; neither reaches a light point, the samplers give [0, 1).)
        let odd = [0.0, 1e-30, 0.333_333_34, 0.666_666_7, 0.999_999_94, 1.0, 2.5, -0.5, f32::NAN, f32::INFINITY];
        for n in [1usize, 3, 7, 1000, (1 << 24) + 5] {
            let r = Uniform::new(n);
            for start in [0, 3, 6] {
                let us: [f32; 8] = std::array::from_fn(|l| odd[(l + start) % odd.len()]);
                for active in [mask_all(), mask_first(5)] {
                    let on = crate::simd::mask_to_bools(active);
                    let (z, p8) = (Vec3x8::ZERO, F8::new(us));
                    let (i8, q8, r8) = r.sample_remap_x8(p8, z, z, active);
                    let (j8, s8) = r.sample_x8(p8, z, z, active);
                    for l in 0..8 {
                        let (i, q, rest) = r.sample_remap(us[l], Vec3::ZERO, Vec3::Y).unwrap();
                        let q = if on[l] { q } else { 0.0 };
                        let rest = if rest.is_nan() { r8.to_array()[l] } else { rest };
                        let got = (i8.to_array()[l], q8.to_array()[l].to_bits(), r8.to_array()[l].to_bits());
                        assert_eq!(got, (i, q.to_bits(), rest.to_bits()), "n {n} u {} lane {l}", us[l]);
                        let (j, s) = if on[l] { r.sample(us[l], Vec3::ZERO, Vec3::Y).unwrap() } else { (0, 0.0) };
                        assert_eq!((j8.to_array()[l], s8.to_array()[l].to_bits()), (j, s.to_bits()), "n {n} lane {l}");
                    }
                }
            }
        }
    }
}

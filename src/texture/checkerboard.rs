//! The `checkerboard` texture plugin: `color0` where the fractional parts of u and v are both
//! at most 1/2 or both above, `color1` elsewhere (Mitsuba 3's pattern and defaults). Mitsuba's
//! float lookup (`eval_1`, what roughness, opacity and blend weights read) has the two colours
//! the other way round: `color1` where `eval` gives `color0` (Mitsuba 3.9.1, checked against the
//! peer); [`Checkerboard::eval_1`] does the same.

use glam::Vec3;

use super::{TexQuery, TexQuery8, UvTransform};
use crate::simd::{Vec3x8, F8};

/// A checkerboard of two constant colours over uv, one square per half unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Checkerboard {
    /// Colour where both fractional parts fall on the same side of 1/2 (Mitsuba's default 0.4).
    pub color0: Vec3,
    /// The other squares' colour (default 0.2).
    pub color1: Vec3,
    /// Mitsuba's `to_uv` (default identity).
    pub to_uv: UvTransform,
}

impl Default for Checkerboard {
    fn default() -> Self {
        Self { color0: Vec3::splat(0.4), color1: Vec3::splat(0.2), to_uv: UvTransform::IDENTITY }
    }
}

impl Checkerboard {
    /// The value at one point.
    pub fn eval(&self, q: &TexQuery) -> Vec3 {
        let uv = self.to_uv.apply(q.uv);
        let (hu, hv) = (uv.x - uv.x.floor() > 0.5, uv.y - uv.y.floor() > 0.5);
        if hu == hv {
            self.color0
        } else {
            self.color1
        }
    }

    /// The values at eight points (bit-identical to [`Checkerboard::eval`] per lane).
    pub fn eval_x8(&self, q: &TexQuery8) -> Vec3x8 {
        let (u, v) = self.to_uv.apply_x8(q.u, q.v);
        let half = F8::splat(0.5);
        let (hu, hv) = ((u - u.floor()).simd_gt(half), (v - v.floor()).simd_gt(half));
        let differ = hu ^ hv;
        Vec3x8::select(differ, Vec3x8::splat(self.color1), Vec3x8::splat(self.color0))
    }

    /// The colours swapped: what Mitsuba's float lookup `eval_1` reads (see the module docs).
    fn swapped(&self) -> Self {
        Self { color0: self.color1, color1: self.color0, to_uv: self.to_uv }
    }

    /// Mitsuba's float value at one point (`eval_1`): the scalar ([`super::scalar`]) of the
    /// colour [`Checkerboard::eval`] gives the *other* squares.
    pub fn eval_1(&self, q: &TexQuery) -> f32 {
        super::scalar(self.swapped().eval(q))
    }

    /// [`Checkerboard::eval_1`] at eight points (bit-identical per lane).
    pub fn eval_1_x8(&self, q: &TexQuery8) -> F8 {
        super::scalar_x8(self.swapped().eval_x8(q))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    fn q(u: f32, v: f32) -> TexQuery {
        TexQuery { uv: Vec2::new(u, v), tri: super::super::NO_TRIANGLE, bary: Vec2::ZERO }
    }

    #[test]
    fn pattern_matches_mitsuba() {
        // Mitsuba 3.9.1, default checkerboard: 0.4 at (0.25, 0.25), (0.75, 0.75), (0.5, 0.5),
        // (1.25, 0.25); 0.2 at (0.75, 0.25), (0.25, 0.75), (-0.25, 0.25).
        let c = Checkerboard::default();
        for (u, v) in [(0.25, 0.25), (0.75, 0.75), (0.5, 0.5), (1.25, 0.25)] {
            assert_eq!(c.eval(&q(u, v)), Vec3::splat(0.4), "({u}, {v})");
        }
        for (u, v) in [(0.75, 0.25), (0.25, 0.75), (-0.25, 0.25)] {
            assert_eq!(c.eval(&q(u, v)), Vec3::splat(0.2), "({u}, {v})");
        }
        // to_uv scales the squares: uv' = 2 uv puts (0.3, 0.1) at (0.6, 0.2), colour 1.
        let s = Checkerboard { to_uv: UvTransform::from_mat4(glam::Mat4::from_scale(Vec3::splat(2.0))), ..c };
        assert_eq!(s.eval(&q(0.3, 0.1)), Vec3::splat(0.2));
        assert_eq!(c.eval(&q(0.3, 0.1)), Vec3::splat(0.4));
    }

    #[test]
    fn float_lookup_swaps_the_colours_as_mitsuba() {
        // Mitsuba 3.9.1, checkerboard color0 = 0.05, color1 = 0.3: eval / eval_1 are 0.05 / 0.3
        // at (0.25, 0.25), (0.75, 0.75), (0.5, 0.5), (1.25, 0.25) and 0.3 / 0.05 at (0.75, 0.25),
        // (0.25, 0.75), (0.1, 0.6), (-0.25, 0.25).
        let c = Checkerboard { color0: Vec3::splat(0.05), color1: Vec3::splat(0.3), ..Checkerboard::default() };
        for (u, v) in [(0.25, 0.25), (0.75, 0.75), (0.5, 0.5), (1.25, 0.25)] {
            assert_eq!((c.eval(&q(u, v)), c.eval_1(&q(u, v))), (Vec3::splat(0.05), 0.3), "({u}, {v})");
        }
        for (u, v) in [(0.75, 0.25), (0.25, 0.75), (0.1, 0.6), (-0.25, 0.25)] {
            assert_eq!((c.eval(&q(u, v)), c.eval_1(&q(u, v))), (Vec3::splat(0.3), 0.05), "({u}, {v})");
        }
        // Colours read as their luminance.
        let rgb = Checkerboard { color0: Vec3::X, color1: Vec3::Y, ..c };
        assert_eq!(rgb.eval_1(&q(0.25, 0.25)), super::super::luminance(Vec3::Y));
    }

    #[test]
    fn x8_matches_scalar() {
        let c = Checkerboard {
            color0: Vec3::new(1.0, 2.0, 3.0),
            color1: Vec3::new(-1.0, 0.5, 0.0),
            to_uv: UvTransform::from_mat4(glam::Mat4::from_scale(Vec3::splat(3.0))),
        };
        for k in 0..64 {
            let u: [f32; 8] = std::array::from_fn(|i| (k * 8 + i) as f32 * 0.0731 - 2.0);
            let v: [f32; 8] = std::array::from_fn(|i| (k * 13 + i * 5) as f32 * 0.0519 - 1.5);
            let q8 = TexQuery8 {
                u: F8::new(u),
                v: F8::new(v),
                tri: crate::simd::U8::splat(super::super::NO_TRIANGLE),
                b1: F8::ZERO,
                b2: F8::ZERO,
            };
            let (x8, f8) = (c.eval_x8(&q8), c.eval_1_x8(&q8).to_array());
            for (i, f) in f8.iter().enumerate() {
                assert_eq!(x8.lane(i), c.eval(&q8.lane(i)));
                assert_eq!(f.to_bits(), c.eval_1(&q8.lane(i)).to_bits());
            }
        }
    }
}

//! The `rawconstant` texture plugin: one value everywhere, used as given (no colour conversion).

use glam::Vec3;

use super::{TexQuery, TexQuery8};
use crate::simd::Vec3x8;

/// A constant value (Mitsuba's `value`, a float given as three equal channels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawConstant {
    /// The value.
    pub value: Vec3,
}

impl RawConstant {
    /// The value at one point.
    pub fn eval(&self, _q: &TexQuery) -> Vec3 {
        self.value
    }

    /// The value at eight points.
    pub fn eval_x8(&self, _q: &TexQuery8) -> Vec3x8 {
        Vec3x8::splat(self.value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_value_everywhere() {
        let c = RawConstant { value: Vec3::new(0.3, 2.0, -1.0) };
        let q = TexQuery { uv: glam::Vec2::new(0.7, -3.0), tri: 4, bary: glam::Vec2::new(0.1, 0.2) };
        assert_eq!(c.eval(&q), c.value);
        let q8 = TexQuery8 {
            u: crate::simd::F8::splat(0.5),
            v: crate::simd::F8::splat(9.0),
            tri: crate::simd::U8::splat(0),
            b1: crate::simd::F8::ZERO,
            b2: crate::simd::F8::ZERO,
        };
        assert_eq!(c.eval_x8(&q8).lane(5), c.value);
    }
}

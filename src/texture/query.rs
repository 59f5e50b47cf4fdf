//! What a texture is evaluated at ([`TexQuery`], [`TexQuery8`]) and Mitsuba's `to_uv`
//! ([`UvTransform`]).

use glam::{Mat3, Mat4, Vec2};

use crate::simd::{F8, U8};

/// The triangle index of a query that is not on a triangle (spheres, misses).
pub const NO_TRIANGLE: u32 = u32::MAX;

/// One point a texture is evaluated at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TexQuery {
    /// Surface uv.
    pub uv: Vec2,
    /// Index of the triangle hit in `SceneDesc::triangles`, or [`NO_TRIANGLE`].
    pub tri: u32,
    /// Barycentric weights of the triangle's corners 1 and 2 (Embree's hit u, v).
    pub bary: Vec2,
}

/// Eight points a texture is evaluated at (the lanes of [`TexQuery`]).
#[derive(Debug, Clone, Copy)]
pub struct TexQuery8 {
    /// Surface u.
    pub u: F8,
    /// Surface v.
    pub v: F8,
    /// Triangle index per lane, or [`NO_TRIANGLE`].
    pub tri: U8,
    /// Barycentric weight of corner 1.
    pub b1: F8,
    /// Barycentric weight of corner 2.
    pub b2: F8,
}

impl TexQuery8 {
    /// Lane `i` as a scalar query.
    pub fn lane(&self, i: usize) -> TexQuery {
        TexQuery {
            uv: Vec2::new(self.u.as_array()[i], self.v.as_array()[i]),
            tri: self.tri.as_array()[i],
            bary: Vec2::new(self.b1.as_array()[i], self.b2.as_array()[i]),
        }
    }
}

/// Mitsuba's `to_uv`: the affine map `uv' = A uv + b` of a 3x3 matrix (last row 0 0 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UvTransform {
    /// Row-major `[[a00, a01, b0], [a10, a11, b1]]`.
    rows: [[f32; 3]; 2],
}

impl Default for UvTransform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl UvTransform {
    /// The identity.
    pub const IDENTITY: Self = Self { rows: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] };

    /// From a 3x3 matrix acting on `(u, v, 1)` (its last row is ignored).
    pub fn from_mat3(m: Mat3) -> Self {
        Self { rows: [[m.x_axis.x, m.y_axis.x, m.z_axis.x], [m.x_axis.y, m.y_axis.y, m.z_axis.y]] }
    }

    /// From the 4x4 transform an XML `to_uv` composes: rows and columns 0, 1 and 3, as Mitsuba
    /// makes its 3x3 (`<scale value="2"/>` then `<translate x="-.5" y="-.5"/>`: uv' = 2 uv - 0.5).
    pub fn from_mat4(m: Mat4) -> Self {
        Self { rows: [[m.x_axis.x, m.y_axis.x, m.w_axis.x], [m.x_axis.y, m.y_axis.y, m.w_axis.y]] }
    }

    /// Whether this is the identity (lookups then skip it).
    pub fn is_identity(&self) -> bool {
        *self == Self::IDENTITY
    }

    /// `uv` mapped (the same operations, in the same order, as [`UvTransform::apply_x8`]).
    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        if self.is_identity() {
            return uv;
        }
        let [a, b] = self.rows;
        Vec2::new((a[0] * uv.x + a[1] * uv.y) + a[2], (b[0] * uv.x + b[1] * uv.y) + b[2])
    }

    /// A gradient `g` taken in the mapped coordinates, carried back to the unmapped ones: `A^T g`
    /// (the chain rule through `uv' = A uv + b`).
    #[inline]
    pub fn pull_back(&self, g: Vec2) -> Vec2 {
        let [a, b] = self.rows;
        Vec2::new(a[0] * g.x + b[0] * g.y, a[1] * g.x + b[1] * g.y)
    }

    /// Eight uv points mapped (bit-identical to [`UvTransform::apply`] per lane).
    #[inline]
    pub fn apply_x8(&self, u: F8, v: F8) -> (F8, F8) {
        if self.is_identity() {
            return (u, v);
        }
        let [a, b] = self.rows.map(|r| r.map(F8::splat));
        ((a[0] * u + a[1] * v) + a[2], (b[0] * u + b[1] * v) + b[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn to_uv_takes_mitsubas_rows_and_columns() {
        // Mitsuba 3.9.1: to_uv = translate(0.1, 0.2, 0.3) * scale(2, 3, 4) prints the 3x3
        // [[2, 0, 0.1], [0, 3, 0.2], [0, 0, 1]].
        let m =
            Mat4::from_translation(glam::Vec3::new(0.1, 0.2, 0.3)) * Mat4::from_scale(glam::Vec3::new(2.0, 3.0, 4.0));
        let t = UvTransform::from_mat4(m);
        assert_eq!(t.rows, [[2.0, 0.0, 0.1], [0.0, 3.0, 0.2]]);
        assert_eq!(t.apply(Vec2::new(1.0, 1.0)), Vec2::new(2.1, 3.2));
        let r = UvTransform::from_mat3(Mat3::from_cols_array(&[0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.5, 0.25, 1.0]));
        assert_eq!(r.apply(Vec2::new(1.0, 2.0)), Vec2::new(-2.0 + 0.5, 1.0 + 0.25));
        let (u, v) = r.apply_x8(F8::splat(1.0), F8::splat(2.0));
        assert_eq!((u.as_array()[3], v.as_array()[5]), (-1.5, 1.25));
        assert!(UvTransform::default().is_identity() && !t.is_identity());
    }
}

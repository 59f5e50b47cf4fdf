//! The `mesh_attribute` texture plugin: a named per-vertex (`vertex_*`, interpolated
//! barycentrically) or per-face (`face_*`) attribute of the mesh hit, times `scale`; one-channel
//! attributes read as grey. The scene gives it the attribute's data with [`MeshAttribute::bind`].

use std::sync::Arc;

use glam::Vec3;

use super::{TexQuery, TexQuery8};
use crate::simd::{Vec3x8, F8};

/// The values of one named attribute over a run of triangles (one mesh).
#[derive(Debug, Clone, PartialEq)]
pub struct AttrRun {
    /// The first triangle (index in `SceneDesc::triangles`).
    pub first: u32,
    /// How many triangles.
    pub count: u32,
    /// Values per corner or face: 1 or 3.
    pub dims: u32,
    /// `dims` values per corner (3 per triangle, in the order of its vertices) when true, per
    /// triangle when false.
    pub per_corner: bool,
    /// `count * dims` or `count * 3 * dims` values.
    pub data: Arc<[f32]>,
}

/// A named mesh attribute as a texture.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshAttribute {
    /// Mitsuba's attribute name with its prefix (`vertex_color`, `face_weight`).
    pub name: String,
    /// Factor on the values (Mitsuba's `scale`, default 1).
    pub scale: f32,
    /// The attribute's data on the meshes that have it (from [`MeshAttribute::bind`]); a
    /// triangle of none of them reads 0.
    pub runs: Vec<AttrRun>,
}

impl MeshAttribute {
    /// An attribute texture not yet bound to data.
    pub fn new(name: impl Into<String>, scale: f32) -> Self {
        Self { name: name.into(), scale, runs: Vec::new() }
    }

    /// Gives it the data of the runs of its name (runs of other names are ignored); returns
    /// how many runs it now reads, so the scene can refuse a name no mesh has.
    pub fn bind(&mut self, runs: impl IntoIterator<Item = (String, AttrRun)>) -> usize {
        self.runs = runs.into_iter().filter(|(n, _)| *n == self.name).map(|(_, r)| r).collect();
        self.runs.sort_by_key(|r| r.first);
        self.runs.len()
    }

    /// The value at one point.
    pub fn eval(&self, q: &TexQuery) -> Vec3 {
        let Some(r) = self.runs.iter().find(|r| q.tri.wrapping_sub(r.first) < r.count) else {
            return Vec3::ZERO;
        };
        let (t, d) = ((q.tri - r.first) as usize, r.dims as usize);
        let at = |i: usize| {
            let s = &r.data[i * d..(i + 1) * d];
            if d == 3 {
                Vec3::new(s[0], s[1], s[2])
            } else {
                Vec3::splat(s[0])
            }
        };
        let v = if r.per_corner {
            let (b1, b2) = (q.bary.x, q.bary.y);
            let b0 = (1.0 - b1) - b2;
            (at(3 * t) * b0 + at(3 * t + 1) * b1) + at(3 * t + 2) * b2
        } else {
            at(t)
        };
        v * self.scale
    }

    /// The values at eight points (per lane: table lookups; bit-identical to `eval`).
    pub fn eval_x8(&self, q: &TexQuery8) -> Vec3x8 {
        let v: [Vec3; 8] = std::array::from_fn(|i| self.eval(&q.lane(i)));
        Vec3x8::new(F8::new(v.map(|c| c.x)), F8::new(v.map(|c| c.y)), F8::new(v.map(|c| c.z)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    fn attr() -> MeshAttribute {
        let mut a = MeshAttribute::new("vertex_color", 2.0);
        // Triangles 5 and 6 (per corner, RGB), and a face attribute of another name.
        let corners = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.5, 0.5], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]];
        let run = AttrRun { first: 5, count: 2, dims: 3, per_corner: true, data: corners.concat().into() };
        let face = AttrRun { first: 0, count: 7, dims: 1, per_corner: false, data: vec![0.25; 7].into() };
        assert_eq!(a.bind([("vertex_color".to_string(), run), ("face_w".to_string(), face)]), 1);
        a
    }

    #[test]
    fn corners_interpolate_barycentrically() {
        let a = attr();
        let q = |tri, b1, b2| TexQuery { uv: Vec2::ZERO, tri, bary: Vec2::new(b1, b2) };
        // Corners of triangle 5 (scale 2).
        assert_eq!(a.eval(&q(5, 0.0, 0.0)), Vec3::new(2.0, 0.0, 0.0));
        assert_eq!(a.eval(&q(5, 1.0, 0.0)), Vec3::new(0.0, 2.0, 0.0));
        assert_eq!(a.eval(&q(5, 0.0, 1.0)), Vec3::new(0.0, 0.0, 2.0));
        // Inside: 2 (0.5 c0 + 0.25 c1 + 0.25 c2).
        assert_eq!(a.eval(&q(5, 0.25, 0.25)), Vec3::new(1.0, 0.5, 0.5));
        // Triangle 6: 2 (0.2 (0.5) + 0.3 (1) + 0.5 (0)) = 0.8 per channel.
        let v = a.eval(&q(6, 0.3, 0.5));
        assert!((v - Vec3::splat(0.8)).abs().max_element() < 1e-6, "{v}");
        // Triangles without it read 0.
        assert_eq!(a.eval(&q(4, 0.3, 0.3)), Vec3::ZERO);
        assert_eq!(a.eval(&q(super::super::NO_TRIANGLE, 0.3, 0.3)), Vec3::ZERO);
    }

    #[test]
    fn faces_are_constant_and_grey() {
        let mut f = MeshAttribute::new("face_w", 1.0);
        let run = AttrRun { first: 2, count: 2, dims: 1, per_corner: false, data: vec![0.25, 0.75].into() };
        assert_eq!(f.bind([("face_w".to_string(), run)]), 1);
        let q = |tri, b1| TexQuery { uv: Vec2::ZERO, tri, bary: Vec2::new(b1, 0.1) };
        assert_eq!(f.eval(&q(3, 0.7)), Vec3::splat(0.75));
        assert_eq!(f.eval(&q(2, 0.1)), Vec3::splat(0.25));
        // x8 = scalar per lane.
        let a = attr();
        let q8 = TexQuery8 {
            u: F8::ZERO,
            v: F8::ZERO,
            tri: crate::simd::U8::new([5, 6, 4, 5, 6, 0, u32::MAX, 5]),
            b1: F8::new([0.1, 0.2, 0.3, 0.4, 0.05, 0.6, 0.7, 0.0]),
            b2: F8::new([0.3, 0.1, 0.3, 0.5, 0.9, 0.1, 0.2, 1.0]),
        };
        let x8 = a.eval_x8(&q8);
        for i in 0..8 {
            assert_eq!(x8.lane(i), a.eval(&q8.lane(i)));
        }
    }
}

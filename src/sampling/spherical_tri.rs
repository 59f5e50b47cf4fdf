//! Uniform sampling of the solid angle a triangle subtends (Arvo 1995, "Stratified Sampling of
//! Spherical Triangles").
//!
//! The triangle's corners seen from o are the unit directions A, B, C. Its solid angle comes from
//! Van Oosterom and Strackee's `tan(S / 2) = |A . (B x C)| / (1 + A.B + B.C + C.A)`, which keeps
//! its digits for a small triangle (the angle sum `alpha + beta + gamma - pi` does not in f32).
//! u picks the sub-triangle A B C' of area `u S`, C' on the arc A C (Arvo's first step). Arvo's
//! closed form gives cos b' (b' the arc A C'), whose `sqrt(1 - cos^2)` loses the digits of a short
//! arc; here b' comes from the excess of two sides and their angle, `tan(E / 2) = tan(b'/2)
//! tan(c/2) sin(alpha) / (1 + tan(b'/2) tan(c/2) cos(alpha))`, solved for the half-angle tangent:
//! `tan(b'/2) = sin(E/2) / (tan(c/2) sin(alpha - E/2))`, with `tan(c/2) = |A - B| / |A + B|`.
//! v picks the point on the arc B C' uniformly in `1 - cos` of its angle from B,
//! which is uniform in solid angle over the triangle. That second step is done with half angles:
//! `sin(th / 2) = sqrt(v) |B - C'| / 2` (the chord), so a short arc keeps its precision where
//! Arvo's `z = 1 - v (1 - C'.B)` cancels. The density is 1 / S per unit solid angle.
//!
//! Only the x8 form does arithmetic; the scalar form is lane 0 of it on splatted input, so the two
//! are bit-identical. Callers fall back to area sampling for small S (see `light::warp`).

use crate::simd::{Vec3x8, F8};
use glam::Vec3;

/// The spherical triangle of a triangle seen from a point, for 8 lanes.
#[derive(Clone, Copy, Debug)]
pub struct SphericalTri8 {
    o: Vec3x8,
    a: Vec3x8,
    b: Vec3x8,
    /// unit direction along the arc from A towards C, orthogonal to A
    w_ac: Vec3x8,
    /// the angle at A between the arcs A B and A C
    alpha: F8,
    /// tan(c / 2), c the arc A B
    tan_half_c: F8,
    /// the triangle's plane: a unit normal and `n . v0`
    n: Vec3x8,
    n_v0: F8,
    s: F8,
}

impl SphericalTri8 {
    /// The triangle `v0 v1 v2` seen from `o`, per lane.
    #[inline]
    pub fn new(o: Vec3x8, v0: Vec3x8, v1: Vec3x8, v2: Vec3x8) -> Self {
        let a = (v0 - o).normalize_or_zero();
        let b = (v1 - o).normalize_or_zero();
        let c = (v2 - o).normalize_or_zero();
        let (ab, bc, ca) = (a.dot(b), b.dot(c), c.dot(a));
        let det = a.dot(b.cross(c)).abs();
        let s = F8::splat(2.0) * det.atan2(F8::ONE + ab + bc + ca);
        // The angle at A between the arcs A B and A C.
        let n_ab = a.cross(b).normalize_or_zero();
        let n_ac = a.cross(c).normalize_or_zero();
        let alpha = n_ab.cross(n_ac).length().atan2(n_ab.dot(n_ac));
        let tan_half_c = (a - b).length() / (a + b).length();
        let w_ac = (c - a.scale(ca)).normalize_or_zero();
        let n = (v1 - v0).cross(v2 - v0).normalize_or_zero();
        Self { o, a, b, w_ac, alpha, tan_half_c, n, n_v0: n.dot(v0), s }
    }

    /// The solid angle S (0 where it is not positive and finite: `o` in the triangle's plane or
    /// a degenerate triangle).
    #[inline]
    pub fn solid_angle(&self) -> F8 {
        let ok = self.s.simd_gt(F8::ZERO) & self.s.is_finite() & self.alpha.simd_gt(F8::ZERO);
        ok.select(self.s, F8::ZERO)
    }

    /// The unit direction from `o` for the unit-square sample `(u, v)`, uniform in solid angle over
    /// the spherical triangle (density 1 / S).
    #[inline]
    pub fn sample_dir(&self, u: F8, v: F8) -> Vec3x8 {
        // The sub-triangle A B C' of area E = u S: tan(b'/2) = sin(E/2) / (tan(c/2) sin(alpha - E/2)).
        let half_e = u * self.s * F8::splat(0.5);
        let (sn_e, _) = half_e.sin_cos();
        let (sn_d, _) = (self.alpha - half_e).sin_cos();
        let x = sn_e / (self.tan_half_c * sn_d);
        let x = (self.tan_half_c * sn_d).simd_gt(F8::ZERO).select(x, F8::ZERO);
        let x2 = x * x;
        let inv = F8::ONE / (F8::ONE + x2);
        let (cos_b, sin_b) = ((F8::ONE - x2) * inv, (x + x) * inv);
        let c2 = self.w_ac.mul_add(sin_b, self.a.scale(cos_b));
        // Along the arc from B to C': sin(th / 2) = sqrt(v) |B - C'| / 2.
        let half = v.sqrt() * (self.b - c2).length() * F8::splat(0.5);
        let half = half.min(F8::ONE);
        let cos_t = F8::ONE - F8::splat(2.0) * half * half;
        let sin_t = F8::splat(2.0) * half * (F8::ONE - half * half).max(F8::ZERO).sqrt();
        let w = (c2 - self.b.scale(c2.dot(self.b))).normalize_or_zero();
        w.mul_add(sin_t, self.b.scale(cos_t))
    }

    /// The point of the triangle for `(u, v)`: where the direction [`SphericalTri8::sample_dir`]
    /// from `o` meets the triangle's plane.
    #[inline]
    pub fn sample(&self, u: F8, v: F8) -> Vec3x8 {
        let w = self.sample_dir(u, v);
        let t = (self.n_v0 - self.n.dot(self.o)) / self.n.dot(w);
        w.mul_add(t, self.o)
    }
}

/// Scalar [`SphericalTri8`]: the point for `(u, v)` and the solid angle S of the triangle
/// `v0 v1 v2` seen from `o`; lane 0 of the x8 form.
pub fn sample_spherical_tri(o: Vec3, v: [Vec3; 3], u: f32, w: f32) -> (Vec3, f32) {
    let s = Vec3x8::splat;
    let t = SphericalTri8::new(s(o), s(v[0]), s(v[1]), s(v[2]));
    (t.sample(F8::splat(u), F8::splat(w)).lane(0), t.solid_angle().as_array()[0])
}

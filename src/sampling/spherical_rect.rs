//! Uniform sampling of the solid angle a rectangle subtends (Ureña, Fajardo and King 2013, "An
//! Area-Preserving Parametrization for Spherical Rectangles").
//!
//! The rectangle is `corner + s ex + t ey`, s in [0, lx], t in [0, ly], with `ex`, `ey` orthonormal.
//! In the frame (ex, ey, ez) at the reference point o, with ez turned away from the rectangle, its
//! corners are (x0 | x1, y0 | y1, z0) with z0 < 0. The four great circles through o and its edges
//! have unit normals n0..n3; the spherical rectangle's inner angles are g_i = pi/2 + asin(n_i .
//! n_i+1), so its area is S = sum_i asin(n_i . n_i+1), written without the 2 pi that cancels in
//! the paper's `g0 + g1 + g2 + g3 - 2 pi` (in f32 that cancellation loses every digit of a small
//! S). Each asin is an atan2 of a dot and a cross product (no clamp, no loss near +-1), and a
//! pair's sum one atan2 of a product of complex numbers: two polynomial atan2 per shading point
//! (`simd::math::atan2`, one division each) rather than four asin and four divisions; the
//! coordinates are scaled by a power of two. u picks the x of the point by inverting the area to
//! the left of x (the paper's `au = u S + k`; its three steps `fu`, `cu`, `xu` multiplied out into
//! one square root and one division), v its y uniformly in the height `h = y / sqrt(x^2 + y^2 +
//! z0^2)` along the column, which is uniform in solid angle. The density is 1 / S per unit solid
//! angle. The warp's cost is its divisions and square roots, which share one unit of the core
//! (measured: `cargo bench --bench lights -- warps` reads the same per packet whether packets
//! wait on each other or not), so the forms here are the ones with the fewest.
//!
//! Only the x8 form does arithmetic; the scalar form is lane 0 of it on splatted input, so the two
//! are bit-identical. Precision: for a small S the argument `au`, near pi/2 .. pi, keeps
//! `ulp(au) / S` of u's resolution; see `light::warp` for the solid angle under which the caller
//! falls back to area sampling.

use crate::simd::math::{atan2, pow2_recip};
use crate::simd::{Vec3x8, F8};
use glam::Vec3;

/// The spherical rectangle of a rectangle seen from a point, for 8 lanes: everything its
/// sampling needs, computed once per shading point.
#[derive(Clone, Copy, Debug)]
pub struct SphericalRect8 {
    o: Vec3x8,
    ex: Vec3x8,
    ey: Vec3x8,
    ez: Vec3x8,
    x0: F8,
    y0: F8,
    z0: F8,
    x1: F8,
    y1: F8,
    b0: F8,
    b1: F8,
    /// `sqrt(1 - b0^2) = -z0 / l0`
    w: F8,
    k: F8,
    s: F8,
}

impl SphericalRect8 {
    /// The rectangle `corner + s ex + t ey` (`ex`, `ey` orthonormal, s in [0, lx], t in [0, ly])
    /// seen from `o`, per lane.
    #[inline]
    pub fn new(o: Vec3x8, corner: Vec3x8, ex: Vec3x8, ey: Vec3x8, lx: F8, ly: F8) -> Self {
        let d = corner - o;
        let ez0 = ex.cross(ey);
        let z0 = d.dot(ez0);
        // Turn ez away from the rectangle, so z0 <= 0.
        let flip = z0.simd_gt(F8::ZERO);
        let sgn = flip.select(-F8::ONE, F8::ONE);
        let ez = ez0.scale(sgn);
        let z0 = z0 * sgn;
        let (x0, y0) = (d.dot(ex), d.dot(ey));
        let (x1, y1) = (x0 + lx, y0 + ly);
        let z2 = z0 * z0;
        // a_i = asin(n_i . n_i+1) = atan2(n_i . n_i+1, |n_i x n_i+1|) with the unnormalized
        // edge-plane normals (0, z0, -y0), (-z0, 0, x1), (0, -z0, y1), (z0, 0, -x0): the dot
        // products are -y0 x1, x1 y1, -y1 x0, x0 y0 and the cross products' lengths |z0| times
        // the distance to the corner between the two edges (the normals' lengths cancel). A
        // pair's sum is the argument of the product of their (cos, sin) pairs: two atan2 in all.
        // Coordinates are scaled to about 1 first (S is scale-free) to keep the fourth powers
        // in f32's range: by a power of two, which rounds nothing and needs no division.
        let inv = pow2_recip(x0.abs() + x1.abs() + y0.abs() + y1.abs() - z0);
        let (sx0, sx1, sy0, sy1, sz0) = (x0 * inv, x1 * inv, y0 * inv, y1 * inv, z0 * inv);
        let (sz2, az) = (sz0 * sz0, -sz0);
        let r = |x: F8, y: F8| az * x.mul_add(x, y.mul_add(y, sz2)).sqrt();
        let (p0, q0) = (-(sy0 * sx1), r(sx1, sy0));
        let (p1, q1) = (sx1 * sy1, r(sx1, sy1));
        let (p2, q2) = (-(sy1 * sx0), r(sx0, sy1));
        let (p3, q3) = (sx0 * sy0, r(sx0, sy0));
        let arg = |(p, q): (F8, F8), (p2, q2): (F8, F8)| atan2(q.mul_add(p2, p * q2), q.mul_add(q2, -(p * p2)));
        let a01 = arg((p0, q0), (p1, q1));
        let a23 = arg((p2, q2), (p3, q3));
        let s = a01 + a23;
        // k = 2 pi - g2 - g3.
        let k = F8::PI - a23;
        let (l0, l2) = (y0.mul_add(y0, z2).sqrt(), y1.mul_add(y1, z2).sqrt());
        // b0 and w = sqrt(1 - b0^2) (the sine of the angle whose cosine is b0) share 1 / l0: the
        // warp's time is its divisions and square roots, which share one unit.
        let inv_l0 = F8::ONE / l0;
        let (b0, b1, w) = (-y0 * inv_l0, y1 / l2, -z0 * inv_l0);
        Self { o, ex, ey, ez, x0, y0, z0, x1, y1, b0, b1, w, k, s }
    }

    /// The solid angle S (0 or NaN-free; 0 where `o` lies in the rectangle's plane).
    #[inline]
    pub fn solid_angle(&self) -> F8 {
        let ok = self.s.simd_gt(F8::ZERO) & self.s.is_finite();
        ok.select(self.s, F8::ZERO)
    }

    /// The point of the rectangle for the unit-square sample `(u, v)`: uniform in solid angle
    /// about `o` (density 1 / S). Lanes whose S is 0 give a point of no use (the caller falls
    /// back to area sampling there).
    #[inline]
    pub fn sample(&self, u: F8, v: F8) -> Vec3x8 {
        let Self { x0, y0, z0, x1, y1, b0, b1, w, k, s, .. } = *self;
        let au = u.mul_add(s, k);
        let (sin_au, cos_au) = au.sin_cos();
        // The paper's fu = n / sin(au), cu = sign(fu) / sqrt(fu^2 + b0^2) and xu = -cu z0 /
        // sqrt(1 - cu^2), multiplied out: xu = -sign(n) sin(au) z0 / sqrt(n^2 - w^2 sin(au)^2),
        // with n^2 - w^2 sin^2 as (n - w sin)(n + w sin) (no cancellation of the squares). One
        // square root and one division where the three steps chained three of each.
        let n = cos_au.mul_add(b0, -b1);
        let tiny = F8::splat(f32::MIN_POSITIVE);
        let q = w.mul_neg_add(sin_au, n) * w.mul_add(sin_au, n);
        let num = -(sin_au * z0).flip_signs(n);
        let xu = num / q.max(tiny).sqrt();
        let xu = xu.max(x0).min(x1);
        let dd = xu.mul_add(xu, z0 * z0);
        let h0 = y0 / y0.mul_add(y0, dd).sqrt();
        let h1 = y1 / y1.mul_add(y1, dd).sqrt();
        let hv = v.mul_add(h1 - h0, h0);
        let hv2 = hv * hv;
        let inside = hv2.simd_lt(F8::splat(1.0 - 1e-6));
        // y = h sqrt(dd / (1 - h^2)): one square root where two divided.
        let yv = inside.select(hv * (dd / (F8::ONE - hv2).max(tiny)).sqrt(), y1);
        let yv = yv.max(y0).min(y1);
        self.ez.mul_add(z0, self.ey.mul_add(yv, self.ex.mul_add(xu, self.o)))
    }
}

/// Scalar [`SphericalRect8`]: the point for `(u, v)` and the solid angle S of the rectangle
/// `corner + s ex + t ey` (s in [0, lx], t in [0, ly]) seen from `o`; lane 0 of the x8 form.
#[allow(clippy::too_many_arguments)]
pub fn sample_spherical_rect(
    o: Vec3,
    corner: Vec3,
    ex: Vec3,
    ey: Vec3,
    lx: f32,
    ly: f32,
    u: f32,
    v: f32,
) -> (Vec3, f32) {
    let s = Vec3x8::splat;
    let r = SphericalRect8::new(s(o), s(corner), s(ex), s(ey), F8::splat(lx), F8::splat(ly));
    (r.sample(F8::splat(u), F8::splat(v)).lane(0), r.solid_angle().as_array()[0])
}

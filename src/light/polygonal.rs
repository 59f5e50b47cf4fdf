//! Exact irradiance from a polygonal Lambertian emitter without visibility (Lambert's formula as used by
//! Arvo 1995, "Applications of Irradiance Tensors"): the irradiance vector
//! `Phi(x) = 1/2 sum_k theta_k gamma_k`, with `theta_k` the angle the edge `(v_k, v_k+1)` subtends at
//! `x` and `gamma_k = normalize((v_k - x) x (v_k+1 - x))`. For a receiver with unit normal `n` that sees
//! the whole polygon in its upper hemisphere, the irradiance per unit emitted radiance is `Phi . n`
//! (the cosine-weighted solid angle, at most pi), so `analyticdirect` shades
//! `L_out = kd/pi * L_light * (Phi . n)`.
//!
//! Orientation: for a `quadLight a ab ac L` pass the vertices `[a, a+ab, a+ab+ac, a+ac]`. Their
//! right-hand normal is `ab x ac`, and the light emits towards `ac x ab`, the opposite side. For `x` on
//! the emitting side, `Phi` points from `x` towards the light and `Phi . n > 0` for a receiver facing
//! it, with no sign flip. For `x` behind the light (`(x - a) . (ab x ac) > 0`) `Phi` points away from the
//! light, so `Phi . n` is negative for a receiver facing the light. The caller must treat such points
//! as unlit (and clamp `Phi . n` at 0 for receivers that see the polygon only partly, where the
//! formula is not exact anyway).
//!
//! Each edge term is computed as `c * atan2(|c|, a.b) / |c|` with `c = a x b` and `a, b` the vertices
//! relative to `x`, `c` evaluated as `a x (v_k+1 - v_k)` so that it keeps its precision when `a` and
//! `b` are nearly parallel (a small light far away, whose edge terms cancel to its solid angle). That gives the same angle as `acos(a.b / (|a||b|))` but is accurate at small and
//! near-pi angles. Edges with `|c| = 0` (zero length, `x` at a vertex or on the line through the
//! edge) or a non-finite `|c|` contribute 0, so degenerate positions such as `x` on the polygon's plane or on an edge give
//! finite results, never NaN.

use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

/// Smallest `|a x b|` treated as a proper edge. Below this the edge term is 0; above it
/// `atan2(..) / |c| <= pi / MIN_POSITIVE` is still finite. Edges whose `|c|` overflows (points
/// farther than ~1e19) or is NaN are skipped as well.
const MIN_CROSS: f32 = f32::MIN_POSITIVE;

/// Irradiance vector form factor `Phi(x) = 1/2 sum_k theta_k gamma_k` of the polygon `verts` seen from
/// `x` (world space). Irradiance per unit radiance for a receiver with normal `n` is `Phi . n`. This is
/// positive when the receiver faces the emitting side of a `quadLight` given as
/// `[a, a+ab, a+ab+ac, a+ac]` (see the module docs for the sign convention and degenerate cases).
pub fn polygon_phi(x: Vec3, verts: &[Vec3; 4]) -> Vec3 {
    let r = verts.map(|v| v - x);
    (0..4).fold(Vec3::ZERO, |phi, k| {
        let (a, b) = (r[k], r[(k + 1) % 4]);
        // a x b = a x (b - a), with the edge b - a taken from the vertices (exact for a tiny light
        // far away, where a and b are nearly parallel and a x b would cancel).
        let c = a.cross(verts[(k + 1) % 4] - verts[k]);
        let s = c.length();
        if s > MIN_CROSS && s.is_finite() {
            phi + c * (0.5 * s.atan2(a.dot(b)) / s)
        } else {
            phi
        }
    })
}

/// Eight-lane twin of [`polygon_phi`]: shading points `x` in lanes, the same polygon for all lanes.
/// Inactive lanes return 0.
pub fn polygon_phi_x8(x: Vec3x8, verts: &[Vec3; 4], active: Mask8) -> Vec3x8 {
    let r = verts.map(|v| Vec3x8::splat(v) - x);
    let phi = (0..4).fold(Vec3x8::ZERO, |phi, k| {
        let (a, b) = (r[k], r[(k + 1) % 4]);
        let c = a.cross(Vec3x8::splat(verts[(k + 1) % 4] - verts[k]));
        let s = c.length();
        let ok = s.simd_gt(F8::splat(MIN_CROSS)) & s.simd_lt(F8::splat(f32::INFINITY));
        Vec3x8::select(ok, c.mul_add(F8::splat(0.5) * s.atan2(a.dot(b)) / s, phi), phi)
    });
    Vec3x8::select(active, phi, Vec3x8::ZERO)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{mask_all, mask_from_bools};
    use std::f64::consts::PI;

    /// The vertices of `quadLight a ab ac` in the format's order.
    fn quad(a: Vec3, ab: Vec3, ac: Vec3) -> [Vec3; 4] {
        [a, a + ab, a + ab + ac, a + ac]
    }

    /// Irradiance per unit radiance at `x` with normal `n` from the emitting side of the quad, by
    /// `m x m` midpoint quadrature in f64 of `cos(th_x) cos(th_l) / d^2 dA`. Asserts that every point
    /// of the light is above the receiver's plane. With `back`, the light's normal is negated (for
    /// points behind it).
    fn quadrature(x: Vec3, n: Vec3, a: Vec3, ab: Vec3, ac: Vec3, back: bool, m: usize) -> f64 {
        let v = |p: Vec3| p.as_dvec3();
        let (x, n, a, ab, ac) = (v(x), v(n.normalize()), v(a), v(ab), v(ac));
        let area = ab.cross(ac).length();
        let nl = ac.cross(ab).normalize() * if back { -1.0 } else { 1.0 };
        let mut sum = 0.0;
        for i in 0..m {
            for j in 0..m {
                let p = a + ab * ((i as f64 + 0.5) / m as f64) + ac * ((j as f64 + 0.5) / m as f64);
                let w = p - x;
                let d2 = w.length_squared();
                let d = d2.sqrt();
                let (cx, cl) = (n.dot(w) / d, -nl.dot(w) / d);
                assert!(cx > 0.0 && cl > 0.0, "test case must see the light fully from the front");
                sum += cx * cl / d2;
            }
        }
        sum * area / (m * m) as f64
    }

    /// Receivers (point, normal) below a horizontal parallelogram light at y = 2 that emits downwards
    /// (ac x ab = -y), plus a tilted light. All see their light entirely in the upper hemisphere.
    fn cases() -> Vec<(Vec3, Vec3, Vec3, Vec3, Vec3)> {
        let (a, ab, ac) = (Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.2, 0.0, 0.3));
        let (ta, tab, tac) = (Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 0.8), Vec3::new(0.6, -0.6, 0.0));
        vec![
            (Vec3::ZERO, Vec3::Y, a, ab, ac),
            (Vec3::new(0.3, 1.2, -0.2), Vec3::Y, a, ab, ac),
            (Vec3::new(2.0, 0.0, 1.0), Vec3::Y, a, ab, ac),
            (Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.3, 1.0, -0.2), a, ab, ac),
            (Vec3::new(-3.0, 0.0, 0.5), Vec3::new(0.7, 0.7, 0.0), a, ab, ac),
            (Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.1, 1.0, -0.6), a, ab, ac),
            (Vec3::new(0.2, 1.9, 0.1), Vec3::Y, a, ab, ac),
            (Vec3::new(0.0, 0.0, 0.4), Vec3::new(1.0, 1.0, 0.0), ta, tab, tac),
            (Vec3::new(-0.5, 0.0, 0.4), Vec3::new(1.0, 0.2, 0.1), ta, tab, tac),
        ]
    }

    #[test]
    fn matches_midpoint_quadrature() {
        for (i, (x, n, a, ab, ac)) in cases().into_iter().enumerate() {
            let e = quadrature(x, n, a, ab, ac, false, 2000);
            let phi = f64::from(polygon_phi(x, &quad(a, ab, ac)).dot(n.normalize()));
            assert!(phi > 0.0, "case {i}: facing the emitting side must be positive");
            assert!(((phi - e) / e).abs() < 1e-4, "case {i}: phi.n = {phi}, quadrature {e}");
        }
    }

    #[test]
    fn behind_the_light_the_sign_flips() {
        // Above the downward-emitting light: the same magnitude with the opposite sign.
        let (a, ab, ac) = (Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.2, 0.0, 0.3));
        let (x, n) = (Vec3::new(0.4, 3.1, 0.2), Vec3::new(0.2, -1.0, 0.1));
        let e = quadrature(x, n, a, ab, ac, true, 1000);
        let phi = f64::from(polygon_phi(x, &quad(a, ab, ac)).dot(n.normalize()));
        assert!(((phi + e) / e).abs() < 1e-4, "phi.n = {phi}, quadrature {e}");
    }

    #[test]
    fn centred_square_closed_form() {
        // Square of half side s at height h, receiver on the axis facing it:
        // E/L = 4 t atan(t), t = X / sqrt(1 + X^2), X = s / h (four corner rectangles).
        for (s, h) in [(0.5f32, 2.0f32), (1.0, 0.1), (3.0, 1.0), (0.01, 1.0)] {
            let v = quad(Vec3::new(-s, h, -s), Vec3::new(0.0, 0.0, 2.0 * s), Vec3::new(2.0 * s, 0.0, 0.0));
            let phi = polygon_phi(Vec3::ZERO, &v);
            let xx = f64::from(s / h);
            let t = xx / (1.0 + xx * xx).sqrt();
            let exact = 4.0 * t * t.atan();
            assert!(((f64::from(phi.y) - exact) / exact).abs() < 2e-5, "s={s} h={h}: {} vs {exact}", phi.y);
            assert!(phi.x.abs() < 1e-6 * phi.y && phi.z.abs() < 1e-6 * phi.y, "on-axis Phi is along the axis");
        }
    }

    #[test]
    fn x8_matches_scalar_per_lane() {
        for (_, _, a, ab, ac) in cases().into_iter().step_by(7) {
            let v = quad(a, ab, ac);
            let xs: [Vec3; 8] = std::array::from_fn(|i| {
                let t = i as f32;
                Vec3::new(0.37 * t - 1.2, 1.9 - 0.45 * t, 0.21 * t * t - 0.8)
            });
            let got = polygon_phi_x8(Vec3x8::from_lanes(xs), &v, mask_all());
            for (i, x) in xs.iter().enumerate() {
                let want = polygon_phi(*x, &v);
                let err = (got.lane(i) - want).length();
                assert!(err <= 1e-5 * want.length().max(1e-3), "lane {i}: {:?} vs {want:?}", got.lane(i));
            }
        }
    }

    #[test]
    fn degenerate_positions_are_finite() {
        let (a, ab, ac) = (Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0));
        let v = quad(a, ab, ac);
        let xs = [
            a + 0.5 * ab + 0.5 * ac,                   // centre, on the plane
            a + 0.5 * ab,                              // middle of an edge
            a,                                         // a vertex
            a + 2.0 * ac,                              // on the plane outside, on the line through an edge
            a - ab - ac,                               // on the plane outside, on a diagonal
            a + 0.3 * ab + Vec3::new(0.0, -1e-6, 0.0), // just in front of an edge
            Vec3::splat(1e30),                         // very far
            Vec3::new(0.0, 2.0 + 1e-7, 0.0),           // just behind the centre
        ];
        let got = polygon_phi_x8(Vec3x8::from_lanes(xs), &v, mask_all());
        for (i, x) in xs.iter().enumerate() {
            let p = polygon_phi(*x, &v);
            assert!(p.is_finite() && got.lane(i).is_finite(), "lane {i}: {p:?} / {:?}", got.lane(i));
            assert!(p.length() <= std::f32::consts::PI * 1.0001, "lane {i}: |Phi| <= pi");
        }
        // On the light itself every edge subtends its full angle: Phi = pi * normalize(ab x ac).
        let centre = polygon_phi(xs[0], &v);
        assert!((centre - std::f32::consts::PI * ab.cross(ac).normalize()).length() < 1e-5, "{centre:?}");
        // Zero-length edges (a triangle with a repeated vertex, or a point) are fine too.
        let tri = [a, a + ab, a + ab + ac, a + ab + ac];
        assert!(polygon_phi(Vec3::ZERO, &tri).is_finite());
        assert_eq!(polygon_phi(Vec3::ZERO, &[a; 4]), Vec3::ZERO);
    }

    #[test]
    fn inactive_lanes_are_zero_even_with_nan_input() {
        let v = quad(Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0));
        let mut xs = [Vec3::ZERO; 8];
        xs[1] = Vec3::NAN;
        xs[5] = Vec3::splat(f32::INFINITY);
        let active = mask_from_bools([true, false, true, true, true, false, true, true]);
        let got = polygon_phi_x8(Vec3x8::from_lanes(xs), &v, active);
        assert_eq!((got.lane(1), got.lane(5)), (Vec3::ZERO, Vec3::ZERO));
        assert!((got.lane(0) - polygon_phi(Vec3::ZERO, &v)).length() < 1e-6);
    }

    /// A light of side 1e-3 (area 1e-6, the stability suite's tiny light) seen from 1 to 3 units
    /// away, on and off its axis: Phi . n matches the f64 quadrature to 2e-4 (x8: 5e-4). The
    /// four edge terms are ~5e-4 each and cancel to ~1e-6, so each must be accurate to ~1e-7
    /// relative: a x b of two nearly parallel f32 vectors is not (it loses ~1e-4 relative), a x
    /// (b - a) with the exact edge b - a is. What remains is the rounding of the four angles,
    /// magnified by the cancellation ~ (distance / size)^2: about 1e-3 relative at 2 units from
    /// this light (2.5e-8 sr), so the points stay within 1.6 units.
    #[test]
    fn tiny_light_is_accurate() {
        let (a, ab, ac) = (Vec3::new(-0.0005, 1.0, -0.0005), Vec3::new(0.0, 0.0, 0.001), Vec3::new(0.001, 0.0, 0.0));
        let v = quad(a, ab, ac);
        let xs: [Vec3; 8] = [
            Vec3::ZERO,
            Vec3::new(0.3, 0.0, 0.1),
            Vec3::new(-1.0, 0.0, 0.7),
            Vec3::new(1.2, -0.3, -0.9),
            Vec3::new(0.01, 0.5, 0.0),
            Vec3::new(0.6, 0.2, 1.0),
            Vec3::new(-0.2, -2.0, 0.05),
            Vec3::new(1.1, 0.0, 0.0),
        ];
        let got = polygon_phi_x8(Vec3x8::from_lanes(xs), &v, mask_all());
        for (i, &x) in xs.iter().enumerate() {
            let e = quadrature(x, Vec3::Y, a, ab, ac, false, 40);
            // x8: wide's polynomial atan2 is a few ulp off std's, and the cancellation magnifies it.
            for (what, phi, rtol) in [("scalar", polygon_phi(x, &v), 2e-4), ("x8", got.lane(i), 5e-4)] {
                let p = f64::from(phi.y);
                assert!(((p - e) / e).abs() < rtol, "{what} x={x}: phi.n = {p}, quadrature {e}");
            }
        }
    }

    #[test]
    fn full_hemisphere_limit_is_pi() {
        // A huge light just above the receiver covers almost the whole hemisphere: Phi . n -> pi.
        let big = 1e4f32;
        let v = quad(Vec3::new(-big, 1.0, -big), Vec3::new(0.0, 0.0, 2.0 * big), Vec3::new(2.0 * big, 0.0, 0.0));
        let phi = polygon_phi(Vec3::ZERO, &v);
        assert!((f64::from(phi.y) - PI).abs() < 1e-3, "{phi:?}");
    }
}

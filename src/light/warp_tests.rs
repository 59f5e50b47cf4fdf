//! Tests of the solid-angle warps (`sampling::spherical_rect`, `sampling::spherical_tri`) and of
//! their use on the lights (`light::warp`).
//!
//! Chi-square: points are binned on the light itself (a grid of sub-rectangles, or of congruent
//! sub-triangles), and a cell's expected count is N times its solid angle (in f64, Van Oosterom
//! and Strackee's formula on the cell's triangles, independent of the warps) divided by the solid
//! angle S the warp claims (its pdf is 1 / S). The pdf's integral over the light is computed by
//! quadrature of `cos_l / (d^2 S)` over its area, which uses neither formula.

use super::*;
use crate::sampling::chi2::{gamma_q, statistic, Rng, CHI2_TESTS, SIGNIFICANCE};
use crate::sampling::spherical_rect::sample_spherical_rect;
use crate::sampling::spherical_tri::sample_spherical_tri;
use glam::{DVec3, Vec3};

/// Solid angle of the triangle `a b c` seen from `o`, in f64.
fn tri_solid_angle(o: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (a, b, c) = ((a - o).normalize(), (b - o).normalize(), (c - o).normalize());
    2.0 * a.dot(b.cross(c)).abs().atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a))
}

/// The integral over the light `a + s ab + t ac` (unit square, or the triangle when `tri`) of
/// `pdf * cos_l / d^2` seen from `o`, by the midpoint rule on an n x n grid (f64).
fn pdf_integral(o: Vec3, e: &Emitter, pdf: f64) -> f64 {
    let (a, ab, ac, n) = (e.a.as_dvec3(), e.ab.as_dvec3(), e.ac.as_dvec3(), e.normal.as_dvec3());
    let o = o.as_dvec3();
    // Centroid rule on the cells of an 800 x 800 subdivision (squares or congruent triangles).
    let cells = Cells { n: 800, tri: e.triangle };
    let mut sum = 0.0;
    for c in 0..cells.count() {
        for [p, q, r] in cells.triangles(c) {
            let (s, t) = ((p.0 + q.0 + r.0) / 3.0, (p.1 + q.1 + r.1) / 3.0);
            let da = ab.cross(ac).length() * 0.5 * ((q.0 - p.0) * (r.1 - p.1) - (r.0 - p.0) * (q.1 - p.1)).abs();
            let to = a + ab * s + ac * t - o;
            let d2 = to.length_squared();
            sum += pdf * (-n.dot(to) / d2.sqrt()).max(0.0) / d2 * da;
        }
    }
    sum
}

/// Cells of the light's (s, t) coordinates: n x n squares, or the n^2 congruent sub-triangles of
/// a triangle (an "up" triangle per square below the diagonal, a "down" one where it fits).
struct Cells {
    n: usize,
    tri: bool,
}

impl Cells {
    fn count(&self) -> usize {
        if self.tri {
            self.n * self.n + self.n * self.n
        } else {
            self.n * self.n
        }
    }

    /// The cell of (s, t), if any.
    fn of(&self, s: f64, t: f64) -> usize {
        let n = self.n as f64;
        let (i, j) = ((s * n).floor().clamp(0.0, n - 1.0), (t * n).floor().clamp(0.0, n - 1.0));
        let base = (i as usize) * self.n + j as usize;
        if self.tri && (s * n - i) + (t * n - j) > 1.0 {
            self.n * self.n + base
        } else {
            base
        }
    }

    /// The corners (s, t) of a cell's triangles.
    fn triangles(&self, c: usize) -> Vec<[(f64, f64); 3]> {
        let nn = self.n * self.n;
        let (down, b) = (c >= nn, c % nn);
        let (i, j) = ((b / self.n) as f64, (b % self.n) as f64);
        let h = 1.0 / self.n as f64;
        let (s0, t0, s1, t1) = (i * h, j * h, (i + 1.0) * h, (j + 1.0) * h);
        if !self.tri {
            vec![[(s0, t0), (s1, t0), (s1, t1)], [(s0, t0), (s1, t1), (s0, t1)]]
        } else if !down {
            if i + j > self.n as f64 - 1.0 {
                vec![]
            } else {
                vec![[(s0, t0), (s1, t0), (s0, t1)]]
            }
        } else if i + j > self.n as f64 - 2.0 {
            vec![]
        } else {
            vec![[(s1, t0), (s1, t1), (s0, t1)]]
        }
    }
}

/// The (s, t) coordinates of a point `y` of the light.
fn coords(e: &Emitter, y: Vec3) -> (f64, f64) {
    let (ab, ac) = (e.ab.as_dvec3(), e.ac.as_dvec3());
    let d = y.as_dvec3() - e.a.as_dvec3();
    let (g11, g12, g22) = (ab.dot(ab), ab.dot(ac), ac.dot(ac));
    let (r1, r2) = (d.dot(ab), d.dot(ac));
    let det = g11 * g22 - g12 * g12;
    ((r1 * g22 - r2 * g12) / det, (r2 * g11 - r1 * g12) / det)
}

/// Chi-square p-value of `n` points of `sample` (point and the claimed S) on light `e` seen from
/// `o`; also asserts that the pdf 1 / S integrates to 1 over the light.
fn chi2_on_light(name: &str, e: &Emitter, o: Vec3, sample: impl Fn(f32, f32) -> (Vec3, f32)) -> f64 {
    let omega = sample(0.5, 0.5).1 as f64;
    let integral = pdf_integral(o, e, 1.0 / omega);
    assert!((integral - 1.0).abs() < 2e-4, "{name}: the pdf integrates to {integral} over the light");
    let cells = Cells { n: 16, tri: e.triangle };
    let (a, ab, ac, od) = (e.a.as_dvec3(), e.ab.as_dvec3(), e.ac.as_dvec3(), o.as_dvec3());
    let at = |(s, t): (f64, f64)| a + ab * s + ac * t;
    let n = crate::sampling::chi2::SAMPLES;
    let expected: Vec<f64> = (0..cells.count())
        .map(|c| {
            let w: f64 = cells.triangles(c).iter().map(|[p, q, r]| tri_solid_angle(od, at(*p), at(*q), at(*r))).sum();
            w / omega * n as f64
        })
        .collect();
    let mut observed = vec![0u64; cells.count()];
    let mut rng = Rng::new(0x5eed);
    for _ in 0..n {
        let [u, v] = rng.u2();
        let (y, s) = sample(u, v);
        assert_eq!(s as f64, omega, "{name}: S depends on the sample");
        assert!(y.is_finite(), "{name}: point {y} at ({u}, {v})");
        let (s, t) = coords(e, y);
        let tol = 1e-4;
        assert!(
            s > -tol && t > -tol && if e.triangle { s + t < 1.0 + tol } else { s < 1.0 + tol && t < 1.0 + tol },
            "{name}: point ({s}, {t}) off the light at ({u}, {v})"
        );
        observed[cells.of(s, t)] += 1;
    }
    let (chi2, dof) = statistic(&observed, &expected, n, name);
    let p = gamma_q(0.5 * dof as f64, 0.5 * chi2);
    eprintln!("chi2 {name}: chi2 = {chi2:.1}, dof = {dof}, p = {p:.4}, S = {omega:.4e}, integral = {integral:.6}");
    p
}

fn rect_light() -> Emitter {
    Emitter::quad(Vec3::new(-0.5, 2.0, -0.25), Vec3::X * 1.0, Vec3::Z * 0.5, Vec3::ONE)
}

fn tri_light() -> Emitter {
    Emitter::triangle([Vec3::new(-0.5, 1.0, 0.2), Vec3::new(0.7, 1.3, -0.1), Vec3::new(0.1, 0.8, 0.9)], Vec3::ONE)
}

/// Reference points: below the light's middle, far off to one side, and close to a corner.
fn viewpoints(e: &Emitter) -> [Vec3; 3] {
    let mid = e.a + 0.3 * (e.ab + e.ac);
    [mid + e.normal * 1.5, mid + e.normal * 0.4 + e.ab * 2.5 - e.ac * 1.5, e.a + e.normal * 0.02 + e.ab * 0.01]
}

#[test]
fn spherical_rectangle_matches_its_pdf_chi_square() {
    let e = rect_light();
    assert!(e.is_rectangle());
    for (k, o) in viewpoints(&e).into_iter().enumerate() {
        let ex = e.ab.normalize();
        let ey = e.ac.normalize();
        let p = chi2_on_light(&format!("spherical rectangle {k}"), &e, o, |u, v| {
            sample_spherical_rect(o, e.a, ex, ey, e.ab.length(), e.ac.length(), u, v)
        });
        let alpha = SIGNIFICANCE / CHI2_TESTS as f64;
        assert!(p >= alpha, "spherical rectangle {k}: chi-square rejects the warp (p = {p:.3e} < {alpha:.1e})");
    }
}

#[test]
fn spherical_triangle_matches_its_pdf_chi_square() {
    let e = tri_light();
    for (k, o) in viewpoints(&e).into_iter().enumerate() {
        let v = [e.a, e.a + e.ab, e.a + e.ac];
        let p = chi2_on_light(&format!("spherical triangle {k}"), &e, o, |u, w| sample_spherical_tri(o, v, u, w));
        let alpha = SIGNIFICANCE / CHI2_TESTS as f64;
        assert!(p >= alpha, "spherical triangle {k}: chi-square rejects the warp (p = {p:.3e} < {alpha:.1e})");
    }
}

#[test]
fn emitter_warp_matches_its_pdf_chi_square_and_its_area_form() {
    // Through the lights' code: `Emitters::warp_x8` on a mixed list, its `area` (S d^2 / cos_l)
    // read back as the pdf, and `solid_angle_x8` agreeing with the points' S.
    let list = Emitters::new([rect_light()], [tri_light()]);
    for (i, e) in list.list.iter().enumerate() {
        let o = viewpoints(e)[0];
        let p = chi2_on_light(&format!("emitter {i}"), e, o, |u, v| {
            let mut ls = list.place_x8(U8::splat(i as u32), F8::ONE, F8::splat(u), F8::splat(v));
            list.warp_x8(LightWarp::SolidAngle, &mut ls, Vec3x8::splat(o), crate::simd::mask_all());
            let y = ls.y.lane(0);
            let to = y - o;
            let cos_l = -e.normal.dot(to.normalize());
            let s_from_area = cos_l * ls.area.as_array()[0] / to.length_squared();
            let (s, warped) = list.solid_angle_x8(U8::splat(i as u32), Vec3x8::splat(o), crate::simd::mask_all());
            assert!(warped.all());
            let s = s.as_array()[0];
            assert!((s_from_area - s).abs() <= 1e-5 * s, "area form {s_from_area} vs S {s}");
            (y, s)
        });
        let alpha = SIGNIFICANCE / CHI2_TESTS as f64;
        assert!(p >= alpha, "emitter {i}: chi-square rejects the warp (p = {p:.3e} < {alpha:.1e})");
    }
}

#[test]
fn warps_x8_match_scalar_bit_for_bit() {
    let (r, t) = (rect_light(), tri_light());
    let mut rng = Rng::new(11);
    for _ in 0..200 {
        let os: [Vec3; 8] =
            std::array::from_fn(|_| Vec3::new(rng.f32() * 4.0 - 2.0, rng.f32() * 1.5, rng.f32() * 4.0 - 2.0));
        let us: [f32; 8] = std::array::from_fn(|_| rng.f32());
        let vs: [f32; 8] = std::array::from_fn(|_| rng.f32());
        let o8 = Vec3x8::from_lanes(os);
        let (u8_, v8) = (F8::new(us), F8::new(vs));
        let s = Vec3x8::splat;
        let (ex, ey) = (r.ab.normalize(), r.ac.normalize());
        let (lx, ly) = (r.ab.length(), r.ac.length());
        let rect = crate::sampling::spherical_rect::SphericalRect8::new(
            o8,
            s(r.a),
            s(ex),
            s(ey),
            F8::splat(lx),
            F8::splat(ly),
        );
        let tv = [t.a, t.a + t.ab, t.a + t.ac];
        let tri = crate::sampling::spherical_tri::SphericalTri8::new(o8, s(tv[0]), s(tv[1]), s(tv[2]));
        let (yr, sr, yt, st) = (rect.sample(u8_, v8), rect.solid_angle(), tri.sample(u8_, v8), tri.solid_angle());
        for i in 0..8 {
            let (y1, s1) = sample_spherical_rect(os[i], r.a, ex, ey, lx, ly, us[i], vs[i]);
            assert_eq!(y1.to_array().map(f32::to_bits), yr.lane(i).to_array().map(f32::to_bits));
            assert_eq!(s1.to_bits(), sr.as_array()[i].to_bits());
            let (y2, s2) = sample_spherical_tri(os[i], tv, us[i], vs[i]);
            assert_eq!(y2.to_array().map(f32::to_bits), yt.lane(i).to_array().map(f32::to_bits));
            assert_eq!(s2.to_bits(), st.as_array()[i].to_bits());
        }
        // The lights' per-lane gather equals the splatted light, lane by lane.
        let list = Emitters::new([r], [t]);
        let ids = U8::new(std::array::from_fn(|i| (i % 2) as u32));
        let mut mixed = list.place_x8(ids, F8::ONE, u8_, v8);
        list.warp_x8(LightWarp::SolidAngle, &mut mixed, o8, crate::simd::mask_all());
        for (k, e) in list.list.iter().enumerate() {
            let mut one = e.sample_x8(u8_, v8);
            e.warp_x8(LightWarp::SolidAngle, &mut one, o8, crate::simd::mask_all());
            // The table's row (the path tracer's) warps as the light's own.
            let mut by_row = e.sample_x8(u8_, v8);
            list.warp_rows[k].warp_x8(LightWarp::SolidAngle, &mut by_row, o8, crate::simd::mask_all());
            assert_eq!(bits3(by_row.y), bits3(one.y));
            assert_eq!(by_row.area.to_bits().to_array(), one.area.to_bits().to_array());
            for i in (k..8).step_by(2) {
                assert_eq!(mixed.y.lane(i).to_array().map(f32::to_bits), one.y.lane(i).to_array().map(f32::to_bits));
                assert_eq!(mixed.area.as_array()[i].to_bits(), one.area.as_array()[i].to_bits());
            }
        }
    }
}

/// The bits of eight points.
fn bits3(v: Vec3x8) -> [[u32; 8]; 3] {
    [v.x, v.y, v.z].map(|c| c.to_bits().to_array())
}

/// The rectangle warp in f64 (the paper's formulas, four asin and the three steps fu, cu, xu), for
/// the precision measurement.
#[allow(clippy::too_many_arguments)]
fn rect_f64(o: DVec3, c: DVec3, ex: DVec3, ey: DVec3, lx: f64, ly: f64, u: f64, v: f64) -> DVec3 {
    let d = c - o;
    let mut ez = ex.cross(ey);
    let mut z0 = d.dot(ez);
    if z0 > 0.0 {
        z0 = -z0;
        ez = -ez;
    }
    let (x0, y0) = (d.dot(ex), d.dot(ey));
    let (x1, y1) = (x0 + lx, y0 + ly);
    let l = |a: f64| (a * a + z0 * z0).sqrt();
    let (l0, l1, l2, l3) = (l(y0), l(x1), l(y1), l(x0));
    let g = |c: f64| c.clamp(-1.0, 1.0).asin();
    let (a0, a1, a2, a3) =
        (g(-y0 * x1 / (l0 * l1)), g(x1 * y1 / (l1 * l2)), g(-y1 * x0 / (l2 * l3)), g(x0 * y0 / (l3 * l0)));
    let s = a0 + a1 + a2 + a3;
    let k = std::f64::consts::PI - a2 - a3;
    let (b0, b1) = (-y0 / l0, y1 / l2);
    let au = u * s + k;
    let fu = (au.cos() * b0 - b1) / au.sin();
    let cu = (1.0 / (fu * fu + b0 * b0).sqrt()).copysign(fu).clamp(-1.0, 1.0);
    let xu = (-(cu * z0) / (1.0 - cu * cu).sqrt()).clamp(x0, x1);
    let dd = xu * xu + z0 * z0;
    let (h0, h1) = (y0 / (y0 * y0 + dd).sqrt(), y1 / (y1 * y1 + dd).sqrt());
    let hv = h0 + v * (h1 - h0);
    let yv = (hv * dd.sqrt() / (1.0 - hv * hv).sqrt()).clamp(y0, y1);
    o + ex * xu + ey * yv + ez * z0
}

/// Arvo's triangle warp in f64, for the precision measurement.
fn tri_f64(o: DVec3, v: [DVec3; 3], u: f64, w: f64) -> DVec3 {
    let (a, b, c) = ((v[0] - o).normalize(), (v[1] - o).normalize(), (v[2] - o).normalize());
    let s = 2.0 * a.dot(b.cross(c)).abs().atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a));
    let cos_alpha = a.cross(b).normalize().dot(a.cross(c).normalize()).clamp(-1.0, 1.0);
    let (alpha, sin_alpha) = (cos_alpha.acos(), (1.0 - cos_alpha * cos_alpha).sqrt());
    let (sn, cs) = (u * s - alpha).sin_cos();
    let (p, q) = (cs - cos_alpha, sn + sin_alpha * a.dot(b));
    let cos_b = (((q * cs - p * sn) * cos_alpha - q) / ((q * sn + p * cs) * sin_alpha)).clamp(-1.0, 1.0);
    let c2 = a * cos_b + (c - a * c.dot(a)).normalize() * (1.0 - cos_b * cos_b).sqrt();
    let z = 1.0 - w * (1.0 - c2.dot(b));
    let dir = b * z + (c2 - b * c2.dot(b)).normalize() * (1.0 - z * z).max(0.0).sqrt();
    let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
    o + dir * (n.dot(v[0] - o) / n.dot(dir))
}

/// Largest distance between the f32 warps' points and the f64 formulas over a 64 x 64 grid of
/// (u, v), relative to the light's size, for a unit light seen head-on at distance `dist`:
/// (S, rectangle error, triangle error).
fn warp_error_at(dist: f32) -> (f32, f64, f64) {
    let o = Vec3::new(0.13, -dist, 0.07);
    let (c, ex, ey) = (Vec3::new(-0.5, 0.0, -0.5), Vec3::X, Vec3::Z);
    let tv = [Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 0.0, -0.5), Vec3::new(0.0, 0.0, 0.5)];
    let (mut er, mut et, mut s) = (0f64, 0f64, 0f32);
    let k = 64;
    for i in 0..=k {
        for j in 0..=k {
            let (u, v) = ((i as f32 / k as f32).min(0.999_999_9), (j as f32 / k as f32).min(0.999_999_9));
            let (y, sr) = sample_spherical_rect(o, c, ex, ey, 1.0, 1.0, u, v);
            s = sr;
            let yd = rect_f64(o.as_dvec3(), c.as_dvec3(), DVec3::X, DVec3::Z, 1.0, 1.0, u as f64, v as f64);
            er = er.max((y.as_dvec3() - yd).length());
            let (y, _) = sample_spherical_tri(o, tv, u, v);
            let yd = tri_f64(o.as_dvec3(), tv.map(|p| p.as_dvec3()), u as f64, v as f64);
            et = et.max((y.as_dvec3() - yd).length());
        }
    }
    (s, er, et)
}

#[test]
fn f32_warp_error_by_solid_angle() {
    // The measurement behind OMEGA_MIN (printed with --nocapture), and its bound: at the
    // threshold both warps place points within 1e-3 of the light's size of the exact ones.
    for dist in [1.0f32, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0] {
        let (s, er, et) = warp_error_at(dist);
        eprintln!("distance {dist:6}: S = {s:.3e} sr, rectangle error {er:.2e}, triangle error {et:.2e}");
    }
    // A unit square at distance OMEGA_MIN^-1/2 subtends OMEGA_MIN: the threshold.
    let (s, er, et) = warp_error_at(OMEGA_MIN.powf(-0.5));
    assert!((s - OMEGA_MIN).abs() < 0.01 * OMEGA_MIN, "{s}");
    assert!(er < 1e-3 && et < 1e-4, "at S = {s}: rectangle {er}, triangle {et}");
}

#[test]
fn warp_falls_back_to_area_sampling_below_the_threshold() {
    // A unit square light seen head-on, just nearer and just farther than where it subtends
    // OMEGA_MIN: warped (area = S d^2 / cos_l, not the light's) on one side, the area sample
    // untouched on the other, and the hit's pdf (`solid_angle_x8`) deciding the same way.
    let e = Emitter::quad(Vec3::new(-0.5, 0.0, -0.5), Vec3::X, Vec3::Z, Vec3::ONE);
    assert_eq!(e.normal, Vec3::Y);
    let list = Emitters::new([e], []);
    let (u, v) = (F8::splat(0.3), F8::splat(0.8));
    let all = crate::simd::mask_all();
    let edge = OMEGA_MIN.powf(-0.5);
    let (near, far) = (Vec3::new(0.0, edge * 0.99, 0.0), Vec3::new(0.0, edge * 1.01, 0.0));
    for (o, warped) in [(near, true), (far, false)] {
        let o8 = Vec3x8::splat(o);
        let area = list.place_x8(U8::splat(0), F8::ONE, u, v);
        let mut ls = area;
        list.warp_x8(LightWarp::SolidAngle, &mut ls, o8, all);
        let (s, w) = list.solid_angle_x8(U8::splat(0), o8, all);
        let s = s.as_array()[0];
        assert_eq!(w.all(), warped, "at {o}: S = {s}, threshold {OMEGA_MIN}");
        assert_eq!(s >= OMEGA_MIN, warped);
        assert_eq!(ls.area.as_array()[0] != e.area, warped, "area {:?}", ls.area);
        assert_eq!(ls.y.lane(0) != area.y.lane(0), warped);
        // Behind the light (its back side): never warped.
        let (_, w) = list.solid_angle_x8(U8::splat(0), Vec3x8::splat(-o), all);
        assert!(w.none());
    }
    // A skewed parallelogram is not a rectangle: area sampling.
    let skew = Emitter::quad(Vec3::ZERO, Vec3::X, Vec3::new(0.3, 0.0, 1.0), Vec3::ONE);
    assert!(!skew.is_rectangle());
    let (_, w) = Emitters::new([skew], []).solid_angle_x8(U8::splat(0), Vec3x8::splat(Vec3::new(0.5, -1.0, 0.5)), all);
    assert!(w.none());
}

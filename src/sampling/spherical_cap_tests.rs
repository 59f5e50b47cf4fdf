//! Tests of the sphere cone warp: chi-square of its directions against uniform in the cone (binned
//! in f64 from the points it returns), its points on the visible cap, the pdf 1 / S integrated
//! over the sphere by quadrature (which uses neither the warp nor its S formula), x8 against
//! scalar, and the f32 error against an f64 ray-sphere construction by solid angle.

use super::*;
use crate::sampling::chi2::{gamma_q, statistic, Rng, CHI2_TESTS, SIGNIFICANCE};
use glam::DVec3;

/// Viewpoints of a sphere of radius 0.7 at `c`: grazing (d = 1.02 r), near, mid, far (a small
/// cone).
fn cases() -> Vec<(Vec3, Vec3, f32)> {
    let c = Vec3::new(0.3, -0.2, 1.1);
    let r = 0.7;
    let dir = Vec3::new(0.48, 0.6, -0.64).normalize();
    [1.02, 1.5, 4.0, 60.0].into_iter().map(|k| (c - dir * (k * r), c, r)).collect()
}

/// The integral over the sphere of `pdf * max(0, cos_l) / dist^2` seen from distance `d` of a
/// sphere of radius `r` (f64 midpoint rule in the angle at the centre; the integrand is
/// rotationally symmetric about the axis).
fn pdf_integral(d: f64, r: f64, pdf: f64) -> f64 {
    let n = 1_000_000;
    let h = std::f64::consts::PI / n as f64;
    let mut sum = 0.0;
    for i in 0..n {
        let a = (i as f64 + 0.5) * h;
        let (sa, ca) = a.sin_cos();
        let dist2 = (d - r * ca).powi(2) + (r * sa).powi(2);
        let cos_l_dist = d * ca - r;
        if cos_l_dist > 0.0 {
            sum += cos_l_dist / (dist2 * dist2.sqrt()) * 2.0 * std::f64::consts::PI * r * r * sa * h;
        }
    }
    pdf * sum
}

#[test]
fn cap_warp_is_uniform_in_its_cone_chi_square_and_its_pdf_integrates_to_one() {
    for (k, (o, c, r)) in cases().into_iter().enumerate() {
        let name = format!("sphere cap {k}");
        let s = sample_spherical_cap(o, c, r, 0.5, 0.5).2 as f64;
        let d = (c - o).as_dvec3().length();
        let integral = pdf_integral(d, r as f64, 1.0 / s);
        assert!((integral - 1.0).abs() < 2e-4, "{name}: the pdf integrates to {integral} over the sphere");
        // Cone coordinates in f64 from the returned points.
        let (od, cd) = (o.as_dvec3(), c.as_dvec3());
        let w = (cd - od).normalize();
        let sin2_max = (r as f64 / d).powi(2);
        let omc_max = sin2_max / (1.0 + (1.0 - sin2_max).sqrt());
        let (e1, e2) = {
            let a = if w.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
            let e1 = (a - w * w.dot(a)).normalize();
            (e1, w.cross(e1))
        };
        let bins = 16;
        let n = crate::sampling::chi2::SAMPLES;
        let mut observed = vec![0u64; bins * bins];
        let mut rng = Rng::new(0xcafe + k as u64);
        for _ in 0..n {
            let [u, v] = rng.u2();
            let (y, nrm, s2) = sample_spherical_cap(o, c, r, u, v);
            assert_eq!(s2 as f64, s, "{name}: S depends on the sample");
            let yd = y.as_dvec3();
            assert!(((yd - cd).length() - r as f64).abs() < 2e-6 * (1.0 + d), "{name}: {y} off the sphere");
            assert!((nrm.as_dvec3() - (yd - cd) / r as f64).length() < 1e-5, "{name}: normal {nrm} at {y}");
            let to = yd - od;
            let dist = to.length();
            // On the visible side: the normal faces the viewpoint (to rounding near the rim).
            assert!(-nrm.as_dvec3().dot(to / dist) > -1e-3, "{name}: {y} not visible at ({u}, {v})");
            let dir = to / dist;
            let cos_t = dir.dot(w);
            let omc = (1.0 - cos_t).max(0.0);
            let a = (omc / omc_max).clamp(0.0, 1.0 - 1e-12);
            let phi = dir.dot(e2).atan2(dir.dot(e1)).rem_euclid(2.0 * std::f64::consts::PI);
            let (i, j) = ((a * bins as f64) as usize, (phi / (2.0 * std::f64::consts::PI) * bins as f64) as usize);
            observed[i.min(bins - 1) * bins + j.min(bins - 1)] += 1;
        }
        let expected = vec![n as f64 / (bins * bins) as f64; bins * bins];
        let (chi2, dof) = statistic(&observed, &expected, n, &name);
        let p = gamma_q(0.5 * dof as f64, 0.5 * chi2);
        eprintln!("chi2 {name}: chi2 = {chi2:.1}, dof = {dof}, p = {p:.4}, S = {s:.4e}, integral = {integral:.6}");
        let alpha = SIGNIFICANCE / CHI2_TESTS as f64;
        assert!(p >= alpha, "{name}: chi-square rejects the warp (p = {p:.3e} < {alpha:.1e})");
    }
}

#[test]
fn cap_x8_matches_scalar_bit_for_bit_and_inside_has_no_cone() {
    let mut rng = Rng::new(5);
    for _ in 0..200 {
        let os: [Vec3; 8] = std::array::from_fn(|_| Vec3::new(rng.f32() * 6.0 - 3.0, rng.f32() * 6.0 - 3.0, rng.f32()));
        let cs: [Vec3; 8] = std::array::from_fn(|_| Vec3::new(rng.f32(), rng.f32(), rng.f32() * 2.0));
        let rs: [f32; 8] = std::array::from_fn(|_| 0.05 + rng.f32());
        let (us, vs): ([f32; 8], [f32; 8]) = (std::array::from_fn(|_| rng.f32()), std::array::from_fn(|_| rng.f32()));
        let cap = SphericalCap8::new(Vec3x8::from_lanes(os), Vec3x8::from_lanes(cs), F8::new(rs));
        let (y, n) = cap.sample(F8::new(us), F8::new(vs));
        let s = cap.solid_angle().to_array();
        for i in 0..8 {
            let (y1, n1, s1) = sample_spherical_cap(os[i], cs[i], rs[i], us[i], vs[i]);
            assert_eq!(y.lane(i).to_array().map(f32::to_bits), y1.to_array().map(f32::to_bits));
            assert_eq!(n.lane(i).to_array().map(f32::to_bits), n1.to_array().map(f32::to_bits));
            assert_eq!(s[i].to_bits(), s1.to_bits());
            let inside = (os[i] - cs[i]).length() <= rs[i];
            assert_eq!(s1 == 0.0, inside, "lane {i}: S {s1}");
        }
    }
    // The ends of the unit square give finite points on the sphere.
    for (o, c, r) in cases() {
        for (u, v) in [(0.0, 0.0), (1.0, 1.0), (0.999_999_94, 0.5), (1.0, 0.0)] {
            let (y, n, _) = sample_spherical_cap(o, c, r, u, v);
            assert!(y.is_finite() && n.is_finite() && ((y - c).length() - r).abs() < 1e-5, "{y} {n} at ({u}, {v})");
        }
    }
}

/// The f64 reference: the direction uniform in the cone (same frame and parametrization) and its
/// nearest intersection with the sphere.
fn cap_f64(o: DVec3, c: DVec3, r: f64, u: f64, v: f64) -> (DVec3, f64) {
    let dc = c - o;
    let d = dc.length();
    let w = dc / d;
    let sin2_max = (r / d).powi(2);
    let cos_max = (1.0 - sin2_max).sqrt();
    let omc_max = sin2_max / (1.0 + cos_max);
    // Frame8::from_normal in f64.
    let sign = 1f64.copysign(w.z);
    let a = -1.0 / (sign + w.z);
    let b = w.x * w.y * a;
    let s = DVec3::new(1.0 + sign * w.x * w.x * a, sign * b, -sign * w.x);
    let t = DVec3::new(b, sign + w.y * w.y * a, -w.y);
    let k = u * omc_max;
    let (cos_t, sin_t) = (1.0 - k, (k * (2.0 - k)).sqrt());
    let (sp, cp) = (v * 2.0 * std::f64::consts::PI).sin_cos();
    let dir = (s * cp + t * sp) * sin_t + w * cos_t;
    let disc = (r * r - d * d * sin_t * sin_t).max(0.0);
    let hit = d * cos_t - disc.sqrt();
    (o + dir * hit, 2.0 * std::f64::consts::PI * omc_max)
}

/// Largest distance between the f32 warp's points and the f64 construction over a 64 x 64 grid
/// (u < 1 - 1e-3, off the silhouette where the ray construction itself is ill-conditioned),
/// relative to the radius, and the relative error of S, for a unit sphere at distance `dist`.
fn cap_error_at(dist: f32) -> (f64, f64, f64) {
    let o = Vec3::new(0.13, -0.21, 0.07);
    let c = o + Vec3::new(0.36, 0.48, 0.8) * dist;
    let (od, cd) = (o.as_dvec3(), c.as_dvec3());
    let (mut e, mut s32, mut s64) = (0f64, 0f64, 0f64);
    let k = 64;
    for i in 0..=k {
        for j in 0..=k {
            let (u, v) = ((i as f32 / k as f32).min(0.999), (j as f32 / k as f32).min(0.999_999_9));
            let (y, _, s) = sample_spherical_cap(o, c, 1.0, u, v);
            let (yd, sd) = cap_f64(od, cd, 1.0, u as f64, v as f64);
            e = e.max((y.as_dvec3() - yd).length());
            (s32, s64) = (s as f64, sd);
        }
    }
    (s64, e, (s32 - s64).abs() / s64)
}

#[test]
fn f32_cap_warp_error_by_solid_angle() {
    // The measurement behind `light::warp::SPHERE_OMEGA_MIN` (printed with --nocapture): the point
    // error relative to the radius and S's relative error stay small as the sphere shrinks to a
    // dot; asserted down to 1e-10 sr.
    for dist in [1.5f32, 3.0, 10.0, 100.0, 1e3, 1e4, 1e5, 1.8e5, 1e6, 1e8] {
        let (s, e, es) = cap_error_at(dist);
        eprintln!("distance {dist:8.1e}: S = {s:.3e} sr, point error {e:.2e} r, S error {es:.2e}");
        if s >= 1e-10 {
            assert!(e < 0.1 && es < 1e-5, "at S = {s:.3e}: point error {e:.2e} r, S error {es:.2e}");
        }
    }
}

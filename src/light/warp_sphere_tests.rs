//! Tests of sphere lights in `light::warp` and `light::emitters`: area sampling uniform on the
//! sphere (chi-square), the solid-angle warp through the lights' code (its area form read back as
//! the pdf 1 / S, the normal it returns, the same S at a hit), inside the sphere, and the fallback
//! edge [`SPHERE_OMEGA_MIN`].

use super::*;
use crate::sampling::chi2::{gamma_q, statistic, Rng, CHI2_TESTS, SIGNIFICANCE};
use crate::sampling::spherical_cap::sample_spherical_cap;
use crate::simd::mask_all;
use glam::Vec3;

fn ball() -> Emitter {
    Emitter::sphere(Vec3::new(0.4, 2.0, -0.3), 0.6, Vec3::new(3.0, 2.0, 1.0))
}

fn list() -> Emitters {
    let q = Emitter::quad(Vec3::new(-1.0, 2.0, -1.0), Vec3::X * 2.0, Vec3::Z * 2.0, Vec3::splat(1.0));
    let t = Emitter::triangle([Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::new(3.0, 0.0, 0.0));
    Emitters::new([q, ball()], [t])
}

#[test]
fn area_sampling_of_a_sphere_is_uniform_on_it_chi_square() {
    // Bins equal in area: z = cos(polar angle) in 8 bands, azimuth in 16 sectors.
    let e = ball();
    assert!((e.area - 4.0 * std::f32::consts::PI * 0.36).abs() < 1e-5);
    let (bz, bp) = (8usize, 16usize);
    let n = crate::sampling::chi2::SAMPLES;
    let mut observed = vec![0u64; bz * bp];
    let mut rng = Rng::new(77);
    for _ in 0..n / 8 {
        let (us, vs): ([f32; 8], [f32; 8]) = (std::array::from_fn(|_| rng.f32()), std::array::from_fn(|_| rng.f32()));
        let ls = e.sample_x8(F8::new(us), F8::new(vs));
        assert_eq!(ls.area.to_array(), [e.area; 8]);
        for i in 0..8 {
            let (y, nrm) = (ls.y.lane(i), ls.normal.lane(i));
            assert!(((y - e.a).length() - e.radius).abs() < 1e-5 && (nrm - (y - e.a) / e.radius).length() < 1e-5);
            assert_eq!(e.point(us[i], vs[i]), y, "scalar point");
            let z = ((nrm.z as f64 + 1.0) * 0.5 * bz as f64) as usize;
            let phi = (nrm.y as f64).atan2(nrm.x as f64).rem_euclid(2.0 * std::f64::consts::PI);
            let p = (phi / (2.0 * std::f64::consts::PI) * bp as f64) as usize;
            observed[z.min(bz - 1) * bp + p.min(bp - 1)] += 1;
        }
    }
    let m = n / 8 * 8;
    let expected = vec![m as f64 / (bz * bp) as f64; bz * bp];
    let (chi2, dof) = statistic(&observed, &expected, m, "sphere area");
    let p = gamma_q(0.5 * dof as f64, 0.5 * chi2);
    let alpha = SIGNIFICANCE / CHI2_TESTS as f64;
    assert!(p >= alpha, "sphere area sampling: chi-square rejects it (p = {p:.3e})");
}

#[test]
fn sphere_warp_through_the_lights_gives_the_cap_points_and_pdf_one_over_s() {
    let l = list();
    let i = 1u32;
    let e = l.list[i as usize];
    assert!(e.sphere && !e.is_rectangle() && l.any_sphere && l.n_quads == 2);
    let mut rng = Rng::new(3);
    for o in [Vec3::new(0.1, 0.0, 0.2), Vec3::new(2.0, 5.0, 1.0), Vec3::new(0.4, 2.0, -1.0)] {
        let o8 = Vec3x8::splat(o);
        // Mixed lanes: the sphere on lanes 0, 2, 4, 6, the quad and the triangle on the others.
        let ids = U8::new([1, 0, 1, 2, 1, 0, 1, 2]);
        let (us, vs): ([f32; 8], [f32; 8]) = (std::array::from_fn(|_| rng.f32()), std::array::from_fn(|_| rng.f32()));
        let mut ls = l.place_x8(ids, F8::ONE, F8::new(us), F8::new(vs));
        l.warp_x8(LightWarp::SolidAngle, &mut ls, o8, mask_all());
        let (s, warped) = l.solid_angle_x8(ids, o8, mask_all());
        for k in [0usize, 2, 4, 6] {
            let (y, nrm, s1) = sample_spherical_cap(o, e.a, e.radius, us[k], vs[k]);
            assert_eq!(ls.y.lane(k), y, "lane {k}: the cap's point");
            assert_eq!(ls.normal.lane(k), nrm, "lane {k}: the cap's normal");
            assert_eq!(s.as_array()[k], s1);
            assert!(crate::simd::mask_to_bools(warped)[k]);
            // The area form: cos_l / (d^2 area) = 1 / S.
            let to = y - o;
            let cos_l = -nrm.dot(to.normalize());
            let s_from_area = cos_l * ls.area.as_array()[k] / to.length_squared();
            assert!((s_from_area - s1).abs() <= 1e-4 * s1, "area form {s_from_area} vs S {s1}");
            // At a hit of that point, the path tracer's normal is the same.
            assert!((e.normal_at(y) - nrm).length() < 1e-5);
        }
    }
}

#[test]
fn inside_a_sphere_light_is_area_sampling() {
    let l = list();
    let e = l.list[1];
    let o8 = Vec3x8::splat(e.a + Vec3::new(0.1, -0.2, 0.05));
    let (u, v) = (F8::splat(0.3), F8::splat(0.7));
    let area = l.place_x8(U8::splat(1), F8::ONE, u, v);
    let mut ls = area;
    l.warp_x8(LightWarp::SolidAngle, &mut ls, o8, mask_all());
    let (s, w) = l.solid_angle_x8(U8::splat(1), o8, mask_all());
    assert!(w.none() && s.to_array() == [0.0; 8]);
    assert_eq!(ls.y.lane(0), area.y.lane(0));
    assert_eq!(ls.area.to_array(), [e.area; 8]);
}

#[test]
fn sphere_warp_falls_back_to_area_sampling_below_the_threshold() {
    // A sphere at distance 1 whose radius makes S = pi (r/d)^2 (to first order) just above and
    // just below SPHERE_OMEGA_MIN: warped on one side, the area sample untouched on the other,
    // and the hit's pdf (`solid_angle_x8`) deciding the same way.
    let r_edge = (SPHERE_OMEGA_MIN / std::f32::consts::PI).sqrt();
    let o8 = Vec3x8::splat(Vec3::ZERO);
    let (u, v) = (F8::splat(0.3), F8::splat(0.8));
    for (k, warped) in [(1.02f32, true), (0.98, false)] {
        let e = Emitter::sphere(Vec3::new(0.0, 1.0, 0.0), r_edge * k, Vec3::ONE);
        let l = Emitters::new([e], []);
        let area = l.place_x8(U8::splat(0), F8::ONE, u, v);
        let mut ls = area;
        l.warp_x8(LightWarp::SolidAngle, &mut ls, o8, mask_all());
        let (s, w) = l.solid_angle_x8(U8::splat(0), o8, mask_all());
        let s = s.as_array()[0];
        assert_eq!(w.all(), warped, "radius {}: S = {s:e}, threshold {SPHERE_OMEGA_MIN:e}", e.radius);
        assert_eq!(s >= SPHERE_OMEGA_MIN, warped);
        assert_eq!(ls.area.as_array()[0] != e.area, warped, "area {:?}", ls.area);
        if warped {
            // Even there the point is the dot (to f32's resolution about it) and the pdf finite.
            let y = ls.y.lane(0);
            assert!(y.is_finite() && (y - e.a).length() <= 1e-7, "{y}");
            assert!(ls.area.as_array()[0].is_finite());
        } else {
            assert_eq!(ls.y.lane(0), area.y.lane(0));
        }
    }
}

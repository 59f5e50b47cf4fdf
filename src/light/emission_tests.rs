//! Emission sampling: every kind's rays integrate the emitted power (analytic integrals over
//! cones of directions), and area lights' directions follow their pdf (chi-square).

use super::*;
use crate::light::delta::DeltaLight;
use crate::light::desc::{DeltaLightDesc, RgbImage};
use glam::Mat4;

/// The mean of `f(sample)` over an n x n grid of stratified unit-square points per dimension
/// pair (position and direction share the grid, shifted).
fn mean<F: FnMut((f32, f32), (f32, f32)) -> f64>(n: u32, mut f: F) -> f64 {
    let mut s = 0.0;
    for i in 0..n {
        for j in 0..n {
            let u = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let v = (
                ((i * 7 + j * 3) % n) as f32 / n as f32 + 0.25 / n as f32,
                ((j * 5 + i) % n) as f32 / n as f32 + 0.5 / n as f32,
            );
            s += f(v, u);
        }
    }
    s / f64::from(n * n)
}

#[test]
fn point_light_power_in_a_cone_is_intensity_times_solid_angle() {
    let l = DeltaLight::new(&DeltaLightDesc::Point { position: Vec3::new(1.0, 2.0, 3.0), intensity: Vec3::splat(2.0) })
        .unwrap();
    // Directions with z > 0.5: solid angle 2 pi (1 - 0.5).
    let m =
        mean(400, |_, u| l.sample_emission(u).map_or(0.0, |e| if e.dir.z > 0.5 { f64::from(e.weight.x) } else { 0.0 }));
    let want = 2.0 * std::f64::consts::PI * 0.5 * 2.0;
    assert!((m / want - 1.0).abs() < 0.01, "{m} vs {want}");
    let total = mean(100, |_, u| l.sample_emission(u).map_or(0.0, |e| f64::from(e.weight.x)));
    assert!((total / f64::from(l.emitted_power()) - 1.0).abs() < 1e-5);
}

#[test]
fn spot_light_power_is_its_falloff_integrated() {
    // At (0, 3, 0), +z (the axis) pointing down.
    let to_world = Mat4::from_cols(glam::Vec4::X, glam::Vec4::Z, -glam::Vec4::Y, glam::Vec4::new(0.0, 3.0, 0.0, 1.0));
    let (cut, beam) = (30f64, 15f64);
    let l = DeltaLight::new(&DeltaLightDesc::Spot {
        to_world,
        intensity: Vec3::splat(1.0),
        cutoff_deg: cut as f32,
        beam_width_deg: beam as f32,
        texture: None,
    })
    .unwrap();
    // Analytic: 2 pi [ int_0^beam sin + int_beam^cut (cut - t) / (cut - beam) sin dt ].
    let (c, b) = (cut.to_radians(), beam.to_radians());
    let n = 100_000;
    let mut ramp = 0.0;
    for i in 0..n {
        let t = b + (c - b) * (i as f64 + 0.5) / n as f64;
        ramp += (c - t) / (c - b) * t.sin() * (c - b) / n as f64;
    }
    let want = 2.0 * std::f64::consts::PI * ((1.0 - b.cos()) + ramp);
    let m = mean(500, |_, u| l.sample_emission(u).map_or(0.0, |e| f64::from(e.weight.x)));
    assert!((m / want - 1.0).abs() < 0.01, "{m} vs {want}");
    // Every ray leaves within the cone, around the light's axis (down, -y).
    let axis = to_world.transform_vector3(Vec3::Z).normalize();
    assert!(axis.y < -0.99);
    for k in 0..100 {
        let e = l.sample_emission((k as f32 / 100.0, 0.3)).unwrap();
        assert!(e.dir.dot(axis) >= (c as f32).cos() - 1e-5);
    }
}

#[test]
fn projector_power_lands_on_its_image_plane() {
    let to_world = Mat4::IDENTITY;
    let fov = 40f32;
    let l = DeltaLight::new(&DeltaLightDesc::Projector {
        to_world,
        irradiance: std::sync::Arc::new(RgbImage::constant(Vec3::ONE)),
        scale: 2.0,
        fov_x_deg: fov,
    })
    .unwrap();
    // The irradiance on a plane at distance 1 facing it is pi scale E over the image window:
    // power pi scale E (2 tan)^2 (a square image).
    let t = f64::from((fov.to_radians() * 0.5).tan());
    let want = std::f64::consts::PI * 2.0 * 4.0 * t * t;
    let m = mean(200, |_, u| l.sample_emission(u).map_or(0.0, |e| f64::from(e.weight.x)));
    assert!((m / want - 1.0).abs() < 1e-4, "{m} vs {want}");
    // Its next-event form agrees: li at a point of the plane times the area element.
    let p = Vec3::new(0.1, -0.2, 1.0);
    let world = to_world.transform_point3(p);
    let (_, d, li) = l.sample(world).unwrap();
    let cos = 1.0 / d;
    // E on the plane = li cos (with the point's distance d): pi scale E(uv).
    assert!(((li.x * cos) / (std::f32::consts::PI * 2.0) - 1.0).abs() < 1e-4, "{li}");
}

#[test]
fn area_light_rays_are_cosine_distributed_and_carry_its_power() {
    let e = Emitter::quad(Vec3::new(-1.0, 2.0, -1.0), Vec3::X * 2.0, Vec3::Z * 3.0, Vec3::new(1.0, 2.0, 3.0));
    // cos^2 of a cosine-weighted direction is uniform: chi-square over 10 bins.
    let n = 200;
    let mut bins = [0f64; 10];
    let mut w_sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            // Pseudo-random points (a regular grid through the concentric map would quantize cos).
            let h = |k: u32| {
                let mut x = u64::from(k).wrapping_add(0x9e37_79b9_7f4a_7c15);
                x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
                ((x ^ (x >> 31)) >> 40) as f32 / (1u64 << 24) as f32
            };
            let k = (i * n + j) * 4;
            let (u, v) = ((h(k), h(k + 1)), (h(k + 2), h(k + 3)));
            let s = e.sample_emission(v, u).unwrap();
            let c = s.dir.dot(e.normal);
            assert!(c > 0.0);
            bins[((c * c * 10.0) as usize).min(9)] += 1.0;
            w_sum += f64::from(s.weight.y);
            // The point lies on the light.
            let q = s.p - e.a;
            assert!(q.dot(e.normal).abs() < 1e-4);
        }
    }
    let expect = f64::from(n * n) / 10.0;
    let chi2: f64 = bins.iter().map(|c| (c - expect).powi(2) / expect).sum();
    assert!(chi2 < 27.88, "chi2 {chi2} (9 dof, p = 0.001): {bins:?}");
    let power = w_sum / f64::from(n * n);
    let want = std::f64::consts::PI * 6.0 * 2.0;
    assert!((power / want - 1.0).abs() < 1e-5, "{power} vs {want}");
}

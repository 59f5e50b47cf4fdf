//! The particle tracer's sensor connection and emitter choice.

use super::*;

fn sensor() -> Sensor {
    let (base, ax, ay) = (Vec3::new(0.1, 0.0, 1.0).normalize(), Vec3::new(-0.7, 0.0, 0.07), Vec3::new(0.0, -0.35, 0.0));
    let m = Mat3::from_cols(ax, ay, base);
    Sensor {
        origin: Vec3::new(1.0, 2.0, 3.0),
        inv: m.inverse(),
        norm: 1.0 / (4.0 * m.determinant().abs()),
        near: 0.01,
        width: 40,
        height: 20,
    }
}

#[test]
fn a_point_on_a_camera_ray_projects_to_its_pixel() {
    let s = sensor();
    let m = s.inv.inverse();
    for (x, y) in [(0.5f32, 0.5f32), (13.3, 7.9), (39.9, 19.2), (20.0, 10.5)] {
        let (a, b) = (2.0 * x / 40.0 - 1.0, 2.0 * y / 20.0 - 1.0);
        let d = m * Vec3::new(a, b, 1.0);
        let (px, _) = s.project(s.origin + d * 3.7).unwrap();
        assert_eq!(px, (y as u32) * 40 + x as u32, "({x}, {y})");
    }
    // Behind the camera: nothing.
    assert!(s.project(s.origin - m.col(2)).is_none());
}

#[test]
fn importance_integrates_to_one_over_the_image() {
    // Over uniform directions of the sphere: 4 pi E[W 1(in image)] = 1 (see the module docs).
    let s = sensor();
    let n = 1000;
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let (d, _) =
                crate::light::emission::uniform_sphere(((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32));
            if let Some((_, w)) = s.project(s.origin + d) {
                sum += f64::from(w);
            }
        }
    }
    let total = sum * 4.0 * std::f64::consts::PI / f64::from(n * n);
    assert!((total - 1.0).abs() < 0.01, "{total}");
}

#[test]
fn the_emitter_choice_follows_the_power_and_remaps_u() {
    let lp = LightPaths {
        sources: vec![Source0::Area(0), Source0::Delta(0), Source0::Area(1)],
        cdf: vec![0.25, 0.25, 1.0],
        pmf: vec![0.25, 0.0, 0.75],
        sensor: None,
    };
    let (s, p, u) = lp.pick(0.1).unwrap();
    assert_eq!((s, p), (Source0::Area(0), 0.25));
    assert!((u - 0.4).abs() < 1e-6);
    let (s, p, u) = lp.pick(0.25).unwrap();
    assert_eq!((s, p), (Source0::Area(1), 0.75));
    assert!(u.abs() < 1e-6);
    let (s, _, u) = lp.pick(0.999_999_9).unwrap();
    assert_eq!(s, Source0::Area(1));
    assert!(u < 1.0);
}

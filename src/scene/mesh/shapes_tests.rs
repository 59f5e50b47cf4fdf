//! The generators against the analytic shapes: area, normals, uv ranges and values, outline error.

use super::*;
use crate::scene::texturing::sphere_uv;

fn check_common(m: &Mesh) {
    m.validate().unwrap();
    for (f, t) in m.indices.iter().enumerate() {
        let ng = m.face_cross(f).normalize();
        for &i in t {
            // shading normals unit and on the side of the winding's normal
            let n = m.normals[i as usize];
            assert!((n.length() - 1.0).abs() < 1e-5 && n.dot(ng) > 0.0, "face {f}: n {n} ng {ng}");
            let uv = m.uvs[i as usize];
            assert!((0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y), "uv {uv}");
        }
    }
}

#[test]
fn rectangle_is_exact() {
    let m = rectangle();
    check_common(&m);
    assert_eq!(m.area(), 4.0);
    assert_eq!(m.uvs[1], Vec2::new(1.0, 0.0));
    assert_eq!(m.positions[1], Vec3::new(1.0, -1.0, 0.0));
}

#[test]
fn disk_area_uv_and_outline() {
    let m = disk();
    check_common(&m);
    // inscribed polygon's area: (N/2) sin(2pi/N)
    let n = SEGMENTS as f64;
    let polygon = n / 2.0 * (std::f64::consts::TAU / n).sin();
    assert!((m.area() - polygon).abs() < 1e-4, "area {} vs {polygon}", m.area());
    assert!((m.area() - std::f64::consts::PI).abs() / std::f64::consts::PI < 2.0 * f64::from(chord_error()));
    // uv at the vertices: (r, phi/2pi)
    for (p, uv) in m.positions.iter().zip(&m.uvs) {
        if p.length() > 0.0 {
            assert!((uv.x - p.length()).abs() < 1e-6);
            let v = sphere_uv(*p + Vec3::Z * 0.0).x; // phi/2pi of the point (theta irrelevant)
            assert!((uv.y - v).abs() < 1e-5 || (uv.y - 1.0).abs() < 1e-5 && v < 1e-5, "{p} {uv} {v}");
        }
    }
    // every point of the outline edges is within chord_error of the unit circle
    let max_gap = m
        .indices
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (m.positions[a as usize] + m.positions[b as usize]) * 0.5)
        .filter(|mid| mid.length() > 0.99)
        .map(|mid| 1.0 - mid.length())
        .fold(0.0f32, f32::max);
    assert!(max_gap <= chord_error() * 1.01 && chord_error() < 1e-4, "{max_gap} {}", chord_error());
    // 480 pixels across: under 0.02 pixel
    assert!(chord_error() * 240.0 < 0.02);
}

#[test]
fn cube_faces_uvs() {
    let m = cube();
    check_common(&m);
    assert_eq!(m.area(), 24.0);
    assert_eq!((m.positions.len(), m.indices.len()), (24, 12));
    // each face covers [0,1]^2 in uv: area in uv space 1 per face
    let uv_area: f32 = m
        .indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.uvs[i as usize]);
            0.5 * (b - a).perp_dot(c - a).abs()
        })
        .sum();
    assert!((uv_area - 6.0).abs() < 1e-6);
    // the normals are the faces' outward axes
    for (p, n) in m.positions.iter().zip(&m.normals) {
        assert_eq!(p.dot(*n), 1.0, "{p} {n}");
    }
}

#[test]
fn cylinder_frame_area_and_uvs() {
    let (r, p0, p1) = (0.5, Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.0, 2.0, 5.0));
    let m = cylinder(r, p0, p1).unwrap();
    check_common(&m);
    let n = SEGMENTS as f64;
    let lateral = 2.0 * n * (std::f64::consts::PI / n).sin() * 0.5 * 2.0; // polygon perimeter * h
    assert!((m.area() - lateral).abs() < 1e-3, "{} {lateral}", m.area());
    assert!((m.area() - std::f64::consts::TAU * 0.5 * 2.0).abs() / m.area() < 1e-4);
    for ((p, n), uv) in m.positions.iter().zip(&m.normals).zip(&m.uvs) {
        let radial = *p - Vec3::new(1.0, 2.0, p.z);
        assert!((radial.length() - r).abs() < 1e-5 && (radial.normalize() - *n).length() < 1e-4);
        assert!((uv.y - (p.z - 3.0) / 2.0).abs() < 1e-6, "v is t along the axis");
    }
    // Mitsuba's frame for +z: x axis +x, so u = 0 at p0 + r x
    assert!((m.positions[0] - (p0 + Vec3::X * r)).length() < 1e-6, "{}", m.positions[0]);
    // a slanted axis: ends and radius kept, unit normals perpendicular to the axis
    let (q0, q1) = (Vec3::new(0.0, -1.0, 0.5), Vec3::new(1.0, 1.0, -1.0));
    let m = cylinder(2.0, q0, q1).unwrap();
    let axis = (q1 - q0).normalize();
    for (p, n) in m.positions.iter().zip(&m.normals) {
        assert!(n.dot(axis).abs() < 1e-5);
        let t = (*p - q0).dot(axis);
        assert!(((*p - q0 - axis * t).length() - 2.0).abs() < 1e-4);
    }
    assert!(cylinder(1.0, Vec3::ONE, Vec3::ONE).is_none());
    assert!(cylinder(0.0, Vec3::ZERO, Vec3::ONE).is_none());
    assert!(cylinder(f32::NAN, Vec3::ZERO, Vec3::ONE).is_none());
}

#[test]
fn sphere_uv_is_mitsubas() {
    assert_eq!(sphere_uv(Vec3::Z), Vec2::new(0.0, 0.0));
    assert_eq!(sphere_uv(Vec3::new(0.0, 0.0, -3.0)).y, 1.0);
    let uv = sphere_uv(Vec3::Y);
    assert!((uv - Vec2::new(0.25, 0.5)).length() < 1e-6, "{uv}");
    let uv = sphere_uv(Vec3::NEG_Y * 2.0);
    assert!((uv - Vec2::new(0.75, 0.5)).length() < 1e-6, "{uv}");
}

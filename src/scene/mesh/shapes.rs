//! Mitsuba 3's simple shapes as triangle meshes in object space, with Mitsuba's parameterization,
//! normals and uvs (apply `to_world` with [`Mesh::transform`]):
//!
//! | shape | object space | uv | normal |
//! |---|---|---|---|
//! | [`rectangle`] | `[-1,1]^2` at z=0, 2 triangles (exact) | `((x+1)/2, (y+1)/2)` | +z |
//! | [`disk`] | unit disk at z=0 | `(r, phi/2pi)`, phi in [0, 2pi) from +x | +z |
//! | [`cube`] | `[-1,1]^3`, 12 triangles (exact) | each face onto `[0,1]^2` | per face, outward |
//! | [`cylinder`] | radius r around p0..p1, open ends | `(phi/2pi, t)`, t from p0 (0) to p1 (1) | radial, outward |
//!
//! Mitsuba intersects the disk and the cylinder analytically; here they are inscribed polygons of
//! [`SEGMENTS`] sides, whose edges come at most `1 - cos(pi / SEGMENTS)` = 7.5e-5 of the radius
//! inside the true outline ([`chord_error`]): 0.018 pixel for a disk 480 pixels across, so
//! silhouettes match to well under a pixel at 480x480. Vertex normals are the analytic ones and
//! uvs are exact at the vertices (linear in between: within the same 7.5e-5 for `r` and
//! `1/(2 SEGMENTS)` for the disk's angle inside its innermost ring, radius `1/RINGS`).
//! The analytic sphere (`SphereDesc`) gets its uv at hits from `scene::texturing::sphere_uv`.

use super::Mesh;
use glam::{Mat4, Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// Sides of the polygons standing for the disk's and the cylinder's circles.
pub const SEGMENTS: u32 = 256;
/// Rings of the disk's tessellation (its uv `r` is exact on them).
pub const RINGS: u32 = 8;

/// Largest distance, relative to the radius, between a circle and its inscribed [`SEGMENTS`]-gon.
pub fn chord_error() -> f32 {
    1.0 - (PI / SEGMENTS as f32).cos()
}

/// Mitsuba's `rectangle`: `[-1,1]^2` at z=0, normal +z, uv `((x+1)/2, (y+1)/2)`.
pub fn rectangle() -> Mesh {
    let positions: Vec<Vec3> =
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].iter().map(|&(x, y)| Vec3::new(x, y, 0.0)).collect();
    let uvs = positions.iter().map(|p| Vec2::new((p.x + 1.0) * 0.5, (p.y + 1.0) * 0.5)).collect();
    Mesh { normals: vec![Vec3::Z; 4], uvs, indices: vec![[0, 1, 2], [0, 2, 3]], positions, ..Mesh::default() }
}

/// Mitsuba's `disk`: the unit disk at z=0, normal +z, uv `(r, phi / 2pi)`.
pub fn disk() -> Mesh {
    let mut m = Mesh::default();
    let n = SEGMENTS;
    // One center vertex per sector, at the sector's middle angle (phi is undefined at r = 0).
    for s in 0..n {
        m.positions.push(Vec3::ZERO);
        m.uvs.push(Vec2::new(0.0, (s as f32 + 0.5) / n as f32));
    }
    // Rings 1..=RINGS, each with SEGMENTS + 1 vertices (the seam twice: phi/2pi = 0 and 1).
    let ring = |k: u32, s: u32| n + (k - 1) * (n + 1) + s;
    for k in 1..=RINGS {
        let r = k as f32 / RINGS as f32;
        for s in 0..=n {
            let v = s as f32 / n as f32;
            let (sin, cos) = (v * TAU).sin_cos();
            m.positions.push(Vec3::new(r * cos, r * sin, 0.0));
            m.uvs.push(Vec2::new(r, v));
        }
    }
    for s in 0..n {
        m.indices.push([s, ring(1, s), ring(1, s + 1)]);
        for k in 1..RINGS {
            let (a, b, c, d) = (ring(k, s), ring(k, s + 1), ring(k + 1, s), ring(k + 1, s + 1));
            m.indices.push([a, c, d]);
            m.indices.push([a, d, b]);
        }
    }
    m.normals = vec![Vec3::Z; m.positions.len()];
    m
}

/// Mitsuba's `cube`: `[-1,1]^3`, 24 vertices (4 per face), 12 triangles, outward face normals,
/// each face mapped onto `[0,1]^2` with the corners and uvs Mitsuba uses.
pub fn cube() -> Mesh {
    // Per face: its outward normal and its four corners in the order whose uvs are
    // (0,1), (1,1), (1,0), (0,0); triangles (0,1,2) and (3,0,2) of each face.
    const FACES: [([f32; 3], [[f32; 3]; 4]); 6] = [
        ([0.0, -1.0, 0.0], [[1.0, -1.0, -1.0], [1.0, -1.0, 1.0], [-1.0, -1.0, 1.0], [-1.0, -1.0, -1.0]]),
        ([0.0, 1.0, 0.0], [[1.0, 1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, 1.0, 1.0], [1.0, 1.0, 1.0]]),
        ([1.0, 0.0, 0.0], [[1.0, -1.0, -1.0], [1.0, 1.0, -1.0], [1.0, 1.0, 1.0], [1.0, -1.0, 1.0]]),
        ([0.0, 0.0, 1.0], [[1.0, -1.0, 1.0], [1.0, 1.0, 1.0], [-1.0, 1.0, 1.0], [-1.0, -1.0, 1.0]]),
        ([-1.0, 0.0, 0.0], [[-1.0, -1.0, 1.0], [-1.0, 1.0, 1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, -1.0]]),
        ([0.0, 0.0, -1.0], [[1.0, 1.0, -1.0], [1.0, -1.0, -1.0], [-1.0, -1.0, -1.0], [-1.0, 1.0, -1.0]]),
    ];
    let corner_uvs = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
    let mut m = Mesh::default();
    for (f, (normal, corners)) in FACES.iter().enumerate() {
        let b = 4 * f as u32;
        for (c, uv) in corners.iter().zip(corner_uvs) {
            m.positions.push(Vec3::from_array(*c));
            m.normals.push(Vec3::from_array(*normal));
            m.uvs.push(uv);
        }
        m.indices.push([b, b + 1, b + 2]);
        m.indices.push([b + 3, b, b + 2]);
    }
    m
}

/// Mitsuba's `cylinder` of `radius` from `p0` to `p1`, open at both ends: object space is the
/// unit cylinder along +z (z in [0, 1]) mapped by `T(p0) * Frame(p1 - p0) * S(r, r, |p1 - p0|)`,
/// the frame's x and y axes from the same orthonormal basis as Mitsuba's (Duff et al. 2017), so
/// that the uv seam (`u = phi / 2pi = 0`, phi from the frame's x axis) is where Mitsuba's is.
/// `None` when `p0 == p1` or a value is not finite, or `radius <= 0`.
pub fn cylinder(radius: f32, p0: Vec3, p1: Vec3) -> Option<Mesh> {
    let d = p1 - p0;
    let length = d.length();
    if !(radius > 0.0 && radius.is_finite() && length > 0.0 && length.is_finite() && p0.is_finite()) {
        return None;
    }
    let mut m = Mesh::default();
    let n = SEGMENTS;
    for s in 0..=n {
        let u = s as f32 / n as f32;
        let (sin, cos) = (u * TAU).sin_cos();
        for z in [0.0, 1.0] {
            m.positions.push(Vec3::new(cos, sin, z));
            m.normals.push(Vec3::new(cos, sin, 0.0));
            m.uvs.push(Vec2::new(u, z));
        }
    }
    for s in 0..n {
        let (a, b, c, d) = (2 * s, 2 * s + 1, 2 * s + 2, 2 * s + 3);
        m.indices.push([a, c, d]);
        m.indices.push([a, d, b]);
    }
    let axis = d / length;
    let (x, y) = axis.any_orthonormal_pair();
    let frame = Mat4::from_cols(x.extend(0.0), y.extend(0.0), axis.extend(0.0), p0.extend(1.0));
    m.transform(&(frame * Mat4::from_scale(Vec3::new(radius, radius, length))));
    Some(m)
}

#[cfg(test)]
#[path = "shapes_tests.rs"]
mod tests;

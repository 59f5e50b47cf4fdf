//! The automatic camera of a whole-scene OBJ: the up axis (`--up`, else guessed from the bounds),
//! what kind of view the model asks for, and a camera framing it.
//!
//! - **Up axis.** OBJ's convention is y up; many CAD and Blender exports are z up. Without `--up`,
//!   z is guessed when the bounds are flat in z (its extent under half of both others, like a
//!   building or a landscape lying in the xy plane), else y.
//! - **Interior.** Rays are cast from the centre of the bounds in [`PROBE_RAYS`] directions
//!   (brute force over the triangles: this runs once, before any BVH exists). When most of them
//!   hit something, most of the faces they hit face the centre (by their vertex normals where
//!   the file gives them, else by their winding), and at least two horizontal sides of the bounds
//!   are walls (faces cover over 30% of the bounding plane), the centre is inside a room whose walls
//!   are the model's extent: the model is an interior. (A house with rooms inside, standing on
//!   a larger ground, is not: its bounds are not its walls.)
//! - **Views.** An interior with one side open (a Cornell box: no wall on one horizontal side of the
//!   bounds, a wall opposite) is looked into through the opening, framed to fill the image. A closed
//!   interior (an atrium, a nave) is seen from inside, standing near one end of its longest
//!   horizontal axis, at a third of its height, looking along it. Anything else is seen from the
//!   front (+z for y up, -y for z up, +z for x up), 20 degrees above the horizon.
//!
//! In every view the bounding box's eight corners fit the image (of the aspect given) at the
//! chosen field of view, except inside a closed interior.

use crate::scene::desc::{CameraDesc, QuadLightDesc, SceneDesc};
use glam::Vec3;

/// Directions probed from the centre of the bounds for the interior test.
pub const PROBE_RAYS: usize = 64;

/// A coordinate axis, as `--up` names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum UpAxis {
    /// +x up
    X,
    /// +y up (OBJ's convention)
    Y,
    /// +z up (CAD, Blender's own)
    Z,
}

impl UpAxis {
    /// `x`, `y` or `z` (any case).
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "x" | "+x" => Some(UpAxis::X),
            "y" | "+y" => Some(UpAxis::Y),
            "z" | "+z" => Some(UpAxis::Z),
            _ => None,
        }
    }

    /// `x`, `y` or `z`.
    pub fn name(self) -> &'static str {
        ["x", "y", "z"][self.index()]
    }

    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            UpAxis::X => 0,
            UpAxis::Y => 1,
            UpAxis::Z => 2,
        }
    }

    /// The unit vector.
    pub fn vec(self) -> Vec3 {
        Vec3::AXES[self.index()]
    }

    /// The horizontal direction a default (front) view comes from: +z for y and x up, -y for z up.
    pub fn front(self) -> Vec3 {
        match self {
            UpAxis::Z => -Vec3::Y,
            _ => Vec3::Z,
        }
    }
}

/// The up axis guessed from bounds `lo..hi`: z when the box is flat in z (its extent under half
/// of both the x and the y extent), else y.
pub fn guess_up(lo: Vec3, hi: Vec3) -> UpAxis {
    let e = hi - lo;
    if e.z < 0.5 * e.x.min(e.y) {
        UpAxis::Z
    } else {
        UpAxis::Y
    }
}

/// What kind of view the model asks for (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// an object: seen from the front, slightly above
    Exterior,
    /// an interior open on one side: looked into through the opening
    Opening,
    /// a closed interior: seen from inside
    Interior,
}

impl View {
    /// `exterior`, `opening`, `interior`.
    pub fn name(self) -> &'static str {
        match self {
            View::Exterior => "exterior view",
            View::Opening => "looking in through the open side",
            View::Interior => "interior: camera inside",
        }
    }
}

/// The automatic camera of a scene and how it was chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Framing {
    /// the camera
    pub camera: CameraDesc,
    /// the up axis used
    pub up: UpAxis,
    /// `up` was guessed (no `--up`)
    pub up_guessed: bool,
    /// the kind of view
    pub view: View,
    /// share of the probe rays that hit a face
    pub hit_share: f32,
    /// share of the faces hit that face the centre
    pub inward_share: f32,
    /// for a closed interior, the light to add if the scene has none (see [`View`]): a square
    /// under the ceiling, facing down (the default light behind the camera would be outside)
    pub interior_light: Option<QuadLightDesc>,
}

impl Framing {
    /// The camera as a `--camera "..."` argument (each number the shortest decimal that parses
    /// back to it, so the pasted camera renders the same image).
    pub fn camera_arg(&self) -> String {
        camera_arg(&self.camera)
    }
}

/// `--camera "ex ey ez cx cy cz ux uy uz fovy"` for `c`.
pub fn camera_arg(c: &CameraDesc) -> String {
    let n =
        [c.eye, c.center, c.up].iter().flat_map(|v| v.to_array()).chain([c.fovy_deg]).map(short).collect::<Vec<_>>();
    format!("--camera \"{}\"", n.join(" "))
}

/// `x` as the shortest decimal that parses back to it (`-0` as `0`).
fn short(x: f32) -> String {
    if x == 0.0 || !x.is_finite() {
        "0".into()
    } else {
        format!("{x}")
    }
}

/// The automatic camera of `desc`'s triangles (emissive ones included) for an image of aspect
/// `aspect` (width / height), with `up` or the guessed axis; None without triangles.
pub fn frame_scene(desc: &SceneDesc, up: Option<UpAxis>, aspect: f32) -> Option<Framing> {
    let tris: Vec<[Vec3; 3]> =
        desc.triangles.iter().map(|t| t.v).chain(desc.emissive_triangles.iter().map(|t| t.v)).collect();
    let (lo, hi) = super::bounds(tris.iter().flatten().copied())?;
    let normals = |i: usize| desc.triangle_normals.get(i).filter(|n| n.iter().all(|v| *v != Vec3::ZERO));
    let facing = |i: usize| -> Vec3 {
        match normals(i) {
            Some(n) => n[0] + n[1] + n[2],
            None => (tris[i][1] - tris[i][0]).cross(tris[i][2] - tris[i][0]),
        }
    };
    let center = 0.5 * (lo + hi);
    let (hit_share, inward_share) = probe(&tris, center, facing);
    let up_guessed = up.is_none();
    let up = up.unwrap_or_else(|| guess_up(lo, hi));
    let cover = wall_cover(&tris, lo, hi);
    let interior = hit_share >= 0.6 && inward_share >= 0.5 && walls(&cover, up) >= 2;
    let aspect = if aspect.is_finite() && aspect > 0.0 { aspect } else { 4.0 / 3.0 };
    let (camera, view) = match (interior, interior.then(|| open_side(&cover, up)).flatten()) {
        (true, Some(dir)) => (fit(lo, hi, dir, up.vec(), 45.0, aspect, 1.0), View::Opening),
        (true, None) => (inside(lo, hi, up), View::Interior),
        (false, _) => {
            let el = 20f32.to_radians();
            let dir = up.front() * el.cos() + up.vec() * el.sin();
            (fit(lo, hi, dir, up.vec(), 45.0, aspect, 1.05), View::Exterior)
        }
    };
    let interior_light = (view == View::Interior).then(|| ceiling_light(&tris, lo, hi, up));
    Some(Framing { camera, up, up_guessed, view, hit_share, inward_share, interior_light })
}

/// Share of [`PROBE_RAYS`] rays from `center` that hit a triangle, and share of those whose hit
/// face (normal `facing(i)`) faces `center`.
fn probe(tris: &[[Vec3; 3]], center: Vec3, facing: impl Fn(usize) -> Vec3) -> (f32, f32) {
    // Fibonacci sphere: nearly uniform directions.
    let dirs: Vec<Vec3> = (0..PROBE_RAYS)
        .map(|k| {
            let z = 1.0 - (2.0 * k as f32 + 1.0) / PROBE_RAYS as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = k as f32 * 2.399_963;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect();
    let hits: Vec<(Vec3, usize)> =
        dirs.iter().zip(cast(tris, center, &dirs)).filter_map(|(d, hit)| hit.map(|(_, i)| (*d, i))).collect();
    let inward = hits.iter().filter(|(d, i)| facing(*i).dot(*d) < 0.0).count();
    let hit_share = hits.len() as f32 / PROBE_RAYS as f32;
    (hit_share, if hits.is_empty() { 0.0 } else { inward as f32 / hits.len() as f32 })
}

/// Nearest hit (distance, triangle) of the rays from `origin` along each of `dirs`, by brute
/// force (Moller-Trumbore, triangles in the outer loop).
fn cast(tris: &[[Vec3; 3]], origin: Vec3, dirs: &[Vec3]) -> Vec<Option<(f32, usize)>> {
    let mut nearest = vec![(f32::INFINITY, usize::MAX); dirs.len()];
    for (i, t) in tris.iter().enumerate() {
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let s = origin - t[0];
        let q = s.cross(e1);
        for (d, best) in dirs.iter().zip(nearest.iter_mut()) {
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-20 {
                continue;
            }
            let inv = 1.0 / det;
            let u = s.dot(p) * inv;
            let v = d.dot(q) * inv;
            let dist = e2.dot(q) * inv;
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 0.0 && dist < best.0 {
                *best = (dist, i);
            }
        }
    }
    nearest.into_iter().map(|(t, i)| (i != usize::MAX).then_some((t, i))).collect()
}

/// The default light of a closed interior: a square facing down under the ceiling above the
/// centre (85% of the way from the centre to the first face hit straight up, or to the top of the
/// bounds), a fifth of the smaller horizontal extent per side, with the radiance that gives the
/// floor below an irradiance of about pi.
fn ceiling_light(tris: &[[Vec3; 3]], lo: Vec3, hi: Vec3, up: UpAxis) -> QuadLightDesc {
    let (u, center, ext) = (up.index(), 0.5 * (lo + hi), hi - lo);
    let upv = up.vec();
    let hits = cast(tris, center, &[upv, -upv]);
    let t_up = hits[0].map_or(hi[u] - center[u], |h| h.0);
    let t_down = hits[1].map_or(center[u] - lo[u], |h| h.0);
    let (k1, k2) = ((u + 1) % 3, (u + 2) % 3);
    let side = (0.2 * ext[k1].min(ext[k2])).max(1e-3);
    let (mut ab, mut ac) = (Vec3::AXES[k1] * side, Vec3::AXES[k2] * side);
    // A quad light emits towards normalize(ac x ab): down.
    if ac.cross(ab).dot(upv) > 0.0 {
        std::mem::swap(&mut ab, &mut ac);
    }
    let p = center + upv * (0.85 * t_up);
    let d = 0.85 * t_up + t_down;
    let radiance = Vec3::splat(std::f32::consts::PI * d * d / (side * side));
    QuadLightDesc { a: p - 0.5 * (ab + ac), ab, ac, radiance }
}

/// How much of each bounding plane of `lo..hi` faces lying in it cover: per axis, `[lo, hi]`, the
/// area of the faces parallel to the plane (normal within 26 degrees of the axis) and within 2% of
/// the extent from it, over the plane's area.
fn wall_cover(tris: &[[Vec3; 3]], lo: Vec3, hi: Vec3) -> [[f32; 2]; 3] {
    let ext = (hi - lo).max(Vec3::splat(1e-6));
    let mut cover = [[0f32; 2]; 3];
    for t in tris {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        let area = 0.5 * n.length();
        if area == 0.0 {
            continue;
        }
        let c = (t[0] + t[1] + t[2]) / 3.0;
        for k in 0..3 {
            if n[k].abs() < 0.9 * 2.0 * area {
                continue;
            }
            if c[k] <= lo[k] + 0.02 * ext[k] {
                cover[k][0] += area;
            }
            if c[k] >= hi[k] - 0.02 * ext[k] {
                cover[k][1] += area;
            }
        }
    }
    std::array::from_fn(|k| cover[k].map(|a| a / (ext[(k + 1) % 3] * ext[(k + 2) % 3])))
}

/// The horizontal sides (axis, 0: low / 1: high) of `up`.
fn horizontal_sides(up: UpAxis) -> impl Iterator<Item = (usize, usize)> {
    (0..3).filter(move |&k| k != up.index()).flat_map(|k| [(k, 0), (k, 1)])
}

/// Horizontal sides that are walls: over 30% of their bounding plane covered.
fn walls(cover: &[[f32; 2]; 3], up: UpAxis) -> usize {
    horizontal_sides(up).filter(|&(k, s)| cover[k][s] > 0.3).count()
}

/// The open side of a box-like interior, as the direction from the centre through it: the one
/// horizontal side whose plane is barely covered (under 25%) when the three others, the floor and
/// the ceiling are walls (over 50% covered), as in a Cornell box. None otherwise.
fn open_side(cover: &[[f32; 2]; 3], up: UpAxis) -> Option<Vec3> {
    let u = up.index();
    let closed = |(k, s): (usize, usize)| cover[k][s] > 0.5;
    let open: Vec<(usize, usize)> = horizontal_sides(up).filter(|&(k, s)| cover[k][s] < 0.25).collect();
    let walled = horizontal_sides(up).filter(|&side| closed(side)).count();
    match open.as_slice() {
        [(k, s)] if walled == 3 && closed((u, 0)) && closed((u, 1)) => {
            Some(if *s == 0 { -Vec3::AXES[*k] } else { Vec3::AXES[*k] })
        }
        _ => None,
    }
}

/// Camera inside a closed interior: near the low end of the longest horizontal axis (5% in), at a
/// third of the height, looking level along the axis, 60 degrees of field of view.
fn inside(lo: Vec3, hi: Vec3, up: UpAxis) -> CameraDesc {
    let (ext, center) = (hi - lo, 0.5 * (lo + hi));
    let k = (0..3).filter(|&k| k != up.index()).max_by(|&a, &b| ext[a].total_cmp(&ext[b])).unwrap_or(0);
    let (along, u) = (Vec3::AXES[k], up.index());
    let mut eye = center - along * (0.3 * ext[k]);
    eye[u] = lo[u] + ext[u] / 3.0;
    let mut target = center + along * (0.5 * ext[k]);
    target[u] = eye[u];
    CameraDesc { eye, center: target, up: up.vec(), fovy_deg: 60.0 }
}

/// Camera looking at the centre of `lo..hi` from direction `dir` (unit, from the centre to the
/// eye), far enough that the box's 8 corners fit the image (vertical field `fovy_deg`, aspect
/// `aspect`), times `margin`.
fn fit(lo: Vec3, hi: Vec3, dir: Vec3, up: Vec3, fovy_deg: f32, aspect: f32, margin: f32) -> CameraDesc {
    let center = 0.5 * (lo + hi);
    let right = up.cross(dir).normalize_or(Vec3::X);
    let cam_up = dir.cross(right);
    let tan_y = (0.5 * fovy_deg.to_radians()).tan();
    let tan_x = tan_y * aspect;
    let mut dist = 1e-3f32;
    for i in 0..8 {
        let p = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        ) - center;
        let depth = p.dot(dir);
        dist = dist.max(depth + p.dot(right).abs() / tan_x).max(depth + p.dot(cam_up).abs() / tan_y);
    }
    let dist = dist * margin;
    CameraDesc { eye: center + dir * dist, center, up, fovy_deg }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::desc::TriangleDesc;

    fn quad(desc: &mut SceneDesc, a: Vec3, b: Vec3, c: Vec3, d: Vec3) {
        desc.triangles.push(TriangleDesc { v: [a, b, c], material: 0 });
        desc.triangles.push(TriangleDesc { v: [a, c, d], material: 0 });
    }

    /// A unit box's faces, wound to face inward (`inward`) or outward, without the side at +z
    /// when `open`.
    fn cube(inward: bool, open: bool) -> SceneDesc {
        let mut d = SceneDesc::default();
        let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let mut faces = vec![
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
            [c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.)],
            [c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)],
            [c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
            [c(0., 0., 0.), c(0., 1., 0.), c(1., 1., 0.), c(1., 0., 0.)],
            [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
        ];
        if open {
            faces.pop();
        }
        for mut f in faces {
            let n = (f[1] - f[0]).cross(f[2] - f[0]);
            let to_center = Vec3::splat(0.5) - f[0];
            if (n.dot(to_center) > 0.0) != inward {
                f.reverse();
            }
            quad(&mut d, f[0], f[1], f[2], f[3]);
        }
        d
    }

    #[test]
    fn a_closed_box_wound_outward_is_an_object_and_inward_a_room() {
        let f = frame_scene(&cube(false, false), None, 4.0 / 3.0).unwrap();
        assert_eq!((f.view, f.hit_share, f.inward_share), (View::Exterior, 1.0, 0.0));
        let f = frame_scene(&cube(true, false), None, 4.0 / 3.0).unwrap();
        assert_eq!((f.view, f.inward_share), (View::Interior, 1.0));
        // Inside, looking level along a horizontal axis.
        assert!(f.camera.eye.cmpgt(Vec3::ZERO).all() && f.camera.eye.cmplt(Vec3::ONE).all(), "{:?}", f.camera);
        assert_eq!(f.camera.eye.y, f.camera.center.y);
    }

    #[test]
    fn an_open_box_is_looked_into_through_its_opening_and_fills_the_frame() {
        let f = frame_scene(&cube(true, true), Some(UpAxis::Y), 1.0).unwrap();
        assert_eq!(f.view, View::Opening);
        // Looking along -z from +z; the front face's edges exactly span the 45-degree field.
        assert!((f.camera.eye - Vec3::new(0.5, 0.5, 1.0 + 0.5 / 22.5f32.to_radians().tan())).length() < 1e-4);
    }

    #[test]
    fn up_is_guessed_from_flat_bounds_and_the_camera_arg_parses_back() {
        assert_eq!(guess_up(Vec3::ZERO, Vec3::new(10.0, 8.0, 3.0)), UpAxis::Z);
        assert_eq!(guess_up(Vec3::ZERO, Vec3::new(35.0, 16.0, 15.0)), UpAxis::Y);
        let f = frame_scene(&cube(false, false), Some(UpAxis::Z), 1.5).unwrap();
        assert_eq!((f.up, f.up_guessed, f.camera.up), (UpAxis::Z, false, Vec3::Z));
        assert!(f.camera.eye.y < 0.0 && f.camera.eye.z > 0.5, "{:?}", f.camera);
        let arg = f.camera_arg();
        let inner = arg.trim_start_matches("--camera \"").trim_end_matches('"');
        let back = crate::session::parse_camera(inner).unwrap();
        assert!((back.eye - f.camera.eye).length() < 1e-4 && back.fovy_deg == f.camera.fovy_deg, "{arg}");
    }
}

//! OBJ vertex normals as shading normals: a flat quad with tilted normals shades by the cosine of
//! the interpolated normal (exact, `raytracer` with a directional light), an icosphere with its
//! exact sphere normals renders much closer to the analytic sphere than faceted, and normals that
//! point into the surface or graze it give no NaN, negative or broken pixels.

use crate::common;

use common::*;
use glam::{DVec3, Vec3};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use strata::scene::build::Camera;
use strata::scene::desc::CameraDesc;

const W: u32 = 40;
const H: u32 = 40;
const KD: f64 = 0.8;

/// A `.test` wrapper around `obj` under a directional light `l` (unit, towards the light), camera at
/// (0, 0, 3) looking down -z, with `settings` lines.
fn wrapper(dir: &Path, name: &str, obj: &str, l: DVec3, settings: &str) -> PathBuf {
    let text = format!(
        "size {W} {H}\ncamera 0 0 3 0 0 0 0 1 0 45\n{settings}\nambient 0 0 0\nspecular 0 0 0\n\
         diffuse {KD} {KD} {KD}\ndirectional {} {} {} 1 1 1\nobj {obj}\n",
        l.x, l.y, l.z
    );
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The world point seen through pixel (x, y)'s centre on the plane z = `z0` (the camera of `wrapper`).
fn pixel_ray(x: u32, y: u32) -> (DVec3, DVec3) {
    let desc = CameraDesc { eye: Vec3::new(0.0, 0.0, 3.0), center: Vec3::ZERO, up: Vec3::Y, fovy_deg: 45.0 };
    let cam = Camera::new(&desc, W, H);
    (DVec3::new(0.0, 0.0, 3.0), cam.dir(x as f32 + 0.5, y as f32 + 0.5).as_dvec3())
}

/// A unit-square-ish quad z = 0, x, y in [-1, 1], whose corner normals tilt by `s` along x
/// (n = normalize(-s, 0, 1) at x = -1, normalize(s, 0, 1) at x = 1), or none.
fn tilted_quad(s: Option<f64>) -> String {
    let mut t = String::from("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n");
    match s {
        Some(s) => {
            let _ = write!(t, "vn {} 0 1\nvn {s} 0 1\nf 1//1 2//2 3//2\nf 1//1 3//2 4//1\n", -s);
        }
        None => t.push_str("f 1 2 3\nf 1 3 4\n"),
    }
    t
}

fn render(p: PathBuf, spp: u32, seed: u64) -> Vec<[f64; 3]> {
    means(&film(&strata::session::RenderOptions { seed, ..opts(p, W, H, spp) }))
}

#[test]
fn tilted_vertex_normals_shade_by_the_interpolated_cosine() {
    let d = tmpdir("normals-quad");
    let s = 0.6;
    std::fs::write(d.join("smooth.obj"), tilted_quad(Some(s))).unwrap();
    std::fs::write(d.join("flat.obj"), tilted_quad(None)).unwrap();
    let l = DVec3::new(0.5, 0.0, 1.0).normalize();
    let smooth = render(wrapper(&d, "smooth.test", "smooth.obj", l, ""), 1, 1);
    let flat = render(wrapper(&d, "flat.test", "flat.obj", l, ""), 1, 1);
    let (n0, n1) = (DVec3::new(-s, 0.0, 1.0).normalize(), DVec3::new(s, 0.0, 1.0).normalize());
    let (mut checked, mut brighter, mut darker) = (0, 0, 0);
    for y in 0..H {
        for x in 0..W {
            let (o, dir) = pixel_ray(x, y);
            let p = o + dir * (-o.z / dir.z);
            if p.x.abs() > 0.98 || p.y.abs() > 0.98 {
                continue; // near the edges, the pixel may straddle the quad's border
            }
            let i = (y * W + x) as usize;
            let n = (n0 + (n1 - n0) * ((p.x + 1.0) * 0.5)).normalize();
            let expect = KD * n.dot(l).max(0.0);
            assert!(
                (smooth[i][0] - expect).abs() < 2e-3,
                "pixel ({x}, {y}) x = {:.3}: {} vs {expect}",
                p.x,
                smooth[i][0]
            );
            assert!((flat[i][0] - KD * l.z).abs() < 1e-5, "faceted pixel ({x}, {y}): {}", flat[i][0]);
            checked += 1;
            brighter += usize::from(p.x > 0.1 && smooth[i][0] > flat[i][0] + 0.01);
            darker += usize::from(p.x < -0.1 && smooth[i][0] < flat[i][0] - 0.01);
        }
    }
    assert!(checked > 600, "{checked} pixels on the quad");
    // Normals tilted towards the light (x > 0) are brighter than faceted, away from it darker.
    assert!(brighter > 200 && darker > 200, "brighter {brighter}, darker {darker} of {checked}");
}

/// An icosphere of radius 1 (icosahedron subdivided `levels` times), as OBJ text, with exact
/// sphere normals (`vn` = the unit position) or without.
fn icosphere(levels: u32, normals: bool) -> String {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::new();
        for [a, b, c] in f {
            let mut m = |i: usize, j: usize| {
                *mid.entry((i.min(j), i.max(j))).or_insert_with(|| {
                    v.push(((v[i] + v[j]) * 0.5).normalize());
                    v.len() - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    let mut s = String::new();
    for p in &v {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
        if normals {
            let _ = writeln!(s, "vn {} {} {}", p.x, p.y, p.z);
        }
    }
    for [a, b, c] in f {
        let (a, b, c) = (a + 1, b + 1, c + 1);
        let _ = if normals { writeln!(s, "f {a}//{a} {b}//{b} {c}//{c}") } else { writeln!(s, "f {a} {b} {c}") };
    }
    s
}

#[test]
fn icosphere_with_normals_is_closer_to_the_analytic_sphere() {
    let d = tmpdir("normals-ico");
    std::fs::write(d.join("smooth.obj"), icosphere(3, true)).unwrap();
    std::fs::write(d.join("flat.obj"), icosphere(3, false)).unwrap();
    // Light from the front-right-top: the lit side faces the camera, the terminator is off-centre.
    let l = DVec3::new(0.4, 0.3, 1.0).normalize();
    let smooth = render(wrapper(&d, "smooth.test", "smooth.obj", l, ""), 1, 1);
    let flat = render(wrapper(&d, "flat.test", "flat.obj", l, ""), 1, 1);
    let (mut err_s, mut err_f, mut n) = (0.0, 0.0, 0);
    for y in 0..H {
        for x in 0..W {
            let (o, dir) = pixel_ray(x, y);
            // The analytic unit sphere; pixels near its rim (where the mesh's silhouette differs) skipped.
            let b = o.dot(dir);
            let disc = b * b - (o.length_squared() - 1.0);
            if disc < 0.0 {
                continue;
            }
            let p = o + dir * (-b - disc.sqrt());
            if p.z < 0.6 {
                continue;
            }
            let i = (y * W + x) as usize;
            let expect = KD * p.normalize().dot(l).max(0.0);
            err_s += (smooth[i][0] - expect).powi(2);
            err_f += (flat[i][0] - expect).powi(2);
            n += 1;
            assert!(smooth[i][0].is_finite() && smooth[i][0] >= 0.0);
        }
    }
    let (rms_s, rms_f) = ((err_s / n as f64).sqrt(), (err_f / n as f64).sqrt());
    eprintln!("icosphere vs analytic sphere over {n} pixels: rms {rms_s:.4} with normals, {rms_f:.4} faceted");
    assert!(n > 250, "{n} pixels");
    assert!(rms_s < 0.25 * rms_f, "with normals rms {rms_s}, faceted {rms_f}");
    assert!(rms_s < 0.005, "with normals rms {rms_s}");
}

/// Normals pointing into the surface are read up to sign (the image is the faceted one); normals
/// grazing the surface in every direction fall back to the geometric normal where the ray arrives
/// from below them: no NaN, no negative value, for every integrator.
#[test]
fn inward_and_grazing_normals_give_no_artifacts() {
    let d = tmpdir("normals-guard");
    let quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n";
    std::fs::write(d.join("flat.obj"), format!("{quad}f 1 2 3\nf 1 3 4\n")).unwrap();
    std::fs::write(d.join("inward.obj"), format!("{quad}vn 0 0 -1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n")).unwrap();
    let grazing =
        format!("{quad}vn -1 -1 0.05\nvn 1 -1 0.05\nvn 1 1 -0.05\nvn -1 1 0.05\nf 1//1 2//2 3//3\nf 1//1 3//3 4//4\n");
    std::fs::write(d.join("grazing.obj"), grazing).unwrap();
    let l = DVec3::new(0.3, -0.2, 1.0).normalize();
    let light = "quadLight 1.2 -0.5 1.5 1 0 0 0 1 0 5 5 5";
    let integrators = [
        ("", 1),
        (&*format!("integrator direct\n{light}"), 16),
        (&*format!("integrator pathtracer\nnexteventestimation mis\nimportancesampling brdf\n{light}"), 16),
        (&*format!("integrator analyticdirect\n{light}"), 1),
    ];
    for (k, (settings, spp)) in integrators.iter().enumerate() {
        let img =
            |obj: &str| render(wrapper(&d, &format!("{obj}{k}.test"), &format!("{obj}.obj"), l, settings), *spp, 5);
        let (flat, inward, grazing) = (img("flat"), img("inward"), img("grazing"));
        for (i, ((f, a), g)) in flat.iter().zip(&inward).zip(&grazing).enumerate() {
            for c in 0..3 {
                assert!((f[c] - a[c]).abs() <= 1e-4 * f[c].max(1.0), "{settings:?} pixel {i}: {f:?} vs {a:?}");
                assert!(g[c].is_finite() && g[c] >= 0.0, "{settings:?} pixel {i}: {g:?}");
            }
        }
        let lit = |img: &[[f64; 3]]| img.iter().filter(|p| p[0] > 1e-3).count();
        assert!(lit(&flat) > 500, "{settings:?}: {} lit pixels", lit(&flat));
        assert!(lit(&grazing) > 0, "{settings:?}: grazing normals black out the quad");
    }
}

/// Normals go to world space by the inverse transpose of the `.test` transform (a non-uniform
/// scale tilts them the other way from the surface); the table is padded for earlier triangles
/// and absent for meshes without `vn`.
#[test]
fn normals_follow_the_inverse_transpose_of_the_transform() {
    use strata::scene::parse::{parse_file, Limits};
    let d = tmpdir("normals-xform");
    std::fs::write(d.join("n.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 1 0\nf 1//1 2//1 3//1\n").unwrap();
    std::fs::write(d.join("flat.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let scene = |body: &str| {
        let p = d.join("s.test");
        std::fs::write(&p, format!("camera 0 0 3 0 0 0 0 1 0 45\n{body}")).unwrap();
        parse_file(&p, &Limits::default()).unwrap()
    };
    let flat = scene("obj flat.obj\n");
    assert!(flat.triangle_normals.is_empty(), "no table without vn");
    let s = scene("vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\ntri 0 1 2\nscale 2 1 1\nobj n.obj\nobj flat.obj\n");
    assert_eq!(s.triangles.len(), 3);
    assert_eq!(s.triangle_normals.len(), 2, "padded for the tri before, none for the flat mesh after");
    assert_eq!(s.triangle_normals[0], [Vec3::ZERO; 3]);
    // Under scale (2, 1, 1), the normal (1, 1, 0) becomes (1/2, 1, 0), normalised.
    let expect = Vec3::new(0.5, 1.0, 0.0).normalize();
    for n in s.triangle_normals[1] {
        assert!((n - expect).length() < 1e-6, "{n} vs {expect}");
    }
}

//! The hw1 `raytracer` (Whitted) integrator: every hw1 scene renders finite and quickly, and a
//! small scene written here matches an independent f64 evaluation of the format's formula
//! (Blinn-Phong from a point and a directional light with shadow rays, ambient, emission, ks-weighted
//! mirror recursion) pixel by pixel, including shadowed pixels and multi-bounce mirror pixels.

use crate::common;

use common::*;
use glam::DVec3;
use std::path::PathBuf;
use std::time::Instant;
use strata::sampler::SamplerKind;
use strata::session::RenderOptions;

#[test]
fn every_hw1_scene_renders_finite_and_fast() {
    let c = corpus_required();
    let dir = c.join("hw1");
    let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "test"))
        .collect();
    names.sort();
    assert!(names.len() >= 10, "expected the 10 hw1 scenes, found {}", names.len());
    let start = Instant::now();
    for p in &names {
        let o = opts(p.clone(), 64, 48, 1);
        let out = strata::session::render_to_film(&o).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        assert_eq!(out.stats.counters.nonfinite, 0, "{}: non-finite samples", p.display());
        let img = means(&out.film);
        assert!(img.iter().all(|v| v.iter().all(|c| c.is_finite() && *c >= 0.0)), "{}", p.display());
        let lit = img.iter().filter(|v| v.iter().any(|c| *c > 1e-4)).count();
        assert!(lit >= 64, "{}: only {lit} non-black pixels", p.display());
        let first = img[0];
        assert!(img.iter().any(|v| *v != first), "{}: constant image", p.display());
        let d = &out.scene.desc;
        let reflective = d.materials.iter().any(|m| m.diffuse.max_element() > 0.0 || m.specular.max_element() > 0.0);
        if reflective && (!d.point_lights.is_empty() || !d.directional_lights.is_empty()) {
            assert!(out.stats.counters.shadow > 0, "{}: no shadow rays", p.display());
        }
    }
    let secs = start.elapsed().as_secs_f64();
    eprintln!("hw1 at 64x48: {secs:.2} s");
    assert!(secs < 20.0, "hw1 at 64x48 took {secs:.1} s");
}

/// A material of the test scene.
#[derive(Clone, Copy)]
struct Mat {
    kd: DVec3,
    ks: DVec3,
    s: f64,
    ambient: DVec3,
    emission: DVec3,
}

const EYE: DVec3 = DVec3::new(-3.0, -3.0, 5.0);
const POINT: DVec3 = DVec3::new(1.0, 1.0, 2.0);
const POINT_COLOUR: DVec3 = DVec3::new(1.0, 0.5, 0.25);
const ATT: DVec3 = DVec3::new(0.5, 0.2, 0.1);
const DIR_COLOUR: DVec3 = DVec3::new(0.2, 0.3, 0.4);
const MAXDEPTH: u32 = 3;

fn materials() -> [Mat; 2] {
    [
        // the ground plane: diffuse and a mirror lobe
        Mat {
            kd: DVec3::new(0.5, 0.4, 0.3),
            ks: DVec3::new(0.2, 0.3, 0.1),
            s: 15.0,
            ambient: DVec3::new(0.05, 0.1, 0.02),
            emission: DVec3::new(0.01, 0.0, 0.03),
        },
        // the occluder square: emissive, also a mirror
        Mat {
            kd: DVec3::new(0.1, 0.6, 0.2),
            ks: DVec3::new(0.25, 0.25, 0.25),
            s: 7.0,
            ambient: DVec3::new(0.1, 0.1, 0.1),
            emission: DVec3::new(0.3, 0.2, 0.1),
        },
    ]
}

fn scene_text() -> String {
    let [a, b] = materials();
    let m = |m: Mat| {
        format!(
            "diffuse {} {} {}\nspecular {} {} {}\nshininess {}\nambient {} {} {}\nemission {} {} {}\n",
            m.kd.x,
            m.kd.y,
            m.kd.z,
            m.ks.x,
            m.ks.y,
            m.ks.z,
            m.s,
            m.ambient.x,
            m.ambient.y,
            m.ambient.z,
            m.emission.x,
            m.emission.y,
            m.emission.z
        )
    };
    format!(
        "size 64 48\nintegrator raytracer\nmaxdepth {MAXDEPTH}\ncamera {} {} {} 0 0 0 0 1 0 60\n\
         attenuation {} {} {}\npoint {} {} {} {} {} {}\ndirectional 0.3 -0.2 1 {} {} {}\n\
         {}vertex -10 -10 0\nvertex 10 -10 0\nvertex 10 10 0\nvertex -10 10 0\ntri 0 1 2\ntri 0 2 3\n\
         {}vertex 0.2 0.2 1\nvertex 0.8 0.2 1\nvertex 0.8 0.8 1\nvertex 0.2 0.8 1\ntri 4 5 6\ntri 4 6 7\n",
        EYE.x,
        EYE.y,
        EYE.z,
        ATT.x,
        ATT.y,
        ATT.z,
        POINT.x,
        POINT.y,
        POINT.z,
        POINT_COLOUR.x,
        POINT_COLOUR.y,
        POINT_COLOUR.z,
        DIR_COLOUR.x,
        DIR_COLOUR.y,
        DIR_COLOUR.z,
        m(a),
        m(b)
    )
}

/// Triangles (vertices, material) of the test scene.
fn triangles() -> Vec<([DVec3; 3], usize)> {
    let q = |z: f64, lo: f64, hi: f64| {
        let v = [DVec3::new(lo, lo, z), DVec3::new(hi, lo, z), DVec3::new(hi, hi, z), DVec3::new(lo, hi, z)];
        [[v[0], v[1], v[2]], [v[0], v[2], v[3]]]
    };
    let mut t: Vec<_> = q(0.0, -10.0, 10.0).into_iter().map(|v| (v, 0)).collect();
    t.extend(q(1.0, 0.2, 0.8).into_iter().map(|v| (v, 1)));
    t
}

fn closest(tris: &[([DVec3; 3], usize)], o: DVec3, d: DVec3) -> Option<(f64, usize)> {
    let mut best: Option<(f64, usize)> = None;
    for (i, (v, _)) in tris.iter().enumerate() {
        if let Some(t) = hit_triangle(o, d, *v) {
            if best.is_none_or(|(b, _)| t < b) {
                best = Some((t, i));
            }
        }
    }
    best
}

/// What the f64 reference saw along a camera ray (to make sure every case is exercised).
#[derive(Default)]
struct Seen {
    camera_hit: Option<usize>,
    point_shadowed: bool,
    mirror_hits: u32,
}

/// Whitted radiance along o + t d in f64, written from FORMAT.md.
fn reference(tris: &[([DVec3; 3], usize)], o: DVec3, d: DVec3, depth: u32, seen: &mut Seen) -> DVec3 {
    let mats = materials();
    let Some((t, i)) = closest(tris, o, d) else { return DVec3::ZERO };
    let (v, mi) = tris[i];
    let m = mats[mi];
    if depth == 0 {
        seen.camera_hit = Some(mi);
    } else {
        seen.mirror_hits += 1;
    }
    let p = o + d * t;
    let mut n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
    if n.dot(d) > 0.0 {
        n = -n;
    }
    let wo = -d;
    let po = p + n * 1e-7;
    let mut l = m.emission + m.ambient;
    let bp = |wi: DVec3| {
        let h = (wi + wo).normalize();
        m.kd * n.dot(wi).max(0.0) + m.ks * n.dot(h).max(0.0).powf(m.s)
    };
    // point light
    let to = POINT - p;
    let dist = to.length();
    let wi = to / dist;
    let blocked = closest(tris, po, wi).is_some_and(|(t, _)| t < dist - 1e-6);
    if depth == 0 {
        seen.point_shadowed = blocked;
    }
    if !blocked {
        l += bp(wi) * POINT_COLOUR / (ATT.x + ATT.y * dist + ATT.z * dist * dist);
    }
    // directional light
    let wi = DVec3::new(0.3, -0.2, 1.0).normalize();
    if closest(tris, po, wi).is_none() {
        l += bp(wi) * DIR_COLOUR;
    }
    if depth < MAXDEPTH && m.ks.max_element() > 0.0 {
        let r = n * (2.0 * n.dot(wo)) - wo;
        l += m.ks * reference(tris, po, r, depth + 1, seen);
    }
    l
}

#[test]
fn hand_built_scene_matches_f64_reference() {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("whitted_plane.test");
    std::fs::write(&path, scene_text()).unwrap();
    let (w, h) = (64u32, 48u32);
    let o = RenderOptions {
        scene: Some(path),
        spp: Some(1),
        pixel_sampler: Some(SamplerKind::GRID_CENTER),
        threads: 2,
        ..Default::default()
    };
    let out = strata::session::render_to_film(&o).unwrap();
    assert_eq!(out.stats.counters.nonfinite, 0);
    let img = means(&out.film);
    let tris = triangles();
    let look = (DVec3::ZERO - EYE).normalize();
    let right = look.cross(DVec3::Y).normalize();
    let up = right.cross(look);
    let a = (60f64.to_radians() / 2.0).tan();
    let (mut total, mut ok) = (0, 0);
    let (mut lit_plane, mut shadowed_plane, mut occluder, mut mirror, mut multi) = (0, 0, 0, 0, 0);
    let mut worst = (0.0f64, 0u32, 0u32);
    for py in 0..h {
        for px in 0..w {
            let sx = (2.0 * (f64::from(px) + 0.5) / f64::from(w) - 1.0) * a * f64::from(w) / f64::from(h);
            let sy = (1.0 - 2.0 * (f64::from(py) + 0.5) / f64::from(h)) * a;
            let d = (look + right * sx + up * sy).normalize();
            let mut seen = Seen::default();
            let expect = reference(&tris, EYE, d, 0, &mut seen);
            let got = img[(py * w + px) as usize];
            let rel = (0..3).map(|c| (got[c] - expect[c]).abs() / expect[c].abs().max(1e-3)).fold(0.0, f64::max);
            total += 1;
            if rel > worst.0 {
                worst = (rel, px, py);
            }
            if rel < 1e-3 {
                ok += 1;
                match seen.camera_hit {
                    Some(0) if seen.point_shadowed => shadowed_plane += 1,
                    Some(0) => lit_plane += 1,
                    Some(_) => occluder += 1,
                    None => {}
                }
                if seen.camera_hit == Some(0) && seen.mirror_hits >= 1 {
                    mirror += 1;
                }
                if seen.mirror_hits >= 2 {
                    multi += 1;
                }
            }
        }
    }
    // Pixels straddling a shadow or silhouette edge may legitimately differ between f32 and f64.
    assert!(ok * 100 >= total * 97, "{ok}/{total} pixels within 1e-3; worst {worst:?}");
    assert!(lit_plane >= 20 && shadowed_plane >= 5 && occluder >= 5 && mirror >= 5 && multi >= 1,
        "cases matched: lit {lit_plane}, shadowed {shadowed_plane}, occluder {occluder}, mirror {mirror}, multi-bounce {multi}");
}

/// `maxdepth 0` is local shading only: a mirror plane with nothing above shows no reflection, and
/// raising maxdepth only adds light (all terms are non-negative).
#[test]
fn maxdepth_limits_mirror_recursion() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let mut imgs = vec![];
    for depth in [0, 1, 5] {
        let text = scene_text().replace(&format!("maxdepth {MAXDEPTH}"), &format!("maxdepth {depth}"));
        let path = dir.join(format!("whitted_depth{depth}.test"));
        std::fs::write(&path, text).unwrap();
        let o = RenderOptions {
            scene: Some(path),
            spp: Some(1),
            pixel_sampler: Some(SamplerKind::GRID_CENTER),
            threads: 1,
            ..Default::default()
        };
        let out = strata::session::render_to_film(&o).unwrap();
        if depth == 0 {
            assert_eq!(out.stats.counters.bounce, 0, "maxdepth 0 traces no mirror rays");
        } else {
            assert!(out.stats.counters.bounce > 0);
        }
        imgs.push(means(&out.film));
    }
    for k in 1..imgs.len() {
        let sum = |i: &Vec<[f64; 3]>| i.iter().map(|v| v[0] + v[1] + v[2]).sum::<f64>();
        assert!(sum(&imgs[k]) > sum(&imgs[k - 1]), "depth step {k} adds no light");
        for (a, b) in imgs[k - 1].iter().zip(&imgs[k]) {
            for c in 0..3 {
                assert!(b[c] >= a[c] - 1e-6, "deeper recursion lost light");
            }
        }
    }
}

//! OBJ meshes: the loader on malformed files (file and line in every error, never a panic), the
//! material rule, emissive triangles against the equivalent quad light (statistical tests with the
//! film's variance, fixed seeds) for `direct` and `pathtracer`, exact agreement for
//! `analyticdirect`, whole-scene OBJ renders and the default camera framing.

use crate::common;

use common::*;
use glam::Vec3;
use std::path::{Path, PathBuf};
use strata::scene::obj;
use strata::scene::parse::{parse_file, Limits};
use strata::session::RenderOptions;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn own(name: &str) -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes")).join(name)
}

/// `load` of `text` fails with `file:line:` and every word of `words` in the message.
fn expect_obj_err(dir: &Path, name: &str, text: &str, line: usize, words: &[&str]) {
    let p = write(dir, name, text);
    let e = obj::load(&p).expect_err(name);
    let shown = e.to_string();
    assert_eq!(e.line, line, "{shown}");
    let at = if line == 0 { format!("{}: ", p.display()) } else { format!("{}:{line}: ", p.display()) };
    assert!(shown.starts_with(&at), "{shown}");
    for w in words {
        assert!(shown.contains(w), "'{w}' missing from: {shown}");
    }
}

#[test]
fn malformed_obj_files_give_file_and_line() {
    let d = tmpdir("bad");
    let ok = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    expect_obj_err(&d, "a.obj", "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", 2, &["'v' argument 2", "'x'"]);
    expect_obj_err(&d, "b.obj", &format!("{ok}f 1 2 4\n"), 4, &["vertex index 4 out of range", "3 defined"]);
    expect_obj_err(&d, "c.obj", &format!("{ok}# comment\nf 1 2\n"), 5, &["at least 3 vertices"]);
    expect_obj_err(&d, "d.obj", &format!("{ok}f 1 2 -4\n"), 4, &["index -4 out of range"]);
    expect_obj_err(&d, "e.obj", &format!("{ok}f 1/1 2/1 3/1\n"), 4, &["texture coordinate index 1 out of range"]);
    expect_obj_err(&d, "f.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", 2, &["finite"]);
    expect_obj_err(&d, "g.obj", &format!("{ok}f 1 2 three\n"), 4, &["'three' is not an index"]);
    expect_obj_err(&d, "h.obj", "v 1 2\nf 1 1 1\n", 1, &["'v' expects 3 to 7 numbers"]);
    // No faces, an unreadable file and bytes that are not text: line 0 or the line of the bad byte.
    expect_obj_err(&d, "i.obj", ok, 0, &["no faces"]);
    let missing = d.join("missing.obj");
    let e = obj::load(&missing).unwrap_err();
    assert!(e.line == 0 && e.to_string().contains("cannot read OBJ file"), "{e}");
    std::fs::write(d.join("j.obj"), b"v 0 0 0\nv 1 0 0\xff\n").unwrap();
    let e = obj::load(&d.join("j.obj")).unwrap_err();
    assert!(e.line == 2 && e.to_string().contains("UTF-8"), "{e}");
}

#[test]
fn malformed_mtl_files_name_the_library_and_line() {
    let d = tmpdir("badmtl");
    let obj_text = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";
    let o = write(&d, "t.obj", obj_text);
    for (mtl, line, words) in [
        ("newmtl a\nKd 0.5 0.5\n", 2, &["'Kd' expects 3 numbers"][..]),
        ("newmtl a\nKd 0.5 0.5 0.5\nNs -3\n", 3, &["'Ns' argument 1", ">= 0"][..]),
        ("newmtl a\n\nKe 1 inf 1\n", 3, &["'Ke' argument 2"][..]),
        ("Kd 1 1 1\nnewmtl a\n", 1, &["before any 'newmtl'"][..]),
    ] {
        let m = write(&d, "m.mtl", mtl);
        let e = obj::load(&o).unwrap_err();
        let shown = e.to_string();
        assert!(shown.starts_with(&format!("{}:{line}: ", m.display())), "{shown}");
        for w in words {
            assert!(shown.contains(w), "'{w}' missing from: {shown}");
        }
    }
    // A missing library is not an error: default materials, and a warning naming it.
    std::fs::remove_file(d.join("m.mtl")).unwrap();
    let (mesh, w) = obj::load_with_warnings(&o).unwrap();
    assert!(mesh.materials.is_empty() && mesh.face_material == [u32::MAX]);
    assert!(
        w.len() == 1 && w[0].to_string().starts_with(&format!("{}:1: mtllib 'm.mtl' not found", o.display())),
        "{w:?}"
    );
}

#[test]
fn obj_command_errors_carry_both_locations() {
    let d = tmpdir("cmd");
    write(&d, "bad.obj", "v 0 0 0\nv 0 0 1\nf 1 2 3\n");
    let t = write(&d, "s.test", "size 8 8\ncamera 0 0 5 0 0 0 0 1 0 45\n\nobj bad.obj\n");
    let e = parse_file(&t, &Limits::default()).unwrap_err().to_string();
    assert!(e.starts_with(&format!("{}:4: obj 'bad.obj': ", t.display())), "{e}");
    assert!(e.contains(&format!("{}:3: ", d.join("bad.obj").display())) && e.contains("out of range"), "{e}");
    let t = write(&d, "s2.test", "obj\n");
    assert!(parse_file(&t, &Limits::default()).unwrap_err().to_string().contains(":1: obj expects 1 file name"));
    let t = write(&d, "s3.test", "obj nowhere.obj\n");
    let e = parse_file(&t, &Limits::default()).unwrap_err().to_string();
    assert!(e.contains(":1: obj 'nowhere.obj'") && e.contains("cannot read OBJ file"), "{e}");
    let limits = Limits { max_primitives: 5, ..Limits::default() };
    let t = write(&d, "s4.test", &format!("obj {}\n", own("cornell_box.obj").display()));
    assert!(parse_file(&t, &limits).unwrap_err().to_string().contains("more than 5 primitives"));
}

/// Random byte edits of the Cornell OBJ and MTL: every load returns (Ok or an error), none panics.
#[test]
fn mutated_obj_and_mtl_never_panic() {
    let d = tmpdir("fuzz");
    let obj_src = std::fs::read(own("cornell_box.obj")).unwrap();
    let mtl_src = std::fs::read(own("cornell_box.mtl")).unwrap();
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let alphabet = b" \n/-0123456789.efvnt#xe+";
    let (mut ok, mut failed) = (0, 0);
    for round in 0..300 {
        let (mut o, mut m) = (obj_src.clone(), mtl_src.clone());
        let target = if round % 3 == 0 { &mut m } else { &mut o };
        for _ in 0..1 + next() % 4 {
            let at = (next() as usize) % target.len();
            match next() % 3 {
                0 => target[at] = alphabet[(next() as usize) % alphabet.len()],
                1 => {
                    target.remove(at);
                }
                _ => target.truncate(at),
            }
        }
        std::fs::write(d.join("cornell_box.obj"), &o).unwrap();
        std::fs::write(d.join("cornell_box.mtl"), &m).unwrap();
        match obj::load(&d.join("cornell_box.obj")) {
            Ok(mesh) => {
                assert!(mesh.positions.iter().all(|p| p.is_finite()));
                assert!(mesh.faces.iter().flatten().all(|&i| (i as usize) < mesh.positions.len()));
                ok += 1;
            }
            Err(e) => {
                assert!(e.file.starts_with(&d), "{e}");
                failed += 1;
            }
        }
    }
    assert!(ok > 0 && failed > 0, "ok {ok}, failed {failed}");
}

#[test]
fn materials_follow_the_mtl_where_given_and_the_current_material_elsewhere() {
    let d = tmpdir("mat");
    write(&d, "m.mtl", "newmtl kd_only\nKd 0.1 0.2 0.3\nnewmtl full\nKd 0.4 0.4 0.4\nKs 0.5 0.5 0.5\nNs 30\nnewmtl lamp\nKd 0.9 0.9 0.9\nKe 2 3 4\n");
    write(
        &d,
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nusemtl kd_only\nf 2 4 3\nusemtl full\nf 1 2 4\nusemtl lamp\nf 1 2 3 4\n",
    );
    let t = write(
        &d,
        "s.test",
        "specular 0.25 0.25 0.25\nshininess 7\nemission 0.01 0 0\ntranslate 0 0 -2\nscale 2 2 2\nobj m.obj\n",
    );
    let s = parse_file(&t, &Limits::default()).unwrap();
    assert_eq!(s.triangles.len(), 3);
    let mat = |i: usize| s.materials[s.triangles[i].material as usize];
    // No usemtl: the current material.
    assert_eq!(mat(0).diffuse, Vec3::ZERO);
    assert_eq!(
        (mat(0).specular, mat(0).shininess, mat(0).emission),
        (Vec3::splat(0.25), 7.0, Vec3::new(0.01, 0.0, 0.0))
    );
    // Kd from the MTL, Ks and Ns from the current material.
    assert_eq!((mat(1).diffuse, mat(1).specular, mat(1).shininess), (Vec3::new(0.1, 0.2, 0.3), Vec3::splat(0.25), 7.0));
    assert_eq!((mat(2).diffuse, mat(2).specular, mat(2).shininess), (Vec3::splat(0.4), Vec3::splat(0.5), 30.0));
    // Ke: the quad (two triangles) became emissive triangles, under the transform.
    assert_eq!(s.emissive_triangles.len(), 2);
    let e = s.emissive_triangles[0];
    assert_eq!(e.radiance, Vec3::new(2.0, 3.0, 4.0));
    assert_eq!(e.v[0], Vec3::new(0.0, 0.0, -2.0));
    assert_eq!(e.v[1], Vec3::new(2.0, 0.0, -2.0));
    // Emits towards (v1 - v0) x (v2 - v0) = +z here.
    let n = (e.v[1] - e.v[0]).cross(e.v[2] - e.v[0]);
    assert!(n.z > 0.0);
}

/// A small diffuse room lit by one light, written twice: as a `quadLight`, and as an OBJ of two
/// triangles with `Ke` (placed under a transform) covering the same parallelogram, emitting the
/// same side. Returns (quad scene, triangle scene).
fn equivalent_scenes(dir: &Path, settings: &str, sphere: bool) -> (PathBuf, PathBuf) {
    // Floor and back wall, the wall no higher than the light's plane (nothing behind the light).
    let mut room = "size 24 24\ncamera 0 1 3.2 0 0.9 0 0 1 0 50\nmaxverts 8\n\
        vertex -1.5 0 -1.5\nvertex 1.5 0 -1.5\nvertex 1.5 0 1.5\nvertex -1.5 0 1.5\n\
        vertex -1.5 1.8 -1.5\nvertex 1.5 1.8 -1.5\n\
        diffuse 0.7 0.7 0.7\ntri 0 2 1\ntri 0 3 2\ntri 0 1 5\ntri 0 5 4\n"
        .to_string();
    if sphere {
        room += "diffuse 0.2 0.5 0.8\nspecular 0.3 0.3 0.3\nshininess 20\nsphere 0.2 0.5 0 0.5\n";
    }
    // The light: a = (-0.4, 1.8, -0.6), ab = (0, 0, 0.9), ac = (0.8, 0, 0) emits towards ac x ab = -y.
    let l = "3 2.5 2";
    let q = write(dir, "quad.test", &format!("{room}{settings}\nquadLight -0.4 1.8 -0.6 0 0 0.9 0.8 0 0 {l}\n"));
    write(dir, "light.mtl", &format!("newmtl lamp\nKd 0.5 0.5 0.5\nKe {l}\n"));
    // Corners relative to (0, 1.8, 0): a, a+ab, a+ab+ac, a+ac; faces wound for a -y normal.
    write(
        dir,
        "light.obj",
        "mtllib light.mtl\nv -0.4 0 -0.6\nv -0.4 0 0.3\nv 0.4 0 0.3\nv 0.4 0 -0.6\nusemtl lamp\nf 1 4 3\nf 1 3 2\n",
    );
    let t = write(
        dir,
        "tri.test",
        &format!("{room}{settings}\npushTransform\ntranslate 0 1.8 0\nobj light.obj\npopTransform\n"),
    );
    (q, t)
}

/// Chi-square over 4x4 blocks of pixels of (mean_a - mean_b) / sqrt(var_a + var_b), per channel,
/// from the films' per-pixel variance of the mean (renders with different seeds are independent).
fn block_chi2(a: &RenderOptions, b: &RenderOptions) -> (f64, usize, f64) {
    let (fa, fb) = (film(a), film(b));
    let (ma, mb, va, vb) = (means(&fa), means(&fb), var_of_mean(&fa), var_of_mean(&fb));
    let (w, h) = (fa.width as usize, fa.height as usize);
    let (bw, bh) = (w / 4, h / 4);
    let (mut chi2, mut dof, mut total) = (0.0, 0, 0.0);
    for by in 0..4 {
        for bx in 0..4 {
            for c in 0..3 {
                let (mut d, mut v) = (0.0, 0.0);
                for y in by * bh..(by + 1) * bh {
                    for x in bx * bw..(bx + 1) * bw {
                        let i = y * w + x;
                        d += ma[i][c] - mb[i][c];
                        v += va[i][c] + vb[i][c];
                        total += ma[i][c];
                    }
                }
                if v > 0.0 {
                    chi2 += d * d / v;
                    dof += 1;
                } else {
                    assert_eq!(d, 0.0, "a block without variance differs");
                }
            }
        }
    }
    (chi2, dof, total)
}

/// Chi-square critical value at p = 0.001 for `k` degrees of freedom (Wilson-Hilferty, within 1%
/// for k >= 10).
fn chi2_critical_p001(k: usize) -> f64 {
    let k = k as f64;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + 3.090 * a.sqrt()).powi(3)
}

fn assert_equivalent(name: &str, settings: &str, spp: u32) {
    let d = tmpdir(name);
    let (q, t) = equivalent_scenes(&d, settings, true);
    let base = |p: PathBuf, seed| RenderOptions { seed, ..opts(p, 24, 24, spp) };
    let (chi2, dof, total) = block_chi2(&base(q.clone(), 11), &base(t.clone(), 12));
    let critical = chi2_critical_p001(dof);
    assert!(dof >= 30, "{name}: {dof} blocks with variance");
    assert!(total > 1.0, "{name}: the image is lit ({total})");
    eprintln!("{name}: chi2 {chi2:.1} over {dof} blocks (p = 0.001 critical {critical:.1})");
    assert!(chi2 < critical, "{name}: emissive triangles vs quad light, chi2 {chi2:.1} over {dof} blocks");
    // The test has power: a light 10% brighter in the triangle scene is detected.
    let brighter = std::fs::read_to_string(d.join("light.mtl")).unwrap().replace("Ke 3 2.5 2", "Ke 3.3 2.75 2.2");
    std::fs::write(d.join("light.mtl"), brighter).unwrap();
    let (chi2_off, _, _) = block_chi2(&base(q, 11), &base(t, 12));
    eprintln!("{name}: 10% brighter: chi2 {chi2_off:.1}");
    assert!(chi2_off > critical, "{name}: a 10% brighter light is not detected (chi2 {chi2_off:.1})");
}

#[test]
fn emissive_triangles_match_the_quad_light_direct() {
    assert_equivalent("eq-direct", "integrator direct\nlightsamples 4\nlightstratify on", 64);
}

#[test]
fn emissive_triangles_match_the_quad_light_pathtracer_mis() {
    assert_equivalent(
        "eq-mis",
        "integrator pathtracer\nnexteventestimation mis\nimportancesampling brdf\nmaxdepth 3",
        64,
    );
}

#[test]
fn emissive_triangles_match_the_quad_light_pathtracer_nee_off_and_on() {
    assert_equivalent(
        "eq-off",
        "integrator pathtracer\nnexteventestimation off\nimportancesampling cosine\nmaxdepth 2",
        128,
    );
    assert_equivalent(
        "eq-on",
        "integrator pathtracer\nnexteventestimation on\nimportancesampling cosine\nmaxdepth 3",
        64,
    );
}

/// `analyticdirect` is deterministic: the triangle pair's irradiance is the quad's (the shared
/// diagonal's terms cancel), to float rounding, for receivers that see the whole light above their
/// horizon (no sphere here: where a receiver's horizon cuts the light, each polygon's `Phi . n` is
/// clamped separately, and the formula is not exact for either).
#[test]
fn emissive_triangles_match_the_quad_light_analyticdirect() {
    let d = tmpdir("eq-analytic");
    let (q, t) = equivalent_scenes(&d, "integrator analyticdirect", false);
    let (a, b) = (means(&film(&opts(q, 24, 24, 1))), means(&film(&opts(t, 24, 24, 1))));
    let mut lit = 0;
    for (x, y) in a.iter().zip(&b) {
        for c in 0..3 {
            assert!((x[c] - y[c]).abs() <= 1e-4 * x[c].abs().max(1e-3), "{x:?} vs {y:?}");
        }
        lit += usize::from(x[0] > 0.01);
    }
    assert!(lit > 300, "{lit} lit pixels");
}

/// `--threads` does not change an image with emissive triangles chosen by power.
#[test]
fn emissive_triangle_renders_are_thread_count_independent() {
    let o = |threads| RenderOptions { threads, seed: 3, ..opts(own("cornell_obj.test"), 24, 20, 4) };
    let (a, b) = (film(&o(1)), film(&o(2)));
    assert!(a.sum == b.sum && a.sum_sq == b.sum_sq);
}

#[test]
fn whole_scene_obj_renders_with_its_emissive_patch() {
    let o = RenderOptions { seed: 1, ..opts(own("cornell_box.obj"), 48, 36, 4) };
    let out = strata::session::render_to_film(&o).unwrap();
    assert_eq!(out.stats.counters.nonfinite, 0);
    assert_eq!(out.scene.emitters.n_triangles(), 2);
    assert_eq!(out.scene.emitters.n_quads, 0);
    let m = means(&out.film);
    // The default camera looks into the open box: the centre pixel sees the lit back wall, the
    // patch (radiance 17 12 4; lit walls stay below ~2) shows near the top centre, the image corner
    // sees out of the box (black).
    let at = |x: usize, y: usize| m[y * 48 + x];
    let centre = at(24, 18);
    assert!(centre[0] > 0.05 && centre[0] < 2.0, "{centre:?}");
    assert!((0..18).any(|y| at(24, y)[0] > 5.0), "no pixel sees the patch");
    assert_eq!(at(0, 0), [0.0; 3]);
}

/// The default camera of a whole-scene OBJ frames its bounds: every corner of the bounding box
/// projects inside the image, and the box fills a sensible part of it.
#[test]
fn default_camera_frames_the_bounds() {
    let mesh = obj::load(&own("cornell_box.obj")).unwrap();
    let (lo, hi) = mesh.bounds().unwrap();
    assert_eq!((lo, hi), (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 1.0)));
    for (w, h) in [(640u32, 480u32), (100, 100), (200, 50)] {
        let desc = obj::frame_camera(lo, hi, 45.0);
        let cam = strata::scene::build::Camera::new(&desc, w, h);
        let mut max_ndc: f32 = 0.0;
        for k in 0..8 {
            let p = Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let d = p - cam.eye;
            let z = d.dot(cam.look);
            assert!(z > 0.0, "corner behind the camera");
            let aspect = w as f32 / h as f32;
            let (sx, sy) = (d.dot(cam.right) / z * cam.plane_dist / aspect, d.dot(cam.up) / z * cam.plane_dist);
            assert!(sx.abs() <= 1.0 && sy.abs() <= 1.0, "{w}x{h}: corner {p} at ({sx}, {sy}) is outside");
            max_ndc = max_ndc.max(sx.abs().max(sy.abs()));
        }
        assert!(max_ndc > 0.4, "{w}x{h}: the model fills too little ({max_ndc})");
    }
    // --camera replaces it.
    let c = strata::session::parse_camera("0 1 5 0 1 0 0 1 0 30").unwrap();
    let o = RenderOptions { camera: Some(c), ..opts(own("cornell_box.obj"), 8, 8, 1) };
    assert_eq!(strata::session::load_scene(&o).unwrap().camera, Some(c));
    assert!(strata::session::parse_camera("0 1 5 0 1 5 0 1 0 30").unwrap_err().to_string().contains("coincide"));
    assert!(strata::session::parse_camera("0 1 5").is_err());
}

#[test]
fn procedural_mesh_has_a_million_triangles_and_round_trips() {
    let m = obj::procedural_mesh(1_000_000);
    let torus = m.face_material.iter().filter(|&&i| i == 0).count();
    assert!((1_000_000..1_010_000).contains(&torus), "{torus}");
    assert!(m.faces.iter().all(|f| {
        let [a, b, c] = f.map(|i| m.positions[i as usize]);
        (b - a).cross(c - a).length() > 0.0
    }));
    // Written and read back (a small one: the loader path is the same).
    let small = obj::procedural_mesh(2000);
    let d = tmpdir("gen");
    obj::write_obj(&d.join("t.obj"), &small).unwrap();
    let back = obj::load(&d.join("t.obj")).unwrap();
    assert_eq!(back.faces.len(), small.faces.len());
    let s = strata::scene::obj::scene_from_obj(&d.join("t.obj"), &Limits::default()).unwrap();
    assert_eq!(s.emissive_triangles.len(), 2);
    assert_eq!(s.triangles.len(), small.faces.len() - 2);
    assert_eq!(small.faces.len(), small.face_material.iter().filter(|&&i| i == 0).count() + 6);
}

/// The command line: `gen-mesh`, then `render model.obj --camera`, and a malformed OBJ reported with
/// its file and line (exit status 1, no panic).
#[test]
fn cli_gen_mesh_render_obj_with_camera_and_errors() {
    let d = tmpdir("cli");
    let mesh = d.join("m.obj");
    let r = strata().args(["gen-mesh", "--triangles", "400"]).arg(&mesh).output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(String::from_utf8_lossy(&r.stdout).contains("406 triangles"));
    assert!(d.join("m.mtl").is_file());
    let out = d.join("img");
    let stats = d.join("s.json");
    let r = strata()
        .arg("render")
        .arg(&mesh)
        .args(["--camera", "0 0.5 6 0 0 0 0 1 0 40", "--size", "24x16", "--spp", "2", "--threads", "2", "-q"])
        .arg("-o")
        .arg(&out)
        .arg("--stats")
        .arg(&stats)
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(d.join("img.exr").is_file() && d.join("img.png").is_file());
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!((j["integrator"].as_str(), j["width"].as_u64()), (Some("pathtracer"), Some(24)));
    assert_eq!(j["features"]["emissive_triangles"], 2);
    assert_eq!(j["features"]["direct_light_choice"], "power");
    assert_eq!(j["features"]["light_selection"], "uniform", "the rule in use, as at the top level");
    assert_eq!(j["light_selection"], "uniform");
    assert_eq!(j["nonfinite_samples"], 0);
    let bad = write(&d, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    let r = strata().arg("render").arg(&bad).args(["--size", "8x8", "-q"]).output().unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains(&format!("{}:4: ", bad.display())) && err.contains("out of range"), "{err}");
    let r = strata().arg("render").arg(&mesh).args(["--camera", "0 0 1 0 0 1 0 1 0 40"]).output().unwrap();
    assert!(!r.status.success() && String::from_utf8_lossy(&r.stderr).contains("coincide"));
}

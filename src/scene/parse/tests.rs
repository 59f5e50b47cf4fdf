//! Tests of the `.test` parser.

use super::*;
use glam::Mat4;
use std::path::PathBuf;

fn parse(text: &str) -> Result<SceneDesc, SceneError> {
    parse_str(text, Path::new("t.test"), &Limits::default())
}

fn parse_ok(text: &str) -> SceneDesc {
    parse(text).unwrap_or_else(|e| panic!("{e}"))
}

/// Parses `text`, expects an error on `line` whose message contains every one of `words`.
fn expect_err(text: &str, line: usize, words: &[&str]) {
    let e = parse(text).expect_err(text);
    assert_eq!(e.line, line, "{e}");
    for w in words {
        assert!(e.message.contains(w), "message {:?} lacks {w:?}", e.message);
    }
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

/// The corpus folder, or `None` (with a printed reason) when it is absent.
fn corpus() -> Option<PathBuf> {
    let dir = std::env::var_os("STRATA_CSE168")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/cse168")));
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("skipping: CSE168 corpus not found at {} (set STRATA_CSE168)", dir.display());
        None
    }
}

fn corpus_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for hw in ["hw1", "hw2", "hw3", "hw4"] {
        let Ok(entries) = std::fs::read_dir(dir.join(hw)) else { continue };
        files.extend(entries.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "test")));
    }
    files.sort();
    files
}

fn load(dir: &Path, name: &str) -> SceneDesc {
    parse_file(&dir.join(name), &Limits::default()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn whole_corpus_parses() {
    let Some(dir) = corpus() else { return };
    let files = corpus_files(&dir);
    assert!(files.len() >= 20, "only {} corpus files", files.len());
    for f in &files {
        let d = parse_file(f, &Limits::default()).unwrap_or_else(|e| panic!("{e}"));
        assert!(d.camera.is_some(), "{}: no camera", f.display());
        let n = d.materials.len() as u32;
        assert!(d.triangles.iter().all(|t| t.material < n && t.v.iter().all(|v| v.is_finite())));
        assert!(d.spheres.iter().all(|s| s.material < n && s.object_to_world.is_finite()));
    }
}

#[test]
fn corpus_facts() {
    let Some(dir) = corpus() else { return };
    let d = load(&dir, "hw2/analytic.test");
    assert_eq!((d.quad_lights.len(), d.integrator), (1, IntegratorKind::AnalyticDirect));
    assert_eq!((d.width, d.height), (640, 480));
    assert_eq!(d.camera.map(|c| c.fovy_deg), Some(45.0));
    assert_eq!(d.output.as_deref(), Some("analytic.png"));

    let d = load(&dir, "hw2/dragon.test");
    assert!((99_000..=101_000).contains(&d.triangles.len()), "{}", d.triangles.len());
    assert!(d.materials.len() < 10, "{} materials", d.materials.len());
    assert_eq!((d.light_samples, d.light_stratify, d.max_depth), (25, true, 5));

    let d = load(&dir, "hw4/mis.test");
    let mut ggx: Vec<f32> = d.materials.iter().filter(|m| m.brdf == BrdfKind::Ggx).map(|m| m.roughness).collect();
    ggx.dedup();
    assert_eq!(ggx, [0.0005, 0.008, 0.07, 0.15]);
    assert_eq!((d.nee, d.importance_sampling, d.russian_roulette), (Nee::Mis, ImportanceSampling::Brdf, false));
    assert_eq!((d.spp, d.gamma, d.quad_lights.len()), (32, 2.2, 5));

    let d = load(&dir, "hw4/ggx.test");
    assert_eq!(d.max_depth, -1);
    assert!(d.russian_roulette);

    let d = load(&dir, "hw1/scene6.test");
    assert_eq!(d.point_lights[0].attenuation, Vec3::new(1.0, 0.1, 0.05));
    assert!(close(d.directional_lights[0].direction, Vec3::new(0.0, 1.0, -1.0).normalize()));
}

#[test]
fn corpus_spheres() {
    let Some(dir) = corpus() else { return };
    let centre = |s: &SphereDesc| s.object_to_world.transform_point3(Vec3::ZERO);
    // hw1/scene6: translate 0 -0.7 -1.5; scale 0.1; and an ellipsoid 0.3 x 0.6 x 0.3 at (0.5,-0.5,-2).
    let d = load(&dir, "hw1/scene6.test");
    assert_eq!(d.spheres.len(), 4);
    assert!(close(centre(&d.spheres[0]), Vec3::new(0.0, -0.7, -1.5)));
    assert!(close(d.spheres[0].object_to_world.transform_point3(Vec3::X), Vec3::new(0.1, -0.7, -1.5)));
    let e = d.spheres[3].object_to_world;
    assert!(close(centre(&d.spheres[3]), Vec3::new(0.5, -0.5, -2.0)));
    assert!(close(e.transform_point3(Vec3::Y), Vec3::new(0.5, 0.1, -2.0)));
    // hw1/scene5: nested translates -10 0 0 inside 0 -2 -5, radius 0.4.
    let d = load(&dir, "hw1/scene5.test");
    assert!(close(centre(&d.spheres[0]), Vec3::new(-10.0, -2.0, -5.0)));
    assert!(close(d.spheres[0].object_to_world.transform_point3(Vec3::Z), Vec3::new(-10.0, -2.0, -4.6)));
    // hw2/sphere: sphere 0 -0.25 0 0.5 with no transform.
    let d = load(&dir, "hw2/sphere.test");
    let expected = Mat4::from_translation(Vec3::new(0.0, -0.25, 0.0)) * Mat4::from_scale(Vec3::splat(0.5));
    assert!(d.spheres[0].object_to_world.abs_diff_eq(expected, 1e-6));
}

#[test]
fn cornell_walls_face_into_the_box() {
    let Some(dir) = corpus() else { return };
    let d = load(&dir, "hw2/cornell.test");
    assert_eq!(d.triangles.len(), 22);
    let inside = Vec3::new(0.0, 1.0, 0.0);
    // The first 10 triangles are the five walls; the remaining 12 are a cube, facing outwards.
    for t in &d.triangles[..10] {
        let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
        let centroid = (t.v[0] + t.v[1] + t.v[2]) / 3.0;
        assert!(n.dot(inside - centroid) > 0.0, "{t:?} faces out");
    }
    // The ceiling light emits downwards (towards ac x ab).
    let q = d.quad_lights[0];
    assert!(q.ac.cross(q.ab).y < 0.0);
}

#[test]
fn defaults_comments_and_line_endings() {
    let d = parse_ok("# only comments\r\n\r\n   \t\n size 10 20 # trailing\r\nspp 4#x\n");
    assert_eq!((d.width, d.height, d.spp), (10, 20, 4));
    assert_eq!((d.gamma, d.max_depth, d.integrator), (1.0, 5, IntegratorKind::RayTracer));
    assert_eq!(d.source, Path::new("t.test"));
    let d = parse_ok("size 1e2 2.0\ngamma 2.2\nmaxdepth -1\nlightsamples 9\nbrdf GGX\nvertex .5 -1. +2e0");
    assert_eq!((d.width, d.height, d.max_depth, d.light_samples), (100, 2, -1, 9));
    assert_eq!(parse_ok("").camera, None);
}

/// World-space first vertex of the one triangle made after `prefix`, from vertex (1, 0, 0).
fn transformed_x(prefix: &str) -> Vec3 {
    let d = parse_ok(&format!("vertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\n{prefix}\ntri 0 1 2"));
    d.triangles[0].v[0]
}

#[test]
fn transform_order() {
    assert!(close(transformed_x("translate 1 0 0\nscale 2 2 2"), Vec3::new(3.0, 0.0, 0.0)));
    assert!(close(transformed_x("scale 2 2 2\ntranslate 1 0 0"), Vec3::new(4.0, 0.0, 0.0)));
    assert!(close(transformed_x("rotate 0 1 0 90"), Vec3::new(0.0, 0.0, -1.0)));
    assert!(close(transformed_x("rotate 0 5 0 90"), Vec3::new(0.0, 0.0, -1.0)));
    assert!(close(transformed_x("translate 0 0 1\nrotate 0 0 1 90"), Vec3::new(0.0, 1.0, 1.0)));
    assert!(close(transformed_x("pushTransform\ntranslate 5 0 0\npopTransform"), Vec3::X));
    let nested = "translate 1 0 0\npushTransform\nscale 3 3 3\npushTransform\ntranslate 9 9 9\npopTransform";
    assert!(close(transformed_x(nested), Vec3::new(4.0, 0.0, 0.0)));
    // The transform in force when `tri` is read counts, not when the vertices were listed.
    let d = parse_ok("vertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\ntri 0 1 2\ntranslate 0 0 2\ntri 0 1 2");
    assert_eq!(d.triangles[0].v[0], Vec3::X);
    assert!(close(d.triangles[1].v[0], Vec3::new(1.0, 0.0, 2.0)));
}

#[test]
fn lights_and_spheres_under_transforms() {
    let d = parse_ok(
        "translate 1 2 3\nscale 2 2 2\nattenuation 0 0 1\npoint 1 0 0 1 1 1\ndirectional 0 0 5 1 1 1\n\
         sphere 1 0 0 0.5\nquadLight 0 0 0 1 0 0 0 1 0 1 1 1",
    );
    let p = d.point_lights[0];
    assert!(close(p.position, Vec3::new(3.0, 2.0, 3.0)));
    assert_eq!(p.attenuation, Vec3::Z);
    assert!(close(d.directional_lights[0].direction, Vec3::Z));
    let s = d.spheres[0].object_to_world;
    assert!(close(s.transform_point3(Vec3::ZERO), Vec3::new(3.0, 2.0, 3.0)));
    assert!(close(s.transform_point3(Vec3::X), Vec3::new(4.0, 2.0, 3.0)));
    assert_eq!(d.quad_lights[0].a, Vec3::ZERO); // the stack does not apply to quad lights
    assert_eq!(d.quad_lights[0].ab, Vec3::X);
    // Default attenuation for point lights declared before any `attenuation`.
    assert_eq!(parse_ok("point 0 0 0 1 1 1").point_lights[0].attenuation, Vec3::X);
}

#[test]
fn materials_are_deduplicated() {
    let mut text = String::from("vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n");
    for i in 0..1000 {
        text += if i % 2 == 0 { "diffuse 1 0 0\n" } else { "diffuse 0 1 0\n" };
        text += "tri 0 1 2\nsphere 0 0 0 1\n";
    }
    text += "brdf ggx\nroughness 0.3\ntri 0 1 2\nemission -0 0 0\nbrdf phong\nroughness 1\ntri 0 1 2\n";
    let d = parse_ok(&text);
    assert_eq!(d.materials.len(), 3);
    assert_eq!(d.materials[0], Material { diffuse: Vec3::X, ..Material::default() });
    assert_eq!(d.triangles[1].material, 1);
    assert_eq!(d.spheres[2].material, 0);
    assert_eq!(d.materials[2].roughness, 0.3);
    assert_eq!(d.triangles.last().map(|t| t.material), Some(1));
}

#[test]
fn settings() {
    let d = parse_ok(
        "integrator pathtracer\nnexteventestimation on\nrussianroulette on\nimportancesampling cosine\n\
         lightstratify on\noutput out.png\ncamera 0 0 5 0 0 0 0 1 0 30\nmaxverts 1000000000000",
    );
    assert_eq!(
        (d.integrator, d.nee, d.importance_sampling),
        (IntegratorKind::PathTracer, Nee::On, ImportanceSampling::Cosine)
    );
    assert!(d.russian_roulette && d.light_stratify);
    assert_eq!(d.output.as_deref(), Some("out.png"));
    let c = d.camera.expect("camera");
    assert_eq!((c.eye, c.center, c.up, c.fovy_deg), (Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 30.0));
    assert_eq!(d.light_selection, None);
    use crate::light::select::LightSelection;
    for (text, sel) in [
        ("all", LightSelection::ALL),
        ("Power", LightSelection::named("power")),
        ("spatial", LightSelection::named("spatial")),
    ] {
        assert_eq!(parse_ok(&format!("lightselection {text}")).light_selection, Some(sel));
    }
}

#[test]
fn errors_name_line_and_cause() {
    expect_err("size 10 10\nfoo 1 2\n", 2, &["unknown command", "'foo'"]);
    expect_err("pushtransform", 1, &["unknown command", "did you mean 'pushTransform'"]);
    expect_err("# c\ncamera 0 0 0 0 0 -1 0 1 0", 2, &["camera expects 10 numbers, got 9"]);
    expect_err("vertex 1 2 3 4", 1, &["vertex expects 3 numbers, got 4"]);
    expect_err("\n\nvertex 1 x 2", 3, &["vertex", "argument 2", "expected a number", "'x'"]);
    expect_err("vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\ntri 0 1 3", 4, &["tri index 3", "3 vertices"]);
    expect_err("vertex 0 0 0\ntri 0 0 -1", 2, &["tri index -1", "1 vertices"]);
    expect_err("tri 0 1 2.5", 1, &["tri", "expected an integer", "'2.5'"]);
    expect_err("pushTransform\npopTransform\npopTransform", 3, &["popTransform", "empty"]);
    expect_err("size 1000000 1000000", 1, &["1000000x1000000", "268435456 pixels", "--limit max_pixels=N"]);
    expect_err("size 100000 2", 1, &["65536", "max_side"]);
    expect_err("size 0 10", 1, &["size", "positive"]);
    expect_err("scale 1 1 1\nscale 1 0 1", 2, &["scale", "non-zero"]);
    expect_err("spp -4", 1, &["spp", "at least 1", "-4"]);
    expect_err("spp 100000000", 1, &["spp", "max_spp"]);
    expect_err("lightsamples 0", 1, &["lightsamples", "at least 1"]);
    expect_err("maxdepth -2", 1, &["maxdepth", "at least -1"]);
    expect_err("maxverts -1", 1, &["maxverts", "at least 0"]);
    expect_err("vertex nan 0 0", 1, &["vertex", "'nan'", "finite"]);
    expect_err("sphere 0 0 0 1e39", 1, &["sphere", "finite"]);
    expect_err("gamma 0", 1, &["gamma", "> 0"]);
    expect_err("rotate 0 0 0 90", 1, &["rotate", "axis"]);
    expect_err("directional 0 0 0 1 1 1", 1, &["directional", "non-zero"]);
    expect_err("sphere 0 0 0 0", 1, &["sphere", "radius"]);
    expect_err("quadLight 0 0 0 1 0 0 2 0 0 1 1 1", 1, &["quadLight", "area"]);
    expect_err("integrator foo", 1, &["integrator", "raytracer|analyticdirect|direct|pathtracer", "'foo'"]);
    expect_err("lightstratify", 1, &["lightstratify", "on|off", "0 arguments"]);
    expect_err("spp 4\nlightselection nearest", 2, &["lightselection", "all|uniform|power|spatial", "'nearest'"]);
    expect_err("lightselection", 1, &["lightselection", "all|uniform|power|spatial", "0 arguments"]);
    expect_err("attenuation 0 0 0", 1, &["attenuation"]);
    expect_err("shininess -1", 1, &["shininess", ">= 0"]);
    expect_err("camera 0 0 0 0 0 0 0 1 0 45", 1, &["camera", "coincide"]);
    expect_err("camera 0 0 0 0 0 -1 0 0 1 45", 1, &["camera", "parallel"]);
    expect_err("camera 0 0 0 0 0 -1 0 1 0 180", 1, &["fovy"]);
    expect_err("scale 1e30 1e30 1e30\nscale 1e30 1e30 1e30\nvertex 1 1 1\ntri 0 0 0", 4, &["out of range"]);
    expect_err("popTransform extra", 1, &["popTransform expects 0 arguments, got 1"]);
    expect_err(&format!("vertex {} 1 1", "9".repeat(100_000)), 1, &["finite", "..."]);
}

#[test]
fn display_and_file_errors() {
    let e = parse_str("ok 1", Path::new("dir/x.test"), &Limits::default()).expect_err("error");
    assert_eq!(e.to_string(), "dir/x.test:1: unknown command 'ok'");
    let missing = Path::new("/nonexistent/strata/scene.test");
    let e = parse_file(missing, &Limits::default()).expect_err("missing file");
    assert_eq!(e.line, 0);
    assert!(e.to_string().starts_with("/nonexistent/strata/scene.test: cannot read"), "{e}");
    let path = std::env::temp_dir().join(format!("strata-parse-{}.test", std::process::id()));
    std::fs::write(&path, b"size 10 10\n\nvertex 1 \xff 2\n").expect("write temp file");
    let e = parse_file(&path, &Limits::default()).expect_err("bad utf-8");
    let _ = std::fs::remove_file(&path);
    assert_eq!(e.line, 3);
    assert!(e.message.contains("UTF-8"));
}

#[test]
fn limits_are_enforced() {
    let limits = Limits { max_vertices: 3, max_primitives: 2, max_transform_depth: 2, ..Limits::default() };
    let run = |text: &str| parse_str(text, Path::new("t.test"), &limits);
    let e = run("vertex 0 0 0\nvertex 0 0 0\nvertex 0 0 0\nvertex 0 0 0").expect_err("vertices");
    assert!(e.line == 4 && e.message.contains("max_vertices"), "{e}");
    let e = run("sphere 0 0 0 1\npoint 0 0 0 1 1 1\nsphere 0 0 0 1").expect_err("primitives");
    assert!(e.line == 3 && e.message.contains("max_primitives"), "{e}");
    let e = run("pushTransform\npushTransform\npushTransform").expect_err("depth");
    assert!(e.line == 3 && e.message.contains("max_transform_depth"), "{e}");
    assert!(run("pushTransform\npushTransform\npopTransform\npushTransform").is_ok());
}

/// xorshift64*: a tiny deterministic generator for the robustness test.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

#[test]
fn truncated_and_mutated_corpus_never_panics() {
    let Some(dir) = corpus() else { return };
    const NASTY: [&str; 24] = [
        "nan",
        "-inf",
        "1e39",
        "-1",
        "0",
        "-0",
        "99999999999999999999",
        "4294967296",
        "1e-45",
        "2.5",
        "x",
        "é",
        "#",
        "",
        "tri",
        "sphere",
        "pushTransform",
        "popTransform",
        "scale",
        "rotate",
        "size",
        "maxverts",
        "1e15",
        "\u{0}",
    ];
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for file in corpus_files(&dir) {
        let text = std::fs::read_to_string(&file).expect("corpus file is text");
        for _ in 0..50 {
            let mut cut = rng.below(text.len() + 1);
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            let _ = parse_str(&text[..cut], &file, &Limits::default());
        }
        let lines: Vec<&str> = text.lines().collect();
        for _ in 0..20 {
            // Mutate a few tokens in a window of at most 400 lines, so big files stay quick.
            let start = if rng.below(2) == 0 { 0 } else { rng.below(lines.len().saturating_sub(400)) };
            let mut window: Vec<Vec<&str>> =
                lines.iter().skip(start).take(400).map(|l| l.split_ascii_whitespace().collect()).collect();
            for _ in 0..1 + rng.below(4) {
                let l = rng.below(window.len());
                if let Some(line) = window.get_mut(l) {
                    let t = rng.below(line.len() + 1);
                    let token = NASTY[rng.below(NASTY.len())];
                    if t < line.len() {
                        line[t] = token
                    } else {
                        line.push(token)
                    }
                }
            }
            let mutated: Vec<String> = window.iter().map(|l| l.join(" ")).collect();
            let _ = parse_str(&mutated.join("\n"), &file, &Limits::default());
        }
    }
}

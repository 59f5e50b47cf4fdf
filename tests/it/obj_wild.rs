//! The real-world OBJ corpus (`../shared/corpora/obj-wild`, see its `SOURCES.md`; override with
//! `STRATA_OBJ_WILD`): the expected outcome of every file, through the library loader, plus a few
//! real CLI renders; and every file the `tobj` crate loads (with at least one triangle) must render.
//! Skipped, with the reason printed, when the corpus is absent. `STRATA_OBJ_WILD_DUMP=1` prints
//! each file's actual outcome (to update the table).

use crate::common;

use common::*;
use std::path::{Path, PathBuf};
use strata::scene::obj;
use strata::scene::parse::Limits;

/// What loading a file must give.
#[derive(Debug)]
enum Expect {
    /// loads with no warning
    Renders,
    /// loads; every substring is in some warning (and every warning is matched by one)
    RendersWithWarnings(&'static [&'static str]),
    /// refused; the substring is in the error, which starts with `file:line: ` (`file: ` for line 0)
    Refused(&'static str),
}
use Expect::*;

const TABLE: &[(&str, Expect)] = &[
    ("assimp-quirks/WusonOBJ.obj", RendersWithWarnings(&["WusonOBJ.obj:2122: texture coordinates (vt, 1"])),
    (
        "assimp-quirks/box_UTF16BE.obj",
        Refused("box_UTF16BE.obj:1: the file is not valid UTF-8 text (it is UTF-16; save it as UTF-8)"),
    ),
    ("assimp-quirks/box_longline.obj", RendersWithWarnings(&["box_longline.obj:22: usemtl 'Defauli' without any"])),
    ("assimp-quirks/box_mat_with_spaces.obj", RendersWithWarnings(&["box_spaces.mtl:67: the file is not"])),
    (
        "assimp-quirks/box_without_lineending.obj",
        RendersWithWarnings(&["box_without_lineending.obj:22: usemtl 'Default' without any"]),
    ),
    ("assimp-quirks/concave_polygon.obj", Renders),
    (
        "assimp-quirks/cube_mtllib_after_g.obj",
        RendersWithWarnings(&["cube_mtllib_after_g.obj:2: mtllib 'cube_mtllib_after_g.mat' not found;"]),
    ),
    (
        "assimp-quirks/empty_mat.obj",
        RendersWithWarnings(&[
            "empty_mat.obj:233: 'usemtl' without a name:",
            "empty_mat.mtl:3: 'newmtl' without a name:",
        ]),
    ),
    (
        "assimp-quirks/number_formats.obj",
        Refused("number_formats.obj:11: 'v' argument 3: expected a finite number, got '3.1+e2'"),
    ),
    ("assimp-quirks/space_in_material_name.obj", Renders),
    (
        "assimp-quirks/testmixed.obj",
        RendersWithWarnings(&[
            "testmixed.obj:15: 'l' ignored (line elements,",
            "testmixed.obj:23: 'p' ignored (point elements,",
            "testmixed.obj:14: usemtl 'Default' without any",
        ]),
    ),
    ("beast-ngons/beast.obj", RendersWithWarnings(&["beast.obj:32314: texture coordinates (vt, 33963"])),
    (
        "cornell-glossy-pathed/CornellBox-Glossy.obj",
        RendersWithWarnings(&[
            "CornellBox-Glossy.obj:20: texture coordinates (vt, 6",
            "CornellBox-Glossy.obj:4: mtllib 'scenes/cornell-glossy/CornellBox-Glossy.mtl' not found",
        ]),
    ),
    (
        "cornell-original-pathed/CornellBox-Original.obj",
        RendersWithWarnings(&["CornellBox-Original.obj:12: mtllib 'scenes/CornellBox-Original.mtl' not found"]),
    ),
    ("cornell-original/CornellBox-Original.obj", Renders),
    (
        "cornell-tinyobj/cornell_box.obj",
        RendersWithWarnings(&[
            "cornell_box.mtl:22: material 'light': Ka above 1 and no Ke: read as emission Ke 20 20 20",
        ]),
    ),
    (
        "cornell-water-lab/CornellBox-Water.obj",
        RendersWithWarnings(&[
            "CornellBox-Water.obj:1114: texture coordinates (vt, 1262",
            "CornellBox-Water.obj:15701: 'vn' 0 0 0",
        ]),
    ),
    (
        "crytek-sponza-truncated/sponza.obj",
        RendersWithWarnings(&[
            "sponza.obj:5989: texture coordinates (vt, 19692",
            "sponza.obj:4: mtllib 'sponza.mtl' not found;",
            "sponza.obj: 1 of 33663 triangles",
        ]),
    ),
    ("escher2010/escher2010.obj", RendersWithWarnings(&["escher2010.obj:13: texture coordinates (vt, 12170"])),
    ("legocar-deepexploration/legocar.obj", RendersWithWarnings(&["legocar.obj:1017: texture coordinates (vt, 4"])),
    ("ogre-124k/ogre.obj", Renders),
    (
        "regr01-house/regr01.obj",
        RendersWithWarnings(&[
            "regr01.obj:4841: the file is not",
            "regr01.obj:2646: texture coordinates (vt, 688",
            "regr01.mtl:67: the file is not",
        ]),
    ),
    ("scan-buddha-113k/buddha.obj", Renders),
    ("scan-bunny-smooth-vn/bunny_smooth.obj", Renders),
    ("scan-dragon-100k/dragon.obj", RendersWithWarnings(&["dragon.obj:4: mtllib 'dragon.mtl' not found;"])),
    ("scan-nefertiti-100k/nefertiti.obj", Renders),
    ("scan-stanford-bunny/stanford-bunny.obj", Renders),
    (
        "sibenik-blender/sibenik.obj",
        RendersWithWarnings(&[
            "sibenik.obj:40264: texture coordinates (vt, 72612",
            "sibenik.obj:3: mtllib 'untitled.mtl' not found;",
        ]),
    ),
    (
        "spider-assimp/spider.obj",
        RendersWithWarnings(&[
            "spider.obj:769: texture coordinates (vt, 302",
            "spider.obj:1560: 'vn' 0 0 0",
            "spider.obj: 52 of 1368 triangles",
        ]),
    ),
    (
        "sponza-dabrovic-2005/sponza.obj",
        RendersWithWarnings(&[
            "sponza.obj:157: texture coordinates (vt, 71396",
            "sponza.obj:232632: 'vn' 0 0 0",
            "sponza.obj: 4 of 66454 triangles",
        ]),
    ),
    (
        "tinyobj-issues/invalid-relative-vertex-index.obj",
        Refused("invalid-relative-vertex-index.obj:1: face vertex 1: vertex index -4 out of range (0 define"),
    ),
    (
        "tinyobj-issues/issue-140-zero-face-idx.obj",
        Refused("issue-140-zero-face-idx.obj:16: face vertex 1: vertex index 0 out of range (4 defined so f"),
    ),
    (
        "tinyobj-issues/issue-161-inconsistent-f.obj",
        RendersWithWarnings(&[
            "issue-161-inconsistent-f.obj:13: texture coordinates (vt, 4",
            "issue-161-inconsistent-f.obj:19: usemtl 'cube': no such",
            "cube.mtl:22: material 'light': Ka above 1 and no Ke",
        ]),
    ),
    ("tinyobj-issues/issue-235-usemtl-then-o.obj", Renders),
    ("tinyobj-issues/issue-246-usemtl-whitespace.obj", Renders),
    ("tinyobj-issues/issue-319-002.obj", Renders),
    ("tinyobj-issues/issue-319-003.obj", Renders),
    ("tinyobj-issues/issue-330.obj", Renders),
    (
        "tinyobj-issues/issue-356-leading-spaces-newmtl.obj",
        Refused("issue-356-leading-spaces-newmtl.obj: the OBJ file has no faces"),
    ),
    ("tinyobj-issues/leading-decimal-dot-issue-201.obj", Renders),
    ("tinyobj-issues/leading-zero-in-exponent-notation-issue-210.obj", Renders),
    (
        "tinyobj-issues/missing_material_file.obj",
        RendersWithWarnings(&["missing_material_file.obj:11: usemtl 'white' without any"]),
    ),
    (
        "tinyobj-issues/mtl filename with whitespace issue46.obj",
        RendersWithWarnings(&[
            "mtl filename with whitespace issue46.obj:1: mtllib 'invalid-file-without-spaces.mtl' not found;",
            "mtl filename with whitespace issue46.obj:1: mtllib 'invalid file with",
            "mtl filename with whitespace issue46.obj:1: mtllib 'mtl filename with",
        ]),
    ),
    (
        "tinyobj-issues/mtllib-multiple-files-issue-112.obj",
        RendersWithWarnings(&[
            "mtllib-multiple-files-issue-112.obj:1: mtllib 'invalid-file-aaa.mtl' not found;",
            "mtllib-multiple-files-issue-112.obj:1: mtllib 'invalid-file-bbb.mtl' not found;",
        ]),
    ),
    ("tinyobj-issues/pbr-mat-ext.obj", Renders),
    (
        "tinyobj-issues/smoothing-group-two-squares.obj",
        RendersWithWarnings(&["smoothing-group-two-squares.obj:21: face vertex 1: normal"]),
    ),
    ("tinyobj-issues/test-nan.obj", Refused("test-nan.obj:12: 'v' argument 1: expected a finite number, got 'nan'")),
    (
        "trimesh-quirks/chair_model.obj",
        RendersWithWarnings(&[
            "chair_model.obj:1349: texture coordinates (vt, 9025",
            "chair_model.obj:3: mtllib 'model.mtl' not found;",
        ]),
    ),
    ("trimesh-quirks/fuze.obj", RendersWithWarnings(&["fuze.obj:1022: texture coordinates (vt, 664"])),
    ("trimesh-quirks/groups.obj", Renders),
    (
        "trimesh-quirks/negative_indices.obj",
        RendersWithWarnings(&["negative_indices.obj:9: texture coordinates (vt, 14"]),
    ),
    ("trimesh-quirks/polygonfaces.obj", RendersWithWarnings(&["polygonfaces.obj:1: mtllib 'surface.mtl' not found;"])),
    (
        "trimesh-quirks/quadknot.obj",
        RendersWithWarnings(&[
            "quadknot.obj:2899: texture coordinates (vt, 3",
            "quadknot.obj:12: mtllib './quadknot.obj.mtl' not found;",
        ]),
    ),
    ("trimesh-quirks/rabbit.obj", Renders),
    (
        "trimesh-quirks/wallhole.obj",
        RendersWithWarnings(&[
            "wallhole.obj:4: 'usemtl' without a name:",
            "wallhole.obj:97: texture coordinates (vt, 92",
            "wallhole.obj:282: line continued with '\\'",
            "wallhole.obj:3: mtllib '00.mtl' not found;",
        ]),
    ),
];

/// The wild OBJ corpus (`../shared/corpora/obj-wild`, or `$STRATA_OBJ_WILD`); CI always has it,
/// so a missing corpus fails the test naming the path.
fn wild_corpus() -> PathBuf {
    shared_required("STRATA_OBJ_WILD", "corpora/obj-wild", "SOURCES.md")
}

/// Every `.obj` under `dir`, as paths relative to it, sorted.
fn obj_files(dir: &Path) -> Vec<String> {
    fn walk(d: &Path, root: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, root, out);
            } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("obj")) {
                out.push(p.strip_prefix(root).unwrap().to_string_lossy().into_owned());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// The library outcome: Ok(warnings shown as `file:line: message`) or Err(error shown).
fn outcome(path: &Path) -> Result<Vec<String>, String> {
    obj::scene_from_obj_with_warnings(path, &Limits::default())
        .map(|(desc, w)| {
            assert!(!desc.triangles.is_empty() || !desc.emissive_triangles.is_empty());
            w.iter().map(|w| w.to_string()).collect()
        })
        .map_err(|e| e.to_string())
}

#[test]
fn every_wild_file_has_its_expected_outcome() {
    let dir = wild_corpus();
    let files = obj_files(&dir);
    let dump = std::env::var_os("STRATA_OBJ_WILD_DUMP").is_some();
    let mut problems = Vec::new();
    let (mut renders, mut warned, mut refused) = (0, 0, 0);
    for rel in &files {
        let path = dir.join(rel);
        let t = std::time::Instant::now();
        let got = outcome(&path);
        if dump {
            eprintln!("{rel} ({:.2} s): {got:#?}", t.elapsed().as_secs_f64());
        }
        match &got {
            Ok(w) if w.is_empty() => renders += 1,
            Ok(_) => warned += 1,
            Err(_) => refused += 1,
        }
        let Some((_, want)) = TABLE.iter().find(|(f, _)| f == rel) else {
            problems.push(format!("{rel}: not in the table; got {got:?}"));
            continue;
        };
        let ok = match (want, &got) {
            (Renders, Ok(w)) => w.is_empty(),
            (RendersWithWarnings(subs), Ok(w)) => {
                let shown = path.display().to_string();
                subs.iter().all(|s| w.iter().any(|w| w.contains(s)))
                    && w.iter().all(|w| subs.iter().any(|s| w.contains(s)))
                    && w.iter().all(|w| w.starts_with(&shown) || w.contains(".mtl"))
            }
            (Refused(sub), Err(e)) => e.contains(sub) && e.starts_with(&path.display().to_string()),
            _ => false,
        };
        if !ok {
            problems.push(format!("{rel}: expected {want:?}, got {got:#?}"));
        }
    }
    for (f, _) in TABLE {
        if !files.iter().any(|g| g == f) {
            problems.push(format!("{f}: in the table but not in the corpus"));
        }
    }
    eprintln!("{} files: {renders} render, {warned} render with warnings, {refused} refused", files.len());
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Every file the `tobj` crate loads (triangulated, with at least one triangle) loads here too.
#[test]
fn every_file_tobj_loads_renders() {
    let dir = wild_corpus();
    let options = tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
    let mut problems = Vec::new();
    for rel in obj_files(&dir) {
        let path = dir.join(&rel);
        let tobj_tris = match tobj::load_obj(&path, &options) {
            Ok((models, _)) => models.iter().map(|m| m.mesh.indices.len() / 3).sum::<usize>(),
            Err(_) => 0,
        };
        if tobj_tris == 0 {
            continue;
        }
        // The same fan triangulation; `tobj` also makes faces of `l` polylines (strata ignores them).
        match obj::load_with_warnings(&path) {
            Ok((mesh, w))
                if mesh.faces.len() == tobj_tris || w.iter().any(|w| w.message.starts_with("'l' ignored")) => {}
            Ok((mesh, _)) => problems.push(format!("{rel}: {} triangles, tobj {tobj_tris}", mesh.faces.len())),
            Err(e) => problems.push(format!("{rel}: tobj loads {tobj_tris} triangles, strata refuses: {e}")),
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Vertex normals are kept, unit length, one triple per triangle; broken ones are dropped.
#[test]
fn vertex_normals_are_kept_and_validated() {
    let dir = wild_corpus();
    let (mesh, w) = obj::load_with_warnings(&dir.join("scan-bunny-smooth-vn/bunny_smooth.obj")).unwrap();
    assert!(w.is_empty(), "{w:?}");
    assert_eq!(mesh.face_normals.len(), mesh.faces.len());
    assert!(mesh.face_normals.iter().flatten().all(|&n| (mesh.normals[n as usize].length() - 1.0).abs() < 1e-5));
    // v//vn corners whose vn lines are commented out: no normals, one warning, still loads.
    let (mesh, w) = obj::load_with_warnings(&dir.join("tinyobj-issues/smoothing-group-two-squares.obj")).unwrap();
    assert!(mesh.normals.is_empty() && mesh.face_normals.is_empty());
    assert_eq!(w.len(), 1, "{w:?}");
    // No vn at all: nothing.
    let (mesh, _) = obj::load_with_warnings(&dir.join("scan-buddha-113k/buddha.obj")).unwrap();
    assert!(mesh.normals.is_empty() && mesh.face_normals.is_empty());
}

/// Real renders through the command line: warnings on stderr with file:line, refusals with exit
/// status 1 and file:line.
#[test]
fn cli_renders_representative_files() {
    let dir = wild_corpus();
    let out = tmpdir("objwild");
    for (rel, warning) in [
        ("cornell-original/CornellBox-Original.obj", None),
        ("trimesh-quirks/wallhole.obj", Some("wallhole.obj:282: line continued")),
        ("regr01-house/regr01.obj", Some("read as Latin-1")),
        ("cornell-original-pathed/CornellBox-Original.obj", Some("beside the OBJ")),
        ("sibenik-blender/sibenik.obj", Some("using 'sibenik.mtl' beside the OBJ")),
    ] {
        let r = strata()
            .arg("render")
            .arg(dir.join(rel))
            .args(["--spp", "1", "--size", "32x24", "--threads", "2", "-q", "-o"])
            .arg(out.join("img"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(r.status.success(), "{rel}: {err}");
        assert!(out.join("img.png").is_file(), "{rel}");
        match warning {
            None => assert!(!err.contains("warning"), "{rel}: {err}"),
            Some(w) => {
                assert!(err.lines().any(|l| l.starts_with("strata: warning: ") && l.contains(w)), "{rel}: {err}")
            }
        }
        std::fs::remove_file(out.join("img.png")).unwrap();
    }
    let r = strata().arg("render").arg(dir.join("tinyobj-issues/test-nan.obj")).args(["-q"]).output().unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains("test-nan.obj:12: 'v' argument 1: expected a finite number, got 'nan'"), "{err}");
}

/// The automatic camera of the scenes the README's gallery shows, asserted from the camera chosen
/// (not from pixels): the up axis guessed from the bounds, the interiors seen from inside, the
/// Cornell boxes looked into through their open side and filling the frame, the objects from
/// outside and not from above.
#[test]
fn wild_scenes_get_the_up_axis_and_the_view_they_need() {
    use strata::scene::obj::frame::{frame_scene, UpAxis, View};
    let dir = wild_corpus();
    for (rel, up, view) in [
        ("scan-stanford-bunny/stanford-bunny.obj", UpAxis::Y, View::Exterior),
        ("sponza-dabrovic-2005/sponza.obj", UpAxis::Y, View::Interior),
        ("crytek-sponza-truncated/sponza.obj", UpAxis::Y, View::Interior),
        ("sibenik-blender/sibenik.obj", UpAxis::Y, View::Interior),
        ("regr01-house/regr01.obj", UpAxis::Z, View::Exterior),
        ("cornell-original/CornellBox-Original.obj", UpAxis::Y, View::Opening),
        ("cornell-tinyobj/cornell_box.obj", UpAxis::Y, View::Opening),
    ] {
        let (desc, _) = obj::scene_from_obj_with_warnings(&dir.join(rel), &Limits::default()).unwrap();
        let f = frame_scene(&desc, None, 4.0 / 3.0).unwrap();
        assert_eq!((f.up, f.up_guessed, f.view), (up, true, view), "{rel}: {f:?}");
        let c = f.camera;
        assert_eq!(c.up, up.vec(), "{rel}");
        let tris = desc.triangles.iter().map(|t| t.v).chain(desc.emissive_triangles.iter().map(|t| t.v));
        let (lo, hi) = obj::bounds(tris.flatten()).unwrap();
        let inside = c.eye.cmpge(lo).all() && c.eye.cmple(hi).all();
        let dir_ = (c.center - c.eye).normalize();
        let elevation = dir_.dot(-up.vec()).asin().to_degrees();
        match view {
            View::Interior => {
                assert!(inside, "{rel}: eye {} outside {lo}..{hi}", c.eye);
                assert!(elevation.abs() < 1.0, "{rel}: looks level, not {elevation} degrees down");
                assert!(f.interior_light.is_some(), "{rel}");
            }
            View::Exterior => {
                assert!(!inside, "{rel}");
                // Seen from the front, slightly above (the z-up house was seen from straight above).
                assert!((10.0..30.0).contains(&elevation), "{rel}: {elevation} degrees down");
            }
            View::Opening => {
                assert!(!inside && elevation.abs() < 1.0, "{rel}");
                // Fills the frame: the open side's rectangle spans the full height of the image
                // (its top and bottom edges at the edges of the 45-degree field).
                let u = up.index();
                let d = (c.eye - 0.5 * (lo + hi)).abs();
                let k = if d.x > d.z { 0 } else { 2 };
                let near = if c.eye[k] > hi[k] { hi[k] } else { lo[k] };
                let half = 0.5 * (hi[u] - lo[u]);
                let tan = half / (c.eye[k] - near).abs();
                assert!((tan - 22.5f32.to_radians().tan()).abs() < 0.01, "{rel}: tan {tan}");
            }
        }
    }
    // The tinyobj box is open at -z (its classic camera stands at z = -800).
    let (desc, _) =
        obj::scene_from_obj_with_warnings(&dir.join("cornell-tinyobj/cornell_box.obj"), &Limits::default()).unwrap();
    assert!(desc.camera.unwrap().eye.z < 0.0);
    // And it is lit: its 'light' (Ka 20 20 20, no Ke) is an emitter.
    assert_eq!(desc.emissive_triangles.len(), 2);
}

/// The CLI announces the up axis and prints the automatic camera as a `--camera` line: pasting
/// it renders the same image; `--up` is obeyed and said to be.
#[test]
fn the_printed_camera_renders_the_same_image() {
    let dir = wild_corpus();
    let out = tmpdir("objwild-camera");
    let scene = dir.join("cornell-original/CornellBox-Original.obj");
    let run = |extra: &[&str], stem: &str| {
        let r = strata()
            .arg("render")
            .arg(&scene)
            .args(["--spp", "2", "--size", "32x24", "--threads", "2", "-o"])
            .arg(out.join(stem))
            .args(extra)
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        String::from_utf8_lossy(&r.stderr).into_owned()
    };
    let err = run(&[], "auto");
    assert!(
        err.contains("up axis y (guessed from its bounds; set it with --up x|y|z); looking in through the open side"),
        "{err}"
    );
    let line = err.lines().find_map(|l| l.split_once("automatic camera, to edit: --camera \"")).expect(&err).1;
    let cam = line.trim_end_matches('"');
    run(&["--camera", cam], "pasted");
    assert_eq!(std::fs::read(out.join("auto.png")).unwrap(), std::fs::read(out.join("pasted.png")).unwrap());
    let pixels = |stem: &str| strata::film::read_exr(&out.join(format!("{stem}.exr"))).unwrap().rgb;
    assert!(pixels("auto") == pixels("pasted"), "the pasted camera renders the same EXR pixels");
    let err = run(&["--up", "z"], "zup");
    assert!(err.contains("up axis z (from --up)"), "{err}");
    let r = strata().arg("render").arg(&scene).args(["--up", "w"]).output().unwrap();
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("expected x, y or z, got `w`"));
}

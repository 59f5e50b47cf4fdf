//! Wavefront OBJ/MTL meshes through `tobj`: as a whole scene (`strata render model.obj`) or placed
//! into a `.test` scene by the `obj FILE` command (see `scene::parse`).
//!
//! Faces are triangulated (fans); only positions are used (normals and texture coordinates are read
//! and ignored: shading uses the geometric normal). Materials, per face:
//! - a face whose MTL material has a non-zero `Ke` is an area light: radiance `Ke`, emitted on one
//!   side only, towards `(v1 - v0) x (v2 - v0)` of its (transformed) vertices, i.e. the side from
//!   which the face is wound counter-clockwise; it reflects nothing (black), like a `quadLight`;
//! - otherwise `Kd` -> `diffuse`, `Ks` -> `specular`, `Ns` -> `shininess` (modified Phong), each
//!   taken from the MTL where it gives it and from the *current material* where it does not; every
//!   other field (`emission`, `ambient`, `brdf`, `roughness`) is the current material's. A face with
//!   no MTL material (no `usemtl`, unknown name, missing library) gets the current material.
//!
//! The current material is the `.test` material state where the `obj` command appears, and
//! [`whole_scene_material`] for a whole-scene OBJ.
//!
//! Errors name the file and the 1-based line. `tobj` reports only a kind of error (and skips some bad
//! lines silently), so every file is first checked line by line by [`locate_obj_error`] /
//! [`locate_mtl_error`], which give the line and the reason.
//! Nothing here panics on bad input (a panic inside `tobj` would be caught and reported).

use crate::scene::desc::{CameraDesc, ImportanceSampling, IntegratorKind, Material, Nee, SceneDesc};
use crate::scene::error::{LineError, SceneError};
use crate::scene::limits::Limits;
use glam::Vec3;
use std::cell::RefCell;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One MTL material: the fields strata uses, `None` where the MTL does not give them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MtlMaterial {
    /// `newmtl` name
    pub name: String,
    /// `Kd`
    pub kd: Option<Vec3>,
    /// `Ks`
    pub ks: Option<Vec3>,
    /// `Ns`
    pub ns: Option<f32>,
    /// `Ke`
    pub ke: Option<Vec3>,
}

impl MtlMaterial {
    /// Radiance if this material makes its faces area lights (`Ke` given and not all zero).
    pub fn emission(&self) -> Option<Vec3> {
        self.ke.filter(|k| *k != Vec3::ZERO)
    }

    /// The material of a non-emissive face: MTL fields where given, `current` elsewhere.
    pub fn resolve(&self, current: &Material) -> Material {
        Material {
            diffuse: self.kd.unwrap_or(current.diffuse),
            specular: self.ks.unwrap_or(current.specular),
            shininess: self.ns.unwrap_or(current.shininess),
            ..*current
        }
    }
}

/// A loaded OBJ: triangles over one position array, with their MTL material.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjMesh {
    /// vertex positions, as in the file
    pub positions: Vec<Vec3>,
    /// triangles (indices into `positions`)
    pub faces: Vec<[u32; 3]>,
    /// per triangle: index into `materials`, or `u32::MAX` for none
    pub face_material: Vec<u32>,
    /// the MTL materials
    pub materials: Vec<MtlMaterial>,
}

impl ObjMesh {
    /// Axis-aligned bounds of the positions used by faces (None without faces).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        bounds(self.faces.iter().flatten().map(|&i| self.positions[i as usize]))
    }
}

/// Bounds of points (None if there are none).
pub fn bounds(points: impl Iterator<Item = Vec3>) -> Option<(Vec3, Vec3)> {
    points.fold(None, |b, p| Some(b.map_or((p, p), |(lo, hi): (Vec3, Vec3)| (lo.min(p), hi.max(p)))))
}

fn err(file: &Path, line: usize, message: impl Into<String>) -> SceneError {
    SceneError::new(file, line, message)
}

/// Loads `path` and its material libraries (relative to its directory).
pub fn load(path: &Path) -> Result<ObjMesh, SceneError> {
    let bytes = std::fs::read(path).map_err(|e| err(path, 0, format!("cannot read OBJ file: {e}")))?;
    let text = std::str::from_utf8(&bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()].iter().filter(|&&b| b == b'\n').count() + 1;
        err(path, line, "the file is not valid UTF-8 text")
    })?;
    // tobj skips some malformed lines silently (a face of two vertices, say): check every line first.
    if let Some((line, msg)) = locate_obj_error(text) {
        return Err(err(path, line, msg));
    }
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    // MTL failures, with the library's path, captured from the loader callback.
    let mtl_error: RefCell<Option<SceneError>> = RefCell::new(None);
    let options = tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &options, |mtl: &Path| {
            let mtl_path = dir.join(mtl);
            load_mtl(&mtl_path).unwrap_or_else(|e| {
                mtl_error.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::MaterialParseError)
            })
        })
    }));
    let (models, materials) = match result {
        Err(_) => return Err(err(path, 0, "the OBJ parser failed on this file (internal panic caught)")),
        Ok(Err(e)) => {
            let (line, msg) = locate_obj_error(text).unwrap_or((0, format!("malformed OBJ ({e})")));
            return Err(err(path, line, msg));
        }
        Ok(Ok(v)) => v,
    };
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let materials = materials.map_err(|e| err(path, 0, format!("material library: {e}")))?;
    let materials: Vec<MtlMaterial> = materials
        .into_iter()
        .map(|m| MtlMaterial {
            name: m.name,
            kd: m.diffuse.map(Vec3::from_array),
            ks: m.specular.map(Vec3::from_array),
            ns: m.shininess,
            ke: m.emissive.map(Vec3::from_array),
        })
        .collect();
    let mut mesh = ObjMesh { materials, ..Default::default() };
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len();
        let n_pos = m.positions.len() / 3;
        mesh.positions.extend(m.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        let mat = m.material_id.filter(|&i| i < mesh.materials.len()).map_or(u32::MAX, |i| i as u32);
        for f in m.indices.chunks_exact(3) {
            if f.iter().any(|&i| i as usize >= n_pos) {
                let (line, msg) = locate_obj_error(text).unwrap_or((0, "face vertex index out of range".into()));
                return Err(err(path, line, msg));
            }
            let idx = [f[0], f[1], f[2]].map(|i| u32::try_from(base + i as usize).unwrap_or(u32::MAX));
            if idx.contains(&u32::MAX) {
                return Err(err(path, 0, "more than 2^32 vertices"));
            }
            mesh.faces.push(idx);
            mesh.face_material.push(mat);
        }
    }
    if mesh.positions.iter().any(|p| !p.is_finite()) {
        let (line, msg) = locate_obj_error(text).unwrap_or((0, "vertex position is not a finite number".into()));
        return Err(err(path, line, msg));
    }
    if mesh.faces.is_empty() {
        return Err(err(path, 0, "the OBJ file has no faces"));
    }
    Ok(mesh)
}

/// Loads one MTL library, checking every value strata uses (finite; colours and `Ns` >= 0).
fn load_mtl(path: &Path) -> Result<tobj::MTLLoadResult, SceneError> {
    let bytes = std::fs::read(path).map_err(|e| err(path, 0, format!("cannot read material library: {e}")))?;
    let text = std::str::from_utf8(&bytes).map_err(|_| err(path, 0, "the material library is not valid UTF-8 text"))?;
    if let Some((line, msg)) = locate_mtl_error(text) {
        return Err(err(path, line, msg));
    }
    let loaded = tobj::load_mtl_buf(&mut text.as_bytes());
    if let Err(e) = &loaded {
        return Err(err(path, 0, format!("malformed material library ({e})")));
    }
    Ok(loaded)
}

/// The non-blank lines of OBJ/MTL text as (1-based line number, command, arguments), comments
/// (`#` to the end of the line) removed.
fn commands(text: &str) -> impl Iterator<Item = (usize, &str, Vec<&str>)> {
    text.split('\n').enumerate().filter_map(|(k, raw)| {
        let mut tok = raw.split('#').next().unwrap_or_default().split_ascii_whitespace();
        let cmd = tok.next()?;
        Some((k + 1, cmd, tok.collect()))
    })
}

/// First line of OBJ text that strata or tobj cannot read, with the reason: `v` needs 3 finite
/// numbers, `vt` 1 to 3 numbers, `vn` 3 numbers, `f` at least 3 vertex references `i`, `i/t`,
/// `i//n` or `i/t/n` with non-zero indices inside the lists read so far (negative = relative).
pub fn locate_obj_error(text: &str) -> Option<(usize, String)> {
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    for (line, cmd, args) in commands(text) {
        let floats = |min: usize, max: usize, what: &str| -> Result<(), LineError> {
            if args.len() < min || args.len() > max {
                let want = if min == max { format!("{min}") } else { format!("{min} to {max}") };
                return Err(format!("'{cmd}' expects {want} numbers ({what}), got {}", args.len()).into());
            }
            for (i, a) in args.iter().enumerate() {
                match a.parse::<f32>() {
                    Ok(v) if v.is_finite() => {}
                    _ => {
                        return Err(
                            format!("'{cmd}' argument {}: expected a finite number, got '{}'", i + 1, short(a)).into()
                        )
                    }
                }
            }
            Ok(())
        };
        let r = match cmd {
            "v" => floats(3, 7, "x y z [w] or x y z r g b").map(|_| nv += 1),
            "vt" => floats(1, 3, "u [v [w]]").map(|_| nt += 1),
            "vn" => floats(3, 3, "x y z").map(|_| nn += 1),
            "f" => face(&args, nv, nt, nn),
            _ => Ok(()),
        };
        if let Err(m) = r {
            return Some((line, m.0));
        }
    }
    None
}

fn face(args: &[&str], nv: i64, nt: i64, nn: i64) -> Result<(), LineError> {
    if args.len() < 3 {
        return Err(format!("face 'f' needs at least 3 vertices, got {}", args.len()).into());
    }
    for (j, a) in args.iter().enumerate() {
        let parts: Vec<&str> = a.split('/').collect();
        if parts.len() > 3 {
            return Err(format!("face vertex {}: '{}' is not i, i/t, i//n or i/t/n", j + 1, short(a)).into());
        }
        for (p, (&s, (n, what))) in
            parts.iter().zip([(nv, "vertex"), (nt, "texture coordinate"), (nn, "normal")]).enumerate()
        {
            if s.is_empty() && p > 0 {
                continue;
            }
            let i: i64 = s.parse().map_err(|_| format!("face vertex {}: '{}' is not an index", j + 1, short(a)))?;
            let ok = if i > 0 { i <= n } else { i < 0 && -i <= n };
            if !ok {
                return Err(format!("face vertex {}: {what} index {i} out of range ({n} defined so far)", j + 1).into());
            }
        }
    }
    Ok(())
}

/// First line of MTL text with a value strata cannot use: `Ka Kd Ks Ke Tf` need 3 finite,
/// non-negative numbers, `Ns` one, `Ni d Tr` one finite number, `newmtl` a name; and no colour may
/// come before the first `newmtl`.
pub fn locate_mtl_error(text: &str) -> Option<(usize, String)> {
    let mut seen_newmtl = false;
    for (line, cmd, args) in commands(text) {
        let numbers = |n: usize, non_negative: bool| -> Result<(), LineError> {
            if args.len() != n {
                return Err(
                    format!("'{cmd}' expects {n} number{}, got {}", if n == 1 { "" } else { "s" }, args.len()).into()
                );
            }
            for (i, a) in args.iter().enumerate() {
                match a.parse::<f32>() {
                    Ok(v) if v.is_finite() && (!non_negative || v >= 0.0) => {}
                    Ok(_) if non_negative => {
                        return Err(format!(
                            "'{cmd}' argument {}: expected a finite number >= 0, got '{}'",
                            i + 1,
                            short(a)
                        )
                        .into())
                    }
                    _ => {
                        return Err(
                            format!("'{cmd}' argument {}: expected a finite number, got '{}'", i + 1, short(a)).into()
                        )
                    }
                }
            }
            Ok(())
        };
        let r = match cmd {
            "newmtl" => {
                seen_newmtl = true;
                if args.is_empty() {
                    Err("'newmtl' expects a material name".into())
                } else {
                    Ok(())
                }
            }
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" | "Ns" | "Ni" | "d" | "Tr" if !seen_newmtl => {
                Err(format!("'{cmd}' before any 'newmtl'").into())
            }
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => numbers(3, true),
            "Ns" => numbers(1, true),
            "Ni" | "d" | "Tr" => numbers(1, false),
            _ => Ok(()),
        };
        if let Err(m) = r {
            return Some((line, m.0));
        }
    }
    None
}

fn short(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((cut, _)) => format!("{}...", &s[..cut]),
        None => s.to_string(),
    }
}

/// The current material of a whole-scene OBJ: grey diffuse 0.8, no ambient (faces without an MTL
/// material get it; MTL fields override it as in the module docs).
pub fn whole_scene_material() -> Material {
    Material { diffuse: Vec3::splat(0.8), ambient: Vec3::ZERO, ..Material::default() }
}

/// Camera framing the box `lo..hi`: looking along -z at its centre from +z (OBJ's convention: y up),
/// far enough that the bounding sphere fits the vertical field of view `fovy_deg` (and so the
/// horizontal one of any image at least as wide as tall).
pub fn frame_camera(lo: Vec3, hi: Vec3, fovy_deg: f32) -> CameraDesc {
    let center = 0.5 * (lo + hi);
    let r = (0.5 * (hi - lo).length()).max(1e-3);
    let dist = r / (0.5 * fovy_deg.to_radians()).sin();
    CameraDesc { eye: center + Vec3::Z * dist, center, up: Vec3::Y, fovy_deg }
}

/// A whole scene from one OBJ: its triangles (materials as in the module docs, current material
/// [`whole_scene_material`]), a camera from [`frame_camera`] at 45 degrees (replace it with
/// `--camera`), 640x480, 16 spp, gamma 2.2, `pathtracer` with `nexteventestimation mis`,
/// `importancesampling brdf`, `maxdepth 5`, output named after the file.
pub fn scene_from_obj(path: &Path, limits: &Limits) -> Result<SceneDesc, SceneError> {
    let mesh = load(path)?;
    let mut desc = SceneDesc {
        source: path.to_path_buf(),
        spp: 16,
        gamma: 2.2,
        integrator: IntegratorKind::PathTracer,
        nee: Nee::Mis,
        importance_sampling: ImportanceSampling::Brdf,
        max_depth: 5,
        output: path.file_stem().map(|s| format!("{}.png", s.to_string_lossy())),
        ..SceneDesc::default()
    };
    let (lo, hi) = mesh.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
    desc.camera = Some(frame_camera(lo, hi, 45.0));
    if mesh.faces.len() > limits.max_primitives {
        return Err(err(path, 0, format!("more than {} triangles (--max-primitives)", limits.max_primitives)));
    }
    let current = whole_scene_material();
    let mut index_of = std::collections::HashMap::new();
    place(&mesh, &current, Ok, &mut desc, &mut |m: Material, d: &mut SceneDesc| {
        let key: Vec<u32> = [m.diffuse, m.specular, m.emission, m.ambient]
            .iter()
            .flat_map(|v| v.to_array())
            .chain([m.shininess, m.roughness])
            .map(f32::to_bits)
            .collect();
        Ok(*index_of.entry(key).or_insert_with(|| {
            d.materials.push(m);
            d.materials.len() as u32 - 1
        }))
    })
    .map_err(|m| m.at(path, 0))?;
    Ok(desc)
}

/// Adds `mesh` to `desc`: every face's vertices through `to_world`, emissive faces to
/// `emissive_triangles`, the others to `triangles` with the material `intern` returns an index for.
pub fn place(
    mesh: &ObjMesh,
    current: &Material,
    to_world: impl Fn(Vec3) -> Result<Vec3, LineError>,
    desc: &mut SceneDesc,
    intern: &mut dyn FnMut(Material, &mut SceneDesc) -> Result<u32, LineError>,
) -> Result<(), LineError> {
    use crate::scene::desc::{EmissiveTriangleDesc, TriangleDesc};
    // One resolved material index per MTL material (and one for "none"), computed on first use.
    let mut resolved: Vec<Option<u32>> = vec![None; mesh.materials.len() + 1];
    let world: Vec<Vec3> = mesh.positions.iter().map(|&p| to_world(p)).collect::<Result<_, _>>()?;
    for (f, &mi) in mesh.faces.iter().zip(&mesh.face_material) {
        let v = f.map(|i| world[i as usize]);
        let mtl = mesh.materials.get(mi as usize);
        if let Some(radiance) = mtl.and_then(MtlMaterial::emission) {
            desc.emissive_triangles.push(EmissiveTriangleDesc { v, radiance });
            continue;
        }
        let slot = if mtl.is_some() { mi as usize } else { mesh.materials.len() };
        let material = match resolved[slot] {
            Some(i) => i,
            None => {
                let m = mtl.map_or(*current, |m| m.resolve(current));
                let i = intern(m, desc)?;
                resolved[slot] = Some(i);
                i
            }
        };
        desc.triangles.push(TriangleDesc { v, material });
    }
    Ok(())
}

/// A procedural test mesh of at least `min_triangles` triangles: a bumpy torus (2 n x n quads, no
/// degenerate triangles) tilted towards +z, on a floor before a wall, under an emissive patch
/// (2 x 2 n^2 + 6 triangles); material names
/// `torus`, `floor`, `light` (see [`write_obj`]).
pub fn procedural_mesh(min_triangles: usize) -> ObjMesh {
    let n = ((min_triangles as f64 / 4.0).sqrt().ceil() as usize).max(3);
    let (nu, nv) = (2 * n, n);
    let (big_r, small_r) = (1.0f32, 0.35f32);
    let tilt = glam::Mat3::from_rotation_x(1.0);
    let mut mesh = ObjMesh::default();
    for i in 0..nu {
        let u = i as f32 / nu as f32 * std::f32::consts::TAU;
        for j in 0..nv {
            let v = j as f32 / nv as f32 * std::f32::consts::TAU;
            let bump = 1.0 + 0.08 * (7.0 * u).sin() * (5.0 * v).sin();
            let r = small_r * bump;
            let p = Vec3::new((big_r + r * v.cos()) * u.cos(), r * v.sin(), (big_r + r * v.cos()) * u.sin());
            mesh.positions.push(tilt * p);
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            mesh.faces.push([a, c, b]);
            mesh.faces.push([a, d, c]);
        }
    }
    mesh.face_material = vec![0; mesh.faces.len()];
    let mut quad = |corners: [Vec3; 4], material: u32| {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(corners);
        mesh.faces.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        mesh.face_material.extend([material, material]);
    };
    // Floor below the torus (facing +y), a wall behind it (facing +z), a light above (facing -y).
    let (y0, y1, e) = (-1.2, 1.6, 1.6);
    quad([Vec3::new(-e, y0, -e), Vec3::new(-e, y0, e), Vec3::new(e, y0, e), Vec3::new(e, y0, -e)], 1);
    quad([Vec3::new(-e, y0, -e), Vec3::new(e, y0, -e), Vec3::new(e, y1 + 0.2, -e), Vec3::new(-e, y1 + 0.2, -e)], 1);
    quad([Vec3::new(-0.5, y1, -0.5), Vec3::new(0.5, y1, -0.5), Vec3::new(0.5, y1, 0.5), Vec3::new(-0.5, y1, 0.5)], 2);
    mesh.materials = vec![
        MtlMaterial {
            name: "torus".into(),
            kd: Some(Vec3::new(0.7, 0.45, 0.3)),
            ks: Some(Vec3::splat(0.2)),
            ns: Some(40.0),
            ke: None,
        },
        MtlMaterial { name: "floor".into(), kd: Some(Vec3::splat(0.6)), ks: None, ns: None, ke: None },
        MtlMaterial { name: "light".into(), kd: Some(Vec3::ZERO), ks: None, ns: None, ke: Some(Vec3::splat(20.0)) },
    ];
    mesh
}

/// Writes `mesh` as `path` (OBJ, one `usemtl` per run of faces) and `path` with extension `.mtl`
/// (its materials). Returns the MTL path.
pub fn write_obj(path: &Path, mesh: &ObjMesh) -> std::io::Result<PathBuf> {
    let mtl_path = path.with_extension("mtl");
    let mtl_name = mtl_path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut m = std::io::BufWriter::new(std::fs::File::create(&mtl_path)?);
    for mat in &mesh.materials {
        writeln!(m, "newmtl {}", mat.name)?;
        let v3 = |k: &str, v: Option<Vec3>| v.map(|v| format!("{k} {} {} {}\n", v.x, v.y, v.z)).unwrap_or_default();
        write!(m, "{}{}{}", v3("Kd", mat.kd), v3("Ks", mat.ks), v3("Ke", mat.ke))?;
        if let Some(ns) = mat.ns {
            writeln!(m, "Ns {ns}")?;
        }
    }
    m.flush()?;
    let mut w = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(path)?);
    writeln!(w, "# strata procedural mesh: {} triangles\nmtllib {mtl_name}", mesh.faces.len())?;
    for p in &mesh.positions {
        writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
    }
    let mut current = u32::MAX - 1;
    for (f, &mi) in mesh.faces.iter().zip(&mesh.face_material) {
        if mi != current {
            if let Some(mat) = mesh.materials.get(mi as usize) {
                writeln!(w, "usemtl {}", mat.name)?;
            }
            current = mi;
        }
        writeln!(w, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1)?;
    }
    w.flush()?;
    Ok(mtl_path)
}

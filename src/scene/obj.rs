//! Wavefront OBJ/MTL meshes: as a whole scene (`strata render model.obj`) or placed into a `.test`
//! scene by the `obj FILE` command (see `scene::parse`).
//!
//! The OBJ is read by [`parse_obj`] (here, not `tobj`: real-world files need repairs `tobj` cannot
//! make); MTL libraries are checked by [`locate_mtl_error`] and read by `tobj::load_mtl_buf`.
//! Faces are triangulated as fans `(c0, ci, ci+1)`, as `tobj` does. Positions are used for
//! geometry; vertex normals (`vn`, validated, unit length: [`ObjMesh::normals`] /
//! [`ObjMesh::face_normals`]) become per-corner shading normals ([`place`]; see
//! `scene::build` for interpolation and the consistency guard); texture
//! coordinates are read, checked and ignored. Materials, per face:
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
//! Real errors (unreadable or UTF-16 files, malformed numbers, non-finite positions, bad face
//! indices, malformed MTL values, no faces) are refused with the file and the 1-based line.
//! What mainstream loaders (tinyobjloader, Blender, assimp) accept is loaded, and each repair or
//! ignored feature gives one [`ObjWarning`] with file and line:
//! - a missing `mtllib` file: tried at its path, then by its base name beside the OBJ (paths
//!   relative to some other directory), then, when no library of the OBJ is found at all,
//!   `<obj stem>.mtl` beside the OBJ; otherwise skipped (default materials when none is found);
//! - several files on one `mtllib` line, and `\ `-escaped spaces in their names;
//! - text that is not UTF-8 is read as Latin-1 (names and comments; numbers must still parse);
//! - `\` at the end of a line continues it on the next one;
//! - an empty `usemtl` or an unknown material name: the current material;
//! - texture coordinates, `l`/`p` elements, curves and unknown keywords are ignored;
//! - broken vertex normals (malformed or non-finite or zero `vn`, out-of-range normal indices): the
//!   faces using them get none;
//! - `v x y z w` with `w = 0`: `w` ignored (otherwise positions are divided by `w`, as in `tobj`);
//!   extra numbers after `x y z` (colours) ignored;
//! - in an MTL: `newmtl` without a name (the material an empty `usemtl` selects), and `Ka`/`Kd`/
//!   `Ks`/`Ke`/`Tf` with one number `r` (`r r r`, as the MTL spec defines it).
//!
//! [`load`] and [`scene_from_obj`] print the warnings to stderr (`strata: warning: FILE:LINE: ...`);
//! [`load_with_warnings`] and [`scene_from_obj_with_warnings`] return them instead.
//! Nothing here panics on bad input (a panic inside `tobj` would be caught and reported).

use crate::scene::desc::{CameraDesc, ImportanceSampling, IntegratorKind, Material, Nee, SceneDesc};
use crate::scene::error::{LineError, SceneError};
use crate::scene::limits::Limits;
use glam::Vec3;
use std::borrow::Cow;
use std::collections::HashMap;
use std::fmt;
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

/// "No normal" in [`ObjMesh::face_normals`].
pub const NO_NORMAL: u32 = u32::MAX;

/// A loaded OBJ: triangles over one position array, with their MTL material and vertex normals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjMesh {
    /// vertex positions, as in the file (one per `v` line, in order)
    pub positions: Vec<Vec3>,
    /// triangles (indices into `positions`)
    pub faces: Vec<[u32; 3]>,
    /// per triangle: index into `materials`, or `u32::MAX` for none
    pub face_material: Vec<u32>,
    /// the MTL materials
    pub materials: Vec<MtlMaterial>,
    /// vertex normals, one per `vn` line in order, normalized; an invalid one (not finite, zero
    /// length, malformed) is stored as `Vec3::ZERO` and never referenced. Empty when no triangle has
    /// normals.
    pub normals: Vec<Vec3>,
    /// per triangle, the indices into `normals` of its three corners (same corner order as
    /// `faces`), or `[NO_NORMAL; 3]` when any corner has no valid normal. Empty (not
    /// `faces.len()` long) when no triangle has normals.
    pub face_normals: Vec<[u32; 3]>,
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

/// Something repaired or ignored while loading an OBJ or MTL file (see the module docs).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ObjWarning {
    /// the OBJ or MTL file
    pub file: PathBuf,
    /// 1-based line; 0 when not tied to a line
    pub line: usize,
    /// what was repaired or ignored, and how
    pub message: String,
}

impl fmt::Display for ObjWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}: {}", self.file.display(), self.message)
        } else {
            write!(f, "{}:{}: {}", self.file.display(), self.line, self.message)
        }
    }
}

/// Prints warnings to stderr, one line each: `strata: warning: FILE:LINE: message`.
pub fn print_warnings(warnings: &[ObjWarning]) {
    let mut e = std::io::stderr().lock();
    for w in warnings {
        let _ = writeln!(e, "strata: warning: {w}");
    }
}

fn err(file: &Path, line: usize, message: impl Into<String>) -> SceneError {
    SceneError::new(file, line, message)
}

fn warn(file: &Path, line: usize, message: impl Into<String>) -> ObjWarning {
    ObjWarning { file: file.to_path_buf(), line, message: message.into() }
}

/// Decoded text of an OBJ/MTL file: UTF-8 (a BOM dropped), else Latin-1 (one char per byte) with
/// the line of the first byte that is not UTF-8. UTF-16 (a UTF-16 BOM or NUL bytes) is refused with
/// the line where it shows.
fn decode(bytes: &[u8]) -> Result<(Cow<'_, str>, Option<usize>), (usize, String)> {
    let line_at = |i: usize| bytes[..i].iter().filter(|&&b| b == b'\n').count() + 1;
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    if bytes.starts_with(b"\xfe\xff") || bytes.starts_with(b"\xff\xfe") {
        return Err((1, "the file is not valid UTF-8 text (it is UTF-16; save it as UTF-8)".into()));
    }
    if let Some(i) = bytes.iter().position(|&b| b == 0) {
        return Err((line_at(i), "the file is not valid UTF-8 text (a NUL byte: UTF-16 or binary?)".into()));
    }
    match std::str::from_utf8(bytes) {
        Ok(t) => Ok((Cow::Borrowed(t), None)),
        Err(e) => Ok((Cow::Owned(bytes.iter().map(|&b| b as char).collect()), Some(line_at(e.valid_up_to())))),
    }
}

const LATIN1: &str = "the file is not valid UTF-8 text; read as Latin-1";

/// Reads and decodes `path`; `what` names the file kind in the "cannot read" error.
fn read_text(path: &Path, what: &str, warnings: &mut Vec<ObjWarning>) -> Result<(String, bool), SceneError> {
    let bytes = std::fs::read(path).map_err(|e| err(path, 0, format!("cannot read {what}: {e}")))?;
    let (text, latin1) = decode(&bytes).map_err(|(line, m)| err(path, line, m))?;
    if let Some(line) = latin1 {
        warnings.push(warn(path, line, format!("{LATIN1} (ISO 8859-1)")));
    }
    Ok((text.into_owned(), latin1.is_some()))
}

/// Loads `path` and its material libraries, printing the warnings to stderr.
pub fn load(path: &Path) -> Result<ObjMesh, SceneError> {
    let (mesh, warnings) = load_with_warnings(path)?;
    print_warnings(&warnings);
    Ok(mesh)
}

/// Loads `path` and its material libraries (relative to its directory): the mesh and what was
/// repaired or ignored, in file order (the OBJ's warnings, then each library's).
pub fn load_with_warnings(path: &Path) -> Result<(ObjMesh, Vec<ObjWarning>), SceneError> {
    let mut warnings = Vec::new();
    let (text, latin1) = read_text(path, "OBJ file", &mut warnings)?;
    let parsed = parse_obj(&text).map_err(|(line, mut msg)| {
        if latin1 && text.split('\n').nth(line.wrapping_sub(1)).is_some_and(|l| !l.is_ascii()) {
            msg.push_str(&format!(" ({LATIN1})"));
        }
        err(path, line, msg)
    })?;
    warnings.extend(parsed.warnings.iter().map(|(line, m)| warn(path, *line, m.clone())));
    let (materials, by_name) = load_libraries(path, &parsed, &mut warnings)?;
    // usemtl slots -> material indices
    let any_library = !materials.is_empty() || !parsed.mtllibs.is_empty();
    let mut slot_material = Vec::with_capacity(parsed.usemtl.len());
    let mut warned_no_library = false;
    for (line, name) in &parsed.usemtl {
        let found = by_name.get(name.as_str()).or_else(|| by_name.get(name.split('#').next().unwrap_or("").trim()));
        match found {
            Some(&i) => slot_material.push(i),
            None => {
                slot_material.push(u32::MAX);
                if name.is_empty() {
                    // warned by parse_obj
                } else if !materials.is_empty() {
                    let m = format!(
                        "usemtl '{}': no such material in the library; using the default material",
                        short(name)
                    );
                    warnings.push(warn(path, *line, m));
                } else if !any_library && !warned_no_library {
                    warned_no_library = true;
                    let m = format!("usemtl '{}' without any mtllib; using default materials", short(name));
                    warnings.push(warn(path, *line, m));
                }
            }
        }
    }
    let face_material =
        parsed.face_slot.iter().map(|&s| slot_material.get(s as usize).copied().unwrap_or(u32::MAX)).collect();
    let mut mesh = ObjMesh {
        positions: parsed.positions,
        faces: parsed.faces,
        face_material,
        materials,
        normals: parsed.normals,
        face_normals: parsed.face_normals,
    };
    if mesh.faces.is_empty() {
        return Err(err(path, 0, "the OBJ file has no faces"));
    }
    let with_normals = mesh.face_normals.iter().filter(|n| n[0] != NO_NORMAL).count();
    if with_normals == 0 {
        mesh.normals.clear();
        mesh.face_normals.clear();
    } else if with_normals < mesh.faces.len() {
        let m = format!(
            "{} of {} triangles have no valid vertex normals (they use the geometric normal)",
            mesh.faces.len() - with_normals,
            mesh.faces.len()
        );
        warnings.push(warn(path, 0, m));
    }
    Ok((mesh, warnings))
}

/// Finds and loads the OBJ's material libraries: the materials (in library order) and a name map
/// (a later definition of a name wins, as in `tobj`).
fn load_libraries(
    path: &Path,
    parsed: &ParsedObj,
    warnings: &mut Vec<ObjWarning>,
) -> Result<(Vec<MtlMaterial>, HashMap<String, u32>), SceneError> {
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mut loaded: Vec<PathBuf> = Vec::new();
    let mut missing: Vec<(usize, String, String)> = Vec::new();
    let mut materials = Vec::new();
    let mut by_name = HashMap::new();
    let mut load_one = |lib: &Path, materials: &mut Vec<MtlMaterial>, warnings: &mut Vec<ObjWarning>| {
        for m in load_mtl(lib, warnings)? {
            by_name.insert(m.name.clone(), materials.len() as u32);
            materials.push(m);
        }
        Ok::<(), SceneError>(())
    };
    for (line, rest) in &parsed.mtllibs {
        for name in mtllib_names(rest, &dir) {
            let direct = dir.join(&name);
            let base = Path::new(&name.replace('\\', "/")).file_name().map(|b| dir.join(b));
            let (lib, how) = if direct.is_file() {
                (direct, None)
            } else if let Some(b) = base.filter(|b| b.is_file()) {
                let shown = b.file_name().unwrap_or_default().to_string_lossy().into_owned();
                (b, Some(format!("mtllib '{name}' not found at that path; using '{shown}' beside the OBJ")))
            } else {
                let why = match std::fs::metadata(&direct) {
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => "not found".to_string(),
                    Err(e) => format!("cannot be read ({e})"),
                    Ok(_) => "is not a file".to_string(),
                };
                missing.push((*line, name, why));
                continue;
            };
            if loaded.contains(&lib) {
                continue;
            }
            if let Some(m) = how {
                warnings.push(warn(path, *line, m));
            }
            load_one(&lib, &mut materials, warnings)?;
            loaded.push(lib);
        }
    }
    if loaded.is_empty() && !missing.is_empty() {
        let stem = path.with_extension("mtl");
        if stem.is_file() {
            let (line, name, _) = &missing[0];
            let shown = stem.file_name().unwrap_or_default().to_string_lossy().into_owned();
            let m = format!("mtllib '{name}' not found; using '{shown}' beside the OBJ (named after it)");
            warnings.push(warn(path, *line, m));
            load_one(&stem, &mut materials, warnings)?;
            missing.remove(0);
            loaded.push(stem);
        }
    }
    for (line, name, why) in missing {
        let then = if loaded.is_empty() { "using default materials" } else { "skipped" };
        warnings.push(warn(path, line, format!("mtllib '{name}' {why}; {then}")));
    }
    Ok((materials, by_name))
}

/// The file names on an `mtllib` line: the whole rest of the line if that names a file in `dir`
/// (names with spaces, as `tobj` reads them), else its words, where `\ ` is an escaped space.
fn mtllib_names(rest: &str, dir: &Path) -> Vec<String> {
    let rest = rest.trim();
    if rest.is_empty() {
        return Vec::new();
    }
    if dir.join(rest).is_file() {
        return vec![rest.to_string()];
    }
    let mut names = Vec::new();
    let mut cur = String::new();
    let mut chars = rest.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek().is_some_and(|n| n.is_whitespace()) => cur.push(chars.next().unwrap_or(' ')),
            c if c.is_whitespace() => {
                if !cur.is_empty() {
                    names.push(std::mem::take(&mut cur));
                }
            }
            c => cur.push(c),
        }
    }
    if !cur.is_empty() {
        names.push(cur);
    }
    names
}

/// Loads one MTL library, checking every value strata uses (finite; colours and `Ns` >= 0).
fn load_mtl(path: &Path, warnings: &mut Vec<ObjWarning>) -> Result<Vec<MtlMaterial>, SceneError> {
    let (text, _) = read_text(path, "material library", warnings)?;
    if let Some((line, msg)) = locate_mtl_error(&text) {
        return Err(err(path, line, msg));
    }
    let (text, unnamed) = repair_mtl(&text);
    if let Some(line) = unnamed {
        warnings.push(warn(path, line, "'newmtl' without a name: an unnamed material (for 'usemtl' without a name)"));
    }
    let loaded = std::panic::catch_unwind(|| tobj::load_mtl_buf(&mut text.as_bytes()))
        .map_err(|_| err(path, 0, "the MTL parser failed on this file (internal panic caught)"))?;
    let (materials, _) = loaded.map_err(|e| err(path, 0, format!("malformed material library ({e})")))?;
    Ok(materials
        .into_iter()
        .map(|m| MtlMaterial {
            name: if m.name == UNNAMED { String::new() } else { m.name },
            kd: m.diffuse.map(Vec3::from_array),
            ks: m.specular.map(Vec3::from_array),
            ns: m.shininess,
            ke: m.emissive.map(Vec3::from_array),
        })
        .collect())
}

/// Stands for an empty `newmtl` name while `tobj` reads the MTL (it refuses empty names).
const UNNAMED: &str = "\u{1}strata-unnamed-material";

/// MTL text as `tobj` reads it, same line numbers: an empty `newmtl` named [`UNNAMED`] (and the
/// first such line), a colour of one number `r` written `r r r`.
fn repair_mtl(text: &str) -> (String, Option<usize>) {
    let mut out = String::with_capacity(text.len() + 64);
    let mut unnamed = None;
    for (k, raw) in text.split('\n').enumerate() {
        if k > 0 {
            out.push('\n');
        }
        let code = raw.split('#').next().unwrap_or_default();
        let tok: Vec<&str> = code.split_ascii_whitespace().collect();
        match tok.as_slice() {
            ["newmtl"] => {
                unnamed.get_or_insert(k + 1);
                out.push_str("newmtl ");
                out.push_str(UNNAMED);
            }
            [c @ ("Ka" | "Kd" | "Ks" | "Ke" | "Tf"), r] => out.push_str(&format!("{c} {r} {r} {r}")),
            _ => out.push_str(raw),
        }
    }
    (out, unnamed)
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

/// The lines of `text` as (1-based line number, content without `\r`), a line ending in `\` joined
/// with the next one (numbered as its first line); and the first line so continued.
fn logical_lines(text: &str) -> (Vec<(usize, Cow<'_, str>)>, Option<usize>) {
    let mut out: Vec<(usize, Cow<'_, str>)> = Vec::new();
    let mut first_continued = None;
    let mut pending: Option<(usize, String)> = None;
    for (k, raw) in text.split('\n').enumerate() {
        let raw = raw.strip_suffix('\r').unwrap_or(raw);
        let continued = raw.trim_end_matches([' ', '\t']).ends_with('\\');
        let body = if continued { raw.trim_end_matches([' ', '\t']).strip_suffix('\\').unwrap_or(raw) } else { raw };
        match (pending.take(), continued) {
            (Some((n, mut s)), c) => {
                s.push(' ');
                s.push_str(body);
                if c {
                    pending = Some((n, s));
                } else {
                    out.push((n, Cow::Owned(s)));
                }
            }
            (None, true) => {
                first_continued.get_or_insert(k + 1);
                pending = Some((k + 1, body.to_string()));
            }
            (None, false) => out.push((k + 1, Cow::Borrowed(raw))),
        }
    }
    if let Some((n, s)) = pending {
        out.push((n, Cow::Owned(s)));
    }
    (out, first_continued)
}

/// An OBJ's contents as read by [`parse_obj`], before its material libraries are loaded.
#[derive(Debug, Default)]
pub struct ParsedObj {
    /// one per `v` line
    pub positions: Vec<Vec3>,
    /// one per `vn` line, normalized (`Vec3::ZERO` if invalid)
    pub normals: Vec<Vec3>,
    /// triangles
    pub faces: Vec<[u32; 3]>,
    /// per triangle, normal indices or `[NO_NORMAL; 3]`
    pub face_normals: Vec<[u32; 3]>,
    /// per triangle, index into `usemtl` or `u32::MAX` (none, or an empty name)
    pub face_slot: Vec<u32>,
    /// distinct `usemtl` names with the line of first use
    pub usemtl: Vec<(usize, String)>,
    /// `mtllib` lines: (line, the rest of the line)
    pub mtllibs: Vec<(usize, String)>,
    /// (line, message) of what was repaired or ignored
    pub warnings: Vec<(usize, String)>,
}

/// Reads OBJ text: the first real error as (line, message), else the contents (see module docs).
/// `v` needs 3 finite numbers (up to 7 accepted), `vt` 1 to 3, `f` at least 3 vertex references
/// `i`, `i/t`, `i//n` or `i/t/n` with non-zero vertex and texture indices inside the lists read so
/// far (negative = relative); normal indices out of range only drop the normal.
pub fn parse_obj(text: &str) -> Result<ParsedObj, (usize, String)> {
    let mut p = ParsedObj::default();
    let (lines, continued) = logical_lines(text);
    if let Some(line) = continued {
        p.warnings.push((line, "line continued with '\\' (joined with the next line)".into()));
    }
    let mut valid_normal: Vec<bool> = Vec::new();
    let mut nt = 0i64;
    let mut first_vt = None;
    let mut bad_normal_line: Option<(usize, String)> = None;
    let mut bad_normal_index: Option<(usize, String)> = None;
    let mut w_zero = None;
    let mut ignored: Vec<(String, usize, usize)> = Vec::new(); // keyword, first line, count
    let mut empty_usemtl = None;
    let mut slot_of: HashMap<String, u32> = HashMap::new();
    let mut slot = u32::MAX;
    let mut corners: Vec<(u32, u32)> = Vec::new();
    for (line, content) in &lines {
        let line = *line;
        let uncommented = content.split('#').next().unwrap_or_default();
        let mut tok = uncommented.split_ascii_whitespace();
        let Some(cmd) = tok.next() else { continue };
        let args: Vec<&str> = tok.collect();
        let r: Result<(), String> = match cmd {
            "v" => floats(cmd, &args, 3, 7, "x y z [w] or x y z r g b").map(|v| {
                let mut pos = Vec3::new(v[0], v[1], v[2]);
                if v.len() == 4 {
                    if v[3] != 0.0 && (pos / v[3]).is_finite() {
                        pos /= v[3];
                    } else {
                        w_zero.get_or_insert(line);
                    }
                }
                p.positions.push(pos);
            }),
            "vt" => floats(cmd, &args, 1, 3, "u [v [w]]").map(|_| {
                nt += 1;
                first_vt.get_or_insert(line);
            }),
            "vn" => {
                let n = floats(cmd, &args, 3, 3, "x y z").map(|v| Vec3::new(v[0], v[1], v[2]));
                let n = n.and_then(|n| {
                    let u = n.normalize_or_zero();
                    if u == Vec3::ZERO {
                        Err(format!("'vn' {} {} {} has zero length", n.x, n.y, n.z))
                    } else {
                        Ok(u)
                    }
                });
                match n {
                    Ok(u) => {
                        p.normals.push(u);
                        valid_normal.push(true);
                    }
                    Err(m) => {
                        bad_normal_line.get_or_insert((line, m));
                        p.normals.push(Vec3::ZERO);
                        valid_normal.push(false);
                    }
                }
                Ok(())
            }
            "f" => {
                corners.clear();
                let nv = p.positions.len() as i64;
                let nn = p.normals.len() as i64;
                let r = face(&args, nv, nt, nn, &mut corners, &mut bad_normal_index);
                if let Some(b) = bad_normal_index.as_mut().filter(|b| b.0 == 0) {
                    b.0 = line;
                }
                r.map(|_| {
                    let c0 = corners[0];
                    for w in corners[1..].windows(2) {
                        let tri = [c0, w[0], w[1]];
                        p.faces.push(tri.map(|c| c.0));
                        let ns = tri.map(|c| c.1);
                        let ok = ns.iter().all(|&n| n != NO_NORMAL && valid_normal[n as usize]);
                        p.face_normals.push(if ok { ns } else { [NO_NORMAL; 3] });
                        p.face_slot.push(slot);
                    }
                })
            }
            "usemtl" => {
                let name = content.trim_start().strip_prefix("usemtl").unwrap_or("").trim();
                let name = if name.starts_with('#') { "" } else { name };
                if name.is_empty() {
                    empty_usemtl.get_or_insert(line);
                }
                {
                    let next = p.usemtl.len() as u32;
                    slot = *slot_of.entry(name.to_string()).or_insert_with(|| {
                        p.usemtl.push((line, name.to_string()));
                        next
                    });
                }
                Ok(())
            }
            "mtllib" => {
                let rest = content.trim_start().strip_prefix("mtllib").unwrap_or("");
                let rest = if rest.contains('#') { rest.split('#').next().unwrap_or("") } else { rest };
                p.mtllibs.push((line, rest.trim().to_string()));
                Ok(())
            }
            "o" | "g" | "s" | "mg" => Ok(()),
            other => {
                match ignored.iter_mut().find(|(c, ..)| c == other) {
                    Some(e) => e.2 += 1,
                    None => ignored.push((other.to_string(), line, 1)),
                }
                Ok(())
            }
        };
        if let Err(m) = r {
            return Err((line, m));
        }
    }
    if p.faces.len() > u32::MAX as usize || p.positions.len() >= u32::MAX as usize {
        return Err((0, "more than 2^32 vertices".into()));
    }
    if let Some(line) = first_vt {
        p.warnings.push((line, format!("texture coordinates (vt, {nt} in the file) ignored")));
    }
    if let Some((line, m)) = bad_normal_line {
        p.warnings.push((line, format!("{m}: faces using broken vertex normals get none")));
    }
    if let Some((line, m)) = bad_normal_index {
        p.warnings.push((line, format!("{m}: faces using it get no vertex normals")));
    }
    if let Some(line) = w_zero {
        p.warnings.push((line, "'v' with w = 0 (or an overflowing x/w): w ignored".into()));
    }
    if let Some(line) = empty_usemtl {
        p.warnings.push((line, "'usemtl' without a name: the MTL's unnamed material if any, else the default".into()));
    }
    for (cmd, line, count) in ignored {
        let what = match cmd.as_str() {
            "l" => "line elements",
            "p" => "point elements",
            "vp" | "cstype" | "deg" | "bmat" | "step" | "curv" | "curv2" | "surf" | "parm" | "trim" | "hole"
            | "scrv" | "sp" | "end" | "con" | "ctech" | "stech" => "free-form geometry",
            _ => "unknown keyword",
        };
        let times = if count == 1 { String::new() } else { format!(", {count} lines") };
        p.warnings.push((line, format!("'{}' ignored ({what}{times})", short(&cmd))));
    }
    p.warnings.sort_by_key(|w| w.0);
    Ok(p)
}

/// Numbers of a `v`/`vt`/`vn` line: `min..=max` of them, all finite.
fn floats(cmd: &str, args: &[&str], min: usize, max: usize, what: &str) -> Result<Vec<f32>, String> {
    if args.len() < min || args.len() > max {
        let want = if min == max { format!("{min}") } else { format!("{min} to {max}") };
        return Err(format!("'{cmd}' expects {want} numbers ({what}), got {}", args.len()));
    }
    args.iter()
        .enumerate()
        .map(|(i, a)| match a.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("'{cmd}' argument {}: expected a finite number, got '{}'", i + 1, short(a))),
        })
        .collect()
}

/// First line of OBJ text that strata cannot read, with the reason (see [`parse_obj`]).
pub fn locate_obj_error(text: &str) -> Option<(usize, String)> {
    parse_obj(text).err()
}

/// Checks one face and pushes its corners as (0-based vertex, 0-based normal or `NO_NORMAL`).
fn face(
    args: &[&str],
    nv: i64,
    nt: i64,
    nn: i64,
    out: &mut Vec<(u32, u32)>,
    bad_normal: &mut Option<(usize, String)>,
) -> Result<(), String> {
    if args.len() < 3 {
        return Err(format!("face 'f' needs at least 3 vertices, got {}", args.len()));
    }
    for (j, a) in args.iter().enumerate() {
        let mut parts = a.split('/');
        let (pv, pt, pn) = (parts.next().unwrap_or(""), parts.next(), parts.next());
        if parts.next().is_some() {
            return Err(format!("face vertex {}: '{}' is not i, i/t, i//n or i/t/n", j + 1, short(a)));
        }
        let index =
            |s: &str| s.parse::<i64>().map_err(|_| format!("face vertex {}: '{}' is not an index", j + 1, short(a)));
        let resolve = |i: i64, n: i64| {
            if i > 0 && i <= n {
                Some(i - 1)
            } else if i < 0 && -i <= n {
                Some(n + i)
            } else {
                None
            }
        };
        let i = index(pv)?;
        let Some(v) = resolve(i, nv) else {
            return Err(format!("face vertex {}: vertex index {i} out of range ({nv} defined so far)", j + 1));
        };
        if let Some(t) = pt.filter(|t| !t.is_empty()) {
            let i = index(t)?;
            if resolve(i, nt).is_none() {
                return Err(format!(
                    "face vertex {}: texture coordinate index {i} out of range ({nt} defined so far)",
                    j + 1
                ));
            }
        }
        let mut normal = NO_NORMAL;
        if let Some(n) = pn.filter(|n| !n.is_empty()) {
            let i = index(n)?;
            match resolve(i, nn) {
                Some(k) => normal = k as u32,
                None => {
                    bad_normal.get_or_insert((
                        0,
                        format!("face vertex {}: normal index {i} out of range ({nn} defined so far)", j + 1),
                    ));
                }
            }
        }
        out.push((v as u32, normal));
    }
    Ok(())
}

/// First line of MTL text with a value strata cannot use: `Ka Kd Ks Ke Tf` need 3 (or 1) finite,
/// non-negative numbers, `Ns` one, `Ni d Tr` one finite number; and no colour may
/// come before the first `newmtl`.
pub fn locate_mtl_error(text: &str) -> Option<(usize, String)> {
    let mut seen_newmtl = false;
    for (line, cmd, args) in commands(text) {
        let numbers = |n: usize, non_negative: bool| -> Result<(), String> {
            if args.len() != n {
                return Err(format!("'{cmd}' expects {n} number{}, got {}", if n == 1 { "" } else { "s" }, args.len()));
            }
            for (i, a) in args.iter().enumerate() {
                match a.parse::<f32>() {
                    Ok(v) if v.is_finite() && (!non_negative || v >= 0.0) => {}
                    Ok(_) if non_negative => {
                        return Err(format!(
                            "'{cmd}' argument {}: expected a finite number >= 0, got '{}'",
                            i + 1,
                            short(a)
                        ))
                    }
                    _ => {
                        return Err(format!("'{cmd}' argument {}: expected a finite number, got '{}'", i + 1, short(a)))
                    }
                }
            }
            Ok(())
        };
        let r = match cmd {
            "newmtl" => {
                seen_newmtl = true;
                Ok(())
            }
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" | "Ns" | "Ni" | "d" | "Tr" if !seen_newmtl => {
                Err(format!("'{cmd}' before any 'newmtl'"))
            }
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => numbers(if args.len() == 1 { 1 } else { 3 }, true),
            "Ns" => numbers(1, true),
            "Ni" | "d" | "Tr" => numbers(1, false),
            _ => Ok(()),
        };
        if let Err(m) = r {
            return Some((line, m));
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
/// Prints the warnings to stderr (see [`scene_from_obj_with_warnings`]).
pub fn scene_from_obj(path: &Path, limits: &Limits) -> Result<SceneDesc, SceneError> {
    let (desc, warnings) = scene_from_obj_with_warnings(path, limits)?;
    print_warnings(&warnings);
    Ok(desc)
}

/// [`scene_from_obj`], returning the loader's warnings instead of printing them.
pub fn scene_from_obj_with_warnings(path: &Path, limits: &Limits) -> Result<(SceneDesc, Vec<ObjWarning>), SceneError> {
    let (mesh, warnings) = load_with_warnings(path)?;
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
    place(&mesh, &current, Ok, glam::DMat3::IDENTITY, &mut desc, &mut |m: Material, d: &mut SceneDesc| {
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
    Ok((desc, warnings))
}

/// Adds `mesh` to `desc`: every face's vertices through `to_world`, emissive faces to
/// `emissive_triangles`, the others to `triangles` with the material `intern` returns an index for.
/// Vertex normals go through `normal_matrix` (see [`normal_matrix`]), renormalised, into
/// `desc.triangle_normals` (padded with "none" up to the triangle they belong to); a triangle whose
/// normals do not all survive (zero after the transform) is faceted; emissive faces ignore them.
pub fn place(
    mesh: &ObjMesh,
    current: &Material,
    to_world: impl Fn(Vec3) -> Result<Vec3, LineError>,
    normal_matrix: glam::DMat3,
    desc: &mut SceneDesc,
    intern: &mut dyn FnMut(Material, &mut SceneDesc) -> Result<u32, LineError>,
) -> Result<(), LineError> {
    use crate::scene::desc::{EmissiveTriangleDesc, TriangleDesc};
    // One resolved material index per MTL material (and one for "none"), computed on first use.
    let mut resolved: Vec<Option<u32>> = vec![None; mesh.materials.len() + 1];
    let world: Vec<Vec3> = mesh.positions.iter().map(|&p| to_world(p)).collect::<Result<_, _>>()?;
    let normals: Vec<Vec3> =
        mesh.normals.iter().map(|&n| (normal_matrix * n.as_dvec3()).as_vec3().normalize_or_zero()).collect();
    for (k, (f, &mi)) in mesh.faces.iter().zip(&mesh.face_material).enumerate() {
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
        let corner = |c: u32| normals.get(c as usize).copied().unwrap_or(Vec3::ZERO);
        let ns = mesh.face_normals.get(k).map_or([Vec3::ZERO; 3], |c| c.map(corner));
        if ns.iter().all(|n| *n != Vec3::ZERO) {
            desc.triangle_normals.resize(desc.triangles.len(), [Vec3::ZERO; 3]);
            desc.triangle_normals.push(ns);
        }
        desc.triangles.push(TriangleDesc { v, material });
    }
    Ok(())
}

/// The matrix taking object-space normals to world space under the affine `m`: the cofactor
/// matrix of its linear part, `det * inverse transpose`, times the sign of `det` (so the direction
/// is that of the inverse transpose; the length is renormalised by the caller). Defined for any `m`
/// (zero for a singular one of rank < 2).
pub fn normal_matrix(m: &glam::DMat4) -> glam::DMat3 {
    let l = glam::DMat3::from_mat4(*m);
    let (a, b, c) = (l.x_axis, l.y_axis, l.z_axis);
    let cof = glam::DMat3::from_cols(b.cross(c), c.cross(a), a.cross(b));
    if l.determinant() < 0.0 {
        -cof
    } else {
        cof
    }
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

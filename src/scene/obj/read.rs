//! Reading OBJ files: the mesh with its `usemtl` slots resolved, and the search for its `mtllib`
//! libraries (the text is decoded by [`super::text`]).

use super::faces::parse_obj;
use super::mtl::load_mtl;
use super::text::{read_text, LATIN1};
use super::{err, print_warnings, short, warn, MtlMaterial, ObjMesh, ObjWarning, ParsedObj, NO_NORMAL};
use crate::scene::error::SceneError;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Loads `path` and its material libraries, printing the warnings to stderr (files up to the
/// default `max_file_bytes`).
pub fn load(path: &Path) -> Result<ObjMesh, SceneError> {
    load_bounded(path, crate::scene::parse::Limits::default().max_file_bytes)
}

/// [`load`] reading each file up to `max_file_bytes` (`--limit max_file_bytes`).
pub fn load_bounded(path: &Path, max_file_bytes: u64) -> Result<ObjMesh, SceneError> {
    let (mesh, warnings) = load_with_warnings_bounded(path, max_file_bytes)?;
    print_warnings(&warnings);
    Ok(mesh)
}

/// Loads `path` and its material libraries (relative to its directory): the mesh and what was
/// repaired or ignored, in file order (the OBJ's warnings, then each library's). Files are read up
/// to the default `max_file_bytes`.
pub fn load_with_warnings(path: &Path) -> Result<(ObjMesh, Vec<ObjWarning>), SceneError> {
    load_with_warnings_bounded(path, crate::scene::parse::Limits::default().max_file_bytes)
}

/// [`load_with_warnings`] reading each file up to `max` bytes (`--limit max_file_bytes`).
pub fn load_with_warnings_bounded(path: &Path, max: u64) -> Result<(ObjMesh, Vec<ObjWarning>), SceneError> {
    let mut warnings = Vec::new();
    let (text, latin1) = read_text(path, "OBJ file", max, &mut warnings)?;
    let parsed = parse_obj(&text).map_err(|(line, mut msg)| {
        if latin1 && text.split('\n').nth(line.wrapping_sub(1)).is_some_and(|l| !l.is_ascii()) {
            msg.push_str(&format!(" ({LATIN1})"));
        }
        err(path, line, msg)
    })?;
    warnings.extend(parsed.warnings.iter().map(|(line, m)| warn(path, *line, m.clone())));
    let (materials, by_name, libraries) = load_libraries(path, &parsed, max, &mut warnings)?;
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
        libraries,
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

/// The materials of an OBJ's libraries (in library order), their names' indices, and the library
/// files read.
type Libraries = (Vec<MtlMaterial>, HashMap<String, u32>, Vec<PathBuf>);

/// Finds and loads the OBJ's material libraries: the materials (in library order) and a name map
/// (a later definition of a name wins, as in `tobj`).
fn load_libraries(
    path: &Path,
    parsed: &ParsedObj,
    max: u64,
    warnings: &mut Vec<ObjWarning>,
) -> Result<Libraries, SceneError> {
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mut loaded: Vec<PathBuf> = Vec::new();
    let mut missing: Vec<(usize, String, String)> = Vec::new();
    let mut materials = Vec::new();
    let mut by_name = HashMap::new();
    let mut load_one = |lib: &Path, materials: &mut Vec<MtlMaterial>, warnings: &mut Vec<ObjWarning>| {
        for m in load_mtl(lib, max, warnings)? {
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
            if let Some(m) = outside(&lib, &dir) {
                warnings.push(warn(path, *line, format!("mtllib '{}': {m}", short(&name))));
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
    Ok((materials, by_name, loaded))
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

/// A warning if the library `lib` lies outside the OBJ's directory `dir` (after resolving links):
/// an OBJ from elsewhere naming `/etc/passwd` or `../../x` should not be read silently.
fn outside(lib: &Path, dir: &Path) -> Option<String> {
    let here = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
    let (l, d) = (std::fs::canonicalize(lib).ok()?, std::fs::canonicalize(here).ok()?);
    (!l.starts_with(&d)).then(|| format!("{} is outside the OBJ's directory; read anyway", l.display()))
}

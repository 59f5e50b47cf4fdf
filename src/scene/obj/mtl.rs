//! MTL libraries: the checks strata needs ([`locate_mtl_error`]), the repairs `tobj` cannot make,
//! and the read through `tobj::load_mtl_buf`.

use super::line_error::ObjLineError;
use super::text::read_text;
use super::{err, short, warn, MtlMaterial, ObjWarning};
use crate::scene::error::SceneError;
use glam::Vec3;
use std::path::Path;

/// Loads one MTL library, checking every value strata uses (finite; colours and `Ns` >= 0).
pub(super) fn load_mtl(path: &Path, max: u64, warnings: &mut Vec<ObjWarning>) -> Result<Vec<MtlMaterial>, SceneError> {
    let (text, _) = read_text(path, "material library", max, warnings)?;
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
        .map(|m| {
            let ke = m.emissive.map(Vec3::from_array).or_else(|| {
                let ka = m.ambient.map(Vec3::from_array).filter(|ka| ka.max_element() > 1.0)?;
                let line = ka_line(&text, &m.name);
                warnings.push(warn(
                    path,
                    line,
                    format!("material '{}': Ka above 1 and no Ke: read as emission Ke {} {} {} (the pre-Ke convention of Embree's Cornell box)", short(&m.name), ka.x, ka.y, ka.z),
                ));
                Some(ka)
            });
            MtlMaterial {
                name: if m.name == UNNAMED { String::new() } else { m.name },
                kd: m.diffuse.map(Vec3::from_array),
                ks: m.specular.map(Vec3::from_array),
                ns: m.shininess,
                ke,
            }
        })
        .collect())
}

/// Line of the `Ka` of material `name` in MTL text (0 if not found).
fn ka_line(text: &str, name: &str) -> usize {
    let mut current = false;
    for (line, cmd, args) in commands(text) {
        match cmd {
            "newmtl" => current = args.join(" ") == name,
            "Ka" if current => return line,
            _ => {}
        }
    }
    0
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

/// First line of MTL text with a value strata cannot use: `Ka Kd Ks Ke Tf` need 3 (or 1) finite,
/// non-negative numbers, `Ns` one, `Ni d Tr` one finite number; and no colour may
/// come before the first `newmtl`.
pub fn locate_mtl_error(text: &str) -> Option<(usize, String)> {
    let mut seen_newmtl = false;
    for (line, cmd, args) in commands(text) {
        let numbers = |n: usize, non_negative: bool| -> Result<(), ObjLineError> {
            if args.len() != n {
                return Err(ObjLineError::MtlNumbers { cmd: cmd.into(), n, got: args.len() });
            }
            for (i, a) in args.iter().enumerate() {
                let (arg, text) = (i + 1, || short(a));
                match a.parse::<f32>() {
                    Ok(v) if v.is_finite() && (!non_negative || v >= 0.0) => {}
                    Ok(_) if non_negative => return Err(ObjLineError::Negative { cmd: cmd.into(), arg, text: text() }),
                    _ => return Err(ObjLineError::NotFinite { cmd: cmd.into(), arg, text: text() }),
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
                Err(ObjLineError::BeforeNewmtl { cmd: cmd.into() })
            }
            "Ka" | "Kd" | "Ks" | "Ke" | "Tf" => numbers(if args.len() == 1 { 1 } else { 3 }, true),
            "Ns" => numbers(1, true),
            "Ni" | "d" | "Tr" => numbers(1, false),
            _ => Ok(()),
        };
        if let Err(m) = r {
            return Some((line, m.to_string()));
        }
    }
    None
}

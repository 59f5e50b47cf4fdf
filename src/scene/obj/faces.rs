//! OBJ text: logical lines (with `\\` continuations), `v`/`vt`/`vn` records, and faces checked
//! and triangulated as fans `(c0, ci, ci+1)`.

use super::line_error::ObjLineError;
use super::{short, NO_NORMAL};
use glam::Vec3;
use std::borrow::Cow;
use std::collections::HashMap;

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
        let r: Result<(), ObjLineError> = match cmd {
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
                        Err(ObjLineError::ZeroNormal { x: n.x, y: n.y, z: n.z })
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
                        bad_normal_line.get_or_insert((line, m.to_string()));
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
            return Err((line, m.to_string()));
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
fn floats(cmd: &str, args: &[&str], min: usize, max: usize, what: &'static str) -> Result<Vec<f32>, ObjLineError> {
    if args.len() < min || args.len() > max {
        let want = if min == max { format!("{min}") } else { format!("{min} to {max}") };
        return Err(ObjLineError::VertexNumbers { cmd: cmd.into(), want, what, got: args.len() });
    }
    args.iter()
        .enumerate()
        .map(|(i, a)| match a.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(ObjLineError::NotFinite { cmd: cmd.into(), arg: i + 1, text: short(a) }),
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
) -> Result<(), ObjLineError> {
    if args.len() < 3 {
        return Err(ObjLineError::FewVertices(args.len()));
    }
    for (j, a) in args.iter().enumerate() {
        let mut parts = a.split('/');
        let (pv, pt, pn) = (parts.next().unwrap_or(""), parts.next(), parts.next());
        if parts.next().is_some() {
            return Err(ObjLineError::VertexForm { vertex: j + 1, text: short(a) });
        }
        let index = |s: &str| s.parse::<i64>().map_err(|_| ObjLineError::NotAnIndex { vertex: j + 1, text: short(a) });
        let out_of_range = |what, index, defined| ObjLineError::OutOfRange { vertex: j + 1, what, index, defined };
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
            return Err(out_of_range("vertex", i, nv));
        };
        if let Some(t) = pt.filter(|t| !t.is_empty()) {
            let i = index(t)?;
            if resolve(i, nt).is_none() {
                return Err(out_of_range("texture coordinate", i, nt));
            }
        }
        let mut normal = NO_NORMAL;
        if let Some(n) = pn.filter(|n| !n.is_empty()) {
            let i = index(n)?;
            match resolve(i, nn) {
                Some(k) => normal = k as u32,
                None => {
                    bad_normal.get_or_insert((0, out_of_range("normal", i, nn).to_string()));
                }
            }
        }
        out.push((v as u32, normal));
    }
    Ok(())
}

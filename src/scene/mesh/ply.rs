//! Stanford PLY meshes (ASCII, binary little and big endian) read as Mitsuba 3 reads them, with the
//! `ply-rs-bw` crate parsing the header and each element.
//!
//! - `vertex`: `x y z` (required); `nx ny nz` normals; texture coordinates `u v`, `s t`,
//!   `texture_u texture_v` or `texture_s texture_t`; every other scalar property is a vertex
//!   attribute (below).
//! - `face`: the list `vertex_indices` (or `vertex_index`), polygons triangulated as fans
//!   `(c0, ci, ci+1)`; every other scalar property is a face attribute.
//! - Attributes, named with the prefix `vertex_` or `face_`: properties `NAME_x/_y/_z`,
//!   `NAME_r/_g/_b`, `NAME_red/_green/_blue` or `NAME_0/_1/_2` make one 3-value attribute `NAME`;
//!   bare `r g b` or `red green blue` make `color` (so `vertex_color`, `face_color`); `NAME_0`
//!   alone, or any other property, makes a 1-value attribute (`weight_0` -> `face_weight`, `foo`
//!   -> `vertex_foo`). Integer colour components (`uchar`, `ushort`) are scaled to [0, 1].
//! - Other elements are read and ignored.
//!
//! Refused, naming the file and the line (ASCII) or the element: a header the crate cannot parse,
//! element counts above `--limit max_vertices` / `max_primitives` or larger than the bytes left in
//! the file (checked before anything is allocated), a truncated payload, a non-finite position,
//! normal or uv, a face with fewer than 3 vertices, and vertex indices out of range.

use super::{check_limit, read_file, Location, Mesh, MeshAttr, MeshError};
use crate::scene::limits::Limits;
use glam::{Vec2, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{ElementDef, Encoding, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType};
use std::io::{BufRead, BufReader, Cursor};
use std::path::Path;

/// One element's properties in header order.
struct Row(Vec<Property>);

impl PropertyAccess for Row {
    fn new() -> Self {
        Row(Vec::with_capacity(8))
    }
    fn set_property(&mut self, _name: &str, property: Property) -> PropertyAccessResult {
        self.0.push(property);
        PropertyAccessResult::Set
    }
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v.into(),
        Property::UChar(v) => v.into(),
        Property::Short(v) => v.into(),
        Property::UShort(v) => v.into(),
        Property::Int(v) => v.into(),
        Property::UInt(v) => v.into(),
        Property::Float(v) => v.into(),
        Property::Double(v) => v,
        _ => return None,
    })
}

fn list(p: &Property) -> Option<Vec<i64>> {
    fn conv<T: Copy + Into<i64>>(v: &[T]) -> Vec<i64> {
        v.iter().map(|&x| x.into()).collect()
    }
    Some(match p {
        Property::ListChar(v) => conv(v),
        Property::ListUChar(v) => conv(v),
        Property::ListShort(v) => conv(v),
        Property::ListUShort(v) => conv(v),
        Property::ListInt(v) => conv(v),
        Property::ListUInt(v) => conv(v),
        _ => return None,
    })
}

fn scalar_bytes(t: &ScalarType) -> u64 {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Fewest bytes one element can take in the payload (binary: its scalars and list counts; ASCII:
/// one digit and a separator per property).
fn min_element_bytes(def: &ElementDef, encoding: Encoding) -> u64 {
    def.properties
        .values()
        .map(|p| match (&p.data_type, encoding) {
            (_, Encoding::Ascii) => 2,
            (PropertyType::Scalar(t), _) => scalar_bytes(t),
            (PropertyType::List(count, _), _) => scalar_bytes(count),
        })
        .sum::<u64>()
        .max(1)
}

/// Where the components of a grouped attribute go.
struct AttrPlan {
    name: String,
    /// (property column, component, scale)
    columns: Vec<(usize, usize, f32)>,
    dims: usize,
}

const COMPONENT_SETS: [[&str; 3]; 4] = [["x", "y", "z"], ["r", "g", "b"], ["red", "green", "blue"], ["0", "1", "2"]];

/// Groups the attribute columns `(index, name, type)` of an element into attributes (module docs).
fn plan_attrs(prefix: &str, columns: &[(usize, &str, ScalarType)]) -> Vec<AttrPlan> {
    // (base, set, [column per component]) in order of first appearance.
    let mut groups: Vec<(String, usize, [Option<usize>; 3])> = Vec::new();
    let mut singles: Vec<usize> = Vec::new();
    for (k, &(_, name, _)) in columns.iter().enumerate() {
        let found = COMPONENT_SETS.iter().enumerate().find_map(|(s, set)| {
            set.iter().enumerate().find_map(|(c, comp)| {
                if name == *comp && s != 0 && s != 3 {
                    Some(("color".to_string(), s, c))
                } else {
                    let base = name.strip_suffix(comp)?.strip_suffix('_').filter(|b| !b.is_empty())?;
                    Some((base.to_string(), s, c))
                }
            })
        });
        match found {
            Some((base, s, c)) => match groups.iter_mut().find(|g| g.0 == base && g.1 == s) {
                Some(g) if g.2[c].is_none() => g.2[c] = Some(k),
                Some(_) => singles.push(k),
                None => {
                    let mut slots = [None; 3];
                    slots[c] = Some(k);
                    groups.push((base, s, slots));
                }
            },
            None => singles.push(k),
        }
    }
    let mut plans = Vec::new();
    let scale = |k: usize, colour: bool| match (colour, &columns[k].2) {
        (true, ScalarType::UChar) => 1.0 / 255.0,
        (true, ScalarType::UShort) => 1.0 / 65535.0,
        _ => 1.0,
    };
    for (base, s, slots) in groups {
        let colour = s == 1 || s == 2;
        match slots {
            [Some(a), Some(b), Some(c)] => plans.push(AttrPlan {
                name: format!("{prefix}{base}"),
                columns: vec![
                    (columns[a].0, 0, scale(a, colour)),
                    (columns[b].0, 1, scale(b, colour)),
                    (columns[c].0, 2, scale(c, colour)),
                ],
                dims: 3,
            }),
            [Some(a), None, None] if s == 3 => {
                plans.push(AttrPlan { name: format!("{prefix}{base}"), columns: vec![(columns[a].0, 0, 1.0)], dims: 1 })
            }
            _ => singles.extend(slots.into_iter().flatten()),
        }
    }
    singles.sort_unstable();
    for k in singles {
        plans.push(AttrPlan {
            name: format!("{prefix}{}", columns[k].1),
            columns: vec![(columns[k].0, 0, 1.0)],
            dims: 1,
        });
    }
    plans
}

/// Loads a PLY file (module docs) within `limits`.
pub fn load_ply(path: &Path, limits: &Limits) -> Result<Mesh, MeshError> {
    let bytes = read_file(path, limits.max_file_bytes)?;
    parse_ply(path, &bytes, limits)
}

/// Parses the bytes of a PLY file; `path` names it in errors.
pub fn parse_ply(path: &Path, bytes: &[u8], limits: &Limits) -> Result<Mesh, MeshError> {
    let bad = |at: Location, msg: String| MeshError::malformed(path, at, msg);
    let parser = Parser::<Row>::new();
    let mut reader = Reader::new(BufReader::new(Cursor::new(bytes)));
    let header = parser.read_header(&mut reader).map_err(|e| {
        let line = e.line().unwrap_or(0);
        bad(if line > 0 { Location::Line(line) } else { Location::File }, format!("bad PLY header: {e}"))
    })?;
    let header_bytes = find_header_end(bytes).unwrap_or(bytes.len());
    let header_lines = bytes[..header_bytes].iter().filter(|&&b| b == b'\n').count();
    let mut remaining = (bytes.len() - header_bytes) as u64;
    for def in header.elements.values() {
        let count = def.count as u64;
        match def.name.as_str() {
            "vertex" => check_limit(path, "vertices", count, limits.max_vertices as u64, "max_vertices")?,
            "face" => check_limit(path, "faces", count, limits.max_primitives as u64, "max_primitives")?,
            _ => {}
        }
        let need = count.saturating_mul(min_element_bytes(def, header.encoding));
        if need > remaining {
            return Err(bad(
                Location::Element(def.name.clone(), 0),
                format!(
                    "the header declares {count} `{}` elements, which need at least {need} bytes, but only {remaining} \
                     are left in the file (truncated, or a wrong count)",
                    def.name
                ),
            ));
        }
        remaining -= need;
    }
    let vertex_def = header.elements.get("vertex").ok_or_else(|| bad(Location::File, "no `vertex` element".into()))?;
    let face_def = header.elements.get("face").ok_or_else(|| bad(Location::File, "no `face` element".into()))?;

    let mut mesh = Mesh::default();
    let mut vplan = None;
    let mut fplan = None;
    let mut line = header_lines;
    let mut text = String::new();
    for def in header.elements.values() {
        let is_vertex = std::ptr::eq(def, vertex_def);
        let is_face = std::ptr::eq(def, face_def);
        if is_vertex {
            let plan = VertexPlan::new(def).map_err(|m| bad(Location::File, m.to_string()))?;
            mesh.positions.reserve_exact(def.count);
            if plan.normal.is_some() {
                mesh.normals.reserve_exact(def.count);
            }
            if plan.uv.is_some() {
                mesh.uvs.reserve_exact(def.count);
            }
            mesh.vertex_attrs = plan.attrs.iter().map(|a| new_attr(a, def.count)).collect();
            vplan = Some(plan);
        } else if is_face {
            let plan = FacePlan::new(def).map_err(|m| bad(Location::File, m.to_string()))?;
            mesh.indices.reserve(def.count);
            mesh.face_attrs = plan.attrs.iter().map(|a| new_attr(a, def.count)).collect();
            fplan = Some(plan);
        }
        for i in 0..def.count {
            line += 1;
            let at = || match header.encoding {
                Encoding::Ascii => Location::Line(line),
                _ => Location::Element(def.name.clone(), i as u64),
            };
            let row = match header.encoding {
                Encoding::Ascii => {
                    text.clear();
                    match reader.get_mut().read_line(&mut text) {
                        Ok(0) => return Err(bad(at(), format!("the file ends before `{}` element {i}", def.name))),
                        Ok(_) => parser.read_ascii_element(&text, def),
                        Err(e) => return Err(bad(at(), format!("cannot read `{}` element {i}: {e}", def.name))),
                    }
                }
                Encoding::BinaryLittleEndian => parser.read_little_endian_element(reader.get_mut(), def),
                Encoding::BinaryBigEndian => parser.read_big_endian_element(reader.get_mut(), def),
            }
            .map_err(|e| bad(at(), format!("bad `{}` element {i}: {e}", def.name)))?;
            if is_vertex {
                vplan.as_ref().unwrap().read(&row, &mut mesh).map_err(|m| bad(at(), m.to_string()))?;
            } else if is_face {
                fplan.as_ref().unwrap().read(&row, &mut mesh).map_err(|m| bad(at(), m.to_string()))?;
            }
        }
    }
    if mesh.indices.is_empty() {
        return Err(bad(Location::File, "no triangles".into()));
    }
    let n = mesh.positions.len();
    for (f, t) in mesh.indices.iter().enumerate() {
        if let Some(&i) = t.iter().find(|&&i| i as usize >= n) {
            return Err(bad(
                Location::Element("triangle".into(), f as u64),
                format!("vertex index {i} is out of range (the file has {n} vertices)"),
            ));
        }
    }
    Ok(mesh)
}

fn find_header_end(bytes: &[u8]) -> Option<usize> {
    let key = b"end_header";
    let at = bytes.windows(key.len()).position(|w| w == key)?;
    let nl = bytes[at..].iter().position(|&b| b == b'\n')?;
    Some(at + nl + 1)
}

/// What is wrong with a PLY header's elements or one row of them (the loader adds file and line).
#[derive(Debug, thiserror::Error)]
enum PlyRowError {
    /// a scalar column holds no number
    #[error("{0} is not a number")]
    NotANumber(&'static str),
    /// a vertex field is infinite or NaN
    #[error("{what} {value} is not finite")]
    NotFinite {
        /// which field (`vertex position`, `vertex normal`, `texture coordinate`)
        what: &'static str,
        /// its value as read
        value: String,
    },
    /// a required column is missing from the header
    #[error("{0}")]
    MissingColumn(&'static str),
    /// a face's index list is not a list of integers
    #[error("vertex indices are not an integer list")]
    NotAList,
    /// a face with fewer than three vertices
    #[error("a face has {0} vertices (at least 3 needed)")]
    TooFewVertices(usize),
    /// a vertex index outside u32 (or the u32::MAX sentinel)
    #[error("vertex index {0} is out of range")]
    IndexOutOfRange(i64),
}

fn new_attr(plan: &AttrPlan, count: usize) -> MeshAttr {
    MeshAttr { name: plan.name.clone(), dims: plan.dims, data: Vec::with_capacity(plan.dims * count) }
}

fn push_attrs(plans: &[AttrPlan], attrs: &mut [MeshAttr], row: &Row) -> Result<(), PlyRowError> {
    for (plan, attr) in plans.iter().zip(attrs) {
        let mut v = [0.0f32; 3];
        for &(col, c, s) in &plan.columns {
            v[c] = scalar(&row.0[col]).ok_or(PlyRowError::NotANumber("attribute"))? as f32 * s;
        }
        attr.data.extend_from_slice(&v[..plan.dims]);
    }
    Ok(())
}

/// Scalar columns of an element that are not in `used`, as (index, name, type).
fn other_columns<'a>(def: &'a ElementDef, used: &[usize]) -> Vec<(usize, &'a str, ScalarType)> {
    def.properties
        .values()
        .enumerate()
        .filter(|(k, _)| !used.contains(k))
        .filter_map(|(k, p)| match &p.data_type {
            PropertyType::Scalar(t) => Some((k, p.name.as_str(), t.clone())),
            PropertyType::List(..) => None,
        })
        .collect()
}

fn column(def: &ElementDef, name: &str) -> Option<usize> {
    def.properties.values().position(|p| p.name == name && matches!(p.data_type, PropertyType::Scalar(_)))
}

fn columns<const N: usize>(def: &ElementDef, names: [&str; N]) -> Option<[usize; N]> {
    let found = names.map(|n| column(def, n));
    found.iter().all(Option::is_some).then(|| found.map(Option::unwrap))
}

struct VertexPlan {
    position: [usize; 3],
    normal: Option<[usize; 3]>,
    uv: Option<[usize; 2]>,
    attrs: Vec<AttrPlan>,
}

impl VertexPlan {
    fn new(def: &ElementDef) -> Result<Self, PlyRowError> {
        let position = columns(def, ["x", "y", "z"])
            .ok_or(PlyRowError::MissingColumn("the `vertex` element has no scalar `x`, `y` and `z`"))?;
        let normal = columns(def, ["nx", "ny", "nz"]);
        let uv = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"], ["texture_s", "texture_t"]]
            .into_iter()
            .find_map(|names| columns(def, names));
        let mut used: Vec<usize> = position.to_vec();
        used.extend(normal.iter().flatten());
        used.extend(uv.iter().flatten());
        let attrs = plan_attrs("vertex_", &other_columns(def, &used));
        Ok(Self { position, normal, uv, attrs })
    }

    fn read(&self, row: &Row, mesh: &mut Mesh) -> Result<(), PlyRowError> {
        let get = |k: usize| scalar(&row.0[k]).map(|v| v as f32).ok_or(PlyRowError::NotANumber("a vertex field"));
        let p = Vec3::new(get(self.position[0])?, get(self.position[1])?, get(self.position[2])?);
        if !p.is_finite() {
            return Err(PlyRowError::NotFinite { what: "vertex position", value: p.to_string() });
        }
        mesh.positions.push(p);
        if let Some([a, b, c]) = self.normal {
            let n = Vec3::new(get(a)?, get(b)?, get(c)?);
            if !n.is_finite() {
                return Err(PlyRowError::NotFinite { what: "vertex normal", value: n.to_string() });
            }
            mesh.normals.push(n.normalize_or_zero());
        }
        if let Some([a, b]) = self.uv {
            let uv = Vec2::new(get(a)?, get(b)?);
            if !uv.is_finite() {
                return Err(PlyRowError::NotFinite { what: "texture coordinate", value: uv.to_string() });
            }
            mesh.uvs.push(uv);
        }
        push_attrs(&self.attrs, &mut mesh.vertex_attrs, row)
    }
}

struct FacePlan {
    indices: usize,
    attrs: Vec<AttrPlan>,
}

impl FacePlan {
    fn new(def: &ElementDef) -> Result<Self, PlyRowError> {
        let indices = def
            .properties
            .values()
            .position(|p| {
                (p.name == "vertex_indices" || p.name == "vertex_index")
                    && matches!(p.data_type, PropertyType::List(..))
            })
            .ok_or(PlyRowError::MissingColumn("the `face` element has no list `vertex_indices` (or `vertex_index`)"))?;
        Ok(Self { indices, attrs: plan_attrs("face_", &other_columns(def, &[indices])) })
    }

    fn read(&self, row: &Row, mesh: &mut Mesh) -> Result<(), PlyRowError> {
        let idx = list(&row.0[self.indices]).ok_or(PlyRowError::NotAList)?;
        if idx.len() < 3 {
            return Err(PlyRowError::TooFewVertices(idx.len()));
        }
        let idx = idx
            .iter()
            .map(|&i| u32::try_from(i).ok().filter(|&i| i != u32::MAX).ok_or(PlyRowError::IndexOutOfRange(i)))
            .collect::<Result<Vec<u32>, PlyRowError>>()?;
        for k in 1..idx.len() - 1 {
            mesh.indices.push([idx[0], idx[k], idx[k + 1]]);
            if k > 1 {
                // The face's attributes again for each further triangle of its fan.
                for a in &mut mesh.face_attrs {
                    let last = a.data.len() - a.dims;
                    a.data.extend_from_within(last..);
                }
            } else {
                push_attrs(&self.attrs, &mut mesh.face_attrs, row)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
#[path = "ply_tests.rs"]
mod tests;

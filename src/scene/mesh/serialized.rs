//! Mitsuba's `.serialized` meshes (format versions 3 and 4), zlib through `flate2`.
//!
//! A file holds shapes one after another, then a dictionary: the byte offset of each shape (u64
//! in version 4, u32 in version 3) and, last, their count (u32); all little endian. A shape is a
//! u16 magic `0x041C`, a u16 version and a zlib stream holding: u32 flags (`0x0001` vertex
//! normals, `0x0002` uvs, `0x0008` vertex colors, `0x0010` face normals, `0x1000` single or
//! `0x2000` double precision), in version 4 a NUL-terminated name, u64 vertex count, u64 triangle
//! count, positions, normals, uvs, colors (3 values per vertex each, 2 for uvs) and the triangles'
//! indices (u32, or u64 when there are more than 2^32 vertices).
//!
//! [`load_serialized`] reads shape `shape_index` (Mitsuba's property). Vertex colors become the
//! `vertex_color` attribute; the face-normals flag drops the normals (as Mitsuba's
//! `face_normals`). Refused with the file and the shape or byte: a bad magic, version or
//! dictionary, an index past the count, counts above `--limit max_vertices`/`max_primitives` or
//! larger than the decompressed stream can hold (checked before allocating: the stream is
//! inflated only up to the size its counts need), truncated or corrupt zlib data, non-finite
//! values and indices out of range.

use super::{check_limit, Location, Mesh, MeshAttr, MeshError};
use crate::scene::limits::Limits;
use glam::{Vec2, Vec3};
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_UVS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const SINGLE: u32 = 0x1000;
const DOUBLE: u32 = 0x2000;

/// Loads shape `shape_index` (0-based) of a `.serialized` file within `limits`.
pub fn load_serialized(path: &Path, shape_index: u32, limits: &Limits) -> Result<Mesh, MeshError> {
    let io = |source| MeshError::Io { file: path.to_path_buf(), source };
    let (mut file, len) = crate::files::open_regular(path).map_err(io)?;
    check_limit(path, "bytes", len, limits.max_file_bytes, "max_file_bytes")?;
    let bad = |at: Location, msg: String| MeshError::malformed(path, at, msg);
    if len < 8 {
        return Err(bad(Location::File, format!("{len} bytes: too short for a serialized mesh")));
    }
    let mut word = [0u8; 4];
    file.seek(SeekFrom::Start(len - 4)).and_then(|_| file.read_exact(&mut word)).map_err(io)?;
    let count = u32::from_le_bytes(word);
    let mut head = [0u8; 4];
    file.seek(SeekFrom::Start(0)).and_then(|_| file.read_exact(&mut head)).map_err(io)?;
    let version = u16::from_le_bytes([head[2], head[3]]);
    if u16::from_le_bytes([head[0], head[1]]) != MAGIC || !(version == 3 || version == 4) {
        return Err(bad(Location::Byte(0), "not a Mitsuba serialized mesh (magic 0x041C, version 3 or 4)".into()));
    }
    if shape_index >= count {
        return Err(bad(Location::File, format!("shape_index {shape_index}: the file holds {count} shapes")));
    }
    let entry = if version == 4 { 8 } else { 4 };
    let table = u64::from(count) * entry + 4;
    if table > len {
        return Err(bad(Location::File, format!("a dictionary of {count} shapes does not fit in {len} bytes")));
    }
    let mut off = [0u8; 8];
    let at = len - table + u64::from(shape_index) * entry;
    file.seek(SeekFrom::Start(at)).and_then(|_| file.read_exact(&mut off[..entry as usize])).map_err(io)?;
    let start = u64::from_le_bytes(off);
    let end = if shape_index + 1 < count {
        file.seek(SeekFrom::Start(at + entry)).and_then(|_| file.read_exact(&mut off[..entry as usize])).map_err(io)?;
        u64::from_le_bytes(off)
    } else {
        len - table
    };
    if !(start + 4 <= end && end <= len - table) {
        return Err(bad(Location::Element("shape".into(), shape_index.into()), format!("bad offsets {start}..{end}")));
    }
    let mut shape = vec![0u8; (end - start) as usize];
    file.seek(SeekFrom::Start(start)).and_then(|_| file.read_exact(&mut shape)).map_err(io)?;
    parse_shape(path, shape_index, start, &shape, limits)
}

/// Reads the little-endian fields of a decompressed shape stream.
struct Stream<'a> {
    z: flate2::read::ZlibDecoder<&'a [u8]>,
}

impl Stream<'_> {
    fn bytes<const N: usize>(&mut self) -> std::io::Result<[u8; N]> {
        let mut b = [0u8; N];
        self.z.read_exact(&mut b)?;
        Ok(b)
    }
    fn float(&mut self, double: bool) -> std::io::Result<f32> {
        Ok(if double { f64::from_le_bytes(self.bytes()?) as f32 } else { f32::from_le_bytes(self.bytes()?) })
    }
    fn vec3(&mut self, double: bool) -> std::io::Result<Vec3> {
        Ok(Vec3::new(self.float(double)?, self.float(double)?, self.float(double)?))
    }
}

fn parse_shape(path: &Path, index: u32, start: u64, shape: &[u8], limits: &Limits) -> Result<Mesh, MeshError> {
    let at = || Location::Element("shape".into(), index.into());
    let bad = |msg: String| MeshError::malformed(path, at(), msg);
    let version = u16::from_le_bytes([shape[2], shape[3]]);
    if u16::from_le_bytes([shape[0], shape[1]]) != MAGIC || !(version == 3 || version == 4) {
        return Err(MeshError::malformed(
            path,
            Location::Byte(start),
            "no serialized shape starts here (bad magic or version)",
        ));
    }
    let mut s = Stream { z: flate2::read::ZlibDecoder::new(&shape[4..]) };
    let zerr = |e: std::io::Error, what: &str| bad(format!("cannot decompress {what}: {e} (truncated or corrupt)"));
    let flags = u32::from_le_bytes(s.bytes().map_err(|e| zerr(e, "the flags"))?);
    let double = match flags & (SINGLE | DOUBLE) {
        SINGLE => false,
        DOUBLE => true,
        _ => return Err(bad(format!("flags {flags:#x}: neither single (0x1000) nor double (0x2000) precision"))),
    };
    if version == 4 {
        let mut name_len = 0;
        loop {
            let [b] = s.bytes().map_err(|e| zerr(e, "the name"))?;
            if b == 0 {
                break;
            }
            name_len += 1;
            if name_len > 1 << 16 {
                return Err(bad("the shape's name is not terminated".into()));
            }
        }
    }
    let nv = u64::from_le_bytes(s.bytes().map_err(|e| zerr(e, "the counts"))?);
    let nt = u64::from_le_bytes(s.bytes().map_err(|e| zerr(e, "the counts"))?);
    check_limit(path, "vertices", nv, limits.max_vertices as u64, "max_vertices")?;
    check_limit(path, "triangles", nt, limits.max_primitives as u64, "max_primitives")?;
    let fsize = if double { 8 } else { 4 };
    let per_vertex = fsize
        * (3 + 3 * u64::from(flags & HAS_NORMALS != 0)
            + 2 * u64::from(flags & HAS_UVS != 0)
            + 3 * u64::from(flags & HAS_COLORS != 0));
    let wide = nv > u64::from(u32::MAX);
    let need = nv * per_vertex + nt * 3 * if wide { 8 } else { 4 };
    // zlib cannot expand data by more than about 1032:1: a count whose data could not come from
    // this many compressed bytes is refused before anything is allocated.
    if need > (shape.len() as u64).saturating_mul(1100) {
        return Err(bad(format!(
            "{nv} vertices and {nt} triangles need {need} bytes of data, more than {} compressed bytes can hold",
            shape.len()
        )));
    }
    let (nvu, ntu) = (nv as usize, nt as usize);
    let mut m = Mesh::default();
    let trunc = |e| zerr(e, "the data");
    m.positions.reserve_exact(nvu);
    for i in 0..nvu {
        let p = s.vec3(double).map_err(trunc)?;
        if !p.is_finite() {
            return Err(bad(format!("vertex {i}: position {p} is not finite")));
        }
        m.positions.push(p);
    }
    if flags & HAS_NORMALS != 0 {
        m.normals.reserve_exact(nvu);
        for i in 0..nvu {
            let n = s.vec3(double).map_err(trunc)?;
            if !n.is_finite() {
                return Err(bad(format!("vertex {i}: normal {n} is not finite")));
            }
            m.normals.push(n.normalize_or_zero());
        }
    }
    if flags & HAS_UVS != 0 {
        m.uvs.reserve_exact(nvu);
        for i in 0..nvu {
            let uv = Vec2::new(s.float(double).map_err(trunc)?, s.float(double).map_err(trunc)?);
            if !uv.is_finite() {
                return Err(bad(format!("vertex {i}: uv {uv} is not finite")));
            }
            m.uvs.push(uv);
        }
    }
    if flags & HAS_COLORS != 0 {
        let mut data = Vec::with_capacity(3 * nvu);
        for _ in 0..nvu {
            data.extend(s.vec3(double).map_err(trunc)?.to_array());
        }
        m.vertex_attrs.push(MeshAttr { name: "vertex_color".into(), dims: 3, data });
    }
    m.indices.reserve_exact(ntu);
    for f in 0..ntu {
        let mut t = [0u32; 3];
        for c in &mut t {
            let i = if wide {
                u64::from_le_bytes(s.bytes().map_err(trunc)?)
            } else {
                u32::from_le_bytes(s.bytes().map_err(trunc)?).into()
            };
            if i >= nv {
                return Err(bad(format!("triangle {f}: vertex index {i} is out of range ({nv} vertices)")));
            }
            *c = i as u32;
        }
        m.indices.push(t);
    }
    if flags & FACE_NORMALS != 0 {
        m.face_normals();
    }
    Ok(m)
}

#[cfg(test)]
#[path = "serialized_tests.rs"]
mod tests;

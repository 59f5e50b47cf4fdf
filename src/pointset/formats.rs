//! Point-set file formats: UTK text (one point per line, coordinates separated by spaces, sets
//! separated by lines starting with `#`), UTK binary (`.bin`: the `UTK!` header, then the data)
//! and NumPy `.npy` (`[sets, points, dims]` or `[points, dims]`, float32 or float64). Reading
//! checks shape and values ([`PointSets::check`]); writing is what `strata pointset --export`
//! uses.

use super::{PointSetError, PointSets};
use std::io::Write;
use std::path::Path;

/// UTK's binary magic number, "UTK!" read as a little-endian u32.
const UTK_MAGIC: u32 = 0x214B_5455;
/// UTK binary data type codes.
const UTK_F32: u8 = 4;
const UTK_F64: u8 = 5;

/// A point-set file's format, from its extension: `.bin` UTK binary, `.npy` NumPy, else UTK text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// UTK text
    Text,
    /// UTK binary
    UtkBin,
    /// NumPy `.npy`
    Npy,
}

impl Format {
    /// The format of `path` by extension (case-insensitive).
    pub fn of(path: &Path) -> Self {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("bin") => Self::UtkBin,
            Some("npy") => Self::Npy,
            _ => Self::Text,
        }
    }
}

/// The largest point-set file read (1 GiB: 2^26 points of two coordinates as UTK text take about
/// 1.6 GB, far above any sampler's use): a sparse or endless file is refused before it is read.
pub const MAX_POINTSET_BYTES: u64 = 1 << 30;

/// Reads and checks the point sets in `path` (format by extension), through the bounded reader
/// ([`crate::files::read_bounded`]: a regular file of at most [`MAX_POINTSET_BYTES`]).
pub fn read(path: &Path) -> Result<PointSets, PointSetError> {
    let bytes = crate::files::read_bounded(path, MAX_POINTSET_BYTES)
        .map_err(|source| PointSetError::Io { path: path.to_path_buf(), source })?;
    let name = path.display().to_string();
    let ps = match Format::of(path) {
        Format::Text => parse_text(&name, &bytes)?,
        Format::UtkBin => parse_utk_bin(&name, &bytes)?,
        Format::Npy => parse_npy(&name, &bytes)?,
    };
    Ok(PointSets { digest: crate::checkpoint::hash_bytes(&bytes), ..ps })
}

/// UTK text: points per line, `#` lines between sets; blank lines ignored. Values are checked
/// here, with the line of each point in the message.
pub fn parse_text(name: &str, bytes: &[u8]) -> Result<PointSets, PointSetError> {
    let text = std::str::from_utf8(bytes).map_err(|e| PointSetError::Format {
        source_name: name.into(),
        why: format!("not UTF-8 text ({e}); binary files need the .bin or .npy extension"),
    })?;
    let (mut data, mut dims, mut sets, mut in_set, mut set_points) = (Vec::new(), 0usize, 0usize, 0usize, None);
    let mut close_set = |in_set: &mut usize, sets: &mut usize, line: usize| -> Result<(), PointSetError> {
        if *in_set == 0 {
            return Ok(());
        }
        match set_points {
            None => set_points = Some(*in_set),
            Some(p) if p != *in_set => {
                return Err(PointSetError::UnequalSets {
                    source_name: name.into(),
                    set: *sets,
                    points: *in_set,
                    first: p,
                    at: format!(" (ending before line {line})"),
                })
            }
            _ => {}
        }
        *sets += 1;
        *in_set = 0;
        Ok(())
    };
    let mut last_line = 0;
    for (i, line) in text.lines().enumerate() {
        let (line, no) = (line.trim(), i + 1);
        last_line = no;
        if line.is_empty() {
            continue;
        }
        if line.starts_with('#') {
            close_set(&mut in_set, &mut sets, no)?;
            continue;
        }
        let start = data.len();
        for word in line.split_whitespace() {
            let v: f64 = word.parse().map_err(|_| PointSetError::Line {
                source_name: name.into(),
                line: no,
                why: format!("`{word}` is not a number (a point is coordinates separated by spaces)"),
            })?;
            data.push(v);
        }
        let d = data.len() - start;
        if dims == 0 {
            dims = d;
        } else if d != dims {
            return Err(PointSetError::Line {
                source_name: name.into(),
                line: no,
                why: format!("{d} coordinates, the file's first point has {dims}"),
            });
        }
        for (c, &v) in data[start..].iter().enumerate() {
            super::check_value(v).map_err(|why| PointSetError::Line {
                source_name: name.into(),
                line: no,
                why: format!("set {sets}, point {in_set}, coordinate {c}: {why}"),
            })?;
        }
        in_set += 1;
    }
    close_set(&mut in_set, &mut sets, last_line + 1)?;
    let points = set_points.unwrap_or(0);
    PointSets::new(name, sets, points, dims, data)
}

/// UTK binary: u32 magic "UTK!", 4 metadata bytes (byte 0 the data type: 4 float, 5 double; the
/// integer types are refused), u32 set count, u32 points per set, u32 dimension, then the values
/// set by set, point by point, little-endian.
pub fn parse_utk_bin(name: &str, bytes: &[u8]) -> Result<PointSets, PointSetError> {
    let bad = |why: String| PointSetError::Format { source_name: name.into(), why };
    if bytes.len() < 20 {
        return Err(bad(format!("{} bytes, shorter than the 20-byte UTK header", bytes.len())));
    }
    let word = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    if word(0) != UTK_MAGIC {
        return Err(bad(format!("no `UTK!` magic number (first bytes {:02x?})", &bytes[..4])));
    }
    let dtype = bytes[4];
    let (sets, points, dims) = (word(8) as usize, word(12) as usize, word(16) as usize);
    let size = match dtype {
        UTK_F32 => 4,
        UTK_F64 => 8,
        0..=3 => {
            return Err(bad(format!(
                "integer coordinates (UTK type {dtype}); strata needs points in [0, 1): write float or double"
            )))
        }
        _ => return Err(bad(format!("unknown UTK data type {dtype} (4 float and 5 double are read)"))),
    };
    let count = sets.checked_mul(points).and_then(|n| n.checked_mul(dims));
    let body = &bytes[20..];
    if count.and_then(|n| n.checked_mul(size)) != Some(body.len()) {
        return Err(bad(format!(
            "the header says {sets} sets x {points} points x {dims} dimensions of {size} bytes, the file holds {} data bytes",
            body.len()
        )));
    }
    let data = match size {
        4 => body.chunks_exact(4).map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]]))).collect(),
        _ => body.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes"))).collect(),
    };
    PointSets::new(name, sets, points, dims, data)
}

/// NumPy `.npy`: float32 or float64 (either byte order), C or Fortran order, shape
/// `[sets, points, dims]` or `[points, dims]` (one set).
pub fn parse_npy(name: &str, bytes: &[u8]) -> Result<PointSets, PointSetError> {
    let bad = |why: String| PointSetError::Format { source_name: name.into(), why };
    let npy = npyz::NpyFile::new(bytes).map_err(|e| bad(format!("not a NumPy .npy file: {e}")))?;
    let shape: Vec<usize> = npy.shape().iter().map(|&d| d as usize).collect();
    check_npy_length(bytes, &shape, &npy.dtype().descr()).map_err(|e| bad(e.to_string()))?;
    let (sets, points, dims) = match shape[..] {
        [p, d] => (1, p, d),
        [s, p, d] => (s, p, d),
        _ => return Err(bad(format!("shape {shape:?}: expected [sets, points, dims] or [points, dims]"))),
    };
    let fortran = npy.order() == npyz::Order::Fortran;
    let descr = npy.dtype().descr();
    let data: Vec<f64> = if descr.contains("f8") {
        npy.into_vec::<f64>().map_err(|e| bad(e.to_string()))?
    } else if descr.contains("f4") {
        npy.into_vec::<f32>().map_err(|e| bad(e.to_string()))?.into_iter().map(f64::from).collect()
    } else {
        return Err(bad(format!("dtype {descr}: expected float32 or float64")));
    };
    let data = if fortran {
        // Element (s, p, d) sits at s + sets * (p + points * d).
        let mut c = vec![0.0; data.len()];
        for s in 0..sets {
            for p in 0..points {
                for d in 0..dims {
                    c[(s * points + p) * dims + d] = data[s + sets * (p + points * d)];
                }
            }
        }
        c
    } else {
        data
    };
    PointSets::new(name, sets, points, dims, data)
}

/// Why an `.npy` file's length does not match its header.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum NpyLengthError {
    /// the header's length field is missing
    #[error("truncated header")]
    TruncatedHeader,
    /// the declared shape overflows 64 bits of bytes
    #[error("shape {0:?} is too large")]
    TooLarge(Vec<usize>),
    /// the file ends before the data its header declares
    #[error("truncated: the header declares shape {shape:?} of {descr} ({data} bytes of data), the file ends {short} bytes short")]
    Truncated {
        /// the declared shape
        shape: Vec<usize>,
        /// the declared item type
        descr: String,
        /// bytes of data declared
        data: u64,
        /// bytes missing
        short: u64,
    },
    /// bytes after the declared array
    #[error("{extra} trailing bytes after the {shape:?} array its header declares")]
    Trailing {
        /// bytes past the array
        extra: u64,
        /// the declared shape
        shape: Vec<usize>,
    },
}

/// Checks that an `.npy` file holds exactly the data its header declares (`shape` of items of
/// `descr`): a short file is named as truncated, bytes after the array are refused.
fn check_npy_length(bytes: &[u8], shape: &[usize], descr: &str) -> Result<(), NpyLengthError> {
    let major = bytes.get(6).copied().unwrap_or(0);
    let start = match major {
        1 => bytes.get(8..10).map(|b| 10 + u16::from_le_bytes([b[0], b[1]]) as u64),
        _ => bytes.get(8..12).map(|b| 12 + u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64),
    }
    .ok_or(NpyLengthError::TruncatedHeader)?;
    let item: u64 = descr.chars().filter(char::is_ascii_digit).collect::<String>().parse().unwrap_or(0);
    let data = shape
        .iter()
        .try_fold(item, |n, &d| n.checked_mul(d as u64))
        .ok_or_else(|| NpyLengthError::TooLarge(shape.to_vec()))?;
    let want = start.saturating_add(data);
    let have = bytes.len() as u64;
    if have < want {
        return Err(NpyLengthError::Truncated { shape: shape.to_vec(), descr: descr.into(), data, short: want - have });
    }
    if have > want {
        return Err(NpyLengthError::Trailing { extra: have - want, shape: shape.to_vec() });
    }
    Ok(())
}

/// Writes `ps` to `path` in the format of its extension (values printed so they read back
/// exactly: Rust's shortest round-trip form of the f64).
pub fn write(path: &Path, ps: &PointSets) -> Result<(), PointSetError> {
    let mut out = Vec::new();
    match Format::of(path) {
        Format::Text => {
            for s in 0..ps.sets {
                if s > 0 {
                    out.extend_from_slice(b"#\n");
                }
                for p in 0..ps.points {
                    let pt = ps.point(s, p);
                    let words: Vec<String> = pt.iter().map(|v| format!("{v}")).collect();
                    writeln!(out, "{}", words.join(" ")).expect("write to a Vec");
                }
            }
        }
        Format::UtkBin => {
            out.extend_from_slice(&UTK_MAGIC.to_le_bytes());
            out.extend_from_slice(&[UTK_F64, 0, 0, 0]);
            for n in [ps.sets, ps.points, ps.dims] {
                out.extend_from_slice(&(n as u32).to_le_bytes());
            }
            for v in &ps.data {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        Format::Npy => {
            use npyz::WriterBuilder;
            let shape = [ps.sets as u64, ps.points as u64, ps.dims as u64];
            let mut w = npyz::WriteOptions::new()
                .default_dtype()
                .shape(&shape)
                .writer(&mut out)
                .begin_nd()
                .map_err(|source| PointSetError::Io { path: path.to_path_buf(), source })?;
            w.extend(ps.data.iter().copied())
                .map_err(|source| PointSetError::Io { path: path.to_path_buf(), source })?;
            w.finish().map_err(|source| PointSetError::Io { path: path.to_path_buf(), source })?;
        }
    }
    crate::film::write_atomic(path, &out).map_err(|source| PointSetError::Io { path: path.to_path_buf(), source })
}

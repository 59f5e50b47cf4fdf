//! The checkpoint file format (version 1): see the [module doc](super).

use super::{fnv1a, CheckpointError, Header};
use crate::film::{self, Block, Film, Moments};
use std::path::Path;

/// File magic.
pub const MAGIC: &[u8; 8] = b"STRATACK";
/// Format version written and read.
pub const VERSION: u32 = 1;
/// Refuse headers larger than this (a corrupt length must not allocate gigabytes).
const MAX_HEADER: u64 = 64 << 20;

/// Checksum of a file body: FNV-1a over 8-byte words (fast enough for GB-sized states), then over
/// the tail bytes.
fn checksum(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let words = bytes.chunks_exact(8);
    let tail = words.remainder();
    for w in words {
        h ^= u64::from_le_bytes(w.try_into().expect("8 bytes"));
        h = h.wrapping_mul(0x0000_0100_0000_01b3).rotate_left(29);
    }
    fnv1a(h, tail)
}

/// The header for `film` (its samples and blocks filled in from the film).
pub fn header_for(mut base: Header, film: &Film) -> Header {
    let s = film.samples();
    base.width = film.width;
    base.height = film.height;
    base.samples = [s.start, s.end];
    base.blocks = film.blocks().iter().map(|b| [u32::from(b.k), b.j]).collect();
    base
}

/// Serializes `film` with `header` (whose samples and blocks are overwritten from the film).
pub fn to_bytes(header: &Header, film: &Film) -> Vec<u8> {
    let header = header_for(header.clone(), film);
    let json = serde_json::to_vec(&header).expect("a header serializes");
    let data = film.block_data();
    let mut out = Vec::with_capacity(28 + json.len() + data.len() * 48);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(json.len() as u64).to_le_bytes());
    out.extend_from_slice(&json);
    for m in data {
        for v in m {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    let sum = checksum(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// Writes a checkpoint atomically (temporary file, fsync, rename).
pub fn write(path: &Path, header: &Header, film: &Film) -> Result<(), CheckpointError> {
    film::write_atomic(path, &to_bytes(header, film))
        .map_err(|source| CheckpointError::Write { path: path.to_path_buf(), source })
}

/// Parses checkpoint bytes; `name` labels errors.
pub fn from_bytes(bytes: &[u8], name: &str) -> Result<(Header, Film), CheckpointError> {
    let bad = |why: String| CheckpointError::Unusable { name: name.to_string(), why };
    if bytes.len() < 8 || &bytes[..8] != MAGIC {
        return Err(bad("wrong magic (not a strata checkpoint file)".into()));
    }
    if bytes.len() < 28 {
        return Err(bad(format!("truncated ({} bytes)", bytes.len())));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != VERSION {
        return Err(bad(format!("format version {version}, this strata reads version {VERSION}")));
    }
    let hlen = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    if hlen > MAX_HEADER || 20 + hlen + 8 > bytes.len() as u64 {
        return Err(bad(format!("truncated or corrupt (header of {hlen} bytes in a file of {})", bytes.len())));
    }
    let body_end = bytes.len() - 8;
    let stored = u64::from_le_bytes(bytes[body_end..].try_into().expect("8 bytes"));
    let hend = 20 + hlen as usize;
    let header: Header = serde_json::from_slice(&bytes[20..hend]).map_err(|e| bad(format!("corrupt header: {e}")))?;
    let pixels = header.width as u64 * header.height as u64;
    let max = crate::scene::parse::Limits::default().max_pixels;
    if pixels == 0 || pixels > max {
        return Err(bad(format!("image size {}x{} outside 1..={max} pixels", header.width, header.height)));
    }
    let expected =
        (hend as u64).saturating_add((header.blocks.len() as u64).saturating_mul(pixels).saturating_mul(48)) + 8;
    if expected != bytes.len() as u64 {
        return Err(bad(format!(
            "truncated or corrupt: {} bytes, expected {expected} for {} blocks of {}x{} pixels",
            bytes.len(),
            header.blocks.len(),
            header.width,
            header.height
        )));
    }
    if checksum(&bytes[..body_end]) != stored {
        return Err(bad("checksum mismatch (the file is corrupt)".into()));
    }
    let mut blocks = Vec::with_capacity(header.blocks.len());
    for &[k, j] in &header.blocks {
        let k = u8::try_from(k).ok().filter(|&k| k <= 32).ok_or_else(|| bad(format!("bad block size 2^{k}")))?;
        blocks.push(Block { k, j });
    }
    let data: Vec<Moments> = bytes[hend..body_end]
        .chunks_exact(48)
        .map(|c| std::array::from_fn(|q| f64::from_le_bytes(c[8 * q..8 * q + 8].try_into().expect("8 bytes"))))
        .collect();
    let [lo, hi] = header.samples;
    if lo > hi {
        return Err(bad(format!("bad sample range {lo}..{hi}")));
    }
    let film = Film::from_parts(header.width, header.height, lo..hi, blocks, data).map_err(|e| bad(e.to_string()))?;
    Ok((header, film))
}

/// Reads a checkpoint written by [`write`], checking magic, version, size and checksum, through
/// the bounded reader: a regular file only ([`crate::files::open_regular`]); the magic, version
/// and header are read and checked first, and the file's size must be exactly what the header
/// declares (no truncation, no trailing bytes) before the body is read.
pub fn read(path: &Path) -> Result<(Header, Film), CheckpointError> {
    let name = path.display().to_string();
    let io = |source| CheckpointError::Read { path: path.to_path_buf(), source };
    let (mut file, len) = crate::files::open_regular(path).map_err(io)?;
    let head = crate::files::read_exact_len(&mut file, 20).map_err(io)?;
    let bad = |why: String| CheckpointError::Unusable { name: name.clone(), why };
    if head.len() < 8 || &head[..8] != MAGIC {
        return Err(bad("wrong magic (not a strata checkpoint file)".into()));
    }
    if head.len() < 20 {
        return Err(bad(format!("truncated ({len} bytes)")));
    }
    let version = u32::from_le_bytes(head[8..12].try_into().expect("4 bytes"));
    if version != VERSION {
        return Err(bad(format!("format version {version}, this strata reads version {VERSION}")));
    }
    let hlen = u64::from_le_bytes(head[12..20].try_into().expect("8 bytes"));
    if hlen > MAX_HEADER || 20 + hlen + 8 > len {
        return Err(bad(format!("truncated or corrupt (header of {hlen} bytes in a file of {len})")));
    }
    let json = crate::files::read_exact_len(&mut file, hlen as usize).map_err(io)?;
    let header: Header = serde_json::from_slice(&json).map_err(|e| bad(format!("corrupt header: {e}")))?;
    let pixels = header.width as u64 * header.height as u64;
    let expected =
        (20 + hlen).saturating_add((header.blocks.len() as u64).saturating_mul(pixels).saturating_mul(48)) + 8;
    if expected != len {
        // More bytes than one record: the records of a replicated reference.
        let replicas = if expected < len {
            ", or the checkpoint of a reference's replicas (`strata reference` resumes it)"
        } else {
            ""
        };
        return Err(bad(format!(
            "truncated or corrupt: {len} bytes, expected {expected} for {} blocks of {}x{} pixels{replicas}",
            header.blocks.len(),
            header.width,
            header.height
        )));
    }
    let mut bytes = head;
    bytes.extend_from_slice(&json);
    bytes.extend(crate::files::read::read_all_of(file, len - 20 - hlen, len - 20 - hlen).map_err(io)?);
    from_bytes(&bytes, &name)
}

/// Writes the checkpoint of a replicated reference (`strata reference` with replicas): the
/// replicas' records, each a whole checkpoint as [`to_bytes`] makes it, one after another in
/// replica order, atomically.
pub fn write_replicas(path: &Path, records: &[Vec<u8>]) -> Result<(), CheckpointError> {
    film::write_atomic(path, &records.concat())
        .map_err(|source| CheckpointError::Write { path: path.to_path_buf(), source })
}

/// The length of the checkpoint record at the start of `b` from its header, if it parses.
fn record_len(b: &[u8]) -> Option<usize> {
    let hlen = u64::from_le_bytes(b.get(12..20)?.try_into().ok()?);
    let hend = 20usize.checked_add(usize::try_from(hlen).ok().filter(|&h| h as u64 <= MAX_HEADER)?)?;
    let header: Header = serde_json::from_slice(b.get(20..hend)?).ok()?;
    let pixels = header.width as u64 * header.height as u64;
    let n = (hend as u64).saturating_add((header.blocks.len() as u64).saturating_mul(pixels).saturating_mul(48)) + 8;
    Some(usize::try_from(n).ok()?.min(b.len()))
}

/// Reads a checkpoint of one render or of a replicated reference ([`write_replicas`]): its
/// records in order, each checked as [`from_bytes`] checks one (errors name the replica).
pub fn read_replicas(path: &Path) -> Result<Vec<(Header, Film)>, CheckpointError> {
    let name = path.display().to_string();
    let bytes = crate::files::read::read_bounded(path, u64::MAX)
        .map_err(|source| CheckpointError::Read { path: path.to_path_buf(), source })?;
    let (mut out, mut at) = (Vec::new(), 0);
    while at < bytes.len() || out.is_empty() {
        let rest = &bytes[at..];
        let n = record_len(rest).unwrap_or(rest.len());
        let label = if out.is_empty() { name.clone() } else { format!("{name} (replica {})", out.len() + 1) };
        out.push(from_bytes(&rest[..n], &label)?);
        at += n;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::hash_bytes;
    use super::*;

    fn film(r: std::ops::Range<u32>) -> Film {
        let mut f = Film::new(3, 2);
        for s in r {
            let px: Vec<[f32; 3]> =
                (0..6).map(|p| [s as f32 * 0.3 + p as f32, 1.0 / (1.0 + s as f32), -(p as f32)]).collect();
            f.add_sample(s, &px);
        }
        f
    }

    fn header() -> Header {
        let options = [
            ("spp", serde_json::json!(64)),
            ("seed", serde_json::json!(3)),
            ("pixel_sampler", serde_json::json!("sobol")),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
        Header {
            strata_version: "0.1.0".into(),
            strata_build: "b1".into(),
            strata_commit: "c1".into(),
            scene: "a.test".into(),
            scene_hash: hash_bytes(b"size 8 8\n"),
            options,
            width: 3,
            height: 2,
            target: [0, 64],
            samples: [0, 0],
            blocks: vec![],
            cpu_seconds: 1.5,
            render_seconds: 0.75,
            rays: 1000,
            parts: vec![],
        }
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let f = film(5..27);
        let bytes = to_bytes(&header(), &f);
        let (h, g) = from_bytes(&bytes, "x").unwrap();
        assert_eq!(g, f);
        assert_eq!((h.samples, h.blocks.len(), h.cpu_seconds), ([5, 27], f.blocks().len(), 1.5));
        assert_eq!(header_for(header(), &f), h);
        // An empty film round-trips too.
        let (_, e) = from_bytes(&to_bytes(&header(), &Film::new(3, 2)), "e").unwrap();
        assert_eq!(e.samples(), 0..0);
    }

    #[test]
    fn replica_records_round_trip_and_name_a_broken_one() {
        let dir = std::env::temp_dir().join(format!("strata-replicas-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("r.ckpt");
        let films = [film(0..9), film(0..9), film(0..16)];
        let records: Vec<Vec<u8>> = films.iter().map(|f| to_bytes(&header(), f)).collect();
        write_replicas(&p, &records).unwrap();
        let back = read_replicas(&p).unwrap();
        assert_eq!(back.iter().map(|(_, f)| f.clone()).collect::<Vec<_>>(), films);
        // One render's checkpoint reads as one record; `read` names a file of several.
        write(&p, &header(), &films[0]).unwrap();
        assert_eq!(read_replicas(&p).unwrap().len(), 1);
        write_replicas(&p, &records).unwrap();
        assert!(read(&p).unwrap_err().to_string().contains("replicas"));
        let mut bytes = records.concat();
        bytes.truncate(bytes.len() - 3);
        std::fs::write(&p, bytes).unwrap();
        let e = read_replicas(&p).unwrap_err().to_string();
        assert!(e.contains("(replica 3)") && e.contains("truncated"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn truncated_or_corrupt_files_are_clear_errors() {
        let bytes = to_bytes(&header(), &film(0..9));
        for cut in [0, 5, 12, 27, 40, bytes.len() / 2, bytes.len() - 9, bytes.len() - 1] {
            let e = from_bytes(&bytes[..cut], "t.ckpt").unwrap_err().to_string();
            assert!(e.starts_with("t.ckpt: "), "{e}");
            assert!(e.contains("truncated") || e.contains("magic") || e.contains("corrupt"), "cut {cut}: {e}");
        }
        // A flipped bit anywhere is caught (header or data).
        for at in [25, bytes.len() / 2, bytes.len() - 12] {
            let mut b = bytes.clone();
            b[at] ^= 0x10;
            assert!(from_bytes(&b, "c").is_err(), "flip at {at}");
        }
        let mut b = bytes.clone();
        b[8] = 9;
        assert!(from_bytes(&b, "v").unwrap_err().to_string().contains("version 9"));
        assert!(from_bytes(b"PNG....", "p").unwrap_err().to_string().contains("magic"));
    }

    #[test]
    fn mismatches_name_what_differs() {
        let a = header();
        assert_eq!(a.mismatch(&a.clone(), "this render"), None);
        let mut b = a.clone();
        b.scene_hash = hash_bytes(b"size 8 9\n");
        assert!(a.mismatch(&b, "this render").unwrap().contains("another scene"));
        let mut b = a.clone();
        b.options.insert("seed".into(), serde_json::json!(4));
        let m = a.mismatch(&b, "this render").unwrap();
        assert!(m.contains("seed 3 (this render: 4)"), "{m}");
        let mut b = a.clone();
        b.width = 4;
        assert!(a.mismatch(&b, "this render").unwrap().contains("3x2"));
        let mut b = a.clone();
        b.strata_version = "9.9.9".into();
        assert!(a.mismatch(&b, "this render").unwrap().contains("9.9.9"));
        // Another build is refused unless allowed, naming both builds.
        let mut b = a.clone();
        b.strata_build = "b2".into();
        let m = a.mismatch(&b, "this render").unwrap();
        assert!(m.contains("build b1") && m.contains("build b2") && m.contains("--allow-other-build"), "{m}");
        assert_eq!(a.mismatch_allowing(&b, "this render", true), None);
        // Parts from CPUs whose approximate reciprocals differ (Embree's AVX2 kernels) are
        // refused, saying why and what renders alike everywhere.
        let mut b = a.clone();
        let mut a2 = a.clone();
        a2.options.insert("embree_approx".into(), serde_json::json!("rcpps-80b65207868234cd"));
        b.options.insert("embree_approx".into(), serde_json::json!("rcpps-0123456789abcdef"));
        let m = a2.mismatch(&b, "this render").unwrap();
        assert!(m.contains("embree_approx") && m.contains("vrcpps") && m.contains("AVX-512 nodes"), "{m}");
        // Timing, ranges and parts are not identity.
        let mut b = a.clone();
        (b.cpu_seconds, b.target, b.parts) = (9.0, [0, 8], vec!["p".into()]);
        assert_eq!(a.mismatch(&b, "this render"), None);
    }
}

//! `.serialized` loader tests: the corpus files and hostile files written here.

use super::*;
use crate::scene::mesh::tests::corpus;
use std::io::Write;

fn load(rel: &str, index: u32) -> Mesh {
    let p = corpus(rel);
    let m = load_serialized(&p, index, &Limits::default()).unwrap_or_else(|e| panic!("{e}"));
    m.validate().unwrap();
    m
}

#[test]
fn corpus_rectangles() {
    let m = load("tests/serialized/rectangle_normals_uv.serialized", 0);
    assert_eq!((m.positions.len(), m.indices.len(), m.normals.len(), m.uvs.len()), (4, 2, 4, 4));
    assert_eq!(m.positions[0], Vec3::new(-2.85, 0.0, -7.6));
    assert!((m.area() - 5.7 * 8.2).abs() < 1e-3);
    let m = load("tests/serialized/rectangle_uv.serialized", 0);
    assert!(m.normals.is_empty() && m.uvs.len() == 4);
    let m = load("tests/serialized/rectangle_normals.serialized", 0);
    assert!(m.normals.len() == 4 && m.uvs.is_empty());
    assert_eq!(m.normals[0], Vec3::Y);
}

#[test]
fn corpus_matpreview_shape_index() {
    for (i, nv, nt) in [(0, 289, 512), (1, 2078, 3936), (2, 29439, 57152)] {
        let m = load("common/meshes/matpreview.serialized", i);
        assert_eq!((m.positions.len(), m.indices.len()), (nv, nt), "shape {i}");
        assert_eq!(m.normals.len(), nv);
    }
    let e = load_serialized(&corpus("common/meshes/matpreview.serialized"), 3, &Limits::default()).unwrap_err();
    assert!(e.to_string().contains("3 shapes"), "{e}");
}

/// A version-4 file of one shape whose stream is `payload` (flags onwards, after the name).
fn file(flags: u32, nv: u64, nt: u64, data: &[u8]) -> Vec<u8> {
    let mut raw = flags.to_le_bytes().to_vec();
    raw.extend(b"x\0");
    raw.extend(nv.to_le_bytes());
    raw.extend(nt.to_le_bytes());
    raw.extend(data);
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&raw).unwrap();
    let mut out = vec![0x1C, 0x04, 4, 0];
    out.extend(z.finish().unwrap());
    out.extend(0u64.to_le_bytes());
    out.extend(1u32.to_le_bytes());
    out
}

fn tri_data(v2: [f32; 3], index: u32) -> Vec<u8> {
    let mut d = Vec::new();
    for x in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0].into_iter().chain(v2) {
        d.extend(x.to_le_bytes());
    }
    for i in [0, 1, index] {
        d.extend(i.to_le_bytes());
    }
    d
}

fn err(bytes: &[u8]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("h.serialized");
    std::fs::write(&p, bytes).unwrap();
    let e = load_serialized(&p, 0, &Limits::default()).expect_err("must be refused").to_string();
    assert!(e.contains("h.serialized"), "{e}");
    e
}

#[test]
fn written_file_loads_and_hostile_ones_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("ok.serialized");
    std::fs::write(&p, file(SINGLE, 3, 1, &tri_data([0.0, 1.0, 0.0], 2))).unwrap();
    let m = load_serialized(&p, 0, &Limits::default()).unwrap();
    assert_eq!(m.indices, vec![[0, 1, 2]]);

    let ok = file(SINGLE, 3, 1, &tri_data([0.0, 1.0, 0.0], 2));
    // truncated anywhere: an error, never a panic
    for cut in [1, 5, 9, ok.len() / 2, ok.len() - 13, ok.len() - 1] {
        let _ = err(&ok[..cut]);
    }
    let e = err(&file(SINGLE, 3, 1, &tri_data([0.0, 1.0, 0.0], 3)));
    assert!(e.contains("index 3"), "{e}");
    let e = err(&file(SINGLE, 3, 1, &tri_data([0.0, f32::NAN, 0.0], 2)));
    assert!(e.contains("vertex 2"), "{e}");
    let e = err(&file(SINGLE, 1 << 40, 1, &[]));
    assert!(e.contains("max_vertices"), "{e}");
    let e = err(&file(SINGLE, 1 << 24, 1, &[]));
    assert!(e.contains("compressed bytes"), "{e}");
    let e = err(&file(0, 3, 1, &tri_data([0.0, 1.0, 0.0], 2)));
    assert!(e.contains("precision"), "{e}");
    let mut bad_magic = ok.clone();
    bad_magic[0] = 0;
    assert!(err(&bad_magic).contains("magic"));
    let mut bad_count = ok.clone();
    let n = bad_count.len();
    bad_count[n - 4..].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(err(&bad_count).contains("dictionary"));
    let mut bad_offset = ok;
    bad_offset[n - 12..n - 4].copy_from_slice(&(n as u64).to_le_bytes());
    assert!(err(&bad_offset).contains("offsets"));
}

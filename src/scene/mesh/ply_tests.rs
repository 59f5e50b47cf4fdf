//! PLY loader tests: the corpus files and hostile files.

use super::*;
use crate::scene::mesh::tests::corpus;

fn load(rel: &str) -> Mesh {
    let p = corpus(rel);
    let m = load_ply(&p, &Limits::default()).unwrap_or_else(|e| panic!("{e}"));
    m.validate().unwrap_or_else(|e| panic!("{}: {e:?}", p.display()));
    m
}

fn parse(text: &[u8]) -> Result<Mesh, MeshError> {
    parse_ply(Path::new("t.ply"), text, &Limits::default())
}

#[test]
fn corpus_rectangles_and_triangles() {
    let m = load("tests/ply/triangle.ply");
    assert_eq!((m.positions.len(), m.indices.len()), (3, 1));
    assert!(m.normals.is_empty() && m.uvs.is_empty());

    let m = load("tests/ply/rectangle_normals_uv.ply");
    assert_eq!((m.positions.len(), m.indices.len(), m.normals.len(), m.uvs.len()), (4, 2, 4, 4));
    assert!((m.area() - 5.7 * 8.199999).abs() < 1e-3, "area {}", m.area());
    assert_eq!(m.normals[2], Vec3::Y);
    let m = load("tests/ply/rectangle_uv.ply");
    assert!(m.normals.is_empty());
    assert_eq!(
        m.uvs,
        vec![
            Vec2::new(0.950589, 0.988416),
            Vec2::new(0.025105, 0.988416),
            Vec2::new(0.025105, 0.689127),
            Vec2::new(0.950589, 0.689127)
        ]
    );
    assert_eq!(m.positions[1], Vec3::new(-2.85, 0.0, 0.599999));

    let m = load("tests/ply/cbox_smallbox.ply");
    assert_eq!((m.positions.len(), m.indices.len()), (24, 12));

    let m = load("tests/ply/triangle_face_colors.ply");
    let c = m.attr("face_color").expect("face_color");
    assert_eq!((c.dims, c.data.len()), (3, 3));
    assert_eq!(m.normals.len(), 3);
}

#[test]
fn corpus_sphere_attributes() {
    let m = load("tests/scenes/mesh_attributes/meshes/sphere_attribute.ply");
    assert_eq!(m.positions.len(), 1192);
    assert!(m.indices.len() >= 528);
    let vc = m.attr("vertex_color").expect("vertex_color");
    assert_eq!((vc.dims, vc.data.len()), (3, 3 * 1192));
    let fc = m.attr("face_color").expect("face_color");
    assert_eq!((fc.dims, fc.data.len()), (3, 3 * m.indices.len()));
    let fw = m.attr("face_weight").expect("face_weight");
    assert_eq!((fw.dims, fw.data.len()), (1, m.indices.len()));
    assert_eq!((m.normals.len(), m.uvs.len()), (1192, 1192));
    assert!(
        m.vertex_attrs.len() == 1 && m.face_attrs.len() == 2,
        "{:?}",
        m.face_attrs.iter().map(|a| &a.name).collect::<Vec<_>>()
    );
}

#[test]
fn common_meshes_load() {
    let m = load("common/meshes/bunny.ply");
    assert_eq!((m.positions.len(), m.indices.len()), (35947, 69451));
    for f in ["common/meshes/bunny_lowres.ply", "common/meshes/sphere.ply", "common/meshes/teapot.ply"] {
        let m = load(f);
        assert!(!m.indices.is_empty(), "{f}");
    }
}

const ASCII: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float s\nproperty float t\n\
element face 1\nproperty list uchar int vertex_indices\nproperty float weight\nend_header\n\
0 0 0 255 0 0 0 0\n1 0 0 0 255 0 1 0\n1 1 0 0 0 255 1 1\n0 1 0 0 0 0 0 1\n4 0 1 2 3 0.5\n";

#[test]
fn ascii_quad_colors_and_st() {
    let m = parse(ASCII.as_bytes()).unwrap();
    assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.uvs[2], Vec2::new(1.0, 1.0));
    let c = m.attr("vertex_color").unwrap();
    assert_eq!(c.get(1), &[0.0, 1.0, 0.0]);
    assert_eq!(m.attr("face_weight").unwrap().data, vec![0.5, 0.5]);
}

/// The same mesh written binary, in either byte order.
fn binary(big: bool) -> Vec<u8> {
    let order = if big { "big" } else { "little" };
    let mut b = format!(
        "ply\nformat binary_{order}_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         property double nx\nproperty double ny\nproperty double nz\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    .into_bytes();
    let f = |b: &mut Vec<u8>, x: f32| b.extend(if big { x.to_be_bytes() } else { x.to_le_bytes() });
    let d = |b: &mut Vec<u8>, x: f64| b.extend(if big { x.to_be_bytes() } else { x.to_le_bytes() });
    for p in [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]] {
        p.iter().for_each(|&x| f(&mut b, x));
        [0.0, 0.0, 2.0].iter().for_each(|&x| d(&mut b, x));
    }
    b.push(3);
    for i in [0u32, 1, 2] {
        b.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() });
    }
    b
}

#[test]
fn binary_both_byte_orders() {
    for big in [false, true] {
        let m = parse(&binary(big)).unwrap();
        assert_eq!(m.positions[2], Vec3::new(0.0, 3.0, 0.0), "big {big}");
        assert_eq!(m.normals[0], Vec3::Z, "normals normalized");
        assert!((m.area() - 3.0).abs() < 1e-6);
    }
}

fn err(bytes: &[u8]) -> String {
    let e = parse(bytes).expect_err("must be refused");
    e.to_string()
}

#[test]
fn hostile_files_are_refused_with_where() {
    // truncated binary payload
    let b = binary(false);
    let e = err(&b[..b.len() - 5]);
    assert!(e.starts_with("t.ply") && e.contains("face"), "{e}");
    // huge counts: refused before allocating
    let huge = ASCII.replace("element vertex 4", "element vertex 4000000000000");
    let e = err(huge.as_bytes());
    assert!(e.contains("max_vertices"), "{e}");
    let many = ASCII.replace("element vertex 4", "element vertex 4000");
    let e = err(many.as_bytes());
    assert!(e.contains("bytes") && e.contains("vertex"), "{e}");
    // bad index
    let e = err(ASCII.replace("4 0 1 2 3", "4 0 1 9 3").as_bytes());
    assert!(e.contains("9") && e.contains("out of range"), "{e}");
    let e = err(ASCII.replace("4 0 1 2 3", "4 0 1 -2 3").as_bytes());
    assert!(e.contains("-2") && e.contains(":20"), "{e}");
    // NaN position, on its line
    let e = err(ASCII.replace("1 1 0 0 0 255", "1 nan 0 0 0 255").as_bytes());
    assert!(e.contains(":18"), "{e}");
    // list length 2, garbage header, no faces
    let e = err(ASCII.replace("4 0 1 2 3", "2 0 1").as_bytes());
    assert!(e.contains("2 vertices"), "{e}");
    let e = err(b"ply\nformat ascii 1.0\nelement vertex x\nend_header\n");
    assert!(e.contains("header"), "{e}");
    let e = err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n");
    assert!(e.contains("face") || e.contains("`y`"), "{e}");
    // a binary list whose count (uint) is huge: an error, no allocation of 4G entries
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uint uint vertex_indices\nend_header\n"
        .to_vec();
    b.extend([0u8; 36]);
    b.extend(u32::MAX.to_le_bytes());
    b.extend([0u8; 12]);
    let e = err(&b);
    assert!(e.contains("face"), "{e}");
}

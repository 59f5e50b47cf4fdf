//! Wavefront OBJ as Mitsuba 3's `obj` shape reads it: the whole file is one mesh (objects, groups
//! and materials are ignored), polygons are triangulated as fans, vertices are shared per distinct
//! `v/vt/vn` triple, and texture coordinates have their v flipped (`1 - v`) unless
//! `flip_tex_coords` is false (Mitsuba's default is true).
//!
//! The file is first checked by strata's own OBJ reader ([`crate::scene::obj::locate_obj_error`]:
//! malformed or non-finite numbers, bad indices, with the 1-based line), then loaded by `tobj`
//! (`single_index`, `triangulate`). Normals or uvs given for only some corners are dropped
//! (Mitsuba needs them on every vertex).

use super::{check_limit, read_file, Location, Mesh, MeshError};
use crate::scene::limits::Limits;
use glam::{Vec2, Vec3};
use std::path::Path;

/// Loads an OBJ file as one mesh (module docs) within `limits`.
pub fn load_obj(path: &Path, flip_tex_coords: bool, limits: &Limits) -> Result<Mesh, MeshError> {
    let bytes = read_file(path, limits.max_file_bytes)?;
    parse_obj(path, &bytes, flip_tex_coords, limits)
}

/// Parses the bytes of an OBJ file; `path` names it in errors.
pub fn parse_obj(path: &Path, bytes: &[u8], flip_tex_coords: bool, limits: &Limits) -> Result<Mesh, MeshError> {
    let bad = |at, msg: String| MeshError::malformed(path, at, msg);
    if let Some(i) = bytes.iter().position(|&b| b == 0) {
        let line = bytes[..i].iter().filter(|&&b| b == b'\n').count() + 1;
        return Err(bad(Location::Line(line), crate::scene::limits::NUL_BYTE.into()));
    }
    let text = String::from_utf8_lossy(bytes);
    if let Some((line, msg)) = crate::scene::obj::locate_obj_error(&text) {
        return Err(bad(Location::Line(line), msg));
    }
    let opts = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let loaded = std::panic::catch_unwind(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| Err(tobj::LoadError::OpenFileFailed))
    });
    let (models, _) = match loaded {
        Ok(Ok(m)) => m,
        Ok(Err(e)) => return Err(bad(Location::File, format!("cannot read the OBJ: {e}"))),
        Err(_) => return Err(bad(Location::File, "the OBJ reader (tobj) failed on this file".into())),
    };
    let mut mesh = Mesh::default();
    for model in &models {
        let t = &model.mesh;
        let nv = t.positions.len() / 3;
        check_limit(path, "vertices", (mesh.positions.len() + nv) as u64, limits.max_vertices as u64, "max_vertices")?;
        let nt = t.indices.len() / 3;
        check_limit(
            path,
            "triangles",
            (mesh.indices.len() + nt) as u64,
            limits.max_primitives as u64,
            "max_primitives",
        )?;
        let mut part = Mesh {
            positions: t.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect(),
            ..Mesh::default()
        };
        if t.normals.len() == 3 * nv {
            part.normals = t.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or_zero()).collect();
        }
        if t.texcoords.len() == 2 * nv {
            part.uvs = t
                .texcoords
                .chunks_exact(2)
                .map(|uv| Vec2::new(uv[0], if flip_tex_coords { 1.0 - uv[1] } else { uv[1] }))
                .collect();
        }
        part.indices = t.indices.chunks_exact(3).map(|i| [i[0], i[1], i[2]]).collect();
        part.validate().map_err(|(at, msg)| bad(at, msg))?;
        mesh.append(&part);
    }
    if mesh.indices.is_empty() {
        return Err(bad(Location::File, "no faces".into()));
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::tests::corpus;

    fn load(rel: &str) -> Mesh {
        load_obj(&corpus(rel), true, &Limits::default()).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn corpus_files() {
        let m = load("tests/obj/rectangle_normals_uv.obj");
        assert_eq!((m.positions.len(), m.indices.len(), m.normals.len(), m.uvs.len()), (4, 2, 4, 4));
        assert!((m.area() - 5.7 * 8.2).abs() < 1e-3, "{}", m.area());
        let m = load("tests/obj/rectangle_uv.obj");
        assert!(m.normals.is_empty() && m.uvs.len() == 4);
        let m = load("tests/obj/cbox_smallbox.obj");
        assert_eq!(m.indices.len(), 12);
        let m = load("common/meshes/cbox/luminaire.obj");
        assert_eq!(m.indices.len(), 2);
        assert!((m.area() - 130.0 * 105.0).abs() < 0.05, "{}", m.area());
        for (f, tris) in [("largebox", 12), ("smallbox", 12), ("floor", 2), ("ceiling", 4), ("back", 2)] {
            let m = load(&format!("common/meshes/cbox/{f}.obj"));
            m.validate().unwrap();
            assert_eq!(m.indices.len(), tris, "{f}");
        }
        for f in ["common/meshes/sphere.obj", "common/meshes/rectangle.obj"] {
            let m = load(f);
            m.validate().unwrap();
            assert!(!m.indices.is_empty());
        }
    }

    #[test]
    fn uv_flip_and_vertex_sharing() {
        let text = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0.25\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
        let m = parse_obj(Path::new("q.obj"), text, true, &Limits::default()).unwrap();
        assert_eq!(m.indices.len(), 2);
        assert_eq!(m.positions.len(), 4, "one vertex per distinct v/vt pair");
        assert_eq!(m.uvs[0], Vec2::new(0.0, 0.75), "v flipped");
        let m = parse_obj(Path::new("q.obj"), text, false, &Limits::default()).unwrap();
        assert_eq!(m.uvs[0], Vec2::new(0.0, 0.25));
        // the same position with two uvs: two vertices
        let seam = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 0.5 0\nf 1/1 2/2 3/3\nf 1/4 3/3 2/2\n";
        let m = parse_obj(Path::new("s.obj"), seam, true, &Limits::default()).unwrap();
        assert_eq!(m.positions.len(), 4);
    }

    #[test]
    fn hostile_files() {
        let e = |t: &[u8]| parse_obj(Path::new("h.obj"), t, true, &Limits::default()).unwrap_err().to_string();
        let s = e(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
        assert!(s.starts_with("h.obj:4"), "{s}");
        let s = e(b"v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
        assert!(s.starts_with("h.obj:2"), "{s}");
        let s = e(b"v 0 0 0\n\0\n");
        assert!(s.starts_with("h.obj:2"), "{s}");
        let s = e(b"v 0 0 0\n");
        assert!(s.contains("no faces") || s.contains("h.obj"), "{s}");
        let small = Limits { max_vertices: 2, ..Limits::default() };
        let s = parse_obj(Path::new("h.obj"), b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", true, &small).unwrap_err();
        assert!(s.to_string().contains("max_vertices"), "{s}");
    }
}

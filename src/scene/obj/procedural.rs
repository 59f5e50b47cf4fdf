//! A procedural test mesh and an OBJ/MTL writer (for benches, tests and `strata` examples).

use super::{MtlMaterial, ObjMesh};
use glam::Vec3;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The torus of [`procedural_mesh`] is 2n x n quads.
fn torus_side(min_triangles: usize) -> usize {
    ((min_triangles as f64 / 4.0).sqrt().ceil() as usize).max(3)
}

/// Bytes [`procedural_mesh`] holds for `min_triangles` (positions 12 and face 12 + material 4 bytes
/// per triangle, reserved up front), so that `gen-mesh` can refuse a mesh that does not fit.
/// Computed in u128 and saturated, so a huge count (`--triangles 9223372036854775807`) is refused
/// as too big rather than wrapping to a small number (before: a `capacity overflow` panic).
pub fn procedural_mesh_bytes(min_triangles: usize) -> u64 {
    let n = torus_side(min_triangles) as u128;
    let (verts, tris) = (2 * n * n + 12, 4 * n * n + 6);
    u64::try_from(12 * verts + 16 * tris).unwrap_or(u64::MAX)
}

/// A procedural test mesh of at least `min_triangles` triangles: a bumpy torus (2 n x n quads, no
/// degenerate triangles) tilted towards +z, on a floor before a wall, under an emissive patch
/// (2 x 2 n^2 + 6 triangles); material names
/// `torus`, `floor`, `light` (see [`write_obj`]).
pub fn procedural_mesh(min_triangles: usize) -> ObjMesh {
    let n = torus_side(min_triangles);
    let (nu, nv) = (2 * n, n);
    let (big_r, small_r) = (1.0f32, 0.35f32);
    let tilt = glam::Mat3::from_rotation_x(1.0);
    let mut mesh = ObjMesh::default();
    mesh.positions.reserve_exact(nu * nv + 12);
    mesh.faces.reserve_exact(2 * nu * nv + 6);
    for i in 0..nu {
        let u = i as f32 / nu as f32 * std::f32::consts::TAU;
        for j in 0..nv {
            let v = j as f32 / nv as f32 * std::f32::consts::TAU;
            let bump = 1.0 + 0.08 * (7.0 * u).sin() * (5.0 * v).sin();
            let r = small_r * bump;
            let p = Vec3::new((big_r + r * v.cos()) * u.cos(), r * v.sin(), (big_r + r * v.cos()) * u.sin());
            mesh.positions.push(tilt * p);
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            mesh.faces.push([a, c, b]);
            mesh.faces.push([a, d, c]);
        }
    }
    mesh.face_material = vec![0; mesh.faces.len()];
    let mut quad = |corners: [Vec3; 4], material: u32| {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(corners);
        mesh.faces.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        mesh.face_material.extend([material, material]);
    };
    // Floor below the torus (facing +y), a wall behind it (facing +z), a light above (facing -y).
    let (y0, y1, e) = (-1.2, 1.6, 1.6);
    quad([Vec3::new(-e, y0, -e), Vec3::new(-e, y0, e), Vec3::new(e, y0, e), Vec3::new(e, y0, -e)], 1);
    quad([Vec3::new(-e, y0, -e), Vec3::new(e, y0, -e), Vec3::new(e, y1 + 0.2, -e), Vec3::new(-e, y1 + 0.2, -e)], 1);
    quad([Vec3::new(-0.5, y1, -0.5), Vec3::new(0.5, y1, -0.5), Vec3::new(0.5, y1, 0.5), Vec3::new(-0.5, y1, 0.5)], 2);
    mesh.materials = vec![
        MtlMaterial {
            name: "torus".into(),
            kd: Some(Vec3::new(0.7, 0.45, 0.3)),
            ks: Some(Vec3::splat(0.2)),
            ns: Some(40.0),
            ke: None,
        },
        MtlMaterial { name: "floor".into(), kd: Some(Vec3::splat(0.6)), ks: None, ns: None, ke: None },
        MtlMaterial { name: "light".into(), kd: Some(Vec3::ZERO), ks: None, ns: None, ke: Some(Vec3::splat(20.0)) },
    ];
    mesh
}

/// Writes `mesh` as `path` (OBJ, one `usemtl` per run of faces) and `path` with extension `.mtl`
/// (its materials), each through the safe-write path ([`crate::files::AtomicFile`]: a link, FIFO
/// or device at either name is refused, never written through; the files appear whole or not at
/// all). Returns the MTL path.
pub fn write_obj(path: &Path, mesh: &ObjMesh) -> std::io::Result<PathBuf> {
    let mtl_path = path.with_extension("mtl");
    let mtl_name = mtl_path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut mtl_file = crate::files::AtomicFile::create(&mtl_path)?;
    let mut obj_file = crate::files::AtomicFile::create(path)?;
    let mut m = std::io::BufWriter::new(mtl_file.file());
    for mat in &mesh.materials {
        writeln!(m, "newmtl {}", mat.name)?;
        let v3 = |k: &str, v: Option<Vec3>| v.map(|v| format!("{k} {} {} {}\n", v.x, v.y, v.z)).unwrap_or_default();
        write!(m, "{}{}{}", v3("Kd", mat.kd), v3("Ks", mat.ks), v3("Ke", mat.ke))?;
        if let Some(ns) = mat.ns {
            writeln!(m, "Ns {ns}")?;
        }
    }
    m.flush()?;
    drop(m);
    let mut w = std::io::BufWriter::with_capacity(1 << 20, obj_file.file());
    writeln!(w, "# strata procedural mesh: {} triangles\nmtllib {mtl_name}", mesh.faces.len())?;
    for p in &mesh.positions {
        writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
    }
    let mut current = u32::MAX - 1;
    for (f, &mi) in mesh.faces.iter().zip(&mesh.face_material) {
        if mi != current {
            if let Some(mat) = mesh.materials.get(mi as usize) {
                writeln!(w, "usemtl {}", mat.name)?;
            }
            current = mi;
        }
        writeln!(w, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1)?;
    }
    w.flush()?;
    drop(w);
    mtl_file.commit()?;
    obj_file.commit()?;
    Ok(mtl_path)
}

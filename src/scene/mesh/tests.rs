//! Tests of the `Mesh` operations and of `SceneDesc::add_mesh`.

use super::*;
use crate::scene::desc::SceneDesc;
use glam::{Mat4, Quat};

/// The corpus directory (panics naming it when ../shared is missing).
pub(crate) fn corpus(rel: &str) -> PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpora/mitsuba-tests").join(rel);
    assert!(p.exists(), "test data missing: {} (create ../shared, see HELPERS.md)", p.display());
    p
}

/// A unit right triangle in the z=0 plane, normal +z, with a vertex and a face attribute.
fn tri() -> Mesh {
    Mesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        normals: vec![Vec3::Z; 3],
        uvs: vec![Vec2::ZERO, Vec2::X, Vec2::Y],
        indices: vec![[0, 1, 2]],
        vertex_attrs: vec![MeshAttr { name: "vertex_color".into(), dims: 3, data: (0..9).map(|i| i as f32).collect() }],
        face_attrs: vec![MeshAttr { name: "face_weight".into(), dims: 1, data: vec![0.5] }],
    }
}

#[test]
fn transform_maps_normals_by_inverse_transpose() {
    let mut m = tri();
    m.positions.push(Vec3::new(1.0, 1.0, 1.0));
    m.normals.push(Vec3::new(1.0, 1.0, 0.0).normalize());
    m.uvs.push(Vec2::ONE);
    m.vertex_attrs[0].data.extend([9.0, 10.0, 11.0]);
    // Non-uniform scale: a normal (1,1,0)/sqrt2 must become (1/2, 1, 0) normalized, not (2,1,0).
    let s = Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0));
    m.transform(&s);
    assert_eq!(m.positions[3], Vec3::new(2.0, 1.0, 1.0));
    assert!((m.normals[3] - Vec3::new(0.5, 1.0, 0.0).normalize()).length() < 1e-6, "{}", m.normals[3]);
    assert_eq!(m.indices[0], [0, 1, 2]);
}

#[test]
fn mirroring_transform_keeps_winding_meaning() {
    for mirror in [Vec3::new(-1.0, 1.0, 1.0), Vec3::new(-0.5, -0.5, -0.5)] {
        let mut m = tri();
        let t = Mat4::from_rotation_translation(Quat::from_rotation_y(0.7), Vec3::new(1.0, 2.0, 3.0))
            * Mat4::from_scale(mirror);
        m.transform(&t);
        let ng = m.face_cross(0).normalize();
        // the geometric normal agrees with the transformed shading normals
        assert!(ng.dot(m.normals[0]) > 0.999, "mirror {mirror}: ng {ng} n {}", m.normals[0]);
    }
}

#[test]
fn flip_and_face_normals() {
    let mut m = tri();
    let before = m.face_cross(0);
    m.flip_normals();
    assert_eq!(m.face_cross(0), -before);
    assert_eq!(m.normals[0], -Vec3::Z);
    m.face_normals();
    assert!(m.normals.is_empty());
    assert!(m.validate().is_ok());
}

#[test]
fn vertex_normals_are_angle_weighted() {
    // A corner of a cube: three faces meeting at the origin with angles of 90 degrees each,
    // the first face split into two 45-degree triangles: angle weighting gives (1,1,1)/sqrt3,
    // while area weighting would not care and uniform weighting would lean towards +z.
    let mut m = Mesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y, Vec3::Z],
        indices: vec![[0, 2, 1], [0, 3, 2], [0, 1, 4], [0, 4, 3]],
        ..Mesh::default()
    };
    // faces: z=0 (normal -z, two triangles), y=0 (normal -y), x=0 (normal -x)
    m.ensure_vertex_normals();
    assert!((m.normals[0] - Vec3::splat(-1.0).normalize()).length() < 1e-5, "{}", m.normals[0]);
}

#[test]
fn validate_names_bad_index_and_nan() {
    let mut m = tri();
    m.indices.push([0, 1, 7]);
    let (at, msg) = m.validate().unwrap_err();
    assert_eq!(at, Location::Element("face".into(), 1));
    assert!(msg.contains('7'), "{msg}");
    let mut m = tri();
    m.positions[1].y = f32::NAN;
    assert_eq!(m.validate().unwrap_err().0, Location::Element("vertex".into(), 1));
}

#[test]
fn add_mesh_fills_tables_and_keeps_hash_without_extras() {
    let mut plain = SceneDesc::default();
    let mut m = tri();
    let h0 = plain.content_hash();
    let bare = Mesh { positions: m.positions.clone(), indices: m.indices.clone(), ..Mesh::default() };
    plain.add_mesh(&bare, 0);
    assert!(plain.triangle_normals.is_empty() && plain.triangle_uvs.is_empty() && plain.triangle_attrs.is_empty());
    // Same hash as the triangle pushed by hand (as the .test parser does).
    let mut by_hand = SceneDesc::default();
    by_hand.triangles.push(TriangleDesc { v: [Vec3::ZERO, Vec3::X, Vec3::Y], material: 0 });
    assert_eq!(plain.content_hash(), by_hand.content_hash());
    assert_ne!(plain.content_hash(), h0);

    m.indices = vec![[0, 2, 1]];
    let first = plain.add_mesh(&m, 3);
    assert_eq!(first, 1);
    assert_eq!(plain.triangles[1].v, [Vec3::ZERO, Vec3::Y, Vec3::X]);
    assert_eq!(plain.triangles[1].material, 3);
    assert_eq!(plain.triangle_normals, vec![[Vec3::ZERO; 3], [Vec3::Z; 3]]);
    assert_eq!(plain.triangle_uvs[1], [Vec2::ZERO, Vec2::Y, Vec2::X]);
    let color = &plain.triangle_attrs[0];
    assert_eq!((color.name.as_str(), color.first, color.count, color.per_corner), ("vertex_color", 1, 1, true));
    assert_eq!(color.data, vec![0.0, 1.0, 2.0, 6.0, 7.0, 8.0, 3.0, 4.0, 5.0]);
    assert_eq!(plain.triangle_attrs[1].data, vec![0.5]);
    let h1 = plain.content_hash();
    plain.triangle_attrs[1].data[0] = 0.25;
    assert_ne!(plain.content_hash(), h1, "attributes enter the hash");
}

use crate::scene::desc::TriangleDesc;

#[test]
fn instances_store_the_group_once() {
    let group = vec![(tri(), 2u32)];
    let mut desc = SceneDesc::default();
    let t = Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0)) * Mat4::from_scale(Vec3::new(-2.0, 2.0, 2.0));
    let sphere = Mat4::from_scale(Vec3::splat(0.5));
    let g = desc.add_group("g", &group, vec![(sphere, 1)]);
    assert_eq!(desc.group_index("g"), Some(g));
    desc.add_instance(g, &Mat4::IDENTITY);
    desc.add_instance(g, &t);
    assert!(desc.triangles.is_empty(), "no world copy");
    assert_eq!(desc.groups[0].triangles.len(), 1);
    assert_eq!(desc.groups[0].triangles[0].material, 2);
    assert_eq!(desc.groups[0].triangle_normals[0], [Vec3::Z; 3]);
    assert_eq!(desc.instances.len(), 2);
    assert_eq!(desc.instances[1].to_world, t);
    // spheres are placed per instance
    assert_eq!(desc.spheres.len(), 2);
    assert_eq!(desc.spheres[1].object_to_world, t * sphere);
}

/// Every loader reads through `files::open_regular`: a FIFO (nobody writes to it) is refused
/// before it is opened, never waited on, and a directory is refused too.
#[test]
fn loaders_refuse_fifos_and_directories() {
    use crate::scene::limits::Limits;
    let dir = tempfile::tempdir().unwrap();
    let lim = Limits::default();
    for name in ["f.ply", "f.serialized", "f.obj", "f.vol"] {
        let fifo = dir.path().join(name);
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        for path in [fifo.as_path(), dir.path()] {
            let e = match name {
                "f.ply" => ply::load_ply(path, &lim),
                "f.serialized" => serialized::load_serialized(path, 0, &lim),
                "f.obj" => obj::load_obj(path, true, &lim),
                _ => sdfgrid::load_sdfgrid(path, 1, &lim),
            }
            .unwrap_err()
            .to_string();
            assert!(e.contains("is a FIFO") || e.contains("is a directory"), "{name}: {e}");
            assert!(e.contains(&path.display().to_string()), "{name}: {e}");
        }
    }
}

//! Tests of textures at hits: uvs (triangles with and without corner uvs, spheres), attribute
//! interpolation, textured kd through real Embree hits, and scenes without textures unchanged.

use super::*;
use crate::accel::RayHit8;
use crate::scene::desc::{SceneDesc, TriangleAttrDesc};
use crate::scene::{limits::Limits, parse::parse_str};
use crate::simd::mask_all;
use crate::texture::{Checkerboard, MeshAttribute, RawConstant, Texture, UvTransform};

#[test]
fn sphere_uv_matches_mitsuba() {
    // Mitsuba 3.9.1 `sphere` (unit, at the origin): points and the uv it reports there.
    for (p, uv) in [
        (Vec3::new(0.842615, 0.5, 0.2), Vec2::new(0.0852348, 0.435906)),
        (Vec3::new(0.3, 0.2, 0.932738), Vec2::new(0.0935835, 0.117413)),
        (Vec3::new(-0.4, -0.911043, 0.1), Vec2::new(0.684155, 0.468116)),
    ] {
        let got = sphere_uv(p);
        assert!((got - uv).abs().max_element() < 2e-6, "{p}: {got} != {uv}");
    }
    assert_eq!(sphere_uv(Vec3::X), Vec2::new(0.0, 0.5));
    assert_eq!(sphere_uv(Vec3::Z).y, 0.0);
}

#[test]
fn triangle_uvs_interpolate_or_are_the_barycentrics() {
    let c = [Vec2::new(0.0, 0.0), Vec2::new(2.0, 0.0), Vec2::new(0.0, 4.0)];
    assert_eq!(triangle_uv(Some(&c), 0.25, 0.5), Vec2::new(0.5, 2.0));
    assert_eq!(triangle_uv(Some(&c), 0.0, 0.0), c[0]);
    // A mesh without uvs: Mitsuba 3.9.1 reports the barycentrics (b1, b2) (its uv (0.2, 0.3) at
    // p = (0.2, 0.3, 0) of the triangle (0,0,0), (1,0,0), (0,1,0)).
    assert_eq!(triangle_uv(None, 0.2, 0.3), Vec2::new(0.2, 0.3));
}

/// A 2x2 floor at y = 0 of two triangles (materials 0 and 1) and a sphere (material 1) at
/// (3, 0.5, 0) of radius 0.5, seen from above.
fn desc() -> SceneDesc {
    let text = "size 8 8\ncamera 0 5 0 0 0 0 0 0 1 45\nmaxverts 4\n\
                vertex -1 0 -1\nvertex 1 0 -1\nvertex -1 0 1\nvertex 1 0 1\n\
                diffuse 0.3 0.3 0.5\ntri 0 1 2\ndiffuse 0.5 0.2 0.1\ntri 1 3 2\nsphere 3 0.5 0 0.5\n";
    parse_str(text, std::path::Path::new("t.test"), &Limits::default()).expect("scene")
}

/// Traces eight rays straight down at `xz` and gathers them.
fn shade(sc: &Scene, xz: [(f32, f32); 8]) -> (SurfaceHit8, Hits8) {
    let org = Vec3x8::from_lanes(xz.map(|(x, z)| Vec3::new(x, 4.0, z)));
    let dir = Vec3x8::splat(Vec3::NEG_Y);
    let mut rh = RayHit8::default();
    let active = rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), mask_all());
    let traced = sc.accel.intersect8(&mut rh, true, active);
    let hits = Hits8::from_rayhit(&rh, traced);
    (sc.gather(org, dir, &hits), hits)
}

const XZ: [(f32, f32); 8] =
    [(-0.5, -0.5), (0.5, -0.6), (-0.2, -0.5), (0.7, 0.7), (0.2, 0.1), (3.1, 0.2), (2.8, -0.1), (9.0, 9.0)];

#[test]
fn textured_kd_at_real_hits() {
    let mut d = desc();
    // Corner uvs of triangle 0 only: its uv is x/2 + 1/2 and z/2 + 1/2 at its corners.
    let uv = |x: f32, z: f32| Vec2::new(x * 0.5 + 0.5, z * 0.5 + 0.5);
    d.triangle_uvs = vec![[uv(-1.0, -1.0), uv(1.0, -1.0), uv(-1.0, 1.0)]];
    let checker = Checkerboard {
        color0: Vec3::new(1.0, 0.0, 0.0),
        color1: Vec3::new(0.0, 1.0, 0.0),
        to_uv: UvTransform::from_mat4(glam::Mat4::from_scale(Vec3::splat(2.0))),
    };
    d.textures = vec![Texture::Checkerboard(checker), Texture::RawConstant(RawConstant { value: Vec3::splat(0.7) })];
    d.diffuse_textures = vec![Some(0), Some(1)];
    let untextured = Scene::build(desc()).unwrap();
    let sc = Scene::build(d).unwrap();
    let (sh, hits) = shade(&sc, XZ);
    let (plain, _) = shade(&untextured, XZ);
    let f = |v: F8| v.to_array();
    assert_eq!(crate::simd::mask_to_bools(sh.valid), [true, true, true, true, true, true, true, false]);
    // Everything but kd is as without textures.
    assert_eq!(f(sh.n.y), f(plain.n.y));
    assert_eq!(f(sh.mat.ks.x), f(plain.mat.ks.x));
    for (i, &(x, z)) in XZ.iter().enumerate().take(7) {
        let (geom, prim) = (hits.geom.as_array()[i], hits.prim.as_array()[i] as usize);
        let want = if geom == GEOM_TRIANGLES && prim == 0 {
            // Triangle 0 has uvs: the checker at 2 uv (x/2 + 1/2, z/2 + 1/2) = (x + 1, z + 1).
            checker.eval(&crate::texture::TexQuery { uv: uv(x, z), tri: 0, bary: Vec2::ZERO })
        } else {
            Vec3::splat(0.7)
        };
        assert!((sh.mat.kd.lane(i) - want).abs().max_element() < 1e-5, "lane {i}: {} != {want}", sh.mat.kd.lane(i));
    }
    // By hand, on triangle 0 (x + z < 0): lane 0 (-0.5, -0.5) has 2 uv = (0.5, 0.5), fractional
    // parts not above 1/2: colour 0; lane 2 (-0.2, -0.5) has 2 uv = (0.8, 0.5): colour 1. Lane 4
    // (0.2, 0.1) is on triangle 1: its constant.
    assert_eq!(sh.mat.kd.lane(0), Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(sh.mat.kd.lane(2), Vec3::new(0.0, 1.0, 0.0));
    assert_eq!(sh.mat.kd.lane(4), Vec3::splat(0.7));
    // The miss lane stays black.
    assert_eq!(sh.mat.kd.lane(7), Vec3::ZERO);
}

#[test]
fn mesh_attributes_interpolate_at_hits() {
    let mut d = desc();
    // A per-corner colour on both floor triangles: corner k of triangle t has (t, k, 1).
    let data: Vec<f32> = (0..2).flat_map(|t| (0..3).flat_map(move |k| [t as f32, k as f32, 1.0])).collect();
    d.triangle_attrs =
        vec![TriangleAttrDesc { name: "vertex_color".into(), dims: 3, per_corner: true, first: 0, count: 2, data }];
    d.textures = vec![Texture::MeshAttribute(MeshAttribute::new("vertex_color", 1.0))];
    d.diffuse_textures = vec![Some(0), Some(0)];
    let sc = Scene::build(d).unwrap();
    let (sh, hits) = shade(&sc, XZ);
    for i in 0..5 {
        let prim = hits.prim.as_array()[i] as f32;
        let (b1, b2) = (hits.u.as_array()[i], hits.v.as_array()[i]);
        // (t, 0 b0 + 1 b1 + 2 b2, 1)
        let want = Vec3::new(prim, b1 + 2.0 * b2, 1.0);
        assert!((sh.mat.kd.lane(i) - want).abs().max_element() < 1e-5, "lane {i}: {} != {want}", sh.mat.kd.lane(i));
        assert!(b1 > 0.0 && b2 > 0.0, "inside the triangle");
    }
    // The sphere has no such attribute: 0.
    assert_eq!(sh.mat.kd.lane(5), Vec3::ZERO);
    // An attribute no mesh has is refused, naming the ones there are.
    let mut bad = desc();
    bad.triangle_attrs = vec![TriangleAttrDesc {
        name: "face_w".into(),
        dims: 1,
        per_corner: false,
        first: 0,
        count: 2,
        data: vec![1.0, 2.0],
    }];
    bad.textures = vec![Texture::MeshAttribute(MeshAttribute::new("vertex_color", 1.0))];
    bad.diffuse_textures = vec![Some(0)];
    let e = Scene::build(bad).err().expect("refused").to_string();
    assert!(e.contains("vertex_color") && e.contains("face_w"), "{e}");
}

#[test]
fn sphere_lanes_read_the_sphere_uv() {
    let mut d = desc();
    d.textures = vec![Texture::Checkerboard(Checkerboard {
        color0: Vec3::X,
        color1: Vec3::Y,
        to_uv: UvTransform::from_mat4(glam::Mat4::from_scale(Vec3::splat(8.0))),
    })];
    d.diffuse_textures = vec![None, Some(0)];
    let sc = Scene::build(d).unwrap();
    let xz = [(3.1, 0.2), (2.8, -0.1), (3.3, 0.1), (2.9, 0.3), (3.0, 0.05), (3.2, -0.3), (2.75, 0.2), (-0.5, -0.5)];
    let (sh, _) = shade(&sc, xz);
    for (i, (x, z)) in xz.into_iter().enumerate().take(7) {
        // The hit on the sphere's top, in object space ((p - c) / r).
        let y = (0.25 - (x - 3.0) * (x - 3.0) - z * z).sqrt();
        let uv = sphere_uv(Vec3::new(x - 3.0, y, z) / 0.5) * 8.0;
        let h = |t: f32| t - t.floor() > 0.5;
        let want = if h(uv.x) == h(uv.y) { Vec3::X } else { Vec3::Y };
        assert_eq!(sh.mat.kd.lane(i), want, "lane {i}");
    }
    // Material 0 (the triangle under lane 7) is not textured.
    assert_eq!(sh.mat.kd.lane(7), Vec3::new(0.3, 0.3, 0.5));
}

#[test]
fn scenes_without_textures_are_unchanged() {
    let d = desc();
    let h = d.content_hash();
    let sc = Scene::build(d.clone()).unwrap();
    assert!(sc.material_texture.is_empty() && sc.tri_uv.is_empty() && sc.tri_source.is_empty());
    // Textures that no material uses build no tables either, but enter the hash.
    let mut t = d.clone();
    t.textures = vec![Texture::RawConstant(RawConstant { value: Vec3::ONE })];
    assert_ne!(t.content_hash(), h);
    assert!(Scene::build(t).unwrap().material_texture.is_empty());
    // A texture index past the table is refused.
    let mut bad = d;
    bad.diffuse_textures = vec![Some(3)];
    let e = Scene::build(bad).err().expect("refused").to_string();
    assert!(e.contains("texture 3"), "{e}");
}

#[test]
fn textured_scalar_slots_read_mitsubas_float_lookup() {
    // A checkerboard gives material 0 its colour slot 0 and its scalar slot 0 (a roughness, say).
    // Mitsuba 3.9.1's checkerboard `eval_1` (every float parameter: alpha, opacity, weight) gives
    // `color1` where `eval` (colours) gives `color0`, and back: its `eval` at uv (0.5, 0.5) is
    // color0 = 0.05, its `eval_1` there 0.3 (queried from the peer). Triangle 0 of the floor has
    // uv (x/2 + 1/2, z/2 + 1/2); the checker's to_uv doubles it.
    use crate::bsdf::interface::Slot;
    let mut d = desc();
    let uv = |x: f32, z: f32| Vec2::new(x * 0.5 + 0.5, z * 0.5 + 0.5);
    d.triangle_uvs = vec![[uv(-1.0, -1.0), uv(1.0, -1.0), uv(-1.0, 1.0)]];
    let checker = Checkerboard {
        color0: Vec3::splat(0.05),
        color1: Vec3::splat(0.3),
        to_uv: UvTransform::from_mat4(glam::Mat4::from_scale(Vec3::splat(2.0))),
    };
    d.textures = vec![Texture::Checkerboard(checker)];
    d.param_textures = vec![vec![(Slot::Color(0), 0), (Slot::Scalar(0), 0)]];
    let sc = Scene::build(d).unwrap();
    let (mut sh, hits) = shade(&sc, XZ);
    // Lanes 0 (-0.5, -0.5) and 2 (-0.2, -0.5) hit triangle 0 (material 0): 2 uv = (0.5, 0.5),
    // colour 0 for `eval`, and (0.8, 0.5), colour 1.
    for i in [0, 2] {
        assert_eq!((hits.geom.as_array()[i], hits.prim.as_array()[i]), (GEOM_TRIANGLES, 0), "lane {i}");
    }
    sh.material = U8::ZERO;
    let mut p = crate::bsdf::Params8::COURSE;
    sc.texture_params(&sh, sh.valid, &mut p);
    assert_eq!(p.color[0].lane(0), Vec3::splat(0.05));
    assert_eq!(p.color[0].lane(2), Vec3::splat(0.3));
    assert_eq!(p.scalar[0].to_array()[0], 0.3);
    assert_eq!(p.scalar[0].to_array()[2], 0.05);
}

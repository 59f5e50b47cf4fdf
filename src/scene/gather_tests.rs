//! Tests of the hit gather (`gather.rs`): the splat paths against the lane-by-lane look-ups, mixed
//! packets, the miss record.

use super::*;
use crate::scene::{limits::Limits, parse::parse_str};
use crate::simd::mask_from_bools;

/// A floor of two triangles (two materials), a quad light and a sphere.
fn scene() -> Scene {
    let text = "size 8 8\ncamera 0 1 -4 0 0 0 0 1 0 45\nmaxverts 4\n\
                vertex -1 0 -1\nvertex -1 0 1\nvertex 1 0 -1\nvertex 1 0 1\n\
                diffuse 0.3 0.3 0.5\ntri 0 1 2\ndiffuse 0.5 0.2 0.1\nspecular 0.2 0.2 0.2\ntri 1 3 2\n\
                quadLight -1 2 -1 0 0 2 2 0 0 5 5 5\nsphere 0 1 0 0.5\n";
    let desc = parse_str(text, std::path::Path::new("t.test"), &Limits::default()).expect("scene");
    Scene::build(desc).expect("build")
}

fn hits(hit: [bool; 8], geom: [u32; 8], prim: [u32; 8]) -> Hits8 {
    let f = |a: [f32; 8]| F8::new(a);
    Hits8 {
        hit: mask_from_bools(hit),
        t: f([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]),
        prim: U8::new(prim),
        geom: U8::new(geom),
        inst: U8::splat(INVALID_ID),
        u: f([0.1; 8]),
        v: f([0.2; 8]),
    }
}

fn rays() -> (Vec3x8, Vec3x8) {
    let d = |i: usize| Vec3::new(i as f32 * 0.1 - 0.35, -1.0, 0.3 - i as f32 * 0.05).normalize();
    (Vec3x8::splat(Vec3::new(0.0, 3.0, 0.0)), Vec3x8::from_lanes(std::array::from_fn(d)))
}

fn bits(v: Vec3x8) -> [[u32; 8]; 3] {
    [v.x, v.y, v.z].map(|c| c.to_array().map(f32::to_bits))
}

fn same_record(a: &SurfaceHit8, b: &SurfaceHit8) {
    let f = |x: F8| x.to_array().map(f32::to_bits);
    assert_eq!(f(a.valid), f(b.valid));
    for (x, y) in [(a.p, b.p), (a.n, b.n), (a.ng, b.ng), (a.wo, b.wo), (a.mat.kd, b.mat.kd), (a.mat.ks, b.mat.ks)] {
        assert_eq!(bits(x), bits(y));
    }
    for (x, y) in [(a.emitted, b.emitted), (a.ambient, b.ambient), (a.le, b.le)] {
        assert_eq!(bits(x), bits(y));
    }
    let (m, n) = (&a.mat, &b.mat);
    for (x, y) in [(a.smooth, b.smooth), (m.shininess, n.shininess), (m.alpha, n.alpha), (m.ggx, n.ggx)] {
        assert_eq!(f(x), f(y));
    }
    assert_eq!(a.light.to_array(), b.light.to_array());
}

/// Packets whose hit lanes all hit one (non-light) triangle take the splat path: the same
/// fields, bit for bit, as the lane-by-lane lookups.
#[test]
fn one_triangle_packets_match_the_lane_by_lane_gather() {
    let sc = scene();
    let (_, dir) = rays();
    let light_tri = sc.tri_light.iter().position(|&l| l != INVALID_ID).expect("a light triangle") as u32;
    for (t, hit) in [(0u32, [true; 8]), (1, [true, false, true, true, false, true, true, false])] {
        assert_eq!(sc.tri_light[t as usize], INVALID_ID, "floor triangle {t} is not a light");
        let valid = mask_from_bools(hit);
        let b = valid.to_bitmask();
        let (geom, prim) = ([GEOM_TRIANGLES; 8], [t; 8]);
        let p = Vec3x8::splat(Vec3::new(0.1, 0.0, 0.2));
        let fast = sc.one_triangle(t as usize, valid);
        let slow = sc.lane_by_lane::<false>(b, [&geom, &prim, &[INVALID_ID; 8]], p, dir);
        assert_eq!(bits(fast.n), bits(slow.n));
        assert_eq!(fast.light.to_array(), slow.light.to_array());
        assert_eq!(bits(fast.le), bits(slow.le));
        assert_eq!(fast.any_tri, slow.any_tri);
        for i in lanes_of(b) {
            assert_eq!(fast.mat[i], slow.mat[i], "lane {i}: material id");
        }
        let (mut a, mut c) = (SurfaceHit8::MISS, SurfaceHit8::MISS);
        sc.uniform_materials(fast.mat[0], valid, &mut a);
        sc.gather_materials(valid, &slow.mat, &mut c);
        same_record(&a, &c);
    }
    // Packets the splat path must not take still gather per lane: a light triangle, two
    // triangles, a sphere lane.
    let (org, dir) = rays();
    let sphere = if sc.sphere_point_index.is_empty() { GEOM_ELLIPSOIDS } else { GEOM_SPHERES };
    for (geom, prim) in [
        ([GEOM_TRIANGLES; 8], [light_tri; 8]),
        ([GEOM_TRIANGLES; 8], [0, 1, 0, 1, 0, 0, 1, 1]),
        ([GEOM_TRIANGLES, sphere, GEOM_TRIANGLES, 0, 0, 0, 0, 0], [0; 8]),
    ] {
        let h = hits([true; 8], geom, prim);
        let mut out = SurfaceHit8::MISS;
        sc.gather_into(org, dir, &h, &mut out);
        assert!(out.valid.to_bitmask() == 0xff);
    }
}

/// Packets mixing materials take each hit lane's own material, field by field (bits), and
/// the miss record's on the other lanes, whatever the order of the materials in the lanes.
#[test]
fn mixed_material_packets_take_each_lanes_material() {
    let text = "size 8 8\ncamera 0 1 -4 0 0 0 0 1 0 45\nmaxverts 3\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\n\
                diffuse 0.3 0.3 0.5\ntri 0 1 2\n\
                diffuse 0.5 0.2 0.1\nspecular 0.2 0.3 0.4\nshininess 40\ntri 0 1 2\n\
                brdf ggx\nroughness 0.25\ndiffuse 0.1 0.6 0.2\nambient 0.05 0.02 0.01\ntri 0 1 2\n\
                brdf phong\ndiffuse 0 0 0\nspecular 0 0 0\nemission 2 1 -0\ntri 0 1 2\n";
    let desc = parse_str(text, std::path::Path::new("t.test"), &Limits::default()).expect("scene");
    let sc = Scene::build(desc).expect("build");
    assert!(sc.materials.len() >= 4);
    let f = |x: F8| x.to_array().map(f32::to_bits);
    let v = |x: Vec3x8, i: usize| x.lane(i).to_array().map(f32::to_bits);
    let patterns: [[u32; 8]; 4] =
        [[0, 1, 2, 3, 0, 1, 2, 3], [3, 3, 0, 3, 2, 2, 1, 0], [1, 1, 1, 1, 1, 1, 1, 2], [2, 0, 0, 0, 0, 0, 0, 0]];
    for mat in patterns {
        for hit in [
            [true; 8],
            [true, false, true, true, false, true, false, true],
            [false, true, false, false, false, false, false, true],
        ] {
            let valid = mask_from_bools(hit);
            let mut out = SurfaceHit8::MISS;
            out.mat.kd = Vec3x8::splat(Vec3::ONE); // stale contents of a reused buffer
            sc.gather_materials(valid, &mat, &mut out);
            for i in 0..8 {
                let m = if hit[i] { &sc.materials[mat[i] as usize] } else { &MISS_MATERIAL };
                let o = &out.mat;
                let at = |x: F8| f(x)[i];
                assert_eq!(v(o.kd, i), m.diffuse.to_array().map(f32::to_bits), "{mat:?} {hit:?} lane {i}");
                assert_eq!(v(o.ks, i), m.specular.to_array().map(f32::to_bits));
                assert_eq!((at(o.shininess), at(o.alpha)), (m.shininess.to_bits(), m.roughness.to_bits()));
                assert_eq!(at(o.ggx), if hit[i] && m.brdf == BrdfKind::Ggx { u32::MAX } else { 0 });
                assert_eq!(v(out.emitted, i), (Vec3::ZERO + m.emission).to_array().map(f32::to_bits));
                assert_eq!(v(out.ambient, i), m.ambient.to_array().map(f32::to_bits));
            }
        }
    }
}

/// A packet with no hit gets exactly the miss record (with its points and `wo`).
#[test]
fn a_packet_that_hits_nothing_gets_the_miss_record() {
    let sc = scene();
    let (org, dir) = rays();
    let h = hits([false; 8], [INVALID_ID; 8], [INVALID_ID; 8]);
    let mut out = SurfaceHit8::MISS;
    out.mat.kd = Vec3x8::splat(Vec3::ONE); // stale contents of a reused buffer
    sc.gather_into(org, dir, &h, &mut out);
    let want = SurfaceHit8 { p: dir.mul_add(h.t, org), wo: -dir, ..SurfaceHit8::MISS };
    same_record(&out, &want);
}

/// Packets whose hit lanes all hit triangles, several distinct ones and the light's from either
/// side, take the per-distinct-triangle selects: normal, material id, light id and emission,
/// every lane bit for bit as the lane-by-lane lookups (0 material and no light on missed lanes).
#[test]
fn distinct_triangle_packets_match_the_lane_by_lane_gather() {
    let sc = scene();
    let (_, dir) = rays();
    let lights: Vec<u32> = (0..sc.tri_light.len() as u32).filter(|&t| sc.tri_light[t as usize] != INVALID_ID).collect();
    assert!(lights.len() >= 2, "the quad light's two triangles");
    // Rays up and down: the light faces down, so only lanes going up see its emission.
    let up = Vec3x8::from_lanes(std::array::from_fn(|i| Vec3::new(0.1 * i as f32 - 0.3, 1.0, 0.2).normalize()));
    let mixed = Vec3x8::select(mask_from_bools([true, false, true, false, false, true, false, true]), up, dir);
    let patterns = [
        [0, 1, 0, 1, 1, 0, 0, 1],
        [lights[0], 0, lights[1], 1, lights[0], lights[0], 1, lights[1]],
        [1, lights[1], 1, 1, 0, lights[0], 0, 0],
    ];
    for prim in patterns {
        for hit in [
            [true; 8],
            [true, false, true, true, false, true, true, false],
            [false, false, false, true, false, false, false, false],
        ] {
            for d in [dir, up, mixed] {
                let b = mask_from_bools(hit).to_bitmask();
                let p = Vec3x8::splat(Vec3::new(0.1, 0.0, 0.2));
                let fast = sc.distinct_triangles(mask_from_bools(hit), U8::new(prim), d);
                let slow = sc.lane_by_lane::<false>(b, [&[GEOM_TRIANGLES; 8], &prim, &[INVALID_ID; 8]], p, d);
                assert_eq!(bits(fast.n), bits(slow.n), "{prim:?} {hit:?}");
                assert_eq!(fast.light.to_array(), slow.light.to_array(), "{prim:?} {hit:?}");
                assert_eq!(bits(fast.le), bits(slow.le), "{prim:?} {hit:?}");
                assert_eq!(fast.mat, slow.mat, "{prim:?} {hit:?}");
                assert_eq!(fast.any_tri, slow.any_tri);
            }
        }
    }
    // Some lane of the patterns saw the light's emission (the test reaches that branch).
    let lit = sc.distinct_triangles(mask_from_bools([true; 8]), U8::new(patterns[1]), up);
    assert!(lit.le.max_elem().to_array().iter().any(|&v| v > 0.0));
}

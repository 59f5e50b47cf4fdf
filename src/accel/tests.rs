//! Tests of the Embree layer: FFI layouts (canaries), lane masks, shadow intervals, error reporting.

use super::*;
use crate::simd::{mask_all, mask_to_bools};
use crate::simd::{Vec3x8, F8};
use embree4_sys as sys;
use glam::{Mat4, Vec3, Vec4};

#[repr(C, align(32))]
struct Canaried<T> {
    value: T,
    canary: [u32; 64],
}
const CANARY: u32 = 0xDEAD_BEEF;

fn build(dev: &Device, with_instance: bool) -> Scene {
    let mut b = SceneBuilder::new(dev).unwrap();
    // A quad at z = 5 spanning [-1,1]^2, two triangles.
    let v =
        [Vec3::new(-1.0, -1.0, 5.0), Vec3::new(1.0, -1.0, 5.0), Vec3::new(1.0, 1.0, 5.0), Vec3::new(-1.0, 1.0, 5.0)];
    b.add_triangles(&v, &[[0, 1, 2], [0, 2, 3]]).unwrap();
    // A sphere point of radius 0.5 at (3, 0, 5); a user-geometry sphere of radius 0.5 at
    // (3, 3, 5) and an ellipsoid (0.5, 0.25, 0.5) at (0, 3, 5).
    b.add_spheres(&[Vec4::new(3.0, 0.0, 5.0, 0.5)]).unwrap();
    let sphere = Mat4::from_translation(Vec3::new(3.0, 3.0, 5.0)) * Mat4::from_scale(Vec3::splat(0.5));
    let ellipsoid = Mat4::from_translation(Vec3::new(0.0, 3.0, 5.0)) * Mat4::from_scale(Vec3::new(0.5, 0.25, 0.5));
    b.add_ellipsoids(&[sphere, ellipsoid]).unwrap();
    if with_instance {
        // The quad again, instanced: scaled by 0.5 and moved to (-3, 0, 0) (so at z = 2.5).
        let m = Mat4::from_translation(Vec3::new(-3.0, 0.0, 0.0)) * Mat4::from_scale(Vec3::splat(0.5));
        assert_eq!(b.add_mesh_instance(&v, &[[0, 1, 2], [0, 2, 3]], &m).unwrap(), GEOM_FIRST_INSTANCE);
    }
    let s = b.commit().unwrap();
    dev.take_errors().unwrap();
    s
}

fn packet(xs: [f32; 8], ys: [f32; 8]) -> (Vec3x8, Vec3x8) {
    let org = Vec3x8::new(F8::new(xs), F8::new(ys), F8::ZERO);
    (org, Vec3x8::splat(Vec3::Z))
}

/// Embree 4.4 writes instPrimID after the 4.2-era hit struct: canary words after our structs
/// must survive hits on plain and instanced geometry, for intersect and occluded.
#[test]
fn abi_canaries_survive_plain_and_instanced_hits() {
    let dev = Device::new().unwrap();
    let scene = build(&dev, true);
    let xs = [0.0, 3.0, 3.0, 0.0, -3.0, -3.1, 10.0, 0.0];
    let ys = [0.0, 3.0, 0.0, 3.1, 0.0, 0.05, 0.0, -0.9];
    let (org, dir) = packet(xs, ys);
    let mut c = Canaried { value: RayHit8::default(), canary: [CANARY; 64] };
    c.value.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), mask_all());
    let traced = scene.intersect8(&mut c.value, false, mask_all());
    assert!(c.canary.iter().all(|&w| w == CANARY), "Embree wrote past RayHit8");
    let h = Hits8::from_rayhit(&c.value, traced);
    assert_eq!(mask_to_bools(h.hit), [true, true, true, true, true, true, false, true]);
    let geom = h.geom.to_array();
    let inst = h.inst.to_array();
    assert_eq!([geom[0], geom[7]], [GEOM_TRIANGLES; 2]);
    assert_eq!(geom[2], GEOM_SPHERES);
    assert_eq!([geom[1], geom[3]], [GEOM_ELLIPSOIDS; 2]);
    assert_eq!([h.prim.to_array()[1], h.prim.to_array()[3]], [0, 1]);
    assert_eq!(&inst[4..6], &[GEOM_FIRST_INSTANCE; 2]);
    assert_eq!(&geom[4..6], &[0, 0]);
    assert_eq!(inst[0], INVALID_ID);
    let t = h.t.to_array();
    assert!((t[0] - 5.0).abs() < 1e-5);
    assert!((t[2] - 4.5).abs() < 1e-5, "sphere point front at z = 4.5: {}", t[2]);
    assert!((t[1] - 4.5).abs() < 1e-5, "user sphere front at z = 4.5: {}", t[1]);
    // ellipsoid at (0, 3): z half-axis 0.5; at y offset 0.1 of a 0.25 half-axis, z = 5 - 0.5 sqrt(1 - 0.16).
    assert!((t[3] - (5.0 - 0.5 * 0.84f32.sqrt())).abs() < 1e-5, "ellipsoid: {}", t[3]);
    assert!((t[4] - 2.5).abs() < 1e-5, "instanced quad at z = 2.5: {}", t[4]);
    // The 4.4-only field lands inside our struct: Embree writes it (0 for a plain instance hit)
    // over the INVALID_ID that intersect8 put there.
    assert_eq!(c.value.hit.inst_prim_id[0][4], 0);

    let mut r = Canaried { value: Ray8::default(), canary: [CANARY; 64] };
    r.value.set(org, dir, F8::ZERO, F8::splat(100.0), mask_all());
    let occ = scene.occluded8(&mut r.value, mask_all());
    assert!(r.canary.iter().all(|&w| w == CANARY), "Embree wrote past Ray8");
    assert_eq!(mask_to_bools(occ), [true, true, true, true, true, true, false, true]);
    dev.take_errors().unwrap();
}

/// `strata rays`' 16-wide and one-by-one replays read and write Embree 4.4's `RTCRayHit16` and
/// `RTCRayHit` through our word layouts: the same hit distances and ids as the 8-wide query on
/// triangles, both sphere kinds and an instance (instPrimID included), the same occlusion, and
/// nothing written past the structs.
#[test]
fn other_widths_find_the_hits_of_eight_wide_packets() {
    let dev = Device::new().unwrap();
    let scene = build(&dev, true);
    let xs = [0.0, 3.0, 3.0, 0.0, -3.0, -3.1, 10.0, 0.0];
    let ys = [0.0, 3.0, 0.0, 3.1, 0.0, 0.05, 0.0, -0.9];
    let (org, dir) = packet(xs, ys);
    let mut rh = RayHit8::default();
    rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), mask_all());
    let words: Vec<[u32; RAY_WORDS]> = (0..16).map(|i| rh.ray.lane_words(i % 8)).collect();
    let traced = scene.intersect8(&mut rh, false, mask_all());
    let h = Hits8::from_rayhit(&rh, traced);
    let (t8, prim, geom, inst) = (h.t.to_array(), h.prim.to_array(), h.geom.to_array(), h.inst.to_array());
    let (block, valid) = RayHit16::new(&words);
    let mut b16 = Canaried { value: block, canary: [CANARY; 64] };
    scene.intersect16(&mut b16.value, &valid, false);
    assert!(b16.canary.iter().all(|&w| w == CANARY), "Embree wrote past RayHit16");
    for (j, w) in words.iter().enumerate() {
        let mut one = Canaried { value: RayHit1::new(w), canary: [CANARY; 64] };
        scene.intersect1(&mut one.value, j % 2 == 0);
        assert!(one.canary.iter().all(|&w| w == CANARY), "Embree wrote past RayHit1");
        let l = j % 8;
        // tfar is untouched on a miss (lane 6): infinity in every form.
        let want = if mask_to_bools(h.hit)[l] { t8[l] } else { f32::INFINITY };
        assert_eq!(b16.value.tfar(j).to_bits(), want.to_bits(), "16-wide lane {j}");
        assert_eq!(one.value.tfar().to_bits(), want.to_bits(), "one ray {j}");
        // Hit words: primID, geomID, instID, instPrimID after Ng and u, v.
        let ids16: [u32; 4] = std::array::from_fn(|k| b16.value.0[16 * (RAY_WORDS + 5 + k) + j]);
        let ids1: [u32; 4] = std::array::from_fn(|k| one.value.0[RAY_WORDS + 5 + k]);
        let want = [prim[l], geom[l], inst[l], rh.hit.inst_prim_id[0][l]];
        assert_eq!(ids16, want, "16-wide ids lane {j}");
        assert_eq!(ids1, want, "one ray's ids {j}");
    }
    // Occlusion within tfar = 100 (every lane but 6), and not within 1.
    for (tfar, hit) in [(100.0f32, mask_to_bools(h.hit)), (1.0, [false; 8])] {
        let near: Vec<[u32; RAY_WORDS]> = words
            .iter()
            .map(|w| {
                let mut w = *w;
                w[8] = tfar.to_bits();
                w
            })
            .collect();
        let (mut b, valid) = RayHit16::new(&near);
        scene.occluded16(&mut b, &valid);
        for (j, w) in near.iter().enumerate() {
            let mut one = RayHit1::new(w);
            scene.occluded1(&mut one);
            let occluded = hit[j % 8];
            assert_eq!(b.tfar(j) == f32::NEG_INFINITY, occluded, "16-wide occluded lane {j} tfar {tfar}");
            assert_eq!(one.tfar() == f32::NEG_INFINITY, occluded, "one ray occluded {j} tfar {tfar}");
        }
    }
    // A short block: the lanes past the rays are not valid, so not traced.
    let (mut b, valid) = RayHit16::new(&words[..3]);
    scene.intersect16(&mut b, &valid, true);
    assert!((3..16).all(|j| b.tfar(j) == 0.0 && b.0[16 * (RAY_WORDS + 6) + j] == INVALID_ID));
    dev.take_errors().unwrap();
}

#[test]
fn inactive_and_nan_lanes_are_not_traced() {
    let dev = Device::new().unwrap();
    let scene = build(&dev, false);
    let mut xs = [0.0; 8];
    xs[3] = f32::NAN;
    let (org, dir) = packet(xs, [0.0; 8]);
    let mut rh = RayHit8::default();
    let active = crate::simd::mask_first(6);
    rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), active);
    // A NaN smuggled in after set() must still be dropped by intersect8.
    rh.ray.org_x[3] = f32::NAN;
    let traced = scene.intersect8(&mut rh, true, active);
    assert_eq!(mask_to_bools(traced), [true, true, true, false, true, true, false, false]);
    let h = Hits8::from_rayhit(&rh, traced);
    assert_eq!(mask_to_bools(h.hit), [true, true, true, false, true, true, false, false]);
    assert!(h.t.to_array()[..3].iter().all(|t| (t - 5.0).abs() < 1e-5));
    dev.take_errors().unwrap();
}

#[test]
fn tfar_limits_shadow_rays() {
    let dev = Device::new().unwrap();
    let scene = build(&dev, false);
    let (org, dir) = packet([0.0; 8], [0.0; 8]);
    let mut r = Ray8::default();
    let tf = F8::new([4.9, 5.1, 4.9, 5.1, 100.0, 0.1, 4.99, 5.01]);
    r.set(org, dir, F8::ZERO, tf, mask_all());
    let occ = scene.occluded8(&mut r, mask_all());
    assert_eq!(mask_to_bools(occ), [false, true, false, true, true, false, false, true]);
}

#[test]
fn embree_errors_become_rust_errors() {
    let dev = Device::new().unwrap();
    let mut b = SceneBuilder::new(&dev).unwrap();
    let err = b.add_triangles(&[Vec3::ZERO], &[[0, 1, 2]]).unwrap_err();
    assert!(err.0.contains("out of range"), "{err}");
    dev.take_errors().unwrap();
    // Setting a buffer type a triangle mesh does not have is an Embree error, reported through
    // the callback and turned into an Err.
    // SAFETY: a fresh geometry of a live device, given an invalid buffer on purpose, released.
    unsafe {
        let g = sys::rtcNewGeometry(dev.raw, sys::RTCGeometryType::TRIANGLE);
        sys::rtcSetNewGeometryBuffer(g, sys::RTCBufferType::GRID, 0, sys::RTCFormat::UINT3, 12, 1);
        sys::rtcReleaseGeometry(g);
    }
    let err = dev.take_errors().unwrap_err();
    assert!(!err.0.is_empty(), "{err}");
    dev.take_errors().unwrap();
}

/// One group (child scene) placed by two instances: each hit reports its instance's id (the
/// `instID` field read through our `Hit8` layout), geometry 0 and the group's triangle.
#[test]
fn two_instances_share_one_group_and_report_their_ids() {
    let dev = Device::new().unwrap();
    let mut b = SceneBuilder::new(&dev).unwrap();
    b.add_triangles(&[], &[]).unwrap();
    let v =
        [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0)];
    let g = b.add_group(&v, &[[0, 1, 2], [0, 2, 3]]).unwrap();
    let near = Mat4::from_translation(Vec3::new(0.0, 0.0, 2.0));
    let far = Mat4::from_translation(Vec3::new(5.0, 0.0, 7.0)) * Mat4::from_scale(Vec3::splat(2.0));
    assert_eq!(b.add_instance(g, &near).unwrap(), GEOM_FIRST_INSTANCE);
    assert_eq!(b.add_instance(g, &far).unwrap(), GEOM_FIRST_INSTANCE + 1);
    let scene = b.commit().unwrap();
    let (org, dir) = packet([0.5, -0.5, 5.5, 4.0, 20.0, 0.5, 6.9, 3.5], [-0.5, 0.5, -1.0, 1.0, 0.0, 0.9, 1.9, -1.0]);
    let mut rh = RayHit8::default();
    rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), mask_all());
    let traced = scene.intersect8(&mut rh, false, mask_all());
    let h = Hits8::from_rayhit(&rh, traced);
    assert_eq!(mask_to_bools(h.hit), [true, true, true, true, false, true, true, true]);
    let (i0, i1) = (GEOM_FIRST_INSTANCE, GEOM_FIRST_INSTANCE + 1);
    let inst = h.inst.to_array();
    assert_eq!([inst[0], inst[1], inst[5]], [i0; 3]);
    assert_eq!([inst[2], inst[3], inst[6], inst[7]], [i1; 4]);
    assert_eq!(inst[4], INVALID_ID);
    let (geom, prim) = (h.geom.to_array(), h.prim.to_array());
    assert!([0, 1, 2, 3, 5, 6, 7].iter().all(|&i| geom[i] == 0), "the group's geometry 0: {geom:?}");
    // x > y: triangle 0 (below the diagonal), else 1 (in group space)
    assert_eq!([prim[0], prim[1], prim[2], prim[3]], [0, 1, 0, 1]);
    let t = h.t.to_array();
    assert!((t[0] - 2.0).abs() < 1e-5 && (t[2] - 7.0).abs() < 1e-5, "{t:?}");
}

/// A lone ellipsoid is called only by packets with a ray that crosses its box: Embree makes a
/// one-primitive BVH a bare leaf, which every packet reaches without a box test, so
/// `add_ellipsoids` gives it a sentinel primitive that is never hit (the same hits as without).
#[test]
fn a_lone_ellipsoid_is_called_only_by_rays_near_it() {
    use super::user_geometry::CALLBACK_CALLS;
    let calls = || CALLBACK_CALLS.with(|c| c.replace(0));
    let dev = Device::new().unwrap();
    let mut b = SceneBuilder::new(&dev).unwrap();
    b.add_triangles(&[Vec3::new(-9.0, -9.0, 9.0), Vec3::new(9.0, -9.0, 9.0), Vec3::new(0.0, 9.0, 9.0)], &[[0, 1, 2]])
        .unwrap();
    // The unit sphere at (0, 0, 5): its box is [-1, 1]^2 x [4, 6].
    b.add_ellipsoids(&[Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0))]).unwrap();
    let scene = b.commit().unwrap();
    let trace = |xs: [f32; 8], ys: [f32; 8]| {
        let (org, dir) = packet(xs, ys);
        let mut rh = RayHit8::default();
        rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), mask_all());
        let traced = scene.intersect8(&mut rh, false, mask_all());
        let h = Hits8::from_rayhit(&rh, traced);
        // Shadow rays stop short of the triangle: only the sphere can occlude them.
        let mut r = Ray8::default();
        r.set(org, dir, F8::ZERO, F8::splat(8.5), mask_all());
        let occ = scene.occluded8(&mut r, mask_all());
        (mask_to_bools(h.hit), h.geom.to_array(), h.t.to_array(), mask_to_bools(occ))
    };
    calls();
    // Rays along +z at |x| >= 2: they hit the triangle at z = 9 and pass far from the sphere's box.
    let far = [2.0, 2.5, 3.0, -2.0, -2.5, -3.0, 2.0, -2.0];
    let (hit, geom, t, occ) = trace(far, [0.0; 8]);
    assert_eq!((hit, occ), ([true; 8], [false; 8]));
    assert!(geom.iter().all(|&g| g == GEOM_TRIANGLES) && t.iter().all(|t| (t - 9.0).abs() < 1e-5));
    assert_eq!(calls(), 0, "a packet that misses the ellipsoid's box called its callbacks");
    // Half the rays through the sphere: it is hit at z = 4 (the sentinel hides nothing).
    let xs = [0.0, 2.0, 0.5, 2.5, -0.5, 3.0, 0.0, -2.0];
    let ys = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0];
    let (hit, geom, t, occ) = trace(xs, ys);
    assert_eq!((hit, occ), ([true; 8], [true, false, true, false, true, false, true, false]));
    for i in [0, 2, 4, 6] {
        let z = 5.0 - (1.0 - xs[i] * xs[i] - ys[i] * ys[i]).sqrt();
        assert_eq!(geom[i], GEOM_ELLIPSOIDS);
        assert!((t[i] - z).abs() < 1e-5, "lane {i}: t {} against {z}", t[i]);
    }
    assert!([1, 3, 5, 7].iter().all(|&i| geom[i] == GEOM_TRIANGLES));
    assert!(calls() >= 2, "the packets through the sphere called its intersect and occluded callbacks");
    dev.take_errors().unwrap();
}

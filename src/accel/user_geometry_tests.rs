//! The callbacks' width-8 path (one SIMD pass, masked row blends) against their any-width lane
//! path, called directly as Embree would: same hit records and occlusion, word for word.

use super::*;
use crate::accel::ellipsoid::bench::Rng;
use glam::{Mat4, Vec3};

/// Words of an RTCRayHitN (12 ray + 9 hit fields, one instance level) of width `n`.
const FIELDS: usize = 21;

/// Random rays near the two primitives (unit sphere at the origin, ellipsoid at (3, 0, 0)):
/// hits, misses, grazing rays (the f64 fallback), tnear/tfar cuts, as a width-16 block whose hit
/// part holds a stale earlier hit (which lanes that miss must keep).
fn block(rng: &mut Rng) -> Vec<u32> {
    let n = 16;
    let mut b = vec![0u32; FIELDS * n];
    for lane in 0..n {
        let target = if lane % 2 == 0 { Vec3::ZERO } else { Vec3::new(3.0, 0.0, 0.0) };
        let o = target + rng.dir() * 4.0;
        let d = match lane % 4 {
            // Tangent to the unit sphere: the f32 pass leaves it to f64.
            0 => {
                let a = (-o).normalize();
                let side = a.any_orthonormal_vector();
                let s = (o.length_squared() - 1.0).sqrt() / o.length();
                (a * s + side * (1.0 - s * s).sqrt()).normalize()
            }
            _ => (target + rng.dir() * 1.2 - o).normalize(),
        };
        let tn = if lane % 5 == 0 { 3.5 } else { 0.0 };
        let tf = if lane % 7 == 0 { 3.0 } else { f32::INFINITY };
        let ray = [o.x, o.y, o.z, tn, d.x, d.y, d.z, 0.0, tf];
        for (f, v) in ray.iter().enumerate() {
            b[f * n + lane] = v.to_bits();
        }
        b[9 * n + lane] = u32::MAX; // mask
        for f in 12..FIELDS {
            b[f * n + lane] = 0xABCD_0000 + f as u32; // a stale hit
        }
    }
    b
}

/// Lanes `start..start + w` of a width-16 block as a width-`w` block.
fn narrow(b: &[u32], start: usize, w: usize) -> Vec<u32> {
    (0..FIELDS).flat_map(|f| b[f * 16 + start..f * 16 + start + w].to_vec()).collect()
}

#[test]
fn width_8_path_matches_lane_path() {
    let prims = vec![
        Ellipsoid::new(&Mat4::IDENTITY).unwrap(),
        Ellipsoid::new(
            &(Mat4::from_translation(Vec3::new(3.0, 0.0, 0.0)) * Mat4::from_scale(Vec3::new(1.0, 0.5, 0.8))),
        )
        .unwrap(),
    ];
    let user = &prims as *const Vec<Ellipsoid> as *mut c_void;
    let mut rng = Rng(9);
    let mut ctx = RayQueryContext { inst_id: [7], inst_prim_id: [8] };
    let mut hits = 0;
    for round in 0..200 {
        let wide = block(&mut rng);
        let valid: Vec<i32> = (0..16).map(|i| if (round + i) % 6 == 5 { 0 } else { -1 }).collect();
        for prim in 0..2u32 {
            for occluded in [false, true] {
                // Width 16 (the lane path), then each half at width 8 (the SIMD path).
                let call = |b: &mut Vec<u32>, v: &[i32], n: usize, ctx: &mut RayQueryContext| {
                    let (valid, ptr) = (v.as_ptr() as *mut i32, b.as_mut_ptr());
                    let ctx = ctx as *mut RayQueryContext as *mut sys::RTCRayQueryContext;
                    // SAFETY: `b` is a width-n RTCRayHitN (21 words per lane), `valid` n ints,
                    // `user` the Vec<Ellipsoid> and prim < 2: the callbacks' contract.
                    unsafe {
                        if occluded {
                            let a = sys::RTCOccludedFunctionNArguments {
                                valid,
                                geometryUserPtr: user,
                                primID: prim,
                                context: ctx,
                                ray: ptr as *mut sys::RTCRayN,
                                N: n as u32,
                                geomID: 2,
                            };
                            ellipsoid_occluded(&a);
                        } else {
                            let a = sys::RTCIntersectFunctionNArguments {
                                valid,
                                geometryUserPtr: user,
                                primID: prim,
                                context: ctx,
                                rayhit: ptr as *mut sys::RTCRayHitN,
                                N: n as u32,
                                geomID: 2,
                            };
                            ellipsoid_intersect(&a);
                        }
                    }
                };
                let mut lanes = wide.clone();
                call(&mut lanes, &valid, 16, &mut ctx);
                for half in 0..2 {
                    let mut b8 = narrow(&wide, 8 * half, 8);
                    call(&mut b8, &valid[8 * half..8 * half + 8], 8, &mut ctx);
                    assert_eq!(b8, narrow(&lanes, 8 * half, 8), "round {round} prim {prim} occluded {occluded}");
                }
                hits += (0..16).filter(|&i| lanes[8 * 16 + i] != wide[8 * 16 + i]).count();
            }
        }
    }
    assert!(hits > 1000, "too few hits to mean anything: {hits}");
}

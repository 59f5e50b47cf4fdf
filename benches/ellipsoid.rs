//! Sphere/ellipsoid intersection, one primitive, 8-ray packets: the old scalar f64 path lane by
//! lane (`Ellipsoid::hit`) against the f32 SIMD packet path with its f64 fallback, on camera-like
//! coherent packets (8 neighbouring pixels of a 256x256 view of the hw3 cornellSimple sphere, only
//! packets whose rays reach the bounding box, as Embree would call) and on random rays (random
//! origins in a box around the primitive, aimed at random points of its bounding ball).
//! After criterion, a table of ns per ray (median of 7 interleaved thread-CPU timings) and the
//! share of lanes left to f64; then, for the sphere, the same packets through Embree
//! (`rtcIntersect8` and `rtcOccluded8` on a scene holding only it) as today's user geometry and as
//! Embree's own sphere point (`SceneBuilder::add_spheres`).

use criterion::{criterion_group, criterion_main, Criterion};
use glam::{Mat4, Vec3};
use std::hint::black_box;
use strata::accel::ellipsoid::bench::{pack, Packet, Prim, Rng};
use strata::accel::{Device, Hits8, Ray8, RayHit8, Scene, SceneBuilder};
use strata::simd::{mask_all, Vec3x8, F8};

fn packet(rays: &[(Vec3, Vec3)]) -> Packet {
    pack(&rays.iter().map(|&(o, d)| (o, d, 0.0, f32::INFINITY)).collect::<Vec<_>>())
}

/// 8x1 pixel rows of a 256x256 45-degree view from (0, 1, 3) at (0, 1, 0) whose rays pass within
/// `reach` of `c` (the bounding-box test Embree does before calling the intersector).
fn camera_packets(c: Vec3, reach: f32) -> Vec<Packet> {
    let eye = Vec3::new(0.0, 1.0, 3.0);
    let (fw, up) = (Vec3::new(0.0, 0.0, -1.0), Vec3::Y);
    let right = fw.cross(up);
    let tan = (22.5f32).to_radians().tan();
    let mut out = Vec::new();
    for y in 0..256 {
        for x0 in (0..256).step_by(8) {
            let rays: Vec<(Vec3, Vec3)> = (x0..x0 + 8)
                .map(|x| {
                    let (sx, sy) = ((x as f32 + 0.5) / 128.0 - 1.0, 1.0 - (y as f32 + 0.5) / 128.0);
                    (eye, (fw + right * (sx * tan) + up * (sy * tan)).normalize())
                })
                .collect();
            let reaches = rays.iter().any(|(o, d)| (c - *o).cross(*d).length() < reach);
            if reaches {
                out.push(packet(&rays));
            }
        }
    }
    out
}

fn random_packets(rng: &mut Rng, c: Vec3, reach: f32, n: usize) -> Vec<Packet> {
    (0..n)
        .map(|_| {
            let rays: Vec<(Vec3, Vec3)> = (0..8)
                .map(|_| {
                    let o = c + Vec3::new(rng.sym(), rng.sym(), rng.sym()) * 4.0;
                    let t = c + Vec3::new(rng.sym(), rng.sym(), rng.sym()) * reach;
                    (o, (t - o).normalize())
                })
                .collect();
            packet(&rays)
        })
        .collect()
}

fn ellipsoid_bench(c: &mut Criterion) {
    strata::accel::set_ftz_daz();
    let centre = Vec3::new(0.3, 0.3, 0.2);
    let base = Mat4::from_translation(centre) * Mat4::from_rotation_y(-20f32.to_radians());
    let prims = [
        ("sphere", base * Mat4::from_scale(Vec3::splat(0.3)), 0.3f32),
        ("ellipsoid", base * Mat4::from_rotation_x(0.5) * Mat4::from_scale(Vec3::new(0.3, 0.6, 0.2)), 0.6),
    ];
    let mut rng = Rng(42);
    let mut table = Vec::new();
    for (pname, m, r) in prims {
        let prim = Prim::new(&m).unwrap();
        let sets = [("camera", camera_packets(centre, r)), ("random", random_packets(&mut rng, centre, r, 4096))];
        for (sname, pk) in sets {
            // Same answers (hit count, and distances to 1e-5 relative in sum).
            let (n64, s64) = pk.iter().fold((0, 0.0f64), |(n, s), p| {
                let (a, b) = prim.scalar64(p);
                (n + a, s + f64::from(b))
            });
            let (n32, s32) = pk.iter().fold((0, 0.0f64), |(n, s), p| {
                let (a, b) = prim.packet(p);
                (n + a, s + f64::from(b))
            });
            assert_eq!(n64, n32, "{pname}/{sname}: hit counts differ");
            assert!((s64 - s32).abs() <= 1e-5 * s64.abs(), "{pname}/{sname}: {s64} vs {s32}");
            let unsure: u32 = pk.iter().map(|p| prim.unsure(p)).sum();
            let lanes = pk.len() * 8;
            let mut g = c.benchmark_group(format!("{pname}-{sname}"));
            g.sample_size(20)
                .warm_up_time(std::time::Duration::from_millis(200))
                .measurement_time(std::time::Duration::from_secs(1));
            g.bench_function("scalar-f64", |b| {
                b.iter(|| pk.iter().map(|p| prim.scalar64(black_box(p)).0).sum::<u32>())
            });
            g.bench_function("packet-f32", |b| b.iter(|| pk.iter().map(|p| prim.packet(black_box(p)).0).sum::<u32>()));
            g.finish();
            let cpu = |f: &dyn Fn() -> u32| {
                strata::measure::thread_seconds(|| {
                    for _ in 0..20 {
                        black_box(f());
                    }
                }) / 20.0
            };
            let (mut t64, mut t32) = (Vec::new(), Vec::new());
            for _ in 0..7 {
                t64.push(cpu(&|| pk.iter().map(|p| prim.scalar64(black_box(p)).0).sum()));
                t32.push(cpu(&|| pk.iter().map(|p| prim.packet(black_box(p)).0).sum()));
            }
            let median = |v: &mut Vec<f64>| {
                v.sort_by(f64::total_cmp);
                v[v.len() / 2] * 1e9 / lanes as f64
            };
            let hits = n64 as f64 / lanes as f64;
            table.push((pname, sname, lanes, hits, unsure as f64 / lanes as f64, median(&mut t64), median(&mut t32)));
        }
    }
    println!("\nprimitive  rays     lanes   hit%   f64-fallback%   scalar f64 ns/ray   packet f32 ns/ray   speedup");
    for (p, s, lanes, hits, uns, a, b) in table {
        println!("{p:10} {s:7} {lanes:6} {:6.1} {:14.2} {a:19.2} {b:19.2} {:8.2}x", hits * 100.0, uns * 100.0, a / b);
    }
    embree_table(centre, 0.3, &mut rng);
}

/// The packet's rays as an Embree `Ray8`.
fn ray8(p: &Packet) -> Ray8 {
    let v3 = |f: usize| Vec3x8::new(F8::new(p[f]), F8::new(p[f + 1]), F8::new(p[f + 2]));
    Ray8::new(v3(0), v3(4), F8::new(p[3]), F8::new(p[8]), mask_all()).0
}

/// Closest hits of every packet: (hit lanes, sum of distances).
fn intersect_all(scene: &Scene, pk: &[Packet]) -> (u32, f64) {
    pk.iter().fold((0, 0.0), |(n, s), p| {
        let mut rh = RayHit8 { ray: ray8(p), ..RayHit8::default() };
        let traced = scene.intersect8(&mut rh, false, mask_all());
        let h = Hits8::from_rayhit(&rh, traced);
        let t = h.hit.select(h.t, F8::ZERO).to_array();
        (n + h.hit.to_bitmask().count_ones(), s + t.iter().map(|&t| f64::from(t)).sum::<f64>())
    })
}

/// Occluded lanes of every packet.
fn occluded_all(scene: &Scene, pk: &[Packet]) -> u32 {
    pk.iter().map(|p| scene.occluded8(&mut ray8(p), mask_all()).to_bitmask().count_ones()).sum()
}

/// The sphere of radius `r` at `c` through Embree: user geometry against sphere point.
fn embree_table(c: Vec3, r: f32, rng: &mut Rng) {
    let dev = Device::new().unwrap();
    let mut b = SceneBuilder::new(&dev).unwrap();
    b.add_spheres(&[c.extend(r)]).unwrap();
    let points = b.commit().unwrap();
    let mut b = SceneBuilder::new(&dev).unwrap();
    b.add_ellipsoids(&[Mat4::from_translation(c) * Mat4::from_scale(Vec3::splat(r))]).unwrap();
    let user = b.commit().unwrap();
    println!("\nsphere through Embree  rays     query       user geometry ns/ray   sphere point ns/ray   point/user");
    for (sname, pk) in [("camera", camera_packets(c, r)), ("random", random_packets(rng, c, r, 4096))] {
        let (nu, su) = intersect_all(&user, &pk);
        let (np, sp) = intersect_all(&points, &pk);
        assert_eq!(nu, np, "{sname}: hit counts differ");
        assert!((su - sp).abs() <= 1e-5 * su, "{sname}: {su} vs {sp}");
        let lanes = (pk.len() * 8) as f64;
        let cpu = |f: &dyn Fn() -> u32| {
            strata::measure::thread_seconds(|| {
                for _ in 0..20 {
                    black_box(f());
                }
            }) / 20.0
        };
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2] * 1e9 / lanes
        };
        for query in ["intersect8", "occluded8"] {
            let run = |s: &Scene| -> u32 {
                if query == "intersect8" {
                    intersect_all(s, black_box(&pk)).0
                } else {
                    occluded_all(s, black_box(&pk))
                }
            };
            let (mut tu, mut tp) = (Vec::new(), Vec::new());
            for _ in 0..7 {
                tu.push(cpu(&|| run(&user)));
                tp.push(cpu(&|| run(&points)));
            }
            let (a, b) = (median(tu), median(tp));
            println!("{:22} {sname:7}  {query:10} {a:22.2} {b:21.2} {:11.2}x", "", b / a);
        }
    }
}

criterion_group!(benches, ellipsoid_bench);
criterion_main!(benches);

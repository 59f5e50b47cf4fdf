//! Sphere/ellipsoid intersection, one primitive, 8-ray packets: the old scalar f64 path lane by
//! lane (`Ellipsoid::hit`) against the f32 SIMD packet path with its f64 fallback, on camera-like
//! coherent packets (8 neighbouring pixels of a 256x256 view of the hw3 cornellSimple sphere, only
//! packets whose rays reach the bounding box, as Embree would call) and on random rays (random
//! origins in a box around the primitive, aimed at random points of its bounding ball).
//! After criterion, a table of ns per ray (median of 7 interleaved thread-CPU timings) and the
//! share of lanes left to f64.

use criterion::{criterion_group, criterion_main, Criterion};
use glam::{Mat4, Vec3};
use std::hint::black_box;
use strata::accel::ellipsoid::bench::{pack, Packet, Prim, Rng};

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
}

criterion_group!(benches, ellipsoid_bench);
criterion_main!(benches);

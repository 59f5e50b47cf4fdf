//! Cost of light selection: `lights/<strategy>/<N>/{sample,pmf,sample_x8}` for N = 10, 1000, 10000
//! emitters (random quads over a 40 x 40 area at heights 2..8 facing down, radiance over three
//! decades, as in scenes/manylights.test), shading points on the floor below them with normal +y.
//! Throughput is calls (lanes for x8) per second: ns per call = 1e9 / thrpt. Also prints the tree
//! build time per N.
//!
//! `warps/<light>/{throughput,latency}`: `--light-warp solid-angle` on one light (a 2 x 1
//! rectangle, a triangle, a sphere of radius 0.5, 2 to 3 units above shading points on the floor),
//! the area sample placed again by solid angle (`Emitters::warp_one_x8`), per lane. `throughput`
//! warps independent packets (what a core does when nothing waits on the result); `latency`
//! makes each packet's shading points depend on the previous packet's light points (by 1e-30 of
//! them: the same values), so the chain of divisions and square roots is timed end to end, as
//! shading one packet waits on it in a render.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::Vec3;
use std::hint::black_box;
use std::time::{Duration, Instant};
use strata::light::emitters::{Emitter, Emitters};
use strata::light::select::{LightSampler, LightSelection};
use strata::light::warp::LightWarp;
use strata::simd::{mask_all, Vec3x8, F8};

const CALLS: usize = 1024;

/// SplitMix64 in [0, 1).
struct Rng(u64);
impl Rng {
    fn f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 * (1.0 / 16_777_216.0)
    }
}

fn lights(n: usize, rng: &mut Rng) -> Vec<Emitter> {
    (0..n)
        .map(|_| {
            let c = Vec3::new(rng.f32() * 40.0 - 20.0, 2.0 + 6.0 * rng.f32(), rng.f32() * 40.0 - 20.0);
            let size = 0.05 * 10f32.powf(rng.f32());
            let l = 0.3 * 10f32.powf(3.0 * rng.f32());
            // quad(): emits towards ac x ab = X x Z = -Y.
            Emitter::quad(c, Vec3::Z * size, Vec3::X * size, Vec3::splat(l))
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("lights");
    g.sample_size(20).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1));
    let mut rng = Rng(7);
    let points: Vec<(f32, Vec3)> =
        (0..CALLS).map(|_| (rng.f32(), Vec3::new(rng.f32() * 40.0 - 20.0, 0.0, rng.f32() * 40.0 - 20.0))).collect();
    for n in [10usize, 1000, 10_000] {
        let ls = lights(n, &mut rng);
        for sel in [LightSelection::UNIFORM, LightSelection::named("power"), LightSelection::named("spatial")] {
            let t0 = Instant::now();
            let s = LightSampler::new(&ls, sel);
            eprintln!("build {sel} N={n}: {:.2} ms", t0.elapsed().as_secs_f64() * 1e3);
            g.throughput(Throughput::Elements(CALLS as u64));
            g.bench_function(format!("{sel}/{n}/sample"), |b| {
                b.iter(|| {
                    let mut acc = 0.0f32;
                    for &(u, p) in &points {
                        if let Some((i, q)) = s.sample(black_box(u), black_box(p), Vec3::Y) {
                            acc += q + i as f32;
                        }
                    }
                    acc
                })
            });
            g.bench_function(format!("{sel}/{n}/pmf"), |b| {
                b.iter(|| {
                    let mut acc = 0.0f32;
                    for (k, &(_, p)) in points.iter().enumerate() {
                        acc += s.pmf(black_box(p), Vec3::Y, (k % n) as u32);
                    }
                    acc
                })
            });
            g.bench_function(format!("{sel}/{n}/sample_x8"), |b| {
                b.iter(|| {
                    let mut acc = F8::ZERO;
                    for ch in points.chunks_exact(8) {
                        let u = F8::new(std::array::from_fn(|l| ch[l].0));
                        let p = Vec3x8::from_lanes(std::array::from_fn(|l| ch[l].1));
                        let (_, q) = s.sample_x8(black_box(u), p, Vec3x8::splat(Vec3::Y), mask_all());
                        acc += q;
                    }
                    acc
                })
            });
        }
    }
    g.finish();
}

fn bench_warps(c: &mut Criterion) {
    let mut g = c.benchmark_group("warps");
    g.sample_size(20).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1));
    let mut rng = Rng(11);
    let packets: Vec<(Vec3x8, F8, F8)> = (0..CALLS / 8)
        .map(|_| {
            let p = Vec3x8::from_lanes(std::array::from_fn(|_| {
                Vec3::new(rng.f32() * 6.0 - 3.0, 0.0, rng.f32() * 6.0 - 3.0)
            }));
            (p, F8::new(std::array::from_fn(|_| rng.f32())), F8::new(std::array::from_fn(|_| rng.f32())))
        })
        .collect();
    let up = Vec3::Y * 3.0;
    let rect = Emitter::quad(Vec3::new(-1.0, 3.0, -0.5), Vec3::Z, Vec3::X * 2.0, Vec3::ONE);
    let tri =
        Emitter::triangle([up + Vec3::new(-1.0, 0.0, -0.5), up + Vec3::new(0.0, 0.0, 1.0), up + Vec3::X], Vec3::ONE);
    let sphere = Emitter::sphere(Vec3::new(0.0, 2.5, 0.0), 0.5, Vec3::ONE);
    g.throughput(Throughput::Elements(CALLS as u64));
    for (name, e) in [("rect", rect), ("tri", tri), ("sphere", sphere)] {
        let list = if e.triangle { Emitters::new([], [e]) } else { Emitters::new([e], []) };
        let e = &list.list[0];
        g.bench_function(format!("{name}/throughput"), |b| {
            b.iter(|| {
                let mut acc = F8::ZERO;
                for &(p, u, v) in &packets {
                    let mut ls = e.sample_x8(u, v);
                    list.warp_one_x8(0, LightWarp::SolidAngle, &mut ls, black_box(p), mask_all());
                    acc += ls.area + ls.y.x;
                }
                acc
            })
        });
        g.bench_function(format!("{name}/latency"), |b| {
            b.iter(|| {
                let mut last = Vec3x8::ZERO;
                for &(p, u, v) in &packets {
                    let mut ls = e.sample_x8(u, v);
                    let p = last.mul_add(F8::splat(1e-30), p);
                    list.warp_one_x8(0, LightWarp::SolidAngle, &mut ls, black_box(p), mask_all());
                    last = ls.y;
                }
                last
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench, bench_warps);
criterion_main!(benches);

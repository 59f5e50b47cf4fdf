//! Cost of light selection: `lights/<strategy>/<N>/{sample,pmf,sample_x8}` for N = 10, 1000, 10000
//! emitters (random quads over a 40 x 40 area at heights 2..8 facing down, radiance over three
//! decades, as in scenes/manylights.test), shading points on the floor below them with normal +y.
//! Throughput is calls (lanes for x8) per second: ns per call = 1e9 / thrpt. Also prints the tree
//! build time per N.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::Vec3;
use std::hint::black_box;
use std::time::{Duration, Instant};
use strata::light::emitters::Emitter;
use strata::light::select::{LightSampler, LightSelection};
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

criterion_group!(benches, bench);
criterion_main!(benches);

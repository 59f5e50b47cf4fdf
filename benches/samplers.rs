//! Sampler and warp cost, and equal-time variance.
//!
//! - `sampler/<kind>/{scalar,x8}`: one 2D point of every sampler (sets of 16 points, as 16 light
//!   samples would use); criterion's thrpt is points per second, so ns per sample = 1e9 / thrpt.
//! - `sampler/multijitter-1600/stream_x8`: `multijitter`'s points from a 1600-point set, the size
//!   of `direct`'s light table at 64 spp with 25 light samples (hw2's scenes): a set that is not a
//!   power of two, so its grid (40 x 40) is not the one above.
//! - `warp/<warp>/{scalar,x8}`: uniform hemisphere, cosine, Phong lobe (s = 30), GGX half vector
//!   (alpha = 0.3), parallelogram; thrpt is directions per second.
//! - `equal_time/<technique>`: one single-threaded render per technique; after criterion, a table
//!   of each technique's median seconds (15 renders, interleaved) and across-run variance (K = 8 runs, linear radiance, mean over pixels) and
//!   MSE against a reference, times the seconds of one run (lower is better: a technique twice as
//!   slow must halve the variance to break even). Direct lighting on hw2 cornell (9 light samples,
//!   pixel centre, 128x128) and path tracing on hw4 cornellBRDF (8 spp, 64x64) from ../shared/cse168;
//!   the built-in box (direct) when the corpus is absent.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::Vec3;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use strata::film::Film;
use strata::sampler::{PointSet, SamplerKind};
use strata::sampling as warp;
use strata::scene::desc::{ImportanceSampling, IntegratorKind};
use strata::session::RenderOptions;
use strata::simd::{Mask8, Vec3x8, F8, U8};

const POINTS: u32 = 4096;

fn config(g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>) {
    g.sample_size(20).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(1));
}

fn samplers(c: &mut Criterion) {
    let mut g = c.benchmark_group("sampler");
    config(&mut g);
    g.throughput(Throughput::Elements(u64::from(POINTS)));
    for kind in SamplerKind::ALL {
        let set = PointSet::new(kind, 16);
        g.bench_function(format!("{}/scalar", kind.name()), |b| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for i in 0..POINTS {
                    let p = set.point(black_box(i / 16), 0, 3, i % 16, 7);
                    acc += p[0] + p[1];
                }
                acc
            })
        });
        let lane = U8::from([0, 1, 2, 3, 4, 5, 6, 7]);
        g.bench_function(format!("{}/x8", kind.name()), |b| {
            b.iter(|| {
                let mut acc = F8::splat(0.0);
                for i in 0..POINTS / 8 {
                    // 8 lanes = 8 consecutive points k of one pixel's 16-point set.
                    let k = lane + U8::splat((i % 2) * 8);
                    let (x, y) = set.point_x8(black_box(U8::splat(i / 2)), U8::splat(0), 3, k, 7);
                    acc += x + y;
                }
                acc
            })
        });
        g.bench_function(format!("{}/stream_x8", kind.name()), |b| {
            b.iter(|| {
                let mut acc = F8::splat(0.0);
                // One stream = 8 pixels (lanes) x the 16 points of their sets, as light sampling does.
                for i in 0..POINTS / 128 {
                    let st = set.stream_x8(black_box(lane + U8::splat(i * 8)), U8::splat(0), 3, 7);
                    for k in 0..16 {
                        let (x, y) = st.point(k);
                        acc += x + y;
                    }
                }
                acc
            })
        });
    }
    // The light table of hw2's scenes at 64 spp (25 light samples): 8 pixels a stream, as above.
    let table = PointSet::new(SamplerKind::MULTIJITTER, 1600);
    let lane = U8::from([0, 1, 2, 3, 4, 5, 6, 7]);
    g.bench_function("multijitter-1600/stream_x8", |b| {
        b.iter(|| {
            let mut acc = F8::splat(0.0);
            for i in 0..POINTS / 128 {
                let st = table.stream_x8(black_box(lane + U8::splat(i * 8)), U8::splat(0), 3, 7);
                for k in 0..16 {
                    let (x, y) = st.point(k * 97);
                    acc += x + y;
                }
            }
            acc
        })
    });
    g.finish();
}

fn uniforms() -> (Vec<[f32; 2]>, Vec<[F8; 2]>) {
    let set = PointSet::new(SamplerKind::INDEPENDENT, 1);
    let u: Vec<[f32; 2]> = (0..POINTS).map(|i| set.point(i, 0, 0, 0, 1)).collect();
    let u8: Vec<[F8; 2]> = u
        .chunks(8)
        .map(|c| {
            let x: [f32; 8] = std::array::from_fn(|l| c[l][0]);
            let y: [f32; 8] = std::array::from_fn(|l| c[l][1]);
            [F8::from(x), F8::from(y)]
        })
        .collect();
    (u, u8)
}

fn warps(c: &mut Criterion) {
    let (u, u8) = uniforms();
    let all = Mask8::from([f32::from_bits(u32::MAX); 8]);
    let (a, ab, ac) = (Vec3::new(-0.25, 1.99, -0.25), Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.5, 0.0, 0.0));
    let (a8, ab8, ac8) = (Vec3x8::splat(a), Vec3x8::splat(ab), Vec3x8::splat(ac));
    let mut g = c.benchmark_group("warp");
    config(&mut g);
    g.throughput(Throughput::Elements(u64::from(POINTS)));
    macro_rules! pair {
        ($name:expr, |$p:ident| $scalar:expr, |$q:ident| $x8:expr) => {
            g.bench_function(concat!($name, "/scalar"), |b| {
                b.iter(|| {
                    let mut acc = 0.0f32;
                    for &$p in &u {
                        let (w, pdf) = $scalar;
                        acc += w.x + pdf;
                    }
                    acc
                })
            });
            g.bench_function(concat!($name, "/x8"), |b| {
                b.iter(|| {
                    let mut acc = F8::splat(0.0);
                    for &$q in &u8 {
                        let (w, pdf) = $x8;
                        acc += w.x + pdf;
                    }
                    acc
                })
            });
        };
    }
    pair!("uniform_hemisphere", |p| warp::sample_uniform_hemisphere(black_box(p)), |q| {
        warp::sample_uniform_hemisphere_x8(black_box(q), all)
    });
    pair!("cosine", |p| warp::sample_cosine_hemisphere(black_box(p)), |q| warp::sample_cosine_hemisphere_x8(
        black_box(q),
        all
    ));
    pair!("phong_lobe", |p| warp::sample_phong_lobe(black_box(p), 30.0), |q| warp::sample_phong_lobe_x8(
        black_box(q),
        F8::splat(30.0),
        all
    ));
    pair!("ggx_half", |p| warp::sample_ggx_half(black_box(p), 0.3), |q| warp::sample_ggx_half_x8(
        black_box(q),
        F8::splat(0.3),
        all
    ));
    pair!("parallelogram", |p| warp::sample_parallelogram(a, ab, ac, black_box(p)), |q| warp::sample_parallelogram_x8(
        a8,
        ab8,
        ac8,
        black_box(q),
        all
    ));
    g.finish();
}

/// (table, technique, options, spp) of the equal-time comparison, and each table's reference.
fn techniques() -> Vec<(&'static str, String, RenderOptions, u32)> {
    let corpus = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/cse168"));
    let direct_scene = corpus.join("hw2/cornell.test");
    let base = RenderOptions { size: Some((64, 64)), threads: 1, ..Default::default() };
    let direct = if direct_scene.is_file() {
        RenderOptions { scene: Some(direct_scene), ..base.clone() }
    } else {
        eprintln!("note: {} not found; equal-time variance on the built-in box (direct) only", corpus.display());
        RenderOptions { integrator: Some(IntegratorKind::Direct), ..base.clone() }
    };
    let direct = RenderOptions {
        pixel_sampler: Some(SamplerKind::GRID_CENTER),
        light_samples: Some(9),
        size: Some((128, 128)),
        ..direct
    };
    let mut v: Vec<_> = SamplerKind::ALL
        .iter()
        .map(|&k| ("direct x9", k.name().to_string(), RenderOptions { light_sampler: Some(k), ..direct.clone() }, 1))
        .collect();
    let brdf = corpus.join("hw4/cornellBRDF.test");
    if brdf.is_file() {
        for (name, s) in [
            ("hemisphere", ImportanceSampling::Hemisphere),
            ("cosine", ImportanceSampling::Cosine),
            ("brdf", ImportanceSampling::Brdf),
        ] {
            v.push((
                "path 8spp",
                name.to_string(),
                RenderOptions { scene: Some(brdf.clone()), importance_sampling: Some(s), ..base.clone() },
                8,
            ));
        }
    }
    v
}

fn equal_time(c: &mut Criterion) {
    strata::accel::set_ftz_daz();
    let pool = strata::render::thread_pool(1).unwrap();
    let techs = techniques();
    let prepared: Vec<_> = techs
        .iter()
        .map(|(_, _, opts, spp)| {
            let (scene, integ) = strata::session::prepare(opts).unwrap();
            (scene, integ.resampled(*spp))
        })
        .collect();
    let render = |i: usize| {
        let (scene, integ) = &prepared[i];
        let mut film = Film::new(scene.desc.width, scene.desc.height);
        strata::render::render(scene, integ, &mut film, 0..integ.spp, &pool)
    };
    let mut g = c.benchmark_group("equal_time");
    g.sample_size(10).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    for (i, (table, name, _, _)) in techs.iter().enumerate() {
        g.bench_function(format!("{}/{name}", table.replace(' ', "_")), |b| b.iter(|| render(i)));
    }
    g.finish();
    // Seconds: median of 15 renders per technique, interleaved so all see the same machine load.
    let mut times = vec![Vec::new(); techs.len()];
    for _ in 0..15 {
        for (i, t) in times.iter_mut().enumerate() {
            let start = Instant::now();
            black_box(render(i));
            t.push(start.elapsed().as_secs_f64());
        }
    }
    let secs: Vec<f64> = times
        .iter_mut()
        .map(|t| {
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        })
        .collect();
    // Variance and MSE from K = 8 runs against a reference.
    println!("\ntable       technique      seconds     variance   var x s     MSE        MSE x s    (var x s) / first");
    let mut first: Option<(&str, f64)> = None;
    let mut reference: Option<(&str, strata::lab::experiments::Reference)> = None;
    for ((table, name, opts, spp), &secs) in techs.iter().zip(&secs) {
        if reference.as_ref().map(|r| r.0) != Some(*table) {
            let r = if *spp == 1 {
                let o = RenderOptions {
                    light_sampler: Some(SamplerKind::STRATIFIED),
                    light_samples: Some(1024),
                    threads: 0,
                    ..opts.clone()
                };
                strata::lab::experiments::reference_two_halves(&o)
            } else {
                let o = RenderOptions {
                    importance_sampling: Some(ImportanceSampling::Brdf),
                    spp: Some(512),
                    threads: 0,
                    ..opts.clone()
                };
                strata::lab::experiments::reference_spp(&o)
            };
            reference = Some((table, r.unwrap()));
        }
        let r = &reference.as_ref().unwrap().1;
        let (imgs, _) = strata::lab::experiments::runs(opts, *spp, 8).unwrap();
        let st = strata::lab::experiments::run_stats(&imgs, r).unwrap();
        let vs = st.variance * secs;
        if first.map(|f| f.0) != Some(*table) {
            first = Some((table, vs));
        }
        let ratio = vs / first.unwrap().1;
        println!(
            "{table:11} {name:12} {secs:9.4}   {:10.3e} {vs:10.3e}  {:10.3e} {:10.3e}  {ratio:8.3}",
            st.variance,
            st.mse,
            st.mse * secs
        );
    }
}

criterion_group!(benches, samplers, warps, equal_time);
criterion_main!(benches);

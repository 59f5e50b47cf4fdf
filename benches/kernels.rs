//! Feature-specialized kernels against the general kernel on the same scene, same seeds (the
//! images are bit-identical, see tests/it/kernels.rs): a diffuse-only Cornell box path traced with
//! NEE (`scenes/cornell_diffuse_path.test`, every lobe compiled out) and a Phong scene (hw4
//! cornellBRDF from ../shared/cse168, BRDF importance sampling; the built-in box path traced when
//! the corpus is absent). One thread, whole renders. After criterion, a table of the two kernels'
//! times measured interleaved in one run (median of 7 each, thread CPU seconds) and their ratio.

use criterion::{criterion_group, criterion_main, Criterion};
use std::path::PathBuf;
use strata::film::Film;
use strata::scene::desc::IntegratorKind;
use strata::session::RenderOptions;

fn scenes() -> Vec<(&'static str, RenderOptions)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let diffuse = RenderOptions {
        scene: Some(root.join("scenes/cornell_diffuse_path.test")),
        size: Some((128, 128)),
        spp: Some(4),
        ..Default::default()
    };
    let brdf = root.join("../shared/cse168/hw4/cornellBRDF.test");
    let phong = if brdf.is_file() {
        RenderOptions { scene: Some(brdf), size: Some((128, 128)), spp: Some(4), ..Default::default() }
    } else {
        eprintln!("note: {} not found; the Phong case is the built-in box path traced", brdf.display());
        RenderOptions {
            integrator: Some(IntegratorKind::PathTracer),
            size: Some((128, 128)),
            spp: Some(4),
            ..Default::default()
        }
    };
    vec![("diffuse-cornell", diffuse), ("phong-cornellBRDF", phong)]
}

fn kernels(c: &mut Criterion) {
    strata::accel::set_ftz_daz();
    let pool = strata::render::thread_pool(1).unwrap();
    let mut table = Vec::new();
    for (name, opts) in scenes() {
        let (scene, spec) = strata::session::prepare(&opts).unwrap();
        let (_, gen) = strata::session::prepare(&RenderOptions { general_kernel: true, ..opts.clone() }).unwrap();
        let run = |it: &strata::integrator::Integrator| {
            let mut film = Film::new(scene.desc.width, scene.desc.height);
            strata::render::render(&scene, it, &mut film, 0..it.spp, &pool)
        };
        let mut g = c.benchmark_group(name);
        g.sample_size(10)
            .warm_up_time(std::time::Duration::from_millis(300))
            .measurement_time(std::time::Duration::from_secs(3));
        g.bench_function("specialized", |b| b.iter(|| run(&spec)));
        g.bench_function("general", |b| b.iter(|| run(&gen)));
        g.finish();
        // Interleaved timing in one run, so both kernels see the same machine load; CPU seconds of
        // the pool's one worker (nested `install` runs inline there), so other processes on a
        // shared machine are not charged.
        let cpu = |it: &strata::integrator::Integrator| {
            pool.install(|| {
                strata::measure::thread_seconds(|| {
                    std::hint::black_box(run(it));
                })
            })
        };
        let (mut ts, mut tg) = (Vec::new(), Vec::new());
        for _ in 0..7 {
            ts.push(cpu(&spec));
            tg.push(cpu(&gen));
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        table.push((name, spec.kernel.name(scene.desc.integrator), median(&mut ts), median(&mut tg)));
    }
    println!("\nscene               kernel                      specialized s   general s   general/specialized");
    for (name, k, s, g) in table {
        println!("{name:19} {k:27} {s:12.4} {g:11.4}   {:6.3}x", g / s);
    }
}

criterion_group!(benches, kernels);
criterion_main!(benches);

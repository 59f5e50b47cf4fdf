//! Rays per second of the whole renderer next to Embree's raw rate on the very same packets.
//!
//! For each scene: `render` times a full single-threaded render (camera + shadow rays, all shading);
//! `embree_camera` and `embree_shadow` replay the packets that render traced, through Embree alone.
//! Criterion's "thrpt" lines are rays per second. A summary table (one measured run) follows.
//! Scenes: the built-in Cornell box, `scenes/cornell_diffuse_path.test` (diffuse, path traced with
//! NEE); hw2 cornell, direct3x3, dragon (direct lighting) and hw3
//! cornellNEE, hw4 cornellMIS, dragon (path tracing) from ../shared/cse168
//! (skipped with a note when the corpus is absent); and `torus-1m`, the procedural mesh of
//! `strata gen-mesh` (1,000,006 triangles, emissive patch; generated and written as OBJ at bench
//! start, then loaded through tobj as a whole-scene OBJ: path tracer, NEE with MIS).

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use std::path::PathBuf;
use strata::film::Film;
use strata::measure;
use strata::session::RenderOptions;

fn scenes() -> Vec<(String, RenderOptions)> {
    let own = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/cornell_diffuse_path.test"));
    let mut v = vec![
        ("builtin-cornell".to_string(), RenderOptions { size: Some((256, 256)), spp: Some(1), ..Default::default() }),
        // The path tracer's target scene: diffuse Cornell box with NEE.
        (
            "cornell-diffuse-path".to_string(),
            RenderOptions { scene: Some(own), size: Some((256, 256)), spp: Some(4), ..Default::default() },
        ),
    ];
    // The million-triangle mesh, generated here (never committed).
    let mesh_path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("torus1m.obj");
    let mesh = strata::scene::obj::procedural_mesh(1_000_000);
    strata::scene::obj::write_obj(&mesh_path, &mesh).expect("write the procedural mesh");
    v.push((
        "torus-1m".to_string(),
        RenderOptions { scene: Some(mesh_path), size: Some((320, 240)), spp: Some(2), ..Default::default() },
    ));
    let corpus = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/cse168"));
    if corpus.is_dir() {
        for name in ["hw2/cornell", "hw2/direct3x3", "hw2/dragon", "hw3/cornellNEE", "hw4/cornellMIS", "hw4/dragon"] {
            let spp = if name.starts_with("hw2") { 1 } else { 4 };
            let o = RenderOptions {
                scene: Some(corpus.join(format!("{name}.test"))),
                size: Some((320, 240)),
                spp: Some(spp),
                ..Default::default()
            };
            v.push((name.replace('/', "-"), o));
        }
    } else {
        eprintln!("note: {} not found; benchmarking the built-in scene only", corpus.display());
    }
    v
}

fn throughput(c: &mut Criterion) {
    strata::accel::set_ftz_daz();
    let pool = strata::render::thread_pool(1).unwrap();
    let mut table = Vec::new();
    for (name, opts) in scenes() {
        let (scene, integ) = strata::session::prepare(&opts).unwrap();
        let log = measure::log_rays(&scene, &integ, integ.spp);
        let lanes = |m: &strata::simd::Mask8| u64::from(m.to_bitmask().count_ones());
        let cam: u64 = log.camera.iter().map(|(_, m)| lanes(m)).sum();
        let sh: u64 = log.shadow.iter().map(|(_, m)| lanes(m)).sum();
        let bo: u64 = log.bounce.iter().map(|(_, m)| lanes(m)).sum();
        let mut g = c.benchmark_group(name.clone());
        g.sample_size(10)
            .warm_up_time(std::time::Duration::from_millis(500))
            .measurement_time(std::time::Duration::from_secs(2));
        g.throughput(Throughput::Elements(cam + sh + bo));
        g.bench_function("render", |b| {
            b.iter(|| {
                let mut film = Film::new(scene.desc.width, scene.desc.height);
                strata::render::render(&scene, &integ, &mut film, 0..integ.spp, &pool)
            })
        });
        g.throughput(Throughput::Elements(cam));
        g.bench_function("embree_camera", |b| {
            b.iter_batched(|| log.camera.clone(), |mut p| measure::replay_camera(&scene, &mut p), BatchSize::LargeInput)
        });
        if bo > 0 {
            g.throughput(Throughput::Elements(bo));
            g.bench_function("embree_bounce", |b| {
                b.iter_batched(
                    || log.bounce.clone(),
                    |mut p| measure::replay_bounce(&scene, &mut p),
                    BatchSize::LargeInput,
                )
            });
        }
        g.throughput(Throughput::Elements(sh));
        g.bench_function("embree_shadow", |b| {
            b.iter_batched(|| log.shadow.clone(), |mut p| measure::replay_shadow(&scene, &mut p), BatchSize::LargeInput)
        });
        g.finish();
        table.push((name, measure::ray_rates(&scene, &integ, integ.spp)));
    }
    println!("\nscene              renderer Mrays/s   Embree raw (mixed / camera / bounce / shadow)   renderer/raw");
    for (name, r) in table {
        println!(
            "{name:18} {:10.2}        {:8.2} / {:8.2} / {:8.2} / {:8.2}          {:5.1} %",
            r.renderer_mrays,
            r.raw_mixed_mrays,
            r.raw_camera_mrays,
            r.raw_bounce_mrays,
            r.raw_shadow_mrays,
            100.0 * r.ratio
        );
    }
}

criterion_group!(benches, throughput);
criterion_main!(benches);

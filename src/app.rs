//! The `strata render` command as a library function (the binary, tests and benches share it).

use crate::film::{self, Film, Metadata};
use crate::integrator::kernel::{features_json, Kernel};
use crate::integrator::Integrator;
use crate::render::{self, RenderStats};
use crate::sampler::SamplerKind;
use crate::scene::build::Scene;
use crate::scene::desc::{IntegratorKind, SceneDesc};
use crate::scene::parse::{self, Limits};
use serde_json::json;
use std::path::{Path, PathBuf};

/// The built-in default scene (a Cornell box written for strata).
pub const DEFAULT_SCENE: &str = include_str!("../scenes/cornell.test");

/// Options of `strata render`.
#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    /// scene file; None renders the built-in Cornell box
    pub scene: Option<PathBuf>,
    /// samples per pixel (default: the scene's `spp`)
    pub spp: Option<u32>,
    /// image size override, keeping the camera
    pub size: Option<(u32, u32)>,
    /// base seed
    pub seed: u64,
    /// worker threads (0 = all cores)
    pub threads: usize,
    /// light sample layout (default: the scene's `lightstratify`)
    pub light_sampler: Option<SamplerKind>,
    /// light samples per light (default: the scene's `lightsamples`)
    pub light_samples: Option<u32>,
    /// pixel sample layout (default stratified)
    pub pixel_sampler: Option<SamplerKind>,
    /// output stem: writes OUT.exr and OUT.png (default: the scene's `output` name)
    pub out: Option<PathBuf>,
    /// JSON statistics file
    pub stats: Option<PathBuf>,
    /// integrator override
    pub integrator: Option<IntegratorKind>,
    /// print progress (spp done, Mrays/s, ETA) on stderr while rendering
    pub progress: bool,
    /// run the general kernel instead of the one specialized for the scene's features
    pub general_kernel: bool,
    /// camera override (`--camera`), for `.obj` and `.test` scenes alike
    pub camera: Option<crate::scene::desc::CameraDesc>,
    /// path tracer: clamp each pixel sample's largest channel to this value (biased; None = off)
    pub clamp: Option<f32>,
}

/// Everything a render produced.
pub struct RenderOutput {
    /// the scene as built
    pub scene: Scene,
    /// the integrator settings used
    pub integrator: Integrator,
    /// accumulated samples
    pub film: Film,
    /// timing and counters
    pub stats: RenderStats,
    /// the output stem written to, if any
    pub out: Option<PathBuf>,
}

/// Parses the scene named in `opts` (or the built-in one) and applies the size override.
pub fn load_scene(opts: &RenderOptions) -> Result<SceneDesc, String> {
    let limits = Limits::default();
    let mut desc = match &opts.scene {
        Some(p) if is_obj(p) => crate::scene::obj::scene_from_obj(p, &limits).map_err(|e| e.to_string())?,
        Some(p) => parse::parse_file(p, &limits).map_err(|e| e.to_string())?,
        None => parse::parse_str(DEFAULT_SCENE, Path::new("<built-in cornell>"), &limits).map_err(|e| e.to_string())?,
    };
    if let Some((w, h)) = opts.size {
        if w == 0 || h == 0 || u64::from(w) * u64::from(h) > limits.max_pixels || w > limits.max_side || h > limits.max_side {
            return Err(format!("--size {w}x{h} is outside 1..={} per side and {} pixels", limits.max_side, limits.max_pixels));
        }
        desc.width = w;
        desc.height = h;
    }
    if let Some(k) = opts.integrator {
        desc.integrator = k;
    }
    if let Some(c) = opts.camera {
        desc.camera = Some(c);
    }
    Ok(desc)
}

/// A scene path naming a Wavefront OBJ (extension `.obj`, any case) rather than a `.test` file.
pub fn is_obj(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// `--camera "ex ey ez cx cy cz ux uy uz fovy"` (the format's `camera` arguments), checked as the
/// `.test` parser checks them.
pub fn parse_camera(s: &str) -> Result<crate::scene::desc::CameraDesc, String> {
    let text = format!("camera {}", s.replace(',', " "));
    parse::parse_str(&text, Path::new("--camera"), &Limits::default())
        .map_err(|e| e.message)?
        .camera
        .ok_or_else(|| "--camera expects 10 numbers".to_string())
}

/// Integrator name as the format spells it.
pub fn integrator_name(k: IntegratorKind) -> &'static str {
    match k {
        IntegratorKind::RayTracer => "raytracer",
        IntegratorKind::AnalyticDirect => "analyticdirect",
        IntegratorKind::Direct => "direct",
        IntegratorKind::PathTracer => "pathtracer",
    }
}

/// Parses an integrator name.
pub fn parse_integrator(s: &str) -> Option<IntegratorKind> {
    Some(match s {
        "raytracer" => IntegratorKind::RayTracer,
        "analyticdirect" => IntegratorKind::AnalyticDirect,
        "direct" => IntegratorKind::Direct,
        "pathtracer" => IntegratorKind::PathTracer,
        _ => return None,
    })
}

/// Parses, checks and builds the scene and the integrator of `opts`.
pub fn prepare(opts: &RenderOptions) -> Result<(Scene, Integrator), String> {
    let desc = load_scene(opts)?;
    // Every integrator of the format is implemented (raytracer, analyticdirect, direct,
    // pathtracer); a new kind must be handled here and in `Integrator::radiance_tile`.
    match desc.integrator {
        IntegratorKind::RayTracer | IntegratorKind::AnalyticDirect | IntegratorKind::Direct | IntegratorKind::PathTracer => {}
    }
    let spp = opts.spp.unwrap_or(desc.spp).max(1);
    let scene = Scene::build(desc).map_err(|e| e.to_string())?;
    let mut integrator = Integrator::new(&scene, spp, opts.seed, opts.light_sampler, opts.light_samples, opts.pixel_sampler);
    if opts.general_kernel {
        integrator.kernel = Kernel::GENERAL;
    }
    integrator.clamp = opts.clamp;
    Ok((scene, integrator))
}

/// Renders without writing anything: scene build, integrator set-up, all samples.
pub fn render_to_film(opts: &RenderOptions) -> Result<RenderOutput, String> {
    let (scene, integrator) = prepare(opts)?;
    let spp = integrator.spp;
    let pool = render::thread_pool(opts.threads).map_err(|e| e.to_string())?;
    let mut film = Film::new(scene.desc.width, scene.desc.height);
    let stats = render_passes(&scene, &integrator, &mut film, 0..spp, &pool, opts.progress);
    Ok(RenderOutput { scene, integrator, film, stats, out: None })
}

/// Renders `samples` in passes (about 1% of the samples each, at least one), so that progress can
/// be shown; the image is bit-identical to one pass (running sums continue across passes).
pub fn render_passes(
    scene: &Scene,
    integ: &Integrator,
    film: &mut Film,
    samples: std::ops::Range<u32>,
    pool: &rayon::ThreadPool,
    progress: bool,
) -> RenderStats {
    let total = samples.len() as u32;
    let pass = (total / 100).max(render::SAMPLE_BATCH).max(1);
    let mut stats = RenderStats { threads: pool.current_num_threads(), ..Default::default() };
    let is_tty = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let mut last_line = std::time::Instant::now();
    let mut s = samples.start;
    while s < samples.end {
        let e = samples.end.min(s + pass);
        let st = render::render(scene, integ, film, s..e, pool);
        stats.seconds += st.seconds;
        stats.counters.merge(&st.counters);
        s = e;
        if progress {
            let done = s - samples.start;
            let eta = stats.seconds / f64::from(done) * f64::from(total - done);
            let line = format!("{done}/{total} spp, {:.2} Mrays/s, ETA {eta:.1} s", stats.mrays_per_sec());
            if is_tty {
                let bar = (40 * done / total.max(1)) as usize;
                eprint!("\r[{}{}] {line}   ", "#".repeat(bar), ".".repeat(40 - bar));
            } else if last_line.elapsed().as_secs_f64() > 5.0 || done == total {
                eprintln!("strata: {line}");
                last_line = std::time::Instant::now();
            }
        }
    }
    if progress && is_tty {
        eprintln!();
    }
    stats
}

/// Output stem: `-o OUT`, else the scene's `output` file name without extension (directories
/// stripped: a scene file never chooses where we write), else "strata".
pub fn output_stem(opts: &RenderOptions, desc: &SceneDesc) -> PathBuf {
    if let Some(o) = &opts.out {
        let s = o.to_string_lossy();
        for ext in [".exr", ".png"] {
            if let Some(stripped) = s.strip_suffix(ext) {
                return PathBuf::from(stripped);
            }
        }
        return o.clone();
    }
    desc.output
        .as_deref()
        .and_then(|n| Path::new(n).file_stem())
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("strata"))
}

fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// Metadata written into the EXR header.
pub fn metadata(out: &RenderOutput) -> Metadata {
    let d = &out.scene.desc;
    vec![
        ("strata.version".into(), env!("CARGO_PKG_VERSION").into()),
        ("strata.scene".into(), d.source.display().to_string()),
        ("strata.integrator".into(), integrator_name(d.integrator).into()),
        ("strata.spp".into(), out.integrator.spp.to_string()),
        ("strata.seed".into(), out.integrator.seed.to_string()),
        ("strata.pixel_sampler".into(), out.integrator.pixel_set.kind().name().into()),
        ("strata.light_sampler".into(), out.integrator.light_set.kind().name().into()),
        ("strata.light_samples".into(), out.integrator.light_set.n().to_string()),
        ("strata.render_seconds".into(), format!("{:.6}", out.stats.seconds)),
        ("strata.threads".into(), out.stats.threads.to_string()),
    ]
}

/// The `--stats` JSON.
pub fn stats_json(out: &RenderOutput) -> serde_json::Value {
    let d = &out.scene.desc;
    let c = &out.stats.counters;
    json!({
        "scene": d.source.display().to_string(),
        "integrator": integrator_name(d.integrator),
        "seconds": out.stats.seconds,
        "spp": out.integrator.spp,
        "width": d.width,
        "height": d.height,
        "seed": out.integrator.seed,
        "threads": out.stats.threads,
        "pixel_sampler": out.integrator.pixel_set.kind().name(),
        "light_sampler": out.integrator.light_set.kind().name(),
        "light_samples": out.integrator.light_set.n(),
        "rays": { "camera": c.camera, "shadow": c.shadow, "bounce": c.bounce, "total": c.total_rays() },
        "mrays_per_sec": out.stats.mrays_per_sec(),
        "packets": { "camera": c.camera_packets, "bounce": c.bounce_packets, "shadow": c.shadow_packets },
        "occupancy": c.occupancy(),
        "occupancy_by_kind": { "bounce": c.bounce_occupancy(), "shadow": c.shadow_occupancy() },
        "mean_path_length": c.mean_path_length(),
        "max_depth": out.integrator.max_depth,
        "nee": format!("{:?}", out.integrator.nee).to_lowercase(),
        "russian_roulette": out.integrator.russian_roulette,
        "importance_sampling": format!("{:?}", out.integrator.strategy).to_lowercase(),
        "nonfinite_samples": c.nonfinite,
        "clamp": out.integrator.clamp,
        "biased": out.integrator.clamp.is_some(),
        "features": features_json(&out.scene, d.integrator, out.integrator.nee, out.integrator.russian_roulette, out.integrator.strategy),
        "kernel": out.integrator.kernel.name(d.integrator),
        "version": env!("CARGO_PKG_VERSION"),
    })
}

/// One-line summary printed after a render.
pub fn summary(out: &RenderOutput) -> String {
    let d = &out.scene.desc;
    let c = &out.stats.counters;
    let it = &out.integrator;
    // The settings that matter for this integrator only.
    let technique = match d.integrator {
        IntegratorKind::Direct => format!(" (light {} x{})", it.light_set.kind().name(), it.light_set.n()),
        IntegratorKind::PathTracer => format!(
            " (nee {}, {} sampling, rr {}, maxdepth {})",
            format!("{:?}", it.nee).to_lowercase(),
            format!("{:?}", it.strategy).to_lowercase(),
            if it.russian_roulette { "on" } else { "off" },
            it.max_depth
        ) + &it.clamp.map(|m| format!(", CLAMPED at {m}: biased")).unwrap_or_default(),
        _ => String::new(),
    };
    format!(
        "{} {}x{} {} spp {}{}, kernel {}: {:.3} s, {:.2} Mrays/s (camera {}, bounce {}, shadow {}), occupancy {:.1}%, {} threads, {} non-finite{}",
        d.source.display(),
        d.width,
        d.height,
        it.spp,
        integrator_name(d.integrator),
        technique,
        it.kernel.name(d.integrator),
        out.stats.seconds,
        out.stats.mrays_per_sec(),
        c.camera,
        c.bounce,
        c.shadow,
        100.0 * c.occupancy(),
        out.stats.threads,
        c.nonfinite,
        out.out.as_ref().map(|p| format!(" -> {}.exr/.png", p.display())).unwrap_or_default()
    )
}

/// `strata render`: render, write OUT.exr (with a variance layer) and OUT.png, and the stats JSON.
pub fn run_render(opts: &RenderOptions) -> Result<RenderOutput, String> {
    let mut out = render_to_film(opts)?;
    let stem = output_stem(opts, &out.scene.desc);
    let (w, h) = (out.film.width, out.film.height);
    let mean = out.film.mean();
    let var = out.film.variance_of_mean();
    let exr = with_ext(&stem, "exr");
    film::write_exr(&exr, w, h, &mean, Some(&var), &metadata(&out)).map_err(|e| format!("{}: {e}", exr.display()))?;
    let png = with_ext(&stem, "png");
    film::write_png(&png, w, h, &mean, out.scene.desc.gamma).map_err(|e| format!("{}: {e}", png.display()))?;
    out.out = Some(stem);
    if let Some(p) = &opts.stats {
        let text = serde_json::to_string_pretty(&stats_json(&out)).map_err(|e| e.to_string())?;
        film::write_atomic(p, text.as_bytes()).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    Ok(out)
}

/// `strata rays`: renderer rays/s next to Embree's raw rate on the same packets.
pub fn run_rays(opts: &RenderOptions) -> Result<(crate::measure::RayRates, String), String> {
    let (scene, integrator) = prepare(opts)?;
    let rates = crate::measure::ray_rates(&scene, &integrator, integrator.spp);
    Ok((rates, scene.desc.source.display().to_string()))
}

/// A small table of [`crate::measure::RayRates`].
pub fn rates_table(name: &str, r: &crate::measure::RayRates) -> String {
    format!(
        "{name}: {} camera + {} bounce + {} shadow rays, 1 thread\n  renderer          {:8.2} Mrays/s\n  Embree raw mixed  {:8.2} Mrays/s  (camera {:.2}, bounce {:.2}, shadow {:.2})\n  renderer / raw    {:8.1} %",
        r.camera_rays,
        r.bounce_rays,
        r.shadow_rays,
        r.renderer_mrays,
        r.raw_mixed_mrays,
        r.raw_camera_mrays,
        r.raw_bounce_mrays,
        r.raw_shadow_mrays,
        100.0 * r.ratio
    )
}

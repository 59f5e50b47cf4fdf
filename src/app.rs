//! The `strata render` command as a library function (the binary, tests and benches share it).

use crate::checkpoint::{self, Header};
use crate::film::{self, Film, Metadata};
use crate::integrator::kernel::{features_json, Kernel};
use crate::integrator::Integrator;
use crate::render::{self, RenderStats};
use crate::sampler::SamplerKind;
use crate::scene::build::Scene;
use crate::scene::desc::{IntegratorKind, SceneDesc};
use crate::scene::parse::{self, Limits};
use serde_json::json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

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
    /// path tracer: clamp each pixel sample's largest channel to this value (biased; None = off)
    pub clamp: Option<f32>,
    /// checkpoint file: the accumulated state is written there every `checkpoint_every` seconds
    /// and at the end (default with `--samples` or on interruption: OUT.ckpt)
    pub checkpoint: Option<PathBuf>,
    /// seconds between checkpoints (default [`DEFAULT_CHECKPOINT_EVERY`]; 0 = after every pass)
    pub checkpoint_every: Option<f64>,
    /// continue the render held in this checkpoint (same scene and options, else refused)
    pub resume: Option<PathBuf>,
    /// render only sample indices A..B of the spp (a shard for `strata merge`)
    pub samples: Option<(u32, u32)>,
    /// render whole passes until this many seconds are spent (independent pixel and path layouts;
    /// `--spp`, if given, caps the samples)
    pub time_budget: Option<f64>,
    /// set (e.g. by SIGINT/SIGTERM) to stop after the current pass, checkpoint and write the image
    pub stop: Option<Arc<AtomicBool>>,
    /// camera override (`--camera`), for `.obj` and `.test` scenes alike
    pub camera: Option<crate::scene::desc::CameraDesc>,
    /// path tracer: direction sampling override (default: the scene's `importancesampling`)
    pub importance_sampling: Option<crate::scene::desc::ImportanceSampling>,
    /// path tracer: next event estimation override (default: the scene's `nexteventestimation`)
    pub nee: Option<crate::scene::desc::Nee>,
    /// path tracer: Russian roulette override (default: the scene's `russianroulette`)
    pub russian_roulette: Option<bool>,
    /// maximum depth override, -1 = unbounded (default: the scene's `maxdepth`)
    pub max_depth: Option<i32>,
    /// resource caps (`--limit NAME=VALUE`), applied to the scene file and to the overrides
    pub limits: Limits,
    /// PNG quantizer (`--quantize`; default [`default_quantize`]: the course's truncation for `.test`)
    pub quantize: Option<film::Quantize>,
    /// where pixel sample 0 goes (`--first-sample`; default [`default_first_sample`])
    pub first_sample: Option<crate::integrator::FirstSample>,
}

/// The PNG quantizer of `opts`: `--quantize`, else truncation like the CSE168 course's writer for
/// `.test` scenes (and the built-in one, a `.test`), rounding for `.obj` scenes (not course scenes).
pub fn default_quantize(opts: &RenderOptions) -> film::Quantize {
    opts.quantize.unwrap_or(match &opts.scene {
        Some(p) if is_obj(p) => film::Quantize::Round,
        _ => film::Quantize::Truncate,
    })
}

/// Where pixel sample 0 goes for `opts`: `--first-sample`, else through the pixel centre like the
/// CSE168 course code for `.test` scenes (and the built-in one), jittered for `.obj` scenes.
pub fn default_first_sample(opts: &RenderOptions) -> crate::integrator::FirstSample {
    use crate::integrator::FirstSample;
    opts.first_sample.unwrap_or(match &opts.scene {
        Some(p) if is_obj(p) => FirstSample::Jittered,
        _ => FirstSample::Centre,
    })
}

/// Default seconds between two checkpoints.
pub const DEFAULT_CHECKPOINT_EVERY: f64 = 300.0;
/// Aimed wall-clock seconds of one pass (passes only schedule the work: the image is the same
/// whatever their sizes; shorter passes make checkpoints and Ctrl-C more timely).
const PASS_SECONDS: f64 = 2.0;

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
    /// identity and totals over every session of this render (as in its checkpoint)
    pub header: Header,
    /// the checkpoint written last, if any
    pub checkpoint: Option<PathBuf>,
    /// stopped by the `stop` flag (a signal) before the sample range was done
    pub interrupted: bool,
}

/// Parses the scene named in `opts` (or the built-in one) and applies the size override.
pub fn load_scene(opts: &RenderOptions) -> Result<SceneDesc, String> {
    let limits = opts.limits;
    let mut desc = match &opts.scene {
        Some(p) if is_obj(p) => crate::scene::obj::scene_from_obj(p, &limits).map_err(|e| e.to_string())?,
        Some(p) => parse::parse_file(p, &limits).map_err(|e| e.to_string())?,
        None => parse::parse_str(DEFAULT_SCENE, Path::new("<built-in cornell>"), &limits).map_err(|e| e.to_string())?,
    };
    if let Some((w, h)) = opts.size {
        if w == 0 || h == 0 {
            return Err(format!("--size {w}x{h}: width and height must be positive"));
        }
        if w.max(h) > limits.max_side {
            let (max, hint) = (limits.max_side, parse::limit_hint("max_side"));
            return Err(format!("--size {w}x{h} exceeds the limit of {max} pixels per side ({hint})"));
        }
        if u64::from(w) * u64::from(h) > limits.max_pixels {
            let (max, hint) = (limits.max_pixels, parse::limit_hint("max_pixels"));
            return Err(format!("--size {w}x{h} exceeds the limit of {max} pixels ({hint})"));
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
    if let Some(s) = opts.importance_sampling {
        desc.importance_sampling = s;
    }
    if let Some(n) = opts.nee {
        desc.nee = n;
    }
    if let Some(r) = opts.russian_roulette {
        desc.russian_roulette = r;
    }
    if let Some(d) = opts.max_depth {
        if d < -1 || i64::from(d) > i64::from(limits.max_depth) {
            let (max, hint) = (limits.max_depth, parse::limit_hint("max_depth"));
            return Err(format!("--max-depth {d} is outside -1..={max} ({hint})"));
        }
        desc.max_depth = d;
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

/// Parses a next-event-estimation mode as the format spells it: off, on or mis.
pub fn parse_nee(s: &str) -> Option<crate::scene::desc::Nee> {
    use crate::scene::desc::Nee;
    Some(match s {
        "off" => Nee::Off,
        "on" => Nee::On,
        "mis" => Nee::Mis,
        _ => return None,
    })
}

/// Parses a direction sampling strategy as the format spells it: hemisphere, cosine or brdf.
pub fn parse_importance_sampling(s: &str) -> Option<crate::scene::desc::ImportanceSampling> {
    use crate::scene::desc::ImportanceSampling as I;
    Some(match s {
        "hemisphere" => I::Hemisphere,
        "cosine" => I::Cosine,
        "brdf" => I::Brdf,
        _ => return None,
    })
}

/// Parses, checks and builds the scene and the integrator of `opts`.
pub fn prepare(opts: &RenderOptions) -> Result<(Scene, Integrator), String> {
    let desc = load_scene(opts)?;
    // Every integrator of the format is implemented (raytracer, analyticdirect, direct,
    // pathtracer); a new kind must be handled here and in `Integrator::radiance_tile`.
    match desc.integrator {
        IntegratorKind::RayTracer
        | IntegratorKind::AnalyticDirect
        | IntegratorKind::Direct
        | IntegratorKind::PathTracer => {}
    }
    let spp = opts.spp.unwrap_or(desc.spp).max(1);
    if spp > opts.limits.max_spp {
        let (max, hint) = (opts.limits.max_spp, parse::limit_hint("max_spp"));
        return Err(format!("--spp {spp} exceeds the limit of {max} ({hint})"));
    }
    if let Some(n) = opts.light_samples.filter(|&n| n > opts.limits.max_light_samples) {
        let (max, hint) = (opts.limits.max_light_samples, parse::limit_hint("max_light_samples"));
        return Err(format!("--light-samples {n} exceeds the limit of {max} ({hint})"));
    }
    let scene = Scene::build(desc).map_err(|e| e.to_string())?;
    let mut integrator =
        Integrator::new(&scene, spp, opts.seed, opts.light_sampler, opts.light_samples, opts.pixel_sampler);
    if opts.general_kernel {
        integrator.kernel = Kernel::GENERAL;
    }
    integrator.clamp = opts.clamp;
    integrator.first_sample = default_first_sample(opts);
    Ok((scene, integrator))
}

/// Hash of the scene's bytes (the file as read, or the built-in scene's text).
pub fn scene_hash(opts: &RenderOptions) -> Result<String, String> {
    Ok(match &opts.scene {
        Some(p) => checkpoint::hash_bytes(
            &std::fs::read(p).map_err(|e| format!("{}: cannot read scene file: {e}", p.display()))?,
        ),
        None => checkpoint::hash_bytes(DEFAULT_SCENE.as_bytes()),
    })
}

/// The identity of a render (scene hash, version, size and every option that affects the image)
/// with empty ranges and totals.
pub fn identity(opts: &RenderOptions, scene: &Scene, it: &Integrator) -> Result<Header, String> {
    let d = &scene.desc;
    let options: BTreeMap<String, serde_json::Value> = [
        ("integrator", json!(integrator_name(d.integrator))),
        ("spp", json!(it.spp)),
        ("seed", json!(it.seed)),
        ("pixel_sampler", json!(it.pixel_set.kind().name())),
        ("light_sampler", json!(it.light_set.kind().name())),
        ("light_samples", json!(it.light_set.n())),
        ("layout", json!(if opts.time_budget.is_some() { "time-budget" } else { "spp" })),
        ("gamma", json!(d.gamma)),
        ("clamp", json!(it.clamp)),
        ("first_sample", json!(it.first_sample.name())),
        ("quantize", json!(default_quantize(opts).name())),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    Ok(Header {
        strata_version: env!("CARGO_PKG_VERSION").to_string(),
        scene: d.source.display().to_string(),
        // The file's bytes and the parsed content (which covers included OBJ and MTL files).
        scene_hash: format!("{}-{:016x}", scene_hash(opts)?, d.content_hash()),
        options,
        width: d.width,
        height: d.height,
        target: [0, 0],
        samples: [0, 0],
        blocks: Vec::new(),
        cpu_seconds: 0.0,
        render_seconds: 0.0,
        rays: 0,
        parts: Vec::new(),
    })
}

/// Renders without writing images: scene build, integrator set-up, the sample range in passes
/// (resuming `opts.resume`, writing `opts.checkpoint` periodically and at the end, stopping
/// early on `opts.stop` or when `opts.time_budget` is spent).
pub fn render_to_film(opts: &RenderOptions) -> Result<RenderOutput, String> {
    let (scene, mut integrator) = prepare(opts)?;
    if let Some(b) = opts.time_budget {
        if !(b > 0.0 && b.is_finite()) {
            return Err(format!("--time-budget {b}: expected a positive number of seconds"));
        }
        // The number of samples is not known in advance: layouts that need it become independent.
        integrator = integrator.resampled(None);
    }
    let every = opts.checkpoint_every.unwrap_or(DEFAULT_CHECKPOINT_EVERY);
    if !(every >= 0.0 && every.is_finite()) {
        return Err(format!("--checkpoint-every {every}: expected a number of seconds >= 0"));
    }
    let cap = if opts.time_budget.is_some() { opts.spp.unwrap_or(u32::MAX) } else { integrator.spp };
    let target = match opts.samples {
        Some((a, b)) if a < b && b <= cap => a..b,
        Some((a, b)) => return Err(format!("--samples {a}..{b}: expected A < B <= spp ({cap})")),
        None => 0..cap,
    };
    let mut header = identity(opts, &scene, &integrator)?;
    header.target = [target.start, target.end];
    let mut film = Film::new(scene.desc.width, scene.desc.height);
    if let Some(path) = &opts.resume {
        let (h, f) = checkpoint::read(path)?;
        if let Some(why) = h.mismatch(&header, "this render") {
            return Err(format!("{}: cannot resume: {why}", path.display()));
        }
        let have = f.samples();
        if !have.is_empty() && (have.start != target.start || have.end > target.end) {
            return Err(format!(
                "{}: cannot resume: it holds samples {}..{}, which do not start the requested range {}..{}",
                path.display(),
                have.start,
                have.end,
                target.start,
                target.end
            ));
        }
        (header.cpu_seconds, header.render_seconds, header.rays) = (h.cpu_seconds, h.render_seconds, h.rays);
        film = f;
    }
    let ckpt_path = opts.checkpoint.clone().or_else(|| opts.resume.clone());
    let pool = render::thread_pool(opts.threads).map_err(|e| e.to_string())?;
    let mut progress = Progress::new(opts.progress, &target, film.samples().len() as u32, opts.time_budget);
    let mut stats = RenderStats { threads: pool.current_num_threads(), ..Default::default() };
    let started = Instant::now();
    let mut last_ckpt = Instant::now();
    let mut s = if film.samples().is_empty() { target.start } else { film.samples().end };
    let mut pass = render::SAMPLE_BATCH;
    let mut interrupted = false;
    while s < target.end {
        if opts.stop.as_ref().is_some_and(|f| f.load(Ordering::SeqCst)) {
            interrupted = true;
            break;
        }
        let mut n = pass.min(target.end - s);
        if let Some(b) = opts.time_budget {
            let left = b - started.elapsed().as_secs_f64();
            if left <= 0.0 {
                break;
            }
            // Whole passes that fit in what is left of the budget (at least one sample).
            if let Some(per) = progress.secs_per_spp() {
                n = n.min(((left / per) as u32).max(1));
            }
        }
        let st = render::render(&scene, &integrator, &mut film, s..s + n, &pool);
        s += n;
        stats.seconds += st.seconds;
        stats.cpu_seconds += st.cpu_seconds;
        stats.counters.merge(&st.counters);
        header.cpu_seconds += st.cpu_seconds;
        header.render_seconds += st.seconds;
        header.rays += st.counters.total_rays();
        progress.pass(n, &st, started.elapsed().as_secs_f64());
        // Next pass: about PASS_SECONDS, growing at most 4x, whole wavefront batches when large.
        let per = st.seconds / f64::from(n);
        let want = ((PASS_SECONDS / per.max(1e-9)) as u32).clamp(1, pass.saturating_mul(4));
        pass = if want >= render::SAMPLE_BATCH { want / render::SAMPLE_BATCH * render::SAMPLE_BATCH } else { want };
        if let Some(p) = &ckpt_path {
            if s < target.end && last_ckpt.elapsed().as_secs_f64() >= every {
                checkpoint::write(p, &header, &film)?;
                last_ckpt = Instant::now();
            }
        }
    }
    progress.finish();
    let stem = output_stem(opts, &scene.desc);
    let final_ckpt = match ckpt_path {
        Some(p) => Some(p),
        None if interrupted || opts.samples.is_some() => Some(with_ext(&stem, "ckpt")),
        None => None,
    };
    if let Some(p) = &final_ckpt {
        checkpoint::write(p, &header, &film)?;
    }
    header = checkpoint::header_for(header, &film);
    Ok(RenderOutput { scene, integrator, film, stats, out: None, header, checkpoint: final_ckpt, interrupted })
}

/// Progress on stderr: a bar with spp done, Mrays/s and ETA on a terminal, a plain line every
/// few seconds otherwise, nothing when disabled.
struct Progress {
    on: bool,
    tty: bool,
    total: u64,
    done: u64,
    session: u64,
    budget: Option<f64>,
    seconds: f64,
    rays: u64,
    last_line: Instant,
}

impl Progress {
    fn new(on: bool, target: &std::ops::Range<u32>, done: u32, budget: Option<f64>) -> Self {
        Self {
            on,
            tty: std::io::IsTerminal::is_terminal(&std::io::stderr()),
            total: target.len() as u64,
            done: u64::from(done),
            session: 0,
            budget,
            seconds: 0.0,
            rays: 0,
            last_line: Instant::now(),
        }
    }

    /// Seconds per sample per pixel measured so far in this session.
    fn secs_per_spp(&self) -> Option<f64> {
        (self.session > 0).then(|| self.seconds / self.session as f64)
    }

    fn pass(&mut self, n: u32, st: &RenderStats, elapsed: f64) {
        self.done += u64::from(n);
        self.session += u64::from(n);
        self.seconds += st.seconds;
        self.rays += st.counters.total_rays();
        if !self.on {
            return;
        }
        let mrays = self.rays as f64 / self.seconds.max(1e-12) / 1e6;
        let (line, frac) = match self.budget {
            Some(b) => (
                format!("{} spp, {mrays:.2} Mrays/s, {:.1} s of {b} s budget left", self.done, (b - elapsed).max(0.0)),
                (elapsed / b).min(1.0),
            ),
            None => {
                let eta = self.secs_per_spp().unwrap_or(0.0) * (self.total - self.done) as f64;
                (
                    format!("{}/{} spp, {mrays:.2} Mrays/s, ETA {eta:.1} s", self.done, self.total),
                    self.done as f64 / self.total.max(1) as f64,
                )
            }
        };
        if self.tty {
            let bar = (40.0 * frac) as usize;
            eprint!("\r[{}{}] {line}   ", "#".repeat(bar), ".".repeat(40 - bar));
        } else if self.last_line.elapsed().as_secs_f64() > 5.0 || self.done == self.total {
            eprintln!("strata: {line}");
            self.last_line = Instant::now();
        }
    }

    fn finish(&self) {
        if self.on && self.tty {
            eprintln!();
        }
    }
}

/// Output stem: `-o OUT`, else the scene's `output` file name without extension (directories
/// stripped: a scene file never chooses where we write), else "strata".
pub fn output_stem(opts: &RenderOptions, desc: &SceneDesc) -> PathBuf {
    if let Some(o) = &opts.out {
        return stem_of(o);
    }
    desc.output
        .as_deref()
        .and_then(|n| Path::new(n).file_stem())
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("strata"))
}

/// `o` without a trailing `.exr` or `.png`.
fn stem_of(o: &Path) -> PathBuf {
    let s = o.to_string_lossy();
    for ext in [".exr", ".png"] {
        if let Some(stripped) = s.strip_suffix(ext) {
            return PathBuf::from(stripped);
        }
    }
    o.to_path_buf()
}

fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// EXR metadata of a render or merge state: version, scene and its hash, integrator, samplers,
/// seed, spp held, sample range, total render and CPU seconds, rays, and the parts it came from.
pub fn header_metadata(h: &Header) -> Metadata {
    let opt =
        |k: &str| h.options.get(k).map_or(String::new(), |v| v.as_str().map_or_else(|| v.to_string(), str::to_string));
    let mut m: Metadata = vec![
        ("strata.version".into(), h.strata_version.clone()),
        ("strata.scene".into(), h.scene.clone()),
        ("strata.scene_hash".into(), h.scene_hash.clone()),
        ("strata.integrator".into(), opt("integrator")),
        ("strata.spp".into(), (h.samples[1] - h.samples[0]).to_string()),
        ("strata.samples".into(), format!("{}..{}", h.samples[0], h.samples[1])),
        ("strata.seed".into(), opt("seed")),
        ("strata.pixel_sampler".into(), opt("pixel_sampler")),
        ("strata.light_sampler".into(), opt("light_sampler")),
        ("strata.light_samples".into(), opt("light_samples")),
        ("strata.layout".into(), opt("layout")),
        ("strata.first_sample".into(), opt("first_sample")),
        ("strata.quantize".into(), opt("quantize")),
        ("strata.render_seconds".into(), format!("{:.6}", h.render_seconds)),
        ("strata.cpu_seconds".into(), format!("{:.6}", h.cpu_seconds)),
        ("strata.rays".into(), h.rays.to_string()),
    ];
    if !h.parts.is_empty() {
        m.push(("strata.parts".into(), h.parts.join("; ")));
        m.push(("strata.part_count".into(), h.parts.len().to_string()));
    }
    m
}

/// Metadata written into the EXR header of a render ([`header_metadata`] and the thread count).
pub fn metadata(out: &RenderOutput) -> Metadata {
    let mut m = header_metadata(&out.header);
    m.push(("strata.threads".into(), out.stats.threads.to_string()));
    m
}

/// The `--stats` JSON.
pub fn stats_json(out: &RenderOutput) -> serde_json::Value {
    let d = &out.scene.desc;
    let c = &out.stats.counters;
    json!({
        "scene": d.source.display().to_string(),
        "integrator": integrator_name(d.integrator),
        "seconds": out.stats.seconds,
        "spp": out.film.samples().len(),
        "samples": [out.header.samples[0], out.header.samples[1]],
        "cpu_seconds": out.stats.cpu_seconds,
        "total_render_seconds": out.header.render_seconds,
        "total_cpu_seconds": out.header.cpu_seconds,
        "interrupted": out.interrupted,
        "checkpoint": out.checkpoint.as_ref().map(|p| p.display().to_string()),
        "layout": out.header.options.get("layout"),
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
        "first_sample": out.integrator.first_sample.name(),
        "quantize": out.header.options.get("quantize"),
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
        IntegratorKind::PathTracer => {
            format!(
                " (nee {}, {} sampling, rr {}, maxdepth {})",
                format!("{:?}", it.nee).to_lowercase(),
                format!("{:?}", it.strategy).to_lowercase(),
                if it.russian_roulette { "on" } else { "off" },
                it.max_depth
            ) + &it.clamp.map(|m| format!(", CLAMPED at {m}: biased")).unwrap_or_default()
        }
        _ => String::new(),
    };
    format!(
        "{} {}x{} {} spp {}{}, kernel {}: {:.3} s, {:.2} Mrays/s (camera {}, bounce {}, shadow {}), occupancy {:.1}%, {} threads, {} non-finite{}",
        d.source.display(),
        d.width,
        d.height,
        out.film.samples().len(),
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
    film::write_png_quantized(&png, w, h, &mean, out.scene.desc.gamma, default_quantize(opts))
        .map_err(|e| format!("{}: {e}", png.display()))?;
    out.out = Some(stem);
    if let Some(p) = &opts.stats {
        let text = serde_json::to_string_pretty(&stats_json(&out)).map_err(|e| e.to_string())?;
        film::write_atomic(p, text.as_bytes()).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    Ok(out)
}

/// Sets the returned flag on SIGINT or SIGTERM (a render checks it between passes, then writes a
/// checkpoint and the image); a second signal while the flag is set exits at once.
pub fn stop_on_signals() -> Result<Arc<AtomicBool>, String> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(sig, 130, Arc::clone(&flag))
            .map_err(|e| format!("signal handler: {e}"))?;
        signal_hook::flag::register(sig, Arc::clone(&flag)).map_err(|e| format!("signal handler: {e}"))?;
    }
    Ok(flag)
}

/// What `strata merge` produced.
pub struct MergeOutput {
    /// the merged state (identity, totals, parts)
    pub header: Header,
    /// the merged film
    pub film: Film,
    /// output stem written (OUT.exr, OUT.png)
    pub out: PathBuf,
}

/// `strata merge PARTS... -o OUT`: checks that the parts (checkpoint files of finished `--samples`
/// shards) belong to one render (scene hash, version, size, options) and cover its sample range
/// without overlap or gap, merges their dyadic blocks (bit-identical to one render of the whole
/// range) and writes OUT.exr (metadata: total spp, CPU seconds, the parts) and OUT.png.
pub fn run_merge(parts: &[PathBuf], out: &Path) -> Result<MergeOutput, String> {
    if parts.is_empty() {
        return Err("merge: give the part files to merge".into());
    }
    let mut loaded = Vec::new();
    for p in parts {
        let (h, f) = checkpoint::read(p)?;
        if h.samples != h.target {
            return Err(format!(
                "{}: unfinished part: it holds samples {}..{} of its range {}..{} (finish it with --resume)",
                p.display(),
                h.samples[0],
                h.samples[1],
                h.target[0],
                h.target[1]
            ));
        }
        if let Some((p0, h0, _)) = loaded.first() {
            let p0: &PathBuf = p0;
            if let Some(why) = h.mismatch(h0, &p0.display().to_string()) {
                return Err(format!("{}: does not belong with {}: {why}", p.display(), p0.display()));
            }
        }
        loaded.push((p.clone(), h, f));
    }
    loaded.sort_by_key(|(_, h, _)| h.samples);
    let want_end = match loaded[0].1.options.get("layout").and_then(|v| v.as_str()) {
        Some("spp") => loaded[0].1.options.get("spp").and_then(|v| v.as_u64()),
        _ => None,
    };
    let name = |p: &PathBuf, h: &Header| format!("{} ({}..{})", p.display(), h.samples[0], h.samples[1]);
    if loaded[0].1.samples[0] != 0 {
        return Err(format!("samples 0..{} are missing (no part starts at 0)", loaded[0].1.samples[0]));
    }
    for w in loaded.windows(2) {
        let ((pa, ha, _), (pb, hb, _)) = (&w[0], &w[1]);
        if hb.samples[0] < ha.samples[1] {
            return Err(format!("{} and {} overlap", name(pa, ha), name(pb, hb)));
        }
        if hb.samples[0] > ha.samples[1] {
            return Err(format!(
                "samples {}..{} are missing (between {} and {})",
                ha.samples[1],
                hb.samples[0],
                name(pa, ha),
                name(pb, hb)
            ));
        }
    }
    let last = loaded.last().map(|(_, h, _)| h.samples[1]).unwrap_or(0);
    if let Some(end) = want_end {
        if u64::from(last) != end {
            return Err(format!("samples {last}..{end} of the {end} spp are missing (the last part ends at {last})"));
        }
    }
    let mut header = loaded[0].1.clone();
    let (w, h) = (header.width, header.height);
    let mut film = Film::new(w, h);
    (header.cpu_seconds, header.render_seconds, header.rays, header.parts) = (0.0, 0.0, 0, Vec::new());
    for (p, ph, f) in &loaded {
        film.merge(f).map_err(|e| format!("{}: {e}", p.display()))?;
        header.cpu_seconds += ph.cpu_seconds;
        header.render_seconds += ph.render_seconds;
        header.rays += ph.rays;
        if ph.parts.is_empty() {
            header.parts.push(name(p, ph));
        } else {
            header.parts.extend(ph.parts.iter().cloned());
        }
    }
    header.target = [0, last];
    header = checkpoint::header_for(header, &film);
    let stem = stem_of(out);
    let (mean, var) = (film.mean(), film.variance_of_mean());
    let exr = with_ext(&stem, "exr");
    film::write_exr(&exr, w, h, &mean, Some(&var), &header_metadata(&header))
        .map_err(|e| format!("{}: {e}", exr.display()))?;
    let gamma = header.options.get("gamma").and_then(|v| v.as_f64()).unwrap_or(1.0) as f32;
    let png = with_ext(&stem, "png");
    // Parts written before `quantize` was recorded were rounded.
    let q = header.options.get("quantize").and_then(|v| v.as_str()).and_then(film::Quantize::parse);
    film::write_png_quantized(&png, w, h, &mean, gamma, q.unwrap_or(film::Quantize::Round))
        .map_err(|e| format!("{}: {e}", png.display()))?;
    Ok(MergeOutput { header, film, out: stem })
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

//! `strata` command line.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use strata::sampler::SamplerKind;
use strata::scene::desc::{ImportanceSampling, IntegratorKind, Nee};
use strata::session::{self, RenderOptions};

#[derive(Parser)]
#[command(name = "strata", version, about = "SIMD packet ray tracer on Embree 4 for sampling experiments")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Render a CSE168 .test scene (or the built-in Cornell box) to OUT.exr and OUT.png.
    Render(RenderArgs),
    /// Render a high-spp reference: linear EXR with a per-pixel variance layer (and a PNG), with
    /// progress and ETA. Same flags as `render`; give --spp and -o.
    Reference(RenderArgs),
    /// Compare sampling techniques against a reference: K independent runs per variant at equal spp
    /// (--spp-ladder) or equal time (--budget); writes rows.csv, rows.json, table.md, error.svg.
    /// Seconds are the worker threads' CPU seconds; the sampler's ns/sample and share of the render
    /// come from the phase profiler, which every run has on.
    Compare {
        /// Scene file (.test); omitted: the built-in Cornell box.
        scene: Option<PathBuf>,
        /// Reference EXR (from `strata reference`), same size as the renders.
        #[arg(long)]
        reference: PathBuf,
        /// NAME=OPTIONS, OPTIONS being render flags, e.g. strat=--light-sampler=stratified
        /// (several flags separated by spaces). Repeat for each variant.
        #[arg(long = "variant", required = true)]
        variants: Vec<String>,
        /// Independent runs per variant (seeds differ), at least 2.
        #[arg(long, default_value_t = 4)]
        runs: usize,
        /// Equal time: CPU seconds of the worker threads per run (passes of one sample until spent).
        #[arg(long, conflicts_with = "spp_ladder")]
        budget: Option<f64>,
        /// Equal spp: comma-separated spp values, e.g. 1,2,4,8.
        #[arg(long, value_delimiter = ',')]
        spp_ladder: Option<Vec<u32>>,
        /// Image size WxH for every variant (must match the reference).
        #[arg(long, value_parser = parse_size)]
        size: Option<(u32, u32)>,
        /// Worker threads (0 = all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Output folder.
        #[arg(long, default_value = "compare")]
        out: PathBuf,
        /// Write each variant's phase profile over all its runs (the keys of `strata profile
        /// --json`, plus `variant`) as a JSON list to this file.
        #[arg(long, value_name = "FILE")]
        profile: Option<PathBuf>,
        /// Write the variants' phase profiles as an SVG stacked bar chart (one bar per variant).
        #[arg(long, value_name = "FILE")]
        profile_svg: Option<PathBuf>,
    },
    /// Merge the part files of `render --samples A..B` shards (checkpoints) into OUT.exr and
    /// OUT.png, bit-identical to one render of the whole range; refuses parts of another render,
    /// unfinished parts, overlaps and gaps.
    Merge {
        /// Part files (.ckpt), any order.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Output stem: writes OUT.exr and OUT.png.
        #[arg(short = 'o', long = "out")]
        out: PathBuf,
        /// Print nothing on success.
        #[arg(long, short = 'q')]
        quiet: bool,
    },
    /// Write a procedural OBJ+MTL mesh (bumpy torus on a floor under an emissive patch) of at least
    /// --triangles triangles, for throughput runs: OUT.obj and OUT.mtl.
    GenMesh {
        /// Output OBJ path (the MTL is written beside it).
        out: PathBuf,
        /// Minimum number of triangles of the torus.
        #[arg(long, default_value_t = 1_000_000)]
        triangles: usize,
    },
    /// Regenerate the seed experiments (direct lighting light samplers; path tracing pixel
    /// stratification, cosine, BRDF sampling) into DIR: results.md/json, contact sheets, plots.
    Experiments {
        /// Output folder.
        #[arg(long, default_value = "docs/experiments")]
        out: PathBuf,
        /// The CSE168 corpus (default ../shared/cse168 beside the crate, or $STRATA_CSE168).
        #[arg(long)]
        corpus: Option<PathBuf>,
        /// Independent runs per variant (K).
        #[arg(long, default_value_t = 16)]
        runs: usize,
        /// Image width (heights keep each scene's aspect).
        #[arg(long, default_value_t = 160)]
        width: u32,
        /// Light samples of each half of the direct-lighting reference.
        #[arg(long, default_value_t = 4096)]
        ref_light_samples: u32,
        /// spp of the path-tracing references.
        #[arg(long, default_value_t = 1024)]
        ref_spp: u32,
        /// Worker threads (0 = all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Contact-sheet tiles are the images box-downsampled by this factor.
        #[arg(long, default_value_t = 2)]
        sheet_factor: u32,
    },
    /// Measure the whole renderer's rays/s next to Embree's raw rate on the same packets (1 thread).
    Rays {
        #[command(flatten)]
        args: RenderArgs,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Break the worker threads' time into phases (sampler by dimension group, emitter sampling,
    /// Embree intersect/occluded, user geometry, hit gather, BSDF sampling and eval, MIS,
    /// accumulation, film, other) with % of render, ns per sample and ns per ray; the overhead is
    /// measured by rendering the same job unprofiled, interleaved.
    Profile {
        #[command(flatten)]
        args: RenderArgs,
        /// Also write the profile as JSON to this file.
        #[arg(long = "json", value_name = "FILE")]
        json_file: Option<PathBuf>,
        /// Also write the phases as an SVG stacked bar chart (shares in %, legend) to this file.
        #[arg(long = "svg", value_name = "FILE")]
        svg_file: Option<PathBuf>,
        /// Renders per mode (profiling off and on, interleaved); the fastest of each counts.
        #[arg(long, default_value_t = strata::session::profile::REPEATS)]
        repeats: usize,
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene file (.test, or .obj for a whole-scene OBJ); omitted: the built-in Cornell box.
    scene: Option<PathBuf>,
    /// Camera "ex ey ez cx cy cz ux uy uz fovy" (the format's camera arguments), replacing the
    /// scene's (for an .obj, the default one framing its bounds).
    #[arg(long, value_parser = session::parse_camera, allow_hyphen_values = true)]
    camera: Option<strata::scene::desc::CameraDesc>,
    /// Samples per pixel (default: the scene's spp).
    #[arg(long)]
    spp: Option<u32>,
    /// Image size WxH, keeping the camera (default: the scene's size).
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// Base seed of every sample stream.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Worker threads (0 = all cores).
    #[arg(long, default_value_t = 0)]
    threads: usize,
    // Light sample layout; the help lists the sampler registry.
    #[arg(long, value_parser = parse_sampler, help = format!("Light sample layout: {}", SamplerKind::help_list()))]
    light_sampler: Option<SamplerKind>,
    /// Light samples per light (default: the scene's lightsamples).
    #[arg(long)]
    light_samples: Option<u32>,
    // Pixel sample layout; the help lists the sampler registry.
    #[arg(long, value_parser = parse_sampler, help = format!(
        "Pixel sample layout over a pixel's spp samples: {} (default stratified; grid-center with --spp 1 \
         puts the sample at the pixel centre)",
        SamplerKind::help_list()
    ))]
    pixel_sampler: Option<SamplerKind>,
    /// Integrator override: raytracer, analyticdirect, direct, pathtracer.
    #[arg(long, value_parser = parse_integrator)]
    integrator: Option<IntegratorKind>,
    /// Path tracer direction sampling: hemisphere, cosine, brdf (default: the scene's importancesampling).
    #[arg(long, value_parser = parse_importance_sampling)]
    importance_sampling: Option<ImportanceSampling>,
    /// Path tracer next event estimation: off, on, mis (default: the scene's nexteventestimation).
    #[arg(long, value_parser = parse_nee)]
    nee: Option<Nee>,
    /// Path tracer Russian roulette: on, off (default: the scene's russianroulette).
    #[arg(long, value_parser = parse_on_off)]
    russian_roulette: Option<bool>,
    /// Maximum depth, -1 = unbounded (default: the scene's maxdepth).
    #[arg(long, allow_negative_numbers = true)]
    max_depth: Option<i32>,
    /// Output stem: writes OUT.exr and OUT.png (default: the scene's output name).
    #[arg(short = 'o', long = "out")]
    out: Option<PathBuf>,
    /// Write statistics as JSON to this file.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Profile the render's phases (as `strata profile`, without its unprofiled re-render) and write
    /// the profile JSON to this file; the image is bit-identical either way.
    #[arg(long, value_name = "FILE")]
    profile: Option<PathBuf>,
    /// Print nothing on success.
    #[arg(long, short = 'q')]
    quiet: bool,
    /// Shading kernel: `auto` runs the one compiled for the scene's features (see `features` and
    /// `kernel` in --stats), `general` the one with every feature compiled in. Same image either way.
    #[arg(long, default_value = "auto", value_parser = ["auto", "general"])]
    kernel: String,
    /// Path tracer only, opt-in and BIASED: scale each pixel sample down so its largest RGB channel is
    /// at most MAX (trades fireflies for a darker, inconsistent estimate; off by default).
    #[arg(long, value_name = "MAX", value_parser = parse_clamp)]
    clamp: Option<f32>,
    /// Write the accumulated state here (atomically) every --checkpoint-every seconds and at the
    /// end; resume it with --resume. Default with --samples or on Ctrl-C: OUT.ckpt.
    #[arg(long)]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints (0: after every pass).
    #[arg(long, default_value_t = session::DEFAULT_CHECKPOINT_EVERY)]
    checkpoint_every: f64,
    /// Continue the render held in this checkpoint (refused if the scene or an option differs);
    /// it keeps being checkpointed there unless --checkpoint says otherwise.
    #[arg(long)]
    resume: Option<PathBuf>,
    /// Render only sample indices A..B (0 <= A < B <= spp) of every pixel: a part for `strata merge`.
    #[arg(long, value_parser = parse_range)]
    samples: Option<(u32, u32)>,
    /// Render whole passes until this many seconds are spent and record the spp reached
    /// (independent pixel and path layouts; --spp, if given, caps the samples).
    #[arg(long)]
    time_budget: Option<f64>,
    /// Raise or lower a resource cap, NAME=VALUE (repeatable): max_pixels, max_side, max_vertices,
    /// max_primitives, max_spp, max_depth, max_light_samples, max_transform_depth.
    #[arg(long = "limit", value_name = "NAME=VALUE", value_parser = parse_limit)]
    limits: Vec<String>,
    /// 8-bit PNG values: truncate (the CSE168 course's writer, floor(255 c); default for .test scenes)
    /// or round (default for .obj scenes). The EXR is linear and not affected.
    #[arg(long, value_parser = parse_quantize)]
    quantize: Option<strata::film::Quantize>,
    /// Pixel sample 0: centre (through the pixel centre like the CSE168 course code; default for .test
    /// scenes; O(1/spp) bias, see README) or jittered (strata's unbiased stratified layout; default for
    /// .obj scenes). spp 1 with centre is the course's deterministic image.
    #[arg(long, value_parser = parse_first_sample)]
    first_sample: Option<strata::integrator::FirstSample>,
    /// Path tracer NEE light selection: all (every light, `lightsamples` points each; the CSE168
    /// convention, default for .test scenes), uniform (one light, the historical path-tracer choice;
    /// default for .obj scenes), power (one light by emitted power), spatial (one light by the light tree).
    #[arg(long, value_name = "NAME")]
    light_selection: Option<strata::integrator::LightSelection>,
    /// Keep an OBJ scene without emitters unlit (by default an area light is added above and
    /// behind the camera, announced on stderr).
    #[arg(long)]
    no_default_light: bool,
}

impl RenderArgs {
    fn options(self) -> RenderOptions {
        RenderOptions {
            scene: self.scene,
            spp: self.spp,
            size: self.size,
            seed: self.seed,
            threads: self.threads,
            light_sampler: self.light_sampler,
            light_samples: self.light_samples,
            pixel_sampler: self.pixel_sampler,
            out: self.out,
            stats: self.stats,
            profile: self.profile,
            integrator: self.integrator,
            progress: !self.quiet,
            general_kernel: self.kernel == "general",
            clamp: self.clamp,
            checkpoint: self.checkpoint,
            checkpoint_every: Some(self.checkpoint_every),
            resume: self.resume,
            samples: self.samples,
            time_budget: self.time_budget,
            stop: None,
            camera: self.camera,
            importance_sampling: self.importance_sampling,
            nee: self.nee,
            russian_roulette: self.russian_roulette,
            max_depth: self.max_depth,
            limits: limits_of(&self.limits),
            quantize: self.quantize,
            first_sample: self.first_sample,
            light_selection: self.light_selection,
            no_default_light: self.no_default_light,
            rendering: None,
        }
    }
}

/// Checks one `--limit NAME=VALUE` (the assignment is applied again in [`limits_of`]).
fn parse_limit(s: &str) -> Result<String, String> {
    strata::scene::parse::Limits::default().set(s).map(|()| s.to_string()).map_err(|e| e.to_string())
}

/// The default limits with every (already checked) `--limit` applied in order.
fn limits_of(assignments: &[String]) -> strata::scene::parse::Limits {
    let mut limits = strata::scene::parse::Limits::default();
    for a in assignments {
        let _ = limits.set(a); // validated by `parse_limit`
    }
    limits
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WxH, got `{s}`"))?;
    let p = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("expected WxH with positive integers, got `{s}`"));
    Ok((p(w)?, p(h)?))
}

fn parse_quantize(s: &str) -> Result<strata::film::Quantize, String> {
    strata::film::Quantize::parse(s).ok_or_else(|| format!("expected truncate or round, got `{s}`"))
}

fn parse_first_sample(s: &str) -> Result<strata::integrator::FirstSample, String> {
    strata::integrator::FirstSample::parse(s).ok_or_else(|| format!("expected centre or jittered, got `{s}`"))
}

fn parse_clamp(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("--clamp expects a positive finite radiance, got `{s}`")),
    }
}

fn parse_range(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s.split_once("..").ok_or_else(|| format!("expected A..B, got `{s}`"))?;
    let p =
        |v: &str| v.trim().parse::<u32>().map_err(|_| format!("expected A..B with non-negative integers, got `{s}`"));
    let (a, b) = (p(a)?, p(b)?);
    if a >= b {
        return Err(format!("expected A..B with A < B, got `{s}`"));
    }
    Ok((a, b))
}

fn parse_sampler(s: &str) -> Result<SamplerKind, String> {
    SamplerKind::parse(s).ok_or_else(|| format!("unknown sampler `{s}` ({})", SamplerKind::names()))
}

fn parse_integrator(s: &str) -> Result<IntegratorKind, String> {
    IntegratorKind::parse(s)
        .ok_or_else(|| format!("unknown integrator `{s}` (raytracer, analyticdirect, direct, pathtracer)"))
}

fn parse_nee(s: &str) -> Result<Nee, String> {
    Nee::parse(s).ok_or_else(|| format!("unknown next event estimation `{s}` (off, on, mis)"))
}

fn parse_on_off(s: &str) -> Result<bool, String> {
    match s {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("expected on or off, got `{s}`")),
    }
}

fn parse_importance_sampling(s: &str) -> Result<ImportanceSampling, String> {
    ImportanceSampling::parse(s).ok_or_else(|| format!("unknown importance sampling `{s}` (hemisphere, cosine, brdf)"))
}

/// The build targets x86-64-v3 (see `.cargo/config.toml`): on a CPU without AVX2/FMA the first SIMD
/// instruction would kill the process with SIGILL, so check before anything else runs.
fn cpu_supported() -> Result<(), String> {
    #[cfg(target_arch = "x86_64")]
    {
        let missing: Vec<&str> = [
            ("avx2", std::arch::is_x86_feature_detected!("avx2")),
            ("fma", std::arch::is_x86_feature_detected!("fma")),
        ]
        .into_iter()
        .filter_map(|(name, ok)| (!ok).then_some(name))
        .collect();
        if !missing.is_empty() {
            return Err(format!(
                "this CPU lacks {} (strata is built for x86-64-v3: AVX2 and FMA, Intel Haswell / AMD Zen or newer); run it on a newer node",
                missing.join(", ")
            ));
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    if let Err(msg) = cpu_supported() {
        eprintln!("strata: {msg}");
        return ExitCode::from(2);
    }
    let cli = Cli::parse();
    let result = match cli.cmd {
        Cmd::Render(args) | Cmd::Reference(args) => {
            let quiet = args.quiet;
            let mut opts = args.options();
            match session::stop_on_signals() {
                Ok(flag) => {
                    let rendering = Arc::new(AtomicBool::new(false));
                    exit_on_signal_outside_render(Arc::clone(&flag), Arc::clone(&rendering));
                    opts.stop = Some(flag);
                    opts.rendering = Some(rendering);
                }
                Err(e) => eprintln!("strata: {e}; Ctrl-C will not checkpoint"),
            }
            match session::run_render(&opts) {
                Ok(o) if o.interrupted => {
                    let ck = o.checkpoint.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
                    eprintln!(
                        "strata: interrupted after {} spp; image written, checkpoint {ck}: continue with the same flags and --resume {ck}",
                        o.film.samples().len()
                    );
                    return ExitCode::from(130);
                }
                Ok(o) => {
                    if !quiet {
                        println!("{}", session::summary(&o));
                    }
                    // A signal after the last pass (while the outputs were written, atomically)
                    // left them complete; the exit status still says a signal was received.
                    if opts.stop.as_ref().is_some_and(|f| f.load(Ordering::SeqCst)) {
                        eprintln!(
                            "strata: interrupted after the last pass; outputs complete ({} spp)",
                            o.film.samples().len()
                        );
                        return ExitCode::from(130);
                    }
                    Ok(())
                }
                Err(e) => Err(e.to_string()),
            }
        }
        Cmd::Merge { parts, out, quiet } => {
            strata::checkpoint::run_merge(&parts, &out).map_err(|e| e.to_string()).map(|m| {
                if !quiet {
                    println!(
                        "merged {} parts: {} spp ({}..{}), {:.3} CPU seconds -> {}.exr/.png",
                        m.header.parts.len(),
                        m.header.samples[1] - m.header.samples[0],
                        m.header.samples[0],
                        m.header.samples[1],
                        m.header.cpu_seconds,
                        m.out.display()
                    );
                }
            })
        }
        Cmd::Compare {
            scene,
            reference,
            variants,
            runs,
            budget,
            spp_ladder,
            size,
            threads,
            out,
            profile,
            profile_svg,
        } => {
            let profile_out = ProfileOut { json: profile, svg: profile_svg };
            run_compare(scene, &reference, &variants, runs, budget, spp_ladder, size, threads, &out, &profile_out)
        }
        Cmd::GenMesh { out, triangles } => {
            let mesh = strata::scene::obj::procedural_mesh(triangles);
            strata::scene::obj::write_obj(&out, &mesh)
                .map(|mtl| {
                    println!(
                        "{}: {} triangles, {} vertices (materials {})",
                        out.display(),
                        mesh.faces.len(),
                        mesh.positions.len(),
                        mtl.display()
                    )
                })
                .map_err(|e| format!("{}: {e}", out.display()))
        }
        Cmd::Experiments { out, corpus, runs, width, ref_light_samples, ref_spp, threads, sheet_factor } => {
            let corpus = corpus.unwrap_or_else(strata::lab::experiments::default_corpus);
            let cfg = strata::lab::experiments::Config {
                corpus,
                out: out.clone(),
                runs,
                width,
                ref_light_samples,
                ref_spp,
                threads,
                verbose: true,
                sheet_factor,
            };
            strata::lab::experiments::run(&cfg).map_err(|e| e.to_string()).map(|md| {
                println!("{md}");
                println!("written to {}/ (results.md, results.json, *.png, *.svg)", out.display());
            })
        }
        Cmd::Rays { args, json } => {
            session::run_rays(&args.options()).map_err(|e| e.to_string()).map(|(rates, name)| {
                if json {
                    println!("{}", serde_json::to_string_pretty(&rates).unwrap_or_default());
                } else {
                    println!("{}", session::rates_table(&name, &rates));
                }
            })
        }
        Cmd::Profile { args, json_file, svg_file, repeats } => {
            let quiet = args.quiet;
            // `--profile FILE` (a render flag) means the same here as `--json FILE`.
            let json_file = json_file.or_else(|| args.profile.clone());
            let early =
                [&json_file, &svg_file].into_iter().flatten().try_for_each(|f| session::checks::check_output_file(f));
            early.and_then(|()| session::run_profile(&args.options(), repeats)).map_err(|e| e.to_string()).and_then(
                |p| {
                    if let Some(f) = &json_file {
                        let text = serde_json::to_string_pretty(&p).map_err(|e| e.to_string())?;
                        std::fs::write(f, text).map_err(|e| format!("{}: {e}", f.display()))?;
                    }
                    if let Some(f) = &svg_file {
                        let svg = session::profile::profile_svg(
                            &[(p.scene.as_str(), &p)],
                            &format!("strata profile: {}", p.scene),
                        );
                        session::profile::write_text(f, &svg).map_err(|e| e.to_string())?;
                    }
                    if !quiet {
                        println!("{}", session::profile_table(&p));
                    }
                    Ok(())
                },
            )
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("strata: {e}");
            ExitCode::FAILURE
        }
    }
}

/// A signal before the pass loop starts (scene loading, BVH build, thread start) exits at once
/// with code 130; once it runs, the loop stops after its pass, checkpoints and writes the image.
fn exit_on_signal_outside_render(stop: Arc<AtomicBool>, rendering: Arc<AtomicBool>) {
    std::thread::spawn(move || loop {
        if stop.load(Ordering::SeqCst) && !rendering.load(Ordering::SeqCst) {
            eprintln!("strata: interrupted before rendering started; nothing written");
            std::process::exit(130);
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    });
}

/// Where `compare` writes its variants' profiles (`--profile`, `--profile-svg`).
struct ProfileOut {
    json: Option<PathBuf>,
    svg: Option<PathBuf>,
}

#[allow(clippy::too_many_arguments)]
fn run_compare(
    scene: Option<PathBuf>,
    reference: &std::path::Path,
    specs: &[String],
    runs: usize,
    budget: Option<f64>,
    ladder: Option<Vec<u32>>,
    size: Option<(u32, u32)>,
    threads: usize,
    out: &std::path::Path,
    profile_out: &ProfileOut,
) -> Result<(), String> {
    let mut variants = Vec::new();
    for spec in specs {
        let (name, flags) = spec.split_once('=').ok_or_else(|| format!("--variant `{spec}`: expected NAME=OPTIONS"))?;
        let mut argv = vec!["strata".to_string(), "render".to_string()];
        argv.extend(scene.iter().map(|p| p.display().to_string()));
        argv.extend(flags.split_whitespace().map(str::to_string));
        let cli = Cli::try_parse_from(&argv)
            .map_err(|e| format!("--variant {name}: {}", e.to_string().lines().next().unwrap_or("")))?;
        let Cmd::Render(args) = cli.cmd else { unreachable!("parsed as render") };
        let mut opts = args.options();
        opts.size = size.or(opts.size);
        opts.threads = threads;
        opts.progress = false;
        variants.push(strata::lab::Variant { name: name.to_string(), opts });
    }
    let mode = match (budget, ladder) {
        (Some(b), _) if b > 0.0 && b.is_finite() => strata::lab::Mode::Budget(b),
        (Some(b), _) => return Err(format!("--budget {b}: expected a positive number of seconds")),
        (None, Some(l)) if !l.is_empty() && l.iter().all(|&s| s > 0) => strata::lab::Mode::Ladder(l),
        (None, Some(_)) => return Err("--spp-ladder: expected positive spp values".into()),
        (None, None) => return Err("give --budget SECONDS or --spp-ladder 1,2,4,...".into()),
    };
    for f in [&profile_out.json, &profile_out.svg].into_iter().flatten() {
        session::checks::check_output_file(f).map_err(|e| e.to_string())?;
    }
    let (rows, profiles) =
        strata::lab::compare_profiled(&variants, reference, runs, &mode).map_err(|e| e.to_string())?;
    let title = format!(
        "{} vs {}",
        scene.as_ref().map_or("built-in cornell".into(), |p| p.display().to_string()),
        reference.display()
    );
    let md = strata::lab::write_outputs(&rows, out, &title).map_err(|e| e.to_string())?;
    if let Some(f) = &profile_out.json {
        let text = serde_json::to_string_pretty(&profiles).map_err(|e| e.to_string())?;
        session::profile::write_text(f, &text).map_err(|e| e.to_string())?;
    }
    if let Some(f) = &profile_out.svg {
        let entries: Vec<(&str, &session::Profile)> =
            profiles.iter().map(|v| (v.variant.as_str(), &v.profile)).collect();
        let svg = session::profile::profile_svg(&entries, &format!("phases per variant: {title}"));
        session::profile::write_text(f, &svg).map_err(|e| e.to_string())?;
    }
    println!("{md}");
    println!("written to {}/ (rows.csv, rows.json, table.md, error.svg)", out.display());
    Ok(())
}

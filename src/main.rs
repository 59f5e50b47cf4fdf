//! `strata` command line.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use strata::app::{self, RenderOptions};
use strata::sampler::SamplerKind;

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
    /// Measure the whole renderer's rays/s next to Embree's raw rate on the same packets (1 thread).
    Rays {
        #[command(flatten)]
        args: RenderArgs,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene file (.test); omitted: the built-in Cornell box.
    scene: Option<PathBuf>,
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
    /// Light sample layout: independent (random), stratified, grid-center (biased), halton, sobol, pmj02.
    #[arg(long, value_parser = parse_sampler)]
    light_sampler: Option<SamplerKind>,
    /// Light samples per light (default: the scene's lightsamples).
    #[arg(long)]
    light_samples: Option<u32>,
    /// Pixel sample layout over a pixel's spp samples (default stratified; grid-center with
    /// --spp 1 puts the sample at the pixel centre).
    #[arg(long, value_parser = parse_sampler)]
    pixel_sampler: Option<SamplerKind>,
    /// Integrator override: analyticdirect, direct, pathtracer (raytracer is not implemented yet).
    #[arg(long, value_parser = parse_integrator)]
    integrator: Option<strata::scene::desc::IntegratorKind>,
    /// Output stem: writes OUT.exr and OUT.png (default: the scene's output name).
    #[arg(short = 'o', long = "out")]
    out: Option<PathBuf>,
    /// Write statistics as JSON to this file.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Print nothing on success.
    #[arg(long, short = 'q')]
    quiet: bool,
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
            integrator: self.integrator,
        }
    }
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WxH, got `{s}`"))?;
    let p = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("expected WxH with positive integers, got `{s}`"));
    Ok((p(w)?, p(h)?))
}

fn parse_sampler(s: &str) -> Result<SamplerKind, String> {
    SamplerKind::parse(s).ok_or_else(|| format!("unknown sampler `{s}` (independent, stratified, grid-center, halton, sobol, pmj02)"))
}

fn parse_integrator(s: &str) -> Result<strata::scene::desc::IntegratorKind, String> {
    app::parse_integrator(s).ok_or_else(|| format!("unknown integrator `{s}` (raytracer, analyticdirect, direct, pathtracer)"))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.cmd {
        Cmd::Render(args) => {
            let quiet = args.quiet;
            app::run_render(&args.options()).map(|o| {
                if !quiet {
                    println!("{}", app::summary(&o));
                }
            })
        }
        Cmd::Rays { args, json } => app::run_rays(&args.options()).map(|(rates, name)| {
            if json {
                println!("{}", serde_json::to_string_pretty(&rates).unwrap_or_default());
            } else {
                println!("{}", app::rates_table(&name, &rates));
            }
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("strata: {e}");
            ExitCode::FAILURE
        }
    }
}

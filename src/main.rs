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
    Render {
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
        /// Light sample layout: independent (random), stratified, grid-center (biased), halton.
        #[arg(long, value_parser = parse_sampler)]
        light_sampler: Option<SamplerKind>,
        /// Light samples per light (default: the scene's lightsamples).
        #[arg(long)]
        light_samples: Option<u32>,
        /// Integrator override: analyticdirect, direct.
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
    },
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WxH, got `{s}`"))?;
    let p = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("expected WxH with positive integers, got `{s}`"));
    Ok((p(w)?, p(h)?))
}

fn parse_sampler(s: &str) -> Result<SamplerKind, String> {
    SamplerKind::parse(s).ok_or_else(|| format!("unknown sampler `{s}` (independent, stratified, grid-center, halton)"))
}

fn parse_integrator(s: &str) -> Result<strata::scene::desc::IntegratorKind, String> {
    app::parse_integrator(s).ok_or_else(|| format!("unknown integrator `{s}` (analyticdirect, direct)"))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.cmd {
        Cmd::Render { scene, spp, size, seed, threads, light_sampler, light_samples, integrator, out, stats, quiet } => {
            let opts = RenderOptions { scene, spp, size, seed, threads, light_sampler, light_samples, out, stats, integrator };
            match app::run_render(&opts) {
                Ok(o) => {
                    if !quiet {
                        println!("{}", app::summary(&o));
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("strata: {e}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}

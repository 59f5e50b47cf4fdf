//! The command line as library functions, for the binary and the Python module alike: render
//! flags parsed by the binary's own grammar (`cli.rs`, compiled into the library too), and
//! `compare` (variants from flag strings, the mode, the run and its outputs). The Python module
//! turns keyword arguments into the same flags, so it accepts and refuses exactly what the CLI
//! does, with the same messages.

use crate::cli::{Cli, Cmd};
use crate::lab::{self, Mode, Variant, VariantProfile};
use crate::report::Row;
use crate::session::{self, RenderOptions};
use clap::Parser;
use std::path::{Path, PathBuf};

/// The options of `strata render ARGS...` (`args` without the program and subcommand names);
/// the error is clap's message, as the CLI prints it.
pub fn render_options(args: &[String]) -> Result<RenderOptions, String> {
    let argv = ["strata", "render"].into_iter().map(String::from).chain(args.iter().cloned());
    match Cli::try_parse_from(argv).map_err(|e| e.to_string())?.cmd {
        Cmd::Render(a) => Ok(a.options()),
        _ => unreachable!("parsed as render"),
    }
}

/// Where `compare` writes its variants' profiles (`--profile`, `--profile-svg`).
#[derive(Clone, Debug, Default)]
pub struct ProfileOut {
    /// JSON list of the variants' profiles
    pub json: Option<PathBuf>,
    /// SVG stacked bars of the variants' phases
    pub svg: Option<PathBuf>,
}

/// What `strata compare` was asked.
#[derive(Clone, Debug)]
pub struct CompareArgs {
    /// scene (None: the built-in Cornell box)
    pub scene: Option<PathBuf>,
    /// reference EXR
    pub reference: PathBuf,
    /// NAME=FLAGS per variant
    pub variants: Vec<String>,
    /// runs per variant
    pub runs: usize,
    /// equal time: CPU seconds per run
    pub budget: Option<f64>,
    /// equal spp: the ladder
    pub spp_ladder: Option<Vec<u32>>,
    /// image size for every variant
    pub size: Option<(u32, u32)>,
    /// worker threads
    pub threads: usize,
    /// output folder
    pub out: PathBuf,
    /// profile outputs
    pub profile: ProfileOut,
}

/// What a compare run produced.
pub struct CompareOutput {
    /// one row per (variant, ladder step)
    pub rows: Vec<Row>,
    /// each variant's profile
    pub profiles: Vec<VariantProfile>,
    /// the Markdown table (as printed)
    pub markdown: String,
}

/// The arguments of `strata compare ARGS...` (without the program and subcommand names).
pub fn compare_args(args: &[String]) -> Result<CompareArgs, String> {
    let argv = ["strata", "compare"].into_iter().map(String::from).chain(args.iter().cloned());
    match Cli::try_parse_from(argv).map_err(|e| e.to_string())?.cmd {
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
        } => Ok(CompareArgs {
            scene,
            reference,
            variants,
            runs,
            budget,
            spp_ladder,
            size,
            threads,
            out,
            profile: ProfileOut { json: profile, svg: profile_svg },
        }),
        _ => unreachable!("parsed as compare"),
    }
}

/// The variants of `compare`: each `NAME=FLAGS` parsed as `strata render [SCENE] FLAGS`, with the
/// common size and threads.
pub fn compare_variants(
    scene: Option<&Path>,
    specs: &[String],
    size: Option<(u32, u32)>,
    threads: usize,
) -> Result<Vec<Variant>, String> {
    let mut variants = Vec::new();
    for spec in specs {
        let (name, flags) = spec.split_once('=').ok_or_else(|| format!("--variant `{spec}`: expected NAME=OPTIONS"))?;
        let mut args: Vec<String> = scene.iter().map(|p| p.display().to_string()).collect();
        args.extend(flags.split_whitespace().map(str::to_string));
        let mut opts =
            render_options(&args).map_err(|e| format!("--variant {name}: {}", e.lines().next().unwrap_or("")))?;
        opts.size = size.or(opts.size);
        opts.threads = threads;
        opts.progress = false;
        variants.push(Variant { name: name.to_string(), opts });
    }
    Ok(variants)
}

/// Equal time (`--budget`) or equal spp (`--spp-ladder`), checked.
pub fn compare_mode(budget: Option<f64>, ladder: Option<Vec<u32>>) -> Result<Mode, String> {
    match (budget, ladder) {
        (Some(b), _) if b > 0.0 && b.is_finite() => Ok(Mode::Budget(b)),
        (Some(b), _) => Err(format!("--budget {b}: expected a positive number of seconds")),
        (None, Some(l)) if !l.is_empty() && l.iter().all(|&s| s > 0) => Ok(Mode::Ladder(l)),
        (None, Some(_)) => Err("--spp-ladder: expected positive spp values".into()),
        (None, None) => Err("give --budget SECONDS or --spp-ladder 1,2,4,...".into()),
    }
}

/// Runs `strata compare` and writes its outputs (rows.csv, rows.json, table.md, error.svg in
/// `out`, and the profiles asked for).
pub fn run_compare(a: &CompareArgs) -> Result<CompareOutput, String> {
    let mut variants = compare_variants(a.scene.as_deref(), &a.variants, a.size, a.threads)?;
    let mode = compare_mode(a.budget, a.spp_ladder.clone())?;
    if let Mode::Ladder(l) = &mode {
        // Checks made before rendering (a point set's size, a sampler's period) are against the
        // largest spp the variant renders, not the scene's.
        let top = l.iter().copied().max();
        variants.iter_mut().filter(|v| v.opts.spp.is_none()).for_each(|v| v.opts.spp = top);
    }
    for f in [&a.profile.json, &a.profile.svg].into_iter().flatten() {
        session::checks::check_output_file(f).map_err(|e| e.to_string())?;
    }
    let (rows, profiles) = lab::compare_profiled(&variants, &a.reference, a.runs, &mode).map_err(|e| e.to_string())?;
    let title = format!(
        "{} vs {}",
        a.scene.as_ref().map_or("built-in cornell".into(), |p| p.display().to_string()),
        a.reference.display()
    );
    let markdown = lab::write_outputs(&rows, &a.out, &title).map_err(|e| e.to_string())?;
    if let Some(f) = &a.profile.json {
        let text = serde_json::to_string_pretty(&profiles).map_err(|e| e.to_string())?;
        session::profile::write_text(f, &text).map_err(|e| e.to_string())?;
    }
    if let Some(f) = &a.profile.svg {
        let entries: Vec<(&str, &session::Profile)> =
            profiles.iter().map(|v| (v.variant.as_str(), &v.profile)).collect();
        let svg = session::profile::profile_svg(&entries, &format!("phases per variant: {title}"));
        session::profile::write_text(f, &svg).map_err(|e| e.to_string())?;
    }
    Ok(CompareOutput { rows, profiles, markdown })
}

//! The command line as library functions, for the binary and the Python module alike: render
//! flags parsed by the binary's own grammar (`cli.rs`, compiled into the library too), and
//! `compare` (variants from flag strings, the mode, the run and its outputs). The Python module
//! turns keyword arguments into the same flags, so it accepts and refuses exactly what the CLI
//! does, with the same messages.

use crate::cli::{Cli, Cmd};
use crate::lab::{self, Mode, Variant, VariantProfile};
use crate::report::Row;
use crate::session::{self, RenderOptions, SessionError};
use clap::Parser;
use std::path::{Path, PathBuf};

/// Why flags were refused or a comparison could not run; each message is the one the CLI prints.
#[derive(Debug, thiserror::Error)]
pub enum FrontendError {
    /// The flags do not parse: clap's message, as the CLI prints it.
    #[error("{0}")]
    Flags(#[from] clap::Error),
    /// A `--variant` without `=`.
    #[error("--variant `{0}`: expected NAME=OPTIONS")]
    VariantSpec(String),
    /// A `--variant` whose options have unbalanced quotes.
    #[error("--variant {name}: unbalanced quotes in `{flags}`")]
    VariantQuotes {
        /// the variant's name
        name: String,
        /// its options as given
        flags: String,
    },
    /// A `--variant` whose options do not parse as `strata render` flags.
    #[error("--variant {name}: {}", first_line(source))]
    VariantFlags {
        /// the variant's name
        name: String,
        /// clap's message about its options
        source: clap::Error,
    },
    /// `strata reference` without `--spp`.
    #[error("`strata reference` needs --spp N (a reference is a high-spp render, e.g. --spp 4096)")]
    ReferenceSpp,
    /// Neither `--budget` nor `--spp-ladder`.
    #[error("give --budget SECONDS or --spp-ladder 1,2,4,...")]
    NoMode,
    /// An output could not be written, or a render failed.
    #[error(transparent)]
    Session(#[from] SessionError),
    /// The comparison failed.
    #[error(transparent)]
    Lab(#[from] lab::LabError),
    /// The profiles could not be serialized.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

/// The first line of clap's message (a variant's error is said on one line).
fn first_line(e: &clap::Error) -> String {
    e.to_string().lines().next().unwrap_or("").to_string()
}

/// The options of `strata render ARGS...` (`args` without the program and subcommand names);
/// the error is clap's message, as the CLI prints it.
pub fn render_options(args: &[String]) -> Result<RenderOptions, FrontendError> {
    let argv = ["strata", "render"].into_iter().map(String::from).chain(args.iter().cloned());
    match Cli::try_parse_from(argv)?.cmd {
        Cmd::Render(a) => Ok(a.into_args().options()),
        _ => unreachable!("parsed as render"),
    }
}

/// What `strata reference ARGS...` renders (`args` without the program and subcommand names):
/// its render options, unbiased ([`session::reference::unbiased`]: `--first-sample jittered`
/// unless given), and its replicas (`--replicas`, else the default of its spp). The binary and
/// the Python module's `strata.reference` both run this.
pub fn reference_options(args: &[String]) -> Result<(RenderOptions, u32), FrontendError> {
    let argv = ["strata", "reference"].into_iter().map(String::from).chain(args.iter().cloned());
    match Cli::try_parse_from(argv)?.cmd {
        Cmd::Reference(cmd) => {
            if cmd.render.args.spp.is_none() {
                return Err(FrontendError::ReferenceSpp);
            }
            let replicas = cmd.replicas();
            let mut opts = cmd.render.into_args().options();
            session::reference::unbiased(&mut opts);
            Ok((opts, replicas))
        }
        _ => unreachable!("parsed as reference"),
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
    /// NAME=FLAGS per variant (FLAGS with shell quoting)
    pub variants: Vec<String>,
    /// the variant the efficiency ratios are against (default: the first)
    pub baseline: Option<String>,
    /// compare against a reference of another scene or camera anyway
    pub force: bool,
    /// no progress lines on stderr
    pub quiet: bool,
    /// runs per variant
    pub runs: usize,
    /// equal time: CPU seconds per run (one, or a ladder)
    pub budget: Option<Vec<f64>>,
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
    /// the commands the report says reproduce it (empty: this process's command line; the Python
    /// module gives its call, `strata.compare(...)`, and the equivalent `strata compare ...`, never
    /// `python script.py`)
    pub commands: Vec<String>,
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
pub fn compare_args(args: &[String]) -> Result<CompareArgs, FrontendError> {
    let argv = ["strata", "compare"].into_iter().map(String::from).chain(args.iter().cloned());
    match Cli::try_parse_from(argv)?.cmd {
        Cmd::Compare {
            scene,
            reference,
            variants,
            baseline,
            force,
            quiet,
            runs,
            budget,
            spp_ladder,
            size,
            threads,
            out,
            profile,
            profile_svg,
            ..
        } => Ok(CompareArgs {
            scene,
            reference,
            variants,
            baseline,
            force,
            quiet,
            runs,
            budget,
            spp_ladder,
            size,
            threads,
            out,
            profile: ProfileOut { json: profile, svg: profile_svg },
            commands: Vec::new(),
        }),
        _ => unreachable!("parsed as compare"),
    }
}

/// Splits `--variant NAME=FLAGS` into the name and its flags (shell quoting, `shlex`).
pub fn variant_flags(spec: &str) -> Result<(&str, Vec<String>), FrontendError> {
    let (name, flags) = spec.split_once('=').ok_or_else(|| FrontendError::VariantSpec(spec.into()))?;
    let words =
        shlex::split(flags).ok_or_else(|| FrontendError::VariantQuotes { name: name.into(), flags: flags.into() })?;
    Ok((name, words))
}

/// The variants of `compare`: each `NAME=FLAGS` parsed as `strata render [SCENE] FLAGS` (size,
/// threads and spp are compare's, set by [`lab::run`]).
pub fn compare_variants(scene: Option<&Path>, specs: &[String]) -> Result<Vec<Variant>, FrontendError> {
    let mut variants = Vec::new();
    for spec in specs {
        let (name, flags) = variant_flags(spec)?;
        let mut args: Vec<String> = scene.iter().map(|p| p.display().to_string()).collect();
        args.extend(flags.iter().cloned());
        let opts = render_options(&args).map_err(|e| match e {
            FrontendError::Flags(source) => FrontendError::VariantFlags { name: name.into(), source },
            other => other,
        })?;
        variants.push(Variant { name: name.to_string(), opts, flags });
    }
    Ok(variants)
}

/// Equal time (`--budget`) or equal spp (`--spp-ladder`); the values are checked by [`lab::run`].
pub fn compare_mode(budget: Option<Vec<f64>>, ladder: Option<Vec<u32>>) -> Result<Mode, FrontendError> {
    match (budget, ladder) {
        (Some(b), _) if b.len() == 1 => Ok(Mode::Budget(b[0])),
        (Some(b), _) => Ok(Mode::Budgets(b)),
        (None, Some(l)) => Ok(Mode::Ladder(l)),
        (None, None) => Err(FrontendError::NoMode),
    }
}

/// The command line of this process, shell-quoted (`shlex`), for the report.
pub fn command_line() -> String {
    let args: Vec<String> = std::env::args().collect();
    shlex::try_join(args.iter().map(String::as_str)).unwrap_or_else(|_| args.join(" "))
}

/// Runs `strata compare` and writes its outputs (report.html, rows.csv/json, runs.csv/json,
/// table.md, error.svg in `out`, and the profiles asked for).
pub fn run_compare(a: &CompareArgs) -> Result<CompareOutput, FrontendError> {
    let variants = compare_variants(a.scene.as_deref(), &a.variants)?;
    let mode = compare_mode(a.budget.clone(), a.spp_ladder.clone())?;
    for f in [&a.profile.json, &a.profile.svg].into_iter().flatten() {
        session::checks::check_output_file(f)?;
    }
    let opts = lab::Options {
        runs: a.runs,
        mode,
        baseline: a.baseline.clone(),
        force: a.force,
        size: a.size,
        threads: a.threads,
        progress: !a.quiet,
    };
    let c = lab::run(&variants, &a.reference, &opts)?;
    let title = format!(
        "{} vs {}",
        a.scene.as_ref().map_or("built-in cornell".into(), |p| p.display().to_string()),
        a.reference.display()
    );
    let commands = if a.commands.is_empty() { vec![command_line()] } else { a.commands.clone() };
    let markdown = lab::write_outputs(&c, &a.out, &title, &commands)?;
    if let Some(f) = &a.profile.json {
        let text = serde_json::to_string_pretty(&c.profiles)?;
        session::profile::write_text(f, &text)?;
    }
    if let Some(f) = &a.profile.svg {
        let entries: Vec<(&str, &session::Profile)> =
            c.profiles.iter().map(|v| (v.variant.as_str(), &v.profile)).collect();
        let svg = session::profile::profile_svg(&entries, &format!("phases per variant: {title}"));
        session::profile::write_text(f, &svg)?;
    }
    Ok(CompareOutput { rows: c.rows, profiles: c.profiles, markdown })
}

//! `strata` command line.

use clap::{CommandFactory, Parser};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use strata::session;

mod cli;

use cli::{Cli, Cmd};

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
    refuse_unused_flags(&cli.cmd);
    let result = match cli.cmd {
        Cmd::HelpMarkdown => {
            print!("{}", cli::help_markdown());
            Ok(())
        }
        Cmd::ParseCheck { args } => {
            let argv = std::iter::once("strata".to_string()).chain(args);
            let parsed = Cli::try_parse_from(argv).unwrap_or_else(|e| e.exit());
            refuse_unused_flags(&parsed.cmd);
            println!("ok");
            Ok(())
        }
        Cmd::Render(cmd) | Cmd::Reference(cmd) => {
            let args = cmd.into_args();
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
            json,
            profile,
            profile_svg,
        } => {
            let profile_out = ProfileOut { json: profile, svg: profile_svg };
            let early = json.as_ref().map_or(Ok(()), |f| session::checks::check_output_file(f));
            early
                .map_err(|e| e.to_string())
                .and_then(|()| {
                    run_compare(
                        scene,
                        &reference,
                        &variants,
                        runs,
                        budget,
                        spp_ladder,
                        size,
                        threads,
                        &out,
                        &profile_out,
                    )
                })
                .and_then(|()| copy_rows_json(&out, json.as_deref()))
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
            let json_file = json.as_ref().filter(|f| f.as_os_str() != "-");
            let early = json_file.map_or(Ok(()), |f| session::checks::check_output_file(f));
            early.and_then(|()| session::run_rays(&args.options())).map_err(|e| e.to_string()).and_then(
                |(rates, name)| {
                    let text = serde_json::to_string_pretty(&rates).map_err(|e| e.to_string())?;
                    match (&json, json_file) {
                        (Some(_), None) => println!("{text}"),
                        (_, Some(f)) => {
                            session::profile::write_text(f, &text).map_err(|e| e.to_string())?;
                            println!("{}", session::rates_table(&name, &rates));
                        }
                        (None, None) => println!("{}", session::rates_table(&name, &rates)),
                    }
                    Ok(())
                },
            )
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

/// Refuses, as a usage error (exit status 2), what the parsed command line asks for but the
/// subcommand would ignore: `reference` without `--spp`; `rays` and `profile` with flags that only
/// a render writing an image uses (and `rays` with `--profile`).
fn refuse_unused_flags(cmd: &Cmd) {
    let (name, args) = match cmd {
        Cmd::Reference(cmd) if cmd.args.spp.is_none() => usage_error(
            "reference",
            "`strata reference` needs --spp N (a reference is a high-spp render, e.g. --spp 4096)".into(),
        ),
        Cmd::Rays { args, .. } => ("rays", args),
        Cmd::Profile { args, .. } => ("profile", args),
        _ => return,
    };
    let mut unused = args.unused_by_measurements();
    if name == "rays" && args.profile.is_some() {
        unused.push("--profile");
    }
    if let Some(flag) = unused.first() {
        usage_error(
            name,
            format!("`strata {name}` does not use {flag}: it measures and writes no image or checkpoint; remove it"),
        );
    }
}

/// Prints a clap usage error for subcommand `name` and exits with status 2.
fn usage_error(name: &str, msg: String) -> ! {
    let mut cmd = Cli::command();
    let sub = cmd.find_subcommand_mut(name).map(|s| s.clone()).unwrap_or(cmd);
    sub.bin_name(format!("strata {name}")).error(clap::error::ErrorKind::ArgumentConflict, msg).exit()
}

/// `compare --json FILE`: the rows (`OUT/rows.json`) written there too.
fn copy_rows_json(out: &std::path::Path, json: Option<&std::path::Path>) -> Result<(), String> {
    let Some(f) = json else { return Ok(()) };
    let text = std::fs::read_to_string(out.join("rows.json")).map_err(|e| format!("{}: {e}", out.display()))?;
    session::profile::write_text(f, &text).map_err(|e| e.to_string())
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
        let Cmd::Render(cmd) = cli.cmd else { unreachable!("parsed as render") };
        let args = cmd.into_args();
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

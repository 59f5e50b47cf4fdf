//! `strata` command line.

use clap::{CommandFactory, FromArgMatches, Parser};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use strata::session;

mod cli;

use cli::{Cli, Cmd, ReferenceCmd};

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
    // A file-size limit (`ulimit -f`) must not kill a finished render: with SIGXFSZ caught, a
    // write past the limit fails with EFBIG, which is reported (exit 1) and removes its temporary
    // file, while the other outputs are still tried.
    if let Err(e) = signal_hook::flag::register(signal_hook::consts::SIGXFSZ, Arc::new(AtomicBool::new(false))) {
        eprintln!("strata: warning: cannot catch SIGXFSZ ({e}): a file-size limit would kill the process");
    }
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    let is_reference = matches!(cli.cmd, Cmd::Reference(_));
    refuse_unused_flags(&cli.cmd);
    // Every subcommand's inputs and outputs, checked before any work (render and reference check
    // theirs in the session, with the stem and MTL libraries the scene names).
    if !matches!(cli.cmd, Cmd::Render(_) | Cmd::Reference(_)) {
        if let Err(e) = strata::plan::check(&matches) {
            eprintln!("strata: {e}; checked before any work, nothing was written");
            return ExitCode::FAILURE;
        }
    }
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
        Cmd::Reference(cmd) if resolve_replicas(&cmd) > 1 => {
            let replicas = resolve_replicas(&cmd);
            let args = cmd.render.into_args();
            let quiet = args.quiet;
            let mut opts = args.options();
            // A reference is unbiased by default, whatever the scene's course conventions.
            opts.first_sample.get_or_insert(strata::integrator::FirstSample::Jittered);
            match session::reference::run_reference(&opts, replicas) {
                Ok(rep) => {
                    if !quiet {
                        println!("{}", session::reference::summary(&rep));
                    }
                    Ok(())
                }
                Err(e) => Err(e.to_string()),
            }
        }
        Cmd::Render(cmd) | Cmd::Reference(ReferenceCmd { render: cmd, .. }) => {
            let args = cmd.into_args();
            let quiet = args.quiet;
            let mut opts = args.options();
            if is_reference {
                // A reference is unbiased by default, whatever the scene's course conventions.
                opts.first_sample.get_or_insert(strata::integrator::FirstSample::Jittered);
            }
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
        Cmd::Merge { parts, out, quiet, allow_other_build } => {
            strata::checkpoint::run_merge(&parts, &out, allow_other_build).map_err(|e| e.to_string()).map(|m| {
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
        // The library's copy of this grammar parses the same arguments into `CompareArgs`.
        Cmd::Compare { ref json, .. } => {
            let json = json.clone();
            let early = json.as_ref().map_or(Ok(()), |f| session::checks::check_output_file(f));
            early.map_err(|e| e.to_string()).and_then(|()| strata::frontend::compare_args(&std::env::args().skip(2).collect::<Vec<_>>()).map_err(|e| e.to_string())).and_then(|args| {
                strata::frontend::run_compare(&args).map_err(|e| e.to_string()).and_then(|o| {
                    println!("{}", o.markdown);
                    println!("written to {}/ (report.html, rows.csv, rows.json, runs.csv, runs.json, table.md, error.svg)", args.out.display());
                    copy_rows_json(&args.out, json.as_deref())
                })
            })
        }
        Cmd::GenMesh { out, triangles } => gen_mesh(&out, triangles),
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
                println!("written to {}/ (report.html, results.md, results.json, *.svg)", out.display());
            })
        }
        Cmd::Pointset { target, out, export, sets, points, seed, dim, width, trials, max_freq, options } => {
            run_pointset(target, out, export, [sets, points, dim, width, trials], seed, max_freq, &options)
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
                        session::profile::write_text(f, &text).map_err(|e| e.to_string())?;
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

/// The replicas of `strata reference`: `--replicas`, else the records of the `--resume`
/// checkpoint (one for a single render's), else [`session::reference::default_replicas`] of its spp
/// (1 for a shard or a time budget).
fn resolve_replicas(cmd: &ReferenceCmd) -> u32 {
    let a = &cmd.render.args;
    let single = a.samples.is_some() || a.time_budget.is_some();
    // An unreadable checkpoint counts as one render's: the render reports why it is unreadable.
    let resumed = a.resume.as_ref().map(|p| strata::checkpoint::read_replicas(p).map_or(1, |r| r.len() as u32));
    cmd.replicas.unwrap_or(match resumed {
        _ if single => 1,
        Some(n) => n,
        None => session::reference::default_replicas(a.spp.unwrap_or(1)),
    })
}

/// Refuses, as a usage error (exit status 2), what the parsed command line asks for but the
/// subcommand would ignore: `reference` without `--spp`; `rays` and `profile` with flags that only
/// a render writing an image uses (and `rays` with `--profile`).
fn refuse_unused_flags(cmd: &Cmd) {
    let (name, args) = match cmd {
        Cmd::Reference(cmd) if cmd.render.args.spp.is_none() => usage_error(
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

/// `strata gen-mesh OUT --triangles N`, refused when the mesh would not fit in memory (80% of it,
/// the default `--limit max_memory` of a render).
fn gen_mesh(out: &std::path::Path, triangles: usize) -> Result<(), String> {
    let need = strata::scene::obj::procedural_mesh_bytes(triangles);
    let limit = strata::scene::parse::Limits::default().max_memory;
    if need > limit {
        let show = session::memory::show_bytes;
        return Err(format!(
            "gen-mesh --triangles {triangles}: the mesh needs about {} of memory, above {} (80% of this machine's)",
            show(need),
            show(limit)
        ));
    }
    let mesh = strata::scene::obj::procedural_mesh(triangles);
    strata::scene::obj::write_obj(out, &mesh)
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

/// `strata pointset`: `counts` are sets, points, dim, width, trials.
fn run_pointset(
    target: String,
    out: Option<PathBuf>,
    export: Option<PathBuf>,
    counts: [u32; 5],
    seed: u64,
    max_freq: usize,
    options: &[String],
) -> Result<(), String> {
    let [sets, points, dim, width, trials] = counts;
    let mut opts = strata::pointset::spec::Options::default();
    options.iter().try_for_each(|kv| opts.set(kv)).map_err(|e| e.to_string())?;
    let args = strata::pointset::command::Args {
        target,
        out: out.clone(),
        export: export.clone(),
        sets,
        points,
        seed,
        dim,
        width,
        trials,
        max_freq,
        options: opts,
    };
    let (_, table) = strata::pointset::command::run(&args).map_err(|e| e.to_string())?;
    println!("{table}");
    if let Some(d) = out {
        println!("written to {}/ (spectrum.csv/svg, integration.csv/svg, pointset.json)", d.display());
    }
    if let Some(e) = export {
        println!("sets written to {}", e.display());
    }
    Ok(())
}

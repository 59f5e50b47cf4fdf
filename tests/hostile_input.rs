//! Hostile input (issue #6): property-based tests (proptest) feed the scene parser random scene
//! files and mutations of the corpus and of `scenes/*.test`. For every input the parser returns
//! without panicking, within the watchdog (no hang), allocating at most [`cap`] bytes
//! (32 bytes per input byte plus 4 MiB, measured by a counting allocator on the parsing thread),
//! and every failure is an error naming the file and a line that holds a command. The resource
//! caps name the limit and how to raise it (`--limit NAME=VALUE`), through the library and the CLI.
//! Issue 25's findings (CPUs and builds, outputs, resources) are in `hostile/`.

use proptest::prelude::*;
use run::scratch;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use strata::accel::alloc::CountingAlloc;
use strata::scene::parse::{parse_str, Limits, SceneError};

#[global_allocator]
static ALLOC: CountingAlloc = CountingAlloc;

/// Allocation cap of one parse of `len` bytes of text (the stated bound: 32 bytes per input byte
/// plus 4 MiB; the largest record, a sphere's 80-byte matrix, comes from a 15-byte line, and a
/// `Vec` may hold twice its length; `maxverts` reserves at most 768 KiB up front).
fn cap(len: usize) -> usize {
    32 * len + (4 << 20)
}

/// Aborts the process if a parse takes more than two minutes (a hang, not a slow machine: the
/// largest input here parses in well under a second).
fn watchdog() -> impl Drop {
    struct Guard(std::sync::mpsc::Sender<()>);
    impl Drop for Guard {
        fn drop(&mut self) {
            let _ = self.0.send(());
        }
    }
    let (tx, rx) = std::sync::mpsc::channel::<()>();
    std::thread::spawn(move || {
        if let Err(std::sync::mpsc::RecvTimeoutError::Timeout) = rx.recv_timeout(std::time::Duration::from_secs(120)) {
            eprintln!("hostile_input: a parse did not finish within 120 s (hang)");
            std::process::abort();
        }
    });
    Guard(tx)
}

/// Parses `text` and checks the properties; returns the result for further checks.
fn check(text: &str, source: &Path, limits: &Limits) -> Result<(), TestCaseError> {
    let _dog = watchdog();
    let base = CountingAlloc::start();
    let result = parse_str(text, source, limits);
    let peak = CountingAlloc::peak_above(base);
    prop_assert!(
        peak <= cap(text.len()),
        "{} bytes of text allocated {peak} bytes (cap {})",
        text.len(),
        cap(text.len())
    );
    if let Err(e) = result {
        check_error(&e, text, source)?;
    }
    Ok(())
}

/// A parse error names the file and a 1-based line that holds a command, in `file:line: message`.
fn check_error(e: &SceneError, text: &str, source: &Path) -> Result<(), TestCaseError> {
    let lines: Vec<&str> = text.split('\n').collect();
    prop_assert!(e.line >= 1 && e.line <= lines.len(), "line {} of {}: {e}", e.line, lines.len());
    let content = lines[e.line - 1].split('#').next().unwrap_or_default();
    prop_assert!(!content.trim_matches(|c: char| c.is_ascii_whitespace()).is_empty(), "error on a blank line: {e}");
    prop_assert!(!e.message.is_empty() && e.message.len() < 400, "message: {:?}", e.message);
    let shown = e.to_string();
    prop_assert!(shown.starts_with(&format!("{}:{}: ", source.display(), e.line)), "{shown}");
    Ok(())
}

/// The CSE168 corpus and strata's own scenes, read once.
fn files() -> &'static [(PathBuf, String)] {
    static FILES: OnceLock<Vec<(PathBuf, String)>> = OnceLock::new();
    FILES.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let corpus = common::corpus_required();
        let mut dirs = vec![root.join("scenes")];
        dirs.extend(["hw1", "hw2", "hw3", "hw4"].map(|h| corpus.join(h)));
        let mut out = vec![];
        for d in dirs {
            let Ok(entries) = std::fs::read_dir(&d) else { continue };
            let mut paths: Vec<PathBuf> =
                entries.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "test")).collect();
            paths.sort();
            for p in paths {
                if let Ok(t) = std::fs::read_to_string(&p) {
                    out.push((p, t));
                }
            }
        }
        assert!(!out.is_empty(), "no scene files to mutate");
        out
    })
}

const COMMANDS: [&str; 34] = [
    "size",
    "output",
    "camera",
    "spp",
    "gamma",
    "maxdepth",
    "maxverts",
    "vertex",
    "tri",
    "sphere",
    "pushTransform",
    "popTransform",
    "translate",
    "rotate",
    "scale",
    "diffuse",
    "specular",
    "shininess",
    "emission",
    "ambient",
    "brdf",
    "roughness",
    "quadLight",
    "point",
    "directional",
    "attenuation",
    "integrator",
    "lightsamples",
    "lightstratify",
    "nexteventestimation",
    "russianroulette",
    "importancesampling",
    "Vertex",
    "tri#",
];

const NASTY: [&str; 30] = [
    "nan",
    "NaN",
    "-inf",
    "inf",
    "1e39",
    "-1e39",
    "-1",
    "0",
    "-0",
    "1e-45",
    "99999999999999999999",
    "4294967296",
    "18446744073709551616",
    "9e15",
    "1e15",
    "2.5",
    "0x10",
    "+",
    "-",
    ".",
    "e5",
    "x",
    "é",
    "\u{0}",
    "\u{feff}",
    "on",
    "ggx",
    "pathtracer",
    "#",
    "1e308",
];

/// One token: a small integer, an arbitrary finite or special float, or a nasty string.
fn token() -> impl Strategy<Value = String> {
    prop_oneof![
        (-3i64..40).prop_map(|v| v.to_string()),
        any::<f32>().prop_map(|v| v.to_string()),
        (-1e4f64..1e4).prop_map(|v| format!("{v:e}")),
        prop::sample::select(&NASTY[..]).prop_map(str::to_string),
        "[ -~]{0,12}",
    ]
}

/// One line: a command (or garbage word) and up to 13 tokens, or free text.
fn line() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (prop::sample::select(&COMMANDS[..]), prop::collection::vec(token(), 0..14))
            .prop_map(|(c, t)| format!("{c} {}", t.join(" "))),
        1 => "[ -~\t\r]{0,40}",
        1 => any::<String>().prop_map(|s| s.chars().take(40).collect()),
    ]
}

/// Edits of a scene file's lines.
#[derive(Clone, Debug)]
enum Edit {
    Delete(usize),
    Duplicate(usize, u8),
    Swap(usize, usize),
    ReplaceToken(usize, usize, String),
    InsertToken(usize, usize, String),
    InsertLine(usize, String),
    TruncateBytes(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    let i = any::<usize>();
    prop_oneof![
        i.prop_map(Edit::Delete),
        (i, 1u8..20).prop_map(|(a, n)| Edit::Duplicate(a, n)),
        (i, i).prop_map(|(a, b)| Edit::Swap(a, b)),
        (i, 0usize..14, token()).prop_map(|(a, t, s)| Edit::ReplaceToken(a, t, s)),
        (i, 0usize..14, token()).prop_map(|(a, t, s)| Edit::InsertToken(a, t, s)),
        (i, line()).prop_map(|(a, l)| Edit::InsertLine(a, l)),
        i.prop_map(Edit::TruncateBytes),
    ]
}

/// Applies `edits` to `text`.
fn mutate(text: &str, edits: &[Edit]) -> String {
    let mut lines: Vec<String> = text.split('\n').map(str::to_string).collect();
    let mut truncate = None;
    for e in edits {
        let n = lines.len().max(1);
        match e {
            Edit::Delete(i) if !lines.is_empty() => {
                lines.remove(i % n);
            }
            Edit::Duplicate(i, k) if !lines.is_empty() => {
                let l = lines[i % n].clone();
                for _ in 0..*k {
                    lines.insert(i % n, l.clone());
                }
            }
            Edit::Swap(a, b) if !lines.is_empty() => lines.swap(a % n, b % n),
            Edit::ReplaceToken(i, t, s) | Edit::InsertToken(i, t, s) if !lines.is_empty() => {
                let mut toks: Vec<String> = lines[i % n].split_ascii_whitespace().map(str::to_string).collect();
                let at = t % (toks.len() + 1);
                if matches!(e, Edit::ReplaceToken(..)) && at < toks.len() {
                    toks[at] = s.clone();
                } else {
                    toks.insert(at, s.clone());
                }
                lines[i % n] = toks.join(" ");
            }
            Edit::InsertLine(i, l) => lines.insert(i % (lines.len() + 1), l.clone()),
            Edit::TruncateBytes(i) => truncate = Some(*i),
            _ => {}
        }
    }
    let mut out = lines.join("\n");
    if let Some(i) = truncate {
        let mut cut = i % (out.len() + 1);
        while !out.is_char_boundary(cut) {
            cut -= 1;
        }
        out.truncate(cut);
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, failure_persistence: None, ..ProptestConfig::default() })]

    /// Random scene files built from the format's commands and hostile tokens.
    #[test]
    fn random_scenes_never_panic_and_fail_with_a_line(lines in prop::collection::vec(line(), 0..80)) {
        let text = lines.join("\n");
        check(&text, Path::new("random.test"), &Limits::default())?;
        // Tight limits exercise every cap's error path on the same inputs.
        let tight = Limits { max_pixels: 64, max_side: 16, max_vertices: 4, max_primitives: 3, max_spp: 8, max_depth: 3,
            max_light_samples: 2, max_transform_depth: 2, ..Limits::default() };
        check(&text, Path::new("random.test"), &tight)?;
    }

    /// Mutations of the corpus and of scenes/*.test: deleted, duplicated, swapped and inserted lines,
    /// replaced and inserted tokens, truncation at any byte.
    #[test]
    fn mutated_scene_files_never_panic_and_fail_with_a_line(
        file in any::<prop::sample::Index>(),
        edits in prop::collection::vec(edit(), 1..8),
    ) {
        let (path, text) = file.get(files());
        let mutated = mutate(text, &edits);
        check(&mutated, path, &Limits::default())?;
    }
}

/// Deterministic worst cases for the allocation cap: the densest records the format has, and
/// numbers that ask for a lot (`maxverts`, `size`, `spp`) without the text to back them.
#[test]
fn dense_and_greedy_inputs_stay_under_the_cap() {
    let cases = [
        "sphere 0 0 0 1\n".repeat(20_000),
        "vertex 0 0 0\n".to_string() + &"tri 0 0 0\n".repeat(20_000),
        (0..5_000).map(|i| format!("diffuse {i} 0 0\nsphere 0 0 0 1\n")).collect::<String>(),
        "point 0 0 0 1 1 1\n".repeat(20_000),
        "pushTransform\n".repeat(4_096),
        "maxverts 1000000000000000\nsize 65536 4096\nspp 16777216\nlightsamples 1048576\nmaxdepth 1000000\n"
            .to_string(),
        format!("vertex {} 0 0\n", "1".repeat(1 << 20)),
    ];
    for text in &cases {
        let base = CountingAlloc::start();
        let r = parse_str(text, Path::new("dense.test"), &Limits::default());
        let peak = CountingAlloc::peak_above(base);
        let head: String = text.chars().take(30).collect();
        assert!(
            peak <= cap(text.len()),
            "{head:?}...: {} bytes allocated {peak} (cap {})",
            text.len(),
            cap(text.len())
        );
        if let Err(e) = r {
            // A 1 MiB token is shown shortened, not copied into the message.
            assert!(e.line >= 1 && e.message.len() < 400, "{head:?}...: {} byte message", e.message.len());
        }
    }
}

/// Every resource cap: the error names the limit and says how to raise it, and `--limit` raises it.
#[test]
fn resource_caps_name_the_limit_and_how_to_raise_it() {
    let parse = |text: &str, limits: &Limits| parse_str(text, Path::new("caps.test"), limits);
    let small = Limits {
        max_pixels: 100,
        max_side: 20,
        max_vertices: 2,
        max_primitives: 1,
        max_spp: 8,
        max_depth: 4,
        max_light_samples: 3,
        max_transform_depth: 1,
        ..Limits::default()
    };
    let cases = [
        ("size 11 10", "max_pixels", "size 10 10"),
        ("size 21 1", "max_side", "size 20 1"),
        ("vertex 0 0 0\nvertex 0 0 0\nvertex 0 0 0", "max_vertices", "vertex 0 0 0\nvertex 0 0 0"),
        ("sphere 0 0 0 1\nsphere 0 0 0 1", "max_primitives", "sphere 0 0 0 1"),
        ("spp 9", "max_spp", "spp 8"),
        ("maxdepth 5", "max_depth", "maxdepth 4"),
        ("lightsamples 4", "max_light_samples", "lightsamples 3"),
        ("pushTransform\npushTransform", "max_transform_depth", "pushTransform"),
    ];
    for (text, name, ok) in cases {
        let e = parse(text, &small).expect_err(text);
        let raise = format!("--limit {name}=N");
        assert!(e.message.contains(&raise) && e.line == text.lines().count(), "{text:?}: {e}");
        assert!(parse(ok, &small).is_ok(), "{ok:?} is within the limits");
        let mut raised = small;
        raised.set(&format!("{name}=1000")).unwrap();
        assert!(parse(text, &raised).is_ok(), "{text:?} after --limit {name}=1000");
    }
    let mut l = Limits::default();
    assert!(l.set("max_spp").unwrap_err().to_string().contains("NAME=VALUE"));
    assert!(l.set("max_sppp=3").unwrap_err().to_string().contains("max_spp"), "unknown names list the known ones");
    assert!(l.set("max_spp=-1").unwrap_err().to_string().contains("non-negative integer"));
    assert!(l.set("max_side=4294967296").unwrap_err().to_string().contains("at most 4294967295"));
}

/// The CLI's `--limit` raises the caps of the scene file and of the `--spp` / `--size` /
/// `--light-samples` overrides; without it the error names the limit and the flag.
#[test]
fn cli_limit_flag_raises_caps_and_overrides_are_capped() {
    let bin = env!("CARGO_BIN_EXE_strata");
    let dir = scratch("cli");
    let run = |args: &[&str]| {
        let o =
            std::process::Command::new(bin).args(args).arg("-o").arg(dir.join("img")).arg("--quiet").output().unwrap();
        (o.status.success(), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let base = ["render", "--size", "8x8", "--threads", "1"];
    let with = |extra: &[&'static str]| base.iter().copied().chain(extra.iter().copied()).collect::<Vec<_>>();
    // The built-in scene says `spp 4`.
    let (ok, err) = run(&with(&["--spp", "5", "--limit", "max_spp=4"]));
    assert!(!ok && err.contains("--spp 5") && err.contains("--limit max_spp=N"), "{err}");
    let (ok, err) = run(&with(&["--spp", "5", "--limit", "max_spp=5"]));
    assert!(ok, "{err}");
    let (ok, err) = run(&with(&["--spp", "1", "--limit", "max_pixels=63"]));
    assert!(!ok && err.contains("--limit max_pixels=N"), "{err}");
    let (ok, err) = run(&with(&["--spp", "1", "--light-samples", "5", "--limit", "max_light_samples=4"]));
    assert!(!ok && err.contains("--limit max_light_samples=N"), "{err}");
    // The built-in scene has `size 512 512`: a side limit below it fails in the file, with its line.
    let (ok, err) = run(&["render", "--spp", "1", "--limit", "max_side=100", "--threads", "1"]);
    assert!(!ok && err.contains("<built-in cornell>:3:") && err.contains("--limit max_side=N"), "{err}");
    let (ok, err) = run(&with(&["--limit", "bogus=1"]));
    assert!(!ok && err.contains("unknown limit") && err.contains("max_transform_depth"), "{err}");
}

/// Runs `strata ARGS` in `dir`; kills it and fails if it takes more than `secs` seconds.
fn run_within(dir: &Path, args: &[&str], secs: u64) -> (Option<i32>, String) {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .current_dir(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(secs);
    while child.try_wait().unwrap().is_none() {
        if std::time::Instant::now() > deadline {
            child.kill().ok();
            child.wait().ok();
            panic!("strata {args:?} still running after {secs} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let o = child.wait_with_output().unwrap();
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// `--threads` far above the cores is refused before any thread starts, naming the limit;
/// `--limit max_threads=N` raises it.
#[test]
fn cli_threads_above_the_cap_are_refused() {
    let dir = scratch("threads");
    let (code, err) =
        run_within(&dir, &["render", "--threads", "100000", "--spp", "1", "--size", "8x8", "-o", "t"], 20);
    assert!(code == Some(1) && err.contains("--threads 100000") && err.contains("--limit max_threads=N"), "{err}");
    let (code, err) = run_within(
        &dir,
        &["render", "--threads", "3", "--limit", "max_threads=3", "--spp", "1", "--size", "8x8", "-o", "t"],
        60,
    );
    assert_eq!(code, Some(0), "{err}");
}

/// A missing output or checkpoint directory fails before rendering: at a spp that would take
/// minutes, the command returns at once and names the directory.
#[test]
fn cli_unwritable_outputs_fail_before_rendering() {
    let dir = scratch("paths");
    let missing = dir.join("no-such-dir");
    let m = missing.display().to_string();
    let slow = ["render", "--spp", "100000", "--size", "256x256", "--threads", "1"];
    let cases: [Vec<String>; 3] = [
        vec!["-o".into(), format!("{m}/img")],
        vec!["-o".into(), "img".into(), "--checkpoint".into(), format!("{m}/c.ckpt")],
        vec!["-o".into(), "img".into(), "--stats".into(), format!("{m}/s.json")],
    ];
    for extra in cases {
        let args: Vec<&str> = slow.iter().copied().chain(extra.iter().map(String::as_str)).collect();
        let (code, err) = run_within(&dir, &args, 20);
        assert!(code == Some(1) && err.contains(&m) && err.contains("cannot write"), "{extra:?}: {err}");
    }
    assert!(!dir.join("img.png").exists(), "nothing was rendered");
}

/// A sampler asked for more points than it has distinct ones is refused, naming the limit and
/// Sobol; at its period it renders.
#[test]
fn cli_sampler_past_its_period_is_refused() {
    let dir = scratch("period");
    let base = ["render", "--size", "4x4", "--threads", "1", "-o", "p"];
    let with = |extra: &[&'static str]| base.iter().copied().chain(extra.iter().copied()).collect::<Vec<_>>();
    let (code, err) = run_within(&dir, &with(&["--spp", "8192", "--pixel-sampler", "pmj02"]), 20);
    assert!(code == Some(1) && err.contains("pmj02 has 4096 distinct points") && err.contains("8192 spp"), "{err}");
    assert!(err.contains("--pixel-sampler sobol"), "{err}");
    let light = with(&["--integrator", "direct", "--spp", "64", "--light-samples", "128", "--light-sampler", "pmj02"]);
    let (code, err) = run_within(&dir, &light, 20);
    assert!(code == Some(1) && err.contains("4096") && err.contains("--light-sampler sobol"), "{err}");
    let (code, err) = run_within(&dir, &with(&["--spp", "4096", "--pixel-sampler", "pmj02"]), 120);
    assert_eq!(code, Some(0), "{err}");
}

/// SIGTERM while a big OBJ is still loading exits promptly with code 130 and writes nothing
/// (before, the render started, traced a pass of nothing and wrote an image and a checkpoint).
#[test]
fn cli_sigterm_during_loading_exits_promptly() {
    let dir = scratch("signal");
    let (code, err) = run_within(&dir, &["gen-mesh", "big.obj", "--triangles", "2000000"], 120);
    assert_eq!(code, Some(0), "{err}");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(["render", "big.obj", "--spp", "1", "--size", "8x8", "--threads", "1", "-o", "big"])
        .current_dir(&dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(400));
    let sent = std::time::Instant::now();
    let kill = std::process::Command::new("kill").args(["-TERM", &child.id().to_string()]).status().unwrap();
    assert!(kill.success());
    while child.try_wait().unwrap().is_none() && sent.elapsed().as_secs() < 10 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let exited = child.try_wait().unwrap();
    if exited.is_none() {
        child.kill().ok();
    }
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(exited.is_some(), "still running 10 s after SIGTERM: {err}");
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted before rendering started"), "{err}");
    assert!(!dir.join("big.png").exists() && !dir.join("big.ckpt").exists(), "nothing written");
}

/// An OBJ without emitters gets a default light (announced), so it renders lit; with
/// `--no-default-light` it stays black. `.test` scenes get none.
#[test]
fn unlit_obj_gets_a_default_light() {
    let dir = scratch("light");
    let obj = dir.join("model.obj");
    let (code, err) = run_within(&dir, &["gen-mesh", "model.obj", "--triangles", "2000"], 60);
    assert_eq!(code, Some(0), "{err}");
    std::fs::remove_file(dir.join("model.mtl")).ok(); // no materials: no emitters
    let opts = |no_default_light| strata::session::RenderOptions {
        scene: Some(obj.clone()),
        size: Some((32, 24)),
        spp: Some(4),
        threads: 1,
        no_default_light,
        ..Default::default()
    };
    let mean = |o| {
        let f = strata::session::render_to_film(&o).unwrap().film;
        let m = f.mean();
        m.iter().map(|p| f64::from(p[0] + p[1] + p[2]) / 3.0).sum::<f64>() / m.len() as f64
    };
    let lit = mean(opts(false));
    assert!(lit > 0.05, "mean {lit} with the default light");
    assert_eq!(mean(opts(true)), 0.0, "--no-default-light keeps it unlit");
    let (code, err) = run_within(&dir, &["render", "model.obj", "--spp", "1", "--size", "8x8", "-o", "m"], 60);
    assert!(code == Some(0) && err.contains("no light; added a default area light"), "{err}");
    let (_, err) = run_within(&dir, &["render", "--spp", "1", "--size", "8x8", "-o", "c"], 60);
    assert!(!err.contains("default area light"), "{err}");
    // The real-world unlit models of the issue (the hold-out corpus).
    let corpus = common::shared_required("STRATA_OBJ_WILD", "corpora/obj-wild", "SOURCES.md");
    for m in ["scan-stanford-bunny/stanford-bunny.obj", "sponza-dabrovic-2005/sponza.obj"] {
        let p = corpus.join(m);
        let o = strata::session::RenderOptions { scene: Some(p), ..opts(false) };
        let lit = mean(o);
        assert!(lit > 0.05, "{m}: mean {lit} with the default light");
    }
}

// Issue 25 (the same pixels on every node, never a lost render, never a clobbered file): one
// module per group of findings, sharing the runner in `hostile/run.rs`.
#[path = "it/common.rs"]
mod common;
#[path = "hostile/cpus.rs"]
mod cpus;
#[path = "hostile/outputs.rs"]
mod outputs;
#[path = "hostile/resources.rs"]
mod resources;
// Issue 32: no subcommand clobbers an input, reads without bound, or hangs.
#[path = "hostile/robust.rs"]
mod robust;
#[path = "hostile/run.rs"]
mod run;
#[path = "hostile/xml.rs"]
mod xml;

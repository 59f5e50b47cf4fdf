//! Renders that survive: SIGKILL mid-render then resume, SIGTERM, shards rendered by several
//! processes then merged, time budgets, and refusal of checkpoints or parts that do not belong.
//! Every comparison is of bits: the PNG files byte for byte and the EXR pixels (RGB and variance).

use crate::common;

use common::{strata, tmpdir};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The diffuse Cornell box path traced at 64x48: big enough to be interrupted, small for CI.
fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_diffuse_path.test")
}

/// `render SCENE --size 64x48 --spp SPP --seed 11 -q` plus `extra`, output stem `out`.
fn render_cmd(spp: u32, out: &Path, extra: &[&str]) -> Command {
    let mut c = strata();
    c.arg("render").arg(scene()).args(["-q", "--spp"]).arg(spp.to_string()).arg("-o").arg(out);
    for (flag, default) in [("--size", "64x48"), ("--seed", "11")] {
        if !extra.contains(&flag) {
            c.args([flag, default]);
        }
    }
    c.args(extra);
    c
}

fn run_ok(mut c: Command) -> String {
    let r = c.output().unwrap();
    assert!(r.status.success(), "{:?} failed: {}", c, String::from_utf8_lossy(&r.stderr));
    String::from_utf8_lossy(&r.stdout).into_owned()
}

fn run_err(mut c: Command) -> String {
    let r = c.output().unwrap();
    assert!(!r.status.success(), "{c:?} should fail");
    String::from_utf8_lossy(&r.stderr).into_owned()
}

/// RGB and variance bits of OUT.exr, the bytes of OUT.png, and the EXR metadata.
fn image(stem: &Path) -> (Vec<u32>, Vec<u8>, std::collections::HashMap<String, String>) {
    let img = strata::film::read_exr(&stem.with_extension("exr")).unwrap();
    let var = img.variance.expect("variance layer");
    let bits = img.rgb.iter().chain(&var).flat_map(|p| p.map(f32::to_bits)).collect();
    (bits, std::fs::read(stem.with_extension("png")).unwrap(), img.meta.into_iter().collect())
}

fn assert_same_image(a: &Path, b: &Path) {
    let (ia, pa, _) = image(a);
    let (ib, pb, _) = image(b);
    assert!(ia.iter().any(|&v| v != 0), "a black image proves nothing");
    assert!(ia == ib, "{} and {} differ in EXR pixels", a.display(), b.display());
    assert!(pa == pb, "{} and {} differ in PNG bytes", a.display(), b.display());
}

/// Samples held by a checkpoint file.
fn held(ckpt: &Path) -> std::ops::Range<u32> {
    strata::checkpoint::read(ckpt).unwrap().1.samples()
}

/// Starts a render that checkpoints after every pass, waits for its first checkpoint, and kills it
/// with `signal` while it is still rendering; returns its exit status.
fn start_and_kill(spp: u32, out: &Path, ckpt: &Path, signal: &str) -> std::process::ExitStatus {
    let mut c = render_cmd(spp, out, &["--checkpoint-every", "0", "--threads", "2"]);
    c.arg("--checkpoint").arg(ckpt).stdout(Stdio::null()).stderr(Stdio::null());
    let mut child = c.spawn().unwrap();
    let t0 = Instant::now();
    while !ckpt.exists() {
        assert!(child.try_wait().unwrap().is_none(), "the render ended before its first checkpoint");
        assert!(t0.elapsed() < Duration::from_secs(60), "no checkpoint after 60 s");
        std::thread::sleep(Duration::from_millis(2));
    }
    assert!(child.try_wait().unwrap().is_none(), "the render finished before the kill: make it longer");
    let st = Command::new("kill").args(["-s", signal]).arg(child.id().to_string()).status().unwrap();
    assert!(st.success());
    child.wait().unwrap()
}

#[test]
fn sigkill_mid_render_then_resume_is_bit_identical() {
    let d = tmpdir("kill");
    let spp = 256;
    run_ok(render_cmd(spp, &d.join("whole"), &["--threads", "1"]));
    let ckpt = d.join("run.ckpt");
    let status = start_and_kill(spp, &d.join("resumed"), &ckpt, "KILL");
    assert!(!status.success(), "killed");
    let at = held(&ckpt);
    assert!(at.start == 0 && at.end > 0 && at.end < spp, "killed mid-render: checkpoint holds {at:?}");
    assert!(!d.join("resumed.exr").exists(), "SIGKILL writes nothing more");
    // Resume (with another thread count: still the same bits).
    let mut c = render_cmd(spp, &d.join("resumed"), &["--threads", "2"]);
    c.arg("--resume").arg(&ckpt);
    run_ok(c);
    assert_same_image(&d.join("whole"), &d.join("resumed"));
    assert_eq!(held(&ckpt), 0..spp, "the resumed run checkpoints into its --resume file");
    let (_, _, meta) = image(&d.join("resumed"));
    assert_eq!(meta["strata.spp"], spp.to_string());
}

#[test]
fn sigterm_writes_checkpoint_and_image_then_resumes_bit_identically() {
    let d = tmpdir("term");
    let spp = 256;
    let ckpt = d.join("t.ckpt");
    let status = start_and_kill(spp, &d.join("t"), &ckpt, "TERM");
    assert_eq!(status.code(), Some(130), "interrupted exit status");
    let at = held(&ckpt);
    assert!(at.end > 0 && at.end < spp, "stopped mid-render: {at:?}");
    let (_, _, meta) = image(&d.join("t"));
    assert_eq!(meta["strata.spp"], at.end.to_string(), "the image of the samples done is written");
    let mut c = render_cmd(spp, &d.join("t"), &[]);
    c.arg("--resume").arg(&ckpt);
    run_ok(c);
    run_ok(render_cmd(spp, &d.join("whole"), &[]));
    assert_same_image(&d.join("whole"), &d.join("t"));
}

/// The GNU-parallel recipe of examples/cluster, done with std::process: several processes each
/// render one `--samples` range at the same time, then `merge`.
#[test]
fn shards_from_parallel_processes_merge_bit_identically() {
    let d = tmpdir("shards");
    let spp = 100;
    run_ok(render_cmd(spp, &d.join("whole"), &[]));
    // Uneven, unaligned ranges; started together, one thread each.
    let ranges = [(0u32, 37u32), (37, 64), (64, 65), (65, 100)];
    let children: Vec<_> = ranges
        .iter()
        .map(|&(a, b)| {
            let mut c = render_cmd(spp, &d.join(format!("part{a}")), &["--threads", "1"]);
            c.arg("--samples").arg(format!("{a}..{b}")).stdout(Stdio::null()).stderr(Stdio::piped());
            c.spawn().unwrap()
        })
        .collect();
    for ch in children {
        let r = ch.wait_with_output().unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    }
    let parts: Vec<PathBuf> = ranges.iter().rev().map(|&(a, _)| d.join(format!("part{a}.ckpt"))).collect();
    let mut c = strata();
    c.arg("merge").args(&parts).arg("-o").arg(d.join("merged"));
    let said = run_ok(c);
    assert!(said.contains("merged 4 parts: 100 spp"), "{said}");
    assert_same_image(&d.join("whole"), &d.join("merged"));
    // Merged metadata: total spp, total CPU seconds (sum of the parts'), the parts.
    let (_, _, meta) = image(&d.join("merged"));
    assert_eq!(meta["strata.spp"], "100");
    assert_eq!(meta["strata.part_count"], "4");
    for &(a, b) in &ranges {
        assert!(meta["strata.parts"].contains(&format!("part{a}.ckpt ({a}..{b})")), "{}", meta["strata.parts"]);
    }
    let cpu: f64 = parts.iter().map(|p| strata::checkpoint::read(p).unwrap().0.cpu_seconds).sum();
    let got: f64 = meta["strata.cpu_seconds"].parse().unwrap();
    assert!(cpu > 0.0 && (got - cpu).abs() < 1e-5, "cpu seconds {got} vs parts {cpu}");

    // Gaps, overlaps and strangers are refused with the file names.
    let merge_err = |files: &[PathBuf]| {
        let mut c = strata();
        c.arg("merge").args(files).arg("-o").arg(d.join("bad"));
        run_err(c)
    };
    let e = merge_err(&[parts[0].clone(), parts[2].clone(), parts[3].clone()]);
    assert!(e.contains("samples 64..65 are missing"), "{e}");
    let e = merge_err(&parts[1..]);
    assert!(e.contains("samples 65..100") && e.contains("missing"), "{e}");
    let mut c = render_cmd(spp, &d.join("over"), &[]);
    c.args(["--samples", "30..64"]);
    run_ok(c);
    let e = merge_err(&[parts[3].clone(), d.join("over.ckpt"), parts[1].clone(), parts[0].clone()]);
    assert!(e.contains("overlap") && e.contains("over.ckpt (30..64)"), "{e}");
    let mut c = render_cmd(spp, &d.join("other"), &["--pixel-sampler", "sobol"]);
    c.args(["--samples", "64..65"]);
    run_ok(c);
    let e = merge_err(&[parts[3].clone(), d.join("other.ckpt"), parts[2].clone(), parts[0].clone()]);
    assert!(e.contains("does not belong") && e.contains("pixel_sampler"), "{e}");
    // A part that did not finish its range (as a killed shard leaves it) is refused.
    let (mut h, f) = strata::checkpoint::read(&parts[0]).unwrap();
    h.target = [65, 120];
    strata::checkpoint::write(&d.join("unfinished.ckpt"), &h, &f).unwrap();
    let e = merge_err(&[parts[3].clone(), parts[2].clone(), parts[1].clone(), d.join("unfinished.ckpt")]);
    assert!(e.contains("unfinished part") && e.contains("samples 65..100 of its range 65..120"), "{e}");
    assert!(!d.join("bad.exr").exists());
}

#[test]
fn resume_refuses_other_scene_options_and_broken_files() {
    let d = tmpdir("refuse");
    let ck = d.join("a.ckpt");
    let mut c = render_cmd(32, &d.join("a"), &["--samples", "0..16"]);
    c.arg("--checkpoint").arg(&ck);
    run_ok(c);
    let resume_spp = |spp: u32, extra: &[&str], scene: Option<&Path>| {
        let mut c = render_cmd(spp, &d.join("b"), extra);
        if let Some(s) = scene {
            let mut args: Vec<std::ffi::OsString> = c.get_args().map(|a| a.to_owned()).collect();
            args[1] = s.as_os_str().to_owned();
            c = strata();
            c.args(args);
        }
        c.arg("--resume").arg(&ck);
        run_err(c)
    };
    let resume = |extra: &[&str], scene: Option<&Path>| resume_spp(32, extra, scene);
    let e = resume(&["--seed", "12"], None);
    assert!(e.contains("cannot resume") && e.contains("seed 11 (this render: 12)"), "{e}");
    // More spp extends a render only when its layouts are progressive; this one's default
    // (multijitter, before issue 33 stratified) is laid out for its count.
    let e = resume_spp(64, &[], None);
    assert!(e.contains("cannot extend it from 32 to 64 spp") && e.contains("`multijitter`"), "{e}");
    let e = resume(&["--size", "32x24"], None);
    assert!(e.contains("64x48"), "{e}");
    // The same scene with one byte changed is another scene.
    let other = d.join("other.test");
    let mut text = std::fs::read_to_string(scene()).unwrap();
    text.push_str("\n# changed\n");
    std::fs::write(&other, text).unwrap();
    let e = resume(&[], Some(&other));
    assert!(e.contains("another scene"), "{e}");
    // A range the checkpoint does not start.
    let e = resume(&["--samples", "8..32"], None);
    assert!(e.contains("do not start the requested range 8..32"), "{e}");
    // Truncated and corrupt files.
    let bytes = std::fs::read(&ck).unwrap();
    std::fs::write(&ck, &bytes[..bytes.len() - 100]).unwrap();
    let e = resume(&[], None);
    assert!(e.contains("a.ckpt") && e.contains("truncated"), "{e}");
    let mut flipped = bytes.clone();
    let at = bytes.len() - 1000;
    flipped[at] ^= 1;
    std::fs::write(&ck, &flipped).unwrap();
    assert!(resume(&[], None).contains("checksum"));
    std::fs::write(&ck, b"hello").unwrap();
    assert!(resume(&[], None).contains("not a usable strata checkpoint"));
    // Bad flag values are clear errors.
    assert!(run_err(render_cmd(32, &d.join("c"), &["--samples", "5..3"])).contains("A < B"));
    assert!(run_err(render_cmd(32, &d.join("c"), &["--samples", "0..33"])).contains("<= spp (32)"));
    assert!(run_err(render_cmd(32, &d.join("c"), &["--time-budget", "0"])).contains("--time-budget"));
}

#[test]
fn time_budget_renders_whole_passes_and_records_spp() {
    let d = tmpdir("budget");
    let stats = d.join("s.json");
    let mut c = render_cmd(4000, &d.join("b"), &["--time-budget", "0.5", "--threads", "1"]);
    c.arg("--stats").arg(&stats);
    run_ok(c);
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    let spp = j["spp"].as_u64().unwrap();
    assert!((1..=4000).contains(&spp), "spp reached {spp}");
    assert_eq!(j["layout"], "time-budget");
    let (_, _, meta) = image(&d.join("b"));
    assert_eq!(meta["strata.spp"], spp.to_string());
    // The default (stratified) needs its count: equal time runs the progressive sobol, and says so.
    assert_eq!(meta["strata.pixel_sampler"], "sobol", "budget renders use progressive layouts");
    assert_eq!(j["pixel_sampler"], "sobol");
    assert_eq!(j["rays"]["camera"].as_u64().unwrap(), 64 * 48 * spp, "whole passes: every pixel got spp samples");
    // --spp caps a budgeted render (a budget far larger than the 24 samples need).
    let mut c = render_cmd(24, &d.join("c"), &["--time-budget", "300"]);
    c.arg("--stats").arg(&stats);
    run_ok(c);
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(j["spp"], 24);
    // A named progressive sampler is kept; a named one that needs its count is refused, with a
    // message naming the progressive ones (never swapped silently).
    let mut c = render_cmd(24, &d.join("p"), &["--time-budget", "300", "--sampler", "pmj02"]);
    c.arg("--stats").arg(&stats);
    run_ok(c);
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!((j["pixel_sampler"].as_str(), j["sampler"].as_str()), (Some("pmj02"), Some("pmj02")));
    for (flag, name) in [("--pixel-sampler", "stratified"), ("--sampler", "zsobol"), ("--light-sampler", "grid-center")]
    {
        let err = run_err(render_cmd(24, &d.join("r"), &["--time-budget", "1", flag, name]));
        assert!(
            err.contains(flag)
                && err.contains(name)
                && err.contains("progressive samplers: independent, halton, sobol, pmj02"),
            "{err}"
        );
    }
}

/// A checkpoint covers every input file: a change to an OBJ included by the `.test` file (which
/// itself is unchanged) makes another scene; so does another `--clamp`.
#[test]
fn resume_refuses_a_changed_included_obj_and_another_clamp() {
    let d = tmpdir("included");
    let obj = "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 3 2\nf 1 4 3\n";
    std::fs::write(d.join("floor.obj"), obj).unwrap();
    let test = "size 16 16\ncamera 0 2 3 0 0 0 0 1 0 45\nintegrator pathtracer\nnexteventestimation on\n\
                quadLight -0.2 1.5 -0.2 0 0 0.4 0.4 0 0 10 10 10\ndiffuse 0.5 0.5 0.5\nobj floor.obj\n";
    let scene = d.join("s.test");
    std::fs::write(&scene, test).unwrap();
    let ck = d.join("s.ckpt");
    let cmd = |extra: &[&str]| {
        let mut c = strata();
        c.arg("render").arg(&scene).args(["-q", "--spp", "8", "-o"]).arg(d.join("out")).args(extra);
        c
    };
    let mut c = cmd(&["--samples", "0..4"]);
    c.arg("--checkpoint").arg(&ck);
    run_ok(c);
    let mut c = cmd(&["--clamp", "2"]);
    c.arg("--resume").arg(&ck);
    let e = run_err(c);
    assert!(e.contains("clamp"), "{e}");
    std::fs::write(d.join("floor.obj"), obj.replace("v 1 0 1", "v 1 0 1.001")).unwrap();
    let mut c = cmd(&[]);
    c.arg("--resume").arg(&ck);
    let e = run_err(c);
    assert!(e.contains("another scene"), "{e}");
}

/// Issue 31: `--resume` with a larger `--spp` continues a finished render whose layouts are
/// progressive, bit for bit as rendering the larger count at once (RGB, the variance layer, the
/// PNG), for `render` and `reference` (a checkpointed reference is one render: its variance layer
/// comes from the film's moments) and for every progressive sampler. Only spp may grow: fewer spp
/// or another option is refused as before, and a layout bound to its count refuses, naming it.
/// (Before, any other spp was refused: "spp 256 (this render: 512)".)
#[test]
fn resume_with_more_spp_extends_a_finished_render_bit_identically() {
    let d = tmpdir("extend");
    let cmd = |sub: &str, spp: u32, out: &str, extra: &[&str]| {
        let mut c = strata();
        c.arg(sub).arg(scene()).args(["-q", "--seed", "11", "--size", "32x24", "--threads", "2", "--spp"]);
        c.arg(spp.to_string()).arg("-o").arg(d.join(out)).args(extra);
        c
    };
    // `reference` with its default replicas (8 of 32, then of 64 spp: its checkpoint holds each
    // replica's state) and with one render (the i.i.d. variance layer from the film's moments).
    for (sub, extra, tag) in [
        ("render", &[][..], "render"),
        ("reference", &[][..], "reference"),
        ("reference", &["--replicas", "1"][..], "ref1"),
    ] {
        let ck = d.join(format!("{tag}.ckpt"));
        let ck = ck.to_str().unwrap();
        let flags = |more: &[&'static str]| [&["--sampler", "sobol"][..], extra, more].concat();
        run_ok(cmd(sub, 512, &format!("{tag}-once"), &flags(&[])));
        run_ok(cmd(sub, 256, &format!("{tag}-256"), &[flags(&[]), vec!["--checkpoint", ck]].concat()));
        run_ok(cmd(sub, 512, &format!("{tag}-512"), &[flags(&[]), vec!["--resume", ck]].concat()));
        assert_same_image(&d.join(format!("{tag}-once")), &d.join(format!("{tag}-512")));
        let (_, _, meta) = image(&d.join(format!("{tag}-512")));
        assert_eq!(meta.get("strata.spp").map(String::as_str), Some("512"));
        if tag == "reference" {
            // Every replica extended: 8 of 64 spp (`checkpoint::read_replicas` reads them back
            // in `checkpoint/format.rs`'s tests).
            assert_eq!(meta.get("strata.replicas").map(String::as_str), Some("8"), "{meta:?}");
            assert_eq!(meta.get("strata.replica_spp").map(String::as_str), Some("64"), "{meta:?}");
        } else {
            assert_eq!(held(Path::new(ck)), 0..512, "the checkpoint holds the extended render");
        }
    }
    // Every progressive sampler, by a count that is no power of two, twice.
    for sampler in ["independent", "halton", "pmj02"] {
        let ck = d.join(format!("{sampler}.ckpt"));
        let ck = ck.to_str().unwrap();
        run_ok(cmd("render", 40, &format!("{sampler}-once"), &["--sampler", sampler]));
        run_ok(cmd("render", 12, &format!("{sampler}-12"), &["--sampler", sampler, "--checkpoint", ck]));
        run_ok(cmd("render", 24, &format!("{sampler}-24"), &["--sampler", sampler, "--resume", ck]));
        run_ok(cmd("render", 40, &format!("{sampler}-40"), &["--sampler", sampler, "--resume", ck]));
        assert_same_image(&d.join(format!("{sampler}-once")), &d.join(format!("{sampler}-40")));
    }
    // Only spp may grow: fewer spp, or more spp with another option, is refused as before.
    let ck = d.join("render.ckpt");
    let ck = ck.to_str().unwrap();
    let e = run_err(cmd("render", 256, "x", &["--sampler", "sobol", "--resume", ck]));
    assert!(e.contains("cannot resume") && e.contains("spp 512 (this render: 256)"), "{e}");
    let e = run_err(cmd("render", 1024, "x", &["--sampler", "sobol", "--light-sampler", "halton", "--resume", ck]));
    assert!(e.contains(r#"light_sampler "sobol" (this render: "halton")"#), "{e}");
    assert!(e.contains("spp 512 (this render: 1024)"), "{e}");
    // A reference's checkpoint keeps its replicas: fewer is refused, naming them.
    let ck = d.join("reference.ckpt");
    let e = run_err(cmd(
        "reference",
        512,
        "x",
        &["--sampler", "sobol", "--replicas", "4", "--resume", ck.to_str().unwrap()],
    ));
    assert!(e.contains("holds 8 replicas, more than --replicas 4"), "{e}");
    // Count-bound layouts refuse, naming the layout and why.
    for (flags, name) in [
        (&["--sampler", "stratified"][..], "`stratified`"),
        (&["--sampler", "sobol", "--pixel-sampler", "zsobol"][..], "`zsobol`"),
        (&["--sampler", "sobol", "--light-sampler", "grid-center"][..], "`grid-center`"),
    ] {
        let ck = d.join("bound.ckpt");
        let ck = ck.to_str().unwrap();
        run_ok(cmd("render", 16, "bound", &[flags, &["--checkpoint", ck]].concat()));
        let e = run_err(cmd("render", 32, "bound", &[flags, &["--resume", ck]].concat()));
        assert!(e.contains("cannot extend it from 16 to 32 spp") && e.contains(name), "{e}");
        assert!(e.contains("total count") && e.contains("render 32 spp afresh"), "{e}");
        std::fs::remove_file(ck).unwrap();
    }
    // A point set that is not progressive (a 144-point Fibonacci lattice) is used in whole sets.
    let fib = d.join("fib144.txt");
    let text: String =
        (0..144).map(|i| format!("{} {}\n", f64::from(i) / 144.0, f64::from(i * 89 % 144) / 144.0)).collect();
    std::fs::write(&fib, text).unwrap();
    let spec = format!("file:{}", fib.display());
    let ck = d.join("fib.ckpt");
    let ck = ck.to_str().unwrap();
    run_ok(cmd("render", 16, "fib", &["--sampler", "sobol", "--pixel-sampler", &spec, "--checkpoint", ck]));
    let e = run_err(cmd("render", 32, "fib", &["--sampler", "sobol", "--pixel-sampler", &spec, "--resume", ck]));
    assert!(e.contains("cannot extend") && e.contains("not progressive") && e.contains("144 points"), "{e}");
}

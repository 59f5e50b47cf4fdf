//! Issue 32: no subcommand clobbers an input, reads without bound, or hangs. One test per finding
//! (the Embree configuration's is in `cpus.rs`); the first is one table of (subcommand, output
//! flag, input it names) cases generated from the subcommands' declared files
//! (`strata::plan::declared`), so a new flag is covered.

use super::run::{scratch, shell, strata, Run};
use std::fs;
use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use strata::files::Role;
use strata::plan::{declared, Decl, Names};

const SCENE: &str = "size 8 8\ncamera 0 0 3 0 0 0 0 1 0 45\npoint 0 0 3 1 1 1\ndiffuse 1 1 1\nsphere 0 0 0 1\n";
/// A UTK text point set: 16 points (valid under any file name).
const POINTS: &str = "0.1 0.2\n0.3 0.4\n0.5 0.6\n0.7 0.8\n0.15 0.25\n0.35 0.45\n0.55 0.65\n0.75 0.85\n\
0.12 0.22\n0.32 0.42\n0.52 0.62\n0.72 0.82\n0.17 0.27\n0.37 0.47\n0.57 0.67\n0.77 0.87\n";

/// The arguments a subcommand needs besides the attacked input and output (None: no case).
fn base(sub: &str) -> Option<Vec<&'static str>> {
    Some(match sub {
        "render" | "reference" => vec!["--size", "8x8", "--spp", "1", "-q"],
        "profile" | "rays" => vec!["--size", "8x8", "--spp", "1"],
        "compare" => vec!["--variant", "a=--sampler=independent", "--spp-ladder", "1,2", "--size", "8x8", "-q"],
        "merge" | "pointset" => vec![],
        _ => return None,
    })
}

/// Valid content for an input named by `decl` (the render's and compare's inputs are refused
/// before they are read, but a `file:` sampler is loaded while the command line is parsed).
fn content(dir: &Path, decl: &Decl) -> Vec<u8> {
    match (decl.subcommand, decl.flag) {
        ("merge", _) | (_, "--resume") => fs::read(dir.join("part.ckpt")).unwrap(),
        ("compare", "--reference") => fs::read(dir.join("ref.exr")).unwrap(),
        (_, f) if f.ends_with("sampler") || f == "the point set" => POINTS.as_bytes().to_vec(),
        _ => SCENE.as_bytes().to_vec(),
    }
}

/// The flag value that makes `out`'s first named file be `target`, and `target` for that.
fn aim(out: &Decl, case: usize) -> (String, String) {
    let name = format!("victim{case}");
    match out.names {
        Names::Stem(exts) => (name.clone(), format!("{name}.{}", exts[0])),
        Names::Dir(files) => (name.clone(), format!("{name}/{}", files[0])),
        _ => (name.clone(), name),
    }
}

/// Every declared output of every subcommand, naming each declared input of that subcommand in
/// turn, is refused before any work (exit 1, "the same file"), the input byte for byte as it was.
/// Before: profile, rays, compare, merge and the render's MTL and point sets were replaced, rc 0.
#[test]
fn no_output_flag_may_name_an_input_of_its_subcommand() {
    let dir = scratch("plan-table");
    fs::write(dir.join("s.test"), SCENE).unwrap();
    let setup = [
        vec!["render", "s.test", "--size", "8x8", "--spp", "2", "--samples", "0..1", "-o", "part", "-q"],
        vec!["reference", "s.test", "--size", "8x8", "--spp", "4", "-o", "ref", "-q"],
    ];
    for a in setup {
        let r = strata(&dir, &a, 60);
        assert_eq!(r.code, Some(0), "{a:?}: {}", r.err);
    }
    let decls = declared();
    let mut cases = 0;
    let mut failures = Vec::new();
    for out in decls.iter().filter(|d| d.role == Role::Output) {
        let Some(base_args) = base(out.subcommand) else { continue };
        for input in decls.iter().filter(|d| d.subcommand == out.subcommand && d.role == Role::Input) {
            // A render checkpointing to the file it resumes is how resuming works.
            if input.flag == "--resume" && out.flag == "--checkpoint" {
                continue;
            }
            cases += 1;
            let (value, target) = aim(out, cases);
            let path = dir.join(&target);
            fs::create_dir_all(path.parent().unwrap()).unwrap();
            let bytes = content(&dir, input);
            fs::write(&path, &bytes).unwrap();
            let mut a: Vec<String> = vec![out.subcommand.to_string()];
            match input.flag {
                f if f.starts_with("--") && f.ends_with("sampler") => {
                    a.extend([f.to_string(), format!("file:{target}")])
                }
                f if f.starts_with("--") => a.extend([f.to_string(), target.clone()]),
                _ => a.push(target.clone()),
            }
            if out.subcommand == "compare" && input.flag != "--reference" {
                a.extend(["--reference".to_string(), "ref.exr".to_string()]);
            }
            if out.subcommand == "merge" {
                a.push("part.ckpt".into());
            }
            a.extend(base_args.iter().map(|s| s.to_string()));
            match out.flag {
                "-o" => a.extend(["-o".to_string(), value]),
                f => a.push(format!("{f}={value}")),
            }
            let args: Vec<&str> = a.iter().map(String::as_str).collect();
            let r: Run = strata(&dir, &args, 60);
            let intact = fs::read(&path).ok().as_deref() == Some(&bytes[..]);
            if r.code != Some(1) || !r.err.contains("the same file") || !intact {
                failures.push(format!("{args:?}: exit {:?}, input intact: {intact}: {}", r.code, r.err.trim()));
            }
        }
    }
    assert!(cases >= 60, "{cases} cases");
    assert!(failures.is_empty(), "{} of {cases} cases failed:\n{}", failures.len(), failures.join("\n"));
}

/// Two outputs of one command naming one file, and a gen-mesh OBJ or MTL that is a link, a FIFO
/// or a device, are refused before any work; the link's target is untouched and nothing hangs.
/// Before: `profile --json p.json --svg p.json` wrote both there; gen-mesh wrote through the link
/// into `v1`, into a device, and hung on a FIFO.
#[test]
fn outputs_colliding_or_special_are_refused_for_every_subcommand() {
    let dir = scratch("plan-special");
    fs::write(dir.join("v1"), "precious").unwrap();
    std::os::unix::fs::symlink("v1", dir.join("l.obj")).unwrap();
    assert_eq!(shell(&dir, "mkfifo f.mtl && touch f.obj", &[], 10).code, Some(0));
    std::os::unix::fs::symlink("/dev/null", dir.join("d.mtl")).unwrap();
    for (args, says) in [
        (vec!["profile", "--size", "8x8", "--spp", "1", "--json", "p.json", "--svg", "p.json"], "the same file"),
        (vec!["gen-mesh", "--triangles", "100", "l.obj"], "is a symbolic link"),
        (vec!["gen-mesh", "--triangles", "100", "f.obj"], "is a device, FIFO or socket"),
        (vec!["gen-mesh", "--triangles", "100", "d.obj"], "is a symbolic link"),
        (vec!["pointset", "sobol", "--export", "e.txt", "--out", "o", "--points", "16"], ""),
    ] {
        let r = strata(&dir, &args, 20);
        if says.is_empty() {
            assert_eq!(r.code, Some(0), "{args:?}: {}", r.err);
            continue;
        }
        assert_eq!(r.code, Some(1), "{args:?}: {}", r.err);
        assert!(r.err.contains(says) && r.err.contains("nothing was written"), "{args:?}: {}", r.err);
    }
    assert_eq!(fs::read_to_string(dir.join("v1")).unwrap(), "precious");
    assert!(!dir.join("p.json").exists());
    // A size that does not fit is refused before it is allocated (before: `capacity overflow`, 101).
    let r = strata(&dir, &["gen-mesh", "--triangles", "9223372036854775807", "big.obj"], 20);
    assert!(r.code == Some(1) && r.err.contains("needs about"), "{:?}: {}", r.code, r.err);
}

/// New outputs get 0666 less the umask (0644 under umask 022), replaced ones keep their mode.
/// Before: 0600 whatever the umask.
#[test]
fn outputs_get_the_umask_mode_or_the_replaced_files() {
    let dir = scratch("modes");
    fs::write(dir.join("keep.json"), "{}").unwrap();
    fs::set_permissions(dir.join("keep.json"), fs::Permissions::from_mode(0o640)).unwrap();
    let script = r#"umask 022; exec "$STRATA" "$@""#;
    let a =
        ["render", "--size", "8x8", "--spp", "1", "-q", "-o", "img", "--stats", "keep.json", "--checkpoint", "c.ckpt"];
    let r = shell(&dir, script, &a, 60);
    assert_eq!(r.code, Some(0), "{}", r.err);
    let mode = |f: &str| fs::metadata(dir.join(f)).unwrap().permissions().mode() & 0o777;
    for f in ["img.exr", "img.png", "c.ckpt"] {
        assert_eq!(mode(f), 0o644, "{f}");
    }
    assert_eq!(mode("keep.json"), 0o640);
    let r = shell(&dir, script, &["gen-mesh", "--triangles", "100", "m.obj"], 60);
    assert_eq!(r.code, Some(0), "{}", r.err);
    assert_eq!((mode("m.obj"), mode("m.mtl")), (0o644, 0o644));
}

/// Devices, FIFOs and oversized files named as inputs fail at once with what they are, under a
/// 4 GB address-space limit (before: /dev/zero as a point set, sampler or merge part grew to
/// gigabytes; FIFOs as scene, OBJ, merge part, `--reference` or point set hung; a 2 GB sparse
/// point set was read whole).
#[test]
fn special_or_oversized_inputs_are_refused_before_reading() {
    let dir = scratch("bounded");
    assert_eq!(shell(&dir, "mkfifo fifo fifo.obj fifo.npy", &[], 10).code, Some(0));
    std::os::unix::fs::symlink("/dev/zero", dir.join("zc.ckpt")).unwrap();
    fs::File::create(dir.join("sparse.txt")).unwrap().set_len(2 << 30).unwrap();
    let script = r#"ulimit -v 4000000; exec "$STRATA" "$@""#;
    for (args, says) in [
        (vec!["pointset", "/dev/zero"], "is a device"),
        (vec!["render", "--size", "8x8", "--spp", "1", "--sampler", "file:/dev/zero", "-o", "z"], "is a device"),
        (vec!["merge", "-o", "x", "zc.ckpt"], "is a device"),
        (vec!["pointset", "sparse.txt"], "above the limit"),
        (vec!["render", "fifo", "--size", "8x8", "--spp", "1", "-o", "z"], "is a FIFO"),
        (vec!["render", "fifo.obj", "--size", "8x8", "--spp", "1", "-o", "z"], "is a FIFO"),
        (vec!["merge", "-o", "x", "fifo"], "is a FIFO"),
        (vec!["pointset", "fifo.npy"], "is a FIFO"),
        (
            vec![
                "compare",
                "--reference",
                "fifo",
                "--variant",
                "a=--sampler=independent",
                "--spp-ladder",
                "1,2",
                "-o",
                "c",
            ],
            "is a FIFO",
        ),
    ] {
        let r = shell(&dir, script, &args, 20);
        assert!(r.code == Some(1) || r.code == Some(2), "{args:?}: exit {:?}: {}", r.code, r.err);
        assert!(
            r.err.contains(says) && r.err.contains("reads only regular files")
                || says == "above the limit" && r.err.contains(says),
            "{args:?}: {}",
            r.err
        );
    }
}

/// The image directory removed during the render: the images cannot be written, the checkpoint
/// still is (the whole render, resumable), exit 1 naming what was written. Before: the error
/// came first and the final checkpoint was never written.
#[test]
fn an_image_that_cannot_be_written_keeps_the_checkpoint() {
    let dir = scratch("lost-images");
    fs::create_dir(dir.join("imgs")).unwrap();
    let script = r#""$STRATA" "$@" & pid=$!
        for i in $(seq 1 600); do [ -e c.ckpt ] && break; sleep 0.05; done
        rm -rf imgs; wait $pid"#;
    let a = [
        "render",
        "--size",
        "64x48",
        "--spp",
        "4096",
        "--threads",
        "1",
        "-q",
        "-o",
        "imgs/img",
        "--checkpoint",
        "c.ckpt",
        "--checkpoint-every",
        "0",
    ];
    let r = shell(&dir, script, &a, 300);
    assert_eq!(r.code, Some(1), "{}", r.err);
    assert!(r.err.contains("imgs/img.exr") && r.err.contains("written: c.ckpt"), "{}", r.err);
    let (h, _) = strata::checkpoint::read(&dir.join("c.ckpt")).unwrap();
    assert_eq!(h.samples, [0, 4096], "the whole render is in the checkpoint");
}

/// A file-size limit (`ulimit -f`, SIGXFSZ not ignored by the caller): exit 1 with `File too
/// large`, no temporary file left. Before: killed by SIGXFSZ (status 153) leaving `.c.ckpt.*.tmp`.
#[test]
fn a_file_size_limit_is_an_error_not_a_kill() {
    let dir = scratch("xfsz");
    let script = r#"trap - XFSZ; ulimit -f 100; exec "$STRATA" "$@""#;
    let a = ["render", "--size", "64x48", "--spp", "64", "--threads", "2", "-q", "-o", "img", "--checkpoint", "c.ckpt"];
    let r = shell(&dir, script, &a, 120);
    assert_eq!(r.code, Some(1), "{}", r.err);
    assert!(r.err.contains("File too large"), "{}", r.err);
    for e in fs::read_dir(&dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.ends_with(".tmp") && !name.starts_with('.'), "left: {name}");
    }
}

/// A second render to the `-o` of a running one is refused (before: both ran and the EXR of one
/// could be paired with the PNG of the other); the first completes.
#[test]
fn a_second_render_to_the_same_output_is_refused() {
    let dir = scratch("lock");
    let script = r#""$STRATA" render --size 64x48 --spp 2048 --threads 1 -q -o same & pid=$!
        for i in $(seq 1 200); do [ -e .same.lock ] && break; sleep 0.05; done
        "$STRATA" render --size 8x8 --spp 1 -q -o same; second=$?
        wait $pid; first=$?
        echo "first=$first second=$second" >&2"#;
    let r = shell(&dir, script, &[], 300);
    assert!(r.err.contains("first=0 second=1"), "{}", r.err);
    assert!(r.err.contains("another strata process is writing this output"), "{}", r.err);
    assert!(!dir.join(".same.lock").exists(), "the lock is removed");
}

/// Smaller findings: `--samples` checkpoints periodically to OUT.ckpt; `-o` stems too long for the
/// temporary name or empty (`-o .exr`) are refused before rendering; `.npy` files with trailing
/// bytes or cut short are refused with what the header declares.
#[test]
fn smaller_findings() {
    let dir = scratch("smaller");
    // Killed by its CPU limit mid-render: the periodic checkpoint OUT.ckpt is there.
    let script = r#"ulimit -t 3; exec "$STRATA" "$@""#;
    let a = [
        "render",
        "--size",
        "64x48",
        "--spp",
        "100000",
        "--threads",
        "1",
        "-q",
        "--samples",
        "0..100000",
        "-o",
        "part",
        "--checkpoint-every",
        "0",
    ];
    let r = shell(&dir, script, &a, 120);
    assert_ne!(r.code, Some(0), "{}", r.err);
    let (h, _) = strata::checkpoint::read(&dir.join("part.ckpt")).expect("a periodic part.ckpt");
    assert!(h.samples[1] > 0, "{:?}", h.samples);
    let long = "a".repeat(245);
    for (o, says) in [(long.as_str(), "shorten it"), (".exr", "empty file stem")] {
        let r = strata(&dir, &["render", "--size", "256x256", "--spp", "100000", "-q", "-o", o], 20);
        assert!(r.code == Some(1) && r.err.contains(says), "-o {o}: {}", r.err);
    }
    assert!(!dir.join(".exr").exists() && !dir.join(".png").exists());
    let hdr = "{'descr': '<f8', 'fortran_order': False, 'shape': (4, 2), }";
    let hdr = format!("{hdr}{}\n", " ".repeat(128 - 10 - hdr.len() - 1));
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    npy.extend((hdr.len() as u16).to_le_bytes());
    npy.extend(hdr.as_bytes());
    npy.extend((0..8).flat_map(|i| (f64::from(i) / 8.0).to_le_bytes()));
    let mut long_npy = npy.clone();
    long_npy.extend(b"junk");
    fs::write(dir.join("t.npy"), &long_npy).unwrap();
    fs::write(dir.join("s.npy"), &npy[..npy.len() - 8]).unwrap();
    for (f, says) in [("t.npy", "4 trailing bytes"), ("s.npy", "truncated: the header declares shape [4, 2]")] {
        let r = strata(&dir, &["pointset", f], 20);
        assert!(r.code == Some(1) && r.err.contains(says), "{f}: {}", r.err);
    }
}

/// Smaller findings, continued: an OBJ whose only triangle overflows is an error, not a black
/// image; `compare` refuses a ladder that is not increasing and absurd run counts; merging a
/// `--time-budget` checkpoint says what it is; `STRATA_BVH=bogus` is refused; the EXR records
/// `bvh` and `spheres` as the checkpoint does.
#[test]
fn smaller_findings_of_scenes_and_commands() {
    let dir = scratch("smaller2");
    fs::write(dir.join("huge.obj"), "v -3e19 -3e19 -5\nv 3e19 -3e19 -5\nv 0 3e19 -5\nf 1 2 3\n").unwrap();
    let r = strata(&dir, &["render", "huge.obj", "--size", "8x8", "--spp", "1", "-o", "h", "-q"], 60);
    assert!(r.code == Some(1) && r.err.contains("every triangle was dropped"), "{:?}: {}", r.code, r.err);
    assert!(!dir.join("h.png").exists());
    fs::write(dir.join("s.test"), SCENE).unwrap();
    let r = strata(&dir, &["reference", "s.test", "--size", "8x8", "--spp", "4", "-o", "ref", "-q"], 60);
    assert_eq!(r.code, Some(0), "{}", r.err);
    let (_, m) = super::run::exr(&dir.join("ref.exr"));
    for k in ["strata.bvh", "strata.spheres"] {
        assert!(!super::run::meta(&m, k).is_empty(), "{k} in {m:?}");
    }
    let cmp = ["compare", "s.test", "--reference", "ref.exr", "--variant", "a=--sampler=independent", "--size", "8x8"];
    for (extra, says) in [
        (vec!["--spp-ladder", "4,2,2"], "strictly increasing"),
        (vec!["--spp-ladder", "1,2", "--runs", "4294967296"], "at most 100000 runs"),
    ] {
        let mut a = cmp.to_vec();
        a.extend(extra);
        let r = strata(&dir, &a, 60);
        assert!(r.code == Some(1) && r.err.contains(says), "{a:?}: {}", r.err);
    }
    let r =
        strata(&dir, &["render", "s.test", "--time-budget", "0.3", "--checkpoint", "tb.ckpt", "-o", "tb", "-q"], 60);
    assert_eq!(r.code, Some(0), "{}", r.err);
    let r = strata(&dir, &["merge", "tb.ckpt", "-o", "m"], 60);
    assert!(r.code == Some(1) && r.err.contains("the checkpoint of a --time-budget render"), "{}", r.err);
    assert!(!r.err.contains("4294967295"), "{}", r.err);
    let r = super::run::strata_env(&dir, &["render", "s.test", "-o", "b", "-q"], &[("STRATA_BVH", "bogus")], 60);
    assert!(r.code == Some(1) && r.err.contains("STRATA_BVH=\"bogus\""), "{}", r.err);
}

//! Issue 25, findings 2 to 5: outputs never clobber what they should not, and a finished render is
//! never lost. Temporary files are made exclusively under unpredictable names (a link planted at
//! the old `OUT.png.tmp-PID` is not followed); an output that is a link, a directory or a device is
//! refused; outputs colliding with each other or with an input are refused before any sample; the
//! images are written before the checkpoint, and a checkpoint that cannot be written (a full disk)
//! is an error that keeps them, a failed periodic one a warning.

use super::run::{exr, meta, scratch, shell, strata};
use std::fs;
use std::os::unix::fs::FileTypeExt;

const SMALL: [&str; 7] = ["render", "--size", "8x8", "--spp", "1", "--threads", "1"];
/// A render that would take minutes: an error must come before it starts.
const SLOW: [&str; 7] = ["render", "--size", "256x256", "--spp", "100000", "--threads", "1"];

fn with<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    SMALL.iter().copied().chain(extra.iter().copied()).collect()
}

fn slow<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    SLOW.iter().copied().chain(extra.iter().copied()).collect()
}

/// `ln -s victim.txt out.png.tmp-$$` before `exec strata render -o out` (the issue's attack):
/// the victim is untouched and out.png is a regular file, not a link to it.
#[test]
fn planted_temporary_links_are_not_followed() {
    let dir = scratch("planted");
    fs::write(dir.join("victim.txt"), "precious").unwrap();
    let script = r#"for e in png exr; do ln -s victim.txt out.$e.tmp-$$; done; exec "$STRATA" "$@""#;
    let r = shell(&dir, script, &with(&["-o", "out", "-q"]), 60);
    assert_eq!(r.code, Some(0), "{}", r.err);
    assert_eq!(fs::read_to_string(dir.join("victim.txt")).unwrap(), "precious");
    for f in ["out.png", "out.exr"] {
        assert!(fs::symlink_metadata(dir.join(f)).unwrap().file_type().is_file(), "{f} is a regular file");
    }
}

/// `--stats`, `--checkpoint` or `--profile` naming a link, a FIFO (a special file like /dev/null)
/// or a directory is refused before rendering, saying what it is, and left as it was.
#[test]
fn outputs_that_are_links_devices_or_directories_are_refused() {
    let dir = scratch("special");
    fs::write(dir.join("victim.txt"), "precious").unwrap();
    std::os::unix::fs::symlink("victim.txt", dir.join("link.json")).unwrap();
    let fifo = shell(&dir, "mkfifo fifo", &[], 10);
    assert_eq!(fifo.code, Some(0), "{}", fifo.err);
    fs::create_dir(dir.join("adir")).unwrap();
    for (flag, path, what) in [
        ("--stats", "link.json", "a symbolic link"),
        ("--profile", "fifo", "a device, FIFO or socket"),
        ("--checkpoint", "adir", "a directory"),
        ("--stats", "adir", "a directory"),
    ] {
        let r = strata(&dir, &slow(&["-o", "o", flag, path, "-q"]), 20);
        assert_eq!(r.code, Some(1), "{flag} {path}: {}", r.err);
        assert!(r.err.contains(what) && r.err.contains("nothing was traced"), "{flag} {path}: {}", r.err);
    }
    assert!(!dir.join("o.png").exists(), "nothing rendered");
    assert_eq!(fs::read_to_string(dir.join("victim.txt")).unwrap(), "precious");
    assert!(fs::symlink_metadata(dir.join("link.json")).unwrap().file_type().is_symlink());
    assert!(fs::symlink_metadata(dir.join("fifo")).unwrap().file_type().is_fifo());
    // `-o` naming a directory is an error (before, `-o adir/` wrote adir/.exr and `-o .` ..exr).
    for o in ["adir/", ".", "adir", "adir/.."] {
        let r = strata(&dir, &with(&["-o", o, "-q"]), 20);
        assert!(r.code == Some(1) && r.err.contains("-o names a directory"), "-o {o}: {}", r.err);
    }
    assert!(!dir.join("adir/.exr").exists() && !dir.join("..exr").exists());
}

/// Outputs colliding with each other or with the scene are refused before any sample, naming
/// both (before: the stats JSON replaced the checkpoint, the EXR the checkpoint, the stats the scene).
#[test]
fn colliding_outputs_and_inputs_are_refused_before_rendering() {
    let dir = scratch("collide");
    let scene = "size 8 8\ncamera 0 0 3 0 0 0 0 1 0 45\npoint 0 0 3 1 1 1\ndiffuse 1 1 1\nsphere 0 0 0 1\n";
    fs::write(dir.join("scene.test"), scene).unwrap();
    for (extra, says) in [
        (vec!["--samples", "0..8", "-o", "part", "--stats", "part.ckpt"], "the checkpoint and --stats"),
        (vec!["-o", "img", "--checkpoint", "img.exr"], "the image img.exr and the checkpoint"),
        (vec!["-o", "img", "--stats", "scene.test"], "--stats and the scene file"),
        (vec!["-o", "img", "--stats", "./img.png"], "the image img.png and --stats"),
        (vec!["-o", "img", "--stats", "s.json", "--profile", "s.json"], "--stats and --profile"),
    ] {
        let mut a = slow(&["scene.test"]);
        a.extend(&extra);
        let r = strata(&dir, &a, 20);
        assert_eq!(r.code, Some(1), "{extra:?}: {}", r.err);
        assert!(r.err.contains(says) && r.err.contains("the same file"), "{extra:?}: {}", r.err);
    }
    assert_eq!(fs::read_to_string(dir.join("scene.test")).unwrap(), scene, "the scene is untouched");
    assert!(!dir.join("img.png").exists() && !dir.join("part.png").exists());
}

/// Checks the images of a render that could not write its checkpoint: both there, full spp.
fn images_complete(dir: &std::path::Path, stem: &str, spp: &str) {
    let (_, m) = exr(&dir.join(format!("{stem}.exr")));
    assert_eq!(meta(&m, "strata.spp"), spp, "the EXR holds the whole render");
    assert!(dir.join(format!("{stem}.png")).is_file());
}

/// A checkpoint that cannot be written (the file-size limit of the process, `ulimit -f`: EFBIG
/// like a full disk, on any machine) fails the run with a non-zero exit after the images are
/// written; failed periodic checkpoints only warn. Before: exit 1 and no image.
#[test]
fn a_checkpoint_that_cannot_be_written_keeps_the_images() {
    let dir = scratch("efbig");
    // 64x48 at 255 spp: images under 100 KB, a checkpoint of 147 KB per dyadic block (8 at the
    // end; one after the first pass of 16 samples, which fits under the 200 KiB limit).
    let script = r#"trap "" XFSZ; ulimit -f 200; exec "$STRATA" "$@""#;
    let base = ["render", "--size", "64x48", "--spp", "255", "--threads", "2", "-q"];
    let mut a = base.to_vec();
    a.extend(["-o", "img", "--checkpoint", "c.ckpt", "--checkpoint-every", "0"]);
    let r = shell(&dir, script, &a, 120);
    assert_eq!(r.code, Some(1), "{}", r.err);
    assert!(r.err.contains("c.ckpt: cannot write checkpoint") && r.err.contains("were written"), "{}", r.err);
    assert!(r.err.contains("the previous checkpoint stays, trying again"), "periodic failures warn: {}", r.err);
    images_complete(&dir, "img", "255");
    // The last checkpoint that could be written stays (a part of the range, resumable).
    if dir.join("c.ckpt").exists() {
        let (h, _) = strata::checkpoint::read(&dir.join("c.ckpt")).unwrap();
        assert!(h.samples[0] == 0 && h.samples[1] < 255, "{:?}", h.samples);
    }
    // `--samples` writes OUT.ckpt: the same.
    let mut a = base.to_vec();
    a.extend(["--samples", "0..127", "-o", "part"]);
    let r = shell(&dir, script, &a, 120);
    assert_eq!(r.code, Some(1), "{}", r.err);
    assert!(r.err.contains("part.ckpt: cannot write checkpoint"), "{}", r.err);
    images_complete(&dir, "part", "127");
    for e in fs::read_dir(&dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(["img.exr", "img.png", "c.ckpt", "part.exr", "part.png"].contains(&name.as_str()), "left: {name}");
    }
}

/// A full disk: the checkpoint on a 256 KiB tmpfs (mounted for the test: needs root, as CI
/// has), the images beside the test. Exit 1, images complete, the tmpfs
/// holds no temporary file.
#[test]
fn a_checkpoint_on_a_full_disk_keeps_the_images() {
    let dir = scratch("full");
    let mnt = dir.join("full");
    fs::create_dir(&mnt).unwrap();
    let m = mnt.display().to_string();
    let mounted = shell(&dir, r#"mount -t tmpfs -o size=256k strata-test "$1""#, &[&m], 20);
    assert_eq!(
        mounted.code,
        Some(0),
        "this test mounts a tmpfs, which needs root (CI runs as root): {}",
        mounted.err.trim()
    );
    struct Unmount(String);
    impl Drop for Unmount {
        fn drop(&mut self) {
            let _ = std::process::Command::new("umount").arg(&self.0).status();
        }
    }
    let _guard = Unmount(m.clone());
    let ck = format!("{m}/c.ckpt");
    let a = ["render", "--size", "64x48", "--spp", "255", "--threads", "2", "-o", "img", "-q", "--checkpoint", &ck];
    let r = strata(&dir, &a, 120);
    assert_eq!(r.code, Some(1), "{}", r.err);
    assert!(r.err.contains("No space left on device") && r.err.contains("were written"), "{}", r.err);
    images_complete(&dir, "img", "255");
    assert_eq!(fs::read_dir(&mnt).unwrap().count(), 0, "nothing left on the full disk");
    drop(_guard);
}

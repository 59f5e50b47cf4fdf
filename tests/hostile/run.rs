//! Running the `strata` binary from the hostile-input tests: with environment variables, under a
//! shell (for `ulimit`, planted links), with a time limit. `STRATA_TEST_BINARY` runs another
//! binary (e.g. an older build, to see a test fail on the code it fixes).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What a run printed and how it ended.
pub struct Run {
    /// exit code (None: killed by a signal)
    pub code: Option<i32>,
    /// stderr
    pub err: String,
}

/// The binary under test.
pub fn bin() -> String {
    std::env::var("STRATA_TEST_BINARY").unwrap_or_else(|_| env!("CARGO_BIN_EXE_strata").to_string())
}

/// Runs `cmd` in `dir`; kills it and fails if it takes more than `secs` seconds.
pub fn run_cmd(mut cmd: Command, dir: &Path, secs: u64) -> Run {
    let mut child =
        cmd.current_dir(dir).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().expect("start the command");
    let deadline = Instant::now() + Duration::from_secs(secs);
    while child.try_wait().expect("wait").is_none() {
        if Instant::now() > deadline {
            child.kill().ok();
            child.wait().ok();
            panic!("{cmd:?} still running after {secs} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let o = child.wait_with_output().expect("output");
    Run { code: o.status.code(), err: String::from_utf8_lossy(&o.stderr).into_owned() }
}

/// `strata ARGS` in `dir` with the environment variables `env` set, within `secs` seconds.
pub fn strata_env(dir: &Path, args: &[&str], env: &[(&str, &str)], secs: u64) -> Run {
    let mut cmd = Command::new(bin());
    cmd.args(args).env_remove("STRATA_EMBREE_CONFIG").env_remove("STRATA_SPHERES").env_remove("STRATA_BVH");
    for (k, v) in env {
        cmd.env(k, v);
    }
    run_cmd(cmd, dir, secs)
}

/// `strata ARGS` in `dir` within `secs` seconds.
pub fn strata(dir: &Path, args: &[&str], secs: u64) -> Run {
    strata_env(dir, args, &[], secs)
}

/// `bash -c SCRIPT` in `dir` with `$STRATA` the binary under test and `$@` = `args`.
pub fn shell(dir: &Path, script: &str, args: &[&str], secs: u64) -> Run {
    let mut cmd = Command::new("bash");
    cmd.arg("-c").arg(script).arg("strata-test").args(args).env("STRATA", bin());
    run_cmd(cmd, dir, secs)
}

/// A fresh scratch directory, removed when dropped ([`crate::common::tmpdir`]).
pub fn scratch(name: &str) -> crate::common::Scratch {
    crate::common::tmpdir(&format!("hostile-{name}"))
}

/// The pixel channels of an EXR: (layer name, f32 bits).
pub type Channels = Vec<(String, Vec<u32>)>;

/// The pixel channels and the text metadata of an EXR.
pub fn exr(path: &Path) -> (Channels, strata::film::Metadata) {
    let img = strata::film::read_exr(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let bits = |v: &[[f32; 3]]| v.iter().flat_map(|p| p.map(f32::to_bits)).collect::<Vec<u32>>();
    let mut ch = vec![("rgb".to_string(), bits(&img.rgb))];
    if let Some(v) = &img.variance {
        ch.push(("variance".to_string(), bits(v)));
    }
    (ch, img.meta)
}

/// The value of metadata key `k`.
pub fn meta<'a>(m: &'a [(String, String)], k: &str) -> &'a str {
    m.iter().find(|(a, _)| a == k).map_or("", |(_, v)| v.as_str())
}

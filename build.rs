//! Finds Embree 4 and tells the linker where it is, with an rpath so binaries, tests and benches run
//! without LD_LIBRARY_PATH. Search order: $EMBREE_DIR (its lib/ or itself), `pkg-config embree4`,
//! then the project-local .embree/lib filled by scripts/setup.sh.
//!
//! Also sets `STRATA_BUILD` (the build in a render's identity: a hash of everything compiled into
//! the binary, the crate's sources, manifest and lock file and the target features, so two builds
//! share it only if they compute the same samples) and `STRATA_COMMIT` (the git commit, with
//! `-dirty` if sources differ from it; informative, in the EXR metadata).
use std::path::{Path, PathBuf};
use std::process::Command;

fn has_embree(dir: &Path) -> bool {
    dir.join("libembree4.so").exists() || dir.join("libembree4.so.4").exists()
}

fn pkg_config_libdir() -> Option<PathBuf> {
    let out = Command::new("pkg-config").args(["--variable=libdir", "embree4"]).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let s = String::from_utf8(out.stdout).ok()?;
    let p = PathBuf::from(s.trim());
    has_embree(&p).then_some(p)
}

/// FNV-1a, 64 bit.
fn fnv(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Every file under `dir`, recursively, sorted.
fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            files_under(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// The build id (see the module doc) and the git commit of the sources in `manifest`.
fn build_id(manifest: &Path) -> (String, String) {
    let mut files = Vec::new();
    files_under(&manifest.join("src"), &mut files);
    // The built-in scene (`include_str!`) and what decides how the crate is compiled.
    let more = ["scenes/cornell.test", "Cargo.toml", "Cargo.lock", "build.rs", ".cargo/config.toml"];
    files.extend(more.map(|f| manifest.join(f)));
    files.sort();
    let mut h = 0xcbf2_9ce4_8422_2325;
    for f in &files {
        h = fnv(h, f.strip_prefix(manifest).unwrap_or(f).to_string_lossy().as_bytes());
        h = fnv(h, &std::fs::read(f).unwrap_or_default());
    }
    for var in ["CARGO_CFG_TARGET_FEATURE", "CARGO_CFG_TARGET_ARCH", "CARGO_ENCODED_RUSTFLAGS"] {
        h = fnv(h, std::env::var(var).unwrap_or_default().as_bytes());
    }
    let git = |args: &[&str]| {
        Command::new("git").args(args).current_dir(manifest).output().ok().filter(|o| o.status.success())
    };
    let commit = git(&["rev-parse", "--short=12", "HEAD"])
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    let dirty = git(&[
        "status",
        "--porcelain",
        "--untracked-files=no",
        "--",
        "src",
        "scenes/cornell.test",
        "Cargo.toml",
        "Cargo.lock",
        "build.rs",
    ])
    .is_some_and(|o| !o.stdout.is_empty());
    (format!("{h:016x}"), if dirty { format!("{commit}-dirty") } else { commit })
}

fn main() {
    println!("cargo:rerun-if-env-changed=EMBREE_DIR");
    println!("cargo:rerun-if-changed=build.rs");
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    for f in ["src", "scenes/cornell.test", "Cargo.toml", "Cargo.lock", ".cargo/config.toml"] {
        println!("cargo:rerun-if-changed={}", manifest.join(f).display());
    }
    println!("cargo:rerun-if-env-changed=RUSTFLAGS");
    let (build, commit) = build_id(&manifest);
    println!("cargo:rustc-env=STRATA_BUILD={build}");
    println!("cargo:rustc-env=STRATA_COMMIT={commit}");
    let local = manifest.join(".embree").join("lib");
    println!("cargo:rerun-if-changed={}", local.display());

    let found = if let Ok(d) = std::env::var("EMBREE_DIR") {
        let d = PathBuf::from(d);
        [d.join("lib"), d.join("lib64"), d.clone()].into_iter().find(|p| has_embree(p))
    } else {
        pkg_config_libdir().or_else(|| has_embree(&local).then(|| local.clone()))
    };
    let Some(dir) = found else {
        panic!(
            "Embree 4 was not found: run ./scripts/setup.sh (it installs Embree 4.4 into .embree/), \
             or set EMBREE_DIR to an Embree 4 install, or make `pkg-config embree4` find one."
        );
    };
    println!("cargo:rustc-link-search=native={}", dir.display());
    println!("cargo:rustc-link-arg=-Wl,-rpath,{}", dir.display());
    println!("cargo:rustc-env=STRATA_EMBREE_LIBDIR={}", dir.display());
    // For dependents' build scripts (python/build.rs adds the same rpath to the Python module).
    println!("cargo:libdir={}", dir.display());
}

//! Finds Embree 4 and tells the linker where it is, with an rpath so binaries, tests and benches run
//! without LD_LIBRARY_PATH. Search order: $EMBREE_DIR (its lib/ or itself), `pkg-config embree4`,
//! then the project-local .embree/lib filled by scripts/setup.sh.
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

fn main() {
    println!("cargo:rerun-if-env-changed=EMBREE_DIR");
    println!("cargo:rerun-if-changed=build.rs");
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
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

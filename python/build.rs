//! The Python module finds Embree the way the `strata` binary does: an rpath to the directory the
//! renderer's build script found it in (`$EMBREE_DIR`, `pkg-config embree4`, or the checkout's
//! `.embree/lib` from scripts/setup.sh), passed on as `DEP_STRATA_EMBREE_LIBDIR`.
fn main() {
    println!("cargo:rerun-if-env-changed=DEP_STRATA_EMBREE_LIBDIR");
    let dir = std::env::var("DEP_STRATA_EMBREE_LIBDIR").expect("strata's build script names Embree's directory");
    println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
}

//! strata's BSDFs against Mitsuba 3's own renders of small XML scenes (`scenes/*.xml`, references
//! in `scenes/refs/`: `$PY scripts/cbox-mitsuba.py scenes/NAME.xml scenes/refs 8192 NAME`, the peer
//! in ../shared/peers/mitsuba, 8192 spp with its `moment` integrator), by Mitsuba's regression
//! criterion at its budget (2,000,000 samples per image, `strata::lab::mitsuba::run_scene`). The
//! scenes read their textures from the shared Mitsuba corpus beside the repository.

use std::path::PathBuf;

/// Renders `scenes/NAME.xml` and z-tests it against Mitsuba's render.
fn passes(name: &str) {
    let corpus = strata::lab::mitsuba::corpus_dir().join("common/textures");
    assert!(corpus.is_dir(), "{}: the Mitsuba corpus is missing (it comes with ../shared)", corpus.display());
    let scene = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes")).join(format!("{name}.xml"));
    let o = strata::lab::mitsuba::run_scene(&scene, 2).unwrap_or_else(|e| panic!("{name}: {e}"));
    eprintln!(
        "{name} vs Mitsuba: {} spp, {:.3} % accepted, smallest p {:.2e} (level {:.2e})",
        o.spp,
        100.0 * o.test.accepted,
        o.test.min_p,
        o.test.level
    );
    assert!(o.test.passed, "{name}: {:?}", o.test);
}

/// A `blendbsdf` of a rough conductor and a rough dielectric, its weight a checkerboard.
#[test]
fn blend_of_roughconductor_and_roughdielectric_with_a_textured_weight() {
    passes("blend_textured_weight");
}

/// A `roughplastic` with a bitmap `diffuse_reflectance` and a checkerboard `specular_reflectance`.
#[test]
fn roughplastic_with_textured_reflectances() {
    passes("roughplastic_bitmap");
}

/// A smooth `conductor` whose `eta` is a checkerboard and `k` a bitmap.
#[test]
fn conductor_with_textured_eta_and_k() {
    passes("conductor_textured_eta_k");
}

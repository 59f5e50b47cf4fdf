//! Mitsuba 3's render-regression suite run on strata: every scene of the corpus
//! (`../shared/corpora/mitsuba-tests`, see its SOURCES.md) rendered at Mitsuba's budget (spp =
//! 2,000,000 / pixels) and tested by [`crate::report::ztest`] against Mitsuba's reference and
//! variance images. [`CORPUS`] lists every scene with what is expected of it: a pass, or a refusal
//! naming the missing feature. `tests/it/mitsuba_corpus.rs` asserts it; `examples/mitsuba_ztest.rs`
//! prints the table.

use super::LabError;
use crate::report::ztest::{mitsuba_ztest, ZTest};
use crate::session::RenderOptions;
use std::path::{Path, PathBuf};

/// Mitsuba's sample budget per image.
pub const SAMPLE_BUDGET: u64 = 2_000_000;

/// What a corpus scene is expected to do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expect {
    /// render and pass the z-test
    Pass,
    /// be refused with an error containing this text (the missing feature)
    Refused(&'static str),
    /// render but fail the z-test, for the stated reason (a known difference, asserted so that
    /// a fix is noticed and the entry moved to `Pass`)
    Fails(&'static str),
}

/// Every scene of the corpus (relative to `tests/scenes/`) and what is expected of it.
pub const CORPUS: &[(&str, Expect)] = &[
    ("bsdf_spheres/test_arealight_path.xml", Expect::Pass),
    ("bsdf_spheres/test_bumpmap_path.xml", Expect::Pass),
    ("bsdf_spheres/test_constant_path.xml", Expect::Pass),
    ("bsdf_spheres/test_envmap_path.xml", Expect::Pass),
    ("bsdf_spheres/test_normalmap_identity_roughconductor_path.xml", Expect::Pass),
    ("bsdf_spheres/test_normalmap_path.xml", Expect::Pass),
    ("bsdf_spheres/test_normalmap_roughconductor_path.xml", Expect::Pass),
    ("bsdf_spheres/test_pointlight_path.xml", Expect::Pass),
    ("bsdf_spheres/test_roughdielectric_path.xml", Expect::Pass),
    ("bsdf_spheres/test_roughplastic_linear_path.xml", Expect::Pass),
    ("bsdf_spheres/test_roughplastic_nonlinear_path.xml", Expect::Pass),
    ("bsdf_spheres/test_textured_diffuse_path.xml", Expect::Pass),
    // Passes (100 % at 868 spp, smallest p 7.0e-4) since scalar parameters read a checkerboard
    // as Mitsuba's `eval_1` does, with color0 and color1 swapped (`texture::Checkerboard`).
    ("bsdf_spheres/test_textured_roughconductor_path.xml", Expect::Pass),
    // Pass since `principled` and `principledthin` are registry BSDFs (100 % at 868 spp; smallest
    // p 5.3e-3, 6.8e-3 and 6.4e-5 against the Sidak level 4.4e-6).
    ("bsdf_spheres/test_texturedprincipled1_path.xml", Expect::Pass),
    ("bsdf_spheres/test_texturedprincipled2_path.xml", Expect::Pass),
    ("bsdf_spheres/test_texturedprincipledthin_path.xml", Expect::Pass),
    ("floating_sphere/test_directional_direct.xml", Expect::Pass),
    ("infinite_mirrors/scene_path.xml", Expect::Pass),
    ("instancing/test_instancing_path.xml", Expect::Pass),
    ("mesh_attributes/test_mesh_attributes_1_face_direct.xml", Expect::Pass),
    ("mesh_attributes/test_mesh_attributes_3_face_direct.xml", Expect::Pass),
    ("mesh_attributes/test_mesh_attributes_3_vertex_direct.xml", Expect::Pass),
    ("orthographic_sensor/test_orthographic_path.xml", Expect::Pass),
    ("projector/test_projector_constant_direct.xml", Expect::Pass),
    ("projector/test_projector_textured_direct.xml", Expect::Pass),
    ("spot_light/test_spot_direct.xml", Expect::Pass),
    ("texture_interp/test_texture_interp_direct.xml", Expect::Pass),
    ("various_emitters/test_various_emitters_ptracer.xml", Expect::Pass),
    // Passes since `diffuse` is one-sided (the open cylinder's inside is black) and the sdfgrid's
    // uv is the origin (the torus is uniformly the checkerboard's color0), as in Mitsuba.
    ("various_shapes/test_various_shapes_path.xml", Expect::Pass),
];

/// The corpus folder: `STRATA_MITSUBA_TESTS`, else `../shared/corpora/mitsuba-tests` beside the
/// crate.
pub fn corpus_dir() -> PathBuf {
    std::env::var_os("STRATA_MITSUBA_TESTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpora/mitsuba-tests"))
}

/// The reference and variance images of a scene: `refs/NAME_ref_rgb{,_var}.exr` beside it,
/// NAME the file stem without its integrator suffix (`_path`, `_direct`, `_ptracer`).
pub fn reference_paths(scene: &Path) -> (PathBuf, PathBuf) {
    let stem = scene.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
    let name = ["_path", "_direct", "_ptracer"].iter().find_map(|s| stem.strip_suffix(s)).unwrap_or(stem);
    let refs = scene.parent().unwrap_or(Path::new(".")).join("refs");
    (refs.join(format!("{name}_ref_rgb.exr")), refs.join(format!("{name}_ref_rgb_var.exr")))
}

/// One scene's result: its spp and the test.
#[derive(Clone, Copy, Debug)]
pub struct Outcome {
    /// samples per pixel rendered (2,000,000 / pixels)
    pub spp: u32,
    /// the z-test
    pub test: ZTest,
}

/// Renders `scene` at Mitsuba's budget with `threads` workers (seed 0) and tests it against its
/// references. A scene strata refuses comes back as the session's error.
pub fn run_scene(scene: &Path, threads: usize) -> Result<Outcome, LabError> {
    let probe = RenderOptions { scene: Some(scene.to_path_buf()), ..Default::default() };
    let desc = crate::session::load_scene(&probe)?;
    let pixels = u64::from(desc.width) * u64::from(desc.height);
    let spp = (SAMPLE_BUDGET / pixels.max(1)).max(1) as u32;
    let (ref_path, var_path) = reference_paths(scene);
    let read = |p: &Path| crate::film::read_exr(p).map_err(|source| LabError::Io { path: p.to_path_buf(), source });
    let (reference, variance) = (read(&ref_path)?, read(&var_path)?);
    let opts = RenderOptions {
        scene: Some(scene.to_path_buf()),
        parsed: Some(std::sync::Arc::new(desc)),
        spp: Some(spp),
        threads,
        ..Default::default()
    };
    let out = crate::session::render_to_film(&opts)?;
    let image = out.film.mean();
    if image.len() != reference.rgb.len() || image.len() != variance.rgb.len() {
        return Err(LabError::Io {
            path: ref_path,
            source: std::io::Error::other(format!("size differs from the render ({} pixels)", image.len())),
        });
    }
    Ok(Outcome { spp, test: mitsuba_ztest(&image, spp, &reference.rgb, &variance.rgb) })
}

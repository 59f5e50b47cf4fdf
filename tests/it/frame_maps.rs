//! Normal and bump maps (Mitsuba's `normalmap`, `bumpmap`) in the path tracer: a white furnace
//! (a convex sphere of reflectance 1 under a constant environment of radiance 1) renders at most
//! 1 everywhere through strongly perturbed frames (the maps' side checks and shadowing term lose
//! energy, nothing gains it), with no NaN or negative pixel, for the course's diffuse and an
//! anisotropic rough mirror, a tilted constant normal map and a bump map of a generated image.
//! Mitsuba's own regression scenes (`mitsuba_corpus.rs`) check the images.

use crate::common::*;
use std::path::Path;

/// A furnace scene around `bsdf` on a unit sphere, 24x24, max depth 16.
fn furnace_scene(dir: &Path, name: &str, bsdf: &str) -> std::path::PathBuf {
    let text = format!(
        r#"<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="16"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="35"/>
    <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film>
    <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <shape type="sphere">{bsdf}</shape>
</scene>
"#
    );
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Renders `scene` and checks every pixel: finite, not negative, its mean at most 1 (4 standard
/// errors of slack); returns the mean over the image.
fn check_furnace(scene: std::path::PathBuf) -> f64 {
    let o = strata::session::RenderOptions { scene: Some(scene.clone()), threads: 2, ..Default::default() };
    let f = film(&o);
    let (m, v) = (means(&f), var_of_mean(&f));
    let mut total = 0.0;
    for (i, (m, v)) in m.iter().zip(&v).enumerate() {
        for c in 0..3 {
            assert!(m[c].is_finite() && m[c] >= 0.0, "{}: pixel {i}: {}", scene.display(), m[c]);
            assert!(
                m[c] <= 1.0 + 4.0 * v[c].sqrt() + 1e-6,
                "{}: pixel {i}: {} > 1 (+- {})",
                scene.display(),
                m[c],
                v[c].sqrt()
            );
        }
        total += m[0];
    }
    total / m.len() as f64
}

#[test]
fn normal_and_bump_mapped_furnaces_gain_no_energy() {
    let dir = tmpdir("frame-maps");
    // A height field of bumps, 64x64 grey.
    let img = image::RgbImage::from_fn(64, 64, |x, y| {
        let h = 0.5 + 0.25 * ((x as f32 * 0.4).sin() + (y as f32 * 0.3).cos());
        image::Rgb([(h * 255.0) as u8; 3])
    });
    img.save(dir.join("height.png")).unwrap();
    let diffuse = r#"<bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf>"#;
    let mirror = r#"<bsdf type="roughconductor"><string name="material" value="none"/>
        <string name="distribution" value="ggx"/><float name="alpha_u" value="0.01"/><float name="alpha_v" value="1"/></bsdf>"#;
    // A constant normal tilted by about 60 degrees, and a bump map of steep bumps.
    let normal = |inner: &str| {
        format!(
            r#"<bsdf type="normalmap"><texture name="normalmap" type="rawconstant"><rgb name="value" value="0.93, 0.5, 0.75"/></texture>{inner}</bsdf>"#
        )
    };
    let bump = |inner: &str| {
        format!(
            r#"<bsdf type="bumpmap"><float name="scale" value="0.05"/><texture type="bitmap"><boolean name="raw" value="true"/><string name="filename" value="height.png"/></texture>{inner}</bsdf>"#
        )
    };
    let plain = check_furnace(furnace_scene(&dir, "plain.xml", diffuse));
    for (name, bsdf) in [
        ("normal_diffuse.xml", normal(diffuse)),
        ("normal_mirror.xml", normal(mirror)),
        ("bump_diffuse.xml", bump(diffuse)),
        ("bump_mirror.xml", bump(mirror)),
    ] {
        let mean = check_furnace(furnace_scene(&dir, name, &bsdf));
        eprintln!("{name}: image mean {mean:.4} (without a map {plain:.4})");
        // Perturbed frames lose some energy at the sphere, never all of it.
        assert!(mean < plain && mean > 0.5, "{name}: image mean {mean} (without a map {plain})");
    }
}

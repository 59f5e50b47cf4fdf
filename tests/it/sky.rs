//! `--sky RADIANCE`, the constant environment light: the white furnace (a white diffuse sphere
//! under a constant sky converges to the sky's radiance, per pixel, in every NEE mode and every
//! light-selection mode, with error falling as samples grow), agreement of every light-selection
//! mode when the sky lights a scene beside a quad light, and the CLI's refusals.

use crate::common;

use common::*;
use std::path::{Path, PathBuf};
use strata::integrator::LightSelection;
use strata::scene::desc::Nee;
use strata::session::RenderOptions;

/// Every registered light-selection rule, in registry order (`all` first).
fn rules() -> Vec<LightSelection> {
    LightSelection::every().collect()
}

/// A white (albedo 1) diffuse unit sphere filling most of a 24x24 image, no light of its own.
fn furnace_scene(dir: &Path) -> PathBuf {
    let p = dir.join("furnace.test");
    std::fs::write(
        &p,
        "size 24 24\nintegrator pathtracer\ncamera 0 0 3 0 0 0 0 1 0 45\nmaxdepth 5\n\
         importancesampling cosine\ndiffuse 1 1 1\nsphere 0 0 0 1\n",
    )
    .unwrap();
    p
}

fn render(o: &RenderOptions) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let out = strata::session::render_to_film(o).unwrap_or_else(|e| panic!("render failed: {e}"));
    assert_eq!(out.stats.counters.nonfinite, 0);
    (means(&out.film), var_of_mean(&out.film))
}

/// Largest |z| of the pixels' means against `want` (those off by more than 1e-5; they must have a
/// variance), and the RMS error.
fn z_against(mean: &[[f64; 3]], var: &[[f64; 3]], want: f64) -> (f64, f64) {
    let (mut zmax, mut se) = (0f64, 0f64);
    for (m, v) in mean.iter().zip(var) {
        for c in 0..3 {
            let d = m[c] - want;
            se += d * d;
            if d.abs() > 1e-5 {
                assert!(v[c] > 0.0, "a pixel without variance is {} instead of {want}", m[c]);
                zmax = zmax.max(d.abs() / v[c].sqrt());
            }
        }
    }
    (zmax, (se / (3 * mean.len()) as f64).sqrt())
}

#[test]
fn white_furnace_converges_to_the_sky_radiance_in_every_mode() {
    let dir = tmpdir("sky-furnace");
    let scene = furnace_scene(&dir);
    let sky = 0.75;
    for nee in [Nee::Off, Nee::On, Nee::Mis] {
        for sel in rules() {
            let o = RenderOptions {
                sky: Some(glam::Vec3::splat(sky)),
                nee: Some(nee),
                light_selection: Some(sel),
                first_sample: Some(strata::camera::FirstSample::Jittered),
                ..opts(scene.clone(), 24, 24, 64)
            };
            let (m, v) = render(&o);
            let (zmax, rms) = z_against(&m, &v, sky as f64);
            // 1728 channels: |z| > 5 by chance has probability ~1e-3 over the whole image.
            assert!(zmax < 5.0, "{nee:?} {sel}: max |z| {zmax} against the sky radiance {sky}");
            if nee == Nee::Off {
                // Cosine sampling of a white diffuse BRDF under a constant sky: every path's
                // estimate is exactly the sky radiance.
                assert!(rms < 1e-5, "{sel}: rms {rms}");
            }
        }
    }
    // Convergence: the error keeps falling as samples grow (MIS, 16 -> 256 spp: about 4x).
    let rms = |spp| {
        let o = RenderOptions {
            sky: Some(glam::Vec3::splat(sky)),
            nee: Some(Nee::Mis),
            ..opts(scene.clone(), 24, 24, spp)
        };
        let (m, v) = render(&o);
        z_against(&m, &v, sky as f64).1
    };
    let (e16, e256) = (rms(16), rms(256));
    assert!(e16 > 0.0 && e256 < 0.4 * e16, "rms 16 spp {e16}, 256 spp {e256}");
}

/// A sphere on a floor under a quad light and a coloured sky.
fn lit_scene(dir: &Path) -> PathBuf {
    let p = dir.join("sky_and_quad.test");
    std::fs::write(
        &p,
        "size 20 16\nintegrator pathtracer\ncamera 0 1.5 4 0 0.5 0 0 1 0 50\nmaxdepth 3\n\
         nexteventestimation mis\nimportancesampling brdf\n\
         quadLight -0.5 3 -0.5 1 0 0 0 0 1 6 6 6\n\
         maxverts 4\nvertex -3 0 -3\nvertex 3 0 -3\nvertex 3 0 3\nvertex -3 0 3\n\
         diffuse 0.6 0.6 0.6\ntri 0 2 1\ntri 0 3 2\n\
         diffuse 0.3 0.5 0.2\nspecular 0.3 0.3 0.3\nshininess 20\nsphere 0 0.6 0 0.6\n",
    )
    .unwrap();
    p
}

#[test]
fn every_light_selection_agrees_with_a_sky_beside_a_quad_light() {
    let dir = tmpdir("sky-select");
    let scene = lit_scene(&dir);
    let run = |sel: LightSelection, seed: u64| {
        let o = RenderOptions {
            sky: Some(glam::Vec3::new(0.4, 0.5, 0.8)),
            light_selection: Some(sel),
            seed,
            first_sample: Some(strata::camera::FirstSample::Jittered),
            ..opts(scene.clone(), 20, 16, 128)
        };
        render(&o)
    };
    let (ma, va) = run(LightSelection::ALL, 1);
    // The sky changes the image: the floor is brighter than under the quad light alone.
    let no_sky = strata::session::render_to_film(&RenderOptions {
        first_sample: Some(strata::camera::FirstSample::Jittered),
        ..opts(scene.clone(), 20, 16, 128)
    })
    .unwrap();
    let sum = |m: &[[f64; 3]]| m.iter().map(|p| p[2]).sum::<f64>();
    assert!(sum(&ma) > 1.2 * sum(&means(&no_sky.film)), "the sky adds light");
    for (k, sel) in [LightSelection::UNIFORM, LightSelection::named("power"), LightSelection::named("spatial")]
        .into_iter()
        .enumerate()
    {
        let (mb, vb) = run(sel, 2 + k as u64);
        let (mut over, mut n, mut d, mut v) = (0, 0, 0.0, 0.0);
        for i in 0..ma.len() {
            for c in 0..3 {
                let var = va[i][c] + vb[i][c];
                d += mb[i][c] - ma[i][c];
                v += var;
                if var > 0.0 {
                    n += 1;
                    over += usize::from((mb[i][c] - ma[i][c]).abs() > 3.0 * var.sqrt());
                }
            }
        }
        let z_mean = d / v.sqrt();
        assert!(z_mean.abs() < 4.0, "{sel} vs all: image sum z {z_mean}");
        assert!((over as f64) < 0.01 * n as f64 + 3.0, "{sel} vs all: {over} of {n} channels beyond 3 sigma");
    }
}

#[test]
fn cli_sky_refusals() {
    // Not a radiance.
    for bad in ["-1", "1,2", "x", "nan"] {
        let r = strata().args(["render", "--sky", bad, "-q"]).output().unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("expected a radiance R or R,G,B of finite numbers >= 0"), "{bad}: {err}");
    }
    // An integrator that does not trace paths.
    let dir = tmpdir("sky-cli");
    let r = strata()
        .args(["render", "--sky", "1", "--integrator", "raytracer", "--spp", "1", "--size", "8x8", "-q", "-o"])
        .arg(dir.join("x"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(err.contains("--sky (and any environment or delta light) needs the path tracer or direct"), "{err}");
    assert!(!dir.join("x.png").exists());
    // Accepted: R,G,B, recorded in the statistics' scene features.
    let stats = dir.join("s.json");
    let r = strata()
        .args(["render", "--sky", "0.5,0.25,1", "--integrator", "pathtracer", "--spp", "1", "--size", "8x8", "-q"])
        .arg("--stats")
        .arg(&stats)
        .arg("-o")
        .arg(dir.join("y"))
        .output()
        .unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(j["features"]["sky"], serde_json::json!([0.5, 0.25, 1.0]), "{j}");
}

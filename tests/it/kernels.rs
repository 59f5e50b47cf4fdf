//! Feature-specialized kernels: the kernel compiled for a scene's features must give the same
//! image, bit for bit, as the general kernel (specialization changes speed, never results).

use crate::common;

use common::{corpus_required, opts};
use std::path::PathBuf;
use strata::session::{render_to_film, stats_json, RenderOptions};

fn own(name: &str) -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes")).join(name)
}

/// Renders `o` with the specialized and with the general kernel; asserts identical mean and
/// variance bits and returns the two kernel names.
fn same_bits(o: &RenderOptions) -> (String, String) {
    let spec = render_to_film(o).expect("specialized render");
    let gen = render_to_film(&RenderOptions { general_kernel: true, ..o.clone() }).expect("general render");
    let bits = |v: Vec<[f32; 3]>| v.into_iter().flat_map(|p| p.map(f32::to_bits)).collect::<Vec<u32>>();
    let name = o.scene.as_ref().map_or("<built-in>".into(), |p| p.display().to_string());
    assert!(spec.film.mean().iter().flatten().any(|&v| v > 0.0), "{name}: black image proves nothing");
    assert_eq!(bits(spec.film.mean()), bits(gen.film.mean()), "{name}: mean differs between kernels");
    assert_eq!(bits(spec.film.variance_of_mean()), bits(gen.film.variance_of_mean()), "{name}: variance differs");
    let k = |r: &strata::session::RenderOutput| stats_json(r)["kernel"].as_str().expect("kernel key").to_string();
    (k(&spec), k(&gen))
}

#[test]
fn own_scenes_specialized_equals_general_bit_for_bit() {
    // Diffuse-only path tracing: every lobe compiled out.
    let (s, g) = same_bits(&opts(own("cornell_diffuse_path.test"), 48, 48, 8));
    assert_eq!((s.as_str(), g.as_str()), ("pathtracer<lobes=none>", "general"));
    // The built-in box (direct lighting, one glossy Phong sphere).
    let o = RenderOptions { size: Some((48, 48)), spp: Some(2), threads: 2, ..Default::default() };
    assert_eq!(same_bits(&o).0, "direct<lobes=phong>");
    // The built-in box path traced with BRDF sampling is a Phong kernel.
    let o = RenderOptions { integrator: Some(strata::scene::desc::IntegratorKind::PathTracer), ..o };
    assert_eq!(same_bits(&o).0, "pathtracer<lobes=phong>");
}

#[test]
fn course_scenes_specialized_equals_general_bit_for_bit() {
    let root = corpus_required();
    for (scene, kernel) in [
        ("hw3/cornellNEE.test", "pathtracer<lobes=phong>"),
        ("hw3/cornellRR.test", "pathtracer<lobes=phong>"),
        ("hw4/cornellBRDF.test", "pathtracer<lobes=phong>"),
        ("hw4/cornellMIS.test", "pathtracer<lobes=phong>"),
        ("hw4/ggx.test", "pathtracer<lobes=ggx>"),
        ("hw2/cornell.test", "direct<lobes=phong>"),
        ("hw2/direct9.test", "direct<lobes=none>"),
    ] {
        let (s, _) = same_bits(&opts(root.join(scene), 40, 40, 4));
        assert_eq!(s, kernel, "{scene}");
    }
}

#[test]
fn stats_report_features() {
    let out = render_to_film(&opts(own("cornell_diffuse_path.test"), 16, 16, 1)).expect("render");
    let j = stats_json(&out);
    let f = &j["features"];
    assert_eq!(f["materials"], serde_json::json!(["diffuse"]));
    assert_eq!(f["geometry"], serde_json::json!(["triangles", "spheres"]));
    assert_eq!(f["quad_lights"], 1);
    assert_eq!(f["direct_light_choice"], "single");
    assert_eq!(f["light_selection"], j["light_selection"], "one name for the rule in use");
    assert_eq!(f["nee"], "on");
    assert_eq!(j["kernel"], "pathtracer<lobes=none>");
}

/// `direct` shades GGX, Phong and diffuse with the path tracer's material code: the kernel
/// compiled for the scene's lobes gives the general kernel's image bit for bit on GGX and Phong
/// scenes, and its image mean agrees with the path tracer's at max depth 1 with NEE (the same
/// direct-lighting integral by another estimator) within 4 standard errors.
#[test]
fn direct_on_ggx_and_phong_is_kernel_invariant_and_agrees_with_the_path_tracer() {
    use strata::integrator::LightSelection;
    use strata::scene::desc::{IntegratorKind, Nee};
    let root = corpus_required();
    for (scene, kernel) in [("hw4/ggx.test", "direct<lobes=ggx>"), ("hw4/cornellBRDF.test", "direct<lobes=phong>")] {
        let o = RenderOptions {
            integrator: Some(IntegratorKind::Direct),
            light_selection: Some(LightSelection::ALL),
            first_sample: Some(strata::integrator::FirstSample::Jittered),
            ..opts(root.join(scene), 64, 32, 16)
        };
        assert_eq!(same_bits(&o).0, kernel, "{scene}");
        // Image means and their standard errors (pixels are independent).
        let mean_se = |o: &RenderOptions| {
            let f = render_to_film(o).expect("render").film;
            let (m, v) = (common::means(&f), common::var_of_mean(&f));
            let n = (3 * m.len()) as f64;
            (m.iter().flatten().sum::<f64>() / n, v.iter().flatten().sum::<f64>().sqrt() / n)
        };
        let (d, d_se) = mean_se(&RenderOptions { spp: Some(256), ..o.clone() });
        let path = RenderOptions {
            integrator: Some(IntegratorKind::PathTracer),
            nee: Some(Nee::On),
            max_depth: Some(1),
            spp: Some(256),
            ..o.clone()
        };
        let (p, p_se) = mean_se(&path);
        let z = (d - p) / (d_se * d_se + p_se * p_se).sqrt();
        eprintln!("{scene}: direct mean {d:.5} +- {d_se:.5}, path tracer {p:.5} +- {p_se:.5}, z {z:.2}");
        assert!(z.abs() < 4.0, "{scene}: direct {d} vs path tracer {p} (z {z:.2})");
    }
}

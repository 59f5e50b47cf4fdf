//! `strata experiments` in a tiny configuration: every file is written, and the qualitative
//! results the experiments exist to show hold (grid centres: no variance but a bias; stratified
//! and Halton light samples: less variance than random; every unbiased path-tracing variant's mean
//! error within 4 standard errors of zero).

use crate::common;

#[test]
fn tiny_experiments_write_tables_report_and_plots() {
    let corpus = common::corpus_required();
    let dir = common::tmpdir("experiments");
    let out = dir.to_path_buf();
    let cfg = strata::lab::experiments::Config {
        corpus,
        out: out.clone(),
        runs: 4,
        width: 32,
        ref_light_samples: 256,
        ref_spp: 128,
        threads: 2,
        verbose: false,
        sheet_factor: 1,
    };
    let md = strata::lab::experiments::run(&cfg).expect("experiments run");
    for f in ["results.md", "results.json", "direct.svg", "report.html"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    for k in ["pixel4", "pixel5", "cosine", "brdf"] {
        assert!(out.join(format!("path-{k}.svg")).is_file(), "{k}");
    }
    // One report page through compare's page code: a flip-book per scene and case, no bitmap sheets.
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert_eq!(page.matches("<section id=").count(), 3 + 4, "3 direct scenes and 4 path cases");
    assert!(page.contains("data-label=\"halton 25\"") && page.contains("data-label=\"brdf 10 spp\""));
    assert!(!out.join("direct-sphere.png").exists());
    assert!(md.contains("## Direct lighting, hw2 dragon, 25 light samples"));
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 3 * 2 * 4 + 4 * 4, "24 direct rows, 4 path tables of 2 equal-spp + 2 equal-time rows");
    let get = |scene: &str, variant: &str, setting: &str, key: &str| -> f64 {
        let r = rows
            .iter()
            .find(|r| r["scene"] == scene && r["variant"] == variant && r["setting"] == setting)
            .unwrap_or_else(|| panic!("{scene} {variant} {setting}"));
        r["stats"][key].as_f64().unwrap()
    };
    for scene in ["sphere", "cornell", "dragon"] {
        for n in ["9", "25"] {
            assert_eq!(get(scene, "grid-center", n, "variance"), 0.0, "{scene} {n}: grid centres are deterministic");
            assert!(get(scene, "grid-center", n, "rms_bias") > 0.0, "{scene} {n}: grid centres are biased");
            let random = get(scene, "random", n, "variance");
            for v in ["stratified", "halton"] {
                assert!(get(scene, v, n, "variance") < 0.7 * random, "{scene} {n}: {v} vs random");
            }
        }
    }
    // Every row was profiled: the sampler's cost per camera sample and its share of the render.
    for r in rows {
        let (ns, share) = (r["stats"]["sampler_ns_per_sample"].as_f64(), r["stats"]["sampler_share"].as_f64());
        assert!(ns.is_some_and(|v| v > 0.0), "{r}");
        assert!(share.is_some_and(|v| v > 0.0 && v < 1.0), "{r}");
    }
    assert!(md.contains("| sampler ns/sample | % in sampler |") && md.contains("CPU time of the worker threads"));
    for r in rows.iter().filter(|r| r["table"] != "direct") {
        let z = r["stats"]["z"].as_f64().unwrap();
        assert!(z.abs() < 4.0, "{} {} {}: z = {z}", r["table"], r["variant"], r["setting"]);
    }
}

//! The checks `strata compare` makes before it renders: variants (names, flags it owns) and the
//! reference (scene, size, camera, as recorded in the EXR by `strata reference`).

use super::{LabError, Variant};
use crate::film::ExrImage;
use crate::session::RenderOptions;

/// Refuses an empty or duplicate variant name and a variant that sets what `compare` owns: the spp
/// (`--spp-ladder`/`--budget`), the size (compare's `--size`, one for all), the outputs (`-o`,
/// `--stats`, `--profile`: compare's `--out` and `--profile`) and the render loop (`--samples`,
/// `--time-budget`, checkpoints).
pub fn check_variants(variants: &[Variant]) -> Result<(), LabError> {
    if variants.is_empty() {
        return Err(LabError::NoVariants);
    }
    for (i, v) in variants.iter().enumerate() {
        if v.name.trim().is_empty() {
            return Err(LabError::BadVariant { variant: v.name.clone(), why: "the name is empty".into() });
        }
        if variants[..i].iter().any(|w| w.name == v.name) {
            return Err(LabError::BadVariant {
                variant: v.name.clone(),
                why: "the name is given twice (variant names label rows and images: make them unique)".into(),
            });
        }
        if let Some(why) = owned_flag(&v.opts) {
            return Err(LabError::BadVariant { variant: v.name.clone(), why: why.into() });
        }
    }
    Ok(())
}

/// Why a variant's options are refused, if they set something `compare` owns.
fn owned_flag(o: &RenderOptions) -> Option<&'static str> {
    let owned: [(bool, &'static str); 9] = [
        (o.spp.is_some(), "--spp is set by compare (--spp-ladder or --budget), for every variant"),
        (
            o.size.is_some(),
            "--size is set by compare's own --size, one for every variant (it must match the reference)",
        ),
        (o.out.is_some(), "-o/--out: compare writes its outputs into its own --out folder"),
        (o.stats.is_some(), "--stats: compare writes rows.json and runs.json into its --out folder"),
        (o.profile.is_some(), "--profile: every compare run is profiled; use compare's --profile FILE"),
        (o.samples.is_some(), "--samples: compare renders whole runs"),
        (o.time_budget.is_some(), "--time-budget: use compare's --budget"),
        (o.checkpoint.is_some() || o.resume.is_some(), "--checkpoint/--resume: compare's runs are not checkpointed"),
        (o.threads != 0, "--threads is set by compare's own --threads"),
    ];
    owned.into_iter().find_map(|(set, why)| set.then_some(why))
}

/// What of the reference differs from `variant`'s scene file hash (`file_hash`), image size and
/// camera; empty when they agree. A reference without the attributes (not written by strata) is
/// checked for its size only, and the returned notes say what could not be checked.
pub fn reference_mismatch(
    reference: &ExrImage,
    variant: &str,
    file_hash: &str,
    size: (u32, u32),
    camera: &str,
) -> (Vec<String>, Vec<String>) {
    let meta = |k: &str| reference.meta.iter().find(|(key, _)| key == k).map(|(_, v)| v.as_str());
    let (mut diffs, mut notes) = (Vec::new(), Vec::new());
    match meta("strata.scene_hash").map(|h| h.split('-').next().unwrap_or(h)) {
        Some(h) if h != file_hash => diffs.push(format!(
            "scene: the reference is of {} (file hash {h}), variant {variant} renders a scene with file hash {file_hash}",
            meta("strata.scene").unwrap_or("another scene")
        )),
        Some(_) => {}
        None => notes.push("the reference has no strata.scene_hash attribute: its scene was not checked".into()),
    }
    if (reference.width, reference.height) != size {
        diffs.push(format!(
            "size: the reference is {}x{}, variant {variant} renders {}x{} (give compare --size)",
            reference.width, reference.height, size.0, size.1
        ));
    }
    match meta("strata.camera") {
        Some(c) if c != camera => {
            diffs.push(format!("camera: the reference's is \"{c}\", variant {variant}'s is \"{camera}\""))
        }
        Some(_) => {}
        None => notes.push("the reference has no strata.camera attribute: its camera was not checked".into()),
    }
    (diffs, notes)
}

/// What is known of a reference's own noise: the degrees of freedom of each value of its variance
/// layer (`R - 1` for R replicas, `spp - 1` for the i.i.d. layer of one render; `None` when not
/// recorded) and notes for the report: its provenance (spp, samplers, mean variance, how the layer
/// was estimated) and a warning when the layer is the i.i.d. formula over samples that are not
/// independent (it then overstates the reference's noise, and so does every statistic that
/// subtracts it).
pub fn reference_noise(reference: &ExrImage) -> (Option<f64>, Vec<String>) {
    let meta = |k: &str| reference.meta.iter().find(|(key, _)| key == k).map(|(_, v)| v.as_str());
    let Some(var) = &reference.variance else {
        return (None, vec!["the reference has no variance layer: it is taken as exact".into()]);
    };
    let mean = var.iter().flat_map(|p| p.iter().map(|&v| f64::from(v))).sum::<f64>() / (3 * var.len().max(1)) as f64;
    let samplers: Vec<&str> =
        ["strata.pixel_sampler", "strata.light_sampler", "strata.layout"].iter().filter_map(|k| meta(k)).collect();
    let how = meta("strata.variance");
    let mut notes = vec![format!(
        "reference: {} spp, samplers {}, seed {}, mean own variance {mean:.3e} per value ({})",
        meta("strata.spp").unwrap_or("?"),
        if samplers.is_empty() { "not recorded".to_string() } else { samplers.join(" / ") },
        meta("strata.seed").unwrap_or("?"),
        how.unwrap_or("how the variance layer was estimated is not recorded"),
    )];
    let replicas = meta("strata.replicas").and_then(|r| r.parse::<f64>().ok()).filter(|&r| r >= 2.0);
    let dof = match replicas {
        Some(r) => Some(r - 1.0),
        None => {
            let all_independent = !samplers.is_empty() && samplers.iter().all(|s| s.contains("independent"));
            if !all_independent {
                notes.push(
                    "the reference's variance layer is the i.i.d. formula over samples that are not (all) independent: \
                     it overstates the reference's noise, so `MSE - ref. var.` and the bias intervals are too generous; \
                     remake it with `strata reference` (independent replicas)"
                        .into(),
                );
            }
            meta("strata.spp").and_then(|n| n.parse::<f64>().ok()).filter(|&n| n >= 2.0).map(|n| n - 1.0)
        }
    };
    (dof, notes)
}

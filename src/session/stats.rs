//! The statistics of a render, in one place: the `--stats` JSON and the one-line summary.

use super::RenderOutput;
use crate::integrator::kernel::features_json;
use crate::scene::desc::IntegratorKind;
use serde_json::json;

/// The `--stats` JSON.
pub fn stats_json(out: &RenderOutput) -> serde_json::Value {
    let d = &out.scene.desc;
    let c = &out.stats.counters;
    let mut j = json!({
        "scene": d.source.display().to_string(),
        "integrator": d.integrator.name(),
        "seconds": out.stats.seconds,
        "spp": out.film.samples().len(),
        "samples": [out.header.samples[0], out.header.samples[1]],
        "cpu_seconds": out.stats.cpu_seconds,
        "total_render_seconds": out.header.render_seconds,
        "total_cpu_seconds": out.header.cpu_seconds,
        "interrupted": out.interrupted,
        "checkpoint": out.checkpoint.as_ref().map(|p| p.display().to_string()),
        "layout": out.header.options.get("layout"),
        "width": d.width,
        "height": d.height,
        "seed": out.integrator.seed,
        "threads": out.stats.threads,
        "pixel_sampler": out.integrator.pixel_set.kind().name(),
        "light_sampler": out.integrator.light_set.kind().name(),
        "light_samples": out.integrator.light_set.n(),
        "sampler": out.integrator.path_set.set().kind().name(),
        "light_choice": out.integrator.light_choice.name(),
        "light_warp": out.integrator.light_warp.name(),
        "rays": { "camera": c.camera, "shadow": c.shadow, "bounce": c.bounce, "total": c.total_rays() },
        "mrays_per_sec": out.stats.mrays_per_sec(),
        "packets": { "camera": c.camera_packets, "bounce": c.bounce_packets, "shadow": c.shadow_packets },
        "occupancy": c.occupancy(),
        "occupancy_by_kind": { "bounce": c.bounce_occupancy(), "shadow": c.shadow_occupancy() },
        "mean_path_length": c.mean_path_length(),
        "max_depth": out.integrator.max_depth,
        "nee": out.integrator.path.nee.name(),
        "russian_roulette": out.integrator.path.russian_roulette,
        "importance_sampling": out.integrator.path.strategy.name(),
        "nonfinite_samples": c.nonfinite,
        "clamp": out.integrator.path.clamp,
        "biased": out.integrator.path.clamp.is_some(),
        "first_sample": out.integrator.first_sample.name(),
        "light_selection": out.integrator.light_selection.name(),
        "quantize": out.header.options.get("quantize"),
        "features": features(out),
        "kernel": out.integrator.kernel.name(d.integrator),
        "version": env!("CARGO_PKG_VERSION"),
    });
    // The process's CPU seconds over the passes, and the share of it not spent making samples
    // (tile set-up and film copies, film merges, workers waiting at a pass's end).
    j["process_cpu_seconds"] = json!(out.stats.process_cpu_seconds);
    j["overhead_share"] = json!(out.stats.overhead_share());
    j
}

/// `features` of `--stats`: what the scene uses, with `light_selection` the rule in use (the same
/// value as the top-level `light_selection`; `direct`'s own choice is `direct_light_choice`).
fn features(out: &RenderOutput) -> serde_json::Value {
    let it = &out.integrator;
    let mut f =
        features_json(&out.scene, out.scene.desc.integrator, it.path.nee, it.path.russian_roulette, it.path.strategy);
    f["light_selection"] = serde_json::json!(it.light_selection.name());
    f
}

/// One-line summary printed after a render.
pub fn summary(out: &RenderOutput) -> String {
    summary_with_spp(out, &format!("{} spp", out.film.samples().len()))
}

/// [`summary`] with the sample count spelled `spp` ("64 spp", "64 spp (8 replicas x 8)").
pub fn summary_with_spp(out: &RenderOutput, spp: &str) -> String {
    let d = &out.scene.desc;
    let c = &out.stats.counters;
    let it = &out.integrator;
    // The settings that matter for this integrator only.
    let technique = match d.integrator {
        IntegratorKind::Direct => format!(
            " (light {} x{}, lights {})",
            it.light_set.kind().name(),
            it.light_set.n(),
            it.light_selection.name()
        ),
        IntegratorKind::PathTracer => {
            format!(
                " (sampler {}, pixel {}, light {}, nee {}, lights {}, {} sampling, rr {}, maxdepth {})",
                it.path_set.set().kind().name(),
                it.pixel_set.kind().name(),
                it.light_set.kind().name(),
                it.path.nee.name(),
                it.light_selection.name(),
                it.path.strategy.name(),
                if it.path.russian_roulette { "on" } else { "off" },
                it.max_depth
            ) + &it.path.clamp.map(|m| format!(", CLAMPED at {m}: biased")).unwrap_or_default()
        }
        _ => String::new(),
    };
    format!(
        "{} {}x{} {} {}{}, kernel {}: {:.3} s, {:.2} Mrays/s (camera {}, bounce {}, shadow {}), occupancy {:.1}%, {} threads, {} non-finite{}",
        d.source.display(),
        d.width,
        d.height,
        spp,
        d.integrator.name(),
        technique,
        it.kernel.name(d.integrator),
        out.stats.seconds,
        out.stats.mrays_per_sec(),
        c.camera,
        c.bounce,
        c.shadow,
        100.0 * c.occupancy(),
        out.stats.threads,
        c.nonfinite,
        out.out.as_ref().map(|p| format!(" -> {}.exr/.png", p.display())).unwrap_or_default()
    )
}

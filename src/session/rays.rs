//! `strata rays`: the whole renderer's rays/s next to Embree's raw rate on the same packets.

use super::{prepare, RenderOptions, SessionError};
use crate::measure::{self, RayRates};

/// `strata rays`: renderer rays/s next to Embree's raw rate on the same packets; returns the
/// rates and the scene's name.
pub fn run_rays(opts: &RenderOptions) -> Result<(RayRates, String), SessionError> {
    let (scene, integrator) = prepare(opts)?;
    if integrator.kind == crate::scene::desc::IntegratorKind::ParticleTracer {
        // Its light paths are traced outside the per-tile calls `strata rays` logs and replays.
        return Err(SessionError::RaysNotLogged { integrator: integrator.kind.name() });
    }
    let rates = measure::ray_rates(&scene, &integrator, integrator.spp);
    Ok((rates, scene.desc.source.display().to_string()))
}

/// A small table of [`RayRates`].
pub fn rates_table(name: &str, r: &RayRates) -> String {
    let kinds = |c: f64, b: f64, s: f64| format!("(camera {c:.2}, bounce {b:.2}, shadow {s:.2})");
    format!(
        "{name}: {} camera + {} bounce + {} shadow rays, 1 thread\n  renderer          {:8.2} Mrays/s\n  Embree raw mixed  {:8.2} Mrays/s  {}\n  renderer / raw    {:8.1} %\n  Embree alone on the same lanes at its other widths (rendering traces 8 wide):\n    16 wide         {:8.2} Mrays/s  {}\n    one by one      {:8.2} Mrays/s  {}",
        r.camera_rays,
        r.bounce_rays,
        r.shadow_rays,
        r.renderer_mrays,
        r.raw_mixed_mrays,
        kinds(r.raw_camera_mrays, r.raw_bounce_mrays, r.raw_shadow_mrays),
        100.0 * r.ratio,
        r.raw16_mixed_mrays,
        kinds(r.raw16_camera_mrays, r.raw16_bounce_mrays, r.raw16_shadow_mrays),
        r.raw1_mixed_mrays,
        kinds(r.raw1_camera_mrays, r.raw1_bounce_mrays, r.raw1_shadow_mrays),
    )
}

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
    format!(
        "{name}: {} camera + {} bounce + {} shadow rays, 1 thread\n  renderer          {:8.2} Mrays/s\n  Embree raw mixed  {:8.2} Mrays/s  (camera {:.2}, bounce {:.2}, shadow {:.2})\n  renderer / raw    {:8.1} %",
        r.camera_rays,
        r.bounce_rays,
        r.shadow_rays,
        r.renderer_mrays,
        r.raw_mixed_mrays,
        r.raw_camera_mrays,
        r.raw_bounce_mrays,
        r.raw_shadow_mrays,
        100.0 * r.ratio
    )
}

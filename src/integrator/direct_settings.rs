//! `direct`'s own settings (the scene's `bsdf_samples` and emitter sampling, Mitsuba's
//! `emitter_samples`/`bsdf_samples`, after `--bsdf-samples`), resolved once per render.
//! `Integrator::direct` holds them; only `direct` reads them (and a render's identity reports
//! them). The light samples themselves stay `Integrator::light_set` (shared with the layouts).

use crate::scene::desc::SceneDesc;

/// How `direct` splits its shading samples between the emitters and the BSDF.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DirectSettings {
    /// BSDF samples per shading point (0: light sampling alone, the `.test` default)
    pub bsdf_samples: u32,
    /// whether the emitters are sampled (false: BSDF sampling alone, Mitsuba's
    /// `emitter_samples` 0)
    pub emitter_sampling: bool,
}

impl DirectSettings {
    /// The scene's settings.
    pub fn of(d: &SceneDesc) -> Self {
        Self { bsdf_samples: d.bsdf_samples, emitter_sampling: d.emitter_sampling }
    }

    /// Whether light and BSDF samples are both drawn, so both are weighted by MIS.
    pub fn mis(&self) -> bool {
        self.bsdf_samples > 0 && self.emitter_sampling
    }
}

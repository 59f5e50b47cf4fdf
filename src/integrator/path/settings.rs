//! The path tracer's own settings (the scene's `nexteventestimation`, `russianroulette` and
//! `importancesampling`, after command-line overrides, and `--clamp`), resolved once per render.
//! `Integrator::path` holds them; only the path tracer reads them (and the stats, the summary and
//! a render's identity report them).

use crate::scene::desc::{ImportanceSampling, Nee, SceneDesc};

/// What `pathtracer` does at each vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    /// next event estimation: off, on, MIS
    pub nee: Nee,
    /// Russian roulette
    pub russian_roulette: bool,
    /// first vertex where Russian roulette is played (1: the camera hit)
    pub rr_depth: u32,
    /// direction sampling strategy
    pub strategy: ImportanceSampling,
    /// opt-in and biased: each pixel sample is scaled so its largest channel is at most this
    /// radiance (None: no clamping, the unbiased default)
    pub clamp: Option<f32>,
}

impl PathSettings {
    /// The scene's settings, without clamping.
    pub fn of(d: &SceneDesc) -> Self {
        Self {
            nee: d.nee,
            russian_roulette: d.russian_roulette,
            rr_depth: d.rr_depth.max(1),
            strategy: d.importance_sampling,
            clamp: None,
        }
    }
}

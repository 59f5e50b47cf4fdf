//! `<integrator type="ptracer">`: Mitsuba's particle tracer (`max_depth`, -1 unbounded;
//! `rr_depth`; `hide_emitters`), strata's `ptracer` integrator (`integrator/ptracer.rs`): light
//! paths from the emitters, each vertex connected to the sensor and splatted onto the film.
//! `samples_per_pass` only schedules Mitsuba's passes; it is read and ignored (strata's passes
//! never change the image).

use super::{Build, Plugin, Run};
use crate::scene::desc::IntegratorKind;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "integrator", kind: "ptracer", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    b.desc.integrator = IntegratorKind::ParticleTracer;
    // Mitsuba's `max_depth` counts segments from the emitter to the sensor: a light path of
    // `max_depth` segments has `max_depth - 1` surface vertices, strata's depth.
    b.desc.max_depth = super::path::depth(p)?;
    let _ = p.int("samples_per_pass", -1)?;
    super::path::roulette_and_emitters(b, p)
}

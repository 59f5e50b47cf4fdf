//! `<integrator type="path">`: `max_depth` (-1: unbounded), `rr_depth`, `hide_emitters`; strata's
//! path tracer with NEE and MIS, as Mitsuba's.

use super::{Build, Plugin, Run};
use crate::scene::desc::{ImportanceSampling, IntegratorKind, Nee};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "integrator", kind: "path", run: Run::Scene(run) };

/// Mitsuba's `max_depth` (longest path in segments, -1 unbounded) as strata's (bounces after
/// the camera ray: one less).
pub fn depth(p: &Props) -> Result<i32, SceneError> {
    let d = p.int("max_depth", -1)?;
    if d == 0 || d < -1 {
        return Err(p.elem.at.err(format!("max_depth {d} is not supported (use -1 or a depth >= 1)")));
    }
    Ok(if d < 0 { -1 } else { d as i32 - 1 })
}

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    b.desc.integrator = IntegratorKind::PathTracer;
    b.desc.max_depth = depth(p)?;
    b.desc.nee = Nee::Mis;
    b.desc.importance_sampling = ImportanceSampling::Brdf;
    roulette_and_emitters(b, p)
}

/// `rr_depth` and `hide_emitters`, as Mitsuba's `path` and `ptracer` read them. Russian roulette
/// changes the variance, not the expected image; as Mitsuba's, it is played from the vertex
/// `rr_depth` on (a path that never reaches it never plays).
pub(super) fn roulette_and_emitters(b: &mut Build, p: &Props) -> Result<(), SceneError> {
    let rr = p.int("rr_depth", 5)?;
    if !(1..=i64::from(u32::MAX)).contains(&rr) {
        return Err(p.elem.at.err(format!("rr_depth {rr} must be >= 1")));
    }
    b.desc.russian_roulette = true;
    b.desc.rr_depth = rr as u32;
    b.desc.hide_emitters = p.bool("hide_emitters", false)?;
    Ok(())
}

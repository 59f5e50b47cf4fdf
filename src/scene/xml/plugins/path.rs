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
    // Russian roulette changes the variance, not the expected image; Mitsuba plays it from depth
    // `rr_depth` (strata's vertex rr_depth), so a path that can never reach it (max_depth <=
    // rr_depth) never plays it: then strata does not either.
    let rr = p.int("rr_depth", 5)?;
    let max_depth = p.int("max_depth", -1)?;
    b.desc.russian_roulette = rr < 1_000 && !(max_depth >= 1 && max_depth <= rr);
    b.desc.rr_depth = rr.clamp(1, 1_000) as u32;
    if p.bool("hide_emitters", false)? {
        return Err(p.elem.at.err("hide_emitters is not supported yet"));
    }
    Ok(())
}

//! `<integrator type="direct">`: `emitter_samples` (strata's light samples per light);
//! `bsdf_samples` only changes Mitsuba's variance (strata samples the lights alone, which covers
//! every area light it renders).

use super::{Build, Plugin, Run};
use crate::scene::desc::IntegratorKind;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "integrator", kind: "direct", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let shading = p.int("shading_samples", 1)?;
    let e = p.int("emitter_samples", shading)?;
    let bs = p.int("bsdf_samples", shading)?;
    if e < 1 || e > i64::from(b.limits.max_light_samples) {
        return Err(p.elem.at.err(format!("emitter_samples {e} must be in 1..={}", b.limits.max_light_samples)));
    }
    if bs < 0 {
        return Err(p.elem.at.err(format!("bsdf_samples {bs} must be >= 0")));
    }
    b.desc.hide_emitters = p.bool("hide_emitters", false)?;
    b.desc.integrator = IntegratorKind::Direct;
    b.desc.light_samples = e as u32;
    Ok(())
}

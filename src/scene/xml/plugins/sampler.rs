//! `<sampler>`: Mitsuba's sampler types mapped onto strata's registry (`independent`,
//! `stratified`, `multijitter` (strata's, correlated multi-jittered as Mitsuba's), `ldsampler` and `sobol` -> sobol), and `sample_count`
//! (the scene's spp). `--sampler` and `--spp` override both.

use super::{Build, Plugin, Run};
use crate::sampler::SamplerKind;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;

/// `independent`.
pub const INDEPENDENT: Plugin = Plugin { tag: "sampler", kind: "independent", run: Run::Scene(run) };
/// `stratified`.
pub const STRATIFIED: Plugin = Plugin { tag: "sampler", kind: "stratified", run: Run::Scene(run) };
/// `multijitter` (strata's multijitter).
pub const MULTIJITTER: Plugin = Plugin { tag: "sampler", kind: "multijitter", run: Run::Scene(run) };
/// `ldsampler` (strata's sobol).
pub const LDSAMPLER: Plugin = Plugin { tag: "sampler", kind: "ldsampler", run: Run::Scene(run) };
/// `sobol`.
pub const SOBOL: Plugin = Plugin { tag: "sampler", kind: "sobol", run: Run::Scene(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(), SceneError> {
    let kind = match p.elem.attr("type").unwrap_or("") {
        "independent" => SamplerKind::INDEPENDENT,
        "stratified" => SamplerKind::STRATIFIED,
        "multijitter" => SamplerKind::MULTIJITTER,
        _ => SamplerKind::SOBOL,
    };
    let n = p.int("sample_count", 4)?;
    if n < 1 || n > i64::from(b.limits.max_spp) {
        return Err(p.elem.at.err(format!("sample_count {n} must be in 1..={}", b.limits.max_spp)));
    }
    // Seeds, jitter and scrambling are the layout's own in strata (`--seed`).
    for name in ["seed", "jitter", "scramble_seed"] {
        p.ignore(name);
    }
    b.desc.spp = n as u32;
    b.desc.sampler = Some(kind);
    Ok(())
}

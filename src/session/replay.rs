//! The sampler replay of `strata profile`: one more render of the job with the sampler's calls
//! recorded ([`crate::sampler::replay`]), then those calls timed alone on this thread (thread CPU
//! time, best of a few runs, minus the cost of decoding the log), with the render's layouts and
//! with every registered kind in their place.

use crate::film::Film;
use crate::integrator::Integrator;
use crate::render;
use crate::sampler::replay::{self, Recording, ReplayMode, ReplaySets};
use crate::sampler::SamplerKind;
use crate::scene::build::Scene;
use serde::Serialize;

/// Timed runs of each replay; the least thread CPU time counts.
pub const REPLAY_REPEATS: usize = 3;

/// The replay with every call site drawing from one registered kind.
#[derive(Clone, Debug, Serialize)]
pub struct KindReplay {
    /// the sampler kind's canonical name
    pub kind: String,
    /// nanoseconds of sampler work per camera sample (scaled to every call of the render)
    pub ns_per_sample: f64,
    /// sampler calls the render made (the same sequence for every kind)
    pub calls: u64,
}

/// What the sampler alone costs on the exact call sequence of the render.
#[derive(Clone, Debug, Serialize)]
pub struct SamplerReplay {
    /// nanoseconds of sampler work per camera sample with the render's own layouts, replayed
    pub ns_per_sample: f64,
    /// the sampler phases of the profiled render, in nanoseconds per camera sample: their share of
    /// the render times its worker CPU seconds (comparable with the replay's CPU time)
    pub instrumented_ns_per_sample: f64,
    /// the render's layouts per call site ("pixel stratified, light stratified, path stratified")
    pub layouts: String,
    /// sampler calls the render made
    pub calls: u64,
    /// camera samples (pixels x spp)
    pub samples: u64,
    /// calls in the replayed log (fewer than `calls` when the log cap kept a subset of the tiles)
    pub recorded_calls: u64,
    /// the replayed calls are a deterministic subset of the tiles, scaled by `calls / recorded_calls`
    pub subset: bool,
    /// tiles in the log, and the subset level (kept tiles: hash level >= this; 0 = all)
    pub tiles_recorded: usize,
    /// subset level of the log (0: every tile)
    pub subset_level: u32,
    /// bytes of the log
    pub log_bytes: usize,
    /// nanoseconds per call spent decoding the log (measured, subtracted)
    pub decode_ns_per_call: f64,
    /// timed runs per replay (least thread CPU time counts)
    pub repeats: usize,
    /// the replay with each registered sampler kind at every call site, in registry order
    pub by_kind: Vec<KindReplay>,
}

/// The layouts `it` draws from at each call site.
pub fn replay_sets(it: &Integrator) -> ReplaySets {
    ReplaySets {
        pixel: it.pixel_set,
        light: it.light_set,
        light_table: it.light_table.clone(),
        path: it.path_set.clone(),
        path_n: it.spp,
        seed: it.seed,
    }
}

/// Renders the job once with the sampler calls recorded (at most `cap_words` log words); returns
/// the recording and the image (which must equal the unrecorded one).
pub fn record(
    scene: &Scene,
    it: &Integrator,
    pool: &rayon::ThreadPool,
    cap_words: usize,
) -> (Recording, Vec<[f32; 3]>) {
    replay::start(cap_words);
    pool.broadcast(|_| replay::arm(true));
    let mut film = Film::new(scene.desc.width, scene.desc.height);
    render::render(scene, it, &mut film, 0..it.spp, pool);
    pool.broadcast(|_| replay::arm(false));
    (replay::finish(), film.mean())
}

/// Least thread CPU nanoseconds of `repeats` runs of `f`.
fn best_ns(repeats: usize, mut f: impl FnMut() -> u32) -> f64 {
    (0..repeats.max(1))
        .map(|_| {
            let t = cpu_time::ThreadTime::now();
            std::hint::black_box(f());
            t.elapsed().as_nanos() as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// Times `rec` replayed with the render's layouts (`sets`) and with every registered kind, on
/// this thread, and scales to nanoseconds per camera sample of the whole render.
pub fn time_replay(rec: &Recording, sets: &ReplaySets, samples: u64, repeats: usize) -> SamplerReplay {
    let recorded = rec.recorded_calls();
    let decode = best_ns(repeats, || rec.replay(sets, ReplayMode::DecodeOnly).1);
    // ns of the whole render per camera sample from the replayed subset's ns.
    let per_sample = |ns: f64| {
        if rec.calls() == 0 {
            return 0.0; // no sampler call: the sampler costs nothing
        }
        if recorded == 0 {
            return f64::NAN; // every tile's log was over the cap: not measured (JSON null)
        }
        (ns - decode).max(0.0) / recorded as f64 * rec.calls() as f64 / samples.max(1) as f64
    };
    let own = per_sample(best_ns(repeats, || rec.replay(sets, ReplayMode::Sample).1));
    let by_kind = SamplerKind::ALL
        .iter()
        .map(|&k| {
            let s = sets.with_kind(k);
            KindReplay {
                kind: k.name().to_string(),
                ns_per_sample: per_sample(best_ns(repeats, || rec.replay(&s, ReplayMode::Sample).1)),
                calls: rec.calls(),
            }
        })
        .collect();
    SamplerReplay {
        ns_per_sample: own,
        instrumented_ns_per_sample: 0.0,
        layouts: format!(
            "pixel {}, light {}, path {}",
            sets.pixel.kind().name(),
            sets.light.kind().name(),
            sets.path.set().kind().name()
        ),
        calls: rec.calls(),
        samples,
        recorded_calls: recorded,
        subset: recorded < rec.calls(),
        tiles_recorded: rec.tiles(),
        subset_level: rec.level(),
        log_bytes: rec.words() * 4,
        decode_ns_per_call: decode / recorded.max(1) as f64,
        repeats,
        by_kind,
    }
}

/// The replay table `strata profile` prints under the phases.
pub fn replay_table(r: &SamplerReplay) -> String {
    let f = |x: f64| if x.is_finite() { format!("{x:.1}") } else { "n/a".to_string() };
    let mut s = format!(
        "sampler replay ({}; {} calls, {} per sample; one thread, best of {}): {} ns/sample replayed vs {} ns/sample instrumented\n",
        r.layouts,
        r.calls,
        f(r.calls as f64 / r.samples.max(1) as f64),
        r.repeats,
        f(r.ns_per_sample),
        f(r.instrumented_ns_per_sample)
    );
    if r.subset {
        s += &format!(
            "  log capped: {} of {} calls replayed ({} tiles, level {}), scaled by {:.2}\n",
            r.recorded_calls,
            r.calls,
            r.tiles_recorded,
            r.subset_level,
            r.calls as f64 / r.recorded_calls.max(1) as f64
        );
    }
    s += &format!("  {:<14} {:>10} {:>8}\n", "every call by", "ns/sample", "vs this");
    for k in &r.by_kind {
        s += &format!(
            "  {:<14} {:>10} {:>7}x\n",
            k.kind,
            f(k.ns_per_sample),
            if r.ns_per_sample > 0.0 { format!("{:.2}", k.ns_per_sample / r.ns_per_sample) } else { "n/a".into() }
        );
    }
    s.pop();
    s
}

#[cfg(test)]
#[path = "replay_tests.rs"]
mod tests;

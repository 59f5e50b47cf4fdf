//! `strata profile`: the worker threads' time split into phases ([`crate::profile`]), with the
//! profiler's overhead measured in the same run (the same job rendered with profiling off,
//! interleaved) and the profiled image checked bit-identical to the unprofiled one. The same
//! [`Profile`] (JSON) comes out of `render`/`reference --profile` and, per variant, `compare
//! --profile` ([`Profile::from_stats`]), and [`profile_svg`] draws profiles as stacked bars.

use super::replay::{record, replay_sets, replay_table, time_replay, SamplerReplay, REPLAY_REPEATS};
use super::{prepare, RenderOptions, SessionError};
use crate::film;
use crate::film::Film;
use crate::profile::{self, PHASES};
use crate::render::{self, RenderStats};
use serde::Serialize;

/// Renders of each mode (profiling off, on), interleaved; the least CPU time of each counts.
pub const REPEATS: usize = 3;

/// One phase of a [`Profile`].
#[derive(Clone, Debug, Serialize)]
pub struct PhaseRow {
    /// phase name (a name starting with `sampler` is sample generation)
    pub name: String,
    /// seconds summed over the worker threads
    pub seconds: f64,
    /// fraction of `total_seconds`
    pub share: f64,
    /// nanoseconds per camera sample (pixel x spp)
    pub ns_per_sample: f64,
    /// nanoseconds per ray traced (camera, bounce and shadow)
    pub ns_per_ray: f64,
}

/// What `strata profile` measured.
#[derive(Clone, Debug, Serialize)]
pub struct Profile {
    /// scene file (or the built-in scene's name)
    pub scene: String,
    /// what the phases split: worker-thread seconds inside the tiles of the profiled render(s),
    /// plus the film merges after them and the output encoding where the command writes images
    pub total_seconds: f64,
    /// the phases; their seconds sum to `total_seconds`
    pub phases: Vec<PhaseRow>,
    /// sum of the phases' seconds over `total_seconds` (1 up to clock rounding)
    pub phase_sum_ratio: f64,
    /// worker-thread CPU seconds of the fastest profiled render
    pub cpu_seconds_profiled: f64,
    /// worker-thread CPU seconds of the fastest unprofiled render (`strata profile` only: null
    /// where nothing was rendered unprofiled, as in `render --profile`)
    pub cpu_seconds_unprofiled: Option<f64>,
    /// measured overhead of profiling: profiled / unprofiled CPU seconds - 1 (`strata profile`
    /// only, else null)
    pub overhead: Option<f64>,
    /// the share of the process's CPU time over the passes not spent making samples (tile set-up
    /// and film copies, film merges, workers waiting at a pass's end;
    /// [`RenderStats::overhead_share`]): of the profiled renders, and in `compare` of the variant's
    /// unprofiled runs (null where nothing was measured)
    pub overhead_share: Option<f64>,
    /// the profiled image is bit-identical to the unprofiled one (`strata profile` only, else null)
    pub bit_identical: Option<bool>,
    /// camera samples (pixels x spp)
    pub samples: u64,
    /// rays traced per render
    pub rays: u64,
    /// worker threads
    pub threads: usize,
    /// renders per mode, interleaved (1 for a profile of one command's renders)
    pub repeats: usize,
    /// the sampler alone on the render's exact call sequence, and with every other kind
    /// (`strata profile` only, else null)
    pub sampler_replay: Option<SamplerReplay>,
}

impl Profile {
    /// The phase split of `st` (one render, or several merged with [`RenderStats::merge`]) of
    /// scene `scene`; the fields only `strata profile` measures (overhead, the unprofiled time,
    /// bit identity) are None.
    pub fn from_stats(scene: &str, st: &RenderStats) -> Profile {
        let (samples, rays) = (st.samples, st.counters.total_rays());
        let total = st.profiled_ns as f64 * 1e-9;
        let phases: Vec<PhaseRow> = PHASES
            .iter()
            .map(|&p| {
                let s = st.phase_ns[p as usize] as f64 * 1e-9;
                PhaseRow {
                    name: p.name().to_string(),
                    seconds: s,
                    share: s / total.max(1e-12),
                    ns_per_sample: s * 1e9 / samples.max(1) as f64,
                    ns_per_ray: s * 1e9 / rays.max(1) as f64,
                }
            })
            .collect();
        let sum: f64 = phases.iter().map(|p| p.seconds).sum();
        Profile {
            scene: scene.to_string(),
            total_seconds: total,
            phase_sum_ratio: sum / total.max(1e-12),
            phases,
            cpu_seconds_profiled: st.cpu_seconds,
            cpu_seconds_unprofiled: None,
            overhead: None,
            overhead_share: (st.process_cpu_seconds > 0.0).then(|| st.overhead_share()),
            bit_identical: None,
            samples,
            rays,
            threads: st.threads,
            repeats: 1,
            sampler_replay: None,
        }
    }

    /// Seconds in sample generation: the phases whose names start with `sampler`.
    pub fn sampler_seconds(&self) -> f64 {
        self.phases.iter().filter(|r| r.name.starts_with("sampler")).map(|r| r.seconds).sum()
    }

    /// Fraction of the profiled time in sample generation.
    pub fn sampler_share(&self) -> f64 {
        self.sampler_seconds() / self.total_seconds.max(1e-12)
    }

    /// Nanoseconds of sample generation per camera sample.
    pub fn sampler_ns_per_sample(&self) -> f64 {
        self.sampler_seconds() * 1e9 / self.samples.max(1) as f64
    }
}

/// Profiles as a stacked bar chart (one bar per `(label, profile)`, its length the profiled
/// nanoseconds per camera sample, one segment and legend entry per phase in table order).
pub fn profile_svg(entries: &[(&str, &Profile)], title: &str) -> String {
    let names: Vec<&str> = PHASES.iter().map(|p| p.name()).collect();
    let bars: Vec<crate::report::Bar> = entries
        .iter()
        .map(|(label, p)| {
            let ns = p.total_seconds * 1e9 / p.samples.max(1) as f64;
            crate::report::Bar {
                label: label.to_string(),
                total: ns,
                total_label: format!("{ns:.0} ns/sample, sampler {:.1}%", 100.0 * p.sampler_share()),
                shares: names.iter().map(|n| p.phases.iter().find(|r| r.name == *n).map_or(0.0, |r| r.share)).collect(),
            }
        })
        .collect();
    crate::report::stacked_bars_svg(&bars, &names, title, "ns per camera sample (worker threads)")
}

/// Writes `text` to `path` atomically (a profile's JSON or SVG).
pub fn write_text(path: &std::path::Path, text: &str) -> Result<(), SessionError> {
    film::write_atomic(path, text.as_bytes())
        .map_err(|source| SessionError::Output { path: path.to_path_buf(), source })
}

fn render_once(
    scene: &crate::scene::build::Scene,
    it: &crate::integrator::Integrator,
    pool: &rayon::ThreadPool,
    on: bool,
) -> (RenderStats, Vec<[f32; 3]>) {
    profile::set_enabled(on);
    let mut film = Film::new(scene.desc.width, scene.desc.height);
    let st = render::render(scene, it, &mut film, 0..it.spp, pool);
    profile::set_enabled(false);
    (st, film.mean())
}

/// `strata profile`: renders the job `repeats` times with profiling off and on, interleaved, and
/// returns the phase split of the fastest profiled render, then renders it once more recording
/// the sampler calls and times their replay ([`super::replay`]).
pub fn run_profile(opts: &RenderOptions, repeats: usize) -> Result<Profile, SessionError> {
    run_profile_capped(opts, repeats, crate::sampler::replay::DEFAULT_CAP_WORDS)
}

/// [`run_profile`] keeping at most `cap_words` words of the sampler call log.
pub fn run_profile_capped(opts: &RenderOptions, repeats: usize, cap_words: usize) -> Result<Profile, SessionError> {
    let (scene, integrator) = prepare(opts)?;
    let pool = render::thread_pool(opts.threads)?;
    let repeats = repeats.max(1);
    let (mut off, mut on): (Option<RenderStats>, Option<RenderStats>) = (None, None);
    let mut bit_identical = true;
    let mut first_image: Option<Vec<[f32; 3]>> = None;
    for _ in 0..repeats {
        for mode in [false, true] {
            let (st, img) = render_once(&scene, &integrator, &pool, mode);
            match &first_image {
                None => first_image = Some(img),
                Some(f) => bit_identical &= bits(f) == bits(&img),
            }
            let best = if mode { &mut on } else { &mut off };
            if best.as_ref().is_none_or(|b| st.cpu_seconds < b.cpu_seconds) {
                *best = Some(st);
            }
        }
    }
    let (off, on) = (off.unwrap_or_default(), on.unwrap_or_default());
    let mut p = Profile::from_stats(&scene.desc.source.display().to_string(), &on);
    let (rec, img) = record(&scene, &integrator, &pool, cap_words);
    bit_identical &= first_image.as_ref().is_none_or(|f| bits(f) == bits(&img));
    let mut sampler_replay = time_replay(&rec, &replay_sets(&integrator), p.samples, REPLAY_REPEATS);
    drop(rec);
    // The phases are thread wall time; their share of the profiled render's CPU time compares
    // with the replay's thread CPU time on a loaded machine too.
    sampler_replay.instrumented_ns_per_sample = p.sampler_share() * on.cpu_seconds * 1e9 / p.samples.max(1) as f64;
    p.cpu_seconds_unprofiled = Some(off.cpu_seconds);
    p.overhead = Some(on.cpu_seconds / off.cpu_seconds.max(1e-12) - 1.0);
    p.bit_identical = Some(bit_identical);
    p.repeats = repeats;
    p.sampler_replay = Some(sampler_replay);
    Ok(p)
}

fn bits(img: &[[f32; 3]]) -> Vec<u32> {
    img.iter().flatten().map(|v| v.to_bits()).collect()
}

/// The phase table `strata profile` prints.
pub fn profile_table(p: &Profile) -> String {
    let mut s = format!(
        "{}: {} samples, {} rays, {} threads, {:.3} s profiled (worker threads in tiles, film merge, output)\n",
        p.scene, p.samples, p.rays, p.threads, p.total_seconds
    );
    s += &format!("{:<44} {:>9} {:>7} {:>10} {:>9}\n", "phase", "seconds", "%", "ns/sample", "ns/ray");
    for r in &p.phases {
        s += &format!(
            "{:<44} {:>9.4} {:>6.1}% {:>10.1} {:>9.1}\n",
            r.name,
            r.seconds,
            100.0 * r.share,
            r.ns_per_sample,
            r.ns_per_ray
        );
    }
    s += &format!(
        "sampler total {:.1}% ({:.1} ns/sample); phases sum to {:.2}% of the total",
        100.0 * p.sampler_share(),
        p.sampler_ns_per_sample(),
        100.0 * p.phase_sum_ratio
    );
    if let (Some(overhead), Some(off)) = (p.overhead, p.cpu_seconds_unprofiled) {
        s += &format!(
            "; overhead {:+.1}% (CPU {:.3} s profiled vs {:.3} s off, best of {})",
            100.0 * overhead,
            p.cpu_seconds_profiled,
            off,
            p.repeats
        );
    }
    if let Some(same) = p.bit_identical {
        s += if same { "; image bit-identical with profiling off" } else { "; image DIFFERS with profiling off" };
    }
    if let Some(r) = &p.sampler_replay {
        s += "\n";
        s += &replay_table(r);
    }
    s
}

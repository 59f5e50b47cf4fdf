//! The pass loop of a render session: the sample range in passes of about [`PASS_SECONDS`],
//! resuming a checkpoint, writing one periodically and at the end, stopping on a signal or when
//! a time budget is spent.

use super::progress::Progress;
use super::scene::{prepare, scene_hash};
use super::{output_stem, RenderOptions, SessionError, DEFAULT_CHECKPOINT_EVERY};
use crate::checkpoint::{self, Header};
use crate::film::{with_ext, Film};
use crate::integrator::Integrator;
use crate::render::{self, RenderStats};
use crate::scene::build::Scene;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Aimed wall-clock seconds of one pass (passes only schedule the work: the image is the same
/// whatever their sizes; shorter passes make checkpoints and Ctrl-C more timely).
pub const PASS_SECONDS: f64 = 2.0;

/// Everything a render produced.
pub struct RenderOutput {
    /// the scene as built
    pub scene: Scene,
    /// the integrator settings used
    pub integrator: Integrator,
    /// accumulated samples
    pub film: Film,
    /// timing and counters
    pub stats: RenderStats,
    /// the output stem written to, if any
    pub out: Option<PathBuf>,
    /// identity and totals over every session of this render (as in its checkpoint)
    pub header: Header,
    /// the checkpoint of this render (written last by [`render_to_film`]; by `run_render` after
    /// the images), if any
    pub checkpoint: Option<PathBuf>,
    /// stopped by the `stop` flag (a signal) before the sample range was done
    pub interrupted: bool,
    /// the advisory lock on the output stem, held from before the first pass until the outputs
    /// are written (a render that writes images; None for [`render_to_film`])
    pub(super) lock: Option<crate::files::StemLock>,
}

/// Renders without writing images: scene build, integrator set-up, the sample range in passes
/// (resuming `opts.resume`, writing `opts.checkpoint` periodically and at the end, stopping
/// early on `opts.stop` or when `opts.time_budget` is spent). A render that ends with no sample
/// is an error ([`SessionError::NoSamples`]) and writes nothing.
pub fn render_to_film(opts: &RenderOptions) -> Result<RenderOutput, SessionError> {
    let out = render_passes(opts, false)?;
    write_checkpoint(&out)?;
    Ok(out)
}

/// Writes the final checkpoint of `out` (its [`RenderOutput::checkpoint`], if any).
pub(super) fn write_checkpoint(out: &RenderOutput) -> Result<(), SessionError> {
    if let Some(p) = &out.checkpoint {
        checkpoint::write(p, &out.header, &out.film)?;
    }
    Ok(())
}

/// [`render_to_film`] without the final checkpoint (the caller writes the images first, then it:
/// a checkpoint that cannot be written never costs the finished images). Periodic checkpoints
/// are written here; one that fails is reported and tried again a period later, the previous
/// one staying in place. With `lock`, the output stem's [`crate::files::StemLock`] is taken
/// before the first pass (a second render to the same stem is refused) and returned held.
pub(super) fn render_passes(opts: &RenderOptions, lock: bool) -> Result<RenderOutput, SessionError> {
    render_passes_from(opts, lock, None)
}

/// A checkpoint already read: its file (for messages), header and film.
pub(super) type Resumed = (PathBuf, Header, Film);

/// [`render_passes`], resuming `prior` when given (a replica's record of a reference's
/// checkpoint) instead of reading `opts.resume`.
pub(super) fn render_passes_from(
    opts: &RenderOptions,
    lock: bool,
    prior: Option<Resumed>,
) -> Result<RenderOutput, SessionError> {
    let (scene, mut integrator) = prepare(opts)?;
    let stem = output_stem(opts, &scene.desc);
    let lock = match lock {
        true => Some(
            crate::files::StemLock::acquire(&stem)
                .map_err(|e| SessionError::BadOutput { path: stem.clone(), why: e.to_string() })?,
        ),
        false => None,
    };
    if let Some(b) = opts.time_budget {
        if !(b > 0.0 && b.is_finite()) {
            return Err(SessionError::TimeBudget(b));
        }
        // The number of samples is not known in advance: progressive layouts continue pass after
        // pass; a layout named on the command line that needs its count is refused.
        integrator = integrator.equal_time()?;
    }
    let every = opts.checkpoint_every.unwrap_or(DEFAULT_CHECKPOINT_EVERY);
    if !(every >= 0.0 && every.is_finite()) {
        return Err(SessionError::CheckpointEvery(every));
    }
    let cap = if opts.time_budget.is_some() { opts.spp.unwrap_or(u32::MAX) } else { integrator.spp };
    let target = match opts.samples {
        Some((a, b)) if a < b && b <= cap => a..b,
        Some((a, b)) => return Err(SessionError::Samples { a, b, cap }),
        None => 0..cap,
    };
    let mut header = checkpoint::identity(&scene_hash(opts)?, &scene, &integrator, opts.time_budget.is_some());
    header.target = [target.start, target.end];
    header.options.insert("quantize".into(), serde_json::json!(super::options::default_quantize(opts).name()));
    let mut film = Film::new(scene.desc.width, scene.desc.height);
    let prior = match (prior, &opts.resume) {
        (Some(p), _) => Some(p),
        (None, Some(path)) => checkpoint::read(path).map(|(h, f)| Some((path.clone(), h, f)))?,
        (None, None) => None,
    };
    if let Some((path, h, f)) = prior {
        // A larger --spp continues the render (the one change a resume may make), if its samples
        // do not depend on the total count: then the result is bit-identical to rendering it at once.
        if let Some((have, asked)) = h.spp_growth(&header, opts.allow_other_build) {
            if let Some(why) = count_bound(&integrator) {
                return Err(SessionError::ResumeGrow { path, have, asked, why });
            }
        } else if let Some(why) = h.mismatch_allowing(&header, "this render", opts.allow_other_build) {
            return Err(SessionError::ResumeMismatch { path, why });
        }
        let have = f.samples();
        if !have.is_empty() && (have.start != target.start || have.end > target.end) {
            return Err(SessionError::ResumeRange {
                path,
                have: [have.start, have.end],
                target: [target.start, target.end],
            });
        }
        (header.cpu_seconds, header.render_seconds, header.rays) = (h.cpu_seconds, h.render_seconds, h.rays);
        film = f;
    }
    // `--samples` checkpoints to OUT.ckpt by default, periodically too (`--checkpoint-every`).
    let ckpt_path = opts
        .checkpoint
        .clone()
        .or_else(|| opts.resume.clone())
        .or_else(|| opts.samples.is_some().then(|| with_ext(&stem, "ckpt")));
    let pool = render::thread_pool(opts.threads)?;
    let (w, h) = (scene.desc.width, scene.desc.height);
    let tiles = u64::from(w.div_ceil(render::TILE)) * u64::from(h.div_ceil(render::TILE));
    let mut progress = Progress::new(opts.progress, &target, film.samples().len() as u32, opts.time_budget, tiles);
    let mut stats = RenderStats { threads: pool.current_num_threads(), ..Default::default() };
    let started = Instant::now();
    let mut last_ckpt = Instant::now();
    let mut s = if film.samples().is_empty() { target.start } else { film.samples().end };
    let mut pass = render::SAMPLE_BATCH;
    let mut interrupted = false;
    if let Some(r) = &opts.rendering {
        r.store(true, Ordering::SeqCst);
    }
    // `--profile`: the phase profiler runs over every pass (it never changes the image).
    let profiling = opts.profile.is_some().then(crate::profile::enable);
    // A time budget ends on whole sets of a point set that is not progressive.
    let block = if opts.time_budget.is_some() { whole_set_spp(&integrator) } else { 1 };
    // The film stays cut into tiles over the passes: copied in once, merged back for checkpoints
    // and at the end, not around every pass.
    let (mut tiled, cut) = render::TiledFilm::from_film(&film);
    stats.merge(&cut);
    while s < target.end {
        if opts.stop.as_ref().is_some_and(|f| f.load(Ordering::SeqCst)) {
            interrupted = true;
            break;
        }
        let mut n = pass.min(target.end - s);
        if let Some(b) = opts.time_budget {
            let left = b - started.elapsed().as_secs_f64();
            if left <= 0.0 {
                break;
            }
            // Whole passes that fit in what is left of the budget (at least one sample).
            if let Some(per) = progress.secs_per_spp() {
                n = n.min(((left / per) as u32).max(1));
            }
            n = n.div_ceil(block).saturating_mul(block).min(target.end - s);
        }
        let st = progress.watch(n, started, |tiles_done| {
            render::render_tiled(&scene, &integrator, &mut tiled, s..s + n, &pool, tiles_done)
        });
        s += n;
        stats.merge(&st);
        header.cpu_seconds += st.cpu_seconds;
        header.render_seconds += st.seconds;
        header.rays += st.counters.total_rays();
        progress.pass(n, &st, started.elapsed().as_secs_f64());
        // Next pass: about PASS_SECONDS, growing at most 4x, whole wavefront batches when large.
        let per = st.seconds / f64::from(n);
        let want = ((PASS_SECONDS / per.max(1e-9)) as u32).clamp(1, pass.saturating_mul(4));
        pass = if want >= render::SAMPLE_BATCH { want / render::SAMPLE_BATCH * render::SAMPLE_BATCH } else { want };
        if let Some(p) = &ckpt_path {
            if s < target.end && last_ckpt.elapsed().as_secs_f64() >= every {
                stats.merge(&tiled.write_to(&mut film));
                if let Err(e) = checkpoint::write(p, &header, &film) {
                    progress.warn(&format!(
                        "strata: warning: {e}; the previous checkpoint stays, trying again in {every} s (rendering goes on)"
                    ));
                }
                last_ckpt = Instant::now();
            }
        }
    }
    stats.merge(&tiled.write_to(&mut film));
    drop(tiled);
    drop(profiling);
    progress.finish();
    if film.samples().is_empty() {
        return Err(SessionError::NoSamples(match opts.time_budget {
            _ if interrupted => "interrupted before the first pass".to_string(),
            Some(b) => format!("--time-budget {b} s was spent before the first pass"),
            None => "no pass ran".to_string(),
        }));
    }
    let final_ckpt = match ckpt_path {
        Some(p) => Some(p),
        None if interrupted || opts.samples.is_some() => Some(with_ext(&stem, "ckpt")),
        None => None,
    };
    header = checkpoint::header_for(header, &film);
    Ok(RenderOutput { scene, integrator, film, stats, out: None, header, checkpoint: final_ckpt, interrupted, lock })
}

/// Why the samples of `it` depend on its total count (so a render of more samples is not a
/// continuation of one of fewer), or None when every layout its integrator draws from is
/// progressive: a count-bound registry layout (a jittered grid of spp cells, Morton order over
/// the count) or a loaded point set that is not progressive (used in whole sets).
pub fn count_bound(it: &crate::integrator::Integrator) -> Option<String> {
    use crate::integrator::samples::Source;
    let entry = crate::integrator::INTEGRATORS.iter().find(|e| e.kind == it.kind)?;
    let [pixel, light, path] = it.kinds();
    let layouts = [(Source::Pixel, pixel, "pixel"), (Source::Light, light, "light"), (Source::Path, path, "path")];
    layouts.into_iter().filter(|(src, ..)| entry.dims.iter().any(|d| d.source == *src)).find_map(|(_, k, role)| {
        if let Some(n) = crate::sampler::file::whole_set_points(k) {
            Some(format!(
                "its {role} sampler {} is a set of {n} points that is not progressive (it is used in whole sets, \
                 so its first samples depend on how many there are)",
                k.name()
            ))
        } else if !k.info().progressive {
            Some(format!(
                "its {role} sampler `{}` ({}) lays its samples out for their total count, so a render of \
                 more samples places even its first ones elsewhere (renders with a progressive sampler extend: {})",
                k.name(),
                k.info().description,
                crate::integrator::settings::progressive_names()
            ))
        } else {
            None
        }
    })
}

/// The spp granularity of an equal-time run of `it`: runs must end on whole sets of every loaded
/// point set that is not progressive (`sampler::file::whole_set_points`), never partway through
/// one (`docs/POINTSETS.md`'s block rule). The pixel and path dimensions use indices `0..spp`, the
/// light dimensions `0..spp * light_samples`, so a set of N points needs spp a multiple of N, and
/// of `N / gcd(N, light_samples)` for the light. 1 when every layout is progressive.
pub fn whole_set_spp(it: &crate::integrator::Integrator) -> u32 {
    fn gcd(a: u64, b: u64) -> u64 {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
    let [pixel, light, path] = it.kinds();
    let n_light = u64::from(it.light_set.n().max(1));
    let need = [(pixel, 1), (light, n_light), (path, 1)].into_iter().filter_map(|(k, per)| {
        let n = u64::from(crate::sampler::file::whole_set_points(k)?);
        Some(n / gcd(n, per))
    });
    let lcm = need.fold(1u64, |a, b| a / gcd(a, b) * b);
    u32::try_from(lcm).unwrap_or(u32::MAX)
}

/// Sets the returned flag on SIGINT or SIGTERM (a render checks it between passes, then writes a
/// checkpoint and the image); a second signal while the flag is set exits at once.
pub fn stop_on_signals() -> Result<Arc<AtomicBool>, SessionError> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(sig, 130, Arc::clone(&flag)).map_err(SessionError::Signal)?;
        signal_hook::flag::register(sig, Arc::clone(&flag)).map_err(SessionError::Signal)?;
    }
    Ok(flag)
}

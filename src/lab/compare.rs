//! `strata compare`: sampling techniques against a reference, K independent runs per variant, at
//! equal spp (a ladder) or equal time (a budget). Inputs are checked first ([`super::checks`]):
//! the reference must be of the variants' scene, size and camera. Measures per-step and per-run
//! rows (`report_page.rs` writes them: CSV, JSON, a Markdown table, log-log plots with error bars
//! and `report.html`). Seconds are the worker threads' CPU seconds of unprofiled runs, and every
//! row carries the sampler's cost from the phase profiler, measured on one separate profiled
//! render per step ([`profile_spp`]) whose time is in no row.

use super::progress::Progress;
use super::{checks, io_err, LabError};
use crate::camera::FirstSample;
use crate::film::{self, Film};
use crate::render::{self, RenderStats};
use crate::report::{self, flip, loglog_slope, ReferenceInfo, Row, RunStats, Slope};
use crate::session::profile::Profile;
use crate::session::{self, RenderOptions};
use serde::Serialize;
use std::path::Path;

/// One technique: a name, the render options that define it and the flags they came from.
#[derive(Clone, Debug)]
pub struct Variant {
    /// label in tables and plots
    pub name: String,
    /// render options (scene, samplers, ...); seed and spp are set per run, size and threads by
    /// [`Options`]
    pub opts: RenderOptions,
    /// the command-line flags that gave `opts` (said back when two variants render the same image)
    pub flags: Vec<String>,
}

impl Variant {
    /// A variant from its options alone (no flags to quote).
    pub fn new(name: impl Into<String>, opts: RenderOptions) -> Self {
        Variant { name: name.into(), opts, flags: Vec::new() }
    }
}

/// Equal-spp ladder or equal-time budget.
#[derive(Clone, Debug)]
pub enum Mode {
    /// render each run at each of these spp
    Ladder(Vec<u32>),
    /// render each run in passes until this many CPU seconds of the worker threads are spent
    Budget(f64),
    /// a budget ladder: [`Mode::Budget`] at each of these (increasing) CPU seconds, for slopes
    /// against time
    Budgets(Vec<f64>),
}

/// How a comparison runs.
#[derive(Clone, Debug)]
pub struct Options {
    /// independent runs per variant (K >= 2)
    pub runs: usize,
    /// equal spp or equal time
    pub mode: Mode,
    /// the variant the efficiency ratios are against (default: the first)
    pub baseline: Option<String>,
    /// compare against a reference of another scene, size or camera anyway (the notes say so)
    pub force: bool,
    /// image size of every variant (default: the scene's)
    pub size: Option<(u32, u32)>,
    /// worker threads (0 = all cores)
    pub threads: usize,
    /// print a progress line per run on stderr
    pub progress: bool,
}

impl Options {
    /// K runs under `mode`, the rest default (first variant as baseline, no force, scene size,
    /// all cores, no progress).
    pub fn new(runs: usize, mode: Mode) -> Self {
        Options { runs, mode, baseline: None, force: false, size: None, threads: 0, progress: false }
    }
}

/// One variant's phase profile over its profiled renders, one per step (`compare --profile`).
#[derive(Clone, Debug, Serialize)]
pub struct VariantProfile {
    /// the variant's name
    pub variant: String,
    /// its profile (the keys of `strata profile --json`)
    #[serde(flatten)]
    pub profile: Profile,
}

/// One render of one variant at one step: a line of `runs.csv` / `runs.json`.
#[derive(Clone, Debug, Serialize)]
pub struct RunRow {
    /// the variant
    pub variant: String,
    /// the ladder step's spp (0 for an equal-time budget)
    pub step: u32,
    /// run index 0..K
    pub run: usize,
    /// the seed of this run's sample streams
    pub seed: u64,
    /// CPU seconds of the worker threads
    pub seconds: f64,
    /// samples per pixel rendered
    pub spp: u32,
    /// MSE against the reference
    pub mse: f64,
    /// relative MSE against the reference
    pub rel_mse: f64,
    /// MSE less the reference's mean variance (its own noise)
    pub mse_corrected: f64,
    /// mean signed error
    pub mean_error: f64,
    /// mean FLIP against the reference
    pub flip: f64,
    /// the equal-time budget of this run's step, CPU seconds (0 for a ladder step)
    pub budget: f64,
    /// MSE over the smallest 99.9% of squared errors ([`report::robust::trimmed_mse`])
    pub mse_trimmed: f64,
}

/// A variant's fitted convergence: log RMSE (noise-corrected) against log spp over the ladder and
/// against log CPU seconds, one point per run (see [`report::slope`]).
#[derive(Clone, Debug, Serialize)]
pub struct Convergence {
    /// the variant
    pub variant: String,
    /// slope against spp (None with fewer than two ladder steps)
    pub vs_spp: Option<Slope>,
    /// slope against CPU seconds
    pub vs_seconds: Option<Slope>,
}

/// What a comparison measured: the tables' rows, per-run rows, profiles, slopes, notes, and one
/// image per variant for the report.
pub struct Comparison {
    /// one row per (variant, step)
    pub rows: Vec<Row>,
    /// one row per (variant, step, run)
    pub runs: Vec<RunRow>,
    /// each variant's phase profile
    pub profiles: Vec<VariantProfile>,
    /// each variant's convergence slopes
    pub convergence: Vec<Convergence>,
    /// what the reader must know: forced mismatches, variants that render the same image, caps
    pub notes: Vec<String>,
    /// the reference image (linear RGB) and its size
    pub reference: film::ExrImage,
    /// each variant's images of every run at the last step (run 1 first)
    pub images: Vec<(String, Vec<Vec<[f32; 3]>>)>,
    /// the baseline variant
    pub baseline: String,
    /// worker threads of the renders
    pub threads: usize,
}

/// [`run`] with default options (first variant as baseline, no progress): the rows.
pub fn compare(variants: &[Variant], reference: &Path, runs: usize, mode: &Mode) -> Result<Vec<Row>, LabError> {
    run(variants, reference, &Options::new(runs, mode.clone())).map(|c| c.rows)
}

/// [`compare`] with each variant's profile over all its renders.
pub fn compare_profiled(
    variants: &[Variant],
    reference: &Path,
    runs: usize,
    mode: &Mode,
) -> Result<(Vec<Row>, Vec<VariantProfile>), LabError> {
    run(variants, reference, &Options::new(runs, mode.clone())).map(|c| (c.rows, c.profiles))
}

/// The seed of run `run` of a variant with base seed `base` (independent streams per run).
pub fn run_seed(base: u64, run: usize) -> u64 {
    base.wrapping_add(1 + run as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
}

/// Runs every variant `opts.runs` times (seeds 1..=K, independent streams) under `opts.mode`,
/// compares each with the reference (its variance layer enters the bias test and the
/// noise-corrected MSE) and returns what was measured. Variants and the reference are checked
/// first; every cap of a render (`--limit`) applies to each ladder step and to the budget's passes.
pub fn run(variants: &[Variant], reference: &Path, opts: &Options) -> Result<Comparison, LabError> {
    checks::check_variants(variants)?;
    if opts.runs < 2 {
        return Err(LabError::TooFewRuns { why: " (bias and variance need independent runs)" });
    }
    if opts.runs > super::MAX_RUNS {
        return Err(LabError::TooManyRuns(opts.runs));
    }
    let baseline = match &opts.baseline {
        Some(b) if variants.iter().any(|v| &v.name == b) => b.clone(),
        Some(b) => {
            let names: Vec<&str> = variants.iter().map(|v| v.name.as_str()).collect();
            return Err(LabError::UnknownBaseline { name: b.clone(), names: names.join(", ") });
        }
        None => variants[0].name.clone(),
    };
    let img = film::read_exr(reference).map_err(io_err(reference))?;
    let steps: Vec<u32> = match &opts.mode {
        Mode::Ladder(l) if l.is_empty() || l.contains(&0) || l.windows(2).any(|w| w[0] >= w[1]) => {
            return Err(LabError::BadLadder)
        }
        Mode::Ladder(l) => l.clone(),
        Mode::Budget(b) if !(b.is_finite() && *b > 0.0) => return Err(LabError::BadBudget(*b)),
        Mode::Budget(_) => vec![0],
        Mode::Budgets(l) => {
            if let Some(&b) = l.iter().find(|b| !(b.is_finite() && **b > 0.0)) {
                return Err(LabError::BadBudget(b));
            }
            if l.is_empty() || l.windows(2).any(|w| w[0] >= w[1]) {
                return Err(LabError::BadBudgetLadder);
            }
            vec![0; l.len()]
        }
    };
    // Each step's budget (CPU seconds; 0 for a ladder step).
    let budgets: Vec<f64> = match &opts.mode {
        Mode::Budget(b) => vec![*b],
        Mode::Budgets(l) => l.clone(),
        Mode::Ladder(l) => vec![0.0; l.len()],
    };
    let equal_time = !matches!(opts.mode, Mode::Ladder(_));
    // Prepare every variant first: a refused variant or reference fails before anything renders.
    let mut prepared = Vec::new();
    let mut notes = Vec::new();
    for v in variants {
        let mut o = v.opts.clone();
        o.size = opts.size;
        o.threads = opts.threads;
        o.progress = false;
        // Unbiased by default: the course's centre sample only when a variant asks for it.
        o.first_sample = Some(o.first_sample.unwrap_or(FirstSample::Jittered));
        // Every cap of a render applies to the largest step (or the scene's spp for a budget).
        o.spp = steps.iter().copied().max().filter(|&s| s > 0);
        let (scene, integ) = session::prepare(&o)?;
        let size = (scene.desc.width, scene.desc.height);
        let camera = session::output::camera_text(scene.desc.camera.as_ref());
        let hash = session::scene_hash(&o)?;
        let (diffs, mut n) = checks::reference_mismatch(&img, &v.name, &hash, size, &camera);
        if !diffs.is_empty() {
            if !opts.force || size != (img.width, img.height) {
                return Err(LabError::ReferenceMismatch {
                    reference: reference.to_path_buf(),
                    diffs: diffs.join("; "),
                    hint: if size != (img.width, img.height) { "" } else { " (--force compares anyway)" },
                });
            }
            n.extend(
                diffs.into_iter().map(|d| format!("--force: compared anyway although the reference differs: {d}")),
            );
        }
        for note in n {
            if !notes.contains(&note) {
                notes.push(note);
            }
        }
        if equal_time {
            // A layout that needs its count in advance cannot run at equal time: refuse it now.
            integ.equal_time().map_err(session::SessionError::from)?;
        }
        prepared.push((o, scene, integ));
    }
    let (variance_dof, noise_notes) = checks::reference_noise(&img);
    notes.extend(noise_notes);
    let ref_info = ReferenceInfo { variance: img.variance.as_deref(), gamma: None, variance_dof };
    let ref_srgb = flip::to_srgb8(&img.rgb);
    let mut progress = Progress::new("compare", variants.len() * steps.len() * opts.runs, opts.progress);
    let (mut rows, mut run_rows, mut profiles, mut images) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    // Per variant, step and run: a hash of the image's bits, to find variants that render the same.
    let mut renders: Vec<Vec<Vec<u64>>> = Vec::new();
    for (v, (o, scene, integ)) in variants.iter().zip(&prepared) {
        let pool = render::thread_pool(o.threads)?;
        let mut all = RenderStats { threads: pool.current_num_threads(), ..Default::default() };
        // The runs' own stats (unprofiled): their CPU time per sample and bookkeeping share.
        let mut all_runs = RenderStats { threads: all.threads, ..Default::default() };
        let (mut per_step, mut last) = (Vec::new(), Vec::new());
        for (&step, &budget) in steps.iter().zip(&budgets) {
            let (mut runs_img, mut secs, mut spps, mut hashes) = (Vec::new(), 0.0, 0.0, Vec::new());
            // The samplers the runs of this step used (equal time may replace a default).
            let mut ran = String::new();
            let mut step_stats = RenderStats { threads: all.threads, ..Default::default() };
            for run in 0..opts.runs {
                // Equal time: progressive layouts continue their sequences pass after pass; one that
                // needs its count in advance is refused.
                let mut it = if step > 0 {
                    integ.resampled(step)
                } else {
                    integ.equal_time().map_err(session::SessionError::from)?
                };
                it.seed = run_seed(o.seed, run);
                let mut film = Film::new(img.width, img.height);
                let (seconds, spp) = if step > 0 {
                    let st = render::render(scene, &it, &mut film, 0..step, &pool);
                    step_stats.merge(&st);
                    (st.cpu_seconds, step)
                } else {
                    budget_run(
                        scene,
                        &it,
                        &mut film,
                        &pool,
                        budget,
                        o.limits.max_spp,
                        &mut step_stats,
                        &mut notes,
                        &v.name,
                    )
                };
                ran = samplers_ran(&it);
                secs += seconds;
                spps += f64::from(spp);
                let mean = film.mean();
                let flip_map = flip::flip_map_srgb8(&ref_srgb, &flip::to_srgb8(&mean), img.width, img.height);
                let one = report::metrics::image_error(&mean, &img.rgb)
                    .map_err(|source| LabError::VariantStats { variant: v.name.clone(), source })?;
                let ref_var = ref_mean_variance(&img);
                run_rows.push(RunRow {
                    variant: v.name.clone(),
                    step,
                    run,
                    seed: it.seed,
                    seconds,
                    spp,
                    mse: one.mse,
                    rel_mse: one.rel_mse,
                    mse_corrected: one.mse - ref_var,
                    mean_error: one.mean,
                    flip: flip::mean(&flip_map),
                    budget,
                    mse_trimmed: report::robust::trimmed_mse(&mean, &img.rgb, report::robust::TRIM_KEEP),
                });
                hashes.push(image_hash(&mean));
                runs_img.push(mean);
                progress.run_done(&format!(
                    "{} at {}",
                    v.name,
                    if step > 0 { format!("{step} spp") } else { format!("budget {budget} s") }
                ));
            }
            let stats = RunStats::against(&runs_img, &img.rgb, ref_info)
                .map_err(|source| LabError::VariantStats { variant: v.name.clone(), source })?;
            // The runs are timed with the profiler off (it costs 10-20 % of a render: an equal-time
            // run would measure it too); one separate profiled render of the step gives the
            // sampler's columns and the variant's profile, its time in no row.
            all_runs.merge(&step_stats);
            let reached = if step > 0 { step } else { (spps / opts.runs as f64).round() as u32 };
            let prof = profiled_render(scene, integ, step, profile_spp(reached, integ), o.seed, &pool)?;
            let step_profile = Profile::from_stats("", &prof);
            all.merge(&prof);
            let k = opts.runs as f64;
            let flips = run_rows[run_rows.len() - opts.runs..].iter().map(|r| r.flip).sum::<f64>() / k;
            let mut row = Row::new(v.name.clone(), secs / k, spps / k, &stats)?
                .with_sampler(step_profile.sampler_ns_per_sample(), step_profile.sampler_share());
            row.first_sample = integ.first_sample.name().into();
            row.flip = flips;
            let mine = &run_rows[run_rows.len() - opts.runs..];
            row.mse_trimmed = mine.iter().map(|r| r.mse_trimmed).sum::<f64>() / k;
            let seed = rows.len() as u64;
            row.mse_boot_ci = report::robust::mean_ci(&mine.iter().map(|r| r.mse).collect::<Vec<_>>(), seed);
            row.rel_mse_boot_ci = report::robust::mean_ci(&mine.iter().map(|r| r.rel_mse).collect::<Vec<_>>(), seed);
            row.setting = ran;
            rows.push(row);
            per_step.push(hashes);
            last = runs_img;
        }
        images.push((v.name.clone(), last));
        renders.push(per_step);
        let mut profile = Profile::from_stats(&scene.desc.source.display().to_string(), &all);
        // The runs' CPU seconds at the profiled renders' sample count, and what profiling costs.
        let per_sample = all_runs.cpu_seconds / all_runs.samples.max(1) as f64;
        profile.cpu_seconds_unprofiled = Some(per_sample * all.samples as f64);
        profile.overhead = Some(all.cpu_seconds / (per_sample * all.samples as f64).max(1e-12) - 1.0);
        profile.overhead_share = Some(all_runs.overhead_share());
        notes.push(format!(
            "variant {}: {:.1}% of the CPU time over its runs went to other than samples (tile set-up and \
             film copies, film merges, workers waiting at a pass's end); the runs were timed unprofiled, \
             the sampler's columns come from one profiled render per step (profiling adds {:+.1}%)",
            v.name,
            100.0 * all_runs.overhead_share(),
            100.0 * profile.overhead.unwrap_or(0.0)
        ));
        profiles.push(VariantProfile { variant: v.name.clone(), profile });
    }
    mark_identical(variants, &renders, steps.len(), &mut rows, &mut notes);
    rank_against_baseline(&mut rows, &baseline, steps.len(), &run_rows, opts.runs);
    let convergence = variants.iter().map(|v| convergence(&v.name, &run_rows)).collect();
    let threads = profiles.first().map_or(opts.threads, |p: &VariantProfile| p.profile.threads);
    Ok(Comparison { rows, runs: run_rows, profiles, convergence, notes, reference: img, images, baseline, threads })
}

/// The spp of the profiled render of a step whose runs reached `reached` spp: a quarter of it
/// (the sampler's ns per sample hardly depends on the count), at least one wavefront batch (or
/// all of `reached` below that), in whole sets of a point set that is not progressive.
pub fn profile_spp(reached: u32, it: &crate::integrator::Integrator) -> u32 {
    let g = session::pass::whole_set_spp(it);
    let n = reached.div_ceil(4).max(reached.min(render::SAMPLE_BATCH)).max(1);
    n.div_ceil(g).saturating_mul(g)
}

/// The profiled render of a step (`step` spp, or 0 for an equal-time step), `spp` samples with
/// the seed of run 1: its stats, phases included.
fn profiled_render(
    scene: &crate::scene::build::Scene,
    integ: &crate::integrator::Integrator,
    step: u32,
    spp: u32,
    seed: u64,
    pool: &rayon::ThreadPool,
) -> Result<RenderStats, LabError> {
    let mut it =
        if step > 0 { integ.resampled(spp) } else { integ.equal_time().map_err(session::SessionError::from)? };
    it.seed = run_seed(seed, 0);
    let mut film = Film::new(scene.desc.width, scene.desc.height);
    let _profiling = crate::profile::enable();
    Ok(render::render(scene, &it, &mut film, 0..spp, pool))
}

/// The mean over values of the reference's own variance (0 without a variance layer).
fn ref_mean_variance(img: &film::ExrImage) -> f64 {
    img.variance.as_ref().map_or(0.0, |v| {
        v.iter().flat_map(|p| p.iter().map(|&x| f64::from(x))).sum::<f64>() / (3 * v.len().max(1)) as f64
    })
}

/// A 64-bit hash of an image's exact bits (FNV-1a): equal images, equal hashes.
fn image_hash(img: &[[f32; 3]]) -> u64 {
    let bytes: Vec<u8> = img.iter().flat_map(|p| p.iter().flat_map(|v| v.to_bits().to_le_bytes())).collect();
    crate::checkpoint::fnv1a(0xcbf2_9ce4_8422_2325, &bytes)
}

/// One equal-time run: passes until `budget` CPU seconds of the workers are spent or the
/// `max_spp` cap is reached (said in `notes`). The pixel layout is independent (the spp is not
/// known in advance). Returns the seconds and spp.
///
/// Passes grow geometrically ([`budget_pass`]): a run of n spp takes O(log n) passes, so what a
/// pass costs besides its samples (tile set-up, workers waiting at its end) is paid a few times
/// per run, not once per sample; the film stays in tiles ([`render::TiledFilm`]), merged once. The stopping rule looks at CPU time only, never at the image, as before.
#[allow(clippy::too_many_arguments)]
fn budget_run(
    scene: &crate::scene::build::Scene,
    it: &crate::integrator::Integrator,
    film: &mut Film,
    pool: &rayon::ThreadPool,
    budget: f64,
    max_spp: u32,
    stats: &mut RenderStats,
    notes: &mut Vec<String>,
    variant: &str,
) -> (f64, u32) {
    // A point set that is not progressive runs in whole sets: passes of whole blocks of `g` spp.
    let g = session::pass::whole_set_spp(it);
    let cap = (max_spp / g * g).max(g);
    let (mut t, mut s) = (0.0, 0u32);
    // The film stays cut into tiles over the passes, merged once at the end.
    let (mut tiled, cut) = render::TiledFilm::from_film(film);
    stats.merge(&cut);
    let tiles_done = std::sync::atomic::AtomicU64::new(0);
    while t < budget && s < cap {
        let n = budget_pass(t, s / g, budget).saturating_mul(g).min(cap - s);
        let st = render::render_tiled(scene, it, &mut tiled, s..s + n, pool, &tiles_done);
        stats.merge(&st);
        t += st.cpu_seconds;
        s += n;
    }
    stats.merge(&tiled.write_to(film));
    if g > 1 {
        let mut sets: Vec<String> = it
            .kinds()
            .iter()
            .filter_map(|&k| crate::sampler::file::whole_set_points(k).map(|n| format!("{} ({n} points)", k.name())))
            .collect();
        sets.dedup();
        let note = format!(
            "variant {variant}: {} not progressive (its prefixes are no sets of their own), so its equal-time \
             runs render whole sets, in blocks of {g} spp, never stopping partway through one (a run may overshoot \
             the budget; its seconds are what it spent)",
            sets.join(", ") + if sets.len() > 1 { " are" } else { " is" }
        );
        if !notes.contains(&note) {
            notes.push(note);
        }
    }
    if t < budget {
        let note = format!(
            "variant {variant}: the budget stopped at the max_spp cap ({max_spp} spp, {t:.3} of {budget} s); raise it with --limit max_spp=N"
        );
        if !notes.contains(&note) {
            notes.push(note);
        }
    }
    (t, s)
}

/// The next pass of an equal-time run that has spent `t` of `budget` CPU seconds on `s` samples:
/// the whole samples that fit in what is left at the cost per sample so far, at most doubling the
/// run (so a slow pass cannot overshoot by more than the run so far) and at least one (the run
/// stops once `t >= budget`, as one-sample passes did).
pub fn budget_pass(t: f64, s: u32, budget: f64) -> u32 {
    if s == 0 || t <= 0.0 {
        return 1;
    }
    let fit = (budget - t) / (t / f64::from(s));
    (fit.floor().min(f64::from(u32::MAX)) as u32).clamp(1, s)
}

/// Marks variants whose every run at every step is bit-identical to an earlier variant's: they are
/// not ranked (`same_as`), and a note names the flags that made no difference.
fn mark_identical(
    variants: &[Variant],
    renders: &[Vec<Vec<u64>>],
    steps: usize,
    rows: &mut [Row],
    notes: &mut Vec<String>,
) {
    for b in 1..variants.len() {
        let Some(a) = (0..b).find(|&a| renders[a] == renders[b]) else { continue };
        let (va, vb) = (&variants[a], &variants[b]);
        for s in 0..steps {
            rows[b * steps + s].same_as = Some(va.name.clone());
        }
        let only = |x: &Variant, y: &Variant| -> Vec<String> {
            x.flags.iter().filter(|f| !y.flags.contains(f)).cloned().collect()
        };
        let diff: Vec<String> = only(vb, va).into_iter().chain(only(va, vb)).collect();
        let what = if diff.is_empty() {
            "their options have the same effect".to_string()
        } else {
            format!(
                "flag {} has no effect on this integrator",
                shlex::try_join(diff.iter().map(String::as_str)).unwrap_or_else(|_| diff.join(" "))
            )
        };
        notes.push(format!("variants {} and {} render the same image: {what}; they are not ranked", va.name, vb.name));
    }
}

/// Sets each row's efficiency ratio to the baseline's row at the same step (rows are grouped by
/// variant, `steps` per variant); rows that render the baseline's image keep NaN and `same_as`.
/// Each ratio also gets a 95% bootstrap interval over both variants' runs (`runs` K per row, in
/// the rows' order).
fn rank_against_baseline(rows: &mut [Row], baseline: &str, steps: usize, runs: &[RunRow], k: usize) {
    let Some(bi) = rows.iter().position(|r| r.variant == baseline) else { return };
    let base: Vec<f64> = rows[bi..bi + steps].iter().map(|r| r.efficiency).collect();
    let pairs = |i: usize| -> Vec<(f64, f64)> { runs[i * k..(i + 1) * k].iter().map(|r| (r.mse, r.seconds)).collect() };
    for (i, r) in rows.iter_mut().enumerate() {
        if r.same_as.is_none() {
            r.eff_vs_baseline = r.efficiency / base[i % steps];
            if runs.len() >= (i + 1) * k && runs.len() >= (bi + steps) * k {
                r.eff_vs_baseline_ci = report::robust::efficiency_ratio_ci(&pairs(i), &pairs(bi + i % steps), i as u64);
            }
        }
    }
}

/// The fitted slopes of one variant from its per-run rows: RMSE with the reference's noise removed.
fn convergence(variant: &str, runs: &[RunRow]) -> Convergence {
    let mine: Vec<&RunRow> = runs.iter().filter(|r| r.variant == variant).collect();
    let rmse = |r: &RunRow| r.mse_corrected.max(0.0).sqrt();
    let spp: Vec<(f64, f64)> = mine.iter().filter(|r| r.step > 0).map(|r| (f64::from(r.spp), rmse(r))).collect();
    let secs: Vec<(f64, f64)> = mine.iter().map(|r| (r.seconds, rmse(r))).collect();
    // Equal-time runs all spend about the budget: no range of seconds to fit a slope over.
    let (lo, hi) = secs.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| (lo.min(p.0), hi.max(p.0)));
    let vs_seconds = if hi > 1.5 * lo { loglog_slope(&secs) } else { None };
    Convergence { variant: variant.into(), vs_spp: loglog_slope(&spp), vs_seconds }
}

/// The samplers an integrator runs, for the `samplers` column: pixel, light and the others, and
/// the light choice.
fn samplers_ran(it: &crate::integrator::Integrator) -> String {
    let [pixel, light, path] = it.kinds().map(|k| k.name());
    let warp = match it.light_warp {
        crate::light::warp::LightWarp::Area => String::new(),
        w => format!(", warp {}", w.name()),
    };
    format!("pixel {pixel}, light {light}, other {path}, choice {}{warp}", it.light_choice.name())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pass loop of [`budget_run`] against a model machine: `cost` CPU seconds per sample and
    /// `overhead` per pass. Returns (passes, spp, seconds).
    fn simulate(budget: f64, cost: f64, overhead: f64) -> (u32, u32, f64) {
        let (mut t, mut s, mut passes) = (0.0, 0u32, 0);
        while t < budget {
            let n = budget_pass(t, s, budget);
            t += overhead + cost * f64::from(n);
            s += n;
            passes += 1;
        }
        (passes, s, t)
    }

    /// One-sample passes paid the per-pass overhead once per sample (compare reached half the spp
    /// per CPU second of a fixed-spp render); geometric passes pay it O(log spp) times.
    #[test]
    fn equal_time_passes_grow_geometrically() {
        for (budget, cost, overhead) in [(1.0, 1e-3, 2e-4), (1.0, 1e-5, 1e-4), (4.0, 3e-2, 0.0), (0.5, 0.2, 0.1)] {
            let (passes, spp, t) = simulate(budget, cost, overhead);
            let bound = 2.0 * f64::from(spp).log2() + 3.0;
            assert!(f64::from(passes) <= bound, "{passes} passes for {spp} spp (bound {bound})");
            let fixed_rate = 1.0 / cost;
            let rate = f64::from(spp) / t;
            assert!(t >= budget, "stopped at {t} of {budget}");
            if spp >= 64 {
                assert!(rate >= 0.95 * fixed_rate, "{rate} spp/s against {fixed_rate} at fixed spp");
                assert!(t <= budget * 1.5 + cost + overhead, "overshoot: {t} for {budget}");
                // One-sample passes (the old rule) on the same machine fall below 0.95x when a
                // pass costs anything: the check is sharp.
                if overhead > 0.0 {
                    assert!(1.0 / (cost + overhead) < 0.95 * fixed_rate);
                }
            }
        }
        assert_eq!(budget_pass(0.0, 0, 1.0), 1);
        assert_eq!(
            budget_pass(0.99, 99, 1.0),
            1,
            "a sample that does not fit still runs: the run stops at t >= budget"
        );
        assert_eq!(budget_pass(0.01, 10, 1.0), 10, "at most doubling");
    }

    #[test]
    fn compare_run_seeds_are_not_reference_replica_seeds() {
        let replicas: Vec<u64> = (0..64).map(|r| session::reference::replica_seed(0, r)).collect();
        assert!((0..256).all(|run| !replicas.contains(&run_seed(0, run))));
    }
}

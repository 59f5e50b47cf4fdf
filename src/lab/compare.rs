//! `strata compare`: sampling techniques against a reference, K independent runs per variant, at
//! equal spp (a ladder) or equal time (a budget); writes CSV, JSON, a Markdown table and a
//! log-log plot of RMSE against seconds. Seconds are the worker threads' CPU seconds, and every
//! row carries the sampler's cost from the phase profiler.

use super::{io_err, LabError};
use crate::film::{self, Film};
use crate::render::{self, RenderStats};
use crate::report::{self, Row, RunStats, Series};
use crate::session::profile::Profile;
use crate::session::{self, RenderOptions};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// One technique: a name and the render options that define it.
#[derive(Clone, Debug)]
pub struct Variant {
    /// label in tables and plots
    pub name: String,
    /// render options (scene, samplers, ...); seed and spp are set per run
    pub opts: RenderOptions,
}

/// Equal-spp ladder or equal-time budget.
#[derive(Clone, Debug)]
pub enum Mode {
    /// render each run at each of these spp
    Ladder(Vec<u32>),
    /// render each run in passes until this many CPU seconds of the worker threads are spent
    Budget(f64),
}

/// One variant's phase profile over all its runs and steps (`compare --profile`).
#[derive(Clone, Debug, Serialize)]
pub struct VariantProfile {
    /// the variant's name
    pub variant: String,
    /// its profile (the keys of `strata profile --json`)
    #[serde(flatten)]
    pub profile: Profile,
}

/// Runs every variant `runs` times (seeds 1..=runs, independent streams) under `mode`, compares
/// with the reference image and returns one row per (variant, ladder step). Times are the worker
/// threads' CPU seconds (a budget too); every render is profiled, so each row carries the
/// sampler's ns per sample and share of the render.
pub fn compare(variants: &[Variant], reference: &Path, runs: usize, mode: &Mode) -> Result<Vec<Row>, LabError> {
    compare_profiled(variants, reference, runs, mode).map(|(rows, _)| rows)
}

/// [`compare`] with the phase profiler on (it never changes an image): also returns each
/// variant's profile over all its renders.
pub fn compare_profiled(
    variants: &[Variant],
    reference: &Path,
    runs: usize,
    mode: &Mode,
) -> Result<(Vec<Row>, Vec<VariantProfile>), LabError> {
    let img = film::read_exr(reference).map_err(io_err(reference))?;
    if runs < 2 {
        return Err(LabError::TooFewRuns { why: " (bias and variance need independent runs)" });
    }
    let mut rows = Vec::new();
    let mut profiles = Vec::new();
    let _profiling = crate::profile::enable();
    for v in variants {
        let (scene, integ) = session::prepare(&v.opts)?;
        if (scene.desc.width, scene.desc.height) != (img.width, img.height) {
            return Err(LabError::SizeMismatch {
                variant: v.name.clone(),
                w: scene.desc.width,
                h: scene.desc.height,
                rw: img.width,
                rh: img.height,
            });
        }
        let pool = render::thread_pool(v.opts.threads)?;
        let mut all = RenderStats { threads: pool.current_num_threads(), ..Default::default() };
        let steps: Vec<Option<u32>> = match mode {
            Mode::Ladder(l) => l.iter().map(|&s| Some(s)).collect(),
            Mode::Budget(_) => vec![None],
        };
        for step in steps {
            let (mut images, mut secs, mut spps) = (Vec::new(), 0.0, 0.0);
            // The samplers the runs of this step used (equal time may replace a default).
            let mut ran = String::new();
            let mut step_stats = RenderStats { threads: all.threads, ..Default::default() };
            for run in 0..runs {
                let mut it = integ.clone();
                it.seed = v.opts.seed.wrapping_add(1 + run as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
                let mut film = Film::new(img.width, img.height);
                let (seconds, spp) = match (step, mode) {
                    (Some(spp), _) => {
                        it = it.resampled(spp);
                        let st = render::render(&scene, &it, &mut film, 0..spp, &pool);
                        step_stats.merge(&st);
                        (st.cpu_seconds, spp)
                    }
                    (None, Mode::Budget(b)) => {
                        // Equal time: whole passes of one sample until the budget (the workers' CPU
                        // seconds) is spent. Progressive layouts continue their sequences pass
                        // after pass; one that needs its count in advance is refused.
                        it = it.equal_time().map_err(session::SessionError::from)?;
                        let (mut t, mut s) = (0.0, 0u32);
                        while t < *b {
                            let st = render::render(&scene, &it, &mut film, s..s + 1, &pool);
                            step_stats.merge(&st);
                            t += st.cpu_seconds;
                            s += 1;
                        }
                        (t, s)
                    }
                    (None, Mode::Ladder(_)) => unreachable!("ladder steps are Some"),
                };
                ran = samplers_ran(&it);
                secs += seconds;
                spps += f64::from(spp);
                images.push(film.mean());
            }
            let stats = RunStats::from_runs(&images, &img.rgb)
                .map_err(|source| LabError::VariantStats { variant: v.name.clone(), source })?;
            let step_profile = Profile::from_stats("", &step_stats);
            all.merge(&step_stats);
            let mut row = Row::new(v.name.clone(), secs / runs as f64, spps / runs as f64, &stats)?
                .with_sampler(step_profile.sampler_ns_per_sample(), step_profile.sampler_share());
            row.setting = ran;
            rows.push(row);
        }
        let profile = Profile::from_stats(&scene.desc.source.display().to_string(), &all);
        profiles.push(VariantProfile { variant: v.name.clone(), profile });
    }
    Ok((rows, profiles))
}

/// Writes rows.csv, rows.json, table.md and error.svg (RMSE against seconds, slope -1/2 guide)
/// into `dir`; returns the Markdown table.
pub fn write_outputs(rows: &[Row], dir: &Path, title: &str) -> Result<String, LabError> {
    std::fs::create_dir_all(dir).map_err(io_err(dir))?;
    let md = report::to_markdown(rows);
    let json = serde_json::to_string_pretty(&report::to_json(rows))?;
    let mut series: Vec<Series> = Vec::new();
    for r in rows {
        let p = (r.seconds, r.stats.mse.sqrt());
        match series.iter_mut().find(|s| s.name == r.variant) {
            Some(s) => s.points.push(p),
            None => series.push(Series { name: r.variant.clone(), points: vec![p] }),
        }
    }
    let svg = report::loglog_svg(&series, title, "CPU seconds (worker threads)", "RMSE", report::plot::RMSE_SLOPE);
    for (name, text) in
        [("rows.csv", report::to_csv(rows)), ("rows.json", json), ("table.md", md.clone()), ("error.svg", svg)]
    {
        let p: PathBuf = dir.join(name);
        film::write_atomic(&p, text.as_bytes()).map_err(io_err(&p))?;
    }
    Ok(md)
}

/// The samplers an integrator runs, for the `samplers` column: pixel, light and the others, and
/// the light choice.
fn samplers_ran(it: &crate::integrator::Integrator) -> String {
    let [pixel, light, path] = it.kinds().map(|k| k.name());
    format!("pixel {pixel}, light {light}, other {path}, choice {}", it.light_choice.name())
}

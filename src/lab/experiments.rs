//! `strata experiments`: the two seed experiments of the course report, regenerated into one folder
//! (Markdown tables, JSON, log-log SVG plots, and `report.html`: flip-books of the images with
//! error maps, through the page code of `strata compare`).
//!
//! - Direct lighting (hw2 sphere, cornell, dragon; 9 and 25 light samples; random, stratified,
//!   grid-centre, Halton). The pixel position is fixed at the pixel centre (`--pixel-sampler
//!   grid-center --spp 1`) for the reference and every variant, so the only randomness left is the
//!   light sampling. The reference is two independent halves of stratified light samples; their
//!   difference estimates the reference's own per-pixel variance.
//! - Path tracing (hw3 cornellNEE, hw4 cornellBRDF): pixel stratification against random jitter,
//!   cosine against uniform hemisphere, Phong-lobe BRDF sampling against cosine, at equal spp and at
//!   equal time, each against a high-spp reference whose variance layer enters the bias test.
//!
//! Seconds are the worker threads' CPU seconds, and every variant's runs are profiled for the
//! sampler's cost (`sampler ns/sample`, `% in sampler`). Every number except these timings (and
//! the equal-time spp derived from them) is a pure function of the configuration: seeds are fixed and renders are bit-identical whatever the thread count.

use super::progress::Progress;
use super::{io_err, LabError};
use crate::film::{self, Film};
use crate::render;
use crate::report::html::{self, box_downsample, Page, Section, Shot};
use crate::report::{self, markdown_table, ReferenceInfo, ReportError, Row, RunStats, Series, Style};
use crate::sampler::SamplerKind;
use crate::scene::desc::ImportanceSampling;
use crate::session::{self, RenderOptions};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Sizes and counts of one run of the experiments.
#[derive(Clone, Debug)]
pub struct Config {
    /// the CSE168 corpus (hw2, hw3, hw4 folders)
    pub corpus: PathBuf,
    /// output folder
    pub out: PathBuf,
    /// independent runs per variant (K >= 2)
    pub runs: usize,
    /// image width; heights follow each scene's aspect ratio
    pub width: u32,
    /// light samples of each half of the direct-lighting reference (stratified)
    pub ref_light_samples: u32,
    /// spp of the path-tracing references
    pub ref_spp: u32,
    /// worker threads (0 = all cores)
    pub threads: usize,
    /// print progress on stderr
    pub verbose: bool,
    /// the report's images are box-downsampled by this factor (keeps report.html small)
    pub sheet_factor: u32,
}

impl Config {
    /// The committed configuration: 160-pixel-wide images, K = 16, references of 2 x 4096 light
    /// samples and 1024 spp.
    pub fn full(corpus: PathBuf, out: PathBuf) -> Self {
        Config {
            corpus,
            out,
            runs: 16,
            width: 160,
            ref_light_samples: 4096,
            ref_spp: 1024,
            threads: 0,
            verbose: true,
            sheet_factor: 2,
        }
    }
}

/// Linear RGB images, one per run.
pub type Images = Vec<Vec<[f32; 3]>>;

/// K renders of `opts` (seeds derived from 1..=K as `strata compare` does) at `spp`: the images
/// and the mean CPU seconds of the worker threads per run.
pub fn runs(opts: &RenderOptions, spp: u32, k: usize) -> Result<(Images, f64), LabError> {
    runs_profiled(opts, spp, k).map(|r| (r.images, r.seconds))
}

/// What [`runs_profiled`] measured.
pub struct Runs {
    /// one image per run
    pub images: Images,
    /// mean CPU seconds of the worker threads per run
    pub seconds: f64,
    /// sample generation's nanoseconds per camera sample over the runs (phase profiler)
    pub sampler_ns_per_sample: f64,
    /// sample generation's fraction of the profiled render time
    pub sampler_share: f64,
}

/// [`runs`] with the phase profiler on (it never changes an image): also the sampler's cost.
pub fn runs_profiled(opts: &RenderOptions, spp: u32, k: usize) -> Result<Runs, LabError> {
    runs_counted(opts, spp, k, &mut |_| {})
}

/// [`runs_profiled`], calling `done(run)` after each run (progress).
pub fn runs_counted(opts: &RenderOptions, spp: u32, k: usize, done: &mut dyn FnMut(usize)) -> Result<Runs, LabError> {
    let (scene, integ) = session::prepare(opts)?;
    let pool = render::thread_pool(opts.threads)?;
    let integ = integ.resampled(spp);
    let mut images = Vec::with_capacity(k);
    let mut all = render::RenderStats { threads: pool.current_num_threads(), ..Default::default() };
    let _profiling = crate::profile::enable();
    for run in 0..k {
        let mut it = integ.clone();
        it.seed = opts.seed.wrapping_add(1 + run as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        let mut f = Film::new(scene.desc.width, scene.desc.height);
        all.merge(&render::render(&scene, &it, &mut f, 0..spp, &pool));
        images.push(f.mean());
        done(run);
    }
    let p = session::profile::Profile::from_stats("", &all);
    Ok(Runs {
        images,
        seconds: all.cpu_seconds / k as f64,
        sampler_ns_per_sample: p.sampler_ns_per_sample(),
        sampler_share: p.sampler_share(),
    })
}

/// A reference image, its per-value variance (of the image itself) and the scene's gamma.
pub struct Reference {
    /// linear RGB
    pub rgb: Vec<[f32; 3]>,
    /// per pixel-channel variance of `rgb`
    pub var: Vec<[f32; 3]>,
    /// the scene's PNG gamma
    pub gamma: f32,
    /// (width, height)
    pub size: (u32, u32),
    /// CPU seconds of the worker threads spent
    pub seconds: f64,
}

fn film_of(opts: &RenderOptions, seed: u64) -> Result<(Film, f32, f64), LabError> {
    let o = RenderOptions { seed, ..opts.clone() };
    let out = session::render_to_film(&o)?;
    if out.stats.counters.nonfinite != 0 {
        return Err(LabError::NonFinite {
            scene: out.scene.desc.source.display().to_string(),
            count: out.stats.counters.nonfinite,
        });
    }
    Ok((out.film, out.scene.desc.gamma, out.stats.cpu_seconds))
}

/// Direct-lighting reference: two halves with independent seeds, averaged; the per-pixel variance
/// of the average is `(a - b)^2 / 4` (spp 1, so the film has no variance layer of its own).
pub fn reference_two_halves(opts: &RenderOptions) -> Result<Reference, LabError> {
    let (a, gamma, ta) = film_of(opts, 0x5eed_0001)?;
    let (b, _, tb) = film_of(opts, 0x5eed_0002)?;
    let (ma, mb) = (a.mean(), b.mean());
    let rgb = ma.iter().zip(&mb).map(|(x, y)| [0, 1, 2].map(|c| 0.5 * (x[c] + y[c]))).collect();
    let var = ma.iter().zip(&mb).map(|(x, y)| [0, 1, 2].map(|c| 0.25 * (x[c] - y[c]).powi(2))).collect();
    Ok(Reference { rgb, var, gamma, size: (a.width, a.height), seconds: ta + tb })
}

/// Path-tracing reference: one high-spp render and its variance-of-the-mean layer.
pub fn reference_spp(opts: &RenderOptions) -> Result<Reference, LabError> {
    let (f, gamma, t) = film_of(opts, 0x5eed_0003)?;
    Ok(Reference { rgb: f.mean(), var: f.variance_of_mean(), gamma, size: (f.width, f.height), seconds: t })
}

/// The statistics of K runs against a reference, with its own variance and gamma (the 8-bit
/// statistics are on that gamma).
pub fn run_stats(images: &[Vec<[f32; 3]>], reference: &Reference) -> Result<RunStats, ReportError> {
    let info = ReferenceInfo { variance: Some(&reference.var), gamma: Some(reference.gamma), variance_dof: None };
    RunStats::against(images, &reference.rgb, info)
}

/// The row of `variant`: K runs at `spp` against `reference`, with their CPU seconds per run and
/// the sampler's cost.
fn measure(variant: &str, r: &Runs, reference: &Reference, spp: u32) -> Result<Row, LabError> {
    let stats =
        run_stats(&r.images, reference).map_err(|source| LabError::VariantStats { variant: variant.into(), source })?;
    Ok(Row::new(variant, r.seconds, f64::from(spp), &stats)?.with_sampler(r.sampler_ns_per_sample, r.sampler_share))
}

fn scene_opts(cfg: &Config, rel: &str, aspect: f64) -> RenderOptions {
    let h = ((f64::from(cfg.width) / aspect).round() as u32).max(1);
    RenderOptions {
        scene: Some(cfg.corpus.join(rel)),
        size: Some((cfg.width, h)),
        threads: cfg.threads,
        // Error studies need the unbiased layout, not the course's pixel-centre sample 0.
        first_sample: Some(crate::integrator::FirstSample::Jittered),
        ..Default::default()
    }
}

fn log(cfg: &Config, msg: &str) {
    if cfg.verbose {
        eprintln!("experiments: {msg}");
    }
}

/// An image of the report, box-downsampled by the configured factor.
fn shot(cfg: &Config, label: String, (w, h): (u32, u32), rgb: &[[f32; 3]]) -> (Shot, (u32, u32)) {
    let (w, h, rgb) = box_downsample(w, h, rgb, cfg.sheet_factor);
    (Shot { label, rgb }, (w, h))
}

/// One section of the report: its images and the rows it shows (`table`, and `scene` for the
/// direct-lighting tables).
pub struct ReportSection {
    /// the images
    pub section: Section,
    /// the rows' `table`
    pub table: String,
    /// the rows' `scene` (direct lighting), empty for a path case
    pub scene: String,
}

/// The direct-lighting experiment: returns its rows and report sections and writes `direct.svg`.
pub fn direct(cfg: &Config, progress: &mut Progress) -> Result<(Vec<Row>, Vec<ReportSection>), LabError> {
    let kinds = [
        ("random", SamplerKind::INDEPENDENT),
        ("stratified", SamplerKind::STRATIFIED),
        ("grid-center", SamplerKind::GRID_CENTER),
        ("halton", SamplerKind::HALTON),
    ];
    let mut rows = Vec::new();
    let mut sections = Vec::new();
    let mut series: Vec<Series> = Vec::new();
    for (name, rel, aspect) in [
        ("sphere", "hw2/sphere.test", 4.0 / 3.0),
        ("cornell", "hw2/cornell.test", 1.0),
        ("dragon", "hw2/dragon.test", 4.0 / 3.0),
    ] {
        let base = RenderOptions {
            spp: Some(1),
            pixel_sampler: Some(SamplerKind::GRID_CENTER),
            ..scene_opts(cfg, rel, aspect)
        };
        log(cfg, &format!("direct {name}: reference 2 x {} stratified light samples", cfg.ref_light_samples));
        let reference = reference_two_halves(&RenderOptions {
            light_sampler: Some(SamplerKind::STRATIFIED),
            light_samples: Some(cfg.ref_light_samples),
            ..base.clone()
        })?;
        let (refshot, (w, h)) =
            shot(cfg, format!("reference (2x{} stratified)", cfg.ref_light_samples), reference.size, &reference.rgb);
        let mut shots = Vec::new();
        for n in [9u32, 25] {
            for (label, kind) in kinds {
                let o = RenderOptions { light_sampler: Some(kind), light_samples: Some(n), ..base.clone() };
                let what = format!("direct {name} {label} x{n}");
                let r = runs_counted(&o, 1, cfg.runs, &mut |_| progress.run_done(&what))?;
                let st = measure(label, &r, &reference, 1)?.grouped("direct", name, format!("{n}"));
                shots.push(shot(cfg, format!("{label} {n}"), reference.size, &r.images[0]).0);
                let sname = format!("{name} {label}");
                let p = (f64::from(n), st.stats.mse.sqrt());
                match series.iter_mut().find(|s| s.name == sname) {
                    Some(s) => s.points.push(p),
                    None => series.push(Series { name: sname, points: vec![p] }),
                }
                rows.push(st);
            }
        }
        sections.push(ReportSection {
            section: Section {
                title: format!("hw2 {name}: direct lighting, pixel centre, K={}", cfg.runs),
                width: w,
                height: h,
                reference: Some(refshot),
                shots,
                runs: Vec::new(),
                blocks: Vec::new(),
            },
            table: "direct".into(),
            scene: name.into(),
        });
    }
    let svg = report::loglog_svg(
        &series,
        "direct lighting: RMSE against light samples",
        "light samples",
        "RMSE",
        report::plot::RMSE_SLOPE,
    );
    let p = cfg.out.join("direct.svg");
    film::write_atomic(&p, svg.as_bytes()).map_err(io_err(&p))?;
    if let Some(last) = sections.last_mut() {
        last.section
            .blocks
            .push(format!("<h3>All scenes: RMSE against light samples</h3>\n{}", html::inline_svg(&svg)));
    }
    Ok((rows, sections))
}

/// One path-tracing comparison: a baseline and a candidate at `spp` (and a ladder for the plot).
struct PathCase {
    key: &'static str,
    title: &'static str,
    scene: &'static str,
    reference: RenderOptions,
    variants: [(&'static str, RenderOptions); 2],
    spp: u32,
    ladder: &'static [u32],
}

/// The number of runs the path-tracing experiment renders before its equal-time steps (progress).
fn path_runs(cases: &[PathCase], k: usize) -> usize {
    cases
        .iter()
        .map(|c| {
            let mut l: Vec<u32> = c.ladder.iter().copied().chain([c.spp]).collect();
            l.sort_unstable();
            l.dedup();
            2 * l.len() * k
        })
        .sum()
}

/// The path-tracing experiment: returns its rows and report sections and writes `path-*.svg`.
pub fn path(cfg: &Config, progress: &mut Progress) -> Result<(Vec<Row>, Vec<ReportSection>), LabError> {
    let nee = scene_opts(cfg, "hw3/cornellNEE.test", 1.0);
    let brdf = scene_opts(cfg, "hw4/cornellBRDF.test", 1.0);
    let is = |o: &RenderOptions, s| RenderOptions { importance_sampling: Some(s), ..o.clone() };
    let px = |o: &RenderOptions, k| RenderOptions { pixel_sampler: Some(k), ..o.clone() };
    let cases = [
        PathCase {
            key: "pixel4",
            title: "pixel jitter: random vs 2x2 strata",
            scene: "hw3 cornellNEE",
            reference: is(&nee, ImportanceSampling::Cosine),
            variants: [
                ("random", px(&nee, SamplerKind::INDEPENDENT)),
                ("stratified", px(&nee, SamplerKind::STRATIFIED)),
            ],
            spp: 4,
            ladder: &[1, 4, 16],
        },
        PathCase {
            key: "pixel5",
            title: "pixel jitter: random vs 5x1 strata",
            scene: "hw3 cornellNEE",
            reference: is(&nee, ImportanceSampling::Cosine),
            variants: [
                ("random", px(&nee, SamplerKind::INDEPENDENT)),
                ("stratified", px(&nee, SamplerKind::STRATIFIED)),
            ],
            spp: 5,
            ladder: &[5],
        },
        PathCase {
            key: "cosine",
            title: "direction sampling: hemisphere vs cosine",
            scene: "hw3 cornellNEE",
            reference: is(&nee, ImportanceSampling::Cosine),
            variants: [
                ("hemisphere", is(&nee, ImportanceSampling::Hemisphere)),
                ("cosine", is(&nee, ImportanceSampling::Cosine)),
            ],
            spp: 10,
            ladder: &[2, 5, 10, 20],
        },
        PathCase {
            key: "brdf",
            title: "direction sampling: cosine vs Phong-lobe BRDF",
            scene: "hw4 cornellBRDF",
            reference: is(&brdf, ImportanceSampling::Brdf),
            variants: [
                ("cosine", is(&brdf, ImportanceSampling::Cosine)),
                ("brdf", is(&brdf, ImportanceSampling::Brdf)),
            ],
            spp: 10,
            ladder: &[2, 5, 10, 20],
        },
    ];
    progress.add(path_runs(&cases, cfg.runs));
    let mut rows = Vec::new();
    let mut sections = Vec::new();
    let mut refs: Vec<(RenderOptions, Reference)> = Vec::new();
    for case in &cases {
        let ro = RenderOptions { spp: Some(cfg.ref_spp), ..case.reference.clone() };
        let cached =
            refs.iter().position(|(o, _)| o.scene == ro.scene && o.importance_sampling == ro.importance_sampling);
        let ri = match cached {
            Some(i) => i,
            None => {
                log(cfg, &format!("path {}: reference {} spp", case.scene, cfg.ref_spp));
                refs.push((ro.clone(), reference_spp(&ro)?));
                refs.len() - 1
            }
        };
        let reference = &refs[ri].1;
        let (refshot, (w, h)) = shot(cfg, format!("reference ({} spp)", cfg.ref_spp), reference.size, &reference.rgb);
        let mut shots = Vec::new();
        let mut series = Vec::new();
        let mut main: Vec<Row> = Vec::new();
        for (label, o) in &case.variants {
            let spp = case.spp;
            let mut ladder: Vec<u32> = case.ladder.iter().copied().chain(std::iter::once(spp)).collect();
            ladder.sort_unstable();
            ladder.dedup();
            let mut points = Vec::new();
            for s in ladder {
                let what = format!("path {} {label} {s} spp", case.key);
                let r = runs_counted(o, s, cfg.runs, &mut |_| progress.run_done(&what))?;
                let st = measure(label, &r, reference, s)?;
                points.push((r.seconds, st.stats.mse.sqrt()));
                if s == spp {
                    shots.push(shot(cfg, format!("{label} {s} spp"), reference.size, &r.images[0]).0);
                    main.push(st);
                }
            }
            series.push(Series { name: (*label).into(), points });
        }
        for st in &main {
            rows.push(st.clone().grouped(case.key, case.scene, "equal spp"));
        }
        // Equal time: the faster technique gets the spp that costs what the slower one spent.
        let (ta, tb) = (main[0].seconds / main[0].spp, main[1].seconds / main[1].spp);
        let (fast, slow) = if ta <= tb { (0, 1) } else { (1, 0) };
        let budget = main[slow].seconds;
        let per_spp = main[fast].seconds / main[fast].spp;
        let eq_spp = ((budget / per_spp).round() as u32).max(1);
        let (label, o) = &case.variants[fast];
        let eq = if f64::from(eq_spp) == main[fast].spp {
            None
        } else {
            progress.add(cfg.runs);
            let what = format!("path {} equal time: {label} {eq_spp} spp", case.key);
            Some(runs_counted(o, eq_spp, cfg.runs, &mut |_| progress.run_done(&what))?)
        };
        let st = match &eq {
            None => main[fast].clone(),
            Some(r) => measure(label, r, reference, eq_spp)?,
        };
        if let Some(r) = &eq {
            shots.push(shot(cfg, format!("{label} {eq_spp} spp (equal time)"), reference.size, &r.images[0]).0);
        }
        rows.push(main[slow].clone().grouped(case.key, case.scene, "equal time"));
        rows.push(st.grouped(case.key, case.scene, "equal time"));
        let svg = report::loglog_svg(
            &series,
            &format!("{}: {}", case.scene, case.title),
            "CPU seconds (worker threads)",
            "RMSE",
            report::plot::RMSE_SLOPE,
        );
        let p = cfg.out.join(format!("path-{}.svg", case.key));
        film::write_atomic(&p, svg.as_bytes()).map_err(io_err(&p))?;
        sections.push(ReportSection {
            section: Section {
                title: format!("{}: {} (`{}`), K={}", case.scene, case.title, case.key, cfg.runs),
                width: w,
                height: h,
                reference: Some(refshot),
                shots,
                runs: Vec::new(),
                blocks: vec![format!("<h3>RMSE against CPU seconds</h3>\n{}", html::inline_svg(&svg))],
            },
            table: case.key.into(),
            scene: String::new(),
        });
    }
    Ok((rows, sections))
}

/// Runs both experiments and writes `results.md`, `results.json`, `report.html` and the plots into
/// `cfg.out`.
pub fn run(cfg: &Config) -> Result<String, LabError> {
    if cfg.runs < 2 {
        return Err(LabError::TooFewRuns { why: "" });
    }
    if cfg.runs > super::MAX_RUNS {
        return Err(LabError::TooManyRuns(cfg.runs));
    }
    if !cfg.corpus.join("hw2").is_dir() {
        return Err(LabError::NoCorpus(cfg.corpus.clone()));
    }
    std::fs::create_dir_all(&cfg.out).map_err(io_err(&cfg.out))?;
    let mut progress = Progress::new("experiments", 3 * 2 * 4 * cfg.runs, cfg.verbose);
    let (mut rows, mut sections) = direct(cfg, &mut progress)?;
    let (path_rows, path_sections) = path(cfg, &mut progress)?;
    rows.extend(path_rows);
    sections.extend(path_sections);
    let md = markdown(&rows, cfg.runs, cfg.width, cfg.sheet_factor);
    let json = serde_json::to_string_pretty(&report::to_grouped_json(&rows))?;
    let page = report_page(cfg, &rows, sections);
    for (name, text) in [("results.md", &md), ("results.json", &json), ("report.html", &page)] {
        let p: PathBuf = cfg.out.join(name);
        film::write_atomic(&p, text.as_bytes()).map_err(io_err(&p))?;
    }
    Ok(md)
}

/// The (table, scene, setting) blocks of `rows`, in order: the rows of one Markdown/HTML table each.
fn groups(rows: &[Row]) -> Vec<&[Row]> {
    let key = |r: &Row| (r.table.clone(), r.scene.clone(), r.setting.clone());
    let mut out = Vec::new();
    let mut i = 0;
    while i < rows.len() {
        let j = (i..rows.len()).find(|&j| key(&rows[j]) != key(&rows[i])).unwrap_or(rows.len());
        out.push(&rows[i..j]);
        i = j;
    }
    out
}

/// The heading of a table of rows.
fn heading(r0: &Row) -> String {
    if r0.table == "direct" {
        format!("Direct lighting, hw2 {}, {} light samples", r0.scene, r0.setting)
    } else {
        format!("{} `{}`, {}", r0.scene, r0.table, r0.setting)
    }
}

/// `report.html` of the experiments: one section per scene or case, its tables under its images.
fn report_page(cfg: &Config, rows: &[Row], sections: Vec<ReportSection>) -> String {
    let mut out = Vec::new();
    for mut rs in sections {
        for g in groups(rows)
            .into_iter()
            .filter(|g| g[0].table == rs.table && (rs.scene.is_empty() || g[0].scene == rs.scene))
        {
            let table = report::html_table(report::table::EXPERIMENT_COLUMNS, g);
            rs.section
                .blocks
                .insert(rs.section.blocks.len().min(2), format!("<h3>{}</h3>\n{table}", html::escape(&heading(&g[0]))));
        }
        out.push(rs.section);
    }
    let command = format!(
        "strata experiments --out {} --corpus {} --runs {} --width {} --ref-light-samples {} --ref-spp {} --sheet-factor {}",
        cfg.out.display(),
        cfg.corpus.display(),
        cfg.runs,
        cfg.width,
        cfg.ref_light_samples,
        cfg.ref_spp,
        cfg.sheet_factor
    );
    html::page_html(&Page {
        title: "strata experiments: the seed experiments".into(),
        intro: format!(
            "<p>K = {} runs per variant, images {} pixels wide (shown box-downsampled by {}). Images are run 1 of each \
             variant; error maps compare it with the reference. Column meanings: see results.md.</p>",
            cfg.runs, cfg.width, cfg.sheet_factor
        ),
        sections: out,
        blocks: Vec::new(),
        commands: vec![command],
    })
}

/// `results.md`: the Markdown tables of `rows` (K = `runs`, images `width` wide, sheets
/// downsampled by `sheet_factor`), one per (table, scene, setting group), with ratios to the first
/// row of each ([`report::table::EXPERIMENT_COLUMNS`]).
pub fn markdown(rows: &[Row], runs: usize, width: u32, sheet_factor: u32) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Seed experiments (generated)\n\nRegenerate with `strata experiments` (see docs/experiments/README.md). K = {} runs per \
         variant, images {} pixels wide. `var` is the across-run variance of a pixel value (mean over pixels and channels) in \
         linear radiance, `var8` the same on the 8-bit gamma-encoded values 0..255; `MSE` against the reference (linear), `MSE8` the same in 8-bit units; `bias` \
         the mean signed error with its standard error `se` (runs' spread plus the reference's own noise) and `z = bias/se`; \
         `rms bias` the root mean squared per-pixel bias with the noise removed; `b-ratio = mean (m-r)^2 / mean (s^2/K + \
         var_ref)`, about 1 when unbiased; `eff = 1/(MSE x s)`; ratios are to the first row of each block. `s` is the CPU time of the \
         worker threads per run (summed over them, so not inflated by other jobs' load as wall clock is); `sampler ns/sample` \
         and `% in sampler` are the phase profiler's sample-generation time (phases named `sampler...`, see `strata profile`) \
         per camera sample and as a share of the profiled render time.\n",
        runs, width
    );
    let _ = writeln!(
        md,
        "Images, error maps (relative squared error, signed error, FLIP) and these tables side by side: \
         [report.html](report.html) (one self-contained page; images box-downsampled by {sheet_factor}).\n"
    );
    for g in groups(rows) {
        let _ = writeln!(md, "## {}\n", heading(&g[0]));
        md += &markdown_table(report::table::EXPERIMENT_COLUMNS, g, Style::Plain);
        md.push('\n');
    }
    md
}

/// `Path` of the corpus beside the crate or in `$STRATA_CSE168`.
pub fn default_corpus() -> PathBuf {
    std::env::var_os("STRATA_CSE168")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/cse168"))
}

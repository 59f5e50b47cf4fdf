//! `strata experiments`: the two seed experiments of the course report, regenerated into one folder
//! (Markdown tables, JSON, PNG contact sheets, log-log SVG plots).
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
//! Every number except seconds (and the equal-time spp derived from them) is a pure function of the
//! configuration: seeds are fixed and renders are bit-identical whatever the thread count.

use crate::app::{self, RenderOptions};
use crate::film::{self, Film};
use crate::render;
use crate::report::contact;
use crate::report::{self, Series};
use crate::sampler::SamplerKind;
use crate::scene::desc::ImportanceSampling;
use serde::Serialize;
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
    /// contact-sheet tiles are the images box-downsampled by this factor (keeps the PNGs small)
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

/// Error statistics of K runs of one variant against a reference with known per-pixel variance.
#[derive(Clone, Debug, Serialize)]
pub struct Stats {
    /// K
    pub runs: usize,
    /// mean seconds of one run
    pub seconds: f64,
    /// spp of one run
    pub spp: u32,
    /// mean over pixels and channels of the across-run variance (linear radiance)
    pub variance: f64,
    /// the same on the 8-bit gamma-encoded values 0..255 (what a PNG shows)
    pub variance_8bit: f64,
    /// mean over runs of the MSE against the reference (linear)
    pub mse: f64,
    /// the same in 8-bit units
    pub mse_8bit: f64,
    /// mean signed error of the mean image (linear)
    pub bias: f64,
    /// standard error of `bias`: the spread of the runs' mean errors and the reference's own noise
    pub bias_se: f64,
    /// `bias / bias_se`
    pub z: f64,
    /// root of the mean squared per-pixel bias, noise removed (`sqrt(max(0, mean (m-r)^2 - var/K - var_ref))`), linear
    pub rms_bias: f64,
    /// `mean (m - r)^2 / mean (s^2/K + var_ref)`: about 1 for an unbiased technique
    pub bias_ratio: f64,
    /// 1 / (MSE x seconds)
    pub efficiency: f64,
}

/// Per-pixel-channel statistics of `runs` against `reference` whose per-value variance is `ref_var`.
pub fn stats(
    runs: &[Vec<[f32; 3]>],
    reference: &[[f32; 3]],
    ref_var: &[[f32; 3]],
    gamma: f32,
    seconds: f64,
    spp: u32,
) -> Stats {
    let k = runs.len() as f64;
    let m = 3.0 * reference.len() as f64;
    let q = |v: f32| f64::from(film::to_u8(v, gamma));
    let (mut var, mut var8, mut mse, mut mse8, mut err, mut sq, mut den, mut refv) =
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut run_err = vec![0.0f64; runs.len()];
    for (i, px) in reference.iter().enumerate() {
        for c in 0..3 {
            let r = f64::from(px[c]);
            let r8 = q(px[c]);
            let vals = runs.iter().map(|run| f64::from(run[i][c]));
            let mean = vals.clone().sum::<f64>() / k;
            let mean8 = runs.iter().map(|run| q(run[i][c])).sum::<f64>() / k;
            let s2 = vals.clone().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
            var += s2;
            var8 += runs.iter().map(|run| (q(run[i][c]) - mean8).powi(2)).sum::<f64>() / (k - 1.0);
            mse += vals.clone().map(|v| (v - r).powi(2)).sum::<f64>() / k;
            mse8 += runs.iter().map(|run| (q(run[i][c]) - r8).powi(2)).sum::<f64>() / k;
            for (e, run) in run_err.iter_mut().zip(runs) {
                *e += f64::from(run[i][c]) - r;
            }
            err += mean - r;
            sq += (mean - r).powi(2);
            let rv = f64::from(ref_var[i][c]);
            den += s2 / k + rv;
            refv += rv;
        }
    }
    let bias = err / m;
    let run_err: Vec<f64> = run_err.iter().map(|e| e / m).collect();
    let spread = run_err.iter().map(|e| (e - bias).powi(2)).sum::<f64>() / (k - 1.0);
    // Pixels' reference errors are independent: the variance of their mean is sum var / M^2.
    let bias_se = (spread / k + refv / (m * m)).sqrt();
    let (mse, var) = (mse / m, var / m);
    Stats {
        runs: runs.len(),
        seconds,
        spp,
        variance: var,
        variance_8bit: var8 / m,
        mse,
        mse_8bit: mse8 / m,
        bias,
        bias_se,
        z: if bias_se > 0.0 {
            bias / bias_se
        } else if bias == 0.0 {
            0.0
        } else {
            f64::INFINITY.copysign(bias)
        },
        rms_bias: ((sq - den) / m).max(0.0).sqrt(),
        bias_ratio: if den > 0.0 { sq / den } else { f64::INFINITY },
        efficiency: report::efficiency(mse, seconds).unwrap_or(f64::NAN),
    }
}

/// Linear RGB images, one per run.
pub type Images = Vec<Vec<[f32; 3]>>;

/// K renders of `opts` (seeds derived from 1..=K as `strata compare` does) at `spp`: the mean images and the mean seconds.
pub fn runs(opts: &RenderOptions, spp: u32, k: usize) -> Result<(Images, f64), String> {
    let (scene, integ) = app::prepare(opts)?;
    let pool = render::thread_pool(opts.threads).map_err(|e| e.to_string())?;
    let integ = integ.resampled(Some(spp));
    let (mut images, mut secs) = (Vec::with_capacity(k), 0.0);
    for run in 0..k {
        let mut it = integ.clone();
        it.seed = opts.seed.wrapping_add(1 + run as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        let mut f = Film::new(scene.desc.width, scene.desc.height);
        secs += render::render(&scene, &it, &mut f, 0..spp, &pool).seconds;
        images.push(f.mean());
    }
    Ok((images, secs / k as f64))
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
    /// seconds spent
    pub seconds: f64,
}

fn film_of(opts: &RenderOptions, seed: u64) -> Result<(Film, f32, f64), String> {
    let o = RenderOptions { seed, ..opts.clone() };
    let out = app::render_to_film(&o)?;
    if out.stats.counters.nonfinite != 0 {
        return Err(format!(
            "{}: {} non-finite samples",
            out.scene.desc.source.display(),
            out.stats.counters.nonfinite
        ));
    }
    Ok((out.film, out.scene.desc.gamma, out.stats.seconds))
}

/// Direct-lighting reference: two halves with independent seeds, averaged; the per-pixel variance
/// of the average is `(a - b)^2 / 4` (spp 1, so the film has no variance layer of its own).
pub fn reference_two_halves(opts: &RenderOptions) -> Result<Reference, String> {
    let (a, gamma, ta) = film_of(opts, 0x5eed_0001)?;
    let (b, _, tb) = film_of(opts, 0x5eed_0002)?;
    let (ma, mb) = (a.mean(), b.mean());
    let rgb = ma.iter().zip(&mb).map(|(x, y)| [0, 1, 2].map(|c| 0.5 * (x[c] + y[c]))).collect();
    let var = ma.iter().zip(&mb).map(|(x, y)| [0, 1, 2].map(|c| 0.25 * (x[c] - y[c]).powi(2))).collect();
    Ok(Reference { rgb, var, gamma, size: (a.width, a.height), seconds: ta + tb })
}

/// Path-tracing reference: one high-spp render and its variance-of-the-mean layer.
pub fn reference_spp(opts: &RenderOptions) -> Result<Reference, String> {
    let (f, gamma, t) = film_of(opts, 0x5eed_0003)?;
    Ok(Reference { rgb: f.mean(), var: f.variance_of_mean(), gamma, size: (f.width, f.height), seconds: t })
}

/// One row of a results table.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// experiment (table) name
    pub table: String,
    /// scene name
    pub scene: String,
    /// technique label
    pub variant: String,
    /// "equal spp", "equal time" or a light-sample count
    pub setting: String,
    /// the statistics
    pub stats: Stats,
}

fn g3(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x.is_finite() && (1e-2..1e4).contains(&x.abs()) {
        format!("{x:.3}")
    } else {
        format!("{x:.2e}")
    }
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

/// The direct-lighting experiment: returns its rows and writes `direct-*.png` and `direct.svg`.
pub fn direct(cfg: &Config) -> Result<Vec<Row>, String> {
    let kinds = [
        ("random", SamplerKind::Independent),
        ("stratified", SamplerKind::Stratified),
        ("grid-center", SamplerKind::GridCenter),
        ("halton", SamplerKind::Halton),
    ];
    let mut rows = Vec::new();
    let mut series: Vec<Series> = Vec::new();
    for (name, rel, aspect) in [
        ("sphere", "hw2/sphere.test", 4.0 / 3.0),
        ("cornell", "hw2/cornell.test", 1.0),
        ("dragon", "hw2/dragon.test", 4.0 / 3.0),
    ] {
        let base = RenderOptions {
            spp: Some(1),
            pixel_sampler: Some(SamplerKind::GridCenter),
            ..scene_opts(cfg, rel, aspect)
        };
        log(cfg, &format!("direct {name}: reference 2 x {} stratified light samples", cfg.ref_light_samples));
        let reference = reference_two_halves(&RenderOptions {
            light_sampler: Some(SamplerKind::Stratified),
            light_samples: Some(cfg.ref_light_samples),
            ..base.clone()
        })?;
        let (w, h) = reference.size;
        let mut tiles = Vec::new();
        for n in [9u32, 25] {
            tiles.push(contact::tile_from_linear(
                w,
                h,
                &reference.rgb,
                cfg.sheet_factor,
                reference.gamma,
                vec!["reference".into(), format!("2x{} str", cfg.ref_light_samples)],
            ));
            for (label, kind) in kinds {
                log(cfg, &format!("direct {name}: {label} x{n}, {} runs", cfg.runs));
                let o = RenderOptions { light_sampler: Some(kind), light_samples: Some(n), ..base.clone() };
                let (imgs, secs) = runs(&o, 1, cfg.runs)?;
                let st = stats(&imgs, &reference.rgb, &reference.var, reference.gamma, secs, 1);
                tiles.push(contact::tile_from_linear(
                    w,
                    h,
                    &imgs[0],
                    cfg.sheet_factor,
                    reference.gamma,
                    vec![
                        format!("{} {n}", label.replace("grid-center", "grid-ctr")),
                        format!("v8 {}", g3(st.variance_8bit)),
                        format!("rb {}", g3(st.rms_bias)),
                    ],
                ));
                let sname = format!("{name} {label}");
                let p = (f64::from(n), st.mse.sqrt());
                match series.iter_mut().find(|s| s.name == sname) {
                    Some(s) => s.points.push(p),
                    None => series.push(Series { name: sname, points: vec![p] }),
                }
                rows.push(Row {
                    table: "direct".into(),
                    scene: name.into(),
                    variant: label.into(),
                    setting: format!("{n}"),
                    stats: st,
                });
            }
        }
        let sheet =
            contact::layout(&tiles, 5, Some(&format!("hw2 {name}: direct lighting, pixel centre, K={}", cfg.runs)));
        let p = cfg.out.join(format!("direct-{name}.png"));
        contact::write_sheet(&p, &sheet).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    let svg = report::loglog_svg(
        &series,
        "direct lighting: RMSE against light samples",
        "light samples",
        "RMSE",
        report::plot::RMSE_SLOPE,
    );
    let p = cfg.out.join("direct.svg");
    film::write_atomic(&p, svg.as_bytes()).map_err(|e| format!("{}: {e}", p.display()))?;
    Ok(rows)
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

/// The path-tracing experiment: returns its rows and writes `path-*.png` and `path-*.svg`.
pub fn path(cfg: &Config) -> Result<Vec<Row>, String> {
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
                ("random", px(&nee, SamplerKind::Independent)),
                ("stratified", px(&nee, SamplerKind::Stratified)),
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
                ("random", px(&nee, SamplerKind::Independent)),
                ("stratified", px(&nee, SamplerKind::Stratified)),
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
    let mut rows = Vec::new();
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
        let (w, h) = reference.size;
        let mut tiles = vec![contact::tile_from_linear(
            w,
            h,
            &reference.rgb,
            cfg.sheet_factor,
            reference.gamma,
            vec!["reference".into(), format!("{} spp", cfg.ref_spp)],
        )];
        let mut series = Vec::new();
        let mut main: Vec<Stats> = Vec::new();
        for (label, o) in &case.variants {
            let spp = case.spp;
            let mut ladder: Vec<u32> = case.ladder.iter().copied().chain(std::iter::once(spp)).collect();
            ladder.sort_unstable();
            ladder.dedup();
            let mut points = Vec::new();
            for s in ladder {
                log(cfg, &format!("path {}: {label} {s} spp, {} runs", case.key, cfg.runs));
                let (imgs, secs) = runs(o, s, cfg.runs)?;
                let st = stats(&imgs, &reference.rgb, &reference.var, reference.gamma, secs, s);
                points.push((secs, st.mse.sqrt()));
                if s == spp {
                    tiles.push(contact::tile_from_linear(
                        w,
                        h,
                        &imgs[0],
                        cfg.sheet_factor,
                        reference.gamma,
                        vec![format!("{label} {s}"), format!("var {}", g3(st.variance)), format!("z {:.2}", st.z)],
                    ));
                    main.push(st);
                }
            }
            series.push(Series { name: (*label).into(), points });
        }
        for ((label, _), st) in case.variants.iter().zip(&main) {
            rows.push(Row {
                table: case.key.into(),
                scene: case.scene.into(),
                variant: (*label).into(),
                setting: "equal spp".into(),
                stats: st.clone(),
            });
        }
        // Equal time: the faster technique gets the spp that costs what the slower one spent.
        let (ta, tb) = (main[0].seconds / f64::from(main[0].spp), main[1].seconds / f64::from(main[1].spp));
        let (fast, slow) = if ta <= tb { (0, 1) } else { (1, 0) };
        let budget = main[slow].seconds;
        let per_spp = main[fast].seconds / f64::from(main[fast].spp);
        let eq_spp = ((budget / per_spp).round() as u32).max(1);
        let (label, o) = &case.variants[fast];
        log(cfg, &format!("path {}: equal time, {label} at {eq_spp} spp", case.key));
        let (imgs, secs) =
            if eq_spp == main[fast].spp { (Vec::new(), main[fast].seconds) } else { runs(o, eq_spp, cfg.runs)? };
        let st = if imgs.is_empty() {
            main[fast].clone()
        } else {
            stats(&imgs, &reference.rgb, &reference.var, reference.gamma, secs, eq_spp)
        };
        if !imgs.is_empty() {
            tiles.push(contact::tile_from_linear(
                w,
                h,
                &imgs[0],
                cfg.sheet_factor,
                reference.gamma,
                vec![format!("{label} {eq_spp}"), "equal time".into(), format!("var {}", g3(st.variance))],
            ));
        }
        let (sl, _) = &case.variants[slow];
        rows.push(Row {
            table: case.key.into(),
            scene: case.scene.into(),
            variant: (*sl).into(),
            setting: "equal time".into(),
            stats: main[slow].clone(),
        });
        rows.push(Row {
            table: case.key.into(),
            scene: case.scene.into(),
            variant: (*label).into(),
            setting: "equal time".into(),
            stats: st,
        });
        let sheet =
            contact::layout(&tiles, tiles.len(), Some(&format!("{}: {}, K={}", case.scene, case.title, cfg.runs)));
        let p = cfg.out.join(format!("path-{}.png", case.key));
        contact::write_sheet(&p, &sheet).map_err(|e| format!("{}: {e}", p.display()))?;
        let svg = report::loglog_svg(
            &series,
            &format!("{}: {}", case.scene, case.title),
            "seconds",
            "RMSE",
            report::plot::RMSE_SLOPE,
        );
        let p = cfg.out.join(format!("path-{}.svg", case.key));
        film::write_atomic(&p, svg.as_bytes()).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    Ok(rows)
}

/// Markdown tables of `rows`, one per (table, scene, setting group), with ratios to the first row.
pub fn markdown(rows: &[Row], cfg: &Config) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Seed experiments (generated)\n\nRegenerate with `strata experiments` (see docs/experiments/README.md). K = {} runs per \
         variant, images {} pixels wide. `var` is the across-run variance of a pixel value (mean over pixels and channels) in \
         linear radiance, `var8` the same on the 8-bit gamma-encoded values 0..255; `MSE` against the reference (linear), `MSE8` the same in 8-bit units; `bias` \
         the mean signed error with its standard error `se` (runs' spread plus the reference's own noise) and `z = bias/se`; \
         `rms bias` the root mean squared per-pixel bias with the noise removed; `b-ratio = mean (m-r)^2 / mean (s^2/K + \
         var_ref)`, about 1 when unbiased; `eff = 1/(MSE x s)`; ratios are to the first row of each block. Seconds are wall \
         clock on a shared machine.\n",
        cfg.runs, cfg.width
    );
    let (mut i, mut shown) = (0, Vec::<String>::new());
    while i < rows.len() {
        let r0 = &rows[i];
        let group = |r: &Row| (r.table.clone(), r.scene.clone(), r.setting.clone());
        let g0 = group(r0);
        let mut j = i;
        while j < rows.len() && group(&rows[j]) == g0 {
            j += 1;
        }
        let (head, sheet) = if r0.table == "direct" {
            (
                format!("## Direct lighting, hw2 {}, {} light samples", r0.scene, r0.setting),
                format!("direct-{}.png", r0.scene),
            )
        } else {
            (format!("## {} `{}`, {}", r0.scene, r0.table, r0.setting), format!("path-{}.png", r0.table))
        };
        let _ = writeln!(md, "{head}\n");
        if !shown.contains(&sheet) {
            let caption = if r0.table == "direct" {
                "Tiles: the reference, then run 1 of random, stratified, grid-center, halton; top row 9, bottom row 25 light \
                 samples (`v8` = var8, `rb` = rms bias)."
            } else {
                "Tiles: the reference, then run 1 of each technique at equal spp, then the faster one at equal time."
            };
            let _ = writeln!(
                md,
                "![{sheet}]({sheet})\n\n{caption} Images box-downsampled by {} for the sheet.\n",
                cfg.sheet_factor
            );
            shown.push(sheet);
        }
        let _ = writeln!(md, "| variant | spp | s | var | var8 | var ratio | MSE | MSE8 | bias | se | z | rms bias | b-ratio | eff | eff ratio |");
        let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        let first = &rows[i].stats;
        for r in &rows[i..j] {
            let s = &r.stats;
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} | {} | {} | {} | {} |",
                r.variant,
                s.spp,
                g3(s.seconds),
                g3(s.variance),
                g3(s.variance_8bit),
                g3(s.variance / first.variance),
                g3(s.mse),
                g3(s.mse_8bit),
                g3(s.bias),
                g3(s.bias_se),
                s.z,
                g3(s.rms_bias),
                g3(s.bias_ratio),
                g3(s.efficiency),
                g3(s.efficiency / first.efficiency),
            );
        }
        let _ = writeln!(md);
        i = j;
    }
    md
}

/// Runs both experiments and writes `results.md`, `results.json`, the contact sheets and plots into
/// `cfg.out`.
pub fn run(cfg: &Config) -> Result<String, String> {
    if cfg.runs < 2 {
        return Err("--runs must be at least 2".into());
    }
    if !cfg.corpus.join("hw2").is_dir() {
        return Err(format!("{}: CSE168 corpus not found (needs hw2, hw3, hw4; use --corpus)", cfg.corpus.display()));
    }
    std::fs::create_dir_all(&cfg.out).map_err(|e| format!("{}: {e}", cfg.out.display()))?;
    let mut rows = direct(cfg)?;
    rows.extend(path(cfg)?);
    let md = markdown(&rows, cfg);
    let json = serde_json::to_string_pretty(&rows).map_err(|e| e.to_string())?;
    for (name, text) in [("results.md", &md), ("results.json", &json)] {
        let p: PathBuf = cfg.out.join(name);
        film::write_atomic(&p, text.as_bytes()).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    Ok(md)
}

/// `Path` of the corpus beside the crate or in `$STRATA_CSE168`.
pub fn default_corpus() -> PathBuf {
    std::env::var_os("STRATA_CSE168")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/cse168"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_of_synthetic_runs_have_the_known_answers() {
        let r = vec![[0.25f32, 0.5, 0.75]; 6];
        let zero = vec![[0.0f32; 3]; 6];
        // Two runs at r - d and r + d: no bias, per-value variance 2 d^2, MSE d^2.
        let d = 0.125f32;
        let runs: Images =
            vec![r.iter().map(|p| p.map(|v| v - d)).collect(), r.iter().map(|p| p.map(|v| v + d)).collect()];
        let s = stats(&runs, &r, &zero, 1.0, 2.0, 4);
        assert_eq!((s.runs, s.spp), (2, 4));
        assert!((s.variance - 2.0 * f64::from(d * d)).abs() < 1e-12, "{}", s.variance);
        assert!((s.mse - f64::from(d * d)).abs() < 1e-12);
        assert_eq!((s.bias, s.z, s.rms_bias), (0.0, 0.0, 0.0));
        assert!((s.efficiency - 1.0 / (2.0 * f64::from(d * d))).abs() < 1e-9);
        // 8-bit (gamma 1, x 255, rounded): 0.125/0.375 -> 32/96, 0.375/0.625 -> 96/159,
        // 0.625/0.875 -> 159/223; variance (a - b)^2 / 2 per channel.
        let want = (64.0f64.powi(2) + 63.0f64.powi(2) + 64.0f64.powi(2)) / 2.0 / 3.0;
        assert!((s.variance_8bit - want).abs() < 1e-9, "{} vs {want}", s.variance_8bit);
        // Identical runs offset by b: zero variance, all error is bias, z infinite.
        let b = 0.0625f32;
        let off: Vec<[f32; 3]> = r.iter().map(|p| p.map(|v| v + b)).collect();
        let s = stats(&[off.clone(), off.clone(), off], &r, &zero, 1.0, 1.0, 1);
        assert_eq!(s.variance, 0.0);
        assert!((s.bias - f64::from(b)).abs() < 1e-12 && (s.rms_bias - f64::from(b)).abs() < 1e-9);
        assert_eq!(s.z, f64::INFINITY);
        // The reference's own variance enters the standard error: M = 18 values of variance v
        // give a mean with variance v / 18.
        let v = 0.02f32;
        let noisy = vec![[v; 3]; 6];
        let runs: Images = vec![r.clone(), r.clone()];
        let s = stats(&runs, &r, &noisy, 1.0, 1.0, 1);
        assert!((s.bias_se - (f64::from(v) / 18.0).sqrt()).abs() < 1e-9, "{}", s.bias_se);
        assert!(s.bias_ratio < 1e-12, "no error at all: ratio 0");
    }
}

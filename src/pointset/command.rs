//! `strata pointset PATH|NAME`: the quality of a point-set file or a registry layout, per set
//! (L2 star discrepancy, minimum toroidal distance), the radial power spectrum (CSV and SVG) and
//! the integration error on the disk and the Gaussian for N = 4..4096 with the fitted slopes (CSV,
//! SVG); `--export FILE` writes the sets (a layout's, or the file's in another format).

use super::analysis::{self, Convergence};
use super::spec::Options;
use super::{formats, PointSetError, PointSets};
use crate::sampler::{PointSet, SamplerKind};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What `strata pointset` is asked.
#[derive(Clone, Debug)]
pub struct Args {
    /// a point-set file or a registry sampler name
    pub target: String,
    /// folder for spectrum.csv/svg, integration.csv/svg, pointset.json (None: write nothing)
    pub out: Option<PathBuf>,
    /// write the sets here (format by extension)
    pub export: Option<PathBuf>,
    /// registry layouts: sets to make (set j is pixel j's)
    pub sets: u32,
    /// registry layouts: points per set
    pub points: u32,
    /// registry layouts: base seed; also the randomization of the integration trials
    pub seed: u64,
    /// registry layouts: sampler dimension of the sets
    pub dim: u32,
    /// registry layouts: image width the pixel ids refer to (screen-space layouts)
    pub width: u32,
    /// randomizations per N in the integration test
    pub trials: u32,
    /// largest radial frequency of the spectrum
    pub max_freq: usize,
    /// how a file's sets are randomized in the integration test (as in a render)
    pub options: Options,
}

impl Default for Args {
    fn default() -> Self {
        Self {
            target: String::new(),
            out: None,
            export: None,
            sets: 4,
            points: 1024,
            seed: 0,
            dim: 0,
            width: 0,
            trials: 256,
            max_freq: 64,
            options: Options::default(),
        }
    }
}

/// One set's measures.
#[derive(Clone, Debug, Serialize)]
pub struct SetRow {
    /// set index
    pub set: usize,
    /// points
    pub points: usize,
    /// L2 star discrepancy
    pub l2_star_discrepancy: f64,
    /// minimum toroidal distance
    pub min_distance: f64,
    /// minimum distance over the hexagonal packing's
    pub min_distance_relative: f64,
}

/// Everything `strata pointset` measured.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// the file or layout
    pub name: String,
    /// the sampler kind the integration test drew from
    pub sampler: String,
    /// per-set measures (at most [`MAX_SETS_MEASURED`] sets)
    pub sets: Vec<SetRow>,
    /// radially averaged power, ring r = frequencies [r, r + 1)
    pub spectrum: Vec<f64>,
    /// error curves and slopes
    pub convergence: Vec<Convergence>,
    /// a file's progressiveness (its prefixes against fresh random sets of their size); None for
    /// a registry layout, whose sets are made at each size
    pub progressive: Option<analysis::Progressiveness>,
}

/// Sets measured one by one (the O(N^2) measures); the spectrum averages the same sets.
pub const MAX_SETS_MEASURED: usize = 16;

/// The sets of registry layout `kind`: set j holds points 0..n of pixel j (sample 0, `dim`).
pub fn layout_sets(kind: SamplerKind, args: &Args) -> Result<PointSets, PointSetError> {
    let set = PointSet::for_image(kind, args.points, args.width);
    let data = (0..args.sets)
        .flat_map(|j| (0..args.points).map(move |k| (j, k)))
        .flat_map(|(j, k)| set.point(j, 0, args.dim, k, args.seed).map(f64::from))
        .collect();
    PointSets::new(kind.name(), args.sets as usize, args.points as usize, 2, data)
}

/// Runs `strata pointset`: measures, writes the outputs asked for, returns the report and its
/// text table.
pub fn run(args: &Args) -> Result<(Report, String), PointSetError> {
    let (ps, kind, ns, progressive) = match SamplerKind::parse(&args.target) {
        Some(kind) => {
            let ps = layout_sets(kind, args)?;
            (ps, kind, (2..=12).map(|m| 1u32 << m).collect::<Vec<u32>>(), None)
        }
        None => {
            let path = PathBuf::from(args.target.strip_prefix("file:").unwrap_or(&args.target));
            let ps = formats::read(&path)?;
            let kind = super::sampler_from_sets(&ps, &format!("file:{}", path.display()), args.options)?;
            let prog = analysis::progressiveness(&ps.sets_2d(MAX_SETS_MEASURED));
            // Prefixes of a progressive file's sets: powers of two from 4 up to its size, and its
            // size; a set that is not progressive only at its size (a render uses it whole).
            let p = ps.points as u32;
            let mut ns: Vec<u32> =
                if prog.progressive { (2..=12).map(|m| 1u32 << m).filter(|&n| n < p).collect() } else { Vec::new() };
            ns.push(p);
            (ps, kind, ns, Some(prog))
        }
    };
    if let Some(e) = &args.export {
        formats::write(e, &ps)?;
    }
    let measured = ps.sets_2d(MAX_SETS_MEASURED);
    let sets = measured
        .iter()
        .enumerate()
        .map(|(set, pts)| {
            let d = analysis::min_distance(pts);
            SetRow {
                set,
                points: pts.len(),
                l2_star_discrepancy: analysis::l2_star_discrepancy(pts),
                min_distance: d,
                min_distance_relative: d / analysis::max_min_distance(pts.len()),
            }
        })
        .collect();
    let report = Report {
        name: ps.source.clone(),
        sampler: kind.name().to_string(),
        sets,
        spectrum: analysis::radial_spectrum(&measured, args.max_freq),
        convergence: analysis::convergence(kind, &ns, args.trials, args.seed),
        progressive,
    };
    if let Some(dir) = &args.out {
        write_outputs(dir, &report)?;
    }
    let table = table(&report);
    Ok((report, table))
}

/// The report as text: one line per set, then the slopes.
pub fn table(r: &Report) -> String {
    let mut s = format!("{} (integration drawn as sampler {})\n", r.name, r.sampler);
    s += "  set   points  L2 star discrepancy  min distance  (/ hex packing)\n";
    for row in &r.sets {
        s += &format!(
            "  {:>3} {:>8} {:>20.6e} {:>13.6} {:>15.3}\n",
            row.set, row.points, row.l2_star_discrepancy, row.min_distance, row.min_distance_relative
        );
    }
    if let Some(p) = &r.progressive {
        let ratios: Vec<String> = p.prefixes.iter().map(|(n, q)| format!("{n}: {q:.2}")).collect();
        s += &format!(
            "  progressive: {} (prefix discrepancy / fresh random sets', at most {}: {})\n",
            if p.progressive { "yes" } else { "no: renders use whole sets, no slope is fitted over prefixes" },
            analysis::PROGRESSIVE_MAX_RATIO,
            if ratios.is_empty() { "no prefix of 8+ points".to_string() } else { ratios.join(", ") }
        );
    }
    for c in &r.convergence {
        let first = c.points.first().map_or(0.0, |p| p.0);
        let last = c.points.last().map_or(0.0, |p| p.0);
        match (c.slope, c.points.first()) {
            (Some(k), _) => {
                s += &format!("  integration error, {:<8} N = {first}..{last}: slope {k:+.3}\n", c.integrand)
            }
            (None, Some((n, e))) => {
                s += &format!("  integration error, {:<8} N = {n}: RMSE {e:.4e} (whole sets only)\n", c.integrand)
            }
            (None, None) => {}
        }
    }
    s.pop();
    s
}

fn io(path: &Path) -> impl Fn(std::io::Error) -> PointSetError + '_ {
    move |source| PointSetError::Io { path: path.to_path_buf(), source }
}

/// The spectrum plot's lowest power (white noise is 1): below it the estimate is rounding, not
/// signal (a lattice's zeros come out near 1e-31), and the axis would spend 30 decades on it.
pub const SPECTRUM_FLOOR: f64 = 1e-4;

/// spectrum.csv/svg, integration.csv/svg and pointset.json in `dir`.
pub fn write_outputs(dir: &Path, r: &Report) -> Result<(), PointSetError> {
    use crate::report::{loglog_svg, Series};
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    use crate::report::table::exact;
    // Numbers in the shortest form that reads back to the same f64 (`4.5e-31`, not 0.000...045).
    let mut spectrum = String::from("frequency,power\n");
    for (f, p) in r.spectrum.iter().enumerate().skip(1) {
        spectrum += &format!("{f},{}\n", exact(*p));
    }
    let mut integration = String::from("integrand,n,rmse\n");
    for c in &r.convergence {
        for (n, e) in &c.points {
            integration += &format!("{},{n},{}\n", c.integrand, exact(*e));
        }
    }
    // The plot's power axis stops at a noise floor (a lattice's exact zeros come out as 1e-31 of
    // rounding); the slope-0 guide is white noise, power 1.
    let floored = r.spectrum.iter().skip(1).any(|&p| p < SPECTRUM_FLOOR);
    let spec_series = [Series {
        name: if floored { format!("{} (power < {SPECTRUM_FLOOR:e} drawn at it)", r.name) } else { r.name.clone() },
        points: r.spectrum.iter().enumerate().skip(1).map(|(f, &p)| (f as f64, p.max(SPECTRUM_FLOOR))).collect(),
    }];
    let spec_svg = crate::report::loglog_svg_guided(
        &spec_series,
        &[],
        &format!("radial power spectrum: {}", r.name),
        "frequency",
        "power (white noise = 1: the guide)",
        0.0,
        Some((1.0, 1.0)),
    );
    let int_series: Vec<Series> = r
        .convergence
        .iter()
        .map(|c| Series {
            name: match c.slope {
                Some(k) => format!("{} (slope {k:+.2})", c.integrand),
                None => format!("{} (whole sets)", c.integrand),
            },
            points: c.points.clone(),
        })
        .collect();
    let int_svg =
        loglog_svg(&int_series, &format!("integration error: {}", r.name), "points N", "RMSE", analysis::RANDOM_SLOPE);
    let json = serde_json::to_string_pretty(r).map_err(|e| PointSetError::Spec(e.to_string()))?;
    for (name, text) in [
        ("spectrum.csv", spectrum),
        ("spectrum.svg", spec_svg),
        ("integration.csv", integration),
        ("integration.svg", int_svg),
        ("pointset.json", json),
    ] {
        let p = dir.join(name);
        crate::film::write_atomic(&p, text.as_bytes()).map_err(io(&p))?;
    }
    Ok(())
}

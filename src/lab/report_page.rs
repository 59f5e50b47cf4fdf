//! The outputs of `strata compare` ([`write_outputs`]: rows and runs as CSV and JSON, the Markdown
//! table, the plots, `report.html`) and the pieces `strata experiments` shares: the convergence
//! plots with 95% error bars and spp labels, the slopes table, and `report.html` through
//! [`crate::report::html`].

use super::compare::{Comparison, Convergence, RunRow};
use super::{io_err, report_figures, LabError};
use crate::film;
use crate::report::html::{self, Page, Section, Shot};
use crate::report::{self, student_t_quantile, Annotation, Series};
use crate::session::profile::{profile_svg, Profile};
use std::fmt::Write as _;
use std::path::Path;

/// Mean of the runs' RMSE at one (variant, step) and its two-sided 95% Student-t interval.
pub fn rmse_interval(runs: &[&RunRow]) -> (f64, f64, f64) {
    let k = runs.len() as f64;
    let rmse: Vec<f64> = runs.iter().map(|r| r.mse.sqrt()).collect();
    let mean = rmse.iter().sum::<f64>() / k;
    if runs.len() < 2 {
        return (mean, mean, mean);
    }
    let sd = (rmse.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0)).sqrt();
    let half = student_t_quantile(0.975, k - 1.0) * sd / k.sqrt();
    (mean, mean - half, mean + half)
}

/// Series of mean RMSE per (variant, step) against `x` (seconds or spp), with error bars and spp
/// labels.
fn series_of(c: &Comparison, x_of: fn(&[&RunRow]) -> f64) -> (Vec<Series>, Vec<Annotation>) {
    let (mut series, mut ann): (Vec<Series>, Vec<Annotation>) = (Vec::new(), Vec::new());
    // Runs are in the rows' order, K per row (variant by variant, step by step).
    let k = if c.rows.is_empty() { 0 } else { c.runs.len() / c.rows.len() };
    for (row, chunk) in c.rows.iter().zip(c.runs.chunks(k.max(1))) {
        let runs: Vec<&RunRow> = chunk.iter().filter(|r| r.variant == row.variant).collect();
        if runs.is_empty() {
            continue;
        }
        let (mean, lo, hi) = rmse_interval(&runs);
        let step = runs[0].step;
        let label = if step > 0 { format!("{step} spp") } else { format!("{:.0} spp", row.spp) };
        let i = match series.iter().position(|s| s.name == row.variant) {
            Some(i) => i,
            None => {
                series.push(Series { name: row.variant.clone(), points: Vec::new() });
                ann.push(Annotation::default());
                series.len() - 1
            }
        };
        series[i].points.push((x_of(&runs), mean));
        ann[i].y_range.push((lo, hi));
        ann[i].labels.push(label);
    }
    (series, ann)
}

/// `error.svg` (mean RMSE of a run against its CPU seconds) and, for a ladder of two or more
/// steps, `error-spp.svg` (against spp), both with 95% error bars over the runs and a slope -1/2
/// guide.
pub fn compare_plots(c: &Comparison, title: &str) -> (String, Option<String>) {
    let secs = |runs: &[&RunRow]| runs.iter().map(|r| r.seconds).sum::<f64>() / runs.len() as f64;
    let (s, a) = series_of(c, secs);
    let by_time = report::loglog_svg_annotated(
        &s,
        &a,
        title,
        "CPU seconds per run (worker threads)",
        "RMSE (mean over runs, 95% CI)",
        report::plot::RMSE_SLOPE,
    );
    let steps: std::collections::BTreeSet<u32> = c.runs.iter().map(|r| r.step).filter(|&s| s > 0).collect();
    let by_spp = (steps.len() >= 2).then(|| {
        let (s, a) = series_of(c, |runs| f64::from(runs[0].spp));
        report::loglog_svg_annotated(
            &s,
            &a,
            title,
            "samples per pixel",
            "RMSE (mean over runs, 95% CI)",
            report::plot::RMSE_SLOPE,
        )
    });
    (by_time, by_spp)
}

/// A slope with its interval, `n/a` when there is none.
fn slope_text(s: Option<report::Slope>) -> String {
    s.map_or("n/a".into(), |s| format!("{:.3} [{:.3}, {:.3}]", s.slope, s.lo, s.hi))
}

/// The Markdown table of fitted convergence slopes (log RMSE, the reference's noise removed, one
/// point per run) with 95% intervals.
pub fn slopes_markdown(conv: &[Convergence]) -> String {
    let mut md = String::from(
        "\nConvergence (least squares over runs of ln RMSE, the reference's variance removed; 95% interval; \
         -0.5 is the Monte Carlo rate):\n\n| variant | slope vs spp | slope vs CPU seconds |\n|:--|--:|--:|\n",
    );
    for c in conv {
        let _ = writeln!(
            md,
            "| {} | {} | {} |",
            c.variant.replace('|', "\\|"),
            slope_text(c.vs_spp),
            slope_text(c.vs_seconds)
        );
    }
    md
}

/// The slopes as an HTML table.
fn slopes_html(conv: &[Convergence]) -> String {
    let mut out = String::from(
        "<h3>Convergence slopes</h3>\n<p>Least squares over the runs of ln RMSE (the reference's variance removed) \
         against ln spp and ln CPU seconds, with 95% intervals; -0.5 is the Monte Carlo rate.</p>\n\
         <table><tr><th>variant</th><th>slope vs spp</th><th>slope vs CPU seconds</th></tr>\n",
    );
    for c in conv {
        let _ = writeln!(
            out,
            "<tr><td>{}</td><td>{}</td><td>{}</td></tr>",
            html::escape(&c.variant),
            slope_text(c.vs_spp),
            slope_text(c.vs_seconds)
        );
    }
    out + "</table>\n"
}

/// The sampler-cost bars of the variants' profiles, as an inline SVG block.
pub fn profile_block(entries: &[(&str, &Profile)], title: &str) -> String {
    format!("<h3>Where the time goes (phase profiler)</h3>\n{}\n", html::inline_svg(&profile_svg(entries, title)))
}

/// Notes as an HTML list (empty when there are none).
pub fn notes_block(notes: &[String]) -> String {
    if notes.is_empty() {
        return String::new();
    }
    let items: String = notes.iter().map(|n| format!("<li>{}</li>", html::escape(n))).collect();
    format!("<ul class=\"notes\">{items}</ul>\n")
}

/// What a reader needs to reproduce a comparison: the reference (spp, samplers, noise and how it
/// was estimated: compare's note), strata's version, commit and build, the CPU, the worker
/// threads and the exact command (or the Python call's equivalent), as (key, value) lines.
pub fn provenance(c: &Comparison, commands: &[String]) -> Vec<(String, String)> {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism().map_or(0, usize::from);
    let reference = c
        .notes
        .iter()
        .find(|n| n.starts_with("reference: "))
        .map_or("(no provenance in its metadata)", |n| &n["reference: ".len()..]);
    let mut lines = vec![
        ("reference".to_string(), reference.to_string()),
        (
            "strata".to_string(),
            format!(
                "{} (commit {}, build {})",
                env!("CARGO_PKG_VERSION"),
                crate::checkpoint::identity::COMMIT,
                crate::checkpoint::identity::BUILD
            ),
        ),
        ("CPU".to_string(), format!("{cpu} ({cores} logical cores seen)")),
        ("threads".to_string(), format!("{} worker threads per render; seconds are their CPU seconds", c.threads)),
        (
            "statistics".to_string(),
            format!(
                "K = {} runs per row; 95% intervals: MSE - ref. var. Student t, bias Student t, MSE, relMSE and the \
                 efficiency ratio percentile bootstrap over runs ({} resamples); robust statistic: trimmed MSE, the \
                 largest {:.1}% of squared errors dropped",
                c.runs.iter().map(|r| r.run).max().map_or(0, |m| m + 1),
                report::robust::RESAMPLES,
                (1.0 - report::robust::TRIM_KEEP) * 100.0
            ),
        ),
    ];
    lines.extend(commands.iter().map(|cmd| ("command".to_string(), cmd.clone())));
    lines
}

/// [`provenance`] as an HTML table.
fn provenance_html(lines: &[(String, String)]) -> String {
    let rows: String = lines
        .iter()
        .map(|(k, v)| format!("<tr><th>{}</th><td><code>{}</code></td></tr>", html::escape(k), html::escape(v)))
        .collect();
    format!("<h3>Provenance</h3>\n<table class=\"provenance\">{rows}</table>\n")
}

/// `report.html` of a comparison.
pub fn compare_html(
    c: &Comparison,
    title: &str,
    commands: &[String],
    by_time: &str,
    by_spp: &Option<String>,
) -> String {
    let reference = Shot { label: "reference".into(), rgb: c.reference.rgb.clone() };
    let first = |runs: &[Vec<[f32; 3]>]| runs.first().cloned().unwrap_or_default();
    let shots = c.images.iter().map(|(name, runs)| Shot { label: name.clone(), rgb: first(runs) }).collect();
    let runs = c
        .images
        .iter()
        .flat_map(|(name, runs)| {
            runs.iter()
                .enumerate()
                .map(move |(r, rgb)| Shot { label: format!("{name} run {}", r + 1), rgb: rgb.clone() })
        })
        .collect();
    let (w, h) = (c.reference.width, c.reference.height);
    let names: Vec<&str> = c.images.iter().map(|(n, _)| n.as_str()).collect();
    let errors: Vec<Vec<f32>> =
        c.images.iter().map(|(_, runs)| report_figures::mean_error(runs, &c.reference.rgb)).collect();
    let errors: Vec<&[f32]> = errors.iter().map(Vec::as_slice).collect();
    let run1: Vec<Vec<[f32; 3]>> = c.images.iter().map(|(_, runs)| first(runs)).collect();
    let run1: Vec<&[[f32; 3]]> = run1.iter().map(Vec::as_slice).collect();
    let k = c.runs.iter().map(|r| r.run).max().map_or(0, |m| m + 1);
    // The results in two tables (cost, then error), so that neither overflows a 1200-px page.
    let cols = report::table::compare_columns(&c.rows);
    let split = cols.iter().position(|col| col.header == "MSE").unwrap_or(cols.len());
    let (cost, error): (Vec<_>, Vec<_>) = (
        cols[..split].to_vec(),
        cols.iter()
            .enumerate()
            .filter(|&(i, col)| i == 0 || i >= split || col.header == "spp")
            .map(|(_, c)| *c)
            .collect(),
    );
    let mut blocks = vec![
        report_figures::crops_html(&c.reference.rgb, w, h, &names, &run1, &errors),
        report_figures::mean_error_html(&names, &errors, w, h, k),
        provenance_html(&provenance(c, commands)),
        notes_block(&c.notes),
        format!(
            "<h3>Results (K = {k} runs per row; efficiency against {})</h3>\n<p>Cost per run:</p>\n{}<p>Error:</p>\n{}",
            html::escape(&c.baseline),
            report::html_table(&cost, &c.rows),
            report::html_table(&error, &c.rows)
        ),
        slopes_html(&c.convergence),
        format!("<h3>Convergence</h3>\n{}", html::inline_svg(by_time)),
    ];
    if let Some(s) = by_spp {
        blocks.push(html::inline_svg(s));
    }
    let entries: Vec<(&str, &Profile)> = c.profiles.iter().map(|p| (p.variant.as_str(), &p.profile)).collect();
    blocks.push(profile_block(&entries, "phases per variant"));
    let page = Page {
        title: format!("strata compare: {title}"),
        intro:
            "<p>Images: each variant's run 1 at the last step, sRGB (clamped), against the reference; error maps of \
                that image against the reference; then every run at the last step (a flip-book of its own), crops \
                where the variants differ most and each variant's mean error over its runs.</p>"
                .into(),
        sections: vec![Section {
            title: title.into(),
            width: c.reference.width,
            height: c.reference.height,
            reference: Some(reference),
            shots,
            runs,
            blocks,
        }],
        blocks: Vec::new(),
        commands: commands.to_vec(),
    };
    html::page_html(&page)
}

/// Writes `rows.csv`, `rows.json`, `runs.csv`, `runs.json`, `table.md`, `error.svg` (RMSE against
/// seconds with 95% error bars), `error-spp.svg` (RMSE against spp, ladders) and `report.html`
/// into `dir`; `commands` are the command lines that reproduce it, said back in the report.
/// Returns the Markdown table with the notes and slopes under it.
pub fn write_outputs(c: &Comparison, dir: &Path, title: &str, commands: &[String]) -> Result<String, LabError> {
    std::fs::create_dir_all(dir).map_err(io_err(dir))?;
    let mut md = report::to_markdown(&c.rows);
    md += &slopes_markdown(&c.convergence);
    for n in &c.notes {
        md += &format!("\nNote: {n}\n");
    }
    md += "\nProvenance:\n\n";
    for (k, v) in provenance(c, commands) {
        md += &format!("- {k}: {v}\n");
    }
    let json = serde_json::to_string_pretty(&report::to_json(&c.rows))?;
    let runs_json = serde_json::to_string_pretty(&c.runs)?;
    let mut runs_csv = csv::WriterBuilder::new().terminator(csv::Terminator::Any(b'\n')).from_writer(Vec::new());
    for r in &c.runs {
        runs_csv.serialize(r).map_err(|e| LabError::Io { path: dir.join("runs.csv"), source: e.into() })?;
    }
    let runs_csv = String::from_utf8(runs_csv.into_inner().unwrap_or_default()).unwrap_or_default();
    let (svg_s, svg_spp) = compare_plots(c, title);
    let html = compare_html(c, title, commands, &svg_s, &svg_spp);
    let mut files = vec![
        ("rows.csv", report::to_csv(&c.rows)),
        ("rows.json", json),
        ("runs.csv", runs_csv),
        ("runs.json", runs_json),
        ("table.md", md.clone()),
        ("error.svg", svg_s),
    ];
    if let Some(s) = svg_spp {
        files.push(("error-spp.svg", s));
    }
    files.push(("report.html", html));
    for (name, text) in files {
        let p = dir.join(name);
        film::write_atomic(&p, text.as_bytes()).map_err(io_err(&p))?;
    }
    Ok(md)
}

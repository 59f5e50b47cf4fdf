//! The results tables of `strata compare` and `strata experiments`: one [`Row`] per variant and
//! setting (its cost and its [`RunStats`]), and one writer for Markdown (aligned or plain), CSV
//! and JSON. A table's layout is a list of [`Column`]s: to add a column, add a field to [`Row`]
//! (if the number is new) and a `Column` to the lists that should show it.

use super::metrics::{efficiency, RunStats};
use super::ReportError;
use serde::Serialize;

/// One variant under one setting: the cost of one run and the error statistics over its runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// experiment (table) name; empty in `strata compare`
    pub table: String,
    /// scene name; empty in `strata compare`
    pub scene: String,
    /// variant name (technique and settings)
    pub variant: String,
    /// "equal spp", "equal time" or a light-sample count; empty in `strata compare`
    pub setting: String,
    /// CPU seconds of the worker threads for one run, summed over the workers (the mean over
    /// runs); wall clock before the profiling columns came (a loaded machine inflated it)
    pub seconds: f64,
    /// samples per pixel of one run (the mean over runs)
    pub spp: f64,
    /// the error statistics over the runs
    pub stats: RunStats,
    /// `1 / (mse * seconds)`, infinite when that product is zero ([`efficiency`])
    pub efficiency: f64,
    /// nanoseconds of sample generation (the profile phases named `sampler...`) per camera
    /// sample; NaN when the runs were not profiled
    pub sampler_ns_per_sample: f64,
    /// fraction of the profiled render time spent in sample generation; NaN when not profiled
    pub sampler_share: f64,
    /// where pixel sample 0 went (`centre` or `jittered`); empty when not recorded
    pub first_sample: String,
    /// mean over runs of the mean FLIP error against the reference (LDR, sRGB); NaN when not computed
    pub flip: f64,
    /// efficiency over the baseline variant's at the same spp step (`strata compare --baseline`);
    /// NaN when not compared or when the two render the same image ([`Row::same_as`])
    pub eff_vs_baseline: f64,
    /// the variant that rendered bit-identical images (then the two are not ranked)
    pub same_as: Option<String>,
    /// mean over runs of the MSE over the smallest 99.9% of squared errors
    /// ([`crate::report::robust::trimmed_mse`]: one firefly does not decide a ranking); NaN when not computed
    pub mse_trimmed: f64,
    /// 95% bootstrap interval over the runs of the mean MSE; NaN when not computed
    pub mse_boot_ci: (f64, f64),
    /// 95% bootstrap interval over the runs of the mean relMSE; NaN when not computed
    pub rel_mse_boot_ci: (f64, f64),
    /// 95% bootstrap interval over both variants' runs of [`Row::eff_vs_baseline`]; NaN when not computed
    pub eff_vs_baseline_ci: (f64, f64),
}

impl Row {
    /// A row from run statistics and the time and samples per pixel of one run.
    pub fn new(variant: impl Into<String>, seconds: f64, spp: f64, stats: &RunStats) -> Result<Self, ReportError> {
        Ok(Row {
            table: String::new(),
            scene: String::new(),
            variant: variant.into(),
            setting: String::new(),
            seconds,
            spp,
            stats: *stats,
            efficiency: efficiency(stats.mse, seconds)?,
            sampler_ns_per_sample: f64::NAN,
            sampler_share: f64::NAN,
            first_sample: String::new(),
            flip: f64::NAN,
            eff_vs_baseline: f64::NAN,
            same_as: None,
            mse_trimmed: f64::NAN,
            mse_boot_ci: (f64::NAN, f64::NAN),
            rel_mse_boot_ci: (f64::NAN, f64::NAN),
            eff_vs_baseline_ci: (f64::NAN, f64::NAN),
        })
    }

    /// This row with the sampler's cost from the runs' profile: nanoseconds per camera sample and
    /// the fraction of render time in sample generation.
    pub fn with_sampler(self, ns_per_sample: f64, share: f64) -> Self {
        Row { sampler_ns_per_sample: ns_per_sample, sampler_share: share, ..self }
    }

    /// This row in table `table`, scene `scene`, under `setting` (the grouping of
    /// `strata experiments`).
    pub fn grouped(self, table: impl Into<String>, scene: impl Into<String>, setting: impl Into<String>) -> Self {
        Row { table: table.into(), scene: scene.into(), setting: setting.into(), ..self }
    }
}

/// One column of a table: its header and its cell, from the row and the first row of its block
/// (for ratios).
#[derive(Clone, Copy)]
pub struct Column {
    /// the header cell
    pub header: &'static str,
    /// the cell of `row`, given the first row of the block
    pub cell: fn(row: &Row, first: &Row) -> String,
}

/// How [`markdown_table`] lays out a table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// columns padded to one width, the first left-aligned and the others right-aligned
    Aligned,
    /// `| a | b |` cells, unpadded, `|---|` separators
    Plain,
}

/// The cells of `rows` under `columns`, ratios against the first row.
fn cells(columns: &[Column], rows: &[Row]) -> Vec<Vec<String>> {
    rows.iter().map(|r| columns.iter().map(|c| (c.cell)(r, &rows[0])).collect()).collect()
}

/// A Markdown pipe table of `rows` under `columns`: a header line, an alignment line and one line
/// per row; ratio columns are against the first row.
pub fn markdown_table(columns: &[Column], rows: &[Row], style: Style) -> String {
    let header: Vec<String> = columns.iter().map(|c| c.header.to_string()).collect();
    let cells = cells(columns, rows);
    let mut out = String::new();
    match style {
        Style::Plain => {
            let line = |row: &[String]| format!("| {} |\n", row.join(" | "));
            out += &line(&header);
            out += &format!("|{}\n", "---|".repeat(columns.len()));
            for row in &cells {
                out += &line(row);
            }
        }
        Style::Aligned => {
            let mut width: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
            for row in &cells {
                for (w, cell) in width.iter_mut().zip(row) {
                    *w = (*w).max(cell.chars().count());
                }
            }
            // The first column is left-aligned, the others right-aligned.
            let line = |row: &[String]| {
                let mut s = String::from("|");
                for (i, (cell, &w)) in row.iter().zip(&width).enumerate() {
                    s += &if i == 0 { format!(" {cell:<w$} |") } else { format!(" {cell:>w$} |") };
                }
                s + "\n"
            };
            out += &line(&header);
            out += "|";
            for (i, w) in width.iter().enumerate() {
                out += &if i == 0 { format!(":{}|", "-".repeat(w + 1)) } else { format!("{}:|", "-".repeat(w + 1)) };
            }
            out += "\n";
            for row in &cells {
                out += &line(row);
            }
        }
    }
    out
}

/// An HTML `<table>` of `rows` under `columns` (ratio columns against the first row), escaped.
pub fn html_table(columns: &[Column], rows: &[Row]) -> String {
    let esc = |s: &str| super::html::escape(&s.replace("\\|", "|"));
    let mut out = String::from("<table>\n<tr>");
    for c in columns {
        let class = if c.header == "samplers" { " class=\"text\"" } else { "" };
        out += &format!("<th{class}>{}</th>", esc(c.header));
    }
    out += "</tr>\n";
    for row in cells(columns, rows) {
        out += "<tr>";
        for (c, col) in row.iter().zip(columns) {
            // Lists of words (the samplers that ran) may wrap; numbers never do.
            let class = if col.header == "samplers" { " class=\"text\"" } else { "" };
            out += &format!("<td{class}>{}</td>", esc(c));
        }
        out += "</tr>\n";
    }
    out + "</table>\n"
}

/// CSV (RFC 4180, the `csv` crate) of `rows` under `columns`: the headers, then one line per
/// row; a cell with a comma, quote or line break is quoted.
pub fn csv_table(columns: &[Column], rows: &[Row]) -> String {
    let mut w = csv::WriterBuilder::new().terminator(csv::Terminator::Any(b'\n')).from_writer(Vec::new());
    let header: Vec<&str> = columns.iter().map(|c| c.header).collect();
    // Writing into a Vec cannot fail.
    let _ = w.write_record(&header);
    for row in cells(columns, rows) {
        let _ = w.write_record(&row);
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

/// A number in the shortest form that parses back to the same f64 (`1.5e-3`; `inf`/`NaN`).
pub fn exact(x: f64) -> String {
    format!("{x:e}")
}

/// Scientific notation with 3 significant digits.
fn sci(x: f64) -> String {
    format!("{x:.2e}")
}

/// A number in 3 decimals when it reads well so, else in scientific notation with 2.
pub fn g3(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x.is_finite() && (1e-2..1e4).contains(&x.abs()) {
        format!("{x:.3}")
    } else {
        format!("{x:.2e}")
    }
}

/// Nanoseconds per sample in one decimal, `n/a` when not profiled.
fn ns1(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.1}")
    } else {
        "n/a".into()
    }
}

/// A fraction as a percentage in one decimal, `n/a` when not profiled.
fn pct1(x: f64) -> String {
    if x.is_finite() {
        format!("{:.1}%", 100.0 * x)
    } else {
        "n/a".into()
    }
}

/// The 8-bit statistics of a row (NaN when they were not computed).
fn eight_bit(r: &Row) -> (f64, f64) {
    r.stats.eight_bit.map_or((f64::NAN, f64::NAN), |e| (e.variance, e.mse))
}

/// The columns of `rows.csv` of `strata compare` ([`to_csv`]).
pub const CSV_COLUMNS: &[Column] = &[
    Column { header: "variant", cell: |r, _| r.variant.clone() },
    Column { header: "seconds", cell: |r, _| exact(r.seconds) },
    Column { header: "spp", cell: |r, _| exact(r.spp) },
    Column { header: "mse", cell: |r, _| exact(r.stats.mse) },
    Column { header: "rel_mse", cell: |r, _| exact(r.stats.rel_mse) },
    Column { header: "bias", cell: |r, _| exact(r.stats.bias) },
    Column { header: "bias_ci_lo", cell: |r, _| exact(r.stats.bias_ci.0) },
    Column { header: "bias_ci_hi", cell: |r, _| exact(r.stats.bias_ci.1) },
    Column { header: "variance", cell: |r, _| exact(r.stats.variance) },
    Column { header: "efficiency", cell: |r, _| exact(r.efficiency) },
    Column { header: "sampler_ns_per_sample", cell: |r, _| exact(r.sampler_ns_per_sample) },
    Column { header: "sampler_share", cell: |r, _| exact(r.sampler_share) },
    Column { header: "first_sample", cell: |r, _| r.first_sample.clone() },
    Column { header: "mse_corrected", cell: |r, _| exact(r.stats.mse_corrected()) },
    Column { header: "flip", cell: |r, _| exact(r.flip) },
    Column { header: "eff_vs_baseline", cell: |r, _| exact(r.eff_vs_baseline) },
    Column { header: "same_as", cell: |r, _| r.same_as.clone().unwrap_or_default() },
    Column { header: "mse_corrected_ci_lo", cell: |r, _| exact(r.stats.mse_corrected_ci.0) },
    Column { header: "mse_corrected_ci_hi", cell: |r, _| exact(r.stats.mse_corrected_ci.1) },
    Column { header: "mse_trimmed", cell: |r, _| exact(r.mse_trimmed) },
    Column { header: "mse_boot_ci_lo", cell: |r, _| exact(r.mse_boot_ci.0) },
    Column { header: "mse_boot_ci_hi", cell: |r, _| exact(r.mse_boot_ci.1) },
    Column { header: "rel_mse_boot_ci_lo", cell: |r, _| exact(r.rel_mse_boot_ci.0) },
    Column { header: "rel_mse_boot_ci_hi", cell: |r, _| exact(r.rel_mse_boot_ci.1) },
    Column { header: "eff_vs_baseline_ci_lo", cell: |r, _| exact(r.eff_vs_baseline_ci.0) },
    Column { header: "eff_vs_baseline_ci_hi", cell: |r, _| exact(r.eff_vs_baseline_ci.1) },
];

/// The CSV header written by [`to_csv`]; `bias_ci` is split into two columns. `seconds` is the
/// workers' CPU seconds of one run; `sampler_share` a fraction (0..1), NaN when not profiled.
/// `mse_corrected` is the MSE less the reference's own variance, `flip` the mean FLIP,
/// `eff_vs_baseline` the efficiency over the baseline's at the same spp step, `same_as` the
/// variant that rendered the same images, `mse_corrected_ci_lo/hi` the 95% interval of
/// `mse_corrected` (the runs' spread and the reference's noise).
pub const CSV_HEADER: &str = "variant,seconds,spp,mse,rel_mse,bias,bias_ci_lo,bias_ci_hi,variance,efficiency,sampler_ns_per_sample,sampler_share,first_sample,mse_corrected,flip,eff_vs_baseline,same_as,mse_corrected_ci_lo,mse_corrected_ci_hi,mse_trimmed,mse_boot_ci_lo,mse_boot_ci_hi,rel_mse_boot_ci_lo,rel_mse_boot_ci_hi,eff_vs_baseline_ci_lo,eff_vs_baseline_ci_hi";

/// Samples per pixel as an integer when it is one (ladders), else with one decimal (the mean over
/// the runs of an equal-time budget).
fn spp_cell(spp: f64) -> String {
    if spp.fract() == 0.0 {
        format!("{spp:.0}")
    } else {
        format!("{spp:.1}")
    }
}

/// The efficiency ratio to the baseline: `=NAME` for a variant that renders the baseline's (or
/// another variant's) image, `n/a` when undefined.
fn vs_baseline(r: &Row) -> String {
    match (&r.same_as, r.eff_vs_baseline) {
        (Some(other), _) => format!("same image as {other}"),
        (None, x) if x.is_finite() => format!("{x:.2}x"),
        _ => "n/a".into(),
    }
}

/// The columns of `table.md` of `strata compare` ([`to_markdown`]).
pub const COMPARE_COLUMNS: &[Column] = &[
    Column { header: "variant", cell: |r, _| r.variant.replace('|', "\\|") },
    Column { header: "samplers", cell: |r, _| r.setting.replace('|', "\\|") },
    Column { header: "first sample", cell: |r, _| r.first_sample.clone() },
    Column { header: "spp", cell: |r, _| spp_cell(r.spp) },
    Column { header: "CPU s/run", cell: |r, _| g3(r.seconds) },
    Column { header: "sampler ns/sample", cell: |r, _| ns1(r.sampler_ns_per_sample) },
    Column { header: "% of render in sampler", cell: |r, _| pct1(r.sampler_share) },
    Column { header: "MSE", cell: |r, _| sci(r.stats.mse) },
    Column {
        header: "MSE 95% CI (bootstrap)",
        cell: |r, _| format!("{} .. {}", sci(r.mse_boot_ci.0), sci(r.mse_boot_ci.1)),
    },
    Column { header: "trimmed MSE (99.9%)", cell: |r, _| sci(r.mse_trimmed) },
    Column { header: "MSE - ref. var.", cell: |r, _| sci(r.stats.mse_corrected()) },
    Column {
        header: "its 95% CI",
        cell: |r, _| format!("{} .. {}", sci(r.stats.mse_corrected_ci.0), sci(r.stats.mse_corrected_ci.1)),
    },
    Column { header: "relMSE", cell: |r, _| sci(r.stats.rel_mse) },
    Column { header: "FLIP", cell: |r, _| if r.flip.is_finite() { format!("{:.4}", r.flip) } else { "n/a".into() } },
    Column { header: "bias", cell: |r, _| sci(r.stats.bias) },
    Column { header: "bias 95% CI", cell: |r, _| format!("[{}, {}]", sci(r.stats.bias_ci.0), sci(r.stats.bias_ci.1)) },
    Column { header: "variance", cell: |r, _| sci(r.stats.variance) },
    Column { header: "efficiency 1/(MSE s)", cell: |r, _| sci(r.efficiency) },
    Column {
        header: "eff. ratio 95% CI (bootstrap)",
        cell: |r, _| {
            let (lo, hi) = r.eff_vs_baseline_ci;
            if lo.is_finite() && hi.is_finite() {
                format!("{lo:.2}x .. {hi:.2}x")
            } else {
                "n/a".into()
            }
        },
    },
    Column { header: "eff. vs baseline, same spp", cell: |r, _| vs_baseline(r) },
];

/// The columns of each table of `results.md` of `strata experiments`; ratios are to the first row
/// of the block.
pub const EXPERIMENT_COLUMNS: &[Column] = &[
    Column { header: "variant", cell: |r, _| r.variant.clone() },
    Column { header: "spp", cell: |r, _| format!("{}", r.spp as u32) },
    Column { header: "s", cell: |r, _| g3(r.seconds) },
    Column { header: "sampler ns/sample", cell: |r, _| ns1(r.sampler_ns_per_sample) },
    Column { header: "% in sampler", cell: |r, _| pct1(r.sampler_share) },
    Column { header: "var", cell: |r, _| g3(r.stats.variance) },
    Column { header: "var8", cell: |r, _| g3(eight_bit(r).0) },
    Column { header: "var ratio", cell: |r, first| g3(r.stats.variance / first.stats.variance) },
    Column { header: "MSE", cell: |r, _| g3(r.stats.mse) },
    Column { header: "MSE8", cell: |r, _| g3(eight_bit(r).1) },
    Column { header: "bias", cell: |r, _| g3(r.stats.bias) },
    Column { header: "se", cell: |r, _| g3(r.stats.bias_se) },
    Column { header: "z", cell: |r, _| format!("{:.2}", r.stats.z) },
    Column { header: "rms bias", cell: |r, _| g3(r.stats.rms_bias) },
    Column { header: "b-ratio", cell: |r, _| g3(r.stats.bias_ratio) },
    Column { header: "eff", cell: |r, _| g3(r.efficiency) },
    Column { header: "eff ratio", cell: |r, first| g3(r.efficiency / first.efficiency) },
];

/// CSV of `strata compare`: [`CSV_HEADER`], then one line per row. Numbers are written in the
/// shortest form that parses back to the same f64 (`1.5e-3`; `inf`/`NaN` for non-finite values); a
/// variant name with a comma, quote or line break is quoted.
pub fn to_csv(rows: &[Row]) -> String {
    csv_table(CSV_COLUMNS, rows)
}

/// The aligned Markdown table of `strata compare` ([`COMPARE_COLUMNS`]). Errors are in scientific
/// notation with 3 significant digits; the last column is each row's efficiency divided by the
/// baseline variant's at the same spp step ([`Row::eff_vs_baseline`]), or the variant it renders
/// the same image as.
pub fn to_markdown(rows: &[Row]) -> String {
    markdown_table(&compare_columns(rows), rows, Style::Aligned)
}

/// [`COMPARE_COLUMNS`] for these rows: the efficiency ratio is headed "same spp" only when the
/// rows it compares (one step of each variant) have the same spp; equal-time steps, whose
/// variants reach different spp, are headed "same budget".
pub fn compare_columns(rows: &[Row]) -> Vec<Column> {
    let variants = rows.iter().map(|r| &r.variant).collect::<std::collections::BTreeSet<_>>().len().max(1);
    let steps = (rows.len() / variants).max(1);
    let same_spp = (0..steps).all(|s| {
        let mut spp = rows.iter().skip(s).step_by(steps).map(|r| r.spp);
        let first = spp.next();
        spp.all(|x| Some(x) == first)
    });
    let mut cols = COMPARE_COLUMNS.to_vec();
    if let Some(c) = cols.iter_mut().find(|c| c.header.starts_with("eff. vs baseline")).filter(|_| !same_spp) {
        c.header = "eff. vs baseline, same budget";
    }
    cols
}

/// A row of `rows.json` of `strata compare`.
#[derive(Serialize)]
struct FlatRow<'a> {
    variant: &'a str,
    /// the samplers that ran (`strata compare` puts them in the row's `setting`)
    samplers: &'a str,
    seconds: f64,
    spp: f64,
    mse: f64,
    rel_mse: f64,
    bias: f64,
    bias_ci: (f64, f64),
    variance: f64,
    efficiency: f64,
    sampler_ns_per_sample: f64,
    sampler_share: f64,
    first_sample: &'a str,
    mse_corrected: f64,
    flip: f64,
    eff_vs_baseline: f64,
    same_as: Option<&'a str>,
    mse_corrected_ci: (f64, f64),
    mse_trimmed: f64,
    mse_boot_ci: (f64, f64),
    rel_mse_boot_ci: (f64, f64),
    eff_vs_baseline_ci: (f64, f64),
}

/// The JSON of `strata compare`: an array of objects with the keys `variant`, `seconds` (the
/// workers' CPU seconds of one run), `spp`, `mse`, `rel_mse`, `bias`, `bias_ci` (`[lo, hi]`),
/// `variance`, `efficiency`, `sampler_ns_per_sample`, `sampler_share` (a fraction),
/// `first_sample`, `mse_corrected`, `flip`, `eff_vs_baseline`, `same_as` and `mse_corrected_ci`
/// (`[lo, hi]`, 95%). JSON has no
/// infinity or NaN: such values (e.g. an infinite efficiency) become `null`.
pub fn to_json(rows: &[Row]) -> serde_json::Value {
    let flat: Vec<FlatRow> = rows
        .iter()
        .map(|r| FlatRow {
            variant: &r.variant,
            samplers: &r.setting,
            seconds: r.seconds,
            spp: r.spp,
            mse: r.stats.mse,
            rel_mse: r.stats.rel_mse,
            bias: r.stats.bias,
            bias_ci: r.stats.bias_ci,
            variance: r.stats.variance,
            efficiency: r.efficiency,
            sampler_ns_per_sample: r.sampler_ns_per_sample,
            sampler_share: r.sampler_share,
            first_sample: &r.first_sample,
            mse_corrected: r.stats.mse_corrected(),
            flip: r.flip,
            eff_vs_baseline: r.eff_vs_baseline,
            same_as: r.same_as.as_deref(),
            mse_corrected_ci: r.stats.mse_corrected_ci,
            mse_trimmed: r.mse_trimmed,
            mse_boot_ci: r.mse_boot_ci,
            rel_mse_boot_ci: r.rel_mse_boot_ci,
            eff_vs_baseline_ci: r.eff_vs_baseline_ci,
        })
        .collect();
    serde_json::to_value(flat).expect("rows serialize to JSON")
}

/// A row of `results.json` of `strata experiments`: its grouping and a `stats` object.
#[derive(Serialize)]
pub struct GroupedRow<'a> {
    table: &'a str,
    scene: &'a str,
    variant: &'a str,
    setting: &'a str,
    stats: GroupedStats,
}

/// The `stats` object of a [`GroupedRow`].
#[derive(Serialize)]
struct GroupedStats {
    runs: usize,
    seconds: f64,
    spp: u32,
    variance: f64,
    variance_8bit: f64,
    mse: f64,
    mse_8bit: f64,
    bias: f64,
    bias_se: f64,
    z: f64,
    rms_bias: f64,
    bias_ratio: f64,
    efficiency: f64,
    sampler_ns_per_sample: f64,
    sampler_share: f64,
}

/// The rows as `strata experiments` writes them to JSON: objects with `table`, `scene`, `variant`,
/// `setting` and `stats` (`runs`, `seconds` (the workers' CPU seconds of one run), `spp`,
/// `variance`, `variance_8bit`, `mse`, `mse_8bit`, `bias`, `bias_se`, `z`, `rms_bias`,
/// `bias_ratio`, `efficiency`, `sampler_ns_per_sample`, `sampler_share`; non-finite numbers are
/// `null`). Serialize the result with `serde_json`.
pub fn to_grouped_json(rows: &[Row]) -> Vec<GroupedRow<'_>> {
    rows.iter()
        .map(|r| {
            let (variance_8bit, mse_8bit) = eight_bit(r);
            let s = &r.stats;
            GroupedRow {
                table: &r.table,
                scene: &r.scene,
                variant: &r.variant,
                setting: &r.setting,
                stats: GroupedStats {
                    runs: s.runs,
                    seconds: r.seconds,
                    spp: r.spp as u32,
                    variance: s.variance,
                    variance_8bit,
                    mse: s.mse,
                    mse_8bit,
                    bias: s.bias,
                    bias_se: s.bias_se,
                    z: s.z,
                    rms_bias: s.rms_bias,
                    bias_ratio: s.bias_ratio,
                    efficiency: r.efficiency,
                    sampler_ns_per_sample: r.sampler_ns_per_sample,
                    sampler_share: r.sampler_share,
                },
            }
        })
        .collect()
}

#[cfg(test)]
#[path = "table_tests.rs"]
mod tests;

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
    /// wall-clock seconds of one run (the mean over runs)
    pub seconds: f64,
    /// samples per pixel of one run (the mean over runs)
    pub spp: f64,
    /// the error statistics over the runs
    pub stats: RunStats,
    /// `1 / (mse * seconds)`, infinite when that product is zero ([`efficiency`])
    pub efficiency: f64,
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
        })
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

/// CSV (RFC 4180) of `rows` under `columns`: the headers, then one line per row; a cell with a
/// comma, quote or line break is quoted.
pub fn csv_table(columns: &[Column], rows: &[Row]) -> String {
    let header: Vec<&str> = columns.iter().map(|c| c.header).collect();
    let mut out = format!("{}\n", header.join(","));
    for row in cells(columns, rows) {
        let row: Vec<String> = row.iter().map(|c| csv_field(c)).collect();
        out += &row.join(",");
        out.push('\n');
    }
    out
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A number in the shortest form that parses back to the same f64 (`1.5e-3`; `inf`/`NaN`).
fn exact(x: f64) -> String {
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
];

/// The CSV header written by [`to_csv`]; `bias_ci` is split into two columns.
pub const CSV_HEADER: &str = "variant,seconds,spp,mse,rel_mse,bias,bias_ci_lo,bias_ci_hi,variance,efficiency";

/// The columns of `table.md` of `strata compare` ([`to_markdown`]).
pub const COMPARE_COLUMNS: &[Column] = &[
    Column { header: "variant", cell: |r, _| r.variant.replace('|', "\\|") },
    Column { header: "seconds", cell: |r, _| sci(r.seconds) },
    Column { header: "spp", cell: |r, _| sci(r.spp) },
    Column { header: "MSE", cell: |r, _| sci(r.stats.mse) },
    Column { header: "relMSE", cell: |r, _| sci(r.stats.rel_mse) },
    Column { header: "bias", cell: |r, _| sci(r.stats.bias) },
    Column { header: "bias 95% CI", cell: |r, _| format!("[{}, {}]", sci(r.stats.bias_ci.0), sci(r.stats.bias_ci.1)) },
    Column { header: "variance", cell: |r, _| sci(r.stats.variance) },
    Column { header: "efficiency", cell: |r, _| sci(r.efficiency) },
    Column {
        header: "eff. vs first",
        cell: |r, first| {
            let ratio = r.efficiency / first.efficiency;
            if ratio.is_nan() {
                "n/a".into()
            } else {
                sci(ratio)
            }
        },
    },
];

/// The columns of each table of `results.md` of `strata experiments`; ratios are to the first row
/// of the block.
pub const EXPERIMENT_COLUMNS: &[Column] = &[
    Column { header: "variant", cell: |r, _| r.variant.clone() },
    Column { header: "spp", cell: |r, _| format!("{}", r.spp as u32) },
    Column { header: "s", cell: |r, _| g3(r.seconds) },
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

/// The aligned Markdown table of `strata compare` ([`COMPARE_COLUMNS`]). Numbers are in
/// scientific notation with 3 significant digits; the last column is each row's efficiency divided
/// by the first row's (`n/a` where that ratio is undefined, e.g. inf/inf).
pub fn to_markdown(rows: &[Row]) -> String {
    markdown_table(COMPARE_COLUMNS, rows, Style::Aligned)
}

/// A row of `rows.json` of `strata compare`.
#[derive(Serialize)]
struct FlatRow<'a> {
    variant: &'a str,
    seconds: f64,
    spp: f64,
    mse: f64,
    rel_mse: f64,
    bias: f64,
    bias_ci: (f64, f64),
    variance: f64,
    efficiency: f64,
}

/// The JSON of `strata compare`: an array of objects with the keys `variant`, `seconds`, `spp`,
/// `mse`, `rel_mse`, `bias`, `bias_ci` (`[lo, hi]`), `variance` and `efficiency`. JSON has no
/// infinity or NaN: such values (e.g. an infinite efficiency) become `null`.
pub fn to_json(rows: &[Row]) -> serde_json::Value {
    let flat: Vec<FlatRow> = rows
        .iter()
        .map(|r| FlatRow {
            variant: &r.variant,
            seconds: r.seconds,
            spp: r.spp,
            mse: r.stats.mse,
            rel_mse: r.stats.rel_mse,
            bias: r.stats.bias,
            bias_ci: r.stats.bias_ci,
            variance: r.stats.variance,
            efficiency: r.efficiency,
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
}

/// The rows as `strata experiments` writes them to JSON: objects with `table`, `scene`, `variant`,
/// `setting` and `stats` (`runs`, `seconds`, `spp`, `variance`, `variance_8bit`, `mse`,
/// `mse_8bit`, `bias`, `bias_se`, `z`, `rms_bias`, `bias_ratio`, `efficiency`; non-finite
/// numbers are `null`). Serialize the result with `serde_json`.
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
                },
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::metrics::EightBit;

    fn row(variant: &str, seconds: f64, mse: f64) -> Row {
        let stats = RunStats {
            runs: 4,
            bias: -1.25e-4,
            bias_se: 1.0e-4,
            bias_ci: (-3.5e-4, 1.0e-4),
            z: -1.25,
            bias_sq: 0.1 * mse,
            rms_bias: 0.01,
            bias_ratio: 1.5,
            variance: 0.9 * mse,
            mse,
            rel_mse: 3.0 * mse,
            eight_bit: Some(EightBit { variance: 2.5, mse: 3.5 }),
        };
        Row::new(variant, seconds, 64.0, &stats).unwrap()
    }

    fn rows() -> Vec<Row> {
        vec![
            row("independent", 2.0, 0.004),
            row("stratified, 8x8", 2.5, 0.001),
            row("say \"halton\" | x", 1.0, 0.0123456),
        ]
    }

    /// Splits one CSV line into fields, honouring RFC 4180 quotes.
    fn parse_csv_line(line: &str) -> Vec<String> {
        let (mut fields, mut field, mut quoted, mut chars) =
            (Vec::new(), String::new(), false, line.chars().peekable());
        while let Some(c) = chars.next() {
            match (c, quoted) {
                ('"', true) if chars.peek() == Some(&'"') => {
                    field.push('"');
                    chars.next();
                }
                ('"', _) => quoted = !quoted,
                (',', false) => fields.push(std::mem::take(&mut field)),
                _ => field.push(c),
            }
        }
        fields.push(field);
        fields
    }

    #[test]
    fn csv_has_header_one_line_per_row_and_parses_back() {
        let rows = rows();
        let csv = to_csv(&rows);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), rows.len() + 1);
        assert_eq!(lines[0], CSV_HEADER);
        for (line, row) in lines[1..].iter().zip(&rows) {
            let f = parse_csv_line(line);
            assert_eq!(f.len(), 10, "{line}");
            let x: Vec<f64> = f[1..].iter().map(|s| s.parse().unwrap()).collect();
            assert_eq!(f[0], row.variant);
            let s = &row.stats;
            let want =
                [row.seconds, row.spp, s.mse, s.rel_mse, s.bias, s.bias_ci.0, s.bias_ci.1, s.variance, row.efficiency];
            assert_eq!(x, want, "{line}");
        }
        // Infinite efficiency survives the round trip too.
        let mut inf = rows[0].clone();
        inf.efficiency = f64::INFINITY;
        let line = to_csv(&[inf]).lines().nth(1).unwrap().to_string();
        assert_eq!(parse_csv_line(&line)[9].parse::<f64>().unwrap(), f64::INFINITY);
    }

    #[test]
    fn json_has_the_compare_keys_and_round_trips_the_numbers() {
        let rows = rows();
        let value = to_json(&rows);
        assert_eq!(value.as_array().unwrap().len(), 3);
        assert_eq!(value[1]["variant"], "stratified, 8x8");
        assert_eq!(value[0]["bias_ci"], serde_json::json!([-3.5e-4, 1.0e-4]));
        let keys: Vec<&str> = value[0].as_object().unwrap().keys().map(String::as_str).collect();
        let mut want = ["variant", "seconds", "spp", "mse", "rel_mse", "bias", "bias_ci", "variance", "efficiency"];
        want.sort_unstable();
        let mut keys = keys;
        keys.sort_unstable();
        assert_eq!(keys, want);
        let text = serde_json::to_string(&value).unwrap();
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        for (b, r) in back.as_array().unwrap().iter().zip(&rows) {
            assert_eq!(b["mse"].as_f64(), Some(r.stats.mse));
            assert_eq!(b["efficiency"].as_f64(), Some(r.efficiency));
            assert_eq!(b["spp"].as_f64(), Some(r.spp));
        }
        let mut inf = rows[0].clone();
        inf.efficiency = f64::INFINITY;
        assert!(to_json(&[inf])[0]["efficiency"].is_null());
    }

    #[test]
    fn grouped_json_has_the_experiment_keys_in_order() {
        let rows: Vec<Row> = rows().into_iter().map(|r| r.grouped("direct", "sphere", "9")).collect();
        let text = serde_json::to_string(&to_grouped_json(&rows)).unwrap();
        let first = text.split("},{").next().unwrap();
        let order = [
            "\"table\":\"direct\"",
            "\"scene\":\"sphere\"",
            "\"variant\":\"independent\"",
            "\"setting\":\"9\"",
            "\"stats\":{\"runs\":4,\"seconds\":2.0,\"spp\":64,\"variance\":",
            "\"variance_8bit\":2.5,\"mse\":0.004,\"mse_8bit\":3.5,\"bias\":-0.000125,\"bias_se\":0.0001,\"z\":-1.25,",
            "\"rms_bias\":0.01,\"bias_ratio\":1.5,\"efficiency\":125.0}",
        ];
        let mut at = 0;
        for o in order {
            let i = first[at..].find(o).unwrap_or_else(|| panic!("{o} after {at} in {first}"));
            at += i + o.len();
        }
    }

    #[test]
    fn markdown_is_aligned_with_efficiency_ratio() {
        let rows = rows();
        let md = to_markdown(&rows);
        let lines: Vec<&str> = md.lines().collect();
        assert_eq!(lines.len(), rows.len() + 2);
        let width = lines[0].chars().count();
        assert!(lines.iter().all(|l| l.chars().count() == width), "{md}");
        assert!(lines[0].contains("eff. vs first") && lines[1].starts_with("|:-"));
        // Ratios: 1, (1/0.0025)/(1/0.008) = 3.2, (1/0.0123456)/(1/0.008) = 0.648.
        let last = |l: &str| l.trim_end_matches('|').rsplit('|').next().unwrap().trim().to_string();
        assert_eq!(last(lines[2]), "1.00e0");
        assert_eq!(last(lines[3]), "3.20e0");
        assert_eq!(last(lines[4]), "6.48e-1");
        assert!(lines[2].contains("4.00e-3") && lines[2].contains("[-3.50e-4, 1.00e-4]"));
        assert!(lines[4].contains("say \"halton\" \\| x"));
        assert_eq!(to_markdown(&[]).lines().count(), 2);
    }

    #[test]
    fn plain_markdown_has_one_cell_per_column_and_ratios_to_the_first_row() {
        let rows = rows();
        let md = markdown_table(EXPERIMENT_COLUMNS, &rows, Style::Plain);
        let lines: Vec<&str> = md.lines().collect();
        assert_eq!(lines.len(), 2 + rows.len());
        assert!(
            lines[0].starts_with("| variant | spp | s | var | var8 |") && lines[0].ends_with("| eff | eff ratio |")
        );
        assert_eq!(lines[1], format!("|{}", "---|".repeat(EXPERIMENT_COLUMNS.len())));
        assert_eq!(lines[2], "| independent | 64 | 2.000 | 3.60e-3 | 2.500 | 1.000 | 4.00e-3 | 3.500 | -1.25e-4 | 1.00e-4 | -1.25 | 0.010 | 1.500 | 125.000 | 1.000 |");
        // Second row: efficiency 1/(0.001 x 2.5) = 400, ratio 400 / 125 = 3.2; variance ratio 0.25.
        assert!(
            lines[3].ends_with(
                "| 0.250 | 1.00e-3 | 3.500 | -1.25e-4 | 1.00e-4 | -1.25 | 0.010 | 1.500 | 400.000 | 3.200 |"
            ),
            "{}",
            lines[3]
        );
    }

    #[test]
    fn csv_columns_spell_the_header_and_g3_reads_well() {
        let header: Vec<&str> = CSV_COLUMNS.iter().map(|c| c.header).collect();
        assert_eq!(header.join(","), CSV_HEADER);
        assert_eq!(
            (g3(0.0), g3(1.5), g3(12345.0), g3(0.001)),
            ("0".into(), "1.500".into(), "1.23e4".into(), "1.00e-3".into())
        );
    }

    #[test]
    fn row_from_stats() {
        let reference = vec![[1.0f32; 3]; 2];
        let runs = vec![vec![[1.5f32; 3]; 2], vec![[0.5f32; 3]; 2]];
        let stats = RunStats::from_runs(&runs, &reference).unwrap();
        let row = Row::new("v", 2.0, 16.0, &stats).unwrap();
        assert_eq!((row.stats.mse, row.efficiency, row.stats.bias), (0.25, 2.0, 0.0));
        assert!(Row::new("v", f64::NAN, 16.0, &stats).is_err());
    }
}

//! One row of results per variant, written as CSV, JSON or an aligned Markdown table.

use super::metrics::{efficiency, RunStats};
use super::ReportError;
use serde::{Deserialize, Serialize};

/// One variant's results: the cost of one run and the error statistics over its runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// variant name (technique and settings)
    pub variant: String,
    /// wall-clock seconds of one run
    pub seconds: f64,
    /// samples per pixel of one run
    pub spp: f64,
    /// mean over runs of the MSE ([`RunStats::mse`])
    pub mse: f64,
    /// mean over runs of the relative MSE ([`RunStats::rel_mse`])
    pub rel_mse: f64,
    /// mean signed error ([`RunStats::bias`])
    pub bias: f64,
    /// 95% confidence interval of `bias` (serialized as a two-element array)
    pub bias_ci: (f64, f64),
    /// mean across-run variance ([`RunStats::variance`])
    pub variance: f64,
    /// `1 / (mse * seconds)`, infinite when that product is zero ([`efficiency`])
    pub efficiency: f64,
}

impl Row {
    /// A row from run statistics and the time and samples per pixel of one run.
    pub fn new(variant: impl Into<String>, seconds: f64, spp: f64, stats: &RunStats) -> Result<Self, ReportError> {
        Ok(Row {
            variant: variant.into(),
            seconds,
            spp,
            mse: stats.mse,
            rel_mse: stats.rel_mse,
            bias: stats.bias,
            bias_ci: stats.bias_ci,
            variance: stats.variance,
            efficiency: efficiency(stats.mse, seconds)?,
        })
    }

    /// The numeric fields in [`CSV_HEADER`] order (after `variant`).
    fn numbers(&self) -> [f64; 9] {
        let (lo, hi) = self.bias_ci;
        [self.seconds, self.spp, self.mse, self.rel_mse, self.bias, lo, hi, self.variance, self.efficiency]
    }
}

/// The CSV header written by [`to_csv`]; `bias_ci` is split into two columns.
pub const CSV_HEADER: &str = "variant,seconds,spp,mse,rel_mse,bias,bias_ci_lo,bias_ci_hi,variance,efficiency";

/// CSV (RFC 4180): [`CSV_HEADER`], then one line per row. Numbers are written in the shortest
/// form that parses back to the same f64 (`1.5e-3`; `inf`/`NaN` for non-finite values); a
/// variant name with a comma, quote or line break is quoted.
pub fn to_csv(rows: &[Row]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for row in rows {
        out += &csv_field(&row.variant);
        for x in row.numbers() {
            out += &format!(",{x:e}");
        }
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

/// A JSON array of row objects with the field names of [`Row`]; `bias_ci` is `[lo, hi]`.
/// JSON has no infinity or NaN: such values (e.g. an infinite efficiency) become `null`.
pub fn to_json(rows: &[Row]) -> serde_json::Value {
    serde_json::to_value(rows).expect("rows serialize to JSON")
}

/// An aligned Markdown pipe table: a header line, an alignment line and one line per row.
/// Numbers are in scientific notation with 3 significant digits; the last column is each row's
/// efficiency divided by the first row's (`n/a` where that ratio is undefined, e.g. inf/inf).
pub fn to_markdown(rows: &[Row]) -> String {
    const HEADER: [&str; 10] = [
        "variant",
        "seconds",
        "spp",
        "MSE",
        "relMSE",
        "bias",
        "bias 95% CI",
        "variance",
        "efficiency",
        "eff. vs first",
    ];
    let sci = |x: f64| format!("{x:.2e}");
    let first = rows.first().map_or(f64::NAN, |r| r.efficiency);
    let cells: Vec<[String; 10]> = rows
        .iter()
        .map(|r| {
            let ratio = r.efficiency / first;
            [
                r.variant.replace('|', "\\|"),
                sci(r.seconds),
                sci(r.spp),
                sci(r.mse),
                sci(r.rel_mse),
                sci(r.bias),
                format!("[{}, {}]", sci(r.bias_ci.0), sci(r.bias_ci.1)),
                sci(r.variance),
                sci(r.efficiency),
                if ratio.is_nan() { "n/a".into() } else { sci(ratio) },
            ]
        })
        .collect();
    let mut width = HEADER.map(|h| h.chars().count());
    for row in &cells {
        for (w, cell) in width.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    // The variant column is left-aligned, the numbers right-aligned.
    let line = |row: [&str; 10]| {
        let mut s = String::from("|");
        for (i, (cell, w)) in row.iter().zip(width).enumerate() {
            s += &if i == 0 { format!(" {cell:<w$} |") } else { format!(" {cell:>w$} |") };
        }
        s + "\n"
    };
    let mut out = line(HEADER);
    out += "|";
    for (i, w) in width.iter().enumerate() {
        out += &if i == 0 { format!(":{}|", "-".repeat(w + 1)) } else { format!("{}:|", "-".repeat(w + 1)) };
    }
    out += "\n";
    for row in &cells {
        out += &line(row.each_ref().map(String::as_str));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows() -> Vec<Row> {
        let row = |variant: &str, seconds: f64, mse: f64| Row {
            variant: variant.into(),
            seconds,
            spp: 64.0,
            mse,
            rel_mse: 3.0 * mse,
            bias: -1.25e-4,
            bias_ci: (-3.5e-4, 1.0e-4),
            variance: 0.9 * mse,
            efficiency: efficiency(mse, seconds).unwrap(),
        };
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
            let back = Row {
                variant: f[0].clone(),
                seconds: x[0],
                spp: x[1],
                mse: x[2],
                rel_mse: x[3],
                bias: x[4],
                bias_ci: (x[5], x[6]),
                variance: x[7],
                efficiency: x[8],
            };
            assert_eq!(&back, row);
        }
        // Infinite efficiency survives the round trip too.
        let mut inf = rows[0].clone();
        inf.efficiency = f64::INFINITY;
        let line = to_csv(&[inf]).lines().nth(1).unwrap().to_string();
        assert_eq!(parse_csv_line(&line)[9].parse::<f64>().unwrap(), f64::INFINITY);
    }

    #[test]
    fn json_round_trips() {
        let rows = rows();
        let value = to_json(&rows);
        assert_eq!(value.as_array().unwrap().len(), 3);
        assert_eq!(value[1]["variant"], "stratified, 8x8");
        assert_eq!(value[0]["bias_ci"], serde_json::json!([-3.5e-4, 1.0e-4]));
        let text = serde_json::to_string(&value).unwrap();
        let back: Vec<Row> = serde_json::from_str(&text).unwrap();
        assert_eq!(back, rows);
        let mut inf = rows[0].clone();
        inf.efficiency = f64::INFINITY;
        assert!(to_json(&[inf])[0]["efficiency"].is_null());
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
    fn row_from_stats() {
        let reference = vec![[1.0f32; 3]; 2];
        let runs = vec![vec![[1.5f32; 3]; 2], vec![[0.5f32; 3]; 2]];
        let stats = RunStats::from_runs(&runs, &reference).unwrap();
        let row = Row::new("v", 2.0, 16.0, &stats).unwrap();
        assert_eq!((row.mse, row.efficiency, row.bias), (0.25, 2.0, 0.0));
        assert!(Row::new("v", f64::NAN, 16.0, &stats).is_err());
    }
}

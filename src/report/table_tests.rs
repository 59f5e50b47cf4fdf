//! Tests of the results tables (`report::table`): CSV, JSON, Markdown and the sampler columns.

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
        ref_variance: 0.0,
        mse_corrected_ci: (0.5 * mse, 1.5 * mse),
    };
    Row::new(variant, seconds, 64.0, &stats).unwrap().with_sampler(12.5, 0.25)
}

fn rows() -> Vec<Row> {
    vec![row("independent", 2.0, 0.004), row("stratified, 8x8", 2.5, 0.001), row("say \"halton\" | x", 1.0, 0.0123456)]
}

/// Splits one CSV line into fields, honouring RFC 4180 quotes.
fn parse_csv_line(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted, mut chars) = (Vec::new(), String::new(), false, line.chars().peekable());
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
        assert_eq!(f.len(), 26, "{line}");
        let ci: Vec<f64> = f[17..19].iter().map(|s| s.parse().unwrap()).collect();
        assert_eq!(ci, [row.stats.mse_corrected_ci.0, row.stats.mse_corrected_ci.1], "{line}");
        let x: Vec<f64> = f[1..12].iter().map(|s| s.parse().unwrap()).collect();
        assert_eq!(f[0], row.variant);
        let s = &row.stats;
        let want = [
            row.seconds,
            row.spp,
            s.mse,
            s.rel_mse,
            s.bias,
            s.bias_ci.0,
            s.bias_ci.1,
            s.variance,
            row.efficiency,
            row.sampler_ns_per_sample,
            row.sampler_share,
        ];
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
    let mut want = [
        "variant",
        "samplers",
        "seconds",
        "spp",
        "mse",
        "rel_mse",
        "bias",
        "bias_ci",
        "variance",
        "efficiency",
        "sampler_ns_per_sample",
        "sampler_share",
        "first_sample",
        "mse_corrected",
        "flip",
        "eff_vs_baseline",
        "same_as",
        "mse_corrected_ci",
        "mse_trimmed",
        "mse_boot_ci",
        "rel_mse_boot_ci",
        "eff_vs_baseline_ci",
    ];
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
        "\"rms_bias\":0.01,\"bias_ratio\":1.5,\"efficiency\":125.0,",
        "\"sampler_ns_per_sample\":12.5,\"sampler_share\":0.25}",
    ];
    let mut at = 0;
    for o in order {
        let i = first[at..].find(o).unwrap_or_else(|| panic!("{o} after {at} in {first}"));
        at += i + o.len();
    }
}

#[test]
fn markdown_is_aligned_with_integer_spp_units_and_the_baseline_ratio() {
    let mut rows = rows();
    (rows[0].eff_vs_baseline, rows[1].eff_vs_baseline) = (1.0, 3.2);
    rows[2].same_as = Some("independent".into());
    rows[0].first_sample = "jittered".into();
    let md = to_markdown(&rows);
    let lines: Vec<&str> = md.lines().collect();
    assert_eq!(lines.len(), rows.len() + 2);
    let width = lines[0].chars().count();
    assert!(lines.iter().all(|l| l.chars().count() == width), "{md}");
    assert!(lines[0].contains("eff. vs baseline, same spp") && lines[1].starts_with("|:-"));
    assert!(lines[0].contains("CPU s/run") && lines[0].contains("first sample"), "units in headers: {}", lines[0]);
    let cell = |l: &str, i: usize| l.split('|').nth(i + 1).unwrap().trim().to_string();
    // spp is an integer, not 6.40e1; the first-sample column says which layout each row used.
    assert_eq!((cell(lines[2], 3), cell(lines[2], 2)), ("64".to_string(), "jittered".to_string()));
    let last = |l: &str| l.trim_end_matches('|').rsplit('|').next().unwrap().trim().to_string();
    assert_eq!(last(lines[2]), "1.00x");
    assert_eq!(last(lines[3]), "3.20x");
    assert_eq!(last(lines[4]), "same image as independent");
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
        lines[0].starts_with("| variant | spp | s | sampler ns/sample | % in sampler | var | var8 |")
            && lines[0].ends_with("| eff | eff ratio |")
    );
    assert_eq!(lines[1], format!("|{}", "---|".repeat(EXPERIMENT_COLUMNS.len())));
    assert_eq!(lines[2], "| independent | 64 | 2.000 | 12.5 | 25.0% | 3.60e-3 | 2.500 | 1.000 | 4.00e-3 | 3.500 | -1.25e-4 | 1.00e-4 | -1.25 | 0.010 | 1.500 | 125.000 | 1.000 |");
    // Second row: efficiency 1/(0.001 x 2.5) = 400, ratio 400 / 125 = 3.2; variance ratio 0.25.
    assert!(
        lines[3]
            .ends_with("| 0.250 | 1.00e-3 | 3.500 | -1.25e-4 | 1.00e-4 | -1.25 | 0.010 | 1.500 | 400.000 | 3.200 |"),
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

/// A row whose runs were not profiled says so: `n/a` in Markdown, NaN in CSV, null in JSON;
/// a profiled one shows its sampler cost in both tables.
#[test]
fn sampler_columns_show_the_profile_or_say_not_profiled() {
    let mut plain = rows()[0].clone();
    (plain.sampler_ns_per_sample, plain.sampler_share) = (f64::NAN, f64::NAN);
    (plain.flip, plain.eff_vs_baseline) = (0.05, 1.0);
    let md = to_markdown(&[rows()[0].clone(), plain.clone()]);
    let lines: Vec<&str> = md.lines().collect();
    assert!(lines[0].contains("sampler ns/sample") && lines[0].contains("% of render in sampler"));
    assert!(lines[2].contains(" 12.5 |") && lines[2].contains(" 25.0% |"), "{}", lines[2]);
    // Not profiled (2), and no runs to bootstrap the efficiency ratio's interval from (1).
    assert_eq!(lines[3].matches(" n/a |").count(), 3, "{}", lines[3]);
    assert!(to_csv(&[plain.clone()]).lines().nth(1).unwrap().contains(",NaN,NaN,"));
    assert!(to_json(&[plain])[0]["sampler_share"].is_null());
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

#[test]
fn the_efficiency_ratio_says_same_budget_when_spp_differ() {
    // Equal spp: every variant at 64 spp per step.
    let header = |rows: &[Row]| compare_columns(rows).iter().find(|c| c.header.starts_with("eff. vs")).unwrap().header;
    assert_eq!(header(&rows()), "eff. vs baseline, same spp");
    // Equal time (a budget ladder of two steps): variants reach different spp at a step.
    let mut r = vec![row("a", 0.25, 0.004), row("a", 0.5, 0.002), row("b", 0.25, 0.003), row("b", 0.5, 0.0015)];
    for (x, spp) in r.iter_mut().zip([70.0, 141.0, 101.5, 203.0]) {
        x.spp = spp;
    }
    assert_eq!(header(&r), "eff. vs baseline, same budget");
    assert!(to_markdown(&r).contains("same budget") && !to_markdown(&r).contains("same spp"));
}

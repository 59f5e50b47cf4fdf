//! Prints Mitsuba 3's regression criterion over its corpus as strata renders it: per scene the
//! spp, the fraction of pixel channels accepted, the smallest p-value and the Sidak level, or the
//! refusal. `cargo run --release --example mitsuba_ztest [-- SCENE_SUBSTRING...] [--threads N]`;
//! the corpus is `../shared/corpora/mitsuba-tests` (or `STRATA_MITSUBA_TESTS`). A Markdown table.

use strata::lab::mitsuba::{corpus_dir, run_scene, CORPUS};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut threads = 0;
    let mut filters = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--threads" {
            threads = it.next().and_then(|n| n.parse().ok()).expect("--threads N");
        } else {
            filters.push(a.clone());
        }
    }
    let dir = corpus_dir().join("tests/scenes");
    if !dir.is_dir() {
        eprintln!("{}: the Mitsuba corpus is not there (set STRATA_MITSUBA_TESTS)", dir.display());
        std::process::exit(1);
    }
    println!("| scene | spp | accepted | smallest p | Sidak level | result |");
    println!("|---|---|---|---|---|---|");
    for (rel, expect) in CORPUS {
        if !filters.is_empty() && !filters.iter().any(|f| rel.contains(f.as_str())) {
            continue;
        }
        match run_scene(&dir.join(rel), threads) {
            Ok(o) => println!(
                "| {rel} | {} | {:.4} % | {:.3e} | {:.3e} | {} (expected {expect:?}) |",
                o.spp,
                100.0 * o.test.accepted,
                o.test.min_p,
                o.test.level,
                if o.test.passed { "pass" } else { "FAIL" }
            ),
            Err(e) => {
                println!("| {rel} | | | | | refused: {} (expected {expect:?}) |", e.to_string().replace('|', "/"))
            }
        }
    }
}

//! `report.html` of `strata compare` in a real browser: Debian's Chromium, headless (installed by
//! scripts/setup.sh). The page loads without console errors; its self-test mode (`#selftest`)
//! presses every flip-book key and writes what each showed into the DOM, read back with
//! `--dump-dom`; a screenshot is kept as a test artifact in `target/test-artifacts/report.png`.
//!
//! Needs `../shared/cse168` (CI always has it: a missing corpus fails this test).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Headless Chromium on `url` with `extra` flags: (stdout, stderr).
fn chromium(url: &str, extra: &[&str]) -> (String, String) {
    let profile = common::tmpdir(&format!("chromium-{}", extra.len()));
    let out = Command::new("chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--no-first-run",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(url)
        .output()
        .expect("chromium runs (scripts/setup.sh installs Debian's chromium)");
    (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Console messages of the page in Chromium's log (`CONSOLE` lines), and uncaught errors.
fn console_errors(log: &str) -> Vec<&str> {
    log.lines().filter(|l| l.contains("CONSOLE") || l.contains("Uncaught")).collect()
}

fn compare_report(dir: &Path) -> PathBuf {
    let sphere = common::corpus_required().join("hw2/sphere.test");
    let st = common::strata()
        .arg("reference")
        .arg(&sphere)
        .args(["--size", "40x30", "--spp", "16", "-q", "-o"])
        .arg(dir.join("ref"))
        .status()
        .unwrap();
    assert!(st.success());
    let out = common::strata()
        .arg("compare")
        .arg(&sphere)
        .arg("--reference")
        .arg(dir.join("ref.exr"))
        .args(["--size", "40x30", "--runs", "2", "--spp-ladder", "1,4", "--threads", "2", "-q"])
        .args(["--variant", "independent=--light-sampler independent"])
        .args(["--variant", "stratified=--light-sampler stratified"])
        .args(["--variant", "halton=--light-sampler halton"])
        .arg("--out")
        .arg(dir.join("cmp"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    dir.join("cmp/report.html")
}

#[test]
fn report_html_flip_book_shows_every_variant_in_headless_chromium() {
    let d = common::tmpdir("report-html");
    let page = compare_report(&d);
    let html = std::fs::read_to_string(&page).unwrap();
    // Self-contained: no network resource.
    for bad in ["src=\"http", "href=\"http", "url(http", "@import", "<link", "src=\"/"] {
        assert!(!html.contains(bad), "report.html refers to {bad}");
    }
    let url = format!("file://{}", page.display());
    let (dom, log) = chromium(&format!("{url}#selftest"), &["--dump-dom"]);
    assert!(console_errors(&log).is_empty(), "console errors: {:?}", console_errors(&log));
    let start = dom.find("<pre id=\"selftest\">").unwrap_or_else(|| panic!("no self-test output in the DOM:\n{log}"));
    let text = &dom[start..dom[start..].find("</pre>").map_or(dom.len(), |e| start + e)];
    // The image flip-book: reference then the three variants, each shown alone and decoded.
    let want = ["reference", "independent", "stratified", "halton"];
    for (i, label) in want.iter().enumerate() {
        let line = format!("book 0 key {} shows {label} visible 1 loaded true", i + 1);
        assert!(text.contains(&line), "missing `{line}` in:\n{text}");
    }
    // The error-map flip-book: relMSE, signed and FLIP of each variant.
    for (i, label) in
        ["independent: relMSE", "independent: signed", "independent: FLIP", "stratified: relMSE"].iter().enumerate()
    {
        let line = format!("book 1 key {} shows {label} visible 1 loaded true", i + 1);
        assert!(text.contains(&line), "missing `{line}` in:\n{text}");
    }
    assert!(text.contains("errors 0"), "page errors: {text}");
    // The page carries the table, the plots with error bars, the profile bars and the command line.
    for part in ["<table>", "class=\"error-bar\"", "class=\"bar\"", "compare", "Convergence slopes", "FLIP"] {
        assert!(html.contains(part), "report.html lacks {part}");
    }
    // A screenshot, kept as a test artifact.
    let shot = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/target/test-artifacts/report.png"));
    std::fs::create_dir_all(shot.parent().unwrap()).unwrap();
    std::fs::remove_file(&shot).ok();
    let (_, log) = chromium(&url, &[&format!("--screenshot={}", shot.display()), "--window-size=1280,1600"]);
    let png = std::fs::read(&shot).unwrap_or_else(|e| panic!("no screenshot {}: {e}\n{log}", shot.display()));
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000, "screenshot of {} bytes", png.len());
}

/// Issue 31: the report is supplementary material. Its HTML carries insets of the regions where
/// the variants differ most (one crop per variant and the reference, per region, with the
/// regions outlined on an overview), each variant's mean squared error image over its runs, and a
/// flip-book over every run (one frame per variant and run, not run 1 only). Before, the page had
/// none of these.
#[test]
fn report_html_has_crops_by_error_a_mean_error_image_and_a_frame_per_run() {
    let d = common::tmpdir("report-figures");
    let page = compare_report(&d);
    let html = std::fs::read_to_string(&page).unwrap();
    let (variants, runs) = (["independent", "stratified", "halton"], 2);
    // Crops: regions A.. each with the reference and every variant, chosen by error.
    let crops = html.matches("<img class=\"crop\"").count();
    assert!(crops > variants.len(), "no crops in report.html ({crops} crop images)");
    assert_eq!(crops % (variants.len() + 1), 0, "each region shows the reference and every variant: {crops}");
    assert!(html.contains("class=\"crop-overview\""), "no overview with the crops outlined");
    for v in variants {
        assert!(html.contains(&format!("data-crop-variant=\"{v}\"")), "no crop of {v}");
        let mean = format!("<img class=\"mean-error\" data-variant=\"{v}\"");
        assert_eq!(html.matches(&mean).count(), 1, "one mean error image of {v}");
        // One flip-book frame per run of the variant, at the last step.
        for r in 1..=runs {
            let frame = format!("data-label=\"{v} run {r}\" data-kind=\"run\"");
            assert_eq!(html.matches(&frame).count(), 1, "flip-book frame `{frame}`");
        }
    }
    assert_eq!(html.matches("data-kind=\"run\"").count(), variants.len() * runs, "one frame per run");
}

/// Issue 31: the report fits a 1200-px window: in headless Chromium at 1200 px the page's scroll
/// width is its client width (no horizontal overflow; the self-test writes both). Before, the
/// provenance and results tables overflowed (scroll width 1979 px at 1200).
#[test]
fn report_html_fits_1200_px_without_horizontal_overflow() {
    let d = common::tmpdir("report-width");
    let page = compare_report(&d);
    let url = format!("file://{}#selftest", page.display());
    let (dom, log) = chromium(&url, &["--dump-dom", "--window-size=1200,1600"]);
    let start = dom.find("<pre id=\"selftest\">").unwrap_or_else(|| panic!("no self-test output in the DOM:\n{log}"));
    let line = dom[start..]
        .lines()
        .find(|l| l.starts_with("layout scroll width"))
        .unwrap_or_else(|| panic!("no layout line in the self-test output:\n{log}"));
    let nums: Vec<u32> = line.split_whitespace().filter_map(|w| w.trim_end_matches(',').parse().ok()).collect();
    let (scroll, client) = (nums[0], nums[1]);
    assert!((1100..=1200).contains(&client), "{line}");
    assert!(scroll <= client, "the page overflows 1200 px: {line}");
}

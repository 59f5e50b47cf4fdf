//! Mitsuba 3's render-regression suite (`../shared/corpora/mitsuba-tests`) on strata: every scene
//! of `strata::lab::mitsuba::CORPUS` is rendered at Mitsuba's budget (2,000,000 samples per
//! image) and z-tested against Mitsuba's reference and variance images as Mitsuba's own
//! `test_renders.py` does; or, where strata lacks a feature, refused with an error naming it. No
//! scene is skipped: a corpus scene missing from the table, or the corpus missing, fails.

use strata::lab::mitsuba::{corpus_dir, run_scene, Expect, CORPUS};

#[test]
fn every_corpus_scene_passes_or_is_refused_as_listed() {
    let dir = corpus_dir().join("tests/scenes");
    assert!(dir.is_dir(), "{}: the Mitsuba corpus is missing (it comes with ../shared)", dir.display());
    // The table lists every scene of the corpus.
    let mut found = Vec::new();
    for group in std::fs::read_dir(&dir).unwrap() {
        let group = group.unwrap().path();
        for f in std::fs::read_dir(&group).into_iter().flatten() {
            let f = f.unwrap().path();
            if f.extension().is_some_and(|e| e == "xml") {
                found.push(f.strip_prefix(&dir).unwrap().to_string_lossy().into_owned());
            }
        }
    }
    found.sort();
    let mut listed: Vec<String> = CORPUS.iter().map(|(s, _)| s.to_string()).collect();
    listed.sort();
    assert_eq!(found, listed, "the table in lab/mitsuba.rs must list every corpus scene");
    let mut failures = Vec::new();
    for &(rel, expect) in CORPUS {
        let result = run_scene(&dir.join(rel), 0);
        match (expect, &result) {
            (Expect::Pass, Ok(o)) if o.test.passed => {}
            (Expect::Fails(_), Ok(o)) if !o.test.passed => {}
            (Expect::Refused(what), Err(e)) if e.to_string().contains(what) => {}
            _ => failures.push(format!("{rel}: expected {expect:?}, got {result:?}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

//! Issue 29: hostile Mitsuba XML gets a clear `file:line` error through the CLI, at once: entity
//! expansion (a DTD), deep nesting, include loops and missing includes, huge numbers, unknown
//! plugins (naming the supported ones), undefined `$parameters`; `-D` fills a parameter.

use super::run::{scratch, strata};
use std::fs;

const HEAD: &str = "<scene version=\"3.0.0\">\n";

#[test]
fn hostile_xml_is_refused_with_file_and_line() {
    let dir = scratch("xml");
    let cases: &[(&str, String, &str)] = &[
        (
            "bomb.xml",
            "<?xml version=\"1.0\"?>\n<!DOCTYPE s [<!ENTITY a \"aaaaaaaaaa\"><!ENTITY b \"&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;\">]>\n<scene version=\"3.0.0\">&b;</scene>\n".into(),
            "DTD",
        ),
        ("deep.xml", format!("{HEAD}{}{}</scene>\n", "<shape type=\"obj\">".repeat(100), "</shape>".repeat(100)), "nest deeper"),
        ("loop.xml", format!("{HEAD}<include filename=\"loop.xml\"/>\n</scene>\n"), "loop.xml:2: include loop"),
        ("missing.xml", format!("{HEAD}<include filename=\"nothere.xml\"/>\n</scene>\n"), "missing.xml:2: cannot include"),
        (
            "huge.xml",
            format!("{HEAD}<shape type=\"sphere\">\n<float name=\"radius\" value=\"1e999\"/>\n</shape>\n</scene>\n"),
            "huge.xml:3: 1e999 is out of range",
        ),
        (
            "unknown.xml",
            format!("{HEAD}<shape type=\"teapot\"/>\n</scene>\n"),
            "unknown.xml:2: unknown shape type \"teapot\" (supported: obj, ply",
        ),
        (
            "ellipsoid_light.xml",
            format!("{HEAD}<shape type=\"sphere\">\n<transform name=\"to_world\"><scale x=\"1\" y=\"2\" z=\"1\"/></transform>\n<emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter>\n</shape>\n</scene>\n"),
            "ellipsoid_light.xml:4: an area emitter on a sphere needs a `to_world` without non-uniform scale",
        ),
        (
            "param.xml",
            format!("{HEAD}<shape type=\"sphere\">\n<float name=\"radius\" value=\"$r\"/>\n</shape>\n</scene>\n"),
            "param.xml:3: undefined parameter $r",
        ),
    ];
    for (name, text, want) in cases {
        fs::write(dir.join(name), text).unwrap();
        let r = strata(&dir, &["render", name, "-o", "out", "-q"], 30);
        assert_eq!(r.code, Some(1), "{name}: {}", r.err);
        assert!(r.err.contains(want), "{name}: wanted {want:?} in {}", r.err);
        assert!(!r.err.contains("panicked"), "{name}: {}", r.err);
    }
    // -D gives the parameter: the error moves on to the missing sensor.
    let r = strata(&dir, &["render", "param.xml", "-D", "r=2", "-o", "out", "-q"], 30);
    assert!(r.code == Some(1) && r.err.contains("no <sensor>"), "{}", r.err);
}

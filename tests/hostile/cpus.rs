//! Issue 25, findings 1 and 7: the same pixels on every node, or refused. Embree runs AVX-512 on
//! a CPU with it (issue 33: exactly specified reciprocals, the same hits on every AVX-512 CPU),
//! else AVX2; a shard that asks for AVX-512, Embree's sphere points or another build does not
//! merge or resume with the others; instruction sets below AVX2 and unknown Embree keys are
//! refused (`isa=sse2` crashed in `rtcOccluded8` on `hw4/dragon.test`). Needs ../shared/cse168.

use super::run::{exr, meta, scratch, strata, strata_env};
use crate::common::corpus_required;

const FLAGS: [&str; 6] = ["--size", "64x48", "--spp", "16", "--threads", "2"];

fn args<'a>(scene: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec!["render", scene];
    a.extend(FLAGS);
    a.extend(extra);
    a.push("-q");
    a
}

/// The default render equals `isa=avx512` bit for bit on a CPU with AVX-512 and `isa=avx2`
/// without (the two kernels differ in 907 of 3072 values here); the EXR records the instruction
/// set and the build.
#[test]
fn default_render_is_the_best_isa_render() {
    let dir = scratch("isa-default");
    let scene = corpus_required().join("hw4/cornellBRDF.test");
    let s = scene.to_str().unwrap();
    let best = if strata::accel::cpu_has_avx512() { "avx512" } else { "avx2" };
    let r = strata(&dir, &args(s, &["-o", "default"]), 120);
    assert_eq!(r.code, Some(0), "{}", r.err);
    let pin = format!("isa={best}");
    let r = strata_env(&dir, &args(s, &["-o", "pinned"]), &[("STRATA_EMBREE_CONFIG", &pin)], 120);
    assert_eq!(r.code, Some(0), "{}", r.err);
    let (a, ma) = exr(&dir.join("default.exr"));
    let (b, _) = exr(&dir.join("pinned.exr"));
    assert!(a == b, "the default render differs from the {pin} one");
    assert_eq!(std::fs::read(dir.join("default.png")).unwrap(), std::fs::read(dir.join("pinned.png")).unwrap());
    assert_eq!(meta(&ma, "strata.embree_isa"), best);
    let approx = if best == "avx512" { "exact".to_string() } else { strata::accel::approx_id("avx2") };
    assert_eq!(meta(&ma, "strata.embree_approx"), approx);
    assert_eq!(meta(&ma, "strata.build"), strata::checkpoint::identity::BUILD);
    assert!(!meta(&ma, "strata.commit").is_empty() && !meta(&ma, "strata.embree_version").is_empty());
}

/// A shard rendered with `isa=avx2` on an AVX-512 CPU (or `STRATA_SPHERES=embree`) is refused
/// by `merge` and by `--resume`, naming both sides; the same shard rendered by default merges
/// bit-identically.
#[test]
fn shards_of_another_isa_or_sphere_intersector_are_refused() {
    let dir = scratch("isa-mix");
    let scene = corpus_required().join("hw4/cornellBRDF.test");
    let s = scene.to_str().unwrap();
    let part = |name: &str, range: &str, env: &[(&str, &str)]| {
        let r = strata_env(&dir, &args(s, &["--samples", range, "-o", name]), env, 120);
        assert_eq!(r.code, Some(0), "{name}: {}", r.err);
    };
    part("p0", "0..8", &[]);
    part("p1", "8..16", &[]);
    let have_avx512 = strata::accel::cpu_has_avx512();
    if have_avx512 {
        let isa = [("STRATA_EMBREE_CONFIG", "isa=avx2")];
        part("p1x", "8..16", &isa);
        let r = strata(&dir, &["merge", "p0.ckpt", "p1x.ckpt", "-o", "mixed", "-q"], 60);
        assert_eq!(r.code, Some(1), "{}", r.err);
        assert!(r.err.contains(r#"embree_isa "avx2" (p0.ckpt: "avx512")"#), "{}", r.err);
        assert!(!dir.join("mixed.exr").exists());
        // Resuming a default (AVX-512) checkpoint under AVX2 is refused too.
        let r = strata_env(&dir, &args(s, &["--resume", "p0.ckpt", "--samples", "0..16", "-o", "r"]), &isa, 60);
        assert_eq!(r.code, Some(1), "{}", r.err);
        assert!(r.err.contains("cannot resume") && r.err.contains("embree_isa"), "{}", r.err);
    } else {
        let isa = [("STRATA_EMBREE_CONFIG", "isa=avx512")];
        let r = strata_env(&dir, &args(s, &["-o", "x"]), &isa, 60);
        assert!(r.code == Some(1) && r.err.contains("no AVX-512"), "{}", r.err);
    }
    let r = strata(&dir, &["merge", "p0.ckpt", "p1.ckpt", "-o", "merged", "-q"], 60);
    assert_eq!(r.code, Some(0), "{}", r.err);
    let r = strata(&dir, &args(s, &["-o", "whole"]), 120);
    assert_eq!(r.code, Some(0), "{}", r.err);
    assert!(exr(&dir.join("merged.exr")).0 == exr(&dir.join("whole.exr")).0, "merged != one render");
    // Embree's sphere points (a comparison switch) enter the identity: the built-in scene has spheres.
    let builtin = |name: &str, range: &str, env: &[(&str, &str)]| {
        let a = ["render", "--size", "32x32", "--spp", "4", "--samples", range, "-o", name, "-q"];
        let r = strata_env(&dir, &a, env, 60);
        assert_eq!(r.code, Some(0), "{name}: {}", r.err);
    };
    builtin("b0", "0..2", &[]);
    builtin("b1", "2..4", &[("STRATA_SPHERES", "embree")]);
    let r = strata(&dir, &["merge", "b0.ckpt", "b1.ckpt", "-o", "bm", "-q"], 60);
    assert!(r.code == Some(1) && r.err.contains(r#"spheres "embree" (b0.ckpt: "strata")"#), "{}", r.err);
}

/// A part written by another build is refused by `merge` (naming both builds and the flag) and
/// merged with `--allow-other-build`, the EXR listing both builds.
#[test]
fn parts_of_another_build_need_allow_other_build() {
    let dir = scratch("build-mix");
    for (name, range) in [("q0", "0..2"), ("q1", "2..4")] {
        let a = ["render", "--size", "16x16", "--spp", "4", "--samples", range, "-o", name, "-q"];
        let r = strata(&dir, &a, 60);
        assert_eq!(r.code, Some(0), "{}", r.err);
    }
    let q1 = dir.join("q1.ckpt");
    let (mut h, f) = strata::checkpoint::read(&q1).unwrap();
    h.strata_build = "0123456789abcdef".into();
    strata::checkpoint::write(&q1, &h, &f).unwrap();
    let r = strata(&dir, &["merge", "q0.ckpt", "q1.ckpt", "-o", "m", "-q"], 60);
    assert_eq!(r.code, Some(1), "{}", r.err);
    assert!(r.err.contains("build 0123456789abcdef") && r.err.contains("--allow-other-build"), "{}", r.err);
    assert!(r.err.contains(strata::checkpoint::identity::BUILD), "{}", r.err);
    let r = strata(&dir, &["merge", "q0.ckpt", "q1.ckpt", "-o", "m", "-q", "--allow-other-build"], 60);
    assert_eq!(r.code, Some(0), "{}", r.err);
    let (_, m) = exr(&dir.join("m.exr"));
    assert_eq!(meta(&m, "strata.build"), format!("{} + 0123456789abcdef", strata::checkpoint::identity::BUILD));
}

/// Instruction sets below AVX2 and unknown keys are refused before rendering, with the reason
/// (before, `isa=sse2` with the high-quality BVH of `hw4/dragon.test` crashed with SIGSEGV).
#[test]
fn embree_configs_below_avx2_or_unknown_are_refused() {
    let dir = scratch("isa-low");
    let scene = corpus_required().join("hw4/dragon.test");
    let s = scene.to_str().unwrap();
    for (cfg, says) in [
        ("isa=sse2", "below AVX2"),
        ("isa=sse4.2", "below AVX2"),
        ("threads=2,tri_accel=bvh4.triangle4", "unknown key `tri_accel`"),
        // Issue 32, finding 1: Embree splits on newlines too (before, this ran SSE2 and the EXR
        // said avx2).
        ("threads=2\nisa=sse2", "below AVX2"),
    ] {
        let a = ["render", s, "--size", "32x32", "--spp", "1", "--threads", "2", "-o", "d", "-q"];
        let r = strata_env(&dir, &a, &[("STRATA_EMBREE_CONFIG", cfg)], 120);
        assert_eq!(r.code, Some(1), "{cfg}: exit {:?}: {}", r.code, r.err);
        assert!(r.err.contains("STRATA_EMBREE_CONFIG") && r.err.contains(says), "{cfg}: {}", r.err);
        assert!(!dir.join("d.png").exists());
    }
}

/// `STRATA_GATHER` (how Halton's digit tables are looked up: AVX2's hardware gather, the default
/// on AMD, or scalar loads) changes the speed only: `hardware`, `scalar` and `auto` render the
/// same Halton image bit for bit on this CPU; any other value is refused before rendering,
/// naming the variable and the values it takes.
#[test]
fn the_gather_switch_keeps_the_pixels_and_refuses_unknown_values() {
    let dir = scratch("gather");
    let scene = corpus_required().join("hw2/sphere.test");
    let s = scene.to_str().unwrap();
    let mut images = Vec::new();
    for mode in ["hardware", "scalar", "auto"] {
        let a = args(s, &["--sampler", "halton", "--light-selection", "uniform", "-o", mode]);
        let r = strata_env(&dir, &a, &[("STRATA_GATHER", mode)], 120);
        assert_eq!(r.code, Some(0), "{mode}: {}", r.err);
        images.push(exr(&dir.join(format!("{mode}.exr"))).0);
    }
    assert!(images[0] == images[1] && images[1] == images[2], "the gather switch changed pixels");
    let a = args(s, &["--sampler", "halton", "-o", "bad"]);
    let r = strata_env(&dir, &a, &[("STRATA_GATHER", "fast")], 60);
    assert_eq!(r.code, Some(1), "{}", r.err);
    assert!(r.err.contains(r#"STRATA_GATHER="fast": expected `auto`, `hardware` or `scalar`"#), "{}", r.err);
    assert!(!dir.join("bad.exr").exists());
}

//! The documentation cannot go stale: `docs/cli.md` is the output of `strata help-markdown` (the
//! command line's own definitions), every flag of every subcommand's `--help` is in it, and every
//! `strata` command in the README's code blocks parses (and passes the subcommand's refusals).

use crate::common;

use common::{strata, tmpdir};
use std::path::Path;

fn repo_file(rel: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn stdout_of(args: &[&str]) -> String {
    let r = strata().args(args).output().unwrap();
    assert!(r.status.success(), "{args:?}: {}", String::from_utf8_lossy(&r.stderr));
    String::from_utf8(r.stdout).unwrap()
}

#[test]
fn the_cli_reference_is_fresh() {
    let want = stdout_of(&["help-markdown"]);
    let have = repo_file("docs/cli.md");
    assert!(
        have == want,
        "docs/cli.md is stale: regenerate it with `cargo run --release -- help-markdown > docs/cli.md`"
    );
}

/// The visible subcommands, from `strata --help`.
fn subcommands() -> Vec<String> {
    let help = stdout_of(&["--help"]);
    let list = &help[help.find("Commands:").unwrap()..help.find("Options:").unwrap()];
    list.lines()
        .skip(1)
        .filter_map(|l| l.split_whitespace().next())
        .filter(|n| *n != "help")
        .map(String::from)
        .collect()
}

#[test]
fn every_flag_in_help_is_in_the_cli_reference() {
    let reference = repo_file("docs/cli.md");
    let subs = subcommands();
    assert!(subs.len() >= 8 && subs.iter().any(|s| s == "render"), "{subs:?}");
    for sub in &subs {
        let help = stdout_of(&[sub, "--help"]);
        let section = reference
            .split_once(&format!("## strata {sub}\n"))
            .unwrap_or_else(|| panic!("docs/cli.md has no section for {sub}"))
            .1;
        let section = section.split("\n## strata ").next().unwrap();
        let flags: Vec<&str> = help
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
            .filter(|w| w.starts_with("--") && w.len() > 2)
            .collect();
        assert!(!flags.is_empty(), "{sub}");
        for flag in flags {
            assert!(section.contains(flag), "{sub}: {flag} is in --help but not in docs/cli.md");
        }
    }
}

/// The `strata` command lines of a Markdown text: the lines of its fenced code blocks
/// (continuation lines joined) and its inline code spans that start with `strata `; a leading
/// `$ `, environment assignments and `cargo run --release --` or a path to the binary dropped, cut
/// at a comment, a pipe, `&&`, `;` or a redirection.
fn commands(md: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut in_block = false;
    let mut line = String::new();
    for raw in md.lines() {
        if raw.trim_start().starts_with("```") {
            in_block = !in_block;
            continue;
        }
        if !in_block {
            // Inline spans: the odd pieces between backticks.
            for span in raw.split('`').skip(1).step_by(2).filter(|s| s.starts_with("strata ")) {
                if let Some(words) = shlex::split(span) {
                    out.push(words.into_iter().skip(1).collect());
                }
            }
            continue;
        }
        line.push_str(raw.trim_end().trim_end_matches('\\'));
        if raw.trim_end().ends_with('\\') {
            line.push(' ');
            continue;
        }
        let text = std::mem::take(&mut line);
        let Some(words) = shlex::split(text.trim().trim_start_matches("$ ")) else { continue };
        let mut words = words.into_iter().skip_while(|w| w.contains('=') && !w.starts_with('-')).peekable();
        match words.peek().map(String::as_str) {
            Some("strata" | "target/release/strata" | "./target/release/strata") => {
                words.next();
            }
            Some("cargo") => {
                let w: Vec<String> = words.by_ref().take(4).collect();
                if w != ["cargo", "run", "--release", "--"] {
                    continue;
                }
            }
            _ => continue,
        }
        let args: Vec<String> = words
            .take_while(|w| !w.starts_with('#') && !["|", "&&", ";", ">", "2>", "&"].contains(&w.as_str()))
            .collect();
        out.push(args);
    }
    out
}

#[test]
fn every_command_in_the_readme_parses() {
    let cmds = commands(&repo_file("README.md"));
    assert!(cmds.len() >= 5, "the README shows strata commands: {cmds:?}");
    // In a scratch directory, where the point-set exports the README makes (`pointset ...
    // --export FILE`) are run for real, so the commands that read them (`--sampler file:FILE`)
    // are checked against a real file.
    let dir = tmpdir("readme-commands");
    for args in cmds {
        if args.first().map(String::as_str) == Some("pointset") && args.iter().any(|a| a == "--export") {
            let r = strata().current_dir(&dir).args(&args).output().unwrap();
            assert!(r.status.success(), "README: `strata {}`: {}", args.join(" "), String::from_utf8_lossy(&r.stderr));
        }
        let r = strata().current_dir(&dir).arg("parse-check").args(&args).output().unwrap();
        assert!(r.status.success(), "README: `strata {}`: {}", args.join(" "), String::from_utf8_lossy(&r.stderr));
    }
}

#[test]
fn the_command_extractor_finds_commands_and_a_bad_one_fails_to_parse() {
    let md = "text `strata merge a.ckpt -o m` and `strata: note`\n```sh\n$ strata render a.test \\\n  --spp 4 -o out # comment\nls\nX=1 target/release/strata rays --json | jq .\n```\n";
    let cmds = commands(md);
    let want = [
        vec!["merge", "a.ckpt", "-o", "m"],
        vec!["render", "a.test", "--spp", "4", "-o", "out"],
        vec!["rays", "--json"],
    ];
    assert_eq!(cmds, want);
    let r = strata().args(["parse-check", "render", "--sppp", "4"]).output().unwrap();
    assert_eq!(r.status.code(), Some(2));
    let r = strata().args(["parse-check", "reference", "scene.test"]).output().unwrap();
    assert_eq!(r.status.code(), Some(2), "reference without --spp is refused by parse-check too");
}

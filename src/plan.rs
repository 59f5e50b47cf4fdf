//! The output plan of every subcommand: which of its flags name files it reads and which name
//! files it writes ([`declared`], one table for all subcommands), turned into a [`files::Plan`]
//! from a parsed command line ([`plan_of`]) and checked by [`files::Plan::check`] before any work
//! (`main.rs` does it for every subcommand; `render`/`reference` check again once the scene has
//! named its output stem and its MTL libraries, `session/checks.rs`).
//!
//! A flag whose value is a path must be declared here: `tests::every_path_flag_is_declared` walks
//! the clap grammar and fails on one that is not, and the hostile-input suite generates one case
//! per declared output (that output naming an input of the same subcommand), so a new flag is
//! covered by both.

use crate::cli::Cli;
use crate::files::{self, Plan, Role};
use clap::CommandFactory;
use std::path::{Path, PathBuf};

/// How a declared flag's value names files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Names {
    /// the value is the file
    File,
    /// the value is a stem: it names `VALUE.ext` for each extension (`-o out` or `-o out.exr`)
    Stem(&'static [&'static str]),
    /// the value is a directory the subcommand writes these files in (created if absent)
    Dir(&'static [&'static str]),
    /// the value is a file, and the file with this extension beside it is written too (gen-mesh's
    /// MTL)
    WithBeside(&'static str),
    /// a sampler: `file:PATH?options` reads PATH, a registry name reads nothing
    SamplerSpec,
    /// a point-set file, or a registry sampler name when no such file exists
    FileOrName,
}

/// One flag (clap argument id) of one subcommand that names a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decl {
    /// the subcommand
    pub subcommand: &'static str,
    /// the clap argument id
    pub id: &'static str,
    /// the flag as typed (`--json`, `-o`), or the positional's name
    pub flag: &'static str,
    /// read or written
    pub role: Role,
    /// how its value names files
    pub names: Names,
}

const fn d(subcommand: &'static str, id: &'static str, flag: &'static str, role: Role, names: Names) -> Decl {
    Decl { subcommand, id, flag, role, names }
}

/// The image files of an output stem.
pub const IMAGES: &[&str] = &["exr", "png"];
/// What `compare -o DIR` writes.
pub const COMPARE_FILES: &[&str] =
    &["report.html", "rows.csv", "rows.json", "runs.csv", "runs.json", "table.md", "error.svg"];
/// What `experiments --out DIR` writes (besides one SVG per experiment).
pub const EXPERIMENT_FILES: &[&str] = &["report.html", "results.md", "results.json"];
/// What `pointset --out DIR` writes.
pub const POINTSET_FILES: &[&str] =
    &["spectrum.csv", "spectrum.svg", "integration.csv", "integration.svg", "pointset.json"];

/// The inputs every render-flag subcommand reads: the scene and the point-set files of samplers.
fn render_inputs(sub: &'static str) -> [Decl; 4] {
    use {Names::*, Role::Input};
    [
        d(sub, "scene", "the scene file", Input, File),
        d(sub, "sampler", "--sampler", Input, SamplerSpec),
        d(sub, "pixel_sampler", "--pixel-sampler", Input, SamplerSpec),
        d(sub, "light_sampler", "--light-sampler", Input, SamplerSpec),
    ]
}

/// Every subcommand's file flags (render flags that `rays` and `profile` refuse are not listed
/// for them: the command line is refused before any file is touched).
pub fn declared() -> Vec<Decl> {
    use {Names::*, Role::*};
    let mut v = Vec::new();
    for sub in ["render", "reference"] {
        v.extend(render_inputs(sub));
        v.extend([
            d(sub, "resume", "--resume", Input, File),
            d(sub, "out", "-o", Output, Stem(IMAGES)),
            d(sub, "stats", "--stats", Output, File),
            d(sub, "json", "--json", Output, File),
            d(sub, "profile", "--profile", Output, File),
            d(sub, "checkpoint", "--checkpoint", Output, File),
        ]);
    }
    v.extend(render_inputs("rays"));
    v.push(d("rays", "json", "--json", Output, File));
    v.extend(render_inputs("profile"));
    v.extend([
        d("profile", "json_file", "--json", Output, File),
        d("profile", "svg_file", "--svg", Output, File),
        d("profile", "profile", "--profile", Output, File),
    ]);
    v.extend([
        d("compare", "scene", "the scene file", Input, File),
        d("compare", "reference", "--reference", Input, File),
        d("compare", "out", "-o", Output, Dir(COMPARE_FILES)),
        d("compare", "json", "--json", Output, File),
        d("compare", "profile", "--profile", Output, File),
        d("compare", "profile_svg", "--profile-svg", Output, File),
        d("merge", "parts", "a part", Input, File),
        d("merge", "out", "-o", Output, Stem(IMAGES)),
        d("gen-mesh", "out", "the OBJ", Output, WithBeside("mtl")),
        d("experiments", "corpus", "--corpus", Input, File),
        d("experiments", "out", "--out", Output, Dir(EXPERIMENT_FILES)),
        d("pointset", "target", "the point set", Input, FileOrName),
        d("pointset", "out", "--out", Output, Dir(POINTSET_FILES)),
        d("pointset", "export", "--export", Output, File),
    ]);
    v
}

/// The files one declared flag's value names.
pub fn files_named(names: Names, value: &Path) -> Vec<PathBuf> {
    let s = value.to_string_lossy();
    match names {
        Names::File => vec![value.to_path_buf()],
        Names::Stem(exts) => {
            let stem = crate::film::stem_of(value);
            exts.iter().map(|e| crate::film::with_ext(&stem, e)).collect()
        }
        Names::Dir(files) => files.iter().map(|f| value.join(f)).collect(),
        Names::WithBeside(ext) => vec![value.to_path_buf(), value.with_extension(ext)],
        Names::SamplerSpec => match s.strip_prefix("file:") {
            Some(rest) => vec![PathBuf::from(rest.split('?').next().unwrap_or(rest))],
            None => vec![],
        },
        Names::FileOrName => {
            if value.exists() {
                vec![value.to_path_buf()]
            } else {
                vec![]
            }
        }
    }
}

/// The plan of a parsed command line (the top-level matches of [`Cli`]): every declared flag of
/// its subcommand that was given, as inputs and outputs (`rays --json` without a file, `-`,
/// prints and names none).
pub fn plan_of(matches: &clap::ArgMatches) -> Plan {
    let mut plan = Plan::new();
    let Some((sub, m)) = matches.subcommand() else { return plan };
    for decl in declared().into_iter().filter(|x| x.subcommand == sub) {
        let Ok(Some(values)) = m.try_get_raw(decl.id) else { continue };
        for value in values {
            if value == "-" && decl.subcommand == "rays" {
                continue;
            }
            for f in files_named(decl.names, Path::new(value)) {
                match decl.role {
                    Role::Input => plan.input(decl.flag, f),
                    Role::Output => match decl.names {
                        Names::Stem(_) | Names::Dir(_) | Names::WithBeside(_) => {
                            let name = f.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                            plan.output(format!("{} ({name})", decl.flag), f)
                        }
                        _ => plan.output(decl.flag, f),
                    },
                };
            }
        }
    }
    plan
}

/// Parses `argv` (without the program name) with the binary's grammar and returns its plan.
pub fn plan_for<I: IntoIterator<Item = T>, T: Into<std::ffi::OsString> + Clone>(argv: I) -> Result<Plan, clap::Error> {
    let m = Cli::command()
        .try_get_matches_from(std::iter::once("strata".into()).chain(argv.into_iter().map(Into::into)))?;
    Ok(plan_of(&m))
}

/// Checks the plan of a parsed command line ([`files::Plan::check`]).
pub fn check(matches: &clap::ArgMatches) -> Result<(), files::PlanError> {
    plan_of(matches).check()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every argument of every subcommand whose value is a path (a `PathBuf` parser), and the
    /// sampler and point-set flags, is declared: a new file flag cannot skip the plan.
    #[test]
    fn every_path_flag_is_declared() {
        let decls = declared();
        let path_type = clap::builder::ValueParser::path_buf().type_id();
        for sub in Cli::command().get_subcommands() {
            for arg in sub.get_arguments() {
                let is_path = arg.get_value_parser().type_id() == path_type;
                let id = arg.get_id().as_str();
                let named = is_path || id.ends_with("sampler") || (sub.get_name() == "pointset" && id == "target");
                let refused = ["rays", "profile"].contains(&sub.get_name())
                    && ["out", "stats", "checkpoint", "resume"].contains(&id)
                    || sub.get_name() == "rays" && id == "profile";
                if named && !refused {
                    assert!(
                        decls.iter().any(|x| x.subcommand == sub.get_name() && x.id == id),
                        "`strata {} {id}` names a file but is not declared in plan::declared()",
                        sub.get_name()
                    );
                }
            }
        }
    }

    #[test]
    fn plans_name_the_files_each_flag_writes() {
        let p = plan_for(["merge", "p0.ckpt", "x.exr", "-o", "x"]).unwrap();
        let outs: Vec<_> = p.outputs().map(|e| e.path.display().to_string()).collect();
        assert_eq!(outs, ["x.exr", "x.png"]);
        assert_eq!(p.inputs().count(), 2);
        let p = plan_for(["gen-mesh", "m.obj", "--triangles", "10"]).unwrap();
        let outs: Vec<_> = p.outputs().map(|e| e.path.display().to_string()).collect();
        assert_eq!(outs, ["m.obj", "m.mtl"]);
        let p = plan_for(["rays", "--json"]).unwrap();
        assert_eq!(p.entries.len(), 0, "`--json` alone prints");
    }
}

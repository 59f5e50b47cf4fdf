//! The output plan: what a subcommand reads and writes, declared once and checked before any work.
//!
//! Every subcommand (render, reference, merge, compare, profile, rays, gen-mesh, pointset,
//! experiments) builds a [`Plan`] from its command line: its inputs and its outputs, each with the
//! flag or role that names it. [`Plan::check`] then refuses, before a scene is read or a sample
//! traced:
//!
//! - an output that is also an input (the same file: same device and inode for an existing file,
//!   else the same canonical directory and name), or the same file as another output;
//! - an output that is not a regular file or a new name (a link, directory, device, FIFO);
//! - an output whose directory does not exist or cannot be written (a probe file is created and
//!   removed);
//! - an output name too long to leave room for its temporary name (name + [`TEMP_NAME_EXTRA`]
//!   bytes must fit in [`NAME_MAX`]), which would otherwise fail after the work is done.

use super::write::{check_target, dir_of, NAME_MAX, TEMP_NAME_EXTRA};
use std::path::{Path, PathBuf};

/// Whether a planned path is read or written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// read by the subcommand
    Input,
    /// written by the subcommand
    Output,
}

/// Why a plan is refused.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// An output path that cannot be used, with the reason.
    #[error("{}: {why}", path.display())]
    Bad {
        /// the output
        path: PathBuf,
        /// what is wrong with it
        why: String,
    },
    /// An output directory that cannot be written.
    #[error("{}: cannot write there ({source})", dir.display())]
    NotWritable {
        /// the directory
        dir: PathBuf,
        /// the error of the probe file
        source: std::io::Error,
    },
}

/// One planned path: its role, what names it (a flag such as `--json`, or a phrase such as
/// `the scene file`) and the path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    /// read or written
    pub role: Role,
    /// the flag or phrase naming it in messages
    pub label: String,
    /// the path as given
    pub path: PathBuf,
}

/// The inputs and outputs of one subcommand.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Plan {
    /// every planned path, in declaration order
    pub entries: Vec<Entry>,
}

impl Plan {
    /// An empty plan.
    pub fn new() -> Self {
        Self::default()
    }

    /// Declares `path`, named by `label`, as read.
    pub fn input(&mut self, label: impl Into<String>, path: impl Into<PathBuf>) -> &mut Self {
        self.entries.push(Entry { role: Role::Input, label: label.into(), path: path.into() });
        self
    }

    /// Declares `path`, named by `label`, as written.
    pub fn output(&mut self, label: impl Into<String>, path: impl Into<PathBuf>) -> &mut Self {
        self.entries.push(Entry { role: Role::Output, label: label.into(), path: path.into() });
        self
    }

    /// Declares the files `names` that a subcommand writes in directory `dir` (named by `label`),
    /// as outputs.
    pub fn outputs_in(&mut self, label: &str, dir: &Path, names: &[&str]) -> &mut Self {
        for n in names {
            self.output(format!("{label} ({n})"), dir.join(n));
        }
        self
    }

    /// The planned outputs.
    pub fn outputs(&self) -> impl Iterator<Item = &Entry> {
        self.entries.iter().filter(|e| e.role == Role::Output)
    }

    /// The planned inputs.
    pub fn inputs(&self) -> impl Iterator<Item = &Entry> {
        self.entries.iter().filter(|e| e.role == Role::Input)
    }

    /// Checks the plan (see the module doc); the first problem found is the error.
    pub fn check(&self) -> Result<(), PlanError> {
        for o in self.outputs() {
            let bad = |why: String| PlanError::Bad { path: o.path.clone(), why };
            let Some(name) = o.path.file_name() else {
                return Err(bad(format!("{} names a directory, not a file", o.label)));
            };
            let len = name.len();
            if len + TEMP_NAME_EXTRA > NAME_MAX {
                return Err(bad(format!(
                    "the file name is {len} bytes; its temporary name needs {} more and a name has at most {NAME_MAX}: shorten it",
                    TEMP_NAME_EXTRA
                )));
            }
            check_target(&o.path).map_err(|e| bad(e.to_string()))?;
            let dir = dir_of(&o.path);
            // A directory the subcommand creates (compare -o, experiments --out) has no file yet.
            if dir.exists() || !self.creates_dir(&o.path) {
                check_writable(&dir)?;
            }
        }
        let keys: Vec<Option<FileKey>> = self.entries.iter().map(|e| FileKey::of(&e.path)).collect();
        for (i, a) in self.entries.iter().enumerate() {
            for (j, b) in self.entries.iter().enumerate().skip(i + 1) {
                if a.role == Role::Input && b.role == Role::Input {
                    continue;
                }
                if keys[i].is_some() && keys[i] == keys[j] {
                    let (out, other) = if a.role == Role::Output { (a, b) } else { (b, a) };
                    let other_path =
                        if other.path == out.path { String::new() } else { format!(" ({})", other.path.display()) };
                    return Err(PlanError::Bad {
                        path: out.path.clone(),
                        why: format!(
                            "{} and {}{other_path} are the same file: one would overwrite the other",
                            out.label, other.label
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Whether `path` lies in a directory this plan's subcommand creates: outputs declared with
    /// [`Plan::outputs_in`] (labels with a parenthesised file name).
    fn creates_dir(&self, path: &Path) -> bool {
        self.outputs().any(|e| e.path == path && e.label.ends_with(')'))
    }
}

/// What makes two paths one file: the device and inode of an existing file, else the canonical
/// directory and the name (or the path as given when its directory does not exist yet).
#[derive(PartialEq, Eq)]
enum FileKey {
    Inode(u64, u64),
    New(PathBuf),
}

impl FileKey {
    fn of(p: &Path) -> Option<Self> {
        use std::os::unix::fs::MetadataExt;
        if let Ok(m) = std::fs::metadata(p) {
            return Some(Self::Inode(m.dev(), m.ino()));
        }
        let name = p.file_name()?;
        Some(Self::New(match std::fs::canonicalize(dir_of(p)) {
            Ok(dir) => dir.join(name),
            Err(_) => p.components().collect(),
        }))
    }
}

/// Creates and removes a probe file in `dir` (named by process and a per-process counter, so
/// checks running at once in one process or several never collide).
pub fn check_writable(dir: &Path) -> Result<(), PlanError> {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let probe = dir.join(format!(".strata-write-probe-{}-{n}", std::process::id()));
    let fail = |source| PlanError::NotWritable { dir: dir.to_path_buf(), source };
    if !dir.is_dir() {
        return Err(fail(std::io::Error::new(std::io::ErrorKind::NotFound, "no such directory")));
    }
    std::fs::OpenOptions::new().write(true).create_new(true).open(&probe).map_err(fail)?;
    std::fs::remove_file(&probe).map_err(fail)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_naming_inputs_or_each_other_or_long_names_are_refused() {
        let dir = std::env::temp_dir().join(format!("strata-plan-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let s = dir.join("s.test");
        std::fs::write(&s, "x").unwrap();
        let mut p = Plan::new();
        p.input("the scene file", &s).output("--json", dir.join("./s.test"));
        let e = p.check().unwrap_err().to_string();
        assert!(e.contains("--json and the scene file") && e.contains("same file"), "{e}");
        let mut p = Plan::new();
        p.output("--json", dir.join("p.json")).output("--svg", dir.join("sub/../p.json"));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let e = p.check().unwrap_err().to_string();
        assert!(e.contains("--json and --svg"), "{e}");
        let mut p = Plan::new();
        p.output("-o", dir.join("x".repeat(250)));
        assert!(p.check().unwrap_err().to_string().contains("shorten it"));
        let mut p = Plan::new();
        p.input("the scene file", &s).output("--json", dir.join("j.json"));
        p.check().unwrap();
        std::fs::remove_dir_all(&dir).ok();
    }
}

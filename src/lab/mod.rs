//! The lab: experiments over the renderer, built on the session layer and `report/`.
//!
//! - [`compare`] — `strata compare` (variants against a reference, equal spp or equal time);
//! - [`experiments`] — `strata experiments` (the seed experiments of the course report).

pub mod checks;
pub mod compare;
pub mod experiments;
pub mod mitsuba;
pub mod progress;
pub mod report_figures;
pub mod report_page;

pub use compare::{
    compare, compare_profiled, run, Comparison, Convergence, Mode, Options, RunRow, Variant, VariantProfile,
};
pub use report_page::write_outputs;

use crate::report::ReportError;
use crate::session::SessionError;
use std::path::PathBuf;

/// The most independent runs per variant `compare` and `experiments` accept.
pub const MAX_RUNS: usize = 100_000;

/// Why a comparison or an experiment could not run or write its outputs.
#[derive(Debug, thiserror::Error)]
pub enum LabError {
    /// A render of a variant failed.
    #[error(transparent)]
    Session(#[from] SessionError),
    /// Fewer than two runs per variant (`why` completes the message).
    #[error("--runs must be at least 2{why}")]
    TooFewRuns {
        /// the reason given after the message, if any
        why: &'static str,
    },
    /// The reference is not of the variants' scene, size or camera.
    #[error("{}: not a reference for this comparison: {diffs}{hint}", reference.display())]
    ReferenceMismatch {
        /// the reference file
        reference: PathBuf,
        /// what differs, naming both sides
        diffs: String,
        /// how to override, when that is possible
        hint: &'static str,
    },
    /// A variant is refused (its name, or a flag `compare` owns).
    #[error("--variant {variant}: {why}")]
    BadVariant {
        /// the variant's name
        variant: String,
        /// why
        why: String,
    },
    /// No variant was given.
    #[error("give at least one --variant NAME=FLAGS")]
    NoVariants,
    /// `--baseline` names no variant.
    #[error("--baseline {name}: no such variant (variants: {names})")]
    UnknownBaseline {
        /// the name given
        name: String,
        /// the variants' names
        names: String,
    },
    /// An empty ladder, a zero step, or steps not strictly increasing.
    #[error("--spp-ladder: expected positive spp values, strictly increasing (e.g. 1,2,4,8)")]
    BadLadder,
    /// More runs per variant than [`MAX_RUNS`].
    #[error("--runs {0}: at most {max} runs per variant", max = MAX_RUNS)]
    TooManyRuns(usize),
    /// A budget that is not a positive number of seconds.
    #[error("--budget {}: expected a positive number of seconds", crate::session::error::short_f64(*.0))]
    BadBudget(f64),
    /// A budget ladder that is not increasing.
    #[error("--budget: a budget ladder must be increasing CPU seconds, e.g. 0.25,0.5,1,2")]
    BadBudgetLadder,
    /// A variant's statistics could not be computed.
    #[error("variant {variant}: {source}")]
    VariantStats {
        /// the variant
        variant: String,
        /// why
        source: ReportError,
    },
    /// A metric could not be computed.
    #[error(transparent)]
    Report(#[from] ReportError),
    /// A reference render has non-finite samples.
    #[error("{scene}: {count} non-finite samples")]
    NonFinite {
        /// the scene
        scene: String,
        /// how many
        count: u64,
    },
    /// The CSE168 corpus is not where it was looked for.
    #[error("{}: CSE168 corpus not found (needs hw2, hw3, hw4; use --corpus)", .0.display())]
    NoCorpus(PathBuf),
    /// The worker pool could not start.
    #[error(transparent)]
    ThreadPool(#[from] crate::render::RenderError),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// the file or folder
        path: PathBuf,
        /// the I/O error
        source: std::io::Error,
    },
    /// JSON output did not serialize.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

/// An I/O error on `path`.
pub(crate) fn io_err(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> LabError + '_ {
    move |source| LabError::Io { path: path.to_path_buf(), source }
}

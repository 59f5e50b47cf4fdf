//! The lab: experiments over the renderer, built on the session layer and `report/`.
//!
//! - [`compare`] — `strata compare` (variants against a reference, equal spp or equal time);
//! - [`experiments`] — `strata experiments` (the seed experiments of the course report).

pub mod compare;
pub mod experiments;

pub use compare::{compare, compare_profiled, write_outputs, Mode, Variant, VariantProfile};

use crate::report::ReportError;
use crate::session::SessionError;
use std::path::PathBuf;

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
    /// A variant's image size differs from the reference's.
    #[error("variant {variant}: image {w}x{h} but the reference is {rw}x{rh} (use --size)")]
    SizeMismatch {
        /// the variant
        variant: String,
        /// its width
        w: u32,
        /// its height
        h: u32,
        /// the reference's width
        rw: u32,
        /// the reference's height
        rh: u32,
    },
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

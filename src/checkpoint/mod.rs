//! Checkpoint and part files: the accumulated state of a render (its dyadic blocks, see `film`),
//! with what identifies the render (scene hash, every option that affects the image), so that a
//! run can be resumed and shards of one render merged bit-identically.
//!
//! Layout (version 1), all integers little-endian:
//! `b"STRATACK"`, u32 version, u64 header length, the header as UTF-8 JSON ([`Header`]), then
//! `blocks * width * height * 6` f64 (block-major; per pixel sum R, G, B, sum of squares R, G, B),
//! then a u64 checksum of every byte before it. Written atomically ([`crate::film::write_atomic`]).
//! A replicated reference's checkpoint is its replicas' records one after another
//! ([`write_replicas`], [`read_replicas`]).
//!
//! - [`format`] — the file layout, [`read`] and [`write`];
//! - [`identity`] — the [`Header`] of a render, what makes two headers one render, EXR metadata;
//! - [`merge`] — `strata merge` of finished `--samples` parts.

pub mod format;
pub mod identity;
pub mod merge;

pub use format::{from_bytes, header_for, read, read_replicas, to_bytes, write, write_replicas, MAGIC, VERSION};
pub use identity::{header_metadata, identity, Header};
pub use merge::{run_merge, MergeOutput};

use std::path::PathBuf;

/// Why a checkpoint could not be read, written or merged (messages name the file).
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The file could not be read.
    #[error("{}: cannot read checkpoint: {source}", path.display())]
    Read {
        /// the checkpoint file
        path: PathBuf,
        /// the I/O error
        source: std::io::Error,
    },
    /// The file could not be written.
    #[error("{}: cannot write checkpoint: {source}", path.display())]
    Write {
        /// the checkpoint file
        path: PathBuf,
        /// the I/O error
        source: std::io::Error,
    },
    /// The bytes are not a checkpoint this strata can use (magic, version, size, checksum, blocks).
    #[error("{name}: not a usable strata checkpoint: {why}")]
    Unusable {
        /// the file (or label) read
        name: String,
        /// what is wrong with it
        why: String,
    },
    /// `strata merge` without parts.
    #[error("merge: give the part files to merge")]
    NoParts,
    /// A checkpoint of a `--time-budget` render (its range has no end) given to merge.
    #[error("{}: the checkpoint of a --time-budget render (samples {}..{}, no fixed range), not a part of `render --samples A..B`: continue it with --resume and --time-budget, or write its image with --resume", path.display(), samples[0], samples[1])]
    TimeBudgetPart {
        /// the file
        path: PathBuf,
        /// the samples it holds
        samples: [u32; 2],
    },
    /// A part whose sample range is not finished.
    #[error("{}: unfinished part: it holds samples {}..{} of its range {}..{} (finish it with --resume)", path.display(), samples[0], samples[1], target[0], target[1])]
    Unfinished {
        /// the part file
        path: PathBuf,
        /// the samples it holds
        samples: [u32; 2],
        /// the range it was asked for
        target: [u32; 2],
    },
    /// A part of another render.
    #[error("{}: does not belong with {}: {why}", path.display(), first.display())]
    Foreign {
        /// the part file
        path: PathBuf,
        /// the first part, which the others must match
        first: PathBuf,
        /// what differs
        why: String,
    },
    /// No part starts at sample 0.
    #[error("samples 0..{0} are missing (no part starts at 0)")]
    MissingStart(u32),
    /// Two parts overlap (each named with its range).
    #[error("{0} and {1} overlap")]
    Overlap(String, String),
    /// A gap between two parts (named with their ranges).
    #[error("samples {from}..{to} are missing (between {a} and {b})")]
    Gap {
        /// first missing sample
        from: u32,
        /// end of the missing samples
        to: u32,
        /// the part before the gap
        a: String,
        /// the part after the gap
        b: String,
    },
    /// The parts end before the render's spp.
    #[error("samples {last}..{end} of the {end} spp are missing (the last part ends at {last})")]
    MissingEnd {
        /// where the last part ends
        last: u64,
        /// the render's spp
        end: u64,
    },
    /// A part's film does not merge (size or range).
    #[error("{}: {source}", path.display())]
    Film {
        /// the part file
        path: PathBuf,
        /// why
        source: crate::film::FilmError,
    },
    /// An output image could not be written.
    #[error("{}: {source}", path.display())]
    Output {
        /// the image file
        path: PathBuf,
        /// the I/O error
        source: std::io::Error,
    },
}

/// FNV-1a, 64 bit, of `bytes`, as 16 hex digits: the scene hash.
pub fn hash_bytes(bytes: &[u8]) -> String {
    format!("{:016x}", fnv1a(0xcbf2_9ce4_8422_2325, bytes))
}

pub(crate) fn fnv1a(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

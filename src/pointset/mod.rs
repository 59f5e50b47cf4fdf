//! Point sets from outside strata: files (UTK text and binary, NumPy `.npy`) and arrays (the
//! Python module), checked and turned into a run-time sampler kind (`--sampler file:PATH`,
//! [`sampler::file`](crate::sampler::file)), and `strata pointset`: the quality measures of a set
//! next to its render error (discrepancy, minimum distance, radial power spectrum, integration
//! error and its convergence slope).
//!
//! Layer: above `sampler`, `checkpoint` and `report`, below `session`.
//!
//! - [`formats`] — reading and writing the three formats;
//! - [`spec`] — `file:PATH?options` sampler specs and their registration;
//! - [`analysis`] — the measures;
//! - [`command`] — `strata pointset` (report, CSV, SVG, `--export`).

pub mod analysis;
pub mod command;
pub mod formats;
pub mod spec;

pub use spec::{sampler_from_sets, SamplerSpec};

use std::path::PathBuf;

/// Point sets as read: `sets` sets of `points` points of `dims` coordinates, each in [0, 1);
/// coordinate d of point p of set s at `data[(s * points + p) * dims + d]`.
#[derive(Clone, Debug, PartialEq)]
pub struct PointSets {
    /// where they came from (a path, or `<array NAME>`), for messages
    pub source: String,
    /// number of sets
    pub sets: usize,
    /// points per set
    pub points: usize,
    /// coordinates per point
    pub dims: usize,
    /// the coordinates, set-major then point-major
    pub data: Vec<f64>,
    /// hash of the content (the file's bytes, or the array's values and shape), hex
    pub digest: String,
}

/// What is wrong with a point-set file or array; every message names the source and, for a
/// value, the set, the point and the coordinate (and the line of a text file).
#[derive(Debug, thiserror::Error)]
pub enum PointSetError {
    /// the file could not be read or written
    #[error("{}: {source}", path.display())]
    Io {
        /// the file
        path: PathBuf,
        /// the I/O error
        source: std::io::Error,
    },
    /// a line of a text file
    #[error("{source_name}:{line}: {why}")]
    Line {
        /// the file
        source_name: String,
        /// 1-based line
        line: usize,
        /// what is wrong
        why: String,
    },
    /// the header or layout of a binary file or array
    #[error("{source_name}: {why}")]
    Format {
        /// the file or array
        source_name: String,
        /// what is wrong
        why: String,
    },
    /// sets of different sizes
    #[error("{source_name}: set {set} has {points} points, set 0 has {first}{at}: every set needs the same number")]
    UnequalSets {
        /// the file or array
        source_name: String,
        /// the set that differs
        set: usize,
        /// its points
        points: usize,
        /// the first set's points
        first: usize,
        /// where (text files: the line)
        at: String,
    },
    /// a coordinate outside [0, 1) or NaN
    #[error("{source_name}: set {set}, point {point}, coordinate {coord}: {why}")]
    Value {
        /// the file or array
        source_name: String,
        /// set index
        set: usize,
        /// point index within the set
        point: usize,
        /// coordinate index
        coord: usize,
        /// what is wrong ("1.5 is outside [0, 1)", "NaN")
        why: CoordinateError,
    },
    /// a spec or option that strata does not know
    #[error("{0}")]
    Spec(String),
    /// too many distinct point sets loaded in one process
    #[error(transparent)]
    Register(#[from] crate::sampler::file::RegisterError),
}

/// Why a coordinate is refused.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum CoordinateError {
    /// NaN.
    #[error("NaN (coordinates must be numbers in [0, 1))")]
    NotANumber,
    /// A number outside [0, 1).
    #[error("{0} is outside [0, 1)")]
    OutOfRange(f64),
}

/// Checks a coordinate: a number in [0, 1).
pub(crate) fn check_value(v: f64) -> Result<(), CoordinateError> {
    if v.is_nan() {
        Err(CoordinateError::NotANumber)
    } else if !(0.0..1.0).contains(&v) {
        Err(CoordinateError::OutOfRange(v))
    } else {
        Ok(())
    }
}

impl PointSets {
    /// Sets of the given shape over `data` (set-major), checked: non-empty, the length matches,
    /// every value in [0, 1) (the first bad one is named by set, point and coordinate). The digest
    /// hashes shape and values (files replace it by the hash of their bytes).
    pub fn new(source: &str, sets: usize, points: usize, dims: usize, data: Vec<f64>) -> Result<Self, PointSetError> {
        let bad = |why: String| PointSetError::Format { source_name: source.into(), why };
        if sets == 0 || points == 0 || dims == 0 {
            return Err(bad(format!("no points ({sets} sets of {points} points of {dims} coordinates)")));
        }
        if sets.checked_mul(points).and_then(|n| n.checked_mul(dims)) != Some(data.len()) {
            return Err(bad(format!("{} values for {sets} sets x {points} points x {dims} coordinates", data.len())));
        }
        let limit = crate::sampler::file::MAX_TABLE_POINTS;
        if (sets * points) as u64 > limit {
            return Err(bad(format!("{} points in all, more than strata holds ({limit})", sets * points)));
        }
        if let Some(i) = data.iter().position(|&v| check_value(v).is_err()) {
            let (point, coord) = (i / dims, i % dims);
            return Err(PointSetError::Value {
                source_name: source.into(),
                set: point / points,
                point: point % points,
                coord,
                why: check_value(data[i]).expect_err("found as bad"),
            });
        }
        let mut bytes = Vec::with_capacity(data.len() * 8 + 24);
        for n in [sets, points, dims] {
            bytes.extend_from_slice(&(n as u64).to_le_bytes());
        }
        data.iter().for_each(|v| bytes.extend_from_slice(&v.to_le_bytes()));
        let digest = crate::checkpoint::hash_bytes(&bytes);
        Ok(Self { source: source.into(), sets, points, dims, data, digest })
    }

    /// Coordinates of point `p` of set `s`.
    pub fn point(&self, s: usize, p: usize) -> &[f64] {
        let i = (s * self.points + p) * self.dims;
        &self.data[i..i + self.dims]
    }

    /// The 2D points of the first `max` sets (at most all of them).
    pub fn sets_2d(&self, max: usize) -> Vec<Vec<[f64; 2]>> {
        (0..self.sets.min(max)).map(|s| self.set_2d(s)).collect()
    }

    /// The 2D points (coordinates 0 and 1) of set `s`.
    pub fn set_2d(&self, s: usize) -> Vec<[f64; 2]> {
        (0..self.points).map(|p| self.point(s, p)).map(|c| [c[0], c.get(1).copied().unwrap_or(0.0)]).collect()
    }
}

#[cfg(test)]
mod tests;

//! Error metrics and reports for equal-time comparisons of sampling techniques.
//!
//! Pure functions on images; nothing here renders. An image is linear RGB, row-major,
//! `&[[f32; 3]]`, and every image compared with a reference must have the reference's pixel count.
//!
//! - [`metrics`]: MSE, relative MSE, statistics over K independent runs ([`RunStats`]: bias with
//!   its standard error, z and a Student-t confidence interval, variance, the MSE decomposition,
//!   noise-corrected rms bias; optionally against a noisy reference and on 8-bit values) and
//!   efficiency: the one statistics code path of `strata compare` and `strata experiments`.
//! - [`table`]: one [`table::Row`] per variant and setting, and the one table writer (Markdown,
//!   CSV, JSON) over column lists, for both commands.
//! - [`plot`]: a self-contained log-log SVG of error against time with a convergence-rate guide.
//! - [`bars`]: a stacked bar chart SVG (the phases of `strata profile`, one bar per variant).
//! - [`flip`]: FLIP error maps and means (LDR, through `nv-flip`).
//! - [`html`]: the self-contained `report.html` (flip-books, error maps, tables, plots).
//! - [`slope`]: fitted log-log convergence slopes with a Student-t interval.
//! - [`student_t`]: Student's t quantile, shared by the intervals above.

pub mod bars;
pub mod flip;
pub mod html;
pub mod metrics;
pub mod plot;
pub mod robust;
pub mod slope;
pub mod student_t;
pub mod table;
pub mod ztest;

pub use bars::{stacked_bars_svg, Bar};
pub use metrics::{efficiency, mse, rel_mse, EightBit, ReferenceInfo, RunStats};
pub use plot::{loglog_svg, loglog_svg_annotated, loglog_svg_guided, Annotation, LogScale, Series};
pub use slope::{loglog_slope, Slope};
pub use student_t::{student_t_quantile, MAX_DOF};
pub use table::{g3, html_table, markdown_table, to_csv, to_grouped_json, to_json, to_markdown, Column, Row, Style};

use std::fmt;

/// Why a metric could not be computed. Metrics never return NaN; they return one of these.
#[derive(Clone, Debug, PartialEq)]
pub enum ReportError {
    /// An image's pixel count differs from the reference's.
    SizeMismatch {
        /// which image ("image", "run 3", ...)
        image: String,
        /// its pixel count
        pixels: usize,
        /// the reference's pixel count
        reference: usize,
    },
    /// A pixel value is NaN or infinite.
    NonFinite {
        /// which image ("image", "reference", "run 3", ...)
        image: String,
        /// row-major pixel index
        pixel: usize,
        /// channel 0..3
        channel: usize,
        /// the offending value
        value: f32,
    },
    /// There are no pixels to average over.
    Empty,
    /// Across-run statistics need at least two runs.
    TooFewRuns(usize),
    /// A scalar argument is NaN, infinite or negative where it must not be.
    InvalidArgument {
        /// the argument's name
        name: &'static str,
        /// its value
        value: f64,
    },
}

impl fmt::Display for ReportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::SizeMismatch { image, pixels, reference } => {
                write!(f, "size mismatch: {image} has {pixels} pixels but the reference has {reference}")
            }
            Self::NonFinite { image, pixel, channel, value } => {
                write!(f, "{image} has a non-finite value {value} at pixel {pixel}, channel {channel}")
            }
            Self::Empty => write!(f, "images have no pixels"),
            Self::TooFewRuns(k) => write!(f, "run statistics need at least 2 runs, got {k}"),
            Self::InvalidArgument { name, value } => {
                write!(f, "{name} must be finite and non-negative, got {value}")
            }
        }
    }
}

impl std::error::Error for ReportError {}

//! Tests of the shading frames and maps at hits (`perturb.rs`).

use super::*;

//! The path wavefront's column layouts (`wave::Columns`): which column of a live path, of the
//! previous vertex kept for MIS, and of a shadow ray holds what.

// Columns of a live path (`Columns<PATH_COLS>`): the index of (tile packet, lane) whose pixel
// sample it is, `packet * 8 + lane` (u32::MAX: a placeholder lane, traced inactive); the linear
// pixel index and the pixel sample index (sampler inputs); the next ray's origin and unit
// direction; the throughput; the solid-angle pdf with which the direction was sampled (for the
// MIS weight of emission found along it).
pub(super) const SLOT: usize = 0;
pub(super) const PIXEL: usize = 1;
pub(super) const SAMPLE: usize = 2;
pub(super) const O: usize = 3;
pub(super) const D: usize = 6;
pub(super) const BETA: usize = 9;
pub(super) const PDF: usize = 12;
pub(super) const PATH_COLS: usize = 13;
// Columns of the previous vertex's shading point and normal as NEE used them (for a
// point-dependent light selection's pmf in the MIS weight of emission found along the path),
// kept only when that selection needs them.
pub(super) const PREV_P: usize = 0;
pub(super) const PREV_N: usize = 3;
// Columns of a shadow ray: pixel sample slot, origin, unnormalized direction to the light
// sample, interval end, and the contribution added to the slot if it is unoccluded.
pub(super) const S_SLOT: usize = 0;
pub(super) const S_O: usize = 1;
pub(super) const S_D: usize = 4;
pub(super) const S_TFAR: usize = 7;
pub(super) const S_C: usize = 8;
pub(super) const SHADOW_COLS: usize = 11;

//! A node of the binary light tree and the cosine margins of its importance bound: what the
//! tree ([`super::tree`]) builds and the collapsed tree ([`super::wide`]) reads.

use glam::Vec3;

/// Margin on the cosine bounds (about 0.06 degrees): a node is given importance 0 only when the
/// best cosine is below `-COS_SLACK`, which absorbs the f32 rounding of the bound itself (the
/// worst term is `sqrt(1 - cos^2)` near `cos = +-1`, off by up to ~3e-4).
pub(crate) const COS_SLACK: f32 = 1e-3;
/// Floor of a cosine factor that passed the slack test, so that the importance stays positive.
pub(crate) const COS_FLOOR: f32 = 1e-6;

/// A node of the light tree (depth-first order: the left child of node `k` is `k + 1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Node {
    /// centre of the bounding sphere (centre of the node's box)
    pub center: Vec3,
    /// radius of the bounding sphere (half the box diagonal, inflated for rounding)
    pub radius: f32,
    /// node power relative to the whole tree's (in (0, 1])
    pub phi: f32,
    /// axis of the cone of emitting normals
    pub axis: Vec3,
    /// cosine of the cone's half angle theta_o
    pub cos_o: f32,
    /// sine of theta_o
    pub sin_o: f32,
    /// right child for an interior node, light index for a leaf
    pub link: u32,
    /// leaf (one emitter)
    pub leaf: bool,
}

//! The memory a render needs, estimated from the scene description before the BVH, the film or any
//! thread is made, and refused above `--limit max_memory` (default 80% of physical memory or of
//! the cgroup's limit): a render too big for the node fails at once with the estimate, instead of
//! being killed by the kernel minutes later.
//!
//! The model (bytes; `px` pixels, `B` the most dyadic blocks the film holds at once over the
//! sample range, `T` triangles, `E` spheres and ellipsoids, `n` threads):
//! - film: `52 px` (sums, squares, counts) + `48 px B` (the block moments); during a pass the
//!   tiles' continued blocks (their vectors' capacity: up to the next power of two of `B`) and the
//!   film's new blocks are alive together;
//! - outputs, after the passes: the film plus the larger of the images (`100 px`: mean and variance,
//!   EXR channels and their compressed bytes, PNG) and the checkpoint bytes (`48 px B`);
//! - scene: [`PER_TRIANGLE`] per triangle (description, build tables, vertex normals when given)
//!   and Embree's BVH ([`BVH_PER_TRIANGLE`], more for the high-quality build), [`PER_ELLIPSOID`]
//!   per sphere or ellipsoid;
//! - threads: [`PER_THREAD`] each (stack and scratch), and [`BASE`] for the process itself.
//!
//! `docs/memory.md` compares the estimate with the measured peak RSS.

use super::{RenderOptions, SessionError};
use crate::film::{canonical_blocks, push_block, Block};
use crate::scene::desc::SceneDesc;
use crate::scene::parse::limit_hint;

/// The process before rendering: binary, Embree and its task threads, allocator arenas.
pub const BASE: u64 = 24 << 20;
/// Per worker thread: stack and tile scratch buffers.
pub const PER_THREAD: u64 = 4 << 20;
/// Per triangle, besides the BVH: its description (40), the built vertices (36), index (12),
/// material and light ids (8), normal (12) (measured with a 2M-triangle OBJ: see docs/robustness.md).
pub const PER_TRIANGLE: u64 = 110;
/// Per triangle with vertex normals: the normals in the description and in the built table.
pub const PER_TRIANGLE_NORMALS: u64 = 72;
/// Embree's BVH per triangle (medium quality; the high-quality build with spatial splits takes
/// [`BVH_HIGH_FACTOR`] times as much).
pub const BVH_PER_TRIANGLE: u64 = 80;
/// The high-quality BVH against the medium one.
pub const BVH_HIGH_FACTOR: u64 = 2;
/// Per sphere or ellipsoid: description, matrices, material, Embree's user primitive.
pub const PER_ELLIPSOID: u64 = 320;

/// The estimate of one render, by part (bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Estimate {
    /// the film at its largest (during a pass, or with the outputs being written)
    pub film: u64,
    /// the scene: descriptions and built tables
    pub scene: u64,
    /// Embree's BVH
    pub bvh: u64,
    /// worker threads and the process itself
    pub threads: u64,
}

impl Estimate {
    /// The sum of the parts.
    pub fn total(&self) -> u64 {
        self.film + self.scene + self.bvh + self.threads
    }
}

/// The most dyadic blocks a film holds over the samples `range` (after each sample; beyond 2^22
/// samples, the count at 2^22 plus one block per doubling).
pub fn max_blocks(range: std::ops::Range<u32>) -> u64 {
    let simulated = range.start..range.end.min(range.start.saturating_add(1 << 22));
    let mut blocks: Vec<Block> = canonical_blocks(range.start..range.start);
    let mut most = 0;
    for s in simulated.clone() {
        push_block(&mut blocks, Block::leaf(s));
        most = most.max(blocks.len());
    }
    let left = u64::from(range.end - simulated.end);
    let extra = if left == 0 { 0 } else { 64 - left.leading_zeros() as u64 };
    most as u64 + extra
}

/// The estimate for rendering `desc` over the sample `range` with `threads` workers.
pub fn estimate(desc: &SceneDesc, range: std::ops::Range<u32>, threads: usize) -> Estimate {
    let px = u64::from(desc.width) * u64::from(desc.height);
    let b = max_blocks(range);
    let state = 52 * px + 48 * px * b;
    let pass = 52 * px + 48 * px * (b + b.next_power_of_two());
    let film = pass.max(state + (100 * px).max(48 * px * b));
    // A shapegroup's triangles are stored once, however many instances place them.
    let tris =
        (desc.triangles.len() + desc.emissive_triangles.len() + 2 * desc.quad_lights.len() + desc.group_triangles())
            as u64;
    let normals = if desc.triangle_normals.is_empty() { 0 } else { PER_TRIANGLE_NORMALS * tris };
    // A bad STRATA_BVH was refused by the command-line checks; here it counts as unset.
    let by_count = tris >= crate::scene::build::HIGH_QUALITY_MIN_TRIANGLES as u64;
    let high = crate::scene::build::forced_bvh().ok().flatten().unwrap_or(by_count);
    let bvh_factor = if high { BVH_HIGH_FACTOR } else { 1 };
    Estimate {
        film,
        scene: PER_TRIANGLE * tris + normals + PER_ELLIPSOID * desc.spheres.len() as u64,
        bvh: BVH_PER_TRIANGLE * bvh_factor * tris,
        threads: BASE + PER_THREAD * threads as u64,
    }
}

/// `bytes` in GiB or MiB, e.g. "12.4 GiB".
pub fn show_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= f64::from(1u32 << 30) {
        format!("{:.1} GiB", b / f64::from(1u32 << 30))
    } else {
        format!("{:.1} MiB", b / f64::from(1u32 << 20))
    }
}

/// Refuses a render of `desc` with `opts` at `spp` whose [`estimate`] is above `max_memory`,
/// naming the estimate and its parts.
pub fn check(opts: &RenderOptions, desc: &SceneDesc, spp: u32) -> Result<(), SessionError> {
    let range = match (opts.samples, opts.time_budget) {
        (Some((a, b)), _) => a..b,
        // A time budget: as many samples as `--spp` allows, counted up to 2^20.
        (None, Some(_)) => 0..opts.spp.unwrap_or(1 << 20).min(1 << 20),
        (None, None) => 0..spp,
    };
    let threads = match opts.threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    };
    let e = estimate(desc, range, threads);
    let limit = opts.limits.max_memory;
    if e.total() <= limit {
        return Ok(());
    }
    Err(SessionError::Memory {
        what: format!("{} at {}x{}", desc.source.display(), desc.width, desc.height),
        need: show_bytes(e.total()),
        breakdown: format!(
            "film and outputs {}, scene {}, BVH {}, threads {}",
            show_bytes(e.film),
            show_bytes(e.scene),
            show_bytes(e.bvh),
            show_bytes(e.threads)
        ),
        limit: show_bytes(limit),
        hint: limit_hint("max_memory"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_blocks_is_the_largest_block_count_over_the_range() {
        assert_eq!(max_blocks(0..1), 1);
        assert_eq!(max_blocks(0..8), 3, "after 7 samples: blocks of 4, 2, 1");
        assert_eq!(max_blocks(0..1024), 10);
        assert_eq!(max_blocks(3..4), 1);
        assert!(max_blocks(0..u32::MAX) >= 32);
    }
}

//! The integrator trait: what each integrator file implements, and all the renderer knows of it
//! (through the registry in `mod.rs`).

use super::context::TileCtx;
use super::samples::Dim;
use super::settings::Integrator;
use crate::bsdf::LobeSet;
use crate::scene::desc::IntegratorKind;
use crate::simd::Vec3x8;

/// An integrator: radiance of a tile's pixel samples. One file per integrator implements it,
/// and one line in `mod.rs`'s `INTEGRATORS` registers it.
pub trait Estimator {
    /// The scene-format integrator it implements (`integrator NAME` in `.test`, `--integrator`).
    const KIND: IntegratorKind;
    /// The sampler dimensions it draws, in order (listed in `docs/ARCHITECTURE.md`).
    const DIMS: &'static [Dim];
    /// Its per-thread buffers, kept across tiles.
    type Scratch: Default + Send + 'static;

    /// Radiance of pixel samples `samples` of every packet of `ctx.pks` into `out`,
    /// sample-major: `out[si * pks.len() + p]` is packet p at sample `samples.start + si`
    /// (inactive lanes zero). `L` is the kernel's compiled lobe set. Every number comes from
    /// `ctx.samples`, every ray goes through `ctx.tracer`.
    fn tile<L: LobeSet>(
        it: &Integrator,
        ctx: &mut TileCtx,
        scratch: &mut Self::Scratch,
        samples: std::ops::Range<u32>,
        out: &mut Vec<Vec3x8>,
    );
}

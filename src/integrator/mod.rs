//! Integrators: radiance of the 4x2 packets of camera samples of a tile. The integrator is the
//! plugin boundary: one trait ([`Estimator`]), one file per integrator that owns its scratch
//! buffers and declares its sampler dimensions, and one line per integrator in [`INTEGRATORS`].
//! They draw every number through the tile context's sample handle ([`Samples`]: profiled and
//! logged for sampler replay), reach Embree only through its [`Tracer`] (traced, counted and
//! logged) and shade through `bsdf::Material8`.
//!
//! The integrators: [`whitted`] (`raytracer`), [`analytic`] (`analyticdirect`), [`direct`]
//! (`direct`) and [`path`] (`pathtracer`). The three direct-lighting ones share the camera-hit
//! wavefront of [`primary`]; the path tracer runs its own. Kernels are monomorphized over a
//! `bsdf::LobeSet` (see [`kernel`]). Their settings: [`settings`].
//!
//! Directions: `wo` points to the viewer, `wi` to the light; pdfs per unit solid angle unless named
//! `_area`.
//!
//! Imports run one way: `mod.rs` (the registry) imports the integrators; they import
//! `estimator`, `settings`, `samples`, `context`, `primary`, `stats` and `kernel`, never `mod.rs`
//! or each other.

use crate::camera::PixelPacket;
use crate::scene::build::Scene;
use crate::scene::desc::IntegratorKind;
use crate::simd::Vec3x8;
use std::any::Any;

pub mod analytic;
pub mod context;
pub mod direct;
pub mod direct_settings;
pub mod estimator;
pub mod kernel;
pub mod light_term;
pub mod path;
mod primary;
pub mod ptracer;
pub mod samples;
pub mod settings;
pub mod stats;
pub mod whitted;

pub use crate::camera::{FirstSample, DIM_CAMERA};
pub use crate::light::select::{LightChoice, LightSampler, LightSelection};
pub use crate::light::warp::LightWarp;
pub use context::{TileCtx, Tracer};
pub use direct::DIM_LIGHT_BASE;
pub use estimator::Estimator;
pub use path::{PathScratch, DIM_PATH_BASE};
pub use ptracer::{LightPaths, Splat};
pub use samples::{Dim, Samples, Source};
pub use settings::{progressive_names, Integrator, NotProgressive, SamplerChoice};
pub use stats::{Counters, RayKind, RayLog};

/// An integrator's scratch slot: its `Estimator::Scratch`, made on first use.
type Slot = Option<Box<dyn Any + Send>>;

/// One registered integrator: its scene-format kind, its declared dimensions and its tile
/// function (monomorphized for every compiled lobe set).
pub struct Entry {
    /// the integrator it runs
    pub kind: IntegratorKind,
    /// the sampler dimensions it draws
    pub dims: &'static [Dim],
    run: fn(&Integrator, &mut TileCtx, &mut Slot, std::ops::Range<u32>, &mut Vec<Vec3x8>),
}

/// The registry entry of estimator `E`.
const fn entry<E: Estimator + 'static>() -> Entry {
    Entry { kind: E::KIND, dims: E::DIMS, run: run::<E> }
}

/// Runs `E` on a tile with its scratch from `slot` (made on first use), in the kernel compiled
/// for the integrator's lobes.
fn run<E: Estimator + 'static>(
    it: &Integrator,
    ctx: &mut TileCtx,
    slot: &mut Slot,
    samples: std::ops::Range<u32>,
    out: &mut Vec<Vec3x8>,
) {
    let any = slot.get_or_insert_with(|| Box::new(E::Scratch::default()));
    // A slot holds only its own entry's scratch: `Scratch` indexes slots by registry position.
    let scratch = any.downcast_mut::<E::Scratch>().expect("a scratch slot holds its integrator's buffers");
    kernel::with_lobe_set!(it.kernel.lobes, L => E::tile::<L>(it, ctx, scratch, samples, out))
}

/// Every integrator, one line each. A new integrator is its file, its line here and its
/// `IntegratorKind` (the name the scene format and `--integrator` use).
pub static INTEGRATORS: &[Entry] = &[
    entry::<whitted::Whitted>(),
    entry::<analytic::Analytic>(),
    entry::<direct::Direct>(),
    entry::<path::PathTracer>(),
    entry::<ptracer::ParticleTracer>(),
];

/// The registry position of `kind` (every kind is registered: tested).
fn position(kind: IntegratorKind) -> usize {
    INTEGRATORS.iter().position(|e| e.kind == kind).expect("every IntegratorKind is in INTEGRATORS")
}

/// Per-thread scratch buffers of the integrators (each integrator's own, made on first use),
/// reused across tiles.
#[derive(Default)]
pub struct Scratch {
    slots: Vec<Slot>,
}

impl Integrator {
    /// Radiance of pixel samples `samples` for each packet of `pks` (a tile), into `out`,
    /// sample-major: `out[si * pks.len() + p]` is packet p at sample `samples.start + si`
    /// (inactive lanes zero). `log` records every packet traced.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance_tile(
        &self,
        scene: &Scene,
        pks: &[PixelPacket],
        samples: std::ops::Range<u32>,
        out: &mut Vec<Vec3x8>,
        sc: &mut Scratch,
        c: &mut Counters,
        log: Option<&mut RayLog>,
    ) {
        let samples_handle = Samples::new(self, self.camera(scene));
        let mut ctx = TileCtx { scene, samples: samples_handle, pks, tracer: Tracer::new(scene, c, log) };
        let i = position(self.kind);
        if sc.slots.len() < INTEGRATORS.len() {
            sc.slots.resize_with(INTEGRATORS.len(), || None);
        }
        (INTEGRATORS[i].run)(self, &mut ctx, &mut sc.slots[i], samples, out);
    }
}

#[cfg(test)]
mod lights_tests;

#[cfg(test)]
mod tests {
    use super::*;

    /// Every scene-format integrator runs through exactly one registry entry.
    #[test]
    fn every_kind_is_registered_once() {
        for (name, kind) in IntegratorKind::NAMES {
            let n = INTEGRATORS.iter().filter(|e| e.kind == *kind).count();
            assert_eq!(n, 1, "{name} is registered {n} times");
        }
        assert_eq!(INTEGRATORS.len(), IntegratorKind::NAMES.len());
    }

    /// `docs/ARCHITECTURE.md` lists every declared dimension of every integrator as a row
    /// `| \`kind\` | name | first | stride | layout |`, and no dimension twice within one.
    #[test]
    fn declared_dimensions_are_documented() {
        let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/ARCHITECTURE.md")).unwrap();
        for e in INTEGRATORS {
            for (i, d) in e.dims.iter().enumerate() {
                let row =
                    format!("| `{}` | {} | {} | {} | {} |", e.kind.name(), d.name, d.first, d.stride, d.source.name());
                assert!(doc.contains(&row), "docs/ARCHITECTURE.md lacks the row\n{row}");
                let twice = e.dims[..i].iter().any(|o| o.first == d.first);
                assert!(!twice, "{}: dimension {} declared twice", e.kind.name(), d.first);
            }
        }
    }
}

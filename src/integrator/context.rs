//! The tile context: what one integrator call over a tile works with. It owns (by reference) the
//! scene, the camera, the tile's packets, the per-thread scratch buffers and a [`Tracer`], the one
//! place where rays reach Embree: every `intersect`/`occluded` call is counted in [`Counters`] and,
//! when a [`RayLog`] is attached (`strata rays`), logged as traced.

use super::path::PathScratch;
use super::stats::{Counters, RayKind, RayLog};
use crate::accel::{Ray8, RayHit8};
use crate::camera::{Camera, PixelPacket};
use crate::sampler::Stream;
use crate::scene::build::{Scene, SurfaceHit8};
use crate::simd::{Mask8, Vec3x8, F8, U8};

/// Embree calls with their counting and logging, written once.
pub struct Tracer<'a> {
    scene: &'a Scene,
    counters: &'a mut Counters,
    log: Option<&'a mut RayLog>,
}

impl<'a> Tracer<'a> {
    /// A tracer over `scene` counting into `counters` and logging into `log` if given.
    pub fn new(scene: &'a Scene, counters: &'a mut Counters, log: Option<&'a mut RayLog>) -> Self {
        Self { scene, counters, log }
    }

    /// Closest hit of the `active` lanes of `rh` (a camera or bounce packet; camera packets carry
    /// Embree's coherent flag). Returns the lanes traced.
    #[inline]
    pub fn intersect(&mut self, rh: &mut RayHit8, kind: RayKind, active: Mask8) -> Mask8 {
        debug_assert!(kind != RayKind::Shadow, "shadow rays go through `occluded`");
        if let Some(l) = self.log.as_deref_mut() {
            if kind == RayKind::Camera { &mut l.camera } else { &mut l.bounce }.push((*rh, active));
        }
        let traced = {
            let _p = crate::profile::scope(crate::profile::Phase::EmbreeIntersect);
            self.scene.accel.intersect8(rh, kind == RayKind::Camera, active)
        };
        self.counters.packet(kind, traced);
        traced
    }

    /// [`Tracer::intersect`] over a batch of packets traced back to back; each mask becomes the
    /// lanes traced.
    #[inline]
    pub fn intersect_all(&mut self, packets: &mut [(RayHit8, Mask8)], kind: RayKind) {
        let _p = crate::profile::scope(crate::profile::Phase::EmbreeIntersect);
        for (rh, active) in packets.iter_mut() {
            *active = self.intersect(rh, kind, *active);
        }
    }

    /// Occlusion of the `active` lanes of the shadow packet `ray`: the lanes that are blocked.
    #[inline]
    pub fn occluded(&mut self, ray: &mut Ray8, active: Mask8) -> Mask8 {
        if let Some(l) = self.log.as_deref_mut() {
            l.shadow.push((*ray, active));
        }
        let occluded = {
            let _p = crate::profile::scope(crate::profile::Phase::EmbreeOccluded);
            self.scene.accel.occluded8(ray, active)
        };
        self.counters.packet(RayKind::Shadow, active);
        occluded
    }

    /// The counters (e.g. to count non-finite samples).
    pub fn counters(&mut self) -> &mut Counters {
        self.counters
    }
}

/// Per-thread buffers of the tile wavefront, reused across samples and tiles.
#[derive(Default)]
pub struct Scratch {
    pub(super) rh: Vec<(RayHit8, Mask8)>,
    pub(super) hits: Vec<SurfaceHit8>,
    pub(super) shade: Vec<Mask8>,
    pub(super) eps: Vec<F8>,
    pub(super) acc: Vec<Vec3x8>,
    pub(super) shadow: Vec<(Ray8, Mask8)>,
    pub(super) contrib: Vec<Vec3x8>,
    pub(super) owner: Vec<u32>,
    pub(super) streams: Vec<Stream<U8>>,
    /// `direct` with one light per sample: the light-choice streams
    pub(super) choice_streams: Vec<Stream<U8>>,
    /// the camera's pixel-sample streams of the tile's packets (direct-lighting integrators)
    pub(super) cam_streams: Vec<Stream<U8>>,
    pub(super) path: PathScratch,
    pub(super) one: Vec<Vec3x8>,
}

/// Everything an integrator needs for one tile.
pub struct TileCtx<'a> {
    /// the scene
    pub scene: &'a Scene,
    /// primary ray generation
    pub camera: Camera<'a>,
    /// the tile's packets
    pub pks: &'a [PixelPacket],
    /// Embree calls, counted and logged
    pub tracer: Tracer<'a>,
    /// per-thread buffers
    pub scratch: &'a mut Scratch,
}

impl TileCtx<'_> {
    /// Closest hit of a camera or bounce packet, counted and logged ([`Tracer::intersect`]).
    #[inline]
    pub fn intersect(&mut self, rh: &mut RayHit8, kind: RayKind, active: Mask8) -> Mask8 {
        self.tracer.intersect(rh, kind, active)
    }

    /// Occlusion of a shadow packet, counted and logged ([`Tracer::occluded`]).
    #[inline]
    pub fn occluded(&mut self, ray: &mut Ray8, active: Mask8) -> Mask8 {
        self.tracer.occluded(ray, active)
    }
}

/// `v` on the lanes of `m`, zero elsewhere.
#[inline]
pub(super) fn masked(v: Vec3x8, m: Mask8) -> Vec3x8 {
    Vec3x8::new(m.select(v.x, F8::ZERO), m.select(v.y, F8::ZERO), m.select(v.z, F8::ZERO))
}

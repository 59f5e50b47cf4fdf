//! The tile context: what one integrator call over a tile works with. It holds (by reference) the
//! scene, the tile's packets, the sample handle [`Samples`] (the one place numbers are drawn) and
//! a [`Tracer`], the one place where rays reach Embree: every `intersect`/`occluded` call is
//! counted in [`Counters`] and, when a [`RayLog`] is attached (`strata rays`), logged as traced.

use super::samples::Samples;
use super::stats::{Counters, RayKind, RayLog};
use crate::accel::{Ray8, RayHit8};
use crate::bsdf::{BsdfSet, LobeSet};
use crate::camera::PixelPacket;
use crate::scene::build::Scene;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Frame8, Mask8, Vec3x8, F8};

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
    /// Embree's coherent flag). Returns the lanes traced. Always inlined: with more registry
    /// BSDFs in the general kernel LLVM stopped inlining it into the course kernels' tile loop
    /// (cornellSimple +0.6 % instructions).
    #[inline(always)]
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
    #[inline(always)]
    pub fn intersect_all(&mut self, packets: &mut [(RayHit8, Mask8)], kind: RayKind) {
        let _p = crate::profile::scope(crate::profile::Phase::EmbreeIntersect);
        if self.log.is_some() {
            for (rh, active) in packets.iter_mut() {
                *active = self.intersect(rh, kind, *active);
            }
            return;
        }
        // Not logging: Embree back to back, the packets counted once.
        let coherent = kind == RayKind::Camera;
        let mut rays = 0;
        for (rh, active) in packets.iter_mut() {
            *active = self.scene.accel.intersect8(rh, coherent, *active);
            rays += active.to_bitmask().count_ones();
        }
        self.counters.count(kind, u64::from(rays), packets.len() as u64);
    }

    /// Occlusion of the `active` lanes of the shadow packet `ray`: the lanes that are blocked.
    #[inline(always)]
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

/// Everything an integrator needs for one tile.
pub struct TileCtx<'a> {
    /// the scene
    pub scene: &'a Scene,
    /// every number the integrator uses (camera jitter, light, path), profiled and logged
    pub samples: Samples<'a>,
    /// the tile's packets
    pub pks: &'a [PixelPacket],
    /// Embree calls, counted and logged
    pub tracer: Tracer<'a>,
}

impl TileCtx<'_> {
    /// Closest hit of a camera or bounce packet, counted and logged ([`Tracer::intersect`]).
    #[inline(always)]
    pub fn intersect(&mut self, rh: &mut RayHit8, kind: RayKind, active: Mask8) -> Mask8 {
        self.tracer.intersect(rh, kind, active)
    }

    /// Occlusion of a shadow packet, counted and logged ([`Tracer::occluded`]).
    #[inline(always)]
    pub fn occluded(&mut self, ray: &mut Ray8, active: Mask8) -> Mask8 {
        self.tracer.occluded(ray, active)
    }
}

/// `v` on the lanes of `m`, zero elsewhere.
#[inline]
pub(super) fn masked(v: Vec3x8, m: Mask8) -> Vec3x8 {
    Vec3x8::new(m.select(v.x, F8::ZERO), m.select(v.y, F8::ZERO), m.select(v.z, F8::ZERO))
}

/// The local shading frame of a hit record: in kernels with registry BSDFs (which every scene
/// with tangents or normal/bump maps runs) built from the hit's tangent (Mitsuba's: dp/du made
/// orthogonal to the normal) where the scene has tangents; from the normal alone otherwise. With
/// the hit's material (`sh.mat`, written by the gather) it is all a packet is shaded with: the
/// one way `direct`, the path tracer and the particle tracer build a [`super::light_term::Shading`].
#[inline(always)]
pub(super) fn shading_frame<L: LobeSet>(scene: &Scene, sh: &SurfaceHit8) -> Frame8 {
    if <L::Bsdfs as BsdfSet>::BITS != 0 && scene.tangents {
        return Frame8::from_normal_tangent(sh.n, sh.s);
    }
    Frame8::from_normal(sh.n)
}

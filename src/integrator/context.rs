//! The tile context: what one integrator call over a tile works with. It holds (by reference) the
//! scene, the tile's packets, the sample handle [`Samples`] (the one place numbers are drawn) and
//! a [`Tracer`], the one place where rays reach Embree: every `intersect`/`occluded` call is
//! counted in [`Counters`] and, when a [`RayLog`] is attached (`strata rays`), logged as traced.

use super::samples::Samples;
use super::stats::{Counters, RayKind, RayLog};
use crate::accel::{Ray8, RayHit8};
use crate::bsdf::{BsdfSet, LobeSet, Material8};
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

/// The material of a hit record, with the registry BSDF rows looked up only in a kernel that
/// compiles registry BSDFs in.
#[inline(always)]
pub(super) fn material<L: LobeSet>(scene: &Scene, sh: &SurfaceHit8) -> Material8 {
    let bsdf = if <L::Bsdfs as BsdfSet>::BITS != 0 {
        let mut p = scene.bsdf_params(sh.material, sh.valid);
        if !scene.param_textures.is_empty() {
            scene.texture_params(sh, sh.valid, &mut p);
        }
        p
    } else {
        // Never read in these kernels (no registry BSDF, no mask).
        crate::bsdf::Params8::UNREAD
    };
    Material8 {
        kd: sh.kd,
        ks: sh.ks,
        shininess: sh.shininess,
        alpha: sh.roughness,
        ggx: sh.ggx,
        bsdf,
        back: sh.back,
        frame_map: None,
    }
}

/// The local shading frame of a hit record: in kernels with registry BSDFs (which every scene
/// with tangents or normal/bump maps runs) built from the hit's tangent (Mitsuba's: dp/du made
/// orthogonal to the normal) where the scene has tangents; from the normal alone otherwise.
#[inline(always)]
pub(super) fn shading_frame<L: LobeSet>(scene: &Scene, sh: &SurfaceHit8) -> Frame8 {
    if <L::Bsdfs as BsdfSet>::BITS != 0 && scene.tangents {
        return Frame8::from_normal_tangent(sh.n, sh.s);
    }
    Frame8::from_normal(sh.n)
}

/// [`material`] with the terms of the hit's normal or bump maps ([`crate::bsdf::FrameMap8`]) in
/// the local `frame` (from [`shading_frame`]), in kernels with registry BSDFs of scenes with maps.
#[inline(always)]
pub(super) fn material_in<L: LobeSet>(scene: &Scene, sh: &SurfaceHit8, frame: &Frame8) -> Material8 {
    let mut mat = material::<L>(scene, sh);
    if <L::Bsdfs as BsdfSet>::BITS != 0 && scene.frame_maps() {
        mat.frame_map = Some(crate::bsdf::FrameMap8 { base: frame.to_local(sh.base_n), a2: sh.bump_a2 });
    }
    mat
}

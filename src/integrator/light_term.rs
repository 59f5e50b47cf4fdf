//! The light term of next-event estimation, written once for `direct` and the path tracer: per
//! light kind its sample, the direction and geometry at a packet of shading points, the BSDF value
//! there, its MIS weight's inputs and its shadow ray.
//!
//! - Area lights (quads, emissive triangles): [`area_sample`] (the one light of a scene, or a
//!   light chosen by the light selection, from u or a dimension of its own, placed by
//!   `--light-warp`), [`towards`] (direction, distance, both cosines, lit lanes) and
//!   [`point_shadow`] (the ray stopping short of the light point).
//! - The environment (`constant`/`--sky`, `envmap`): [`env_sample`] and [`Shading::env_event`]
//!   (a shadow ray to infinity).
//! - Delta lights: [`Shading::delta_events`] (each light once, weight 1; [`delta_tfar`]).
//!
//! Both light the side of the viewer, and on the lanes [`Shading::with_below`] names (a BSDF that
//! transmits, in the path tracer) the other side too: `cos` is then |cos(th_i)| and the caller
//! starts the shadow ray below the surface (where the direction goes below the geometric normal).
//!
//! What an integrator makes of a term stays in its file: `direct` sums groups of samples and
//! scales them once, the path tracer weighs with MIS and its throughput. Their products are
//! ordered differently, and both keep their images bit for bit.

use super::settings::Integrator;
use crate::accel::RayHit8;
use crate::bsdf::LobeSet;
use crate::light::delta::DeltaLight;
use crate::light::emitters::LightSample8;
use crate::light::warp::LightWarp;
use crate::profile::{leaf, Phase};
use crate::scene::build::Scene;
use crate::scene::desc::ImportanceSampling;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Frame8, Mask8, Vec3x8, F8};
use glam::Vec3;

/// A packet of shading points as next events see it: the hits (with their material, `sh.mat`),
/// their shading frame and the direction to the viewer in it, built once per packet.
pub struct Shading<'a> {
    /// the hits, with the material of every lane (`sh.mat`, by reference: it is large, and
    /// copying it costs)
    pub sh: &'a SurfaceHit8,
    /// the shading frame (normal `sh.n`; by reference: a copy costs)
    pub frame: &'a Frame8,
    /// the direction to the viewer, local
    pub wo: Vec3x8,
    /// the strategy whose pdf [`Shading::eval`] returns
    pub strategy: ImportanceSampling,
    /// lanes whose BSDF transmits: next events light them from below the surface too (none
    /// unless [`Shading::with_below`] says so)
    pub below: Mask8,
}

/// Where an area light's next event points: [`towards`].
pub struct PointTerm {
    /// unit direction to the light point
    pub wi: Vec3x8,
    /// squared distance
    pub d2: F8,
    /// 1 / distance
    pub inv_d: F8,
    /// cos(th_i) at the shading point (shading normal)
    pub cos_i: F8,
    /// cos(th_l) at the light point
    pub cos_l: F8,
    /// the `active` lanes the point lights: both cosines positive, d > 0 and, on smooth-shaded
    /// lanes, the light above the geometric surface too
    pub lit: Mask8,
}

impl<'a> Shading<'a> {
    /// The shading points of the hits `sh` in their shading `frame` (from
    /// `context::shading_frame`), their BSDF (`sh.mat`) evaluated under `strategy`.
    #[inline]
    pub fn new(sh: &'a SurfaceHit8, frame: &'a Frame8, strategy: ImportanceSampling) -> Self {
        let wo = frame.to_local(sh.wo);
        Self { sh, frame, wo, strategy, below: F8::ZERO }
    }

    /// The same shading points, lit from below the surface too on the lanes `below` (where the
    /// BSDF transmits): environment and delta next events there take directions on either side.
    #[inline]
    pub fn with_below(self, below: Mask8) -> Self {
        Self { below, ..self }
    }

    /// The lanes lit from the local direction `wi_l` (world `wi`): above the shading surface and
    /// leaving the geometric one ([`leaves`]), or, on the [`Shading::below`] lanes, below both.
    #[inline]
    fn sides(&self, wi_l: Vec3x8, wi: Vec3x8) -> Mask8 {
        let above = wi_l.z.simd_gt(F8::ZERO) & self.leaves(wi);
        if self.below.none() {
            return above;
        }
        let under = !self.sh.smooth | self.sh.ng.dot(wi).simd_lt(F8::ZERO);
        above | (self.below & wi_l.z.simd_lt(F8::ZERO) & under)
    }

    /// [`leaves`] at these shading points.
    #[inline]
    pub fn leaves(&self, wi: Vec3x8) -> Mask8 {
        leaves(self.sh, wi)
    }

    /// The BSDF value and pdf (under `strategy`) of the local direction `wi_l` on lanes `lit`.
    #[inline]
    pub fn eval<L: LobeSet>(&self, wi_l: Vec3x8, lit: Mask8) -> (Vec3x8, F8) {
        let _p = leaf(Phase::BsdfEval);
        self.sh.mat.eval_pdf_k::<L>(self.strategy, self.wo, wi_l, lit)
    }

    /// The environment's next event for the direction `e` (from [`env_sample`]) at the lanes
    /// `shade` with throughput `beta`: the lit lanes (in front of the shading and geometric
    /// surfaces, or behind both on [`Shading::below`] lanes; pdf > 0), the world direction and
    /// `beta f L |cos| / pdf w`, with the weight `w`
    /// from `weight(pdf_bsdf)`; None where no lane is lit. Its shadow ray goes to infinity.
    #[inline]
    pub fn env_event<L: LobeSet>(
        &self,
        e: &EnvSample,
        beta: Vec3x8,
        shade: Mask8,
        weight: impl FnOnce(F8, Mask8) -> F8,
    ) -> Option<(Mask8, Vec3x8, Vec3x8)> {
        let lit = shade & e.pdf.simd_gt(F8::ZERO) & self.sides(e.wi_l, e.wi);
        if lit.none() {
            return None;
        }
        let (f, pdf_b) = self.eval::<L>(e.wi_l, lit);
        let g = lit.select(e.wi_l.z.abs() / e.pdf * weight(pdf_b, lit), F8::ZERO);
        Some((lit, e.wi, beta.mul_elem(f).mul_elem(e.le).scale(g)))
    }

    /// The delta lights' next events at the lanes `shade` with throughput `beta`: each light
    /// once, weight 1 (no BSDF sample can reach a delta light). Calls `push` with (lit lanes,
    /// unit direction, shadow-ray end, `beta f li |cos|`) per light that lights a lane (from
    /// below too on [`Shading::below`] lanes).
    #[inline]
    pub fn delta_events<L: LobeSet>(
        &self,
        scene: &Scene,
        beta: Vec3x8,
        shade: Mask8,
        mut push: impl FnMut(Mask8, Vec3x8, F8, Vec3x8),
    ) {
        for light in &scene.delta {
            let (wi, dist, li, ok) = {
                let _p = leaf(Phase::Emitter);
                light.sample_x8(self.sh.p, shade)
            };
            let wi_l = self.frame.to_local(wi);
            let lit = ok & self.sides(wi_l, wi);
            if lit.none() {
                continue;
            }
            let f = self.eval::<L>(wi_l, lit).0;
            let c = beta.mul_elem(f).mul_elem(li).scale(lit.select(wi_l.z.abs(), F8::ZERO));
            push(lit, wi, delta_tfar(scene, light, dist), c);
        }
    }
}

/// The lanes of the hits `sh` where direction `wi` leaves the surface: all but smooth-shaded
/// lanes, where it must also be above the geometric surface.
#[inline]
pub fn leaves(sh: &SurfaceHit8, wi: Vec3x8) -> Mask8 {
    !sh.smooth | sh.ng.dot(wi).simd_gt(F8::ZERO)
}

/// The direction and geometry of the light points `ls` seen from the hits `sh` on lanes `active`
/// (no BSDF: a term that lights no lane costs no frame or material).
#[inline]
pub fn towards(sh: &SurfaceHit8, ls: &LightSample8, active: Mask8) -> PointTerm {
    let to = ls.y - sh.p;
    let d2 = to.length_squared();
    let inv_d = F8::ONE / d2.sqrt();
    let wi = to.scale(inv_d);
    let cos_i = sh.n.dot(wi);
    let cos_l = -ls.normal.dot(wi);
    let lit = active & cos_i.simd_gt(F8::ZERO) & cos_l.simd_gt(F8::ZERO) & d2.simd_gt(F8::ZERO) & leaves(sh, wi);
    PointTerm { wi, d2, inv_d, cos_i, cos_l, lit }
}

/// How the area light of a next event is chosen ([`area_sample`]).
#[derive(Clone, Copy)]
pub enum AreaChoice {
    /// the scene's one light, pmf 1 (no choice drawn)
    Certain,
    /// by the light selection from the light point's u, remapped (`--light-choice reuse`)
    Reuse,
    /// by the light selection from a number of its own (`--light-choice dimension`)
    Drawn(F8),
}

/// A point on an area light for the unit-square sample `uw` at the shading lanes `shade` of `sh`:
/// the light chosen as `choice` says (its `inv_pmf` in the sample), placed by `--light-warp`,
/// written into `ls`. Returns the lanes that got one. The sample is written in place (returned,
/// its 448 bytes were copied out with `memcpy`: 2-3 % of a direct render on Zen 4).
#[inline(always)]
pub fn area_sample(
    it: &Integrator,
    scene: &Scene,
    sh: &SurfaceHit8,
    shade: Mask8,
    choice: AreaChoice,
    (u, w): (F8, F8),
    ls: &mut LightSample8,
) -> Mask8 {
    let _p = leaf(Phase::Emitter);
    let ok = match choice {
        AreaChoice::Certain => {
            // The one light's own sampling and warp (the same points as through the selection's
            // `place_one_x8` and `Emitters::warp_x8`, without their per-lane look-ups).
            let e = &scene.emitters.list[0];
            *ls = e.sample_x8(u, w);
            scene.emitters.warp_one_x8(0, it.light_warp, ls, sh.p, shade);
            return shade;
        }
        AreaChoice::Reuse => it.light_sampler.sample_point_reuse_x8(&scene.emitters, sh.p, sh.n, shade, (u, w), ls),
        AreaChoice::Drawn(uc) => it.light_sampler.sample_point_x8(&scene.emitters, uc, sh.p, sh.n, shade, (u, w), ls),
    };
    scene.emitters.warp_x8(it.light_warp, ls, sh.p, ok);
    ok
}

/// The direction (unnormalized) and interval end of a shadow ray from `o` to the light point `y`
/// at distance 1 / `inv_d` from the shading point: it stops short of the light by the scene's
/// offset at `y`.
#[inline]
pub fn point_shadow(scene: &Scene, o: Vec3x8, y: Vec3x8, inv_d: F8) -> (Vec3x8, F8) {
    (y - o, F8::ONE - scene.offset_eps(y) * inv_d)
}

/// The end of a delta light's shadow ray at distance `dist`: short of a point light by the
/// scene's offset there, infinity for a directional one.
#[inline]
pub fn delta_tfar(scene: &Scene, light: &DeltaLight, dist: F8) -> F8 {
    match light.position() {
        Some(y) => dist - scene.offset_eps(Vec3x8::splat(y)),
        None => F8::splat(f32::INFINITY),
    }
}

/// How the constant environment is sampled ([`env_sample`]).
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum SkySampling {
    /// cosine-weighted about the shading normal (`direct`: light sampling alone, no MIS)
    Cosine,
    /// the sky's own distribution, uniform over the hemisphere ([`crate::light::sky::Sky`]; the
    /// path tracer's, MIS-weighted against the BSDF)
    Sky,
}

/// An environment direction drawn for a next event.
pub struct EnvSample {
    /// world direction
    pub wi: Vec3x8,
    /// the same in the shading frame (its z is cos(th_i))
    pub wi_l: Vec3x8,
    /// solid-angle pdf
    pub pdf: F8,
    /// radiance arriving along it
    pub le: Vec3x8,
}

/// A direction from the scene's environment (`constant` sampled as `sky`, or the envmap's
/// luminance distribution) for the unit-square sample `uw` on lanes `shade` of the shading
/// `frame`; None without an environment.
#[inline]
pub fn env_sample(
    scene: &Scene,
    sky: SkySampling,
    frame: &Frame8,
    (u, w): (F8, F8),
    shade: Mask8,
) -> Option<EnvSample> {
    let _p = leaf(Phase::Emitter);
    match (&scene.sky, &scene.envmap) {
        (Some(s), _) if sky == SkySampling::Sky => {
            let (wi_l, pdf) = s.sample_x8(u, w, shade);
            Some(EnvSample { wi: frame.to_world(wi_l), wi_l, pdf, le: Vec3x8::splat(s.radiance) })
        }
        (Some(s), _) => {
            // Cosine-weighted about the shading normal: for a diffuse surface the estimate is
            // `L kd` wherever the sky is visible (Mitsuba's MIS of light and BSDF samples comes
            // close to it; uniform hemisphere samples had 12 times its variance on a plane, which
            // its z-test rejects). Cosines are measured from the world direction.
            let (wl, pdf) = crate::sampling::sample_cosine_hemisphere_x8([u, w], shade);
            let wi = frame.to_world(wl);
            Some(EnvSample { wi, wi_l: frame.to_local(wi), pdf, le: Vec3x8::splat(s.radiance) })
        }
        (None, Some(env)) => {
            let (wi, pdf, le) = env.sample_x8(u, w, shade);
            Some(EnvSample { wi, wi_l: frame.to_local(wi), pdf, le })
        }
        (None, None) => None,
    }
}

/// Solid-angle pdf of a next event at a light hit (the path tracer's at a vertex, `direct`'s at
/// a BSDF sample's hit) for a light chosen with probability `pmf` (per lane):
/// pmf d^2 / (A cos_l), or pmf / S where `--light-warp solid-angle` samples the light by its solid
/// angle S seen from the ray's origin (`Emitters::solid_angle_x8`); zero where `is_light` is off
/// or `pmf` is 0.
#[inline]
pub fn light_pdf_at_hit_pmf(
    it: &Integrator,
    scene: &Scene,
    sh: &SurfaceHit8,
    rh: &RayHit8,
    is_light: Mask8,
    pmf: F8,
) -> F8 {
    let ids = sh.light.to_array();
    let pick = |i: usize| scene.emitters.list.get(ids[i] as usize);
    let area = F8::new(std::array::from_fn(|i| pick(i).map_or(1.0, |l| l.area)));
    // (A sphere light's normal is the hit's: `normal_at`.)
    let ln = Vec3x8::from_lanes(std::array::from_fn(|i| pick(i).map_or(Vec3::Z, |l| l.normal_at(sh.p.lane(i)))));
    let t = F8::new(rh.ray.tfar);
    let cos_l = ln.dot(sh.wo);
    let mut p = pmf * t * t / (area * cos_l);
    if it.light_warp == LightWarp::SolidAngle {
        let r = &rh.ray;
        let origin = Vec3x8::new(F8::new(r.org_x), F8::new(r.org_y), F8::new(r.org_z));
        let (omega, warped) = scene.emitters.solid_angle_x8(sh.light, origin, is_light);
        p = warped.select(pmf / omega, p);
    }
    is_light.select(p, F8::ZERO)
}

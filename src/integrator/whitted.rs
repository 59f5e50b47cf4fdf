//! `raytracer` (hw1): Whitted ray tracing with point and directional lights.
//!
//! At every hit: ambient + emission + sum over lights of
//! V * (kd max(n.l, 0) + ks max(n.h, 0)^s) * colour (/ (c0 + c1 d + c2 d^2) for point lights),
//! h = normalize(l + wo), V from a shadow ray; plus ks times the radiance along the mirror
//! direction r = 2 (n.wo) n - wo. The term is not gated on n.l (the format's formula as stated).
//! `maxdepth` is the maximum number of mirror bounces after the camera hit (negative: 64).
//! Quad lights, if any, are visible emitters only (`le`). Packets keep dead lanes masked.

use super::context::{masked, TileCtx, Tracer};
use super::estimator::Estimator;
use super::primary::{self, Wave};
use super::samples::{Dim, CAMERA};
use super::settings::Integrator;
use super::stats::RayKind;
use crate::accel::{Hits8, Ray8, RayHit8};
use crate::bsdf::LobeSet;
use crate::scene::build::Scene;
use crate::scene::desc::IntegratorKind;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Mask8, Vec3x8, F8};

/// Mirror bounces when `maxdepth` is negative (unbounded is not meaningful without roulette).
const UNBOUNDED_DEPTH: i32 = 64;

/// The `raytracer` integrator: the camera-hit wavefront, shaded by [`radiance`] (no sampler
/// dimension besides the pixel jitter).
pub struct Whitted;

impl Estimator for Whitted {
    const KIND: IntegratorKind = IntegratorKind::RayTracer;
    const DIMS: &'static [Dim] = &[CAMERA];
    type Scratch = Wave;

    fn tile<L: LobeSet>(
        it: &Integrator,
        ctx: &mut TileCtx,
        wave: &mut Wave,
        samples: std::ops::Range<u32>,
        out: &mut Vec<Vec3x8>,
    ) {
        primary::tile(ctx, wave, samples, out, |ctx, hits, _, out| {
            let scene = ctx.scene;
            for (o, sh) in out.iter_mut().zip(hits) {
                *o += radiance(scene, it.max_depth, sh, &mut ctx.tracer);
            }
        });
    }
}

/// Radiance added to the camera hit `sh0` (its emission `emitted + le` is already counted by the
/// caller): local shading of the camera hit and every mirror bounce, weighted by the product of ks.
pub fn radiance(scene: &Scene, max_depth: i32, sh0: &SurfaceHit8, tracer: &mut Tracer) -> Vec3x8 {
    let bounces = if max_depth < 0 { UNBOUNDED_DEPTH } else { max_depth };
    let mut l_out = Vec3x8::ZERO;
    let mut sh = *sh0;
    let mut alive = sh.valid;
    let mut weight = Vec3x8::splat(glam::Vec3::ONE);
    let mut depth = 0;
    loop {
        if alive.none() {
            break;
        }
        let mut local = local_shading(scene, &sh, alive, tracer);
        if depth > 0 {
            local += sh.emitted + sh.le;
        }
        l_out += masked(weight.mul_elem(local), alive);
        if depth >= bounces {
            break;
        }
        weight = weight.mul_elem(sh.mat.ks);
        alive &= weight.max_elem().simd_gt(F8::ZERO);
        if alive.none() {
            break;
        }
        // Mirror ray from the offset hit point.
        // Mirror about the shading normal; where that would go into the geometric surface
        // (smooth-shaded lanes only), about the geometric normal instead.
        let r = sh.n.scale(F8::splat(2.0) * sh.n.dot(sh.wo)) - sh.wo;
        let r_geo = sh.ng.scale(F8::splat(2.0) * sh.ng.dot(sh.wo)) - sh.wo;
        let r = Vec3x8::select(sh.smooth & !sh.ng.dot(r).simd_gt(F8::ZERO), r_geo, r);
        let org = sh.ng.mul_add(scene.offset_eps(sh.p), sh.p);
        let mut rh = RayHit8::default();
        let active = rh.ray.set(org, r, F8::ZERO, F8::splat(f32::INFINITY), alive);
        let traced = tracer.intersect(&mut rh, RayKind::Bounce, active);
        sh = scene.gather(rh.ray.org(), rh.ray.dir(), &Hits8::from_rayhit(&rh, traced));
        alive &= sh.valid;
        depth += 1;
    }
    l_out
}

/// Ambient + Blinn-Phong from every point and directional light with shadow rays, on `alive` lanes
/// (emission excluded); zero elsewhere.
fn local_shading(scene: &Scene, sh: &SurfaceHit8, alive: Mask8, tracer: &mut Tracer) -> Vec3x8 {
    let mut acc = masked(sh.ambient, alive);
    let eps = scene.offset_eps(sh.p);
    let o = sh.ng.mul_add(eps, sh.p);
    let mut shade = |wi: Vec3x8, to: Vec3x8, tfar: F8, colour: Vec3x8, tracer: &mut Tracer| {
        let f = blinn_phong(sh, wi, alive);
        let lit = alive & f.max_elem().simd_gt(F8::ZERO);
        if lit.none() {
            return;
        }
        let (mut ray, lit) = Ray8::new(o, to, F8::ZERO, tfar, lit);
        let occluded = tracer.occluded(&mut ray, lit);
        acc += masked(f.mul_elem(colour), lit & !occluded);
    };
    for pl in &scene.desc.point_lights {
        let pos = Vec3x8::splat(pl.position);
        let to_p = pos - sh.p;
        let d = to_p.length();
        let wi = to_p.normalize_or_zero();
        let att = pl.attenuation;
        let denom = F8::splat(att.z).mul_add(d * d, F8::splat(att.y).mul_add(d, F8::splat(att.x)));
        let colour = Vec3x8::splat(pl.color).scale(F8::ONE / denom);
        // Shadow ray from the offset point to the light, stopping just short of it.
        let inv_d = alive.select(F8::ONE / d, F8::ZERO);
        let tfar = F8::ONE - eps * inv_d;
        shade(wi, pos - o, tfar, colour, tracer);
    }
    for dl in &scene.desc.directional_lights {
        let wi = Vec3x8::splat(dl.direction.normalize_or_zero());
        shade(wi, wi, F8::splat(f32::INFINITY), Vec3x8::splat(dl.color), tracer);
    }
    acc
}

/// kd max(n.l, 0) + ks max(n.h, 0)^s with h = normalize(l + wo); zero on inactive lanes.
#[inline]
fn blinn_phong(sh: &SurfaceHit8, wi: Vec3x8, active: Mask8) -> Vec3x8 {
    let _p = crate::profile::leaf(crate::profile::Phase::BsdfEval);
    let cos_l = sh.n.dot(wi).max(F8::ZERO);
    let h = (wi + sh.wo).normalize_or_zero();
    let nh = sh.n.dot(h);
    let has_spec = nh.simd_gt(F8::ZERO);
    // x^s = exp(s ln x), only where x > 0.
    let m = &sh.mat;
    let pow = has_spec.select((m.shininess * has_spec.select(nh, F8::ONE).ln()).exp(), F8::ZERO);
    masked(m.kd.scale(cos_l) + m.ks.scale(pow), active)
}

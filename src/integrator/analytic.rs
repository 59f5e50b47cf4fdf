//! `analyticdirect` (hw2): exact polygonal irradiance from every area light, without visibility.

use super::context::TileCtx;
use super::estimator::Estimator;
use super::primary::{self, Wave};
use super::samples::{Dim, CAMERA};
use super::settings::Integrator;
use crate::bsdf::LobeSet;
use crate::light::polygonal::polygon_phi_x8;
use crate::scene::build::Scene;
use crate::scene::desc::IntegratorKind;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Vec3x8, F8, U8};
use std::f32::consts::PI;

/// Radiance without emission: kd/pi * sum over area lights of L * max(0, Phi . n) (no visibility;
/// as for quads, the receiver must see the whole light in its upper hemisphere and on its emitting
/// side for this to be exact).
#[inline(always)]
pub fn radiance(scene: &Scene, sh: &SurfaceHit8) -> Vec3x8 {
    let mut l_out = Vec3x8::ZERO;
    let shade = sh.valid & F8::from_bits(sh.light.simd_eq(U8::splat(u32::MAX)));
    // Quad lights, then emissive triangles (same polygon formula; `Emitter::corners` winds both alike).
    for light in &scene.emitters.list {
        let phi = if light.sphere {
            sphere_phi_x8(sh.p, light.a, light.radius)
        } else {
            polygon_phi_x8(sh.p, &light.corners(), shade)
        };
        let e = phi.dot(sh.n).max(F8::ZERO);
        l_out += sh.mat.kd.mul_elem(Vec3x8::splat(light.radiance)).scale(e * F8::splat(1.0 / PI));
    }
    l_out
}

/// The irradiance vector of a unit-radiance sphere (centre `c`, radius `r`) at `p`: `pi (r/d)^2`
/// towards the centre (exact where the whole sphere is above the receiver's horizon, as the
/// polygon formula is; zero from inside).
#[inline]
fn sphere_phi_x8(p: Vec3x8, c: glam::Vec3, r: f32) -> Vec3x8 {
    let to = Vec3x8::splat(c) - p;
    let d2 = to.length_squared();
    let r2 = F8::splat(r * r);
    let k = d2.simd_gt(r2).select(F8::splat(PI) * r2 / (d2 * d2.sqrt()), F8::ZERO);
    to.scale(k)
}

/// The `analyticdirect` integrator: the camera-hit wavefront, shaded by [`radiance`].
pub struct Analytic;

impl Estimator for Analytic {
    const KIND: IntegratorKind = IntegratorKind::AnalyticDirect;
    const DIMS: &'static [Dim] = &[CAMERA];
    type Scratch = Wave;

    fn tile<L: LobeSet>(
        _: &Integrator,
        ctx: &mut TileCtx,
        wave: &mut Wave,
        samples: std::ops::Range<u32>,
        out: &mut Vec<Vec3x8>,
    ) {
        primary::tile(ctx, wave, samples, out, |ctx, hits, _, out| {
            for (o, sh) in out.iter_mut().zip(hits) {
                *o += radiance(ctx.scene, sh);
            }
        });
    }
}

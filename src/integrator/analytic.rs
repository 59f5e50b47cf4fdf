//! `analyticdirect` (hw2): exact polygonal irradiance from every area light, without visibility.

use crate::light::polygonal::polygon_phi_x8;
use crate::scene::build::{Scene, SurfaceHit8};
use crate::simd::{Vec3x8, F8, U8};
use std::f32::consts::PI;

/// Radiance without emission: kd/pi * sum over area lights of L * max(0, Phi . n) (no visibility;
/// as for quads, the receiver must see the whole light in its upper hemisphere and on its emitting
/// side for this to be exact).
pub fn radiance(scene: &Scene, sh: &SurfaceHit8) -> Vec3x8 {
    let mut l_out = Vec3x8::ZERO;
    let shade = sh.valid & F8::from_bits(sh.light.simd_eq(U8::splat(u32::MAX)));
    // Quad lights, then emissive triangles (same polygon formula; `Emitter::corners` winds both alike).
    for light in &scene.emitters.list {
        let phi = polygon_phi_x8(sh.p, &light.corners(), shade);
        let e = phi.dot(sh.n).max(F8::ZERO);
        l_out += sh.kd.mul_elem(Vec3x8::splat(light.radiance)).scale(e * F8::splat(1.0 / PI));
    }
    l_out
}

//! Integrators: radiance of one 4x2 packet of camera samples. They reach Embree only through
//! `scene::build::Scene` and `accel` packets.
//!
//! Directions: `wo` points to the viewer, `wi` to the light; pdfs per unit solid angle unless named
//! `_area`. Dimensions given to the sampler: [`DIM_CAMERA`] for the pixel jitter, then
//! [`DIM_LIGHT_BASE`] + light index for the light samples of `direct`.

use crate::accel::{Hits8, Ray8, RayHit8};
use crate::light::polygonal::polygon_phi_x8;
use crate::render::PixelPacket;
use crate::sampler::{PointSet, SamplerKind};
use crate::scene::build::{Scene, SurfaceHit8};
use crate::scene::desc::IntegratorKind;
use crate::simd::{Mask8, Vec3x8, F8, U8};
use glam::Vec3;
use serde::Serialize;
use std::f32::consts::PI;

/// Sampler dimension of the camera (pixel) jitter.
pub const DIM_CAMERA: u32 = 0;
/// First sampler dimension of light sampling; light `l` uses `DIM_LIGHT_BASE + l`.
pub const DIM_LIGHT_BASE: u32 = 16;

/// Ray and packet counters of a render (summed over threads).
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq, Eq)]
pub struct Counters {
    /// camera rays traced
    pub camera: u64,
    /// shadow rays traced
    pub shadow: u64,
    /// bounce rays traced
    pub bounce: u64,
    /// packets sent to Embree
    pub packets: u64,
    /// active lanes summed over those packets
    pub packet_lanes: u64,
    /// samples whose value was not finite (replaced by zero; must stay 0)
    pub nonfinite: u64,
}

impl Counters {
    /// Adds another set of counters.
    pub fn merge(&mut self, o: &Counters) {
        self.camera += o.camera;
        self.shadow += o.shadow;
        self.bounce += o.bounce;
        self.packets += o.packets;
        self.packet_lanes += o.packet_lanes;
        self.nonfinite += o.nonfinite;
    }
    /// All rays traced.
    pub fn total_rays(&self) -> u64 {
        self.camera + self.shadow + self.bounce
    }
    /// Mean fraction of active lanes in the packets sent to Embree.
    pub fn occupancy(&self) -> f64 {
        self.packet_lanes as f64 / (8.0 * self.packets.max(1) as f64)
    }
    fn packet(&mut self, traced: Mask8) -> u64 {
        let n = traced.to_bitmask().count_ones() as u64;
        self.packets += 1;
        self.packet_lanes += n;
        n
    }
}

/// Optional capture of every packet traced, for measuring Embree's raw rate on the same rays.
#[derive(Default)]
pub struct RayLog {
    /// camera packets (rays and their active masks)
    pub camera: Vec<(RayHit8, Mask8)>,
    /// shadow packets
    pub shadow: Vec<(Ray8, Mask8)>,
}

/// An integrator with its settings resolved from the scene and the command line.
#[derive(Clone, Debug)]
pub struct Integrator {
    /// which estimator
    pub kind: IntegratorKind,
    /// samples per pixel
    pub spp: u32,
    /// base seed
    pub seed: u64,
    /// pixel sample layout (over the spp samples of a pixel)
    pub pixel_set: PointSet,
    /// light sample layout (over the light samples of one pixel sample)
    pub light_set: PointSet,
}

impl Integrator {
    /// Settings from the scene, overridden by explicit choices.
    pub fn new(scene: &Scene, spp: u32, seed: u64, light_sampler: Option<SamplerKind>, light_samples: Option<u32>) -> Self {
        let d = &scene.desc;
        let n_light = light_samples.unwrap_or(d.light_samples).max(1);
        let light_kind = light_sampler.unwrap_or(if d.light_stratify { SamplerKind::Stratified } else { SamplerKind::Independent });
        Self {
            kind: d.integrator,
            spp: spp.max(1),
            seed,
            pixel_set: PointSet::new(SamplerKind::Stratified, spp.max(1)),
            light_set: PointSet::new(light_kind, n_light),
        }
    }

    /// Camera rays of packet `pk` for pixel sample `s`: origins and unit directions.
    #[inline]
    pub fn camera_rays(&self, scene: &Scene, pk: &PixelPacket, s: u32) -> (Vec3x8, Vec3x8) {
        let (jx, jy) = self.pixel_set.point_x8(pk.pixel, U8::splat(0), DIM_CAMERA, U8::splat(s), self.seed);
        let dir = scene.camera.dirs8(pk.x + jx, pk.y + jy);
        (Vec3x8::splat(scene.camera.eye), dir)
    }

    /// Radiance of pixel sample `s` for the 8 pixels of `pk` (inactive lanes return zero).
    pub fn radiance(&self, scene: &Scene, pk: &PixelPacket, s: u32, c: &mut Counters) -> Vec3x8 {
        self.radiance_logged(scene, pk, s, c, None)
    }

    /// [`Integrator::radiance`], optionally recording every packet traced into `log`.
    pub fn radiance_logged(&self, scene: &Scene, pk: &PixelPacket, s: u32, c: &mut Counters, mut log: Option<&mut RayLog>) -> Vec3x8 {
        // Camera packet: coherent primary rays from a 4x2 tile.
        let (org, dir) = self.camera_rays(scene, pk, s);
        let mut rh = RayHit8::default();
        let active = rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), pk.active);
        if let Some(l) = log.as_deref_mut() {
            l.camera.push((rh, active));
        }
        let traced = scene.accel.intersect8(&mut rh, true, active);
        c.camera += c.packet(traced);
        let hits = Hits8::from_rayhit(&rh, traced);
        if hits.hit.none() {
            return Vec3x8::ZERO;
        }
        let sh = scene.gather(org, dir, &hits);
        match self.kind {
            IntegratorKind::AnalyticDirect => analytic_direct(scene, &sh),
            _ => self.direct(scene, &sh, pk, s, c, log),
        }
    }

    /// `direct`: emission plus, for each light, the mean over the light samples of
    /// L f cos(th_i) cos(th_l) / (d^2 pdf_area) with visibility from shadow packets.
    fn direct(&self, scene: &Scene, sh: &SurfaceHit8, pk: &PixelPacket, s: u32, c: &mut Counters, mut log: Option<&mut RayLog>) -> Vec3x8 {
        let mut l_out = masked(sh.emitted, sh.valid);
        // Lights shade nothing themselves (black, one-sided emitters).
        let shade = sh.valid & F8::from_bits(sh.light.simd_eq(U8::splat(u32::MAX)).into());
        if shade.none() {
            return l_out;
        }
        let n_light = self.light_set.n();
        let inv_n = F8::splat(1.0 / n_light as f32);
        let eps = scene.offset_eps(sh.p);
        let sample_idx = U8::splat(s);
        for (li, light) in scene.lights.iter().enumerate() {
            let dim = DIM_LIGHT_BASE + li as u32;
            let mut acc = Vec3x8::ZERO;
            for k in 0..n_light {
                // Sample a point on the light (uniform in area, pdf_area = 1/A).
                let (u, v) = self.light_set.point_x8(pk.pixel, sample_idx, dim, U8::splat(k), self.seed);
                let y = Vec3x8::splat(light.a) + Vec3x8::splat(light.ab).scale(u) + Vec3x8::splat(light.ac).scale(v);
                let to = y - sh.p;
                let d2 = to.length_squared();
                let d = d2.sqrt();
                let wi = to.scale(F8::ONE / d);
                let cos_i = sh.n.dot(wi);
                let cos_l = -(Vec3x8::splat(light.normal).dot(wi));
                let lit = shade & cos_i.simd_gt(F8::ZERO) & cos_l.simd_gt(F8::ZERO) & d2.simd_gt(F8::ZERO);
                if lit.none() {
                    continue;
                }
                // Shadow packet from the offset point towards the light sample, stopping short of it.
                let o = sh.n.mul_add(eps, sh.p);
                let dir = y - o;
                let tfar = F8::ONE - scene.offset_eps(y) / d;
                let mut ray = Ray8::default();
                let lit = ray.set(o, dir, F8::ZERO, tfar, lit);
                if let Some(l) = log.as_deref_mut() {
                    l.shadow.push((ray, lit));
                }
                let occluded = scene.accel.occluded8(&mut ray, lit);
                c.shadow += c.packet(lit);
                let visible = lit & !occluded;
                let f = brdf_eval(sh, wi, visible);
                let g = cos_i * cos_l / d2;
                acc += f.scale(masked_f(g, visible));
            }
            let scale = inv_n * F8::splat(light.area);
            l_out += acc.mul_elem(Vec3x8::splat(light.radiance)).scale(scale);
        }
        l_out
    }
}

/// `analyticdirect`: emission plus kd/pi * sum over lights of L * max(0, Phi . n) (no visibility).
fn analytic_direct(scene: &Scene, sh: &SurfaceHit8) -> Vec3x8 {
    let mut l_out = masked(sh.emitted, sh.valid);
    let shade = sh.valid & F8::from_bits(sh.light.simd_eq(U8::splat(u32::MAX)).into());
    for light in &scene.lights {
        let phi = polygon_phi_x8(sh.p, &light.corners(), shade);
        let e = phi.dot(sh.n).max(F8::ZERO);
        l_out += sh.kd.mul_elem(Vec3x8::splat(light.radiance)).scale(e * F8::splat(1.0 / PI));
    }
    l_out
}

/// Modified Phong (the format's definition) in world space:
/// kd/pi + ks (s+2)/(2 pi) max(0, r . wi)^s with r the mirror of wo about n; zero on inactive lanes.
#[inline]
fn brdf_eval(sh: &SurfaceHit8, wi: Vec3x8, active: Mask8) -> Vec3x8 {
    let diffuse = sh.kd.scale(F8::splat(1.0 / PI));
    let r = sh.n.scale(F8::splat(2.0) * sh.n.dot(sh.wo)) - sh.wo;
    let c = r.dot(wi).max(F8::ZERO);
    let spec = c.powf_simd(sh.shininess) * (sh.shininess + F8::splat(2.0)) * F8::splat(0.5 / PI);
    let has_spec = c.simd_gt(F8::ZERO);
    let f = diffuse + sh.ks.scale(has_spec.select(spec, F8::ZERO));
    masked(f, active)
}

#[inline]
fn masked(v: Vec3x8, m: Mask8) -> Vec3x8 {
    Vec3x8::new(m.select(v.x, F8::ZERO), m.select(v.y, F8::ZERO), m.select(v.z, F8::ZERO))
}

#[inline]
fn masked_f(v: F8, m: Mask8) -> F8 {
    m.select(v, F8::ZERO)
}

/// Scalar radiance of a diffuse point lit by one quad light, exact (for tests and the report).
pub fn analytic_irradiance_scalar(x: Vec3, n: Vec3, corners: &[Vec3; 4]) -> f32 {
    crate::light::polygonal::polygon_phi(x, corners).dot(n).max(0.0)
}

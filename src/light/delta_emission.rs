//! Emission sampling of the delta lights (see `light/emission.rs`): a ray leaving the light with
//! weight `I(w) / p(w)`, one function per kind, and each kind's emitted power.
//! - `point`: the direction uniform over the sphere, weight `4 pi I`;
//! - `spot`: uniform in the cone of the cutoff angle, weight `I s(w) t(uv) 2 pi (1 - cos cutoff)`;
//! - `projector`: a point uniform over the image plane at z = 1 (`(u, v)` its texture coordinates),
//!   weight `pi scale E(uv) A` with `A` the plane's area (its intensity is `pi scale E / cos^3`,
//!   its pdf per solid angle `1 / (A cos^3)`);
//! - `directional`: not sampled (it needs the scene's bounding disk); the particle tracer refuses
//!   it when the scene is built.

use super::{DeltaLight, Projector, Spot};
use crate::light::emission::{uniform_cone, uniform_sphere, EmissionSample};
use glam::Vec3;
use std::f32::consts::PI;

impl Spot {
    /// Intensity towards the unit local direction `w` (+z the axis): Mitsuba's falloff times the
    /// texture (as [`DeltaLight::sample`] applies them).
    fn intensity(&self, w: Vec3) -> Vec3 {
        let cos = w.z;
        if cos <= self.cos_cutoff {
            return Vec3::ZERO;
        }
        let mut l = self.intensity;
        if let Some(t) = &self.texture {
            let k = 0.5 / (w.z * self.uv_factor);
            l *= t.eval(0.5 + w.x * k, 0.5 + w.y * k);
        }
        if cos < self.cos_beam {
            l *= (self.cutoff - cos.clamp(-1.0, 1.0).acos()) * self.inv_transition;
        }
        l
    }
}

impl Projector {
    /// Area of the image plane at z = 1.
    fn plane_area(&self) -> f32 {
        4.0 * self.tan_x * self.tan_x / self.aspect
    }
}

/// Mean texel of an image.
fn mean(im: &crate::light::desc::RgbImage) -> Vec3 {
    im.texels.iter().fold(Vec3::ZERO, |a, &t| a + t.max(Vec3::ZERO)) / im.texels.len().max(1) as f32
}

impl DeltaLight {
    /// A ray leaving the light for `u` (2D), or None for `directional` or where the light sends
    /// nothing.
    pub fn sample_emission(&self, u: (f32, f32)) -> Option<EmissionSample> {
        let (p, dir, weight) = match self {
            Self::Directional { .. } => return None,
            Self::Point { position, intensity } => {
                let (dir, pdf) = uniform_sphere(u);
                (*position, dir, *intensity / pdf)
            }
            Self::Spot(s) => {
                let (local, pdf) = uniform_cone(u, s.cos_cutoff);
                let to_world = s.world_to_local.inverse();
                let dir = to_world.transform_vector3(local).normalize_or_zero();
                (s.position, dir, s.intensity(local) / pdf)
            }
            Self::Projector(pr) => {
                let x = (0.5 - u.0) * 2.0 * pr.tan_x;
                let y = (0.5 - u.1) * 2.0 * pr.tan_x / pr.aspect;
                let to_world = pr.world_to_local.inverse();
                let dir = to_world.transform_vector3(Vec3::new(x, y, 1.0)).normalize_or_zero();
                (pr.position, dir, pr.image.eval(u.0, u.1) * (PI * pr.scale * pr.plane_area()))
            }
        };
        (dir != Vec3::ZERO && weight.max_element() > 0.0).then_some(EmissionSample { p, n: Vec3::ZERO, dir, weight })
    }

    /// The light's emitted power (mean over the channels; the spot's falloff taken at the middle
    /// of its transition), for choosing among the emitters; 0 for `directional`.
    pub fn emitted_power(&self) -> f32 {
        let m = |v: Vec3| v.max(Vec3::ZERO).element_sum() / 3.0;
        match self {
            Self::Directional { .. } => 0.0,
            Self::Point { intensity, .. } => 4.0 * PI * m(*intensity),
            Self::Spot(s) => {
                let half = 0.5 * (s.cutoff + s.cos_beam.clamp(-1.0, 1.0).acos());
                let tex = s.texture.as_ref().map_or(Vec3::ONE, |t| mean(t));
                2.0 * PI * (1.0 - half.cos()) * m(s.intensity * tex)
            }
            Self::Projector(pr) => PI * pr.scale * pr.plane_area() * m(mean(&pr.image)),
        }
    }
}

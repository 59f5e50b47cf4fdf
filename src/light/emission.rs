//! Emission sampling for light tracing (the particle tracer, `integrator/ptracer.rs`): a ray
//! leaving an emitter, with the weight `W = Le |cos| / (p_pos p_dir)` (area lights) or
//! `I(w) / p_dir` (lights at a point), so that the mean of `W` times any function of the ray is
//! that function integrated against the emitted power. One function per emitter kind: area
//! lights here ([`Emitter::sample_emission`]), the delta lights in `delta_emission.rs`
//! (`DeltaLight::sample_emission`), and [`Emitter::sample_position`] for the connection of an
//! emitter point to the sensor (emitters seen directly).
//!
//! Each kind also reports its emitted power (`power`), which the particle tracer uses to choose
//! among the emitters: any positive power gives an unbiased image; a power close to the true one
//! gives the least noise.

use super::emitters::Emitter;
use crate::sampling::sample_cosine_hemisphere;
use glam::Vec3;
use std::f32::consts::PI;

/// A ray leaving an emitter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissionSample {
    /// where it leaves (world space)
    pub p: Vec3,
    /// the unit emitting normal there (zero for a light at a point)
    pub n: Vec3,
    /// unit direction of travel
    pub dir: Vec3,
    /// emitted radiance (area) or intensity (point) along `dir`, divided by the pdfs of the
    /// position (per unit area; 1 at a point) and of the direction (per unit solid angle), times
    /// the cosine at an area light: the flux the ray carries
    pub weight: Vec3,
}

/// An orthonormal frame around unit `n` (`(t, b, n)`, right-handed).
pub fn frame(n: Vec3) -> (Vec3, Vec3) {
    let t = if n.x.abs() > 0.9 { Vec3::Y } else { Vec3::X };
    let t = n.cross(t).normalize();
    (t, n.cross(t))
}

/// A unit direction uniform over the sphere for `u`: `(dir, pdf = 1 / 4 pi)`.
pub fn uniform_sphere(u: (f32, f32)) -> (Vec3, f32) {
    let z = 1.0 - 2.0 * u.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.1).sin_cos();
    (Vec3::new(r * c, r * s, z), 0.25 / PI)
}

impl Emitter {
    /// Power emitted (one-sided, Lambertian): `pi * area * mean(radiance)`.
    pub fn emitted_power(&self) -> f32 {
        PI * self.area * self.radiance.max(Vec3::ZERO).element_sum() / 3.0
    }

    /// A point on the light uniform in area for `u`: `(point, pdf per unit area)`.
    pub fn sample_position(&self, u: (f32, f32)) -> (Vec3, f32) {
        (self.point(u.0, u.1), 1.0 / self.area.max(f32::MIN_POSITIVE))
    }

    /// A ray leaving the light: the point uniform in area (`u_pos`), the direction cosine-weighted
    /// on the emitting side (`u_dir`): weight `Le pi area`. None for a light of zero area.
    pub fn sample_emission(&self, u_pos: (f32, f32), u_dir: (f32, f32)) -> Option<EmissionSample> {
        if self.area <= 0.0 || self.normal == Vec3::ZERO {
            return None;
        }
        let (p, _) = self.sample_position(u_pos);
        let (local, _) = sample_cosine_hemisphere([u_dir.0, u_dir.1]);
        let (t, b) = frame(self.normal);
        let dir = (t * local.x + b * local.y + self.normal * local.z).normalize();
        // Le cos / (1/area * cos/pi)
        Some(EmissionSample { p, n: self.normal, dir, weight: self.radiance * (PI * self.area) })
    }
}

/// A direction uniform in the cone of half-angle `acos(cos_max)` around +z for `u`, with its pdf
/// per unit solid angle.
pub fn uniform_cone(u: (f32, f32), cos_max: f32) -> (Vec3, f32) {
    let z = 1.0 - u.0 * (1.0 - cos_max);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.1).sin_cos();
    (Vec3::new(r * c, r * s, z), 1.0 / (2.0 * PI * (1.0 - cos_max)))
}

#[cfg(test)]
#[path = "emission_tests.rs"]
mod tests;

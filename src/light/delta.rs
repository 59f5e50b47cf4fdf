//! Delta lights (Mitsuba's `point`, `directional`, `spot`, `projector`): lights at a point or
//! from one direction. No ray can hit them, so they are reached by next-event estimation alone:
//! at every next event each delta light is sampled (deterministically: its direction from the
//! shading point is fixed) with weight 1, and there is no BSDF-sampling counterpart, hence no
//! MIS weight on either side. They draw no sampler dimension.
//!
//! They sit outside the light selection (`light::select`, which chooses among the area lights):
//! every `--light-selection` treats them alike, as it treats the environment ([`super::sky`],
//! [`super::envmap`]).
//!
//! A sample at a point `p` is the unit direction `wi` to the light, the distance to it (infinite
//! for `directional`) and `li`, the incident radiance divided by the (delta) pdf: the estimate is
//! `f(wo, wi) cos(th_i) li` where the shadow ray is clear. Conventions and falloffs as Mitsuba 3:
//! - `point`: `li = I / d^2`;
//! - `directional`: `li = E` (the irradiance on a surface facing the light);
//! - `spot`: `li = I s(w) t(uv) / d^2`, with `w` the direction from the light in its frame (+z the
//!   axis), `s = 1` within `beam_width`, `(cutoff - angle) / (cutoff - beam_width)` up to `cutoff`,
//!   0 past it; `t` the optional texture at `uv = 0.5 + 0.5 (w.x, w.y) / (w.z tan(cutoff))`;
//! - `projector`: `li = pi scale E(uv) / (z^2 cos)` with `z` the point's depth in the light's frame,
//!   `cos` the cosine between the light's axis and the direction to the point, and `uv` the
//!   point's position on the perspective image plane (`(0, 0)` its top-left, as a camera's).
//!
//! Every function is scalar; the x8 form runs it per lane (bit-identical by construction).

use super::desc::{DeltaLightDesc, RgbImage};
use crate::simd::{mask_from_bools, Mask8, Vec3x8, F8};
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// Why a delta light cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DeltaLightError {
    /// A spot whose beam is wider than its cutoff, or with a cutoff outside (0, 90) degrees.
    #[error(
        "spot light: need 0 < beam_width <= cutoff_angle < 90 degrees, got beam_width {beam} and cutoff_angle {cutoff}"
    )]
    SpotAngles {
        /// beam width, degrees
        beam: f32,
        /// cutoff, degrees
        cutoff: f32,
    },
    /// A projector's field of view outside (0, 180) degrees.
    #[error("projector: fov must lie in (0, 180) degrees, got {0}")]
    ProjectorFov(f32),
    /// An empty image, a singular `to_world` or a non-finite value.
    #[error("{0}: {1}")]
    Invalid(&'static str, &'static str),
}

/// One delta light, ready to sample.
#[derive(Clone, Debug)]
pub enum DeltaLight {
    /// `point`
    Point {
        /// position
        position: Vec3,
        /// intensity
        intensity: Vec3,
    },
    /// `directional`
    Directional {
        /// unit direction towards the light
        to_light: Vec3,
        /// irradiance
        irradiance: Vec3,
    },
    /// `spot`
    Spot(Box<Spot>),
    /// `projector`
    Projector(Box<Projector>),
}

/// A spot light's frame and falloff.
#[derive(Clone, Debug)]
pub struct Spot {
    position: Vec3,
    world_to_local: Mat4,
    intensity: Vec3,
    cutoff: f32,
    cos_cutoff: f32,
    cos_beam: f32,
    inv_transition: f32,
    uv_factor: f32,
    texture: Option<Arc<RgbImage>>,
}

/// A projector's frame and image.
#[derive(Clone, Debug)]
pub struct Projector {
    position: Vec3,
    axis: Vec3,
    world_to_local: Mat4,
    image: Arc<RgbImage>,
    scale: f32,
    /// tan(fov_x / 2)
    tan_x: f32,
    /// image width / height
    aspect: f32,
}

fn invertible(m: &Mat4, what: &'static str) -> Result<Mat4, DeltaLightError> {
    let inv = m.inverse();
    if m.determinant().abs() > 0.0 && inv.is_finite() {
        Ok(inv)
    } else {
        Err(DeltaLightError::Invalid(what, "to_world is singular or not finite"))
    }
}

fn image_ok(im: &RgbImage, what: &'static str) -> Result<(), DeltaLightError> {
    if im.width == 0 || im.height == 0 || im.texels.len() != (im.width as usize) * (im.height as usize) {
        return Err(DeltaLightError::Invalid(what, "the image is empty or its texel count is not width x height"));
    }
    Ok(())
}

impl DeltaLight {
    /// The light of `desc`.
    pub fn new(desc: &DeltaLightDesc) -> Result<Self, DeltaLightError> {
        Ok(match desc {
            DeltaLightDesc::Point { position, intensity } => Self::Point { position: *position, intensity: *intensity },
            DeltaLightDesc::Directional { direction, irradiance } => {
                let d = direction.normalize_or_zero();
                if d == Vec3::ZERO {
                    return Err(DeltaLightError::Invalid("directional light", "the direction is zero or not finite"));
                }
                Self::Directional { to_light: -d, irradiance: *irradiance }
            }
            DeltaLightDesc::Spot { to_world, intensity, cutoff_deg, beam_width_deg, texture } => {
                let (c, b) = (*cutoff_deg, *beam_width_deg);
                if !(b > 0.0 && b <= c && c < 90.0) {
                    return Err(DeltaLightError::SpotAngles { beam: b, cutoff: c });
                }
                if let Some(t) = texture {
                    image_ok(t, "spot light texture")?;
                }
                let (cr, br) = (c.to_radians(), b.to_radians());
                Self::Spot(Box::new(Spot {
                    position: to_world.w_axis.truncate(),
                    world_to_local: invertible(to_world, "spot light")?,
                    intensity: *intensity,
                    cutoff: cr,
                    cos_cutoff: cr.cos(),
                    cos_beam: br.cos(),
                    inv_transition: if cr > br { 1.0 / (cr - br) } else { 0.0 },
                    uv_factor: cr.tan(),
                    texture: texture.clone(),
                }))
            }
            DeltaLightDesc::Projector { to_world, irradiance, scale, fov_x_deg } => {
                if !(*fov_x_deg > 0.0 && *fov_x_deg < 180.0) {
                    return Err(DeltaLightError::ProjectorFov(*fov_x_deg));
                }
                image_ok(irradiance, "projector irradiance")?;
                Self::Projector(Box::new(Projector {
                    position: to_world.w_axis.truncate(),
                    axis: to_world.z_axis.truncate().normalize_or(Vec3::Z),
                    world_to_local: invertible(to_world, "projector")?,
                    image: irradiance.clone(),
                    scale: *scale,
                    tan_x: (fov_x_deg.to_radians() * 0.5).tan(),
                    aspect: irradiance.width as f32 / irradiance.height as f32,
                }))
            }
        })
    }

    /// Mitsuba's name of the light's kind.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Point { .. } => "point",
            Self::Directional { .. } => "directional",
            Self::Spot(_) => "spot",
            Self::Projector(_) => "projector",
        }
    }

    /// The light's sample at `p` (see the module docs): `(wi, distance, li)`, or None where it
    /// sends nothing to `p`.
    pub fn sample(&self, p: Vec3) -> Option<(Vec3, f32, Vec3)> {
        match self {
            Self::Directional { to_light, irradiance } => Some((*to_light, f32::INFINITY, *irradiance)),
            Self::Point { position, intensity } => {
                let to = *position - p;
                let d2 = to.length_squared();
                (d2 > 0.0).then(|| (to / d2.sqrt(), d2.sqrt(), *intensity / d2))
            }
            Self::Spot(s) => {
                let to = s.position - p;
                let d2 = to.length_squared();
                if d2 <= 0.0 {
                    return None;
                }
                let local = s.world_to_local.transform_point3(p).normalize_or_zero();
                let cos = local.z;
                if cos <= s.cos_cutoff {
                    return None;
                }
                let mut l = s.intensity;
                if let Some(t) = &s.texture {
                    let k = 0.5 / (local.z * s.uv_factor);
                    l *= t.eval(0.5 + local.x * k, 0.5 + local.y * k);
                }
                if cos < s.cos_beam {
                    l *= (s.cutoff - cos.clamp(-1.0, 1.0).acos()) * s.inv_transition;
                }
                let d = d2.sqrt();
                Some((to / d, d, l / d2))
            }
            Self::Projector(pr) => {
                let local = pr.world_to_local.transform_point3(p);
                if local.z <= 0.0 {
                    return None;
                }
                let u = 0.5 - 0.5 * local.x / (local.z * pr.tan_x);
                let v = 0.5 - 0.5 * pr.aspect * local.y / (local.z * pr.tan_x);
                if !(0.0..=1.0).contains(&u) || !(0.0..=1.0).contains(&v) {
                    return None;
                }
                let to = pr.position - p;
                let d = to.length();
                if d <= 0.0 {
                    return None;
                }
                let wi = to / d;
                let cos = -pr.axis.dot(wi);
                if cos <= 0.0 {
                    return None;
                }
                let e = pr.image.eval(u, v);
                Some((wi, d, e * (std::f32::consts::PI * pr.scale / (local.z * local.z * cos))))
            }
        }
    }

    /// The light's position (None for `directional`), for the shadow ray's end.
    pub fn position(&self) -> Option<Vec3> {
        match self {
            Self::Directional { .. } => None,
            Self::Point { position, .. } => Some(*position),
            Self::Spot(s) => Some(s.position),
            Self::Projector(p) => Some(p.position),
        }
    }

    /// [`DeltaLight::sample`] of the `active` lanes of `p`: `(wi, distance, li, lanes lit)`,
    /// zero where not lit.
    pub fn sample_x8(&self, p: Vec3x8, active: Mask8) -> (Vec3x8, F8, Vec3x8, Mask8) {
        let on = crate::simd::mask_to_bools(active);
        let s: [Option<(Vec3, f32, Vec3)>; 8] =
            std::array::from_fn(|i| if on[i] { self.sample(p.lane(i)) } else { None });
        let pick =
            |f: &dyn Fn(&(Vec3, f32, Vec3)) -> Vec3| Vec3x8::from_lanes(s.map(|o| o.as_ref().map_or(Vec3::ZERO, f)));
        (
            pick(&|o| o.0),
            F8::new(s.map(|o| o.map_or(0.0, |o| o.1))),
            pick(&|o| o.2),
            mask_from_bools(s.map(|o| o.is_some_and(|o| o.2.max_element() > 0.0))),
        )
    }
}

#[path = "delta_emission.rs"]
mod emission;

#[cfg(test)]
#[path = "delta_tests.rs"]
mod tests;

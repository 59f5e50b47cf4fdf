//! Descriptions of the emitters that are not area lights: Mitsuba's `point`, `spot`,
//! `directional`, `projector` (delta lights, [`DeltaLightDesc`]) and `constant`, `envmap`
//! (the environment, [`EnvironmentDesc`]; at most one per scene, as in Mitsuba). Plain data in
//! Mitsuba's units and conventions, so a front end copies the properties one to one; the
//! renderer's side is [`super::delta`], [`super::sky`] and [`super::envmap`]. They live in
//! `light/` (as the material descriptions live in `bsdf/`) so that the light layer does not import
//! the scene; `scene::desc` re-exports them.
//!
//! Images ([`RgbImage`]) are linear RGB texels, row 0 the image's top row; texture coordinates
//! `(u, v)` address them as Mitsuba's `bitmap` texture does (`(0, 0)` the top-left corner of the
//! first texel, bilinear filtering, `repeat` wrapping). A front end decodes the file (sRGB to
//! linear for 8-bit images unless `raw`) and hands the texels over.

use glam::{Mat4, Vec3};
use std::sync::Arc;

/// A decoded image: `width * height` linear RGB texels, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// width in texels
    pub width: u32,
    /// height in texels
    pub height: u32,
    /// the texels, `texels[y * width + x]`
    pub texels: Vec<Vec3>,
}

impl RgbImage {
    /// A 1 x 1 image of `rgb` (a constant texture, as Mitsuba's `rgb` values are).
    pub fn constant(rgb: Vec3) -> Self {
        Self { width: 1, height: 1, texels: vec![rgb] }
    }

    /// Texel `(x, y)` (clamped to the image).
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        let (x, y) = (x.min(self.width - 1), y.min(self.height - 1));
        self.texels[(y * self.width + x) as usize]
    }

    /// Bilinear lookup at `(u, v)` with repeat wrapping (Mitsuba's `bitmap` defaults: the texel
    /// centres at `((x + 0.5) / width, (y + 0.5) / height)`).
    pub fn eval(&self, u: f32, v: f32) -> Vec3 {
        let (w, h) = (self.width as f32, self.height as f32);
        let (px, py) = (u * w - 0.5, v * h - 0.5);
        let (fx, fy) = (px.floor(), py.floor());
        let (tx, ty) = (px - fx, py - fy);
        let wrap = |i: f32, n: u32| (i as i64).rem_euclid(i64::from(n)) as u32;
        let (x0, y0) = (wrap(fx, self.width), wrap(fy, self.height));
        let (x1, y1) = (wrap(fx + 1.0, self.width), wrap(fy + 1.0, self.height));
        let top = self.texel(x0, y0) * (1.0 - tx) + self.texel(x1, y0) * tx;
        let bottom = self.texel(x0, y1) * (1.0 - tx) + self.texel(x1, y1) * tx;
        top * (1.0 - ty) + bottom * ty
    }
}

/// A light at a point or from one direction: never hit by rays, sampled at every next event.
#[derive(Clone, Debug, PartialEq)]
pub enum DeltaLightDesc {
    /// Mitsuba `point`: `intensity` (W/sr) at `position`.
    Point {
        /// world position
        position: Vec3,
        /// radiant intensity
        intensity: Vec3,
    },
    /// Mitsuba `directional`: `irradiance` (W/m^2) on surfaces facing the light, travelling
    /// along `direction` (Mitsuba's `direction`, or `to_world` applied to +z).
    Directional {
        /// unit direction of travel of the light, world space
        direction: Vec3,
        /// irradiance on a surface perpendicular to it
        irradiance: Vec3,
    },
    /// Mitsuba `spot`: at `to_world`'s origin, shining along its +z; `intensity` inside
    /// `beam_width_deg`, falling off linearly in angle to zero at `cutoff_deg` (Mitsuba's
    /// curve), times `texture` (if any) over the cone's uv
    /// `(0.5 + 0.5 x / (z tan(cutoff)), 0.5 + 0.5 y / (z tan(cutoff)))` in light space.
    Spot {
        /// light-to-world
        to_world: Mat4,
        /// radiant intensity at the centre of the beam
        intensity: Vec3,
        /// cutoff angle, degrees (Mitsuba default 20)
        cutoff_deg: f32,
        /// beam width, degrees (Mitsuba default 3/4 of the cutoff)
        beam_width_deg: f32,
        /// optional texture over the spot's uv
        texture: Option<Arc<RgbImage>>,
    },
    /// Mitsuba `projector`: a perspective projection of `irradiance` from `to_world`'s origin
    /// along its +z, with horizontal field of view `fov_x_deg` (the front end resolves `fov` and
    /// `fov_axis` against the image's aspect, `scene::sensor::FovAxis::fov_x_deg`), times
    /// `scale`: the irradiance on the plane at z = 1 is `pi * scale * irradiance(uv)`.
    Projector {
        /// light-to-world
        to_world: Mat4,
        /// the projected image (a 1 x 1 image for a constant `rgb`)
        irradiance: Arc<RgbImage>,
        /// Mitsuba's `scale`
        scale: f32,
        /// horizontal field of view, degrees
        fov_x_deg: f32,
    },
}

/// The light at infinity (Mitsuba allows one environment emitter per scene).
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentDesc {
    /// Mitsuba `constant` (and `--sky`): `radiance` from every direction.
    Constant(Vec3),
    /// Mitsuba `envmap`: a latitude-longitude image times `scale`, rotated by `to_world`.
    Envmap {
        /// the image (linear RGB)
        image: Arc<RgbImage>,
        /// Mitsuba's `scale`
        scale: f32,
        /// Mitsuba's `to_world` (its linear part orients the map)
        to_world: Mat4,
    },
}

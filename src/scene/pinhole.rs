//! The `.test` pinhole's per-image constants for 8 lanes ([`Pinhole8`]): what every packet's
//! camera directions share, splatted once per tile instead of once per packet
//! (`scene::build::Camera::pinhole`; its `dirs8` is [`Pinhole8::dirs8`]).

use crate::simd::{Vec3x8, F8};
use glam::Vec3;

/// The pinhole's constants, splatted: [`Pinhole8::dirs8`] turns image positions into directions.
#[derive(Clone, Copy, Debug)]
pub struct Pinhole8 {
    /// the eye, every ray's origin
    pub eye: Vec3x8,
    /// the view direction times the image plane's distance
    forward: Vec3x8,
    right: Vec3x8,
    up: Vec3x8,
    /// 2 / width
    x_scale: F8,
    /// 2 / height
    y_scale: F8,
    /// width / height
    aspect: F8,
}

impl Pinhole8 {
    /// The pinhole at `eye` looking along `forward` (the view direction times the image plane's
    /// distance) with the unit `right` and `up` axes, for a `width` x `height` image.
    pub fn new(eye: Vec3, forward: Vec3, right: Vec3, up: Vec3, width: u32, height: u32) -> Self {
        let (w, h) = (width as f32, height as f32);
        Self {
            eye: Vec3x8::splat(eye),
            forward: Vec3x8::splat(forward),
            right: Vec3x8::splat(right),
            up: Vec3x8::splat(up),
            x_scale: F8::splat(2.0 / w),
            y_scale: F8::splat(2.0 / h),
            aspect: F8::splat(w / h),
        }
    }

    /// Unit directions through image positions (x, y) in pixels, y down.
    #[inline(always)]
    pub fn dirs8(&self, x: F8, y: F8) -> Vec3x8 {
        let sx = (x * self.x_scale - F8::ONE) * self.aspect;
        let sy = F8::ONE - y * self.y_scale;
        let d = self.forward + self.right.scale(sx) + self.up.scale(sy);
        d.normalize_or_zero()
    }
}

//! Sensor and pixel-filter descriptions of Mitsuba 3 scenes (plain data, filled by a scene front
//! end; `scene::lens` turns them into the camera, `camera.rs` draws through the filter).
//!
//! Mitsuba's conventions, kept as they are so that a front end copies properties one to one:
//! - `to_world` maps camera space to world space; the camera looks along camera +z, camera +x is
//!   the image's **left** and camera +y its **up** (Mitsuba's `lookat` puts `cross(up, dir)` in
//!   the first column, so image x grows along `-to_world.x_axis`).
//! - `perspective`: `fov` in degrees along `fov_axis` (`x` by default); rays start on the near
//!   plane (`near_clip`, default 0.01 in Mitsuba) in camera space.
//! - `orthographic`: camera space `[-1, 1] x [-1/aspect, 1/aspect]` (aspect = width / height) is
//!   the view, so `to_world`'s scale sets its half-extent; rays start at camera z = `near_clip`.

use glam::Mat4;

/// Which image axis Mitsuba's `fov` is measured along (`fov_axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FovAxis {
    /// horizontal (Mitsuba's default)
    #[default]
    X,
    /// vertical
    Y,
    /// the image diagonal
    Diagonal,
    /// the shorter image axis
    Smaller,
    /// the longer image axis
    Larger,
}

impl FovAxis {
    /// Mitsuba's spelling: `x`, `y`, `diagonal`, `smaller`, `larger`.
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "x" => Self::X,
            "y" => Self::Y,
            "diagonal" => Self::Diagonal,
            "smaller" => Self::Smaller,
            "larger" => Self::Larger,
            _ => return None,
        })
    }

    /// The horizontal field of view (degrees) of a `fov` (degrees) measured along this axis, for
    /// an image of aspect `width / height` (Mitsuba's `parse_fov`).
    pub fn fov_x_deg(self, fov_deg: f64, aspect: f64) -> f64 {
        let t = (fov_deg.to_radians() * 0.5).tan();
        let along_y = |t: f64| 2.0 * (t * aspect).atan();
        let x = match self {
            Self::X => return fov_deg,
            Self::Y => along_y(t),
            Self::Diagonal => 2.0 * (t * aspect / (1.0 + aspect * aspect).sqrt()).atan(),
            Self::Smaller if aspect > 1.0 => along_y(t),
            Self::Smaller => return fov_deg,
            Self::Larger if aspect > 1.0 => return fov_deg,
            Self::Larger => along_y(t),
        };
        x.to_degrees()
    }
}

/// The projection of a Mitsuba sensor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// `perspective`: a pinhole with the field of view `fov_deg` along `fov_axis`
    Perspective {
        /// field of view, degrees
        fov_deg: f32,
        /// the axis it is measured along
        fov_axis: FovAxis,
    },
    /// `orthographic`: parallel rays along camera +z over `to_world`'s scaled unit view
    Orthographic,
}

/// A Mitsuba sensor: `perspective` or `orthographic` (see the module docs for the conventions).
/// When a scene has one it replaces `SceneDesc::camera` (the `.test` look-at camera).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorDesc {
    /// camera-to-world (Mitsuba's `to_world`)
    pub to_world: Mat4,
    /// the projection
    pub projection: Projection,
    /// distance of the near plane along camera +z (Mitsuba's `near_clip`, default 0.01)
    pub near_clip: f32,
}

/// A film's crop window (Mitsuba's `crop_offset_x/y`, `crop_width/height`): the image is the
/// window's `SceneDesc::width` x `height` pixels at `(x, y)` of the full `full_width` x
/// `full_height` frame, whose size alone sets the projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FilmCrop {
    /// the full frame's width in pixels
    pub full_width: u32,
    /// the full frame's height in pixels
    pub full_height: u32,
    /// the window's left column in the full frame
    pub x: u32,
    /// the window's top row in the full frame
    pub y: u32,
}

/// Mitsuba's default `near_clip`.
pub const DEFAULT_NEAR_CLIP: f32 = 0.01;

pub use crate::sampling::filter::PixelFilter;

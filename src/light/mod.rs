//! Lights: every area light (quad lights and emissive triangles) with light selection and point
//! sampling (by area, or by solid angle: [`warp`]), exact polygonal irradiance, the constant environment light ([`sky`]), the image one
//! ([`envmap`]) and Mitsuba's delta lights ([`delta`]: point, directional, spot, projector).
pub mod delta;
pub mod desc;
pub mod emission;
pub mod emitters;
pub mod envmap;
pub mod lane_table;
pub mod polygonal;
pub mod select;
pub mod sky;
pub mod warp;

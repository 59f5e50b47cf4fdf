//! Lights: every area light (quad lights and emissive triangles) with light selection and point
//! sampling, and exact polygonal irradiance.
pub mod emitters;
pub mod polygonal;
pub mod select;

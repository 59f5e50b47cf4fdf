//! Lights: every area light (quad lights and emissive triangles) with light selection and point
//! sampling, exact polygonal irradiance, and the constant environment light ([`sky`]).
pub mod emitters;
pub mod polygonal;
pub mod select;
pub mod sky;

//! Lights: quad (parallelogram) area lights and exact polygonal irradiance.
pub mod polygonal;

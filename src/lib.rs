//! strata: a SIMD packet ray tracer on Embree 4, built to compare sampling techniques.
pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod checkpoint;
pub mod film;
pub mod integrator;
pub mod lab;
pub mod light;
pub mod measure;
pub mod profile;
pub mod render;
pub mod report;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod session;
pub mod simd;

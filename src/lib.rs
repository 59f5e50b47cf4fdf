//! strata: a SIMD packet ray tracer on Embree 4.
pub mod accel;
pub mod scene;
pub mod simd;

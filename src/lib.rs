//! strata: a SIMD packet ray tracer on Embree 4, built to compare sampling techniques.

// The command-line grammar (`cli.rs`, the binary's module) is compiled into the library as well, so
// `frontend` (and through it the Python module) parses flags exactly as the binary does; its
// `strata::` paths name this crate.
extern crate self as strata;
pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod checkpoint;
#[allow(dead_code)]
#[path = "cli.rs"]
mod cli;
pub mod cli_values;
pub mod files;
pub mod film;
pub mod frontend;
pub mod integrator;
pub mod lab;
pub mod light;
pub mod measure;
pub mod plan;
pub mod pointset;
pub mod profile;
pub mod registry;
pub mod render;
pub mod report;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod session;
pub mod simd;
pub mod texture;

//! The one module that talks to Embree 4, and the only `unsafe` in strata (with the CPU-level
//! helpers: FTZ/DAZ, the time-stamp counter, the hardware gather).
//!
//! Embree 4.4 (the library we link) is built with instance arrays, so its ray/hit structs carry an
//! `instPrimID` field that the 4.2-era structs of `embree4-sys` lack: `RTCRayHit8` is 672 bytes, not
//! 640, and a hit written into the crate's struct would run past its end. We therefore define the
//! packet structs here with the 4.4 layout, check their sizes at compile time, and cast at the call.
//!
//! Geometry layout of a built scene (the ids `scene::build` relies on):
//! - geometry [`GEOM_TRIANGLES`]: one triangle mesh holding every triangle (quad lights included);
//! - geometry [`GEOM_SPHERES`]: spheres placed by similarity transforms, as Embree sphere points
//!   (centre, radius) in world space: Embree's own intersector, used by `scene::build` only with
//!   `STRATA_SPHERES=embree` (slower in packets and less exact than the user geometry:
//!   `sphere_points_tests.rs`, `benches/ellipsoid.rs`);
//! - geometry [`GEOM_ELLIPSOIDS`]: every sphere and ellipsoid (the unit sphere under any affine
//!   map), as one Embree user geometry whose primitive i is the unit sphere under that map (no
//!   instancing; f32 SIMD object-space intersection with an f64 fallback chosen by an error bound,
//!   accurate at extreme scales);
//! - geometries from [`GEOM_FIRST_INSTANCE`] on: instances of child scenes (`add_group`: one
//!   triangle mesh, geometry 0 of the child, shared by any number of `add_instance`s); hits report
//!   the instance's id in `inst_id`, geometry 0 and the child's triangle.
//!
//! Geometry kinds must be added in this order; a kind may be skipped.
//!
//! Files: `ffi.rs` the packet structs with their layout asserts and the query arguments;
//! `device.rs` the device and its error callback ([`AccelError`]); `scene.rs` the scene builder, the
//! committed scene and its 8-wide queries ([`Hits8`]); `user_geometry.rs` the ellipsoid callbacks
//! (`ellipsoid.rs` their intersection); `sphere_points_tests.rs` Embree's sphere points against
//! them and the f64 reference;
//! `ftz.rs` the FTZ/DAZ switch; `gather.rs` 8-lane table look-ups (the hardware gather on AMD);
//! `alloc.rs` the counting allocator for tests.

pub mod alloc;
pub mod approx;
mod device;
pub mod ellipsoid;
mod ffi;
mod ftz;
mod gather;
mod scene;
#[cfg(test)]
mod sphere_points_tests;
#[cfg(test)]
mod tests;
mod user_geometry;

pub use approx::approx_id;
pub use device::{cpu_has_avx512, default_isa, AccelError, Device, EmbreeConfig, CONFIG_VAR, DEFAULT_ISA};
pub use ffi::{Hit8, Ray8, RayHit1, RayHit16, RayHit8, RayQueryContext, Valid16, HIT_WORDS, RAY_WORDS};
pub use ftz::{set_ftz_daz, timestamp};
pub use gather::{gather_u16, hardware_gather, hardware_gather_compiled, set_hardware_gather};
pub use scene::{GroupId, Hits8, Scene, SceneBuilder};
pub use user_geometry::{set_callback_timing, take_callback_ticks};

/// Embree's invalid geometry / instance id.
pub const INVALID_ID: u32 = u32::MAX;
/// Geometry id of the triangle mesh.
pub const GEOM_TRIANGLES: u32 = 0;
/// Geometry id of the world-space sphere points.
pub const GEOM_SPHERES: u32 = 1;
/// Geometry id of the ellipsoid user geometry.
pub const GEOM_ELLIPSOIDS: u32 = 2;
/// First geometry id of instances.
pub const GEOM_FIRST_INSTANCE: u32 = 3;

/// Path of the Embree library this binary was linked against (from build.rs).
pub const EMBREE_LIBDIR: &str = env!("STRATA_EMBREE_LIBDIR");

//! The integration tests: one test binary (one link of the crate) with a module per topic.
//! `common` holds the shared helpers; `tests/hostile_input.rs` is a binary of its own because it
//! installs a counting global allocator.

mod common;

mod checkpoint;
mod cli;
mod compare_checks;
mod convergence;
mod direct_bsdf;
mod direct_lighting;
mod docs;
mod experiments;
mod fidelity;
mod flip;
mod frame_maps;
mod furnace;
mod golden;
mod kernels;
mod layering;
mod light_selection;
mod light_warp;
mod materials_mitsuba;
mod mitsuba_corpus;
mod nee_below;
mod normals;
mod obj;
mod obj_wild;
mod path_tracing;
mod pointset_files;
mod profile;
mod ptracer;
mod report_html;
mod sky;
mod stability;
mod whitted;

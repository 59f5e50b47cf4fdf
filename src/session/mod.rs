//! The front end's session layer: what one `strata render` / `reference` / `rays` invocation does,
//! as library functions (the binary, tests and benches share them). `main.rs` only parses the
//! command line into [`RenderOptions`] and calls these.
//!
//! - [`options`] — [`RenderOptions`] and defaults;
//! - [`scene`] — scene loading with the overrides, [`prepare`] (scene and integrator), scene hash;
//! - [`pass`] — the pass loop ([`render_to_film`]) with checkpoints, resume, budget, signals;
//! - [`progress`] — the progress bar (`indicatif`) or plain lines;
//! - [`output`] — output naming, EXR metadata, [`run_render`];
//! - [`reference`] — `strata reference`: independent replicas, the variance layer from them;
//! - [`stats`] — the `--stats` JSON and the summary line;
//! - [`rays`] — `strata rays`;
//! - [`checks`] — command-line checks before rendering (outputs: no directory, link or device,
//!   no collision), the default light;
//! - [`memory`] — the render's memory estimate, refused above `--limit max_memory`;
//! - [`profile`] — `strata profile`;
//! - [`replay`] — the sampler replay of `strata profile`;
//! - [`error`] — [`SessionError`].

pub mod checks;
pub mod error;
pub mod memory;
pub mod options;
pub mod output;
pub mod pass;
pub mod profile;
pub mod progress;
pub mod rays;
pub mod reference;
pub mod replay;
pub mod scene;
pub mod stats;

pub use crate::scene::obj::is_obj;
pub use error::SessionError;
pub use options::{default_first_sample, default_quantize, RenderOptions, DEFAULT_CHECKPOINT_EVERY, DEFAULT_SCENE};
pub use output::{metadata, output_stem, run_render};
pub use pass::{render_to_film, stop_on_signals, RenderOutput};
pub use profile::{profile_table, run_profile, run_profile_capped, Profile};
pub use rays::{rates_table, run_rays};
pub use replay::{KindReplay, SamplerReplay};
pub use scene::{load_scene, parse_camera, parse_scene, prepare, scene_hash};
pub use stats::{stats_json, summary};

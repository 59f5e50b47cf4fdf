//! The options of `strata render` (and of `reference`, `rays`, `compare` variants), and defaults.

use crate::sampler::SamplerKind;
use crate::scene::desc::{CameraDesc, ImportanceSampling, IntegratorKind, Nee};
use crate::scene::parse::Limits;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// The built-in default scene (a Cornell box written for strata).
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/cornell.test");

/// Default seconds between two checkpoints.
pub const DEFAULT_CHECKPOINT_EVERY: f64 = 300.0;

/// Options of `strata render`.
#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    /// scene file; None renders the built-in Cornell box
    pub scene: Option<PathBuf>,
    /// `scene` already parsed ([`super::parse_scene`]; the Python module's `strata.Scene`): each
    /// render starts from it instead of reading the file again (the overrides still apply)
    pub parsed: Option<Arc<crate::scene::desc::SceneDesc>>,
    /// samples per pixel (default: the scene's `spp`)
    pub spp: Option<u32>,
    /// image size override, keeping the camera
    pub size: Option<(u32, u32)>,
    /// base seed
    pub seed: u64,
    /// worker threads (0 = all cores)
    pub threads: usize,
    /// every dimension's layout (`--sampler`; default stratified)
    pub sampler: Option<SamplerKind>,
    /// light sample layout (default: `sampler`, else the scene's `lightstratify`)
    pub light_sampler: Option<SamplerKind>,
    /// where a one-light choice takes its number from (`--light-choice`; default reuse)
    pub light_choice: Option<crate::light::select::LightChoice>,
    /// `--light-warp`: how a point is placed on the chosen area light (default area)
    pub light_warp: Option<crate::light::warp::LightWarp>,
    /// light samples per light (default: the scene's `lightsamples`)
    pub light_samples: Option<u32>,
    /// `direct`: BSDF samples per shading point, MIS-weighted with the light samples (default:
    /// the scene's, Mitsuba's `bsdf_samples`; 0 for `.test` and OBJ scenes)
    pub bsdf_samples: Option<u32>,
    /// pixel sample layout (default stratified)
    pub pixel_sampler: Option<SamplerKind>,
    /// output stem: writes OUT.exr and OUT.png (default: the scene's `output` name)
    pub out: Option<PathBuf>,
    /// JSON statistics file
    pub stats: Option<PathBuf>,
    /// `--profile FILE`: profile the render's phases ([`crate::profile`]) and write the profile
    /// JSON (the keys of `strata profile --json`) here
    pub profile: Option<PathBuf>,
    /// integrator override
    pub integrator: Option<IntegratorKind>,
    /// print progress (spp done, Mrays/s, ETA) on stderr while rendering
    pub progress: bool,
    /// run the general kernel instead of the one specialized for the scene's features
    pub general_kernel: bool,
    /// path tracer: clamp each pixel sample's largest channel to this value (biased; None = off)
    pub clamp: Option<f32>,
    /// checkpoint file: the accumulated state is written there every `checkpoint_every` seconds
    /// and at the end (default with `--samples` or on interruption: OUT.ckpt)
    pub checkpoint: Option<PathBuf>,
    /// seconds between checkpoints (default [`DEFAULT_CHECKPOINT_EVERY`]; 0 = after every pass)
    pub checkpoint_every: Option<f64>,
    /// continue the render held in this checkpoint (same scene and options, else refused)
    pub resume: Option<PathBuf>,
    /// render only sample indices A..B of the spp (a shard for `strata merge`)
    pub samples: Option<(u32, u32)>,
    /// render whole passes until this many seconds are spent (progressive layouts continue across
    /// passes, others are refused; `--spp`, if given, caps the samples)
    pub time_budget: Option<f64>,
    /// set (e.g. by SIGINT/SIGTERM) to stop after the current pass, checkpoint and write the image
    pub stop: Option<Arc<AtomicBool>>,
    /// camera override (`--camera`), for `.obj` and `.test` scenes alike
    pub camera: Option<CameraDesc>,
    /// path tracer: direction sampling override (default: the scene's `importancesampling`)
    pub importance_sampling: Option<ImportanceSampling>,
    /// path tracer: next event estimation override (default: the scene's `nexteventestimation`)
    pub nee: Option<Nee>,
    /// path tracer: Russian roulette override (default: the scene's `russianroulette`)
    pub russian_roulette: Option<bool>,
    /// maximum depth override, -1 = unbounded (default: the scene's `maxdepth`)
    pub max_depth: Option<i32>,
    /// resource caps (`--limit NAME=VALUE`), applied to the scene file and to the overrides
    pub limits: Limits,
    /// PNG quantizer (`--quantize`; default [`default_quantize`]: the course's truncation for `.test`)
    pub quantize: Option<crate::film::Quantize>,
    /// where pixel sample 0 goes (`--first-sample`; default [`default_first_sample`])
    pub first_sample: Option<crate::camera::FirstSample>,
    /// path tracer NEE's light selection (`--light-selection`; default [`default_light_selection`])
    pub light_selection: Option<crate::light::select::LightSelection>,
    /// `--no-default-light`: an OBJ scene without emitters stays unlit (default: a light is added)
    pub no_default_light: bool,
    /// `--allow-other-build`: resume a checkpoint written by another build of strata
    pub allow_other_build: bool,
    /// `--up x|y|z`: the up axis of an OBJ scene's automatic camera (default: guessed from its bounds)
    pub up: Option<crate::scene::obj::frame::UpAxis>,
    /// `--sky R[,G,B]`: a constant environment light of this radiance (path tracer)
    pub sky: Option<glam::Vec3>,
    /// `-D NAME=VALUE`: parameters of a Mitsuba XML scene (`$NAME`), over its `<default>`s
    pub defines: Vec<(String, String)>,
    /// set while the pass loop runs (a signal then stops after the pass and checkpoints; outside
    /// it the binary exits at once with code 130)
    pub rendering: Option<Arc<AtomicBool>>,
}

/// The PNG quantizer of `opts`: `--quantize`, else truncation like the CSE168 course's writer for
/// `.test` scenes (and the built-in one, a `.test`), rounding for `.obj` scenes (not course scenes).
pub fn default_quantize(opts: &RenderOptions) -> crate::film::Quantize {
    use crate::film::Quantize;
    opts.quantize.unwrap_or(course_or_obj(opts, Quantize::Truncate, Quantize::Round))
}

/// Where pixel sample 0 goes for `opts`: `--first-sample`, else through the pixel centre like the
/// CSE168 course code for `.test` scenes (and the built-in one), jittered for `.obj` scenes.
pub fn default_first_sample(opts: &RenderOptions) -> crate::camera::FirstSample {
    use crate::camera::FirstSample;
    opts.first_sample.unwrap_or(course_or_obj(opts, FirstSample::Centre, FirstSample::Jittered))
}

/// NEE's light selection for `opts`: `--light-selection`, else `all` (every light, the CSE168
/// course's convention) for `.test` scenes and the built-in one, `uniform` for `.obj` scenes.
/// (The session puts a scene's `lightselection` keyword between the flag and this default, and
/// gives `direct` `all` by default whatever the scene kind.)
pub fn default_light_selection(opts: &RenderOptions) -> crate::light::select::LightSelection {
    use crate::light::select::LightSelection;
    opts.light_selection.unwrap_or(course_or_obj(opts, LightSelection::ALL, LightSelection::UNIFORM))
}

/// `course` for `.test` scenes (and the built-in one), `obj` for `.obj` scenes: the one rule behind
/// the course-convention defaults.
fn course_or_obj<T>(opts: &RenderOptions, course: T, obj: T) -> T {
    match &opts.scene {
        Some(p) if crate::scene::obj::is_obj(p) || crate::scene::xml::is_xml(p) => obj,
        _ => course,
    }
}

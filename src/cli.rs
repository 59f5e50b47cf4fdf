//! The command line's grammar: subcommands, flags and their value parsers (clap), and the
//! conversion of render flags into [`RenderOptions`]; `main.rs` runs what was asked.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use strata::cli_values::*;
use strata::sampler::SamplerKind;
use strata::scene::desc::{ImportanceSampling, IntegratorKind, Nee};
use strata::session::{self, RenderOptions};

/// Help headings of the render flags.
const SCENE: &str = "Scene and camera";
const SAMPLING: &str = "Sampling";
const LIGHTS: &str = "Lights";
const INTEGRATOR: &str = "Integrator";
const OUTPUT: &str = "Output";
const CHECKPOINTS: &str = "Checkpoints";
const LIMITS: &str = "Limits";

/// The conventions every subcommand follows, printed under `strata --help`.
const CONVENTIONS: &str = "Conventions:
  Budgets: --time-budget (alias --wall-budget) is wall-clock seconds; compare's --budget (alias
    --cpu-budget) is CPU seconds of the worker threads. A flag counting seconds says which.
  Outputs: -o/--out takes a stem (OUT.exr and OUT.png); a given .exr or .png extension is dropped.
    --json FILE writes the subcommand's JSON (render: statistics; profile: the profile; compare:
    the rows; rays: --json alone prints it instead of the table, --json=FILE writes it).
  Spellings: centre and center are both accepted; --nthreads is --threads; --outfile is --out.
  Numbers: counts are whole numbers (spp >= 1); a negative value is refused with what is allowed.
  A subcommand refuses the flags it does not use (rays and profile write no image).";

#[derive(Parser)]
#[command(
    name = "strata",
    version,
    about = "SIMD packet ray tracer on Embree 4 for sampling experiments",
    after_help = CONVENTIONS,
    allow_negative_numbers = true
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) cmd: Cmd,
}

#[derive(Subcommand)]
pub(crate) enum Cmd {
    /// Render a CSE168 .test scene (or the built-in Cornell box) to OUT.exr and OUT.png.
    #[command(allow_negative_numbers = true)]
    Render(RenderCmd),
    /// Render a high-spp reference: linear EXR with a per-pixel variance layer (and a PNG), with
    /// progress and ETA. Same flags as `render`; --spp is required. Unbiased by default:
    /// --first-sample jittered unless given. The image is the mean of --replicas independent
    /// renders (own seeds and scrambles) of spp/replicas samples each, and the variance layer is
    /// the variance of that mean estimated across them (EXR attribute `strata.variance`).
    #[command(allow_negative_numbers = true)]
    Reference(ReferenceCmd),
    /// Compare sampling techniques against a reference: K independent runs per variant at equal spp
    /// (--spp-ladder) or equal time (--budget); writes rows.csv/json, runs.csv/json (one row per
    /// run), table.md, error.svg and report.html (flip-book, error maps, plots). The reference must
    /// be of the same scene, size and camera. Variants default to --first-sample jittered.
    /// Seconds are the worker threads' CPU seconds of runs timed with the profiler off; the
    /// sampler's ns/sample and share of the render come from one separate profiled render per
    /// variant and step (a quarter of the spp its runs reached), whose time is in no row.
    #[command(allow_negative_numbers = true)]
    Compare {
        /// Scene file (.test); omitted: the built-in Cornell box.
        scene: Option<PathBuf>,
        /// Reference EXR (from `strata reference`), same size as the renders.
        #[arg(long)]
        reference: PathBuf,
        /// NAME=OPTIONS, OPTIONS being render flags with shell quoting, e.g.
        /// strat='--light-sampler stratified --camera "0 0 5 0 0 0 0 1 0 45"'. Repeat for each
        /// variant; names are unique. compare owns --spp, --size, -o, --threads (refused here).
        #[arg(long = "variant", required = true)]
        variants: Vec<String>,
        /// The variant the efficiency ratios are against, at each spp step (default: the first).
        #[arg(long, value_name = "NAME")]
        baseline: Option<String>,
        /// Compare against a reference of another scene or camera anyway (the report says so).
        #[arg(long)]
        force: bool,
        /// No progress lines on stderr.
        #[arg(long, short = 'q')]
        quiet: bool,
        /// Independent runs per variant (seeds differ), at least 2.
        #[arg(long, default_value_t = 4, value_parser = parse_count::<usize>)]
        runs: usize,
        /// Equal time: CPU seconds of the worker threads per run (passes growing geometrically until
        /// spent); a comma-separated ladder (0.25,0.5,1,2) gives slopes against time.
        #[arg(long, visible_alias = "cpu-budget", value_name = "CPU_SECONDS", value_delimiter = ',', conflicts_with = "spp_ladder", value_parser = parse_seconds)]
        budget: Option<Vec<f64>>,
        /// Equal spp: comma-separated spp values, e.g. 1,2,4,8.
        #[arg(long, value_delimiter = ',')]
        spp_ladder: Option<Vec<u32>>,
        /// Image size WxH for every variant (must match the reference).
        #[arg(long, value_parser = parse_size)]
        size: Option<(u32, u32)>,
        /// Worker threads (0 = all cores).
        #[arg(long, visible_alias = "nthreads", default_value_t = 0, value_parser = parse_count::<usize>)]
        threads: usize,
        /// Output folder.
        #[arg(long, short = 'o', default_value = "compare")]
        out: PathBuf,
        /// Also write the rows (as OUT/rows.json) to this file.
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
        /// Write each variant's phase profile over its profiled renders, one per step (the keys of
        /// `strata profile --json`, plus `variant`; `overhead` is the profiler's cost against the
        /// unprofiled runs, `overhead_share` the runs' CPU share outside samples) as a JSON list to
        /// this file.
        #[arg(long, value_name = "FILE")]
        profile: Option<PathBuf>,
        /// Write the variants' phase profiles as an SVG stacked bar chart (one bar per variant).
        #[arg(long, value_name = "FILE")]
        profile_svg: Option<PathBuf>,
    },
    /// Merge the part files of `render --samples A..B` shards (checkpoints) into OUT.exr and
    /// OUT.png, bit-identical to one render of the whole range; refuses parts of another render,
    /// unfinished parts, overlaps and gaps.
    #[command(allow_negative_numbers = true)]
    Merge {
        /// Part files (.ckpt), any order.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Output stem: writes OUT.exr and OUT.png.
        #[arg(short = 'o', long = "out")]
        out: PathBuf,
        /// Print nothing on success.
        #[arg(long, short = 'q')]
        quiet: bool,
        /// Merge parts written by different builds of strata (refused by default: samples may
        /// differ between builds); the merged EXR's strata.build lists them.
        #[arg(long)]
        allow_other_build: bool,
    },
    /// Write a procedural OBJ+MTL mesh (bumpy torus on a floor under an emissive patch) of at least
    /// --triangles triangles, for throughput runs: OUT.obj and OUT.mtl.
    #[command(allow_negative_numbers = true)]
    GenMesh {
        /// Output OBJ path (the MTL is written beside it).
        out: PathBuf,
        /// Minimum number of triangles of the torus.
        #[arg(long, default_value_t = 1_000_000, value_parser = parse_count::<usize>)]
        triangles: usize,
    },
    /// Regenerate the seed experiments (direct lighting light samplers; path tracing pixel
    /// stratification, cosine, BRDF sampling) into DIR: results.md/json, report.html (flip-books,
    /// error maps, tables, plots), SVG plots.
    #[command(allow_negative_numbers = true)]
    Experiments {
        /// Output folder.
        #[arg(long, default_value = "docs/experiments")]
        out: PathBuf,
        /// The CSE168 corpus (default ../shared/cse168 beside the crate, or $STRATA_CSE168).
        #[arg(long)]
        corpus: Option<PathBuf>,
        /// Independent runs per variant (K).
        #[arg(long, default_value_t = 16, value_parser = parse_count::<usize>)]
        runs: usize,
        /// Image width (heights keep each scene's aspect).
        #[arg(long, default_value_t = 160, value_parser = parse_positive::<u32>)]
        width: u32,
        /// Light samples of each half of the direct-lighting reference.
        #[arg(long, default_value_t = 4096, value_parser = parse_positive::<u32>)]
        ref_light_samples: u32,
        /// spp of the path-tracing references.
        #[arg(long, default_value_t = 1024, value_parser = parse_positive::<u32>)]
        ref_spp: u32,
        /// Worker threads (0 = all cores).
        #[arg(long, visible_alias = "nthreads", default_value_t = 0, value_parser = parse_count::<usize>)]
        threads: usize,
        /// report.html shows the images box-downsampled by this factor (keeps it small).
        #[arg(long, default_value_t = 2, value_parser = parse_positive::<u32>)]
        sheet_factor: u32,
    },
    /// Measure a point set (a file: UTK text, UTK .bin, .npy; or a registry sampler NAME): per set
    /// the L2 star discrepancy and minimum distance, the radial power spectrum (CSV, SVG) and the
    /// integration error on a disk and a Gaussian for N = 4..4096 with the fitted slope.
    Pointset {
        /// Point-set file or registry sampler name.
        target: String,
        /// Folder for spectrum.csv/svg, integration.csv/svg and pointset.json.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write the sets to FILE (.txt UTK text, .bin UTK binary, .npy NumPy): a layout's sets
        /// (set j = pixel j's points), or a file's in another format.
        #[arg(long, value_name = "FILE")]
        export: Option<PathBuf>,
        /// Registry layouts: number of sets (set j is pixel j's).
        #[arg(long, default_value_t = 4)]
        sets: u32,
        /// Registry layouts: points per set.
        #[arg(long, default_value_t = 1024)]
        points: u32,
        /// Base seed (layouts' sets; the integration test's randomizations).
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Registry layouts: sampler dimension of the sets (0 = the camera's).
        #[arg(long, default_value_t = 0)]
        dim: u32,
        /// Registry layouts: image width the pixel ids refer to (screen-space layouts, e.g. zsobol).
        #[arg(long, default_value_t = 0)]
        width: u32,
        /// Randomizations per N in the integration test.
        #[arg(long, default_value_t = 256)]
        trials: u32,
        /// Largest radial frequency of the spectrum.
        #[arg(long, default_value_t = 64)]
        max_freq: usize,
        /// Files: how the integration test randomizes the sets (as a render would), e.g.
        /// scramble=owen (repeatable).
        #[arg(long = "option", value_name = "KEY=VALUE")]
        options: Vec<String>,
    },
    /// Measure the whole renderer's rays/s next to Embree's raw rate on the same packets (1 thread), and Embree's rate on the same rays 16 and 1 at a time.
    #[command(allow_negative_numbers = true)]
    Rays {
        #[command(flatten)]
        args: RenderArgs,
        /// `--json`: print the rates as JSON instead of a table; `--json=FILE`: write them there
        /// (and print the table).
        #[arg(long, value_name = "FILE", num_args = 0..=1, require_equals = true, default_missing_value = "-")]
        json: Option<PathBuf>,
    },
    /// Break the worker threads' time into phases (sampler by dimension group, emitter sampling,
    /// Embree intersect/occluded, user geometry, hit gather, BSDF sampling and eval, MIS,
    /// accumulation, film, other) with % of render, ns per sample and ns per ray; the overhead is
    /// measured by rendering the same job unprofiled, interleaved.
    #[command(allow_negative_numbers = true)]
    Profile {
        #[command(flatten)]
        args: RenderArgs,
        /// Also write the profile as JSON to this file.
        #[arg(long = "json", value_name = "FILE")]
        json_file: Option<PathBuf>,
        /// Also write the phases as an SVG stacked bar chart (shares in %, legend) to this file.
        #[arg(long = "svg", value_name = "FILE")]
        svg_file: Option<PathBuf>,
        /// Renders per mode (profiling off and on, interleaved); the fastest of each counts.
        #[arg(long, default_value_t = strata::session::profile::REPEATS, value_parser = parse_positive::<usize>)]
        repeats: usize,
    },
    /// Print this command-line reference as Markdown (docs/cli.md is its output; a test fails
    /// when that file is stale).
    #[command(hide = true)]
    HelpMarkdown,
    /// Check that a command line parses and passes the subcommand's refusals, without running it
    /// (the README's and docs' commands are tested so). Exit status 0 and `ok`, or the error.
    #[command(hide = true)]
    ParseCheck {
        /// The command line after `strata`.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
}

/// `render` and `reference`: the render flags, and `--json FILE` (the statistics, as `--stats`).
#[derive(clap::Args)]
pub(crate) struct RenderCmd {
    #[command(flatten)]
    pub(crate) args: RenderArgs,
    /// Write statistics as JSON to this file (the same as --stats).
    #[arg(long, value_name = "FILE", help_heading = OUTPUT, conflicts_with = "stats")]
    pub(crate) json: Option<PathBuf>,
}

/// `reference`: the render flags and `--replicas`.
#[derive(clap::Args)]
pub(crate) struct ReferenceCmd {
    #[command(flatten)]
    pub(crate) render: RenderCmd,
    /// Independent replicas (seeds and scrambles of their own) of spp/replicas samples each: the
    /// variance layer is their variance of the mean, right for every sampler (default: the
    /// largest divisor of --spp from 2 to 8, or with --resume the checkpoint's replicas; 1: one
    /// render and the i.i.d. formula, which overstates stratified and low-discrepancy samplers'
    /// error, but keeps --samples and periodic checkpoints). With replicas, --checkpoint holds
    /// every replica's state (written after each replica), and --resume with a larger --spp
    /// extends each replica: the same bits as rendering that spp at once.
    #[arg(long, help_heading = SAMPLING, value_parser = parse_positive::<u32>)]
    pub(crate) replicas: Option<u32>,
}

impl ReferenceCmd {
    /// The replicas: `--replicas`, else the records of the `--resume` checkpoint (one for a single
    /// render's), else [`strata::session::reference::default_replicas`] of its spp (1 for a shard or
    /// a time budget).
    pub(crate) fn replicas(&self) -> u32 {
        let a = &self.render.args;
        let single = a.samples.is_some() || a.time_budget.is_some();
        // An unreadable checkpoint counts as one render's: the render reports why it is unreadable.
        let resumed = a.resume.as_ref().map(|p| strata::checkpoint::read_replicas(p).map_or(1, |r| r.len() as u32));
        self.replicas.unwrap_or(match resumed {
            _ if single => 1,
            Some(n) => n,
            None => strata::session::reference::default_replicas(a.spp.unwrap_or(1)),
        })
    }
}

impl RenderCmd {
    /// The render flags, `--json` folded into `--stats`.
    pub(crate) fn into_args(self) -> RenderArgs {
        RenderArgs { stats: self.args.stats.or(self.json), ..self.args }
    }
}

#[derive(clap::Args)]
pub(crate) struct RenderArgs {
    /// Scene file (.test, .obj for a whole-scene OBJ, or .xml for a Mitsuba 3 scene); omitted:
    /// the built-in Cornell box.
    pub(crate) scene: Option<PathBuf>,
    /// A parameter of a Mitsuba XML scene, NAME=VALUE (repeatable; Mitsuba's flag): replaces
    /// `$NAME` in the scene, over its `<default name="NAME">`.
    #[arg(short = 'D', value_name = "NAME=VALUE", help_heading = SCENE, value_parser = parse_define)]
    pub(crate) define: Vec<(String, String)>,
    /// Camera "ex ey ez cx cy cz ux uy uz fovy" (the format's camera arguments), replacing the
    /// scene's (for an .obj, the automatic one, which is printed as a --camera line to edit).
    #[arg(long, help_heading = SCENE, value_parser = session::parse_camera, allow_hyphen_values = true)]
    pub(crate) camera: Option<strata::scene::desc::CameraDesc>,
    /// Up axis of an OBJ scene's automatic camera: x, y or z (default: guessed from the bounds,
    /// z when they are flat in z, else y; announced on stderr with the camera).
    #[arg(long, help_heading = SCENE, value_parser = parse_up)]
    pub(crate) up: Option<strata::scene::obj::frame::UpAxis>,
    /// Image size WxH, keeping the camera (default: the scene's size).
    #[arg(long, help_heading = SCENE, value_parser = parse_size)]
    pub(crate) size: Option<(u32, u32)>,
    /// Samples per pixel, at least 1 (default: the scene's spp).
    #[arg(long, help_heading = SAMPLING, value_parser = parse_positive::<u32>)]
    pub(crate) spp: Option<u32>,
    /// Base seed of every sample stream.
    #[arg(long, help_heading = SAMPLING, default_value_t = 0, value_parser = parse_count::<u64>)]
    pub(crate) seed: u64,
    // Every sampling dimension's layout; the help lists the sampler registry.
    #[arg(long, help_heading = SAMPLING, value_parser = parse_sampler, help = format!(
        "Sampler of every dimension (pixel, light point and choice, lobe, direction, roulette): {} \
         (default {}; --pixel-sampler and --light-sampler override their dimensions), or \
         file:PATH[?options] (a point-set file, as --light-sampler)",
        SamplerKind::help_list(),
        SamplerKind::DEFAULT.name()
    ))]
    pub(crate) sampler: Option<SamplerKind>,
    // Pixel sample layout; the help lists the sampler registry.
    #[arg(long, help_heading = SAMPLING, value_parser = parse_sampler, help = format!(
        "Pixel sample layout over a pixel's spp samples: {} (default {}; grid-center with --spp 1 \
         puts the sample at the pixel centre), or file:PATH[?options] (a point-set file, as --light-sampler)",
        SamplerKind::help_list(),
        SamplerKind::DEFAULT.name()
    ))]
    pub(crate) pixel_sampler: Option<SamplerKind>,
    /// Pixel sample 0: centre (or center; through the pixel centre like the CSE168 course code;
    /// default for .test scenes; O(1/spp) bias, see docs/fidelity.md) or jittered (strata's
    /// unbiased stratified layout; default for .obj scenes). spp 1 with centre is the course's
    /// deterministic image.
    #[arg(long, help_heading = SAMPLING, value_parser = parse_first_sample)]
    pub(crate) first_sample: Option<strata::integrator::FirstSample>,
    // Light sample layout; the help lists the sampler registry.
    #[arg(long, help_heading = LIGHTS, value_parser = parse_sampler, help = format!(
        "Light sample layout (light point and choice, in direct and the path tracer): {}, or \
         file:PATH[?scramble=shift|owen|xor|none&sets=hash|pixel&pad=NAME] (a point-set file: UTK text, \
         UTK .bin or .npy; see docs/POINTSETS.md)",
        SamplerKind::help_list()
    ))]
    pub(crate) light_sampler: Option<SamplerKind>,
    /// Where a one-light choice (a --light-selection other than all) takes its number from:
    /// reuse (the light point's first coordinate, remapped, as Mitsuba does; default) or dimension
    /// (a sampler dimension of its own).
    #[arg(long, help_heading = LIGHTS, value_name = "MODE")]
    pub(crate) light_choice: Option<strata::integrator::LightChoice>,
    /// How a point is placed on the chosen area light (direct and the path tracer): area (uniform
    /// in area; default, except in scenes with sphere lights) or solid-angle (uniform in the solid
    /// angle the light subtends: spherical rectangles for rectangular quads, spherical triangles
    /// for emissive triangles, the visible cap's cone for sphere lights, as Mitsuba does; area
    /// sampling where a polygon subtends less than 3e-4 sr, or from inside a sphere). See
    /// docs/light-selection.md.
    #[arg(long, help_heading = LIGHTS, value_name = "WARP")]
    pub(crate) light_warp: Option<strata::integrator::LightWarp>,
    /// Light samples per light, at least 1 (default: the scene's lightsamples).
    #[arg(long, help_heading = LIGHTS, value_parser = parse_positive::<u32>)]
    pub(crate) light_samples: Option<u32>,
    /// direct: BSDF samples per shading point, combined with the light samples by the power
    /// heuristic as Mitsuba's direct does; 0 samples the lights alone (default: the scene's,
    /// Mitsuba's bsdf_samples; 0 for .test and OBJ scenes).
    #[arg(long, help_heading = LIGHTS, value_parser = parse_count::<u32>)]
    pub(crate) bsdf_samples: Option<u32>,
    // Light selection; the help lists the rule registry.
    #[arg(long, help_heading = LIGHTS, value_name = "NAME", help = format!(
        "Light selection of next-event estimation (direct and the path tracer): {}. Default: all for \
         .test scenes, uniform for .obj scenes",
        strata::integrator::LightSelection::help_list()
    ))]
    pub(crate) light_selection: Option<strata::integrator::LightSelection>,
    /// A constant environment light ("sky") of this radiance, R or R,G,B (path tracer; sampled
    /// at every vertex besides the area lights, NEE and MIS like any light; escaped camera rays
    /// see it as the background).
    #[arg(long, help_heading = LIGHTS, value_name = "RADIANCE", value_parser = parse_sky)]
    pub(crate) sky: Option<glam::Vec3>,
    /// Keep an OBJ scene without emitters unlit (by default an area light is added: above and
    /// behind the camera, or under the ceiling when the camera is inside; announced on stderr).
    #[arg(long, help_heading = LIGHTS)]
    pub(crate) no_default_light: bool,
    /// Integrator override: raytracer, analyticdirect, direct, pathtracer, ptracer.
    #[arg(long, help_heading = INTEGRATOR, value_parser = parse_integrator)]
    pub(crate) integrator: Option<IntegratorKind>,
    /// Path tracer direction sampling: hemisphere, cosine, brdf (default: the scene's importancesampling).
    #[arg(long, help_heading = INTEGRATOR, value_parser = parse_importance_sampling)]
    pub(crate) importance_sampling: Option<ImportanceSampling>,
    /// Path tracer next event estimation: off, on, mis (default: the scene's nexteventestimation).
    #[arg(long, help_heading = INTEGRATOR, value_parser = parse_nee)]
    pub(crate) nee: Option<Nee>,
    /// Path tracer Russian roulette: on, off (default: the scene's russianroulette).
    #[arg(long, help_heading = INTEGRATOR, value_parser = parse_on_off)]
    pub(crate) russian_roulette: Option<bool>,
    /// Maximum depth: -1 (unbounded) or a depth >= 0 (default: the scene's maxdepth).
    #[arg(long, help_heading = INTEGRATOR, value_parser = parse_max_depth)]
    pub(crate) max_depth: Option<i32>,
    /// Path tracer only, opt-in and BIASED: scale each pixel sample down so its largest RGB channel is
    /// at most MAX (trades fireflies for a darker, inconsistent estimate; off by default).
    #[arg(long, help_heading = INTEGRATOR, value_name = "MAX", value_parser = parse_clamp)]
    pub(crate) clamp: Option<f32>,
    /// Shading kernel: `auto` runs the one compiled for the scene's features (see `features` and
    /// `kernel` in --stats), `general` the one with every feature compiled in. Same image either way.
    #[arg(long, help_heading = INTEGRATOR, default_value = "auto", value_parser = ["auto", "general"])]
    pub(crate) kernel: String,
    /// Output stem: writes OUT.exr and OUT.png; `-o out.exr` means the stem `out` (default: the
    /// scene's output name).
    #[arg(short = 'o', long = "out", visible_alias = "outfile", help_heading = OUTPUT)]
    pub(crate) out: Option<PathBuf>,
    /// Write statistics as JSON to this file (render and reference: `--json FILE` is the same).
    #[arg(long, value_name = "FILE", help_heading = OUTPUT)]
    pub(crate) stats: Option<PathBuf>,
    /// Profile the render's phases (as `strata profile`, without its unprofiled re-render) and write
    /// the profile JSON to this file; the image is bit-identical either way.
    #[arg(long, value_name = "FILE", help_heading = OUTPUT)]
    pub(crate) profile: Option<PathBuf>,
    /// 8-bit PNG values: truncate (the CSE168 course's writer, floor(255 c); default for .test scenes)
    /// or round (default for .obj scenes). The EXR is linear and not affected.
    #[arg(long, help_heading = OUTPUT, value_parser = parse_quantize)]
    pub(crate) quantize: Option<strata::film::Quantize>,
    /// Print nothing on success.
    #[arg(long, short = 'q', help_heading = OUTPUT)]
    pub(crate) quiet: bool,
    /// Write the accumulated state here (atomically) every --checkpoint-every seconds and at the
    /// end; resume it with --resume. Default with --samples or on Ctrl-C: OUT.ckpt.
    #[arg(long, help_heading = CHECKPOINTS)]
    pub(crate) checkpoint: Option<PathBuf>,
    /// Wall-clock seconds between checkpoints (0: after every pass; default 300).
    #[arg(long, value_name = "SECONDS", help_heading = CHECKPOINTS, value_parser = parse_interval)]
    pub(crate) checkpoint_every: Option<f64>,
    /// Continue the render held in this checkpoint (refused if the scene or an option differs);
    /// it keeps being checkpointed there unless --checkpoint says otherwise.
    #[arg(long, help_heading = CHECKPOINTS)]
    pub(crate) resume: Option<PathBuf>,
    /// Render only sample indices A..B (0 <= A < B <= spp) of every pixel: a part for `strata merge`.
    #[arg(long, help_heading = CHECKPOINTS, value_parser = parse_range)]
    pub(crate) samples: Option<(u32, u32)>,
    /// --resume a checkpoint written by another build of strata (refused by default: samples may
    /// differ between builds).
    #[arg(long, help_heading = CHECKPOINTS)]
    pub(crate) allow_other_build: bool,
    /// Worker threads (0 = all cores).
    #[arg(long, visible_alias = "nthreads", help_heading = LIMITS, default_value_t = 0, value_parser = parse_count::<usize>)]
    pub(crate) threads: usize,
    /// Render whole passes until this many wall-clock seconds are spent and record the spp
    /// reached (progressive samplers continue their sequence across passes; a sampler that needs
    /// its count in advance is refused; --spp, if given, caps the samples).
    #[arg(long, visible_alias = "wall-budget", value_name = "WALL_SECONDS", help_heading = LIMITS, value_parser = parse_seconds)]
    pub(crate) time_budget: Option<f64>,
    /// Raise or lower a resource cap, NAME=VALUE (repeatable): max_pixels, max_side, max_vertices,
    /// max_primitives, max_spp, max_depth, max_light_samples, max_transform_depth, max_threads,
    /// max_memory (bytes the render may use; default 80% of physical memory or the cgroup's limit),
    /// max_file_bytes (size of a scene, OBJ or MTL file).
    #[arg(long = "limit", value_name = "NAME=VALUE", help_heading = LIMITS, value_parser = parse_limit)]
    pub(crate) limits: Vec<String>,
}

impl RenderArgs {
    /// The flags given that write nothing in `rays` and `profile` (which render no image), as
    /// they are spelled.
    pub(crate) fn unused_by_measurements(&self) -> Vec<&'static str> {
        [
            (self.out.is_some(), "-o/--out"),
            (self.stats.is_some(), "--stats"),
            (self.quantize.is_some(), "--quantize"),
            (self.checkpoint.is_some(), "--checkpoint"),
            (self.checkpoint_every.is_some(), "--checkpoint-every"),
            (self.resume.is_some(), "--resume"),
            (self.samples.is_some(), "--samples"),
            (self.time_budget.is_some(), "--time-budget"),
        ]
        .into_iter()
        .filter_map(|(given, flag)| given.then_some(flag))
        .collect()
    }

    pub(crate) fn options(self) -> RenderOptions {
        RenderOptions {
            scene: self.scene,
            parsed: None,
            spp: self.spp,
            size: self.size,
            seed: self.seed,
            threads: self.threads,
            sampler: self.sampler,
            light_sampler: self.light_sampler,
            light_choice: self.light_choice,
            light_warp: self.light_warp,
            light_samples: self.light_samples,
            bsdf_samples: self.bsdf_samples,
            pixel_sampler: self.pixel_sampler,
            out: self.out,
            stats: self.stats,
            profile: self.profile,
            integrator: self.integrator,
            progress: !self.quiet,
            general_kernel: self.kernel == "general",
            clamp: self.clamp,
            checkpoint: self.checkpoint,
            checkpoint_every: Some(self.checkpoint_every.unwrap_or(session::DEFAULT_CHECKPOINT_EVERY)),
            resume: self.resume,
            samples: self.samples,
            time_budget: self.time_budget,
            stop: None,
            camera: self.camera,
            importance_sampling: self.importance_sampling,
            nee: self.nee,
            russian_roulette: self.russian_roulette,
            max_depth: self.max_depth,
            limits: limits_of(&self.limits),
            quantize: self.quantize,
            first_sample: self.first_sample,
            light_selection: self.light_selection,
            no_default_light: self.no_default_light,
            allow_other_build: self.allow_other_build,
            up: self.up,
            sky: self.sky,
            defines: self.define,
            rendering: None,
        }
    }
}

/// The command-line reference as Markdown: every visible subcommand's `--help`, as clap renders it.
pub(crate) fn help_markdown() -> String {
    use clap::CommandFactory;
    let mut cmd = Cli::command();
    cmd.build();
    let mut md = String::from(
        "# strata command-line reference\n\n\
         Generated from the command line's own definitions by `strata help-markdown` (hidden); \
         `tests/it/docs.rs` fails when this file is stale. Regenerate it with\n\
         `cargo run --release -- help-markdown > docs/cli.md`.\n\n",
    );
    let top = cmd.clone();
    md.push_str("Subcommands:");
    let visible = |s: &&clap::Command| !s.is_hide_set() && s.get_name() != "help";
    for sub in top.get_subcommands().filter(visible) {
        md.push_str(&format!(" [`{0}`](#strata-{0}),", sub.get_name()));
    }
    md.pop();
    md.push_str(".\n\n## strata\n\n```text\n");
    md.push_str(&cmd.render_long_help().to_string());
    md.push_str("```\n");
    for sub in top.get_subcommands().filter(visible) {
        let name = sub.get_name().to_string();
        let mut s = sub.clone().bin_name(format!("strata {name}"));
        md.push_str(&format!("\n## strata {name}\n\n```text\n{}```\n", s.render_long_help()));
    }
    md
}

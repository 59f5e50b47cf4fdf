//! The session layer's error: what `strata render`, `reference` and `rays` report (the CLI prints
//! it after `strata: `). Errors of the layers below are wrapped with their messages unchanged.

use crate::checkpoint::CheckpointError;
use crate::scene::build::BuildError;
use crate::scene::error::SceneError;
use std::path::PathBuf;

/// Why a render session could not run or write its outputs.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// The scene file could not be parsed (the scene layer's `FILE:LINE: message`).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The parsed scene could not be built (the build's message).
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The scene file could not be read for its hash.
    #[error("{}: cannot read scene file: {source}", path.display())]
    SceneRead {
        /// the scene file
        path: PathBuf,
        /// the I/O error
        source: std::io::Error,
    },
    /// `--camera` does not parse: the message of the `.test` parser's error for the `camera`
    /// command it makes of the value.
    #[error("{}", .0.message)]
    Camera(#[source] SceneError),
    /// `--camera` parsed without giving a camera.
    #[error("--camera expects 10 numbers")]
    CameraMissing,
    /// `--size` with a zero side.
    #[error("--size {w}x{h}: width and height must be positive")]
    SizeNotPositive {
        /// width asked
        w: u32,
        /// height asked
        h: u32,
    },
    /// A command-line value above a resource cap (`--size`, `--spp`, `--light-samples`).
    #[error("--{flag} {value} exceeds the limit of {max}{unit} ({hint})")]
    OverLimit {
        /// the flag without dashes
        flag: &'static str,
        /// the value as given
        value: String,
        /// the cap
        max: u64,
        /// unit after the cap ("" or " pixels per side", " pixels")
        unit: &'static str,
        /// how to raise the cap
        hint: String,
    },
    /// `--max-depth` outside its range.
    #[error("--sky (and any environment or delta light) needs the path tracer or direct (the scene's integrator is {integrator}); add --integrator pathtracer")]
    /// A sky with an integrator that does not trace paths.
    SkyNeedsPathTracer {
        /// the integrator's name
        integrator: &'static str,
    },
    /// `strata rays` with an integrator whose rays it cannot log (the particle tracer).
    #[error("strata rays: the {integrator} integrator's light paths are not logged for the replay; measure another integrator")]
    RaysNotLogged {
        /// the integrator's name
        integrator: &'static str,
    },
    #[error("--max-depth {depth} is outside -1..={max} ({hint})")]
    MaxDepth {
        /// depth asked
        depth: i32,
        /// the cap
        max: i32,
        /// how to raise the cap
        hint: String,
    },
    /// A flag that changes nothing for the integrator that runs.
    #[error("{flag} changes nothing here: {why}")]
    FlagIgnored {
        /// the flag
        flag: &'static str,
        /// why it changes nothing
        why: String,
    },
    /// An equal-time run (`--time-budget`) of a sampler that needs its sample count.
    #[error(transparent)]
    NotProgressive(#[from] crate::integrator::NotProgressive),
    /// `--time-budget` not a positive number.
    #[error("--time-budget {}: expected a positive number of seconds", short_f64(*.0))]
    TimeBudget(f64),
    /// `--checkpoint-every` negative or not finite.
    #[error("--checkpoint-every {}: expected a number of seconds >= 0", short_f64(*.0))]
    CheckpointEvery(f64),
    /// `--samples A..B` outside the spp.
    #[error("--samples {a}..{b}: expected A < B <= spp ({cap})")]
    Samples {
        /// start asked
        a: u32,
        /// end asked
        b: u32,
        /// the spp cap
        cap: u32,
    },
    /// `--resume` of a checkpoint of another render.
    #[error("{}: cannot resume: {why}", path.display())]
    ResumeMismatch {
        /// the checkpoint
        path: PathBuf,
        /// what differs
        why: String,
    },
    /// `--resume` of a checkpoint whose samples do not start the requested range.
    #[error("{}: cannot resume: it holds samples {}..{}, which do not start the requested range {}..{}", path.display(), have[0], have[1], target[0], target[1])]
    ResumeRange {
        /// the checkpoint
        path: PathBuf,
        /// the samples it holds
        have: [u32; 2],
        /// the range asked for
        target: [u32; 2],
    },
    /// `--resume` with a larger `--spp` of a render whose samples depend on their total count.
    #[error("{}: cannot extend it from {have} to {asked} spp: {why}; render {asked} spp afresh", path.display())]
    ResumeGrow {
        /// the checkpoint
        path: PathBuf,
        /// the spp of the render it holds
        have: u64,
        /// the spp asked for
        asked: u64,
        /// which layout is bound to its count, and why
        why: String,
    },
    /// Reading or writing a checkpoint.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// The worker pool could not start.
    #[error(transparent)]
    ThreadPool(#[from] crate::render::RenderError),
    /// An output file (image, stats) could not be written.
    #[error("{}: {source}", path.display())]
    Output {
        /// the file
        path: PathBuf,
        /// the I/O error
        source: std::io::Error,
    },
    /// The stats JSON did not serialize.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// An output directory (image, checkpoint, stats) cannot be written; found before rendering.
    #[error("{}: cannot write there ({source}); checked before rendering, nothing was traced", dir.display())]
    NotWritable {
        /// the directory
        dir: PathBuf,
        /// the I/O error of the probe file
        source: std::io::Error,
    },
    /// A sampler asked for more points than it has distinct ones.
    #[error(
        "{sampler} has {period} distinct points per pixel; {asked} would repeat them (use --{flag} {alternative})"
    )]
    SamplerPeriod {
        /// the sampler's name
        sampler: &'static str,
        /// its distinct points per (pixel, dim)
        period: u64,
        /// what was asked, as a phrase ("8192 spp")
        asked: String,
        /// the flag choosing the sampler, without dashes
        flag: &'static str,
        /// a sampler without that limit
        alternative: &'static str,
    },
    /// The render ended without a single sample (time budget spent or interrupted before the
    /// first pass): nothing is written, the outputs of an earlier run stay as they were.
    #[error("no sample was rendered ({0}); nothing written, existing outputs left as they were")]
    NoSamples(String),
    /// `--spp 0` or `--light-samples 0` (as `spp 0` / `lightsamples 0` in a scene file).
    #[error("--{flag} 0: expected at least 1 (as in a scene file)")]
    Zero {
        /// the flag without dashes
        flag: &'static str,
    },
    /// An output path that cannot be used: a directory, a link or device, or one that collides
    /// with another output or an input; found before rendering.
    #[error("{}: {why}; checked before rendering, nothing was traced", path.display())]
    BadOutput {
        /// the path
        path: PathBuf,
        /// what is wrong with it
        why: String,
    },
    /// The render would need more memory than `--limit max_memory` allows.
    #[error("{what}: the render needs about {need} ({breakdown}), above the limit of {limit} ({hint})")]
    Memory {
        /// what is rendered (scene and size)
        what: String,
        /// the estimate, formatted
        need: String,
        /// the estimate's parts
        breakdown: String,
        /// the limit, formatted
        limit: String,
        /// how to raise the limit
        hint: String,
    },
    /// The final checkpoint could not be written after the images were.
    #[error("{source} (the images {}.exr and {}.png were written; only the checkpoint is missing)", images.display(), images.display())]
    CheckpointAfterImages {
        /// the output stem written
        images: PathBuf,
        /// the checkpoint error
        source: Box<SessionError>,
    },
    /// Every triangle of a scene without other geometry was dropped: nothing would be rendered.
    #[error("{}: every triangle was dropped ({zero} zero-area, {huge} with an area that overflows f32): nothing is left to render", path.display())]
    NothingLeft {
        /// the scene file
        path: PathBuf,
        /// zero-area triangles
        zero: usize,
        /// triangles whose area overflows f32
        huge: usize,
    },
    /// Outputs of a finished render that could not be written, and those that were (each output
    /// is tried whatever happened to the others).
    #[error("{failed}; {written}")]
    OutputsFailed {
        /// the errors, joined
        failed: String,
        /// what was written (`written: A, B`), or `nothing was written`
        written: String,
    },
    /// A point-set file (or array) has fewer points per set than the render draws per pixel.
    #[error(
        "{sampler}: its sets have {points} points, but {asked} are drawn per pixel (sets of {points} points \
         are the limit: lower {lower}, or give sets of at least {need} points)"
    )]
    FilePoints {
        /// the sampler's name (`file:PATH`)
        sampler: &'static str,
        /// points per set
        points: u64,
        /// what was asked, as a phrase ("64 spp")
        asked: String,
        /// points needed
        need: u64,
        /// the flags that lower the count ("--spp", "--spp or --light-samples")
        lower: &'static str,
    },
    /// A signal handler could not be installed.
    #[error("signal handler: {0}")]
    Signal(std::io::Error),
    /// `strata reference --replicas`: what a replicated reference cannot do.
    #[error("reference: {why}")]
    Replicas {
        /// what was refused and why
        why: String,
    },
}

/// `v` as Rust prints it when that is short, else in scientific notation (`-1e-300`, not 300
/// digits).
pub fn short_f64(v: f64) -> String {
    let plain = v.to_string();
    if plain.len() <= 24 {
        plain
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests {
    /// Before: `--time-budget -1e-300` from the library printed the number with 300 digits.
    #[test]
    fn tiny_numbers_print_short() {
        assert_eq!(super::short_f64(-1e-300), "-1e-300");
        assert_eq!(super::short_f64(2.5), "2.5");
        let e = super::SessionError::TimeBudget(-1e-300).to_string();
        assert!(e.len() < 80 && e.contains("-1e-300"), "{e}");
    }
}

//! An integrator's settings, resolved from the scene and the command line: which estimator,
//! the sample layouts of its dimensions (pixel, light, path) and the light selection. Every
//! integrator reads them through [`Integrator`]; [`Integrator::radiance_tile`] (in `mod.rs`)
//! dispatches to the registered estimator.

use super::direct_settings::DirectSettings;
use super::kernel::Kernel;
use super::path::settings::PathSettings;
use crate::camera::{Camera, FirstSample};
use crate::light::select::{LightChoice, LightSampler, LightSelection};
use crate::sampler::{GridTable, PointSet, SamplerKind};
use crate::scene::build::Scene;
use crate::scene::desc::IntegratorKind;

/// `direct`'s choice among the emissive triangles under `all` (see `triangle_sampler`).
const POWER: LightSelection = LightSelection::named("power");

/// The samplers asked for (`--sampler`, `--pixel-sampler`, `--light-sampler`); `None` takes the
/// default. `sampler` sets every dimension, the other two override theirs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SamplerChoice {
    /// every dimension (`--sampler`)
    pub sampler: Option<SamplerKind>,
    /// the pixel (camera) dimension (`--pixel-sampler`)
    pub pixel: Option<SamplerKind>,
    /// the light dimensions: light point and light choice (`--light-sampler`)
    pub light: Option<SamplerKind>,
}

/// An equal-time run asked for a layout that needs its sample count in advance.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "{flag} {name} needs the number of samples per pixel in advance, which an equal-time run does not know; \
     progressive samplers: {progressive}"
)]
pub struct NotProgressive {
    /// the flag that named it
    pub flag: &'static str,
    /// the sampler
    pub name: &'static str,
    /// the progressive samplers, comma-separated
    pub progressive: String,
}

/// An integrator with its settings resolved from the scene and the command line.
#[derive(Clone, Debug)]
pub struct Integrator {
    /// which estimator
    pub kind: IntegratorKind,
    /// samples per pixel (`u32::MAX` in equal-time runs: not known in advance)
    pub spp: u32,
    /// base seed
    pub seed: u64,
    /// what was asked for (the layouts below are resolved from it)
    pub samplers: SamplerChoice,
    /// pixel sample layout (over the spp samples of a pixel)
    pub pixel_set: PointSet,
    /// light sample layout, `n` = light samples per pixel sample (`direct`'s per-sample grid,
    /// and the number of samples per light of `all`)
    pub light_set: PointSet,
    /// light dimensions drawn over all of a pixel's light samples (spp x N for `direct`, spp for
    /// the path tracer): every light layout except a grid with N > 1 (see [`Integrator::light_streams`])
    pub light_table: GridTable,
    /// path tracer: layout of the other path dimensions (direction, lobe, roulette) over the spp
    /// samples of a pixel
    pub path_set: GridTable,
    /// the path tracer's own settings (NEE, roulette, strategy, clamp)
    pub path: PathSettings,
    /// `direct`'s own settings (BSDF samples, emitter sampling)
    pub direct: DirectSettings,
    /// `raytracer` and path tracer: maximum bounces (-1 = unbounded)
    pub max_depth: i32,
    /// the kernel that runs (specialized for the scene's features, or [`Kernel::GENERAL`])
    pub kernel: Kernel,
    /// where pixel sample 0 goes ([`FirstSample`]; `new` gives `Jittered`)
    pub first_sample: FirstSample,
    /// how NEE chooses lights (`new` gives [`LightSelection::UNIFORM`]; see
    /// [`Integrator::set_light_selection`])
    pub light_selection: LightSelection,
    /// where a one-light choice takes its number from (`--light-choice`; default reuse)
    pub light_choice: LightChoice,
    /// how a point is placed on the chosen area light (`--light-warp`; `new` gives area)
    pub light_warp: crate::light::warp::LightWarp,
    /// the light sampler of `light_selection` over the scene's emitters (shared by the threads)
    pub light_sampler: std::sync::Arc<LightSampler>,
    /// `direct` under `all`: the power choice among the emissive triangles (one sampling group)
    pub triangle_sampler: std::sync::Arc<LightSampler>,
}

impl Integrator {
    /// Settings from the scene, overridden by explicit choices. Defaults: stratified everywhere,
    /// except `direct`'s light dimensions, which follow the scene's `lightstratify` (stratified
    /// or independent).
    pub fn new(scene: &Scene, spp: u32, seed: u64, samplers: SamplerChoice, light_samples: Option<u32>) -> Self {
        let d = &scene.desc;
        let n_light = light_samples.unwrap_or(d.light_samples).max(1);
        let spp = spp.max(1);
        let sets = Sets::resolve(d, samplers, spp, n_light);
        Self {
            kind: d.integrator,
            spp,
            seed,
            samplers,
            pixel_set: sets.pixel,
            light_set: sets.light,
            light_table: sets.light_table,
            path_set: sets.path,
            path: PathSettings::of(d),
            direct: DirectSettings::of(d),
            max_depth: d.max_depth,
            kernel: Kernel::for_scene(scene),
            first_sample: FirstSample::Jittered,
            light_selection: LightSelection::UNIFORM,
            light_choice: LightChoice::Reuse,
            light_warp: crate::light::warp::LightWarp::Area,
            light_sampler: std::sync::Arc::new(LightSampler::new(&scene.emitters.list, LightSelection::UNIFORM)),
            triangle_sampler: std::sync::Arc::new(LightSampler::over_range(
                &scene.emitters.list,
                scene.emitters.n_quads..scene.emitters.list.len(),
                POWER,
            )),
        }
    }

    /// Switches NEE's light selection to `selection`, building its sampler over `scene`'s emitters.
    pub fn set_light_selection(&mut self, scene: &Scene, selection: LightSelection) {
        self.light_selection = selection;
        self.light_sampler = std::sync::Arc::new(LightSampler::new(&scene.emitters.list, selection));
    }

    /// `direct` draws its light points from per-pixel-sample streams of `light_set` (a grid layout
    /// with N > 1 light samples: the course's jittered grid over the N samples of each pixel
    /// sample); otherwise from `light_table`, over all spp x N light samples of the pixel.
    pub fn light_streams(&self) -> bool {
        self.light_set.kind().layout().cell_span(&self.light_set.shape(), 0).is_some() && self.light_set.n() > 1
    }

    /// The same integrator for `spp` samples per pixel: the per-pixel layouts are rebuilt for that
    /// count.
    pub fn resampled(&self, spp: u32) -> Self {
        let mut it = self.clone();
        it.spp = spp.max(1);
        it.set_layouts(self.kinds());
        it
    }

    /// The same integrator for an equal-time run, whose sample count is not known in advance
    /// (`spp` becomes `u32::MAX`): every layout must be progressive (continue the sample index
    /// across passes). A layout named on the command line that needs its count is refused with a
    /// message naming the progressive ones; a default one becomes `sobol` (the stats say so).
    pub fn equal_time(&self) -> Result<Self, NotProgressive> {
        let c = self.samplers;
        let named = [(c.pixel, "--pixel-sampler"), (c.light, "--light-sampler"), (c.sampler, "--sampler")];
        for (kind, flag) in named.into_iter().filter_map(|(k, f)| Some((k?, f))) {
            if !kind.info().progressive {
                return Err(NotProgressive { flag, name: kind.name(), progressive: progressive_names() });
            }
        }
        let keep = |k: SamplerKind| if k.info().progressive { k } else { SamplerKind::SOBOL };
        let mut it = self.clone();
        it.spp = u32::MAX;
        it.set_layouts(self.kinds().map(keep));
        Ok(it)
    }

    /// Rebuilds the layouts for `self.spp` with kinds [pixel, light, path].
    fn set_layouts(&mut self, kinds: [SamplerKind; 3]) {
        let sets = Sets::build(self.kind, kinds, self.spp, self.light_set.n(), self.pixel_set.shape().width());
        (self.pixel_set, self.light_set, self.light_table, self.path_set) =
            (sets.pixel, sets.light, sets.light_table, sets.path);
    }

    /// The resolved layouts: [pixel, light, other path dimensions].
    pub fn kinds(&self) -> [SamplerKind; 3] {
        [self.pixel_set.kind(), self.light_set.kind(), self.path_set.set().kind()]
    }

    /// The camera of this integrator on `scene` (its pixel sampler and seed).
    pub fn camera<'a>(&'a self, scene: &'a Scene) -> Camera<'a> {
        Camera::new(&scene.camera, &self.pixel_set, self.seed, self.first_sample)
    }
}

/// The progressive samplers' names, comma-separated (for messages).
pub fn progressive_names() -> String {
    crate::sampler::SAMPLERS.iter().filter(|s| s.progressive).map(|s| s.name).collect::<Vec<_>>().join(", ")
}

/// The layouts of one integrator.
struct Sets {
    pixel: PointSet,
    light: PointSet,
    light_table: GridTable,
    path: GridTable,
}

impl Sets {
    /// The layouts `samplers` asks for (defaults filled in) for `spp` samples and `n_light` light
    /// samples per pixel sample.
    fn resolve(d: &crate::scene::desc::SceneDesc, samplers: SamplerChoice, spp: u32, n_light: u32) -> Self {
        let base = samplers.sampler.unwrap_or(SamplerKind::DEFAULT);
        let light_default = if d.integrator.traces_paths() || d.light_stratify {
            base
        } else {
            samplers.sampler.unwrap_or(SamplerKind::INDEPENDENT)
        };
        let pixel = samplers.pixel.unwrap_or(base);
        let light = samplers.light.unwrap_or(light_default);
        Self::build(d.integrator, [pixel, light, base], spp, n_light, d.width)
    }

    /// The sets of kinds [pixel, light, path].
    fn build(kind: IntegratorKind, [pixel, light, path]: [SamplerKind; 3], spp: u32, n_light: u32, width: u32) -> Self {
        // The light table spans all of a pixel's light samples: spp x N for `direct`, spp for
        // the path tracer (one light sample per vertex).
        let per_pixel = if kind.traces_paths() { spp } else { spp.saturating_mul(n_light) };
        // What a layout builds on first use is built now, not in the timed tile loop.
        for k in [pixel, light, path] {
            k.layout().prepare();
        }
        Self {
            pixel: PointSet::for_image(pixel, spp, width),
            light: PointSet::for_image(light, n_light, width),
            light_table: GridTable::new(PointSet::for_image(light, per_pixel, width)),
            path: GridTable::new(PointSet::for_image(path, spp, width)),
        }
    }
}

//! The identity of a render (scene hash, version, size, every option that affects the image) as
//! a checkpoint [`Header`], and the EXR metadata written from one.

use crate::film::Metadata;
use crate::integrator::Integrator;
use crate::scene::build::Scene;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::collections::BTreeMap;

/// What a checkpoint records besides the moments.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// strata version that wrote it (part of the identity: sample values may change across versions)
    pub strata_version: String,
    /// the build that wrote it ([`BUILD`]: a hash of the sources, manifest, lock file and target
    /// features; part of the identity unless `--allow-other-build`; empty in older checkpoints)
    #[serde(default)]
    pub strata_build: String,
    /// the git commit of that build (informative)
    #[serde(default)]
    pub strata_commit: String,
    /// scene file as named on the command line (informative)
    pub scene: String,
    /// hash of the scene file's bytes ([`hash_bytes`], hex)
    pub scene_hash: String,
    /// every option that affects the image, resolved (spp, seed, samplers, integrator, ...)
    pub options: BTreeMap<String, serde_json::Value>,
    /// image width
    pub width: u32,
    /// image height
    pub height: u32,
    /// the sample range this run was asked for (`--samples`, else 0..spp)
    pub target: [u32; 2],
    /// the sample range held
    pub samples: [u32; 2],
    /// the dyadic blocks of `samples`, as (k, j)
    pub blocks: Vec<[u32; 2]>,
    /// CPU seconds of the worker threads rendering tiles (summed over sessions and parts)
    pub cpu_seconds: f64,
    /// wall-clock seconds of rendering (summed over sessions)
    pub render_seconds: f64,
    /// rays traced
    pub rays: u64,
    /// the files a merged state came from, with their ranges (empty for a render)
    pub parts: Vec<String>,
}

impl Header {
    /// Why a checkpoint with header `self` cannot continue or join a render with header `want`
    /// (other scene, version, size or options), or None if it can; `label` names `want` in the
    /// message (e.g. "this render").
    pub fn mismatch(&self, want: &Header, label: &str) -> Option<String> {
        self.mismatch_allowing(want, label, false)
    }

    /// The spp of a resumed checkpoint (`self`) and of the render resuming it (`want`) when the
    /// render asks for more samples and nothing else of their identity differs ([`Header::mismatch`]
    /// would be None with equal spp): the one change a resume may make, continuing a finished
    /// render whose layouts are progressive (the caller checks that: its samples must not depend on
    /// the total count). Fewer samples, or any other difference, is None.
    pub fn spp_growth(&self, want: &Header, other_build: bool) -> Option<(u64, u64)> {
        let spp = |h: &Header| h.options.get("spp").and_then(serde_json::Value::as_u64);
        let (have, asked) = (spp(self)?, spp(want)?);
        if asked <= have {
            return None;
        }
        let mut same = want.clone();
        same.options.insert("spp".into(), serde_json::json!(have));
        self.mismatch_allowing(&same, "", other_build).is_none().then_some((have, asked))
    }

    /// [`Header::mismatch`], except that with `other_build` a different build (see
    /// [`Header::strata_build`]) is accepted: the user vouches that both compute the same samples.
    pub fn mismatch_allowing(&self, want: &Header, label: &str, other_build: bool) -> Option<String> {
        if self.strata_build != want.strata_build && !other_build {
            let show = |b: &str, c: &str| {
                if b.is_empty() {
                    "an older strata".to_string()
                } else {
                    format!("build {b} (commit {c})")
                }
            };
            return Some(format!(
                "it was written by {} ({label}: {}); samples may differ between builds (give --allow-other-build if you know they do not)",
                show(&self.strata_build, &self.strata_commit),
                show(&want.strata_build, &want.strata_commit)
            ));
        }
        if self.scene_hash != want.scene_hash {
            return Some(format!(
                "it is of another scene ({} hash {}; {label}: {} hash {})",
                self.scene, self.scene_hash, want.scene, want.scene_hash
            ));
        }
        if self.strata_version != want.strata_version {
            return Some(format!(
                "it was written by strata {} ({label}: {})",
                self.strata_version, want.strata_version
            ));
        }
        if (self.width, self.height) != (want.width, want.height) {
            return Some(format!("it is {}x{} ({label}: {}x{})", self.width, self.height, want.width, want.height));
        }
        let keys: std::collections::BTreeSet<&String> = self.options.keys().chain(want.options.keys()).collect();
        let diffs: Vec<String> = keys
            .into_iter()
            .filter(|k| self.options.get(*k) != want.options.get(*k))
            .map(|k| {
                let show = |v: Option<&serde_json::Value>| v.map_or("(unset)".to_string(), |v| v.to_string());
                format!("{k} {} ({label}: {})", show(self.options.get(k)), show(want.options.get(k)))
            })
            .collect();
        // Both parts ran Embree's AVX2 kernels, on CPUs whose approximations differ.
        let approx = matches!((approx_of(self), approx_of(want)), (Some(a), Some(b)) if a != b);
        let hint = if approx {
            "; this CPU's approximate reciprocals (vrcpps, used by Embree's AVX2 kernels) differ from the \
             other's, so their pixels can differ: render every part on AVX-512 nodes without an isa pin \
             (Embree's AVX-512 kernels are exactly specified), or with isa=avx2 on one kind of CPU"
        } else {
            ""
        };
        (!diffs.is_empty()).then(|| format!("it was rendered with other options: {}{hint}", diffs.join(", ")))
    }
}

/// A header's `embree_approx` when it is a `vrcpps` fingerprint (Embree's AVX2 kernels).
fn approx_of(h: &Header) -> Option<&str> {
    h.options.get("embree_approx").and_then(|v| v.as_str()).filter(|v| v.starts_with("rcpps-"))
}

/// The build of this binary (`STRATA_BUILD` from build.rs: a hash of what was compiled into it).
pub const BUILD: &str = env!("STRATA_BUILD");
/// The git commit this binary was built from (`-dirty` with uncommitted source changes).
pub const COMMIT: &str = env!("STRATA_COMMIT");

/// The identity keys of the intersection backend ([`crate::scene::build::Backend`]): Embree's
/// instruction set, the reciprocal approximations its kernels use on this CPU, its version, the
/// BVH quality and the sphere intersector.
fn backend_options(scene: &Scene) -> [(&'static str, serde_json::Value); 5] {
    let b = &scene.backend;
    [
        ("embree_isa", json!(b.isa)),
        ("embree_approx", json!(b.approx)),
        ("embree_version", json!(b.embree)),
        ("bvh", json!(b.bvh)),
        ("spheres", json!(b.spheres)),
    ]
}

/// The identity of a render of `scene` with `it` (scene file hash `file_hash`, `time_budget`: the
/// spp is not fixed in advance) with empty ranges and totals.
pub fn identity(file_hash: &str, scene: &Scene, it: &Integrator, time_budget: bool) -> Header {
    let d = &scene.desc;
    let options: BTreeMap<String, serde_json::Value> = [
        ("integrator", json!(d.integrator.name())),
        ("spp", json!(it.spp)),
        ("seed", json!(it.seed)),
        ("pixel_sampler", json!(it.pixel_set.kind().name())),
        ("light_sampler", json!(it.light_set.kind().name())),
        ("light_samples", json!(it.light_set.n())),
        ("bsdf_samples", json!(it.direct.bsdf_samples)),
        ("emitter_sampling", json!(it.direct.emitter_sampling)),
        ("sampler", json!(it.path_set.set().kind().name())),
        ("light_choice", json!(it.light_choice.name())),
        ("light_warp", json!(it.light_warp.name())),
        ("layout", json!(if time_budget { "time-budget" } else { "spp" })),
        ("gamma", json!(d.gamma)),
        ("clamp", json!(it.path.clamp)),
        ("first_sample", json!(it.first_sample.name())),
        ("light_selection", json!(it.light_selection.name())),
    ]
    .into_iter()
    .chain(backend_options(scene))
    .map(|(k, v)| (k.to_string(), v))
    // A point-set file's (or array's) content is part of the identity, not only its name.
    .chain(
        [
            ("pixel_sampler", it.pixel_set.kind()),
            ("light_sampler", it.light_set.kind()),
            ("sampler", it.path_set.set().kind()),
        ]
        .into_iter()
        .filter_map(|(k, kind)| {
            crate::sampler::file::file_info(kind).map(|(digest, ..)| (format!("{k}_digest"), json!(digest)))
        }),
    )
    .collect();
    Header {
        strata_version: env!("CARGO_PKG_VERSION").to_string(),
        strata_build: BUILD.to_string(),
        strata_commit: COMMIT.to_string(),
        scene: d.source.display().to_string(),
        // The file's bytes and the parsed content (which covers included OBJ and MTL files).
        scene_hash: format!("{file_hash}-{:016x}", d.content_hash()),
        options,
        width: d.width,
        height: d.height,
        target: [0, 0],
        samples: [0, 0],
        blocks: Vec::new(),
        cpu_seconds: 0.0,
        render_seconds: 0.0,
        rays: 0,
        parts: Vec::new(),
    }
}

/// EXR metadata of a render or merge state: version, scene and its hash, integrator, samplers,
/// seed, spp held, sample range, total render and CPU seconds, rays, and the parts it came from.
pub fn header_metadata(h: &Header) -> Metadata {
    let opt =
        |k: &str| h.options.get(k).map_or(String::new(), |v| v.as_str().map_or_else(|| v.to_string(), str::to_string));
    let mut m: Metadata = vec![
        ("strata.version".into(), h.strata_version.clone()),
        ("strata.build".into(), h.strata_build.clone()),
        ("strata.commit".into(), h.strata_commit.clone()),
        ("strata.embree_isa".into(), opt("embree_isa")),
        ("strata.embree_approx".into(), opt("embree_approx")),
        ("strata.embree_version".into(), opt("embree_version")),
        ("strata.bvh".into(), opt("bvh")),
        ("strata.spheres".into(), opt("spheres")),
        ("strata.scene".into(), h.scene.clone()),
        ("strata.scene_hash".into(), h.scene_hash.clone()),
        ("strata.integrator".into(), opt("integrator")),
        ("strata.spp".into(), (h.samples[1] - h.samples[0]).to_string()),
        ("strata.samples".into(), format!("{}..{}", h.samples[0], h.samples[1])),
        ("strata.seed".into(), opt("seed")),
        ("strata.pixel_sampler".into(), opt("pixel_sampler")),
        ("strata.light_sampler".into(), opt("light_sampler")),
        ("strata.light_samples".into(), opt("light_samples")),
        ("strata.layout".into(), opt("layout")),
        ("strata.first_sample".into(), opt("first_sample")),
        ("strata.light_selection".into(), opt("light_selection")),
        ("strata.quantize".into(), opt("quantize")),
        ("strata.render_seconds".into(), format!("{:.6}", h.render_seconds)),
        ("strata.cpu_seconds".into(), format!("{:.6}", h.cpu_seconds)),
        ("strata.rays".into(), h.rays.to_string()),
    ];
    if !h.parts.is_empty() {
        m.push(("strata.parts".into(), h.parts.join("; ")));
        m.push(("strata.part_count".into(), h.parts.len().to_string()));
    }
    m
}

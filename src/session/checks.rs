//! Command-line checks made before any expensive work (thread cap, outputs: writable directories,
//! regular files or new names, no two the same file nor an input; sampler periods) and the
//! default light of an OBJ scene without emitters.

use super::{RenderOptions, SessionError};
use crate::film::{self, stem_of, with_ext};
use crate::sampler::SamplerKind;
use crate::scene::desc::{QuadLightDesc, SceneDesc};
use crate::scene::parse;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// Checks what the command line alone decides, before the scene is read: `--threads` within
/// `max_threads`, `-o` not a directory, and the outputs ([`check_outputs`] with the `-o` stem, or
/// "strata"; [`super::prepare`] checks them again with the scene's `output` name).
pub fn check_command_line(opts: &RenderOptions) -> Result<(), SessionError> {
    let max = opts.limits.max_threads;
    if opts.threads > max {
        return Err(SessionError::OverLimit {
            flag: "threads",
            value: opts.threads.to_string(),
            max: max as u64,
            unit: " threads (4x the cores by default)",
            hint: parse::limit_hint("max_threads"),
        });
    }
    // STRATA_EMBREE_CONFIG: refused before the scene is read (the device checks it again).
    crate::accel::EmbreeConfig::from_env().map_err(|e| SessionError::Build(e.into()))?;
    crate::scene::build::forced_bvh().map_err(SessionError::Build)?;
    crate::scene::build::forced_gather().map_err(SessionError::Build)?;
    match &opts.out {
        Some(o) => {
            film::check_stem(o).map_err(|e| SessionError::BadOutput { path: o.clone(), why: e.to_string() })?;
            check_outputs(opts, &stem_of(o), &[])
        }
        // The stem comes from the scene's `output`: checked again once the scene is read.
        None => check_outputs(opts, Path::new("strata"), &[]),
    }
}

/// The files a render of `opts` may write with output stem `stem`, each with what names it:
/// OUT.exr, OUT.png, the checkpoint (`--checkpoint`, else `--resume`, else OUT.ckpt, written with
/// `--samples` or on an interruption), `--stats` and `--profile`.
pub fn output_files(opts: &RenderOptions, stem: &Path) -> Vec<(String, PathBuf)> {
    let (exr, png) = (with_ext(stem, "exr"), with_ext(stem, "png"));
    let ckpt = opts.checkpoint.clone().or_else(|| opts.resume.clone()).unwrap_or_else(|| with_ext(stem, "ckpt"));
    let mut out =
        vec![("the image".to_string(), exr), ("the image".to_string(), png), ("the checkpoint".to_string(), ckpt)];
    out.extend(opts.stats.iter().map(|p| ("--stats".to_string(), p.clone())));
    out.extend(opts.profile.iter().map(|p| ("--profile".to_string(), p.clone())));
    out
}

/// Checks the outputs of a render with output stem `stem` before any sample, as one
/// [`crate::files::Plan`]: each a regular file or a new name in a writable directory with room for
/// its temporary name, none the same file as another output or as an input (the scene file and
/// `extra_inputs`, the files it read such as its MTL libraries; the point-set files of `file:`
/// samplers; `--resume` unless it is also the checkpoint).
pub fn check_outputs(opts: &RenderOptions, stem: &Path, extra_inputs: &[PathBuf]) -> Result<(), SessionError> {
    let outputs = output_files(opts, stem);
    let mut plan = crate::files::Plan::new();
    for (what, f) in &outputs {
        let label = if what == "the image" { format!("the image {}", f.display()) } else { what.clone() };
        plan.output(label, f);
    }
    if let Some(p) = &opts.scene {
        plan.input("the scene file", p);
    }
    for p in extra_inputs {
        plan.input(format!("the scene's file {}", p.display()), p);
    }
    let ckpt = &outputs[2].1;
    for p in opts.resume.iter().filter(|r| *r != ckpt) {
        plan.input("the --resume checkpoint", p);
    }
    for (flag, kind) in
        [("--sampler", opts.sampler), ("--pixel-sampler", opts.pixel_sampler), ("--light-sampler", opts.light_sampler)]
    {
        if let Some(kind) = kind.filter(|k| crate::sampler::file::file_info(*k).is_some()) {
            if let Some(rest) = kind.info().name.strip_prefix("file:") {
                plan.input(format!("the {flag} point set"), rest.split('?').next().unwrap_or(rest));
            }
        }
    }
    plan.check().map_err(plan_error)
}

/// A refused plan as the session's error.
fn plan_error(e: crate::files::PlanError) -> SessionError {
    match e {
        crate::files::PlanError::Bad { path, why } => SessionError::BadOutput { path, why },
        crate::files::PlanError::NotWritable { dir, source } => SessionError::NotWritable { dir, source },
    }
}

/// Checks that `file` is a regular file or a new name in a writable directory, for outputs the
/// render options do not name (`strata profile --json/--svg`, `compare --profile`), so a bad path
/// fails before the renders.
pub fn check_output_file(file: &Path) -> Result<(), SessionError> {
    let mut plan = crate::files::Plan::new();
    plan.output("the output", file);
    plan.check().map_err(plan_error)
}

/// Refuses a sampler asked for more points than its period ([`crate::sampler::SamplerInfo`]'s
/// `period`, read from the registry): the pixel sampler uses indices `0..spp`, the light
/// sampler `sample * n + k`, so `0..spp * light_samples`.
pub fn check_sampler_periods(opts: &RenderOptions, desc: &SceneDesc, spp: u32) -> Result<(), SessionError> {
    let base = opts.sampler.unwrap_or(SamplerKind::DEFAULT);
    let pixel = opts.pixel_sampler.or(opts.sampler).unwrap_or(base);
    let n_light = opts.light_samples.unwrap_or(desc.light_samples).max(1);
    let light = opts.light_sampler.or(opts.sampler).unwrap_or(if desc.light_stratify {
        SamplerKind::DEFAULT
    } else {
        SamplerKind::INDEPENDENT
    });
    let flag = |own: Option<SamplerKind>, name| if own.is_some() || opts.sampler.is_none() { name } else { "sampler" };
    let asked_light = u64::from(spp) * u64::from(n_light);
    let cases = [
        (pixel, u64::from(spp), format!("{spp} spp"), flag(opts.pixel_sampler, "pixel-sampler"), "--spp"),
        (
            light,
            asked_light,
            format!("{spp} spp x {n_light} light samples = {asked_light} points"),
            flag(opts.light_sampler, "light-sampler"),
            "--spp or --light-samples",
        ),
        (base, u64::from(spp), format!("{spp} spp"), "sampler", "--spp"),
    ];
    for (kind, asked, phrase, flag, lower) in cases {
        let info = kind.info();
        if let Some((_, _, points)) = crate::sampler::file::file_info(kind).filter(|f| asked > u64::from(f.2)) {
            let (sampler, points) = (info.name, u64::from(points));
            return Err(SessionError::FilePoints { sampler, points, asked: phrase, need: asked, lower });
        }
        if let Some(period) = info.period.filter(|&p| asked > p) {
            let alternative = if info.name == "sobol" { "independent" } else { "sobol" };
            return Err(SessionError::SamplerPeriod { sampler: info.name, period, asked: phrase, flag, alternative });
        }
    }
    Ok(())
}

/// A scene emits light somewhere: area, point or directional lights, emissive triangles or an
/// emissive material.
pub fn has_emitter(desc: &SceneDesc) -> bool {
    !desc.quad_lights.is_empty()
        || !desc.emissive_triangles.is_empty()
        || !desc.point_lights.is_empty()
        || !desc.directional_lights.is_empty()
        || desc.materials.iter().any(|m| m.emission.max_element() > 0.0)
}

/// Adds the default light of an unlit OBJ scene: `interior_light` if given (a closed interior's,
/// from [`crate::scene::obj::frame::Framing`]), else a square area light of twice the model's
/// bounding radius per side, above and behind the camera, facing the model's centre, with a
/// radiance giving an irradiance of about pi (a white diffuse surface facing it looks white).
/// Returns what it added, None (and adds nothing) if the scene has no camera or no geometry.
pub fn add_default_light(desc: &mut SceneDesc, interior_light: Option<QuadLightDesc>) -> Option<&'static str> {
    if let Some(light) = interior_light {
        desc.quad_lights.push(light);
        return Some("a default area light under the ceiling (the camera is inside)");
    }
    let (Some(cam), Some((lo, hi))) = (desc.camera, scene_bounds(desc)) else { return None };
    let center = 0.5 * (lo + hi);
    let r = (0.5 * (hi - lo).length()).max(1e-3);
    let back = (cam.eye - cam.center).normalize_or(Vec3::Z);
    let up = (cam.up - back * cam.up.dot(back)).normalize_or(Vec3::Y);
    let pos = cam.eye + back * r + up * (2.0 * r);
    let w = (center - pos).normalize_or(-back);
    let u = w.any_orthonormal_vector();
    let v = w.cross(u);
    let side = 2.0 * r;
    let (mut ab, mut ac) = (u * side, v * side);
    // A quad light emits towards normalize(ac x ab).
    if ac.cross(ab).dot(w) < 0.0 {
        std::mem::swap(&mut ab, &mut ac);
    }
    let a = pos - 0.5 * (ab + ac);
    let d2 = (center - pos).length_squared();
    let radiance = Vec3::splat(std::f32::consts::PI * d2 / (side * side));
    desc.quad_lights.push(QuadLightDesc { a, ab, ac, radiance });
    Some("a default area light")
}

/// Bounds of the triangles and sphere centres of `desc`.
fn scene_bounds(desc: &SceneDesc) -> Option<(Vec3, Vec3)> {
    let tris = desc.triangles.iter().flat_map(|t| t.v);
    crate::scene::obj::bounds(tris.chain(desc.spheres.iter().map(|s| s.object_to_world.w_axis.truncate())))
}

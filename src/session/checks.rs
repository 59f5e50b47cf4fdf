//! Command-line checks made before any expensive work (thread cap, writable output directories,
//! sampler periods) and the default light of an OBJ scene without emitters.

use super::{RenderOptions, SessionError};
use crate::film::stem_of;
use crate::sampler::SamplerKind;
use crate::scene::desc::{QuadLightDesc, SceneDesc};
use crate::scene::parse;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// Checks what the command line alone decides, before the scene is read: `--threads` within
/// `max_threads`, and every directory the render will write to (image, checkpoint, stats, profile)
/// writable (a probe file is created and removed), so that a bad path fails before any sample.
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
    let stem = opts.out.as_ref().map(|o| stem_of(o)).unwrap_or_else(|| PathBuf::from("strata"));
    let files = [Some(stem), opts.checkpoint.clone(), opts.resume.clone(), opts.stats.clone(), opts.profile.clone()];
    for f in files.iter().flatten() {
        check_writable(&dir_of(f))?;
    }
    Ok(())
}

/// Checks that the directory `file` would be written in is writable (a probe file), for outputs
/// the render options do not name (`strata profile --json/--svg`, `compare --profile`), so a bad
/// path fails before the renders.
pub fn check_output_file(file: &Path) -> Result<(), SessionError> {
    check_writable(&dir_of(file))
}

/// The directory a file is written in ("." for a bare name).
fn dir_of(f: &Path) -> PathBuf {
    match f.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Creates and removes a probe file in `dir` (named by process and a per-process counter, so
/// renders running at once in one process or several never collide).
fn check_writable(dir: &Path) -> Result<(), SessionError> {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let probe = dir.join(format!(".strata-write-probe-{}-{n}", std::process::id()));
    let fail = |source| SessionError::NotWritable { dir: dir.to_path_buf(), source };
    if !dir.is_dir() {
        return Err(fail(std::io::Error::new(std::io::ErrorKind::NotFound, "no such directory")));
    }
    std::fs::OpenOptions::new().write(true).create_new(true).open(&probe).map_err(fail)?;
    std::fs::remove_file(&probe).map_err(fail)
}

/// Refuses a sampler asked for more points than its period ([`crate::sampler::SamplerInfo`]'s
/// `period`, read from the registry): the pixel sampler uses indices `0..spp`, the light
/// sampler `sample * n + k`, so `0..spp * light_samples`.
pub fn check_sampler_periods(opts: &RenderOptions, desc: &SceneDesc, spp: u32) -> Result<(), SessionError> {
    let base = opts.sampler.unwrap_or(SamplerKind::STRATIFIED);
    let pixel = opts.pixel_sampler.or(opts.sampler).unwrap_or(base);
    let n_light = opts.light_samples.unwrap_or(desc.light_samples).max(1);
    let light = opts.light_sampler.or(opts.sampler).unwrap_or(if desc.light_stratify {
        SamplerKind::STRATIFIED
    } else {
        SamplerKind::INDEPENDENT
    });
    let flag = |own: Option<SamplerKind>, name| if own.is_some() || opts.sampler.is_none() { name } else { "sampler" };
    let asked_light = u64::from(spp) * u64::from(n_light);
    let cases = [
        (pixel, u64::from(spp), format!("{spp} spp"), flag(opts.pixel_sampler, "pixel-sampler")),
        (
            light,
            asked_light,
            format!("{spp} spp x {n_light} light samples = {asked_light} points"),
            flag(opts.light_sampler, "light-sampler"),
        ),
        (base, u64::from(spp), format!("{spp} spp"), "sampler"),
    ];
    for (kind, asked, phrase, flag) in cases {
        let info = kind.info();
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

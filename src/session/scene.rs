//! Scene loading with the command-line overrides applied, and the scene and integrator of a
//! render built from its options.

use super::{RenderOptions, SessionError, DEFAULT_SCENE};
use crate::checkpoint;
use crate::integrator::kernel::Kernel;
use crate::integrator::Integrator;
use crate::scene::build::Scene;
use crate::scene::desc::{CameraDesc, SceneDesc};
use crate::scene::obj::is_obj;
use crate::scene::parse::{self, Limits};
use std::path::Path;

/// A `--flag` value over the resource cap `field` of `limits`.
fn over(flag: &'static str, value: String, max: u64, unit: &'static str, field: &str) -> SessionError {
    SessionError::OverLimit { flag, value, max, unit, hint: parse::limit_hint(field) }
}

/// Parses the scene named in `opts` (or the built-in one), without the overrides.
pub fn parse_scene(opts: &RenderOptions) -> Result<SceneDesc, SessionError> {
    let limits = opts.limits;
    Ok(match &opts.scene {
        Some(p) if is_obj(p) => crate::scene::obj::scene_from_obj(p, &limits)?,
        Some(p) if crate::scene::xml::is_xml(p) => {
            let loaded = crate::scene::xml::load(p, &limits, &opts.defines)?;
            for w in &loaded.warnings {
                eprintln!("strata: warning: {w}");
            }
            loaded.desc
        }
        Some(p) => parse::parse_file(p, &limits)?,
        None => parse::parse_str(DEFAULT_SCENE, Path::new("<built-in cornell>"), &limits)?,
    })
}

/// Parses the scene named in `opts` (or the built-in one; or takes `opts.parsed`) and applies
/// the overrides.
pub fn load_scene(opts: &RenderOptions) -> Result<SceneDesc, SessionError> {
    let limits = opts.limits;
    let mut desc = match &opts.parsed {
        Some(d) => SceneDesc::clone(d),
        None => parse_scene(opts)?,
    };
    if let Some((w, h)) = opts.size {
        if w == 0 || h == 0 {
            return Err(SessionError::SizeNotPositive { w, h });
        }
        if w.max(h) > limits.max_side {
            return Err(over("size", format!("{w}x{h}"), limits.max_side.into(), " pixels per side", "max_side"));
        }
        if u64::from(w) * u64::from(h) > limits.max_pixels {
            return Err(over("size", format!("{w}x{h}"), limits.max_pixels, " pixels", "max_pixels"));
        }
        desc.width = w;
        desc.height = h;
    }
    if let Some(k) = opts.integrator {
        desc.integrator = k;
    }
    if let Some(c) = opts.camera {
        desc.camera = Some(c);
    }
    if let Some(s) = opts.importance_sampling {
        desc.importance_sampling = s;
    }
    if let Some(n) = opts.nee {
        desc.nee = n;
    }
    if let Some(r) = opts.russian_roulette {
        desc.russian_roulette = r;
    }
    if let Some(d) = opts.max_depth {
        if d < -1 || i64::from(d) > i64::from(limits.max_depth) {
            let hint = parse::limit_hint("max_depth");
            return Err(SessionError::MaxDepth { depth: d, max: limits.max_depth, hint });
        }
        desc.max_depth = d;
    }
    let obj = matches!(&opts.scene, Some(p) if is_obj(p));
    let name = opts.scene.as_deref().map(|p| p.display().to_string()).unwrap_or_default();
    let interior_light = if obj && opts.camera.is_none() { frame_obj(&mut desc, opts, &name) } else { None };
    if let Some(sky) = opts.sky {
        desc.environment = Some(crate::scene::desc::EnvironmentDesc::Constant(sky));
    }
    if obj && !opts.no_default_light && !super::checks::has_emitter(&desc) && desc.environment.is_none() {
        if let Some(what) = super::checks::add_default_light(&mut desc, interior_light) {
            eprintln!("strata: note: {name} has no light; added {what} (disable with --no-default-light)");
        }
    }
    use crate::scene::desc::IntegratorKind;
    let outside = desc.environment.is_some() || !desc.delta_lights.is_empty();
    if outside
        && !matches!(
            desc.integrator,
            IntegratorKind::PathTracer | IntegratorKind::Direct | IntegratorKind::ParticleTracer
        )
    {
        return Err(SessionError::SkyNeedsPathTracer { integrator: desc.integrator.name() });
    }
    Ok(desc)
}

/// Puts the automatic camera of a whole-scene OBJ ([`crate::scene::obj::frame`]) in `desc`, for
/// its image size and `--up`, and announces the up axis and the camera on stderr (with progress).
/// Returns the light to add to a closed interior if it has none.
fn frame_obj(desc: &mut SceneDesc, opts: &RenderOptions, name: &str) -> Option<crate::scene::desc::QuadLightDesc> {
    let aspect = desc.width as f32 / desc.height as f32;
    let f = crate::scene::obj::frame::frame_scene(desc, opts.up, aspect)?;
    desc.camera = Some(f.camera);
    if opts.progress {
        let how = if f.up_guessed { "guessed from its bounds; set it with --up x|y|z" } else { "from --up" };
        eprintln!("strata: note: {name}: up axis {} ({how}); {}", f.up.name(), f.view.name());
        eprintln!("strata: note: automatic camera, to edit: {}", f.camera_arg());
    }
    f.interior_light
}

/// `--camera "ex ey ez cx cy cz ux uy uz fovy"` (the format's `camera` arguments), checked as the
/// `.test` parser checks them.
pub fn parse_camera(s: &str) -> Result<CameraDesc, SessionError> {
    let text = format!("camera {}", s.replace(',', " "));
    parse::parse_str(&text, Path::new("--camera"), &Limits::default())
        .map_err(SessionError::Camera)?
        .camera
        .ok_or(SessionError::CameraMissing)
}

/// Parses, checks and builds the scene and the integrator of `opts`.
pub fn prepare(opts: &RenderOptions) -> Result<(Scene, Integrator), SessionError> {
    super::checks::check_command_line(opts)?;
    for (flag, v) in [("spp", opts.spp), ("light-samples", opts.light_samples)] {
        if v == Some(0) {
            return Err(SessionError::Zero { flag });
        }
    }
    let desc = load_scene(opts)?;
    // A Mitsuba scene's <sampler> stands where --sampler is not given.
    let with_scene_sampler;
    let opts = match (opts.sampler, desc.sampler) {
        (None, Some(k)) => {
            with_scene_sampler = RenderOptions { sampler: Some(k), ..opts.clone() };
            &with_scene_sampler
        }
        _ => opts,
    };
    super::checks::check_outputs(opts, &super::output_stem(opts, &desc), &desc.inputs)?;
    let spp = opts.spp.unwrap_or(desc.spp).max(1);
    if spp > opts.limits.max_spp {
        return Err(over("spp", spp.to_string(), opts.limits.max_spp.into(), "", "max_spp"));
    }
    if let Some(n) = opts.bsdf_samples.filter(|&n| n > opts.limits.max_light_samples) {
        return Err(over("bsdf-samples", n.to_string(), opts.limits.max_light_samples.into(), "", "max_light_samples"));
    }
    if opts.bsdf_samples == Some(0) && !desc.emitter_sampling {
        // (The scene samples no emitter: BSDF samples are all it has.)
        return Err(SessionError::Zero { flag: "bsdf-samples" });
    }
    if let Some(n) = opts.light_samples.filter(|&n| n > opts.limits.max_light_samples) {
        return Err(over(
            "light-samples",
            n.to_string(),
            opts.limits.max_light_samples.into(),
            "",
            "max_light_samples",
        ));
    }
    super::checks::check_sampler_periods(opts, &desc, spp)?;
    super::memory::check(opts, &desc, spp)?;
    let scene = Scene::build(desc)?;
    let plural = |n: usize| if n == 1 { "" } else { "s" };
    let (zero, huge) = (scene.degenerate_dropped - scene.overflow_dropped, scene.overflow_dropped);
    let d = &scene.desc;
    let triangles = d.triangles.len() + d.emissive_triangles.len() + d.group_triangles();
    if triangles > 0 && scene.degenerate_dropped >= triangles && d.spheres.is_empty() {
        // Before: an OBJ whose only triangle overflowed got a camera framing the dropped vertices
        // and rendered black with exit 0.
        return Err(SessionError::NothingLeft { path: d.source.clone(), zero, huge });
    }
    if zero > 0 {
        eprintln!(
            "strata: warning: {}: dropped {zero} degenerate (zero-area) triangle{}",
            scene.desc.source.display(),
            plural(zero)
        );
    }
    if huge > 0 {
        eprintln!(
            "strata: warning: {}: dropped {huge} triangle{} whose area overflows f32 (edges of about 1e19 or more; scale the scene down)",
            scene.desc.source.display(),
            plural(huge)
        );
    }
    let samplers = crate::integrator::SamplerChoice {
        sampler: opts.sampler,
        pixel: opts.pixel_sampler,
        light: opts.light_sampler,
    };
    let mut integrator = Integrator::new(&scene, spp, opts.seed, samplers, opts.light_samples);
    if let Some(n) = opts.bsdf_samples {
        integrator.direct.bsdf_samples = n;
    }
    integrator.light_choice = opts.light_choice.unwrap_or(crate::light::select::LightChoice::Reuse);
    // Scenes with sphere lights (Mitsuba's) sample by solid angle unless told otherwise, as
    // Mitsuba samples spheres; others keep area sampling: the course's convention for `.test`
    // scenes, and on OBJ and XML quads and triangles solid angle was measured less efficient
    // (docs/light-selection.md, "Which warp by default"; `light_warp_default_per_scene_kind`).
    integrator.light_warp = opts.light_warp.unwrap_or(if scene.emitters.any_sphere {
        crate::light::warp::LightWarp::SolidAngle
    } else {
        crate::light::warp::LightWarp::Area
    });
    if opts.general_kernel {
        integrator.kernel = Kernel::GENERAL;
    }
    integrator.path.clamp = opts.clamp;
    integrator.first_sample = super::options::default_first_sample(opts);
    // `--light-selection`, else the scene's `lightselection`, else `all` for `direct` (its loop over
    // every light) and the default of the scene's kind for the path tracer.
    let selection = opts.light_selection.or(scene.desc.light_selection).unwrap_or_else(|| {
        if scene.desc.integrator == crate::scene::desc::IntegratorKind::Direct {
            crate::light::select::LightSelection::ALL
        } else {
            super::options::default_light_selection(opts)
        }
    });
    integrator.set_light_selection(&scene, selection);
    check_flags_apply(opts, &scene, &integrator)?;
    Ok((scene, integrator))
}

/// Refuses a light-sampling flag that changes nothing for the integrator that runs, saying why:
/// `--light-sampler`, `--light-choice`, `--light-selection` for raytracer and analyticdirect, and
/// `--light-choice` where no light is chosen (selection `all`, fewer than two lights).
fn check_flags_apply(opts: &RenderOptions, scene: &Scene, it: &Integrator) -> Result<(), SessionError> {
    use crate::scene::desc::IntegratorKind;
    let refuse = |flag: &'static str, why: String| Err(SessionError::FlagIgnored { flag, why });
    let name = it.kind.name();
    if matches!(it.kind, IntegratorKind::RayTracer | IntegratorKind::AnalyticDirect) {
        let why = match it.kind {
            IntegratorKind::RayTracer => "raytracer shades point and directional lights, it samples no area light",
            _ => "analyticdirect integrates area lights exactly, it samples none",
        };
        let given = [
            ("--light-sampler", opts.light_sampler.is_some()),
            ("--light-choice", opts.light_choice.is_some()),
            ("--light-warp", opts.light_warp.is_some()),
            ("--light-selection", opts.light_selection.is_some()),
        ];
        if let Some((flag, _)) = given.into_iter().find(|(_, on)| *on) {
            return refuse(flag, why.to_string());
        }
    }
    if opts.light_choice.is_some() {
        if !it.light_selection.picks_one() {
            return refuse(
                "--light-choice",
                format!("{name} with light selection {} samples every light: there is no choice", it.light_selection),
            );
        }
        if scene.emitters.len() < 2 {
            return refuse("--light-choice", "the scene has fewer than two area lights: there is no choice".into());
        }
    }
    if opts.bsdf_samples.is_some() && it.kind != IntegratorKind::Direct {
        return refuse("--bsdf-samples", format!("only direct draws BSDF samples per shading point, not {name}"));
    }
    // (`--light-samples` is accepted everywhere: scripts pass it over whole scene sets, and the
    // `.test` keyword it overrides is there whatever the integrator.)
    Ok(())
}

/// Hash of the scene's bytes (the file as read, or the built-in scene's text).
pub fn scene_hash(opts: &RenderOptions) -> Result<String, SessionError> {
    Ok(match &opts.scene {
        Some(p) => checkpoint::hash_bytes(
            &crate::files::read_bounded(p, opts.limits.max_file_bytes)
                .map_err(|source| SessionError::SceneRead { path: p.clone(), source })?,
        ),
        None => checkpoint::hash_bytes(DEFAULT_SCENE.as_bytes()),
    })
}

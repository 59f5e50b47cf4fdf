//! What the particle tracer (`integrator/ptracer.rs`) cannot render, found from the scene
//! description before anything is built: [`refusal`] names the feature, and `Scene::build`
//! refuses the scene with it rather than render a different image.

use super::desc::{EnvironmentDesc, IntegratorKind, SceneDesc};
use super::sensor::Projection;
use crate::bsdf::interface::flags;
use crate::light::desc::DeltaLightDesc;
use crate::sampling::filter::PixelFilter;

/// The first feature of `desc` the particle tracer does not support, or None (always None for
/// another integrator).
pub fn refusal(desc: &SceneDesc) -> Option<&'static str> {
    if desc.integrator != IntegratorKind::ParticleTracer {
        return None;
    }
    match &desc.sensor {
        None => return Some("the `.test` camera (it connects to a Mitsuba `perspective` sensor only)"),
        Some(s) if !matches!(s.projection, Projection::Perspective { .. }) => {
            return Some("an `orthographic` sensor (it connects to a `perspective` sensor only)")
        }
        Some(_) => {}
    }
    if desc.filter != PixelFilter::Box {
        return Some("a reconstruction filter other than `box` (its splats land in one pixel)");
    }
    match &desc.environment {
        Some(EnvironmentDesc::Constant(_)) => return Some("a `constant` environment emitter"),
        Some(EnvironmentDesc::Envmap { .. }) => return Some("an `envmap` emitter"),
        None => {}
    }
    if desc.delta_lights.iter().any(|d| matches!(d, DeltaLightDesc::Directional { .. })) {
        return Some("a `directional` emitter");
    }
    if desc.materials.iter().any(|m| m.emission != glam::Vec3::ZERO) {
        return Some("emissive materials (only area, point, spot and projector emitters start light paths)");
    }
    let transmits = |m: &crate::bsdf::BsdfParams| {
        m.kind != crate::bsdf::interface::COURSE
            && crate::bsdf::blendbsdf::row_flags(&crate::bsdf::BsdfParams { opacity: 1.0, ..*m }) & flags::TRANSMISSION
                != 0
    };
    if desc.materials.iter().any(|m| transmits(&m.bsdf)) {
        return Some("BSDFs that transmit (the adjoint of refraction's radiance scaling is not written)");
    }
    if !desc.emissive_spheres.is_empty() {
        return Some("sphere area lights (light paths start from meshes and rectangles only)");
    }
    if desc.material_frames.iter().any(Option::is_some) {
        return Some("`normalmap`/`bumpmap` (the adjoint of a shading-normal change is not written)");
    }
    if desc.materials.iter().any(|m| crate::bsdf::mask::masked(&m.bsdf)) {
        return Some("`mask` (light paths do not pass through its null lobe)");
    }
    None
}

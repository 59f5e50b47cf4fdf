//! Feature analysis and kernel choice: at load time a scene is analysed (materials, lights,
//! geometry kinds, integrator settings) and the integrators run a kernel monomorphized for the
//! specular lobes it actually has, so a diffuse-only scene never evaluates a Phong or GGX lobe.
//!
//! Specialization changes speed, never results: a specialized kernel differs from the general one
//! only by code that, under the scene's [`Lobes`] promise, adds exact zeros (tested bit for bit
//! in `tests/it/kernels.rs`). Settings that are uniform over a render (NEE mode, Russian roulette,
//! strategy) are branched on once per packet and are not worth a monomorphized copy. What else a
//! scene does not use costs nothing either: with one light the path tracer splats it instead of
//! gathering a per-lane choice (and skips drawing the choice dimension unless BRDF sampling needs
//! its lobe pick); MIS weights are computed only under `nexteventestimation mis`; a scene without
//! spheres has no Embree user geometry, so no callback ever runs; primary packets carry Embree's
//! coherent flag, later ones not.

use crate::bsdf::Lobes;
use crate::scene::build::Scene;
use crate::scene::desc::{ImportanceSampling, IntegratorKind, Nee};
use serde_json::{json, Value};

/// Runs `$body` with the type `$L` set to the compiled [`crate::bsdf::LobeSet`] for `$lobes` (a
/// [`Lobes`]): a specialized kernel where one is compiled, else the general `AllLobes`. One line
/// per specialized kernel; a new lobe needs none (scenes using it run the general kernel).
macro_rules! with_lobe_set {
    ($lobes:expr, $L:ident => $body:expr) => {{
        use $crate::bsdf::LobeSet as _;
        match $lobes.0 {
            b if b == <$crate::bsdf::Diffuse>::BITS => {
                type $L = $crate::bsdf::Diffuse;
                $body
            }
            b if b == <$crate::bsdf::DiffusePhong>::BITS => {
                type $L = $crate::bsdf::DiffusePhong;
                $body
            }
            b if b == <$crate::bsdf::DiffuseGgx>::BITS => {
                type $L = $crate::bsdf::DiffuseGgx;
                $body
            }
            _ => {
                type $L = $crate::bsdf::AllLobes;
                $body
            }
        }
    }};
}
pub(crate) use with_lobe_set;

/// Which kernel runs: the general one (every lobe compiled in) or one specialized for the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Kernel {
    /// specular lobes compiled in
    pub lobes: Lobes,
}

impl Kernel {
    /// The fully general kernel, right for any scene.
    pub const GENERAL: Self = Self { lobes: Lobes::ALL };

    /// The kernel specialized for `scene`'s materials.
    pub fn for_scene(scene: &Scene) -> Self {
        // Normal and bump maps are applied by the kernels with registry BSDFs: the general one.
        if scene.frame_maps() {
            return Self::GENERAL;
        }
        Self { lobes: Lobes::of(&scene.materials) }
    }

    /// Name reported in the summary and `--stats` (`kernel`): `general`, or the integrator's kernel
    /// with the lobes compiled in, e.g. `pathtracer<lobes=none>`.
    pub fn name(&self, integrator: IntegratorKind) -> String {
        use crate::bsdf::{Diffuse, DiffuseGgx, DiffusePhong, LobeSet};
        // The sets `with_lobe_set!` compiles; any other runs the general kernel.
        let specialized = [<Diffuse as LobeSet>::BITS, DiffusePhong::BITS, DiffuseGgx::BITS];
        if *self == Self::GENERAL || !specialized.contains(&self.lobes.0) {
            return "general".into();
        }
        let names = self.lobes.names();
        let lobes = if names.is_empty() { "none".to_string() } else { names.join("+") };
        format!("{}<lobes={lobes}>", integrator.name())
    }
}

/// The features a scene uses, as reported under `features` in `--stats`.
pub fn features_json(scene: &Scene, kind: IntegratorKind, nee: Nee, rr: bool, strategy: ImportanceSampling) -> Value {
    let d = &scene.desc;
    let mats = &d.materials;
    let mut materials = vec!["diffuse"];
    materials.extend(Lobes::of(mats).names());
    if mats.iter().any(|m| m.emission != glam::Vec3::ZERO) {
        materials.push("emission");
    }
    let mut geometry = Vec::new();
    if !d.triangles.is_empty() || !d.instances.is_empty() {
        geometry.push("triangles");
    }
    if !d.spheres.is_empty() {
        geometry.push("spheres");
    }
    let path = kind == IntegratorKind::PathTracer;
    json!({
        "materials": materials,
        "geometry": geometry,
        "quad_lights": scene.lights.len(),
        "emissive_triangles": scene.emitters.n_triangles(),
        // `direct`'s own choice among the emitters (the rule in use is `light_selection`, added by
        // the session's `--stats`).
        "direct_light_choice": match (scene.emitters.len(), scene.emitters.n_triangles()) {
            (0, _) => "none",
            (1, _) => "single",
            (_, 0) => "uniform",
            _ => "power",
        },
        "point_lights": d.point_lights.len(),
        "directional_lights": d.directional_lights.len(),
        "sky": match &d.environment { Some(crate::scene::desc::EnvironmentDesc::Constant(s)) => Some(s.to_array()), _ => None },
        "integrator": kind.name(),
        "nee": if path { Some(format!("{nee:?}").to_lowercase()) } else { None },
        "russian_roulette": path && rr,
        "importance_sampling": if path { Some(format!("{strategy:?}").to_lowercase()) } else { None },
    })
}

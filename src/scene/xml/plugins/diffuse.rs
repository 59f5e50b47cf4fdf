//! `<bsdf type="diffuse">`: Lambertian `reflectance` (rgb, spectrum or float; default 0.5).
//! One-sided, as Mitsuba's: black from behind unless wrapped in `twosided`. The material leaves
//! this plugin with `bsdf.twosided` false (so that the one-sided and two-sided versions intern
//! apart); the scene's end (`scene::xml::load`) lists such materials in `SceneDesc::one_sided`
//! and restores the course's flag.

use super::{Build, Plugin, Run};
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "diffuse", run: Run::Bsdf(run) };

/// Mitsuba's material of a shape without a BSDF: diffuse, reflectance 0.5.
pub fn default_material() -> Material {
    lambert(Vec3::splat(0.5))
}

/// A one-sided Lambertian material of reflectance `r` (the BRDF is `r / pi`; see the module docs).
pub fn lambert(r: Vec3) -> Material {
    let mut m = Material { diffuse: r, ambient: Vec3::ZERO, ..Material::default() };
    m.bsdf.twosided = false;
    m
}

/// The material of a registry BSDF row: no course lobes, no ambient term.
pub fn registry_material(bsdf: crate::bsdf::BsdfParams) -> Material {
    Material { diffuse: Vec3::ZERO, ambient: Vec3::ZERO, bsdf, ..Material::default() }
}

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    match p.color("reflectance", false)? {
        Some(Color::Rgb(c)) => Ok(lambert(c)),
        Some(Color::Texture(t)) => {
            // The texture gives the reflectance per hit (`Scene::gather`); the material keeps a
            // representative value (its mean, or 0.5 where that is not known before the scene is
            // built, as for a mesh attribute): what reads the material rather than the hit.
            let i = b.texture(t)?;
            let mean = b.desc.textures[i as usize].mean();
            b.pending_texture = Some(i);
            Ok(lambert(if mean.max_element() > 0.0 { mean } else { Vec3::splat(0.5) }))
        }
        None => Ok(default_material()),
    }
}

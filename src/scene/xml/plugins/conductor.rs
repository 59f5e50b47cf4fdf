//! `<bsdf type="conductor">`: a smooth metal (`bsdf::conductor`). `material` (a name of Mitsuba's
//! table, default `none`: a perfect mirror) or `eta` and `k` (default 0 and 1; colours or
//! textures), and `specular_reflectance` (default 1; a colour or a texture). One-sided (black from the back) unless in a `twosided`.

use super::{Build, Plugin, Run};
use crate::bsdf::interface::Slot;
use crate::scene::desc::Material;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::values;
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "bsdf", kind: "conductor", run: Run::Bsdf(run) };

/// Mitsuba's (eta, k) of a conductor element: `material` or `eta`/`k`, not both; `eta` and `k`
/// may be textures (per hit, the row's `color[0]` and `color[1]`; the row keeps their means).
pub fn eta_k<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<(Vec3, Vec3), SceneError> {
    let material = match p.get("material") {
        Some(e) => Some((e, e.need("value")?)),
        None => None,
    };
    match material {
        Some((e, name)) if name != "none" => {
            if p.has("eta") || p.has("k") {
                return Err(e
                    .at
                    .err(format!("{}: give either \"material\" or \"eta\"/\"k\", not both", p.elem.what())));
            }
            values::conductor(e, name)
        }
        _ => Ok((
            b.color_param(p, "eta", Vec3::ZERO, Slot::Color(0))?,
            b.color_param(p, "k", Vec3::ONE, Slot::Color(1))?,
        )),
    }
}

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<Material, SceneError> {
    p.ignore("id");
    let (eta, k) = eta_k(b, p)?;
    let specular = b.color_param(p, "specular_reflectance", Vec3::ONE, Slot::Color(2))?;
    Ok(super::diffuse::registry_material(crate::bsdf::conductor::params(eta, k, specular)))
}

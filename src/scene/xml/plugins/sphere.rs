//! `<shape type="sphere">`: `center`, `radius`, `to_world`, rendered exactly (Embree user geometry).

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::ShapeOut;
use glam::{Mat4, Vec3};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "sphere", run: Run::Shape(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    let center = p.vec3("center")?.unwrap_or(Vec3::ZERO);
    let radius = p.float("radius", 1.0)?;
    if !(radius > 0.0) {
        return Err(p.elem.at.err(format!("sphere radius {radius} must be positive")));
    }
    p.refuse("flip_normals", "a sphere seen from inside needs the `meshes`/`lights` work of issue 29")?;
    let m = p.transform("to_world")? * Mat4::from_translation(center) * Mat4::from_scale(Vec3::splat(radius));
    Ok(ShapeOut::Sphere(m))
}

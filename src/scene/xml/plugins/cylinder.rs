//! `<shape type="cylinder">`: `radius` (1), `p0` (0,0,0), `p1` (0,0,1), open ends, through
//! `to_world`.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::{self, ShapeOut};
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "cylinder", run: Run::Shape(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    let r = p.float("radius", 1.0)?;
    let p0 = p.vec3("p0")?.unwrap_or(Vec3::ZERO);
    let p1 = p.vec3("p1")?.unwrap_or(Vec3::Z);
    let m = crate::scene::mesh::shapes::cylinder(r, p0, p1)
        .ok_or_else(|| p.elem.at.err(format!("cylinder radius {r} must be positive and p0 != p1")))?;
    shape::mesh(p, m)
}

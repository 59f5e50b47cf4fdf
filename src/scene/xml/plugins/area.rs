//! `<emitter type="area">` inside a shape: one-sided `radiance` towards the shape's normals.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "emitter", kind: "area", run: Run::Area(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<Vec3, SceneError> {
    match p.color("radiance", true)? {
        Some(Color::Rgb(c)) => Ok(c),
        Some(Color::Texture(t)) => Err(t.at.err("a textured area emitter needs the `textures` work of issue 29")),
        None => Err(p.elem.at.err("<emitter type=\"area\"> needs a `radiance`")),
    }
}

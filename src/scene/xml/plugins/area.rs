//! `<emitter type="area">` inside a shape: one-sided `radiance` towards the shape's normals, an
//! RGB value or a bitmap texture over the shape's uvs (rendered by the particle tracer only).

use super::{AreaEmission, Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "emitter", kind: "area", run: Run::Area(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<AreaEmission, SceneError> {
    match p.color("radiance", true)? {
        Some(Color::Rgb(c)) => Ok(AreaEmission { radiance: c, texture: None }),
        // A bitmap `radiance`: the particle tracer's (`Scene::build` refuses it elsewhere).
        Some(Color::Texture(t)) => Ok(AreaEmission { radiance: Vec3::ONE, texture: Some(b.bitmap_image(t)?) }),
        None => Err(p.elem.at.err("<emitter type=\"area\"> needs a `radiance`")),
    }
}

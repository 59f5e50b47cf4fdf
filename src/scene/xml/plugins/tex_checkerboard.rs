//! `<texture type="checkerboard">`: `color0` (default 0.4), `color1` (default 0.2), `to_uv`.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};
use crate::texture::{Checkerboard, Texture, UvTransform};
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "texture", kind: "checkerboard", run: Run::Texture(run) };

fn constant(p: &Props, name: &str, default: Vec3) -> Result<Vec3, SceneError> {
    match p.color(name, false)? {
        Some(Color::Rgb(c)) => Ok(c),
        Some(Color::Texture(t)) => {
            Err(t.at.err(format!("a textured checkerboard `{name}` is not supported (constants only)")))
        }
        None => Ok(default),
    }
}

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<Texture, SceneError> {
    let d = Checkerboard::default();
    let color0 = constant(p, "color0", d.color0)?;
    let color1 = constant(p, "color1", d.color1)?;
    let to_uv = UvTransform::from_mat4(p.transform("to_uv")?);
    p.ignore("id");
    Ok(Texture::Checkerboard(Checkerboard { color0, color1, to_uv }))
}

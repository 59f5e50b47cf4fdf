//! `<texture type="rawconstant">`: `value` (rgb, float or vector), used as given.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};
use crate::texture::{RawConstant, Texture};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "texture", kind: "rawconstant", run: Run::Texture(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<Texture, SceneError> {
    if p.get("value").is_some_and(|e| e.tag == "vector" || e.tag == "point") {
        let value = p.vec3("value")?.unwrap_or_default();
        p.ignore("id");
        return Ok(Texture::RawConstant(RawConstant { value }));
    }
    let value = match p.color("value", false)? {
        Some(Color::Rgb(c)) => c,
        Some(Color::Texture(t)) => return Err(t.at.err("rawconstant's `value` must be a constant")),
        None => return Err(p.elem.at.err("rawconstant needs a `value`")),
    };
    p.ignore("id");
    Ok(Texture::RawConstant(RawConstant { value }))
}

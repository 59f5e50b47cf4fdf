//! `<texture type="rawconstant">`: `value` (rgb or float), used as given.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::{Color, Props};
use crate::texture::{RawConstant, Texture};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "texture", kind: "rawconstant", run: Run::Texture(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<Texture, SceneError> {
    let value = match p.color("value", false)? {
        Some(Color::Rgb(c)) => c,
        Some(Color::Texture(t)) => return Err(t.at.err("rawconstant's `value` must be a constant")),
        None => return Err(p.elem.at.err("rawconstant needs a `value`")),
    };
    p.ignore("id");
    Ok(Texture::RawConstant(RawConstant { value }))
}

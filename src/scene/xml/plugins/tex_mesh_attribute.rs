//! `<texture type="mesh_attribute">`: `name` (a `vertex_*` or `face_*` attribute of the shape's
//! mesh), `scale` (default 1).

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::texture::{MeshAttribute, Texture};

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "texture", kind: "mesh_attribute", run: Run::Texture(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<Texture, SceneError> {
    let name = p.string("name")?.ok_or_else(|| p.elem.at.err("mesh_attribute needs a `name` string"))?;
    if !(name.starts_with("vertex_") || name.starts_with("face_")) {
        return Err(p.elem.at.err(format!("mesh_attribute name \"{name}\" must start with vertex_ or face_")));
    }
    let scale = p.float("scale", 1.0)?;
    p.ignore("id");
    Ok(Texture::MeshAttribute(MeshAttribute::new(name, scale)))
}

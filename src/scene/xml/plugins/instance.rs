//! `<shape type="instance">`: a `shapegroup` (by `<ref>`) through `to_world`, flattened (each
//! member's triangles copied; spheres composed with the instance's transform).

use super::{Build, Plugin, Run};
use crate::scene::desc::SphereDesc;
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::ShapeOut;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "instance", run: Run::Shape(run) };

fn run<'e>(b: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    let group = match p.objects("shape").as_slice() {
        [g] if g.attr("type") == Some("shapegroup") => *g,
        _ => return Err(p.elem.at.err("an instance takes one <ref> to a shapegroup")),
    };
    let to_world = p.transform("to_world")?;
    let gp = Props::new(group, b.ids)?;
    let mut meshes = Vec::new();
    for member in gp.objects("shape") {
        let (out, material, emitter) = b.shape_parts(member)?;
        if emitter.is_some() {
            return Err(member.at.err("emitters inside a shapegroup are not supported (Mitsuba refuses them too)"));
        }
        match out {
            ShapeOut::Mesh(m) => meshes.push((m, material)),
            ShapeOut::Sphere(m) => b.desc.spheres.push(SphereDesc { object_to_world: to_world * m, material }),
            ShapeOut::Nothing => return Err(member.at.err("nested shapegroups are not supported")),
        }
    }
    b.desc.add_instance(&meshes, &to_world);
    Ok(ShapeOut::Nothing)
}

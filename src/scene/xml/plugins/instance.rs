//! `<shape type="instance">`: a `shapegroup` (by `<ref>`) through `to_world`. The group's
//! triangles are stored once (on its first instance) and each instance becomes an Embree instance
//! of them at build; the group's spheres are placed per instance (composed with `to_world`).

use super::{Build, Plugin, Run};
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
    if !(to_world.determinant().is_normal()) {
        return Err(p.elem.at.err("an instance's to_world must be invertible"));
    }
    let key = group.attr("id").map_or_else(|| format!("{:?}", group.at), str::to_string);
    let index = match b.desc.group_index(&key) {
        Some(i) => i,
        None => {
            let gp = Props::new(group, b.ids)?;
            let (mut meshes, mut spheres) = (Vec::new(), Vec::new());
            for member in gp.objects("shape") {
                let (out, material, emitter) = b.shape_parts(member)?;
                if emitter.is_some() {
                    return Err(member
                        .at
                        .err("emitters inside a shapegroup are not supported (Mitsuba refuses them too)"));
                }
                match out {
                    ShapeOut::Mesh(m) if !m.vertex_attrs.is_empty() || !m.face_attrs.is_empty() => {
                        return Err(member.at.err("mesh attributes inside a shapegroup are not supported"));
                    }
                    ShapeOut::Mesh(m) => meshes.push((m, material)),
                    ShapeOut::Sphere(m) => spheres.push((m, material)),
                    ShapeOut::Nothing => return Err(member.at.err("nested shapegroups are not supported")),
                }
            }
            let d = &b.desc;
            let stored = d.triangles.len() + d.emissive_triangles.len() + d.group_triangles();
            if stored + meshes.iter().map(|(m, _)| m.indices.len()).sum::<usize>() > b.limits.max_primitives {
                return Err(group.at.err(format!(
                    "the scene has more than {} triangles ({})",
                    b.limits.max_primitives,
                    crate::scene::limits::limit_hint("max_primitives")
                )));
            }
            b.desc.add_group(&key, &meshes, spheres)
        }
    };
    b.desc.add_instance(index, &to_world);
    Ok(ShapeOut::Nothing)
}

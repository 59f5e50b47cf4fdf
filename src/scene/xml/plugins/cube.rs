//! `<shape type="cube">`: the cube [-1, 1]³ with outward faces, through `to_world`.

use super::{Build, Plugin, Run};
use crate::scene::error::SceneError;
use crate::scene::xml::props::Props;
use crate::scene::xml::shape::{self, ShapeOut};
use glam::Vec3;

/// Registry entry.
pub const PLUGIN: Plugin = Plugin { tag: "shape", kind: "cube", run: Run::Shape(run) };

fn run<'e>(_: &mut Build<'e>, p: &Props<'e>) -> Result<ShapeOut, SceneError> {
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for axis in 0..3 {
        for s in [-1.0f32, 1.0] {
            let n = Vec3::from_array(std::array::from_fn(|k| if k == axis { s } else { 0.0 }));
            let u = Vec3::from_array(std::array::from_fn(|k| if k == (axis + 1) % 3 { 1.0 } else { 0.0 }));
            let v = n.cross(u);
            let base = positions.len() as u32;
            positions.extend([n - u - v, n + u - v, n + u + v, n - u + v]);
            // (u, v, n) is right-handed, so this winding faces outwards.
            faces.extend([[base, base + 1, base + 2], [base + 2, base + 3, base]]);
        }
    }
    shape::mesh(p, positions, Vec::new(), faces)
}

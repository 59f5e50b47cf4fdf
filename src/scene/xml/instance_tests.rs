//! `shapegroup` + `instance` are Embree instances: a group's triangles are stored once however
//! many instances place it, and a hit on an instance shades as a hit on a copy placed directly.

use super::*;
use crate::accel::{Hits8, RayHit8};
use crate::scene::build::Scene;
use crate::simd::{mask_all, Vec3x8, F8};
use glam::Vec3;

/// An octahedron with vertex normals and uvs (8 triangles).
const OCTA: &str = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
    vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\nvt 0.5 0.5\nvt 0.2 0.7\n\
    vn 1 0 0\nvn -1 0 0\nvn 0 1 0\nvn 0 -1 0\nvn 0 0 1\nvn 0 0 -1\n\
    f 1/1/1 3/3/3 5/5/5\nf 3/3/3 2/2/2 5/5/5\nf 2/2/2 4/4/4 5/5/5\nf 4/4/4 1/1/1 5/5/5\n\
    f 3/3/3 1/1/1 6/6/6\nf 2/2/2 3/3/3 6/6/6\nf 4/4/4 2/2/2 6/6/6\nf 1/1/1 4/4/4 6/6/6\n";

const HEAD: &str = "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><film type=\"hdrfilm\">\
    <rfilter type=\"box\"/></film></sensor>\n";

/// The group's members: the octahedron and a rectangle with its own `to_world`.
fn members() -> String {
    "<shape type=\"obj\"><string name=\"filename\" value=\"m.obj\"/>\
     <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.2 0.5 0.3\"/></bsdf></shape>\n\
     <shape type=\"rectangle\"><transform name=\"to_world\"><rotate y=\"1\" angle=\"-80\"/>\
     <translate x=\"0.5\"/></transform>\
     <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.9 0.5 0.9\"/></bsdf></shape>\n"
        .to_string()
}

/// The instances' transforms (the second mirrors).
const PLACES: [&str; 2] = [
    "<rotate y=\"1\" angle=\"45\"/><scale value=\"1.5\"/><translate z=\"2\"/>",
    "<rotate x=\"1\" angle=\"-25\"/><scale x=\"-1.2\" y=\"1.2\" z=\"1.2\"/><translate z=\"-2\"/>",
];

fn load_text(text: &str) -> Scene {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("m.obj"), OCTA).unwrap();
    let path = d.path().join("s.xml");
    std::fs::write(&path, text).unwrap();
    Scene::build(load(&path, &Limits::default(), &[]).expect("loads").desc).expect("builds")
}

/// The scene with the group placed by `n` instances (translated apart after `PLACES`).
fn instanced(n: usize) -> Scene {
    let mut text = format!("{HEAD}<shape type=\"shapegroup\" id=\"g\">{}</shape>\n", members());
    for i in 0..n {
        let place = PLACES[i % 2];
        text += &format!(
            "<shape type=\"instance\"><ref id=\"g\"/><transform name=\"to_world\">{place}\
             <translate x=\"{}\"/></transform></shape>\n",
            (i / 2) as f32 * 5.0
        );
    }
    load_text(&(text + "</scene>\n"))
}

/// The same shapes as [`instanced`]`(2)`, each placed directly.
fn flattened() -> Scene {
    let mut text = HEAD.to_string();
    for place in PLACES {
        let m = members().replace("</transform>", &format!("{place}<translate x=\"0\"/></transform>"));
        let m = m.replacen(
            "<string name=\"filename\" value=\"m.obj\"/>",
            &format!("<string name=\"filename\" value=\"m.obj\"/><transform name=\"to_world\">{place}</transform>"),
            1,
        );
        text += &m;
    }
    load_text(&(text + "</scene>\n"))
}

#[test]
fn many_instances_store_the_group_triangles_once() {
    let one = instanced(1);
    let many = instanced(200);
    // 8 octahedron faces + 2 rectangle triangles, stored once.
    assert_eq!(one.tri_normal.len(), 10);
    assert_eq!(many.tri_normal.len(), 10, "200 instances store one copy of the group's triangles");
    assert!(many.desc.triangles.is_empty(), "no flattened copies in the description");
    assert_eq!(many.desc.instances.len(), 200);
}

/// Packets from a grid of origins towards the origin region: instance hits gather the same
/// record (position, normals, smoothness, tangent, material) as hits on directly placed copies.
#[test]
fn instance_hits_gather_as_directly_placed_copies() {
    let (inst, flat) = (instanced(2), flattened());
    assert_eq!(flat.tri_normal.len(), 20);
    let mut compared = 0;
    for k in 0..64 {
        let o = Vec3::new(-6.0 + (k % 8) as f32 * 0.3, -6.0, -3.0 + (k / 8) as f32 * 0.8);
        let lanes = std::array::from_fn(|i| (Vec3::new(-0.4 + i as f32 * 0.12, 0.0, o.z * 0.9) - o).normalize());
        let (org, dir) = (Vec3x8::splat(o), Vec3x8::from_lanes(lanes));
        let shade = |sc: &Scene| {
            let mut rh = RayHit8::default();
            let active = rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), mask_all());
            let traced = sc.accel.intersect8(&mut rh, true, active);
            sc.gather(org, dir, &Hits8::from_rayhit(&rh, traced))
        };
        let (a, b) = (shade(&inst), shade(&flat));
        assert_eq!(a.valid.to_bitmask(), b.valid.to_bitmask(), "packet {k}: the same lanes hit");
        assert_eq!(a.smooth.to_bitmask(), b.smooth.to_bitmask(), "packet {k}");
        assert_eq!(a.mat.back.to_bitmask(), b.mat.back.to_bitmask(), "packet {k}");
        for i in 0..8 {
            if a.valid.to_bitmask() & (1 << i) == 0 {
                continue;
            }
            compared += 1;
            let close = |x: Vec3, y: Vec3, tol: f32| (x - y).abs().max_element() <= tol;
            assert!(close(a.p.lane(i), b.p.lane(i), 1e-4), "packet {k} lane {i}: p");
            assert!(close(a.ng.lane(i), b.ng.lane(i), 1e-4), "packet {k} lane {i}: ng");
            assert!(close(a.n.lane(i), b.n.lane(i), 1e-4), "packet {k} lane {i}: n");
            assert!(close(a.s.lane(i), b.s.lane(i), 1e-3), "packet {k} lane {i}: s");
            assert!(close(a.mat.kd.lane(i), b.mat.kd.lane(i), 0.0), "packet {k} lane {i}: kd");
            let (ma, mb) = (a.material.as_array()[i] as usize, b.material.as_array()[i] as usize);
            assert_eq!(inst.materials[ma].bsdf, flat.materials[mb].bsdf, "packet {k} lane {i}: material");
        }
    }
    assert!(compared > 100, "the rays hit the instances ({compared} hits)");
}

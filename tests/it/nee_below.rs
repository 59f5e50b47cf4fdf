//! Next events below a transmitting surface: the path tracer lights a rough glass sphere's
//! transmitting vertices from the other side of the surface by every light outside the light
//! selection (the constant environment, the envmap, a point light), as it does by area lights.
//! Each image agrees per pixel (and over the whole image) with a reference that does not depend
//! on those next events: for the environments, the same scene rendered by BSDF sampling alone
//! (NEE off); for the point light, the same scene with a small sphere light of the same
//! intensity in its place (whose area-light next events already crossed the surface). Without
//! the next events below, the environments' escaped rays through the glass lose their MIS share
//! (the constant sky's and the envmap's images come out darker) and the point light behind the
//! sphere is not seen through it at all.

use crate::common;

use glam::Vec3;
use std::sync::Arc;
use strata::bsdf::microfacet::Distribution;
use strata::integrator::FirstSample;
use strata::sampler::SamplerKind;
use strata::scene::desc::{DeltaLightDesc, EmissiveSphereDesc, EnvironmentDesc, Nee, RgbImage, SceneDesc, SphereDesc};
use strata::session::RenderOptions;

/// A rough glass unit sphere (GGX, alpha 0.3, IOR 1.5) filling most of a 20x20 image.
const SPHERE: &str = "\
size 20 20
integrator pathtracer
camera 0 0.4 3  0 0 0  0 1 0  45
maxdepth 8
nexteventestimation mis
importancesampling brdf
ambient 0 0 0
diffuse 0 0 0
specular 0 0 0
sphere 0 0 0 1
";

fn glass_sphere() -> SceneDesc {
    let dir = common::tmpdir("nee-below");
    let scene = dir.join("sphere.test");
    std::fs::write(&scene, SPHERE).unwrap();
    let mut d = strata::session::scene::parse_scene(&RenderOptions { scene: Some(scene), ..Default::default() })
        .expect("the sphere parses");
    let k = d.spheres[0].material as usize;
    d.materials[k].bsdf =
        strata::bsdf::roughdielectric::params(Distribution::Ggx, 0.3, 0.3, true, 1.5, Vec3::ONE, Vec3::ONE);
    d
}

type Image = (Vec<[f64; 3]>, Vec<[f64; 3]>);

fn render(d: &SceneDesc, spp: u32, nee: Nee, sampler: &str, seed: u64) -> Image {
    let o = RenderOptions {
        parsed: Some(Arc::new(d.clone())),
        spp: Some(spp),
        seed,
        threads: 2,
        nee: Some(nee),
        sampler: SamplerKind::parse(sampler),
        first_sample: Some(FirstSample::Jittered),
        ..Default::default()
    };
    let out = strata::session::render_to_film(&o).unwrap_or_else(|e| panic!("render failed: {e}"));
    assert_eq!(out.stats.counters.nonfinite, 0);
    (common::means(&out.film), common::var_of_mean(&out.film))
}

/// Asserts `a` agrees with `b`: the largest |z| of a pixel below 7 (a loose check: a pixel's
/// variance estimate is itself noisy where rare paths carry much of its light), of a 4x4 block
/// below 5 and of the whole image below 4.5, per channel (the sums' variances add). Prints them
/// and the ratio of the image sums.
fn agree(name: &str, a: &Image, b: &Image) {
    let (mut zpix, mut zblock, mut zsum, mut ratio) = (0f64, 0f64, 0f64, [0f64; 3]);
    let w = 20;
    for (c, ratio) in ratio.iter_mut().enumerate() {
        let (mut d, mut v, mut sa, mut sb) = (0.0, 0.0, 0.0, 0.0);
        let mut blocks = vec![(0.0, 0.0); (w / 4) * (w / 4)];
        for i in 0..a.0.len() {
            let (e, var) = (a.0[i][c] - b.0[i][c], a.1[i][c] + b.1[i][c]);
            if var > 0.0 {
                zpix = zpix.max(e.abs() / var.sqrt());
            }
            let k = (i / w / 4) * (w / 4) + (i % w) / 4;
            blocks[k] = (blocks[k].0 + e, blocks[k].1 + var);
            (d, v, sa, sb) = (d + e, v + var, sa + a.0[i][c], sb + b.0[i][c]);
        }
        for (e, var) in blocks {
            if var > 0.0 {
                zblock = zblock.max(f64::abs(e) / f64::sqrt(var));
            }
        }
        zsum = zsum.max(d.abs() / v.sqrt());
        *ratio = sa / sb;
    }
    let z = format!("pixel |z| {zpix:.2}, 4x4 block |z| {zblock:.2}, image |z| {zsum:.2}, ratio {ratio:.4?}");
    eprintln!("{name}: {z}");
    assert!(zpix < 7.0 && zblock < 5.0 && zsum < 4.5, "{name}: {z}");
}

#[test]
fn constant_sky_lights_glass_from_below() {
    let mut d = glass_sphere();
    d.environment = Some(EnvironmentDesc::Constant(Vec3::new(0.5, 0.7, 1.0)));
    let mis = render(&d, 256, Nee::Mis, "sobol", 1);
    let on = render(&d, 256, Nee::On, "sobol", 2);
    let bsdf = render(&d, 1024, Nee::Off, "independent", 3);
    agree("sky, MIS against BSDF sampling", &mis, &bsdf);
    agree("sky, NEE on against BSDF sampling", &on, &bsdf);
}

#[test]
fn envmap_lights_glass_from_below() {
    let mut d = glass_sphere();
    // A lat-long map: a dim blue sky over a brown ground, a bright warm patch low on one side.
    let (w, h) = (16u32, 8u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let base = if y < h / 2 { Vec3::new(0.3, 0.4, 0.8) } else { Vec3::new(0.3, 0.2, 0.1) };
            if (x == 3 || x == 4) && (y == 4 || y == 5) {
                Vec3::new(8.0, 6.0, 3.0)
            } else {
                base
            }
        })
        .collect();
    let image = Arc::new(RgbImage { width: w, height: h, texels });
    d.environment = Some(EnvironmentDesc::Envmap { image, scale: 1.0, to_world: glam::Mat4::IDENTITY });
    let mis = render(&d, 256, Nee::Mis, "sobol", 1);
    let bsdf = render(&d, 2048, Nee::Off, "independent", 3);
    agree("envmap, MIS against BSDF sampling", &mis, &bsdf);
}

#[test]
fn point_light_behind_glass_is_seen_through_it() {
    let base = glass_sphere();
    let (pos, intensity) = (Vec3::new(0.3, -0.2, -2.2), Vec3::new(3.0, 2.0, 1.0));
    let mut point = base.clone();
    point.delta_lights.push(DeltaLightDesc::Point { position: pos, intensity });
    // The reference: a sphere light of radius r and radiance I / (pi r^2), the same intensity in
    // every direction (its size changes the image by about (r / distance)^2, 0.1 %).
    let mut area = base;
    let r = 0.04f32;
    // (Black: hits on a light are not shaded, and its own material would only matter there.)
    let mut black = area.materials[area.spheres[0].material as usize];
    black.bsdf = strata::bsdf::BsdfParams::COURSE;
    area.materials.push(black);
    let m = area.materials.len() as u32 - 1;
    area.spheres.push(SphereDesc {
        object_to_world: glam::Mat4::from_translation(pos) * glam::Mat4::from_scale(Vec3::splat(r)),
        material: m,
    });
    let radiance = intensity / (std::f32::consts::PI * r * r);
    area.emissive_spheres.push(EmissiveSphereDesc { sphere: 1, center: pos, radius: r, radiance });
    let a = render(&point, 256, Nee::Mis, "sobol", 1);
    let b = render(&area, 1024, Nee::Mis, "independent", 3);
    let lit: f64 = a.0.iter().map(|p| p[0]).sum();
    assert!(lit > 0.0, "the point light is not seen through the glass");
    agree("point light against a small sphere light", &a, &b);
}

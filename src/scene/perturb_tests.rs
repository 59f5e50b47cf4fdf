//! Tests of the shading frames and maps at hits (`perturb.rs`): Mitsuba's dp/du tangent, the
//! normal map's and the bump map's perturbed normals worked out by hand, the luminance gradient
//! against finite differences, and scenes without maps unchanged.

use super::*;
use crate::accel::RayHit8;
use crate::scene::desc::SceneDesc;
use crate::scene::{limits::Limits, parse::parse_str};
use crate::simd::mask_all;
use crate::texture::{Bitmap, BitmapTexture, FilterType, RawConstant, Texture, UvTransform, WrapMode};

/// A 2x2 floor at y = 0 of two triangles (materials 0 and 1), seen from above. Triangle 0's
/// face normal is -y (Mitsuba's orientation), so the record's normals are its negation.
fn desc() -> SceneDesc {
    let text = "size 8 8\ncamera 0 5 0 0 0 0 0 0 1 45\nmaxverts 4\n\
                vertex -1 0 -1\nvertex 1 0 -1\nvertex -1 0 1\nvertex 1 0 1\n\
                diffuse 0.3 0.3 0.5\ntri 0 1 2\ndiffuse 0.5 0.2 0.1\ntri 1 3 2\n";
    let mut d = parse_str(text, std::path::Path::new("t.test"), &Limits::default()).expect("scene");
    // Triangle 0's uvs: u = x/2 + 1/2, v = z/2 + 1/2, so dp/du = (2, 0, 0) and dp/dv = (0, 0, 2).
    let uv = |x: f32, z: f32| Vec2::new(x * 0.5 + 0.5, z * 0.5 + 0.5);
    d.triangle_uvs = vec![[uv(-1.0, -1.0), uv(1.0, -1.0), uv(-1.0, 1.0)]];
    d
}

/// Traces eight rays straight down at `xz` and gathers them.
fn shade(sc: &Scene, xz: [(f32, f32); 8]) -> SurfaceHit8 {
    let org = Vec3x8::from_lanes(xz.map(|(x, z)| Vec3::new(x, 4.0, z)));
    let dir = Vec3x8::splat(Vec3::NEG_Y);
    let mut rh = RayHit8::default();
    let active = rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), mask_all());
    let traced = sc.accel.intersect8(&mut rh, true, active);
    sc.gather(org, dir, &Hits8::from_rayhit(&rh, traced))
}

/// Lanes 0-3 on triangle 0 (x + z < 0, near x = 0), 4-6 on triangle 1, 7 misses.
const XZ: [(f32, f32); 8] =
    [(-0.1, -0.5), (0.05, -0.6), (-0.2, -0.3), (0.1, -0.4), (0.5, 0.1), (0.3, 0.6), (0.7, 0.7), (9.0, 9.0)];

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

#[test]
fn a_normal_map_tilts_the_shading_frame_built_from_dp_du() {
    let mut d = desc();
    // m = 2 c - 1 = (0.6, 0, 0.8) in the frame (s, t, n) = (x, n x s, -y) = (x, z, -y).
    d.textures = vec![Texture::RawConstant(RawConstant { value: Vec3::new(0.8, 0.5, 0.9) })];
    d.material_frames = vec![Some(FrameMap::Normal { texture: 0 })];
    let sc = Scene::build(d).unwrap();
    assert!(sc.tangents && sc.frame_maps() && sc.hit_extras);
    let sh = shade(&sc, XZ);
    let tan2 = 0.36f32 / 0.64;
    for i in 0..4 {
        // World normal 0.6 x + 0.8 (-y), negated to face the ray from above.
        assert!(close(sh.n.lane(i), Vec3::new(-0.6, 0.8, 0.0)), "lane {i}: {}", sh.n.lane(i));
        // s' = normalize(x - m m.x) in the frame = (0.64, 0, -0.48) / 0.8.
        assert!(close(sh.s.lane(i), Vec3::new(0.8, 0.6, 0.0)), "lane {i}: {}", sh.s.lane(i));
        assert!(close(sh.base_n.lane(i), Vec3::Y));
        assert!((sh.bump_a2.as_array()[i] - tan2 / 8.0).abs() < 1e-6);
        assert!(crate::simd::mask_to_bools(sh.smooth)[i]);
    }
    // Triangle 1 (no uvs, no map): the barycentric dp/du = p1 - p0, its normal unchanged.
    let plain = shade(&Scene::build(desc()).unwrap(), XZ);
    for i in 4..7 {
        assert_eq!(sh.n.lane(i), plain.n.lane(i));
        assert_eq!(sh.base_n.lane(i), sh.n.lane(i));
        assert_eq!(sh.bump_a2.as_array()[i], 0.0);
        // Triangle 1 is (1,0,-1), (1,0,1), (-1,0,1): dp/du = (0, 0, 2).
        assert!(close(sh.s.lane(i), Vec3::Z), "lane {i}: {}", sh.s.lane(i));
    }
    assert_eq!(sh.s.lane(7), Vec3::ZERO);
}

#[test]
fn an_invalid_normal_is_mirrored_to_face_the_viewer() {
    let mut d = desc();
    // m = (0.6, 0, -0.8): below the surface, the viewer (above it) is not on its side: Mitsuba
    // mirrors its tangential part, (-0.6, 0, -0.8), which the viewer still does not face; the
    // frame is that one (the BSDF then sees the viewer from below: black, as Mitsuba's).
    d.textures = vec![Texture::RawConstant(RawConstant { value: Vec3::new(0.8, 0.5, 0.1) })];
    d.material_frames = vec![Some(FrameMap::Normal { texture: 0 })];
    let sh = shade(&Scene::build(d).unwrap(), XZ);
    // -0.6 x - 0.8 (-y) = (-0.6, 0.8, 0), negated.
    assert!(close(sh.n.lane(0), Vec3::new(0.6, -0.8, 0.0)), "{}", sh.n.lane(0));
    assert!(sh.n.lane(0).dot(sh.wo.lane(0)) < 0.0);
}

#[test]
fn a_bump_map_of_a_ramp_tilts_the_normal_by_its_gradient() {
    let mut d = desc();
    // Luminance 0, 0.25, 0.5, 0.75 along u (grey texels), bilinear: between texel centres 1
    // and 2 (u in [0.375, 0.625]) the gradient is 0.25 per texel, 1 per unit u.
    let texels = (0..4).map(|x| [x as f32 * 0.25; 3]).collect();
    let bmp = Bitmap::from_texels(4, 1, texels, FilterType::Bilinear, WrapMode::Clamp).unwrap();
    d.textures = vec![Texture::BitmapTexture(BitmapTexture { bitmap: bmp.into(), to_uv: UvTransform::IDENTITY })];
    let scale = 3.0;
    d.material_frames = vec![Some(FrameMap::Bump { texture: 0, scale })];
    let sh = shade(&Scene::build(d).unwrap(), XZ);
    // dp/du' = (2, 0, 0) + (-y)(3 - 0) = (2, -3, 0), dp/dv' = (0, 0, 2): n' = (-6, -4, 0)
    // normalized (on the face normal's side), negated for the record.
    let want = -Vec3::new(-6.0, -4.0, 0.0).normalize();
    for i in 0..4 {
        assert!(close(sh.n.lane(i), want), "lane {i}: {} != {want}", sh.n.lane(i));
        assert!(sh.s.lane(i).dot(sh.n.lane(i)).abs() < 1e-5);
    }
    let cos2 = want.y * want.y;
    assert!((sh.bump_a2.as_array()[0] - ((1.0 - cos2) / cos2 / 8.0).min(1.0)).abs() < 1e-6);
}

#[test]
fn the_luminance_gradient_is_the_derivative_of_the_bilinear_lookup() {
    let (w, h) = (5u32, 3u32);
    let texels =
        (0..w * h).map(|k| [(k * 7 % 11) as f32 / 11.0, (k * 3 % 5) as f32 / 5.0, (k % 4) as f32 / 4.0]).collect();
    let bmp = Bitmap::from_texels(w, h, texels, FilterType::Bilinear, WrapMode::Repeat).unwrap();
    let lum = |uv: Vec2| bmp.eval(uv).dot(Vec3::new(0.212_671, 0.715_160, 0.072_169));
    let e = 1e-3;
    // Points inside bilinear cells (away from texel centres, where the derivative jumps).
    for uv in [Vec2::new(0.31, 0.45), Vec2::new(0.05, 0.9), Vec2::new(0.77, 0.21), Vec2::new(0.55, 0.6)] {
        let g = bmp.grad_luminance(uv);
        let fd = Vec2::new(
            (lum(uv + Vec2::X * e) - lum(uv - Vec2::X * e)) / (2.0 * e),
            (lum(uv + Vec2::Y * e) - lum(uv - Vec2::Y * e)) / (2.0 * e),
        );
        assert!((g - fd).abs().max_element() < 2e-2, "{uv}: {g} != {fd}");
    }
    let nearest =
        Bitmap::from_texels(2, 2, vec![[1.0; 3], [0.0; 3], [0.5; 3], [0.2; 3]], FilterType::Nearest, WrapMode::Clamp);
    assert_eq!(nearest.unwrap().grad_luminance(Vec2::new(0.4, 0.4)), Vec2::ZERO);
}

#[test]
fn scenes_without_registry_bsdfs_or_maps_have_no_tangents() {
    let sc = Scene::build(desc()).unwrap();
    assert!(!sc.tangents && !sc.frame_maps() && !sc.hit_extras);
    let sh = shade(&sc, XZ);
    assert_eq!(sh.s.lane(0), Vec3::ZERO);
    assert_eq!(sh.bump_a2.to_array(), [0.0; 8]);
}

#[test]
fn sphere_tangents_match_mitsuba() {
    // Mitsuba 3.9.1 `sphere` (center (0.2, 0.1, -0.3), radius 0.7), rays down -z from
    // (0.2 + dx, 0.1 + dy, 5): the hit and Mitsuba's `si.sh_frame.s` there.
    let text = "size 8 8\ncamera 0 0 5 0 0 0 0 1 0 45\ndiffuse 0.5 0.5 0.5\nsphere 0.2 0.1 -0.3 0.7\n";
    let mut d = parse_str(text, std::path::Path::new("t.test"), &Limits::default()).expect("scene");
    d.textures = vec![Texture::RawConstant(RawConstant { value: Vec3::new(0.5, 0.5, 1.0) })];
    d.material_frames = vec![Some(FrameMap::Normal { texture: 0 })];
    let sc = Scene::build(d).unwrap();
    let cases = [
        ((0.3, 0.2), Vec3::new(-0.554_700_3, 0.832_050_4, 0.0)),
        ((-0.4, 0.1), Vec3::new(-0.242_535_6, -0.970_142_5, 0.0)),
        ((0.05, -0.5), Vec3::new(0.995_037_2, 0.099_503_72, 0.0)),
    ];
    let org = Vec3x8::from_lanes(std::array::from_fn(|i| {
        let (dx, dy) = cases[i % 3].0;
        Vec3::new(0.2 + dx, 0.1 + dy, 5.0)
    }));
    let dir = Vec3x8::splat(Vec3::NEG_Z);
    let mut rh = RayHit8::default();
    let active = rh.ray.set(org, dir, F8::ZERO, F8::splat(f32::INFINITY), mask_all());
    let traced = sc.accel.intersect8(&mut rh, true, active);
    let sh = sc.gather(org, dir, &Hits8::from_rayhit(&rh, traced));
    for (i, (_, s)) in cases.iter().enumerate() {
        assert!(close(sh.s.lane(i), *s), "lane {i}: {} != {s}", sh.s.lane(i));
        // The identity map leaves the normal and adds no shadowing.
        assert_eq!(sh.bump_a2.to_array()[i], 0.0);
    }
}

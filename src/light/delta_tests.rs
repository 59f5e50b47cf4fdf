use super::*;
use crate::simd::mask_all;
use glam::Mat4;

fn spot(texture: Option<Arc<RgbImage>>) -> DeltaLight {
    // At the origin, shining along +z (Mitsuba's lookat to (0, 0, 1) with up +y is the identity
    // up to the sign of x).
    let to_world = Mat4::from_translation(Vec3::new(0.0, 0.0, 0.0));
    DeltaLight::new(&DeltaLightDesc::Spot {
        to_world,
        intensity: Vec3::splat(5.0),
        cutoff_deg: 20.0,
        beam_width_deg: 15.0,
        texture,
    })
    .unwrap()
}

#[test]
fn point_light_falls_off_with_the_squared_distance() {
    let l = DeltaLight::new(&DeltaLightDesc::Point { position: Vec3::new(0.0, 2.0, 0.0), intensity: Vec3::splat(8.0) })
        .unwrap();
    let (wi, d, li) = l.sample(Vec3::ZERO).unwrap();
    assert_eq!((wi, d, li), (Vec3::Y, 2.0, Vec3::splat(2.0)));
    assert!(l.sample(Vec3::new(0.0, 2.0, 0.0)).is_none(), "at the light itself");
}

#[test]
fn spot_falloff_is_mitsubas_linear_ramp_in_angle() {
    let l = spot(None);
    let at = |deg: f32| {
        let t = deg.to_radians();
        l.sample(Vec3::new(t.sin(), 0.0, t.cos()) * 2.0).map(|(_, _, li)| li.x * 4.0)
    };
    assert!((at(0.0).unwrap() - 5.0).abs() < 1e-5);
    assert!((at(14.0).unwrap() - 5.0).abs() < 1e-5, "inside the beam");
    assert!((at(17.5).unwrap() - 2.5).abs() < 1e-3, "half way: {:?}", at(17.5));
    assert!(at(20.5).is_none() && at(120.0).is_none(), "past the cutoff");
    // Refusals.
    let bad = DeltaLightDesc::Spot {
        to_world: Mat4::IDENTITY,
        intensity: Vec3::ONE,
        cutoff_deg: 10.0,
        beam_width_deg: 15.0,
        texture: None,
    };
    assert_eq!(DeltaLight::new(&bad).unwrap_err(), DeltaLightError::SpotAngles { beam: 15.0, cutoff: 10.0 });
}

#[test]
fn spot_texture_spans_the_cutoff_cone() {
    // 2 x 1 texture: left half 1, right half 3; nearest to the texel centres at u = 0.25, 0.75.
    let t = Arc::new(RgbImage { width: 2, height: 1, texels: vec![Vec3::ONE, Vec3::splat(3.0)] });
    let l = spot(Some(t));
    let tan = 20f32.to_radians().tan();
    // u = 0.5 + 0.5 x / (z tan(cutoff)): u = 0.25 at x / z = -tan / 2 (the texel centre).
    let p = Vec3::new(-0.5 * tan, 0.0, 1.0);
    let (_, _, li) = l.sample(p).unwrap();
    let cos = p.normalize().z;
    let ramp = if cos < 15f32.to_radians().cos() { (20f32.to_radians() - cos.acos()) / 5f32.to_radians() } else { 1.0 };
    assert!((li.x * p.length_squared() - 5.0 * ramp).abs() < 1e-4, "{li}");
}

#[test]
fn projector_puts_pi_scale_irradiance_on_the_unit_plane() {
    let im = Arc::new(RgbImage::constant(Vec3::new(1.0, 0.5, 0.25)));
    let to_world = Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0));
    let l =
        DeltaLight::new(&DeltaLightDesc::Projector { to_world, irradiance: im, scale: 2.0, fov_x_deg: 90.0 }).unwrap();
    for x in [0.0f32, 0.3, -0.9] {
        // Irradiance on the plane z = 0 (1 in front of the projector), normal -z: li cos_i.
        let p = Vec3::new(x, 0.2, 0.0);
        let (wi, _, li) = l.sample(p).unwrap();
        let e = li * wi.dot(Vec3::NEG_Z);
        assert!((e - std::f32::consts::PI * 2.0 * Vec3::new(1.0, 0.5, 0.25)).abs().max_element() < 1e-4, "{x}: {e}");
    }
    assert!(l.sample(Vec3::new(1.2, 0.0, 0.0)).is_none(), "outside the 90 degree frustum");
    assert!(l.sample(Vec3::new(0.0, 0.0, -2.0)).is_none(), "behind the projector");
}

#[test]
fn directional_light_is_its_irradiance_from_its_direction() {
    let l =
        DeltaLight::new(&DeltaLightDesc::Directional { direction: Vec3::new(0.0, -2.0, 0.0), irradiance: Vec3::ONE })
            .unwrap();
    assert_eq!(l.sample(Vec3::new(5.0, 1.0, 3.0)), Some((Vec3::Y, f32::INFINITY, Vec3::ONE)));
}

#[test]
fn x8_matches_scalar_per_lane() {
    let lights = [
        spot(Some(Arc::new(RgbImage { width: 2, height: 2, texels: vec![Vec3::ONE, Vec3::X, Vec3::Y, Vec3::Z] }))),
        DeltaLight::new(&DeltaLightDesc::Point { position: Vec3::ONE, intensity: Vec3::ONE }).unwrap(),
    ];
    let ps: [Vec3; 8] =
        std::array::from_fn(|i| Vec3::new(0.05 * i as f32 - 0.2, 0.03 * i as f32, 1.0 + 0.1 * i as f32));
    for l in &lights {
        let (wi, d, li, ok) = l.sample_x8(Vec3x8::from_lanes(ps), mask_all());
        let ok = crate::simd::mask_to_bools(ok);
        for i in 0..8 {
            match l.sample(ps[i]) {
                Some((w, dd, ll)) => {
                    assert!(ok[i]);
                    assert_eq!((wi.lane(i), d.to_array()[i], li.lane(i)), (w, dd, ll));
                }
                None => assert!(!ok[i]),
            }
        }
    }
}

//! Tests of the SIMD ellipsoid intersection against the f64 oracle (`Ellipsoid::hit`).

use super::bench::{pack, Rng};
use super::*;
use glam::{Mat4, Quat, Vec3};

/// Tolerance on hit distances against the f64 path: |t - t64| <= REL |t64|.
const REL: f32 = 1e-5;

#[derive(Clone, Copy, Debug)]
struct Ray {
    o: Vec3,
    d: Vec3,
    tn: f32,
    tf: f32,
}

/// Up to 8 rays in Embree field order.
fn fields(rays: &[Ray]) -> bench::Packet {
    pack(&rays.iter().map(|r| (r.o, r.d, r.tn, r.tf)).collect::<Vec<_>>())
}

/// Packet answer of the first `rays.len() <= 8` lanes (lane subsets through `valid`).
fn packet(e: &Ellipsoid, rays: &[Ray], valid: impl Fn(usize) -> bool) -> [Option<f32>; 8] {
    let fields = fields(rays);
    let mut out = [None; 8];
    packet_hits(
        e,
        rays.len(),
        |f| fields[f],
        valid,
        |i, t| {
            assert!(out[i].is_none(), "lane {i} reported twice");
            out[i] = Some(t);
        },
    );
    out
}

/// The normal the renderer computes (scene::build gather): from the hit point, in f32.
fn normal(m: &Mat4, r: &Ray, t: f32) -> Vec3 {
    let w2o = m.inverse();
    let n = glam::Mat3::from_mat4(w2o).transpose();
    (n * w2o.transform_point3(r.d.mul_add(Vec3::splat(t), r.o))).normalize_or_zero()
}

#[derive(Default, Debug)]
struct Stats {
    rays: usize,
    hits: usize,
    unsure: usize,
    max_rel: f32,
    max_normal: f32,
}

/// Checks every ray against the f64 path in packets of 8: same hit/miss, |t - t64| <= REL t64,
/// and (when `normal_tol` is given) renderer normals within it.
fn check(m: &Mat4, rays: &[Ray], normal_tol: Option<f32>) -> Stats {
    let e = Ellipsoid::new(m).expect("invertible");
    let mut st = Stats::default();
    for chunk in rays.chunks(8) {
        let got = packet(&e, chunk, |_| true);
        let fields = fields(chunk);
        let v3 = |f: usize| Vec3x8::new(F8::new(fields[f]), F8::new(fields[f + 1]), F8::new(fields[f + 2]));
        let live = crate::simd::mask_first(chunk.len());
        let fr = fast8(&e.fast, v3(0), v3(4), F8::new(fields[3]), F8::new(fields[8]), live);
        st.unsure += fr.unsure.to_bitmask().count_ones() as usize;
        for (i, r) in chunk.iter().enumerate() {
            let want = e.hit(r.o.to_array(), r.d.to_array(), r.tn, r.tf);
            st.rays += 1;
            match (got[i], want) {
                (None, None) => {}
                (Some(t), Some(t64)) => {
                    st.hits += 1;
                    let rel = (t - t64).abs() / t64.abs().max(f32::MIN_POSITIVE);
                    st.max_rel = st.max_rel.max(rel);
                    assert!(rel <= REL, "t {t} vs f64 {t64} (rel {rel:e}) for {r:?} under {m:?}");
                    assert!(t > r.tn && t < r.tf);
                    if let Some(tol) = normal_tol {
                        let dn = (normal(m, r, t) - normal(m, r, t64)).length();
                        st.max_normal = st.max_normal.max(dn);
                        assert!(dn <= tol, "normal off by {dn:e} for {r:?}");
                    }
                }
                (g, w) => panic!("hit/miss disagree: packet {g:?}, f64 {w:?} for {r:?} under {m:?}"),
            }
        }
    }
    st
}

fn sphere(c: Vec3, r: f32) -> Mat4 {
    Mat4::from_translation(c) * Mat4::from_rotation_y(0.4) * Mat4::from_scale(Vec3::splat(r))
}

fn ellipsoid(c: Vec3, axes: Vec3) -> Mat4 {
    Mat4::from_translation(c)
        * Mat4::from_quat(Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.9))
        * Mat4::from_scale(axes)
}

/// Rays from `eye` towards random points of the ellipsoid's bounding ball of radius `rad`
/// about `c` (scaled 1.3: a mix of hits and misses), unit directions.
fn aimed(rng: &mut Rng, n: usize, eye: Vec3, c: Vec3, rad: f32) -> Vec<Ray> {
    (0..n)
        .map(|_| {
            let target = c + rng.dir() * (rad * 1.3 * rng.unit().cbrt());
            Ray { o: eye, d: (target - eye).normalize(), tn: 0.0, tf: f32::INFINITY }
        })
        .collect()
}

#[test]
fn camera_like_rays_agree_with_f64() {
    let mut rng = Rng(1);
    let c = Vec3::new(0.3, 0.3, 0.2);
    let m = sphere(c, 0.3);
    let st = check(&m, &aimed(&mut rng, 100_000, Vec3::new(0.0, 1.0, 3.0), c, 0.3), Some(1e-4));
    eprintln!("camera-like sphere: {st:?}");
    assert!(st.hits > 30_000);
    let m = ellipsoid(c, Vec3::new(0.3, 0.6, 0.2));
    let st = check(&m, &aimed(&mut rng, 100_000, Vec3::new(0.0, 1.0, 3.0), c, 0.6), Some(1e-4));
    eprintln!("camera-like ellipsoid: {st:?}");
    assert!(st.unsure * 5 < st.rays, "f64 fallback should be rare: {st:?}");
}

#[test]
fn random_rays_agree_with_f64() {
    let mut rng = Rng(2);
    for k in 0..4 {
        let c = Vec3::new(rng.sym(), rng.sym(), rng.sym()) * 5.0;
        let axes = Vec3::new(0.2 + rng.unit(), 0.2 + rng.unit(), 0.2 + rng.unit());
        let m = if k % 2 == 0 { sphere(c, axes.x) } else { ellipsoid(c, axes) };
        let rays: Vec<Ray> = (0..25_000)
            .map(|_| {
                let o = c + Vec3::new(rng.sym(), rng.sym(), rng.sym()) * 4.0;
                // Aim near the centre (many hits) or anywhere.
                let d = if rng.unit() < 0.5 { (c + rng.dir() * 1.5 - o).normalize() } else { rng.dir() };
                let tn = if rng.unit() < 0.2 { rng.unit() * 3.0 } else { 0.0 };
                let tf = if rng.unit() < 0.2 { tn + rng.unit() * 8.0 } else { f32::INFINITY };
                // Unnormalized directions too: t is in units of |d|.
                let s = if rng.unit() < 0.3 { 0.1 + 10.0 * rng.unit() } else { 1.0 };
                Ray { o, d: d * s, tn: tn / s, tf: tf / s }
            })
            .collect();
        let st = check(&m, &rays, None);
        eprintln!("random {k}: {st:?}");
    }
}

#[test]
fn grazing_rays_agree_with_f64() {
    // Rays along z at distance 1 +- eps from the axis of a unit-ish sphere: tangent +- eps.
    for &r in &[1.0f32, 0.37] {
        let c = Vec3::new(0.25, -0.5, 0.0);
        let m = sphere(c, r);
        let mut rays = Vec::new();
        let eps_list = (1..=40i32).flat_map(|k| [-1.0f32, 1.0].map(|s| s * 2f32.powi(-k / 2))).chain([0.0]);
        for eps in eps_list {
            for ang in 0..8 {
                let phi = ang as f32 * 0.785;
                let off = Vec3::new(phi.cos(), phi.sin(), 0.0) * (r * (1.0 + eps));
                rays.push(Ray { o: c + off - Vec3::Z * (3.0 * r), d: Vec3::Z, tn: 0.0, tf: f32::INFINITY });
            }
        }
        let st = check(&m, &rays, Some(1e-2));
        eprintln!("grazing r={r}: {st:?}");
        assert!(st.unsure > 0, "near-tangent rays must go to f64");
    }
    // The same for an ellipsoid, tangent planes found in object space.
    let m = ellipsoid(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 2.0, 0.1));
    let mut rays = Vec::new();
    for k in 1..40 {
        for s in [-1.0f32, 1.0] {
            let eps = s * 2f32.powi(-k / 2);
            let (oo, dd) = (Vec3::new(1.0 + eps, 0.0, -5.0), Vec3::Z);
            rays.push(Ray { o: m.transform_point3(oo), d: m.transform_vector3(dd), tn: 0.0, tf: f32::INFINITY });
        }
    }
    check(&m, &rays, None);
}

#[test]
fn far_away_rays_agree_with_f64() {
    let mut rng = Rng(3);
    for &dist in &[1e4f32, 1e5, 1e6] {
        let c = Vec3::new(1.0, 2.0, -3.0);
        for m in [sphere(c, 0.5), ellipsoid(c, Vec3::new(0.5, 0.3, 0.8))] {
            let mut rays = Vec::new();
            for _ in 0..4000 {
                let eye = c + rng.dir() * (dist * 0.8);
                rays.extend(aimed(&mut rng, 1, eye, c, 0.8));
            }
            let st = check(&m, &rays, None);
            eprintln!("far {dist:e}: {st:?}");
            assert!(st.hits > 0);
        }
    }
}

#[test]
fn rays_from_inside_agree_with_f64() {
    let mut rng = Rng(4);
    let c = Vec3::new(-2.0, 0.5, 1.0);
    for m in [sphere(c, 2.0), ellipsoid(c, Vec3::new(2.0, 0.5, 1.0))] {
        let rays: Vec<Ray> = (0..20_000)
            .map(|_| {
                let o = m.transform_point3(rng.dir() * 0.99 * rng.unit());
                Ray { o, d: rng.dir(), tn: 0.0, tf: f32::INFINITY }
            })
            .collect();
        let st = check(&m, &rays, Some(1e-3));
        assert_eq!(st.hits, st.rays, "every ray from inside hits");
    }
}

#[test]
fn tiny_and_huge_radii_agree_with_f64() {
    let mut rng = Rng(5);
    for &r in &[1e-4f32, 1e4] {
        for c in [Vec3::ZERO, Vec3::new(3.0, -1.0, 2.0) * r, Vec3::new(1e3, 2e3, -5e2)] {
            for m in [sphere(c, r), ellipsoid(c, Vec3::new(r, 0.5 * r, 2.0 * r))] {
                let eye = c + Vec3::new(1.0, 2.0, 5.0) * r;
                let st = check(&m, &aimed(&mut rng, 4000, eye, c, 2.0 * r), None);
                eprintln!("r {r:e} at {c}: {st:?}");
                assert!(st.hits > 0);
            }
        }
    }
}

#[test]
fn extreme_axis_ratios_agree_with_f64() {
    let mut rng = Rng(6);
    let c = Vec3::new(0.5, 0.5, 0.5);
    for axes in [Vec3::new(1.0, 1.0, 1e-4), Vec3::new(1e-4, 1.0, 1e-4), Vec3::new(1e2, 1e-2, 1.0)] {
        for m in [Mat4::from_translation(c) * Mat4::from_scale(axes), ellipsoid(c, axes)] {
            let eye = c + Vec3::new(0.3, 0.2, 1.0) * 5.0 * axes.max_element();
            let st = check(&m, &aimed(&mut rng, 20_000, eye, c, axes.max_element()), None);
            eprintln!("axes {axes}: {st:?}");
        }
    }
}

#[test]
fn interval_boundaries_agree_with_f64() {
    // Unit sphere at 5 on the z axis: roots at 4 and 6 for rays from the origin.
    let m = Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0));
    let mut rays = Vec::new();
    for root in [4.0f32, 6.0] {
        for k in -12..=12 {
            let x = root + k as f32 * root * f32::EPSILON;
            let ray = |tn, tf| Ray { o: Vec3::ZERO, d: Vec3::Z, tn, tf };
            rays.push(ray(x, f32::INFINITY));
            rays.push(ray(0.0, x));
            rays.push(ray(x, x + 0.5));
        }
    }
    rays.push(Ray { o: Vec3::ZERO, d: Vec3::Z, tn: 5.0, tf: 5.0 });
    rays.push(Ray { o: Vec3::ZERO, d: Vec3::Z, tn: 6.0, tf: 4.0 });
    let st = check(&m, &rays, None);
    eprintln!("boundaries: {st:?}");
}

#[test]
fn any_lane_count_and_mask_agree_with_f64() {
    let mut rng = Rng(7);
    let c = Vec3::new(0.0, 0.0, 4.0);
    let m = sphere(c, 1.0);
    let e = Ellipsoid::new(&m).unwrap();
    let rays = aimed(&mut rng, 8, Vec3::ZERO, c, 1.0);
    for n in 1..=8 {
        for mask in [0xffu32, 0x55, 0xaa, 0x01, 0x80, 0x00] {
            let got = packet(&e, &rays[..n], |i| mask & (1 << i) != 0);
            for i in 0..8 {
                let want = if i < n && mask & (1 << i) != 0 {
                    let r = &rays[i];
                    e.hit(r.o.to_array(), r.d.to_array(), r.tn, r.tf)
                } else {
                    None
                };
                assert_eq!(got[i].is_some(), want.is_some(), "n {n} mask {mask:#x} lane {i}");
            }
        }
    }
}

#[test]
fn degenerate_rays_never_report_nan() {
    let m = sphere(Vec3::new(0.0, 0.0, 3.0), 1.0);
    let e = Ellipsoid::new(&m).unwrap();
    let (n, inf) = (f32::NAN, f32::INFINITY);
    let rays = [
        Ray { o: Vec3::ZERO, d: Vec3::ZERO, tn: 0.0, tf: inf },
        Ray { o: Vec3::new(n, 0.0, 0.0), d: Vec3::Z, tn: 0.0, tf: inf },
        Ray { o: Vec3::ZERO, d: Vec3::new(0.0, n, 1.0), tn: 0.0, tf: inf },
        Ray { o: Vec3::ZERO, d: Vec3::Z, tn: n, tf: inf },
        Ray { o: Vec3::ZERO, d: Vec3::Z, tn: 0.0, tf: n },
        Ray { o: Vec3::splat(1e30), d: Vec3::Z, tn: 0.0, tf: inf },
        Ray { o: Vec3::ZERO, d: Vec3::Z * 1e-30, tn: 0.0, tf: inf },
        Ray { o: Vec3::ZERO, d: Vec3::Z * 1e30, tn: 0.0, tf: inf },
    ];
    let got = packet(&e, &rays, |_| true);
    for (i, r) in rays.iter().enumerate() {
        let want = e.hit(r.o.to_array(), r.d.to_array(), r.tn, r.tf);
        assert_eq!(got[i].is_some(), want.is_some(), "lane {i}: {r:?}");
        assert!(got[i].is_none_or(|t| t.is_finite()), "lane {i}");
    }
}

/// The early return of all-miss packets ([`certain_misses`]) changes no answer: for spheres and
/// ellipsoids of many scales and positions, with rays missing by a wide margin, grazing the
/// silhouette (tangent +- 2^-k), from far away, from inside and with non-finite or degenerate
/// directions, every lane it calls a certain miss is a miss of the full bound (neither hit nor
/// unsure), and `fast8` with and without the early return agree bit for bit. It must also fire
/// (most all-miss packets return early), or it would be dead weight.
#[test]
fn early_all_miss_return_changes_no_answer() {
    let mut rng = Rng(11);
    let (mut packets, mut early, mut missing) = (0, 0, 0);
    let v3 = |p: &bench::Packet, f: usize| Vec3x8::new(F8::new(p[f]), F8::new(p[f + 1]), F8::new(p[f + 2]));
    for k in 0..24 {
        let c = Vec3::new(rng.sym(), rng.sym(), rng.sym()) * [1.0, 50.0, 1e4][k % 3];
        let scale = [0.3f32, 1e-3, 40.0, 1.0][k % 4];
        let axes = Vec3::new(0.2 + rng.unit(), 0.2 + rng.unit(), 0.2 + rng.unit()) * scale;
        let m = if k % 2 == 0 { sphere(c, axes.x) } else { ellipsoid(c, axes) };
        let e = Ellipsoid::new(&m).expect("invertible");
        let rad = axes.max_element();
        for j in 0..4000 {
            let rays: Vec<Ray> = (0..8)
                .map(|i| {
                    // One kind of ray in two packets of three (all-miss packets are common).
                    let o = c + rng.dir() * (rad * [3.0, 1e3, 0.5, 1.0 + 1e-6][j % 4]);
                    let d = match (j / 4 + if j % 3 == 0 { i } else { 0 }) % 5 {
                        // anywhere (mostly misses)
                        0 | 1 => rng.dir(),
                        // grazing the bounding sphere of the ellipsoid
                        2 => {
                            (c + rng.dir() * rad * (1.0 + (rng.sym() * 2f32.powi(-((j % 24) as i32)))) - o).normalize()
                        }
                        // at the centre, unnormalized
                        3 => (c - o) * (0.01 + 10.0 * rng.unit()),
                        _ => [Vec3::ZERO, Vec3::splat(f32::NAN), Vec3::new(1e-30, 0.0, 0.0), rng.dir()][j % 4],
                    };
                    Ray { o, d, tn: 0.0, tf: f32::INFINITY }
                })
                .collect();
            let p = fields(&rays);
            let (org, dir, tn, tf) = (v3(&p, 0), v3(&p, 4), F8::new(p[3]), F8::new(p[8]));
            let valid = crate::simd::mask_all();
            let full = fast8_with(&e.fast, org, dir, tn, tf, valid, false);
            let fast = fast8_with(&e.fast, org, dir, tn, tf, valid, true);
            assert_eq!(
                (full.hit.to_bitmask(), full.unsure.to_bitmask(), full.t.to_array().map(f32::to_bits)),
                (fast.hit.to_bitmask(), fast.unsure.to_bitmask(), fast.t.to_array().map(f32::to_bits)),
                "packet {j} of shape {k}"
            );
            // The certain misses by themselves, lane by lane, whatever the rest of the packet.
            let sure = sure_lanes(&e.fast, org, dir) & valid;
            assert_eq!(sure.to_bitmask() & (full.hit | full.unsure).to_bitmask(), 0, "packet {j} of shape {k}");
            packets += 1;
            if (full.hit | full.unsure).none() {
                missing += 1;
                early += usize::from((valid & !sure).none());
            }
        }
    }
    eprintln!("{packets} packets, {missing} all-miss, {early} returned early");
    assert!(missing > 1000 && early * 4 > missing * 3, "{early} of {missing}");
}

/// [`certain_misses`] of a packet, from the same intermediate values as `fast8_with`.
fn sure_lanes(e: &Fast, org: Vec3x8, dir: Vec3x8) -> Mask8 {
    let Approach { e_o, e_d, a, inv_a, oo, ff, .. } = approach(e, org, dir);
    certain_misses(e_o, e_d, a, inv_a, oo, ff, F8::ONE - ff)
}

/// The f32 box Embree tests packets against holds the ellipsoid (its extreme points along each
/// axis, in f64) however the casts round, down to ellipsoids smaller than an f32 step of their
/// position: a box cut short would drop rays that the exact test hits before any callback runs.
#[test]
fn bounds_hold_the_ellipsoid_at_any_scale_and_position() {
    let mut rng = Rng(23);
    let mut checked = 0;
    for r in [1e-5f32, 1e-4, 3e-3, 0.5, 7.0, 1e4] {
        for c in [Vec3::ZERO, Vec3::new(0.3, -0.7, 0.1), Vec3::new(1e3, 2e3, -5e2), Vec3::new(-6e4, 3e5, 1e5)] {
            let axes = Vec3::new(r, r * (0.2 + rng.unit()), r * (0.5 + rng.unit()));
            for m in [sphere(c, r), ellipsoid(c, axes)] {
                let e = Ellipsoid::new(&m).unwrap();
                let md = glam::DMat4::from_cols_array(&m.to_cols_array().map(f64::from));
                for i in 0..3 {
                    let row = md.row(i);
                    let ext = (row.x * row.x + row.y * row.y + row.z * row.z).sqrt();
                    let (lo, hi) = (f64::from(e.lower[i]), f64::from(e.upper[i]));
                    assert!(lo <= row.w - ext && hi >= row.w + ext, "r {r} at {c}, axis {i}: [{lo}, {hi}]");
                    // Padded, not blown up: within 2^-8 of the extent plus 2^-18 of the position.
                    let slack = ext / 256.0 + row.w.abs().max(ext) / f64::from(1u32 << 18);
                    assert!(lo >= row.w - ext - slack && hi <= row.w + ext + slack, "r {r} at {c}: loose box");
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 6 * 4 * 2 * 3);
}

//! Tests of the BRDFs: the format's formulas literally (f64), reciprocity, sample == (eval, pdf) of the
//! sampled direction, x8 == scalar per lane, finiteness at the extremes, normalization, energy, and
//! chi-square tests of the mixture samplers at normal and grazing incidence.

#![allow(clippy::needless_range_loop)] // lane loops index several per-lane arrays

use super::*;
use crate::sampling::chi2::{chi2_test, ggx_core, phong_core, Grid, Rng};
use crate::sampling::GGX_ALPHA_MIN;
use crate::simd::mask_from_bools;
use crate::simd::{Vec3x8, F8};
use glam::DVec3;
use glam::Vec3;
use std::f64::consts::PI;

const STRATEGIES: [ImportanceSampling; 3] =
    [ImportanceSampling::Hemisphere, ImportanceSampling::Cosine, ImportanceSampling::Brdf];

fn phong(kd: f32, ks: f32, s: f32) -> Material {
    Material { kd: Vec3::splat(kd), ks: Vec3::splat(ks), shininess: s, alpha: 1.0, kind: BrdfKind::Phong }
}
fn ggx(kd: f32, ks: f32, alpha: f32) -> Material {
    Material { kd: Vec3::splat(kd), ks: Vec3::splat(ks), shininess: 1.0, alpha, kind: BrdfKind::Ggx }
}
/// Unit direction at polar angle theta (degrees) from +z and azimuth phi (radians).
fn dir(theta_deg: f32, phi: f32) -> Vec3 {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    Vec3::new(st * phi.cos(), st * phi.sin(), ct)
}
fn mirror(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}
fn close(a: f32, b: f32, rtol: f32) -> bool {
    (a - b).abs() <= rtol * a.abs().max(b.abs()) + 1e-30
}
fn close3(a: Vec3, b: Vec3, rtol: f32, atol: f32) -> bool {
    (a - b).abs().cmple(a.abs().max(b.abs()) * rtol + Vec3::splat(atol)).all()
}
/// A random material: Phong or GGX, random colours, shininess up to 1e3, alpha in [0.01, 1].
fn random_material(rng: &mut Rng) -> Material {
    let c = |rng: &mut Rng| Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 0.5;
    let kind = if rng.f32() < 0.5 { BrdfKind::Phong } else { BrdfKind::Ggx };
    Material { kd: c(rng), ks: c(rng), shininess: 1e3f32.powf(rng.f32()), alpha: 0.01 + rng.f32(), kind }
}
/// A random upper-hemisphere direction with theta up to 89.9 degrees.
fn random_up(rng: &mut Rng) -> Vec3 {
    dir(89.9 * rng.f32().sqrt(), std::f32::consts::TAU * rng.f32())
}

// ---- the format's definitions --------------------------------------------------------------------

/// FORMAT.md's f, written literally in f64 (angles through acos/tan, G1 with tan, cos^4 in D).
fn format_f(m: &Material, wo: Vec3, wi: Vec3) -> DVec3 {
    let (wo, wi, n) = (wo.as_dvec3(), wi.as_dvec3(), DVec3::Z);
    let (kd, ks) = (m.kd.as_dvec3(), m.ks.as_dvec3());
    if wo.dot(n) <= 0.0 || wi.dot(n) <= 0.0 {
        return DVec3::ZERO;
    }
    match m.kind {
        BrdfKind::Phong => {
            let r = 2.0 * n.dot(wo) * n - wo;
            let s = m.shininess as f64;
            // max(0, x)^s, with 0^0 read as its limit from the lobe side (0 for x <= 0 also at s = 0),
            // the reading under which the format's sampler (cos = xi^(1/(s+1)) around r) covers f's
            // support; IEEE pow(0, 0) = 1 would make s = 0 Lambertian beyond r's hemisphere.
            let lobe = if r.dot(wi) > 0.0 { r.dot(wi).powf(s) } else { 0.0 };
            kd / PI + ks * (s + 2.0) / (2.0 * PI) * lobe
        }
        BrdfKind::Ggx => {
            let a = m.alpha.max(GGX_ALPHA_MIN) as f64;
            let h = (wi + wo).normalize();
            let th = h.dot(n).acos();
            let d = a * a / (PI * th.cos().powi(4) * (a * a + th.tan().powi(2)).powi(2));
            let g1 = |v: DVec3| {
                let tv = v.dot(n).acos();
                if v.dot(n) <= 0.0 {
                    0.0
                } else {
                    2.0 / (1.0 + (1.0 + a * a * tv.tan().powi(2)).sqrt())
                }
            };
            let f = ks + (DVec3::ONE - ks) * (1.0 - wi.dot(h)).powi(5);
            kd / PI + f * g1(wi) * g1(wo) * d / (4.0 * wi.dot(n).abs() * wo.dot(n).abs())
        }
    }
}

#[test]
fn eval_matches_the_format_literally() {
    let mut rng = Rng::new(40);
    let mats = [
        phong(0.3, 0.6, 0.0),
        phong(0.1, 0.8, 1.0),
        phong(0.2, 0.5, 30.0),
        phong(0.0, 1.0, 1e3),
        ggx(0.3, 0.6, 0.01),
        ggx(0.2, 0.04, 0.1),
        ggx(0.5, 0.5, 0.5),
        ggx(0.0, 1.0, 1.0),
    ];
    for m in mats {
        for _ in 0..20_000 {
            let (wo, mut wi) = (random_up(&mut rng), random_up(&mut rng));
            if rng.f32() < 0.5 {
                // near the specular peak, where the lobe carries its energy
                let r = mirror(wo);
                wi = (r + 0.1 * (random_up(&mut rng) - Vec3::Z) * rng.f32()).normalize();
            }
            let (f, want) = (m.eval(wo, wi), format_f(&m, wo, wi).as_vec3());
            assert!(close3(f, want, 2e-4, 1e-30), "{m:?} wo={wo} wi={wi}: {f} vs the format's {want}");
        }
    }
}

#[test]
fn eval_is_reciprocal_and_one_sided() {
    let mut rng = Rng::new(41);
    for _ in 0..20_000 {
        let m = random_material(&mut rng);
        let (wo, wi) = (random_up(&mut rng), random_up(&mut rng));
        assert!(close3(m.eval(wo, wi), m.eval(wi, wo), 2e-5, 1e-30), "{m:?} {wo} {wi}");
        let below = Vec3::new(wi.x, wi.y, -wi.z);
        assert_eq!((m.eval(wo, below), m.eval(below, wo)), (Vec3::ZERO, Vec3::ZERO));
    }
}

// ---- sample, pdf, eval agree ----------------------------------------------------------------------

#[test]
fn sample_returns_pdf_and_f_of_its_direction() {
    let mut rng = Rng::new(42);
    for _ in 0..100_000 {
        let m = random_material(&mut rng);
        let wo = if rng.f32() < 0.1 { Vec3::new(rng.f32() - 0.5, 0.3, -0.5).normalize() } else { random_up(&mut rng) };
        for st in STRATEGIES {
            let (wi, pdf, f) = m.sample(st, wo, rng.u2(), rng.f32());
            assert!(wi.is_finite() && (wi.length() - 1.0).abs() < 1e-5, "{wi}");
            assert_eq!(pdf.to_bits(), m.pdf(st, wo, wi).to_bits(), "{m:?} {st:?} wo={wo} wi={wi}");
            assert_eq!(f, m.eval(wo, wi));
            assert!(pdf > 0.0 || f == Vec3::ZERO || wi.z == 0.0, "{m:?} {st:?} wo={wo} wi={wi}: f {f} with pdf 0");
        }
    }
}

// ---- x8 == scalar ---------------------------------------------------------------------------------

#[test]
fn x8_matches_scalar_per_lane() {
    let mut rng = Rng::new(43);
    let mask = [true, true, true, true, true, true, true, false];
    let m8a = mask_from_bools(mask);
    for trial in 0..20_000 {
        let mut mats: [Material; 8] = std::array::from_fn(|_| random_material(&mut rng));
        if trial % 4 == 0 {
            mats = [mats[0]; 8]; // uniform kind in the packet
        }
        let mut wo: [Vec3; 8] = std::array::from_fn(|_| random_up(&mut rng));
        wo[1] = Vec3::new(0.6, 0.0, -0.8); // below the horizon
        wo[7] = Vec3::NAN; // inactive lane with garbage
        let mut wi: [Vec3; 8] = std::array::from_fn(|i| {
            let r = mirror(wo[i]);
            if rng.f32() < 0.5 {
                (r + 0.05 * (random_up(&mut rng) - Vec3::Z)).normalize()
            } else {
                random_up(&mut rng)
            }
        });
        wi[2] = -wo[2];
        wi[3].z = -wi[3].z;
        let u: [[f32; 2]; 8] = std::array::from_fn(|_| rng.u2());
        let ul: [f32; 8] = std::array::from_fn(|_| rng.f32());
        let m8 = Material8::from_lanes(mats);
        let (wo8, wi8) = (Vec3x8::from_lanes(wo), Vec3x8::from_lanes(wi));
        let u8 = [F8::new(u.map(|u| u[0])), F8::new(u.map(|u| u[1]))];
        for st in STRATEGIES {
            let (f8, p8) = m8.eval_pdf(st, wo8, wi8, m8a);
            let (swi8, sp8, sf8) = m8.sample(st, wo8, u8, F8::new(ul), m8a);
            let (sp8_own, p8) = (m8.pdf(st, wo8, swi8, m8a).to_array(), p8.to_array());
            for i in 0..8 {
                if !mask[i] {
                    assert_eq!(
                        (f8.lane(i), p8[i], swi8.lane(i), sp8.to_array()[i], sf8.lane(i)),
                        (Vec3::ZERO, 0.0, Vec3::ZERO, 0.0, Vec3::ZERO)
                    );
                    continue;
                }
                // GGX and the hemisphere warps involve no transcendental: bit-exact. Phong's cos^s uses
                // wide's ln/exp: relative error ~|s ln cos| ulp (largest seen: 8e-6, at a 2e-15 tail value).
                let rtol = if mats[i].kind == BrdfKind::Phong { 2e-5 } else { 0.0 };
                let (f, p) = mats[i].eval_pdf(st, wo[i], wi[i]);
                assert!(
                    close3(f8.lane(i), f, rtol, 0.0) && close(p8[i], p, rtol),
                    "{st:?} lane {i} {:?}: x8 ({}, {}) scalar ({f}, {p})",
                    mats[i],
                    f8.lane(i),
                    p8[i]
                );
                // samples: directions agree to a few ulp (sin_cos, ln, exp differ); pdf and f of the
                // x8 direction agree with the scalar twin's at that same direction. (Comparing them at
                // the two slightly different directions would measure conditioning, not the twins:
                // the GGX pdf 1/|wo.h| with h = normalize(wi + wo) is ill-conditioned as wi -> -wo.)
                let wi_s = mats[i].sample(st, wo[i], u[i], ul[i]).0;
                let (w, sp, sf) = (swi8.lane(i), sp8.to_array()[i], sf8.lane(i));
                assert!(close3(w, wi_s, 1e-5, 2e-6), "{st:?} lane {i}: wi x8 {w} scalar {wi_s}");
                let (f_s, p_s) = mats[i].eval_pdf(st, wo[i], w);
                assert!(
                    close(sp, p_s, rtol) && close3(sf, f_s, rtol, 0.0),
                    "{st:?} lane {i} {:?}: x8 ({sp}, {sf}) scalar ({p_s}, {f_s})",
                    mats[i]
                );
                assert_eq!(sp.to_bits(), sp8_own[i].to_bits());
            }
        }
    }
}

// ---- finiteness -----------------------------------------------------------------------------------

#[test]
fn finite_for_extreme_inputs() {
    const U: [f32; 7] = [0.0, 1e-45, f32::MIN_POSITIVE, 0.5, 0.999_999_9, 0.999_999_94, 1.0];
    let mut mats = vec![];
    for (kd, ks) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.5, 0.5)] {
        for s in [0.0, 1e-3, 1.0, 1e3, 1e4, 1e6] {
            mats.push(phong(kd, ks, s));
        }
        for a in [0.0, 1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0] {
            mats.push(ggx(kd, ks, a));
        }
    }
    let wos =
        [Vec3::Z, dir(89.9, 0.3), Vec3::new(1.0, 0.0, 1e-7).normalize(), Vec3::X, Vec3::new(0.6, 0.0, -0.8), -Vec3::Z];
    let mut cases = vec![];
    for m in &mats {
        for &wo in &wos {
            for a in U {
                for b in U {
                    for ul in [0.0, 0.5, 1.0] {
                        cases.push((*m, wo, [a, b], ul));
                    }
                }
            }
        }
    }
    let ok = |f: Vec3, p: f32| f.is_finite() && f.min_element() >= 0.0 && p.is_finite() && p >= 0.0;
    for st in STRATEGIES {
        for &(m, wo, u, ul) in &cases {
            let (wi, p, f) = m.sample(st, wo, u, ul);
            assert!(
                wi.is_finite() && (wi.length() - 1.0).abs() < 1e-5 && ok(f, p),
                "{st:?} {m:?} wo={wo} u={u:?}: {wi} {p} {f}"
            );
            for wi in [wi, -wo, wo, Vec3::Z, -Vec3::Z, Vec3::Y, mirror(wo)] {
                let (f, p) = m.eval_pdf(st, wo, wi);
                assert!(ok(f, p), "{st:?} {m:?} wo={wo} wi={wi}: {f} {p}");
            }
        }
        for c in cases.chunks_exact(8) {
            let m8 = Material8::from_lanes(std::array::from_fn(|i| c[i].0));
            let wo8 = Vec3x8::from_lanes(std::array::from_fn(|i| c[i].1));
            let u8 = [F8::new(std::array::from_fn(|i| c[i].2[0])), F8::new(std::array::from_fn(|i| c[i].2[1]))];
            let (wi, p, f) =
                m8.sample(st, wo8, u8, F8::new(std::array::from_fn(|i| c[i].3)), mask_from_bools([true; 8]));
            for i in 0..8 {
                let (w, p, f) = (wi.lane(i), p.to_array()[i], f.lane(i));
                assert!(
                    w.is_finite() && (w.length() - 1.0).abs() < 1e-5 && ok(f, p),
                    "x8 {st:?} {:?}: {w} {p} {f}",
                    c[i]
                );
            }
        }
    }
}

// ---- normalization and energy ---------------------------------------------------------------------

/// Coordinates in which a material's distribution of wi is binned and integrated.
///
/// Phong: wi itself, theta about the mirror direction r, core rows sized to the lobe.
///
/// GGX: the half vector h (upper hemisphere), wi = 2 (wo.h) h - wo, with dw_wi = 4 |wo.h| dw_h, theta
/// about +z, core rows sized to D. The map is a bijection from the upper hemisphere of h onto the sphere
/// of wi (up to the null set wo.h = 0), so binning h is binning wi. In wi the grazing GGX lobe is a ridge
/// compressed by cos theta_o across the plane of incidence and ending in the integrable singularity
/// 1/|wi + wo| at wi = -wo (every h orthogonal to wo reflects there), which lies 2 (90 - theta_o)
/// degrees from r; no fixed theta-phi grid about r resolves that, while in h the lobe is the smooth
/// D(h) cos theta_h and the Jacobian 4 |wo.h| removes the singularity.
struct Coords {
    grid: Grid,
    wo: Vec3,
    half: bool,
}

impl Coords {
    fn new(m: &Material, wo: Vec3, n_core: usize, n_tail: usize, n_phi: usize) -> Self {
        let half = m.kind == BrdfKind::Ggx;
        let grid = if half {
            Grid::lobe(Vec3::Z, ggx_core(m.alpha as f64), n_core, n_tail, n_phi)
        } else {
            Grid::lobe(mirror(wo), phong_core(m.shininess as f64), n_core, n_tail, n_phi)
        };
        Self { grid, wo, half }
    }
    /// The binning coordinate of a sampled wi.
    fn of(&self, wi: Vec3) -> Vec3 {
        if !self.half {
            return wi;
        }
        let h = (wi.as_dvec3() + self.wo.as_dvec3()).normalize_or(DVec3::Z);
        (if h.z < 0.0 { -h } else { h }).as_vec3()
    }
    /// A density g per unit solid angle of wi, as a density in the binning coordinate. The Jacobian
    /// 4 |wo.h| is taken at the half vector of the f32 wi that g sees: near wo.h = 0 (wi -> -wo) g
    /// grows as 1/|wo.h|, and pairing it with the Jacobian of the unrounded h would turn the rounding
    /// of wi into spikes.
    fn density(&self, c: Vec3, g: &dyn Fn(Vec3) -> f64) -> f64 {
        if !self.half {
            return g(c);
        }
        let (h, wo) = (c.as_dvec3(), self.wo.as_dvec3());
        let wi = (2.0 * wo.dot(h) * h - wo).as_vec3();
        let h_wi = (wi.as_dvec3() + wo).normalize_or_zero();
        if h.z > 0.0 {
            g(wi) * 4.0 * wo.dot(h_wi).abs()
        } else {
            0.0
        }
    }
    /// The integral of g (per unit solid angle of wi) over the sphere of wi.
    fn integrate(&self, g: &dyn Fn(Vec3) -> f64) -> f64 {
        self.grid.integrate_sphere(&|c| self.density(c, g))
    }
}

#[test]
fn pdfs_integrate_to_one_for_every_strategy() {
    // Only where the pdf evaluated at f32 directions is smooth to the quadrature's 1e-4 (see
    // `chi2::simpson`): rounding wi by 6e-8 moves a Phong pdf by ~sqrt(s) 6e-8 relative about a tilted
    // axis, a GGX pdf by ~1.2e-7 / (alpha cos theta_o) through h = normalize(wi + wo).
    let mats = [
        phong(0.4, 0.5, 0.0),
        phong(0.4, 0.5, 20.0),
        phong(0.1, 0.9, 1e4),
        phong(0.0, 1.0, 1e6),
        ggx(0.5, 0.3, 1e-3),
        ggx(0.5, 0.3, 0.02),
        ggx(0.5, 0.3, 0.1),
        ggx(0.0, 1.0, 1.0),
    ];
    for m in mats {
        for theta_o in [0.0f32, 45.0, 80.0, 89.0] {
            let noise = match m.kind {
                BrdfKind::Phong => m.shininess.sqrt() * 6e-8 * theta_o.signum(),
                BrdfKind::Ggx => 1.2e-7 / (m.alpha * theta_o.to_radians().cos()),
            };
            if noise > 5e-5 {
                continue;
            }
            let wo = dir(theta_o, 0.7);
            for st in STRATEGIES {
                let i = Coords::new(&m, wo, 16, 16, 24).integrate(&|wi| m.pdf(st, wo, wi) as f64);
                assert!((i - 1.0).abs() < 1e-4, "{m:?} {st:?} theta_o={theta_o}: integral {i}");
            }
        }
    }
}

/// Directional albedo: the integral of f(wo, wi) cos theta_i over the hemisphere (channel x).
fn albedo(m: &Material, wo: Vec3) -> f64 {
    Coords::new(m, wo, 16, 16, 24).integrate(&|wi| (m.eval(wo, wi).x * wi.z.max(0.0)) as f64)
}

/// White furnace for Phong: with kd + ks <= 1 the albedo never exceeds 1 and equals kd + ks at normal
/// incidence. Away from it the specular albedo drops as ks cos theta_o: the format's (s+2)/(2 pi)
/// normalizes the lobe times cos theta_i about the mirror direction only when r = n; for an unclipped
/// lobe about r the integral of (r.wi)^s (n.wi) is cos theta_o times that at r = n.
#[test]
fn phong_white_furnace() {
    for s in [0.0, 1.0, 10.0, 100.0, 1e3, 1e4, 1e6] {
        for (kd, ks) in [(0.0, 1.0), (0.3, 0.7), (1.0, 0.0)] {
            let m = phong(kd, ks, s);
            let mut row = vec![];
            for theta_o in [0.0f32, 30.0, 60.0, 85.0, 89.0] {
                let a = albedo(&m, dir(theta_o, 0.2));
                row.push(format!("{a:.4}"));
                assert!(a <= 1.0 + 1e-4, "s={s} kd={kd} ks={ks} theta_o={theta_o}: albedo {a}");
                if theta_o == 0.0 {
                    assert!((a - (kd + ks) as f64).abs() < 1e-4, "s={s}: normal-incidence albedo {a}");
                }
                if s >= 1e3 && theta_o <= 60.0 {
                    let want = kd as f64 + ks as f64 * (theta_o as f64).to_radians().cos();
                    assert!((a - want).abs() < 2e-3, "s={s} theta_o={theta_o}: albedo {a}, want ~{want}");
                }
            }
            eprintln!("phong albedo s={s} kd={kd} ks={ks} at theta_o = 0, 30, 60, 85, 89: {}", row.join(" "));
        }
    }
}

/// GGX, alpha 1e-4 .. 1: the specular albedo with ks = 1 (F = 1) never exceeds 1 (single scattering
/// loses energy at large alpha). The format adds kd/pi without a (1 - F) factor, so with kd + ks = 1
/// the total exceeds 1 at grazing incidence where Schlick's F -> 1: asserted <= 1 only up to 30
/// degrees, and equal to kd + F(theta_o) in the near-mirror limit (alpha <= 1e-3) where it is known.
#[test]
fn ggx_energy() {
    for a in [1e-4, 1e-3, 0.01, 0.1, 0.3, 0.6, 1.0] {
        let mut row = vec![];
        for theta_o in [0.0f32, 30.0, 60.0, 85.0, 89.0] {
            let wo = dir(theta_o, 0.2);
            let spec = albedo(&ggx(0.0, 1.0, a), wo);
            let total = albedo(&ggx(0.5, 0.5, a), wo);
            assert!(spec <= 1.0 + 1e-3, "alpha={a} theta_o={theta_o}: specular albedo {spec}");
            // kd + ks = 1 stays within 1 up to 30 degrees (Schlick's excess (1 - ks)(1 - cos)^5 is
            // < 2e-5 there); beyond, the format's missing (1 - F) on kd lets it exceed 1.
            if theta_o <= 30.0 {
                assert!(total <= 1.0 + 1e-3, "alpha={a} theta_o={theta_o}: kd = ks = 0.5 albedo {total}");
            }
            // Near-mirror limit, where the albedo is known: G -> 1, wi.h -> cos theta_o, so the
            // specular albedo is Schlick's F(theta_o) and the total kd + F(theta_o).
            if a <= 1e-3 && theta_o <= 85.0 {
                let f = |ks: f64| ks + (1.0 - ks) * (1.0 - (theta_o as f64).to_radians().cos()).powi(5);
                assert!((spec - 1.0).abs() < 1e-3, "alpha={a} theta_o={theta_o}: mirror albedo {spec}");
                assert!(
                    (total - 0.5 - f(0.5)).abs() < 1e-3,
                    "alpha={a} theta_o={theta_o}: {total} vs {}",
                    0.5 + f(0.5)
                );
            }
            row.push(format!("{spec:.4}/{total:.4}"));
        }
        eprintln!("ggx alpha={a}: albedo ks=1 / kd=ks=0.5 at theta_o = 0, 30, 60, 85, 89: {}", row.join(" "));
    }
}

// ---- chi-square -----------------------------------------------------------------------------------

/// Draws the x8 sampler's directions lane by lane, eight at a time.
fn x8_sampler(m: Material, wo: Vec3) -> impl FnMut(&mut Rng) -> Vec3 {
    let (m8, wo8) = (Material8::from_lanes([m; 8]), Vec3x8::splat(wo));
    let mut buf = vec![];
    move |rng: &mut Rng| {
        if buf.is_empty() {
            let u: [[f32; 3]; 8] = std::array::from_fn(|_| [rng.f32(), rng.f32(), rng.f32()]);
            let (u0, u1, ul) = (F8::new(u.map(|u| u[0])), F8::new(u.map(|u| u[1])), F8::new(u.map(|u| u[2])));
            buf = m8
                .sample(ImportanceSampling::Brdf, wo8, [u0, u1], ul, mask_from_bools([true; 8]))
                .0
                .to_lanes()
                .to_vec();
        }
        buf.pop().unwrap()
    }
}

fn chi2_brdf(m: Material, theta_o: f32, seed: u64, use_x8: bool) {
    let wo = dir(theta_o, 0.4);
    let name = format!(
        "{:?} brdf mixture (kd {}, ks {}, s {}, alpha {}) theta_o={theta_o}{}",
        m.kind,
        m.kd.x,
        m.ks.x,
        m.shininess,
        m.alpha,
        if use_x8 { " x8" } else { "" }
    );
    let coords = Coords::new(&m, wo, 10, 10, 20);
    let pdf = |c: Vec3| coords.density(c, &|wi| m.pdf(ImportanceSampling::Brdf, wo, wi) as f64);
    if use_x8 {
        let mut draw = x8_sampler(m, wo);
        chi2_test(&name, &coords.grid, seed, |r| coords.of(draw(r)), pdf);
    } else {
        chi2_test(
            &name,
            &coords.grid,
            seed,
            |r| coords.of(m.sample(ImportanceSampling::Brdf, wo, r.u2(), r.f32()).0),
            pdf,
        );
    }
}

#[test]
fn chi2_phong_brdf_mixture() {
    chi2_brdf(phong(0.4, 0.5, 20.0), 0.0, 60, false);
    chi2_brdf(phong(0.4, 0.5, 20.0), 88.0, 61, true);
    chi2_brdf(phong(0.4, 0.5, 1e3), 0.0, 62, true);
    chi2_brdf(phong(0.4, 0.5, 1e3), 88.0, 63, false);
}

#[test]
fn chi2_ggx_brdf_mixture() {
    chi2_brdf(ggx(0.5, 0.3, 0.01), 0.0, 70, false);
    chi2_brdf(ggx(0.5, 0.3, 0.01), 89.0, 71, true);
    chi2_brdf(ggx(0.5, 0.3, 0.3), 0.0, 72, true);
    chi2_brdf(ggx(0.5, 0.3, 0.3), 89.0, 73, false);
}

/// Every lobe set gives the general evaluation and sample, bit for bit, on materials that keep its
/// promise (lobes outside the set are exactly zero there); `Lobes` names the sets as kernels do.
#[test]
fn lobe_sets_agree_with_the_general_set_under_their_promise() {
    fn check<L: LobeSet>(m: Material, rng: &mut Rng) {
        let m8 = Material8::from_lanes([m; 8]);
        for _ in 0..64 {
            let (wo, wi) = (random_up(rng), random_up(rng));
            let (wo8, wi8) = (Vec3x8::splat(wo), Vec3x8::splat(wi));
            let u = [F8::splat(rng.f32()), F8::splat(rng.f32())];
            let ul = F8::splat(rng.f32());
            let bits = |(f, p): (Vec3x8, F8)| (f.x.to_array().map(f32::to_bits), p.to_array().map(f32::to_bits));
            for st in [ImportanceSampling::Hemisphere, ImportanceSampling::Cosine, ImportanceSampling::Brdf] {
                let all = mask_from_bools([true; 8]);
                assert_eq!(bits(m8.eval_pdf_k::<L>(st, wo8, wi8, all)), bits(m8.eval_pdf(st, wo8, wi8, all)));
                let (a, pa, _) = m8.sample_k::<L>(st, wo8, u, ul, all);
                let (b, pb, _) = m8.sample(st, wo8, u, ul, all);
                assert_eq!(a.z.to_array().map(f32::to_bits), b.z.to_array().map(f32::to_bits));
                assert_eq!(pa.to_array().map(f32::to_bits), pb.to_array().map(f32::to_bits));
            }
        }
    }
    let mut rng = Rng::new(7);
    check::<Diffuse>(phong(0.6, 0.0, 20.0), &mut rng);
    check::<DiffusePhong>(phong(0.4, 0.3, 20.0), &mut rng);
    check::<DiffuseGgx>(ggx(0.4, 0.3, 0.3), &mut rng);
    check::<DiffuseGgx>(phong(0.6, 0.0, 20.0), &mut rng);
    assert_eq!(Lobes(DiffusePhong::BITS).names(), ["phong"]);
    let mut all = vec!["phong", "ggx"];
    let mut reg = Vec::new();
    <crate::bsdf::AllBsdfs as crate::bsdf::BsdfSet>::members(&mut reg);
    all.extend(reg.iter().map(|m| m.name));
    assert_eq!(Lobes::ALL.names(), all);
    assert_eq!(Lobes(<Diffuse as LobeSet>::BITS).names(), Vec::<&str>::new());
}

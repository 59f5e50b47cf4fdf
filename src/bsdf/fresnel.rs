//! Fresnel reflectance, eight lanes: the exact unpolarized dielectric term with total internal
//! reflection ([`dielectric_x8`], Mitsuba's `fresnel`, pbrt's `FrDielectric`) and the conductor
//! term for a complex index eta + i k ([`conductor_x8`], per RGB channel). Cosines are signed and
//! measured against the surface's own normal (+z of the BSDF frame): `cos_i < 0` means the light
//! arrives from inside, where the relative index is inverted.

use crate::simd::{Vec3x8, F8};

/// Dielectric Fresnel reflectance for the incident cosine `cos_i` (signed) and the relative index
/// `eta` = eta_interior / eta_exterior (> 0). Returns `(r, cos_t, eta_it, eta_ti)`: the reflectance
/// (1 under total internal reflection, 0 for `eta` = 1), the signed cosine of the refracted
/// direction (on the other side of the surface than `cos_i`; 0 under total internal reflection),
/// and the relative indices eta_t/eta_i and eta_i/eta_t along that direction.
#[inline]
pub fn dielectric_x8(cos_i: F8, eta: F8) -> (F8, F8, F8, F8) {
    let outside = cos_i.simd_ge(F8::ZERO);
    let inv = F8::ONE / eta;
    let eta_it = outside.select(eta, inv);
    let eta_ti = outside.select(inv, eta);
    let ci = cos_i.abs().min(F8::ONE);
    // Snell: cos_t^2 = 1 - (eta_i/eta_t)^2 sin_i^2.
    let sin2 = (F8::ONE - ci * ci).max(F8::ZERO);
    let cos_t2 = F8::ONE - eta_ti * eta_ti * sin2;
    let tir = cos_t2.simd_le(F8::ZERO);
    let ct = cos_t2.max(F8::ZERO).sqrt();
    let a_s = (ci - eta_it * ct) / (ci + eta_it * ct);
    let a_p = (eta_it * ci - ct) / (eta_it * ci + ct);
    let r = F8::splat(0.5) * a_s.mul_add(a_s, a_p * a_p);
    let r = tir.select(F8::ONE, eta.simd_eq(F8::ONE).select(F8::ZERO, r.min(F8::ONE)));
    let cos_t = tir.select(F8::ZERO, outside.select(-ct, ct));
    (r, cos_t, eta_it, eta_ti)
}

/// Conductor Fresnel reflectance per RGB channel at the incident cosine `cos_i` (its magnitude is
/// used: a conductor is opaque) for the complex relative index `eta + i k`.
#[inline]
pub fn conductor_x8(cos_i: F8, eta: Vec3x8, k: Vec3x8) -> Vec3x8 {
    let ci = cos_i.abs().min(F8::ONE);
    Vec3x8::new(conductor1(ci, eta.x, k.x), conductor1(ci, eta.y, k.y), conductor1(ci, eta.z, k.z))
}

/// One channel of [`conductor_x8`] (`ci` in [0, 1]): the closed form of |r_s|^2 and |r_p|^2
/// through a^2 + b^2 = |n^2 - sin^2|, a = Re sqrt(n^2 - sin^2).
#[inline]
fn conductor1(ci: F8, eta: F8, k: F8) -> F8 {
    let cos2 = ci * ci;
    let sin2 = (F8::ONE - cos2).max(F8::ZERO);
    let (eta2, k2) = (eta * eta, k * k);
    let t0 = eta2 - k2 - sin2;
    let a2b2 = t0.mul_add(t0, F8::splat(4.0) * eta2 * k2).sqrt();
    let a = (F8::splat(0.5) * (a2b2 + t0)).max(F8::ZERO).sqrt();
    let t1 = a2b2 + cos2;
    let t2 = F8::splat(2.0) * ci * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = cos2.mul_add(a2b2, sin2 * sin2);
    let t4 = t2 * sin2;
    // t3 + t4 = 0 only for a vanishing index at normal incidence, where r_p = r_s.
    let rp = (t3 + t4).simd_gt(F8::ZERO).select(rs * (t3 - t4) / (t3 + t4), rs);
    // t1 + t2 = 0 only for a vanishing index at normal incidence: a perfect mirror.
    let r = F8::splat(0.5) * (rs + rp);
    (t1 + t2).simd_gt(F8::ZERO).select(r.max(F8::ZERO).min(F8::ONE), F8::ONE)
}

/// Scalar [`dielectric_x8`] (lane 0 of a splat: the same arithmetic).
pub fn dielectric(cos_i: f32, eta: f32) -> (f32, f32, f32, f32) {
    let (r, c, a, b) = dielectric_x8(F8::splat(cos_i), F8::splat(eta));
    (r.to_array()[0], c.to_array()[0], a.to_array()[0], b.to_array()[0])
}

/// Scalar [`conductor_x8`].
pub fn conductor(cos_i: f32, eta: glam::Vec3, k: glam::Vec3) -> glam::Vec3 {
    conductor_x8(F8::splat(cos_i), Vec3x8::splat(eta), Vec3x8::splat(k)).lane(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Complex numbers in f64, enough for the Fresnel amplitudes.
    #[derive(Clone, Copy)]
    struct C(f64, f64);
    impl C {
        fn add(self, o: C) -> C {
            C(self.0 + o.0, self.1 + o.1)
        }
        fn sub(self, o: C) -> C {
            C(self.0 - o.0, self.1 - o.1)
        }
        fn mul(self, o: C) -> C {
            C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
        }
        fn div(self, o: C) -> C {
            let d = o.0 * o.0 + o.1 * o.1;
            C((self.0 * o.0 + self.1 * o.1) / d, (self.1 * o.0 - self.0 * o.1) / d)
        }
        fn sqrt(self) -> C {
            let r = (self.0 * self.0 + self.1 * self.1).sqrt();
            let re = ((r + self.0) / 2.0).sqrt();
            let im = ((r - self.0) / 2.0).sqrt().copysign(self.1);
            C(re, im)
        }
        fn norm2(self) -> f64 {
            self.0 * self.0 + self.1 * self.1
        }
    }

    /// The Fresnel equations with a complex transmitted cosine: the reference for both terms.
    fn reference(ci: f64, n: C) -> f64 {
        let sin2 = 1.0 - ci * ci;
        let ct = C(1.0, 0.0).sub(C(sin2, 0.0).div(n.mul(n))).sqrt();
        let ci = C(ci, 0.0);
        let rs = ci.sub(n.mul(ct)).div(ci.add(n.mul(ct)));
        let rp = n.mul(ci).sub(ct).div(n.mul(ci).add(ct));
        0.5 * (rs.norm2() + rp.norm2())
    }

    #[test]
    fn dielectric_matches_the_fresnel_equations() {
        for &eta in &[1.0001f32, 1.33, 1.5, 2.4, 4.0, 1.0 / 1.5, 0.25] {
            for i in 0..=64 {
                let ci = i as f32 / 64.0;
                for sign in [1.0f32, -1.0] {
                    let (r, ct, eta_it, eta_ti) = dielectric(sign * ci, eta);
                    let rel = if sign * ci >= 0.0 { eta as f64 } else { 1.0 / eta as f64 };
                    let want = reference(ci as f64, C(rel, 0.0));
                    let sin_t2 = (1.0 - (ci as f64).powi(2)) / (rel * rel);
                    let want = if sin_t2 >= 1.0 { 1.0 } else { want };
                    assert!((r as f64 - want).abs() < 2e-4, "eta {eta} cos {} r {r} want {want}", sign * ci);
                    assert!((eta_it as f64 - rel).abs() < 1e-5 * rel && (eta_ti * eta_it - 1.0).abs() < 1e-5);
                    if sin_t2 < 1.0 {
                        let want_ct = (1.0 - sin_t2).sqrt();
                        assert!((ct.abs() as f64 - want_ct).abs() < 1e-3, "cos_t {ct} want {want_ct}");
                        assert!(ct * sign <= 0.0 || ci == 0.0, "refracted to the other side");
                    } else {
                        assert_eq!(ct, 0.0);
                    }
                }
            }
        }
    }

    #[test]
    fn dielectric_edge_cases() {
        // Index-matched: nothing reflects; normal incidence from outside: ((n-1)/(n+1))^2.
        assert_eq!(dielectric(0.3, 1.0).0, 0.0);
        assert!((dielectric(1.0, 1.5).0 - 0.04).abs() < 1e-6);
        // Grazing: everything reflects.
        assert_eq!(dielectric(0.0, 1.5).0, 1.0);
        // Total internal reflection just past the critical angle, and a finite value just before.
        let crit = (1.0f32 - 1.0 / (1.5 * 1.5)).sqrt();
        assert_eq!(dielectric(-(crit - 1e-4), 1.5).0, 1.0);
        let (r, ct, _, _) = dielectric(-(crit + 1e-3), 1.5);
        assert!(r.is_finite() && r < 1.0 && r > 0.5 && ct > 0.0, "r {r} ct {ct}");
        for &eta in &[1.0001f32, 4.0, 0.25] {
            for i in 0..=1000 {
                let c = -1.0 + i as f32 / 500.0;
                let (r, ct, a, b) = dielectric(c, eta);
                assert!(r.is_finite() && ct.is_finite() && a.is_finite() && b.is_finite());
                assert!((0.0..=1.0).contains(&r));
            }
        }
    }

    #[test]
    fn conductor_matches_the_fresnel_equations() {
        let cases = [(0.2f32, 3.9f32), (1.5, 0.0), (0.05, 10.0), (2.0, 1.0), (1.0, 50.0), (1e-3, 1e3)];
        for &(eta, k) in &cases {
            for i in 0..=64 {
                let ci = i as f32 / 64.0;
                let r = conductor(ci, glam::Vec3::splat(eta), glam::Vec3::splat(k)).x;
                let want = reference(ci as f64, C(eta as f64, k as f64));
                assert!((r as f64 - want).abs() < 1e-3, "eta {eta} k {k} cos {ci}: {r} want {want}");
                assert_eq!(r, conductor(-ci, glam::Vec3::splat(eta), glam::Vec3::splat(k)).x);
            }
        }
        // Grazing: a mirror; huge k: a mirror too, finite.
        assert_eq!(conductor(0.0, glam::Vec3::splat(0.2), glam::Vec3::splat(3.0)).x, 1.0);
        let r = conductor(0.5, glam::Vec3::splat(1.0), glam::Vec3::splat(1e6)).x;
        assert!(r.is_finite() && r > 0.99, "{r}");
    }
}

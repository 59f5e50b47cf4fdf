//! [`Material`] and [`Material8`] (their types in `material_types.rs`): the diffuse term plus the specular lobe of each material under the
//! format's strategies, evaluated and sampled in the local shading frame (see the `bsdf` module docs).
//! The specular lobes come from a [`LobeSet`]; scalar code and the `eval_pdf`/`sample` entry points
//! use [`AllLobes`], kernels the set compiled for the scene (`*_k::<L>`).

use super::interface::{self, BsdfSet, Sample8};
use super::lobe::{AllLobes, LobeSet};
use super::mask::{self, Mask};
use super::material_types::{Material, Material8, Sampled8};
use super::Bsdf as _;
use super::{diffuse, ImportanceSampling};
use crate::sampling::{fmadd, sample_uniform_hemisphere, sample_uniform_hemisphere_x8};
use crate::sampling::{uniform_hemisphere_pdf, uniform_hemisphere_pdf_x8};
use crate::simd::{and_mask, Mask8, Vec3x8, F8};
use glam::Vec3;

impl Material {
    /// f(wo, wi) (RGB, per steradian) and the pdf of wi per unit solid angle under `strategy`; local
    /// shading frame. What an NEE/MIS light sample needs in one call.
    #[inline]
    pub fn eval_pdf(&self, strategy: ImportanceSampling, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (fs, ps) = AllLobes::eval_pdf(self, wo, wi);
        let f = if wo.z > 0.0 && wi.z > 0.0 { diffuse::eval_plus(self.kd, fs) } else { Vec3::ZERO };
        let pdf = match strategy {
            ImportanceSampling::Hemisphere => uniform_hemisphere_pdf(wi),
            ImportanceSampling::Cosine => diffuse::pdf(wi),
            ImportanceSampling::Brdf => {
                let t = self.specular_probability();
                fmadd(t, ps, (1.0 - t) * diffuse::pdf(wi))
            }
        };
        (f, pdf)
    }

    /// f(wo, wi), RGB per steradian, local shading frame (0 unless both are above the horizon).
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.eval_pdf(ImportanceSampling::Hemisphere, wo, wi).0
    }

    /// Density per unit solid angle with which `sample(strategy, wo, ..)` draws wi; local shading frame.
    #[inline]
    pub fn pdf(&self, strategy: ImportanceSampling, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_pdf(strategy, wo, wi).1
    }

    /// Draws wi for `strategy` from u in [0,1]^2 and, for the BRDF mixture, `u_lobe` in [0,1) picking
    /// the lobe; returns (wi, pdf per unit solid angle, f(wo, wi) RGB), local shading frame. wi is a
    /// finite unit vector; pdf 0 marks a sample to drop; f is 0 below the horizon.
    #[inline]
    pub fn sample(&self, strategy: ImportanceSampling, wo: Vec3, u: [f32; 2], u_lobe: f32) -> (Vec3, f32, Vec3) {
        let wi = match strategy {
            ImportanceSampling::Hemisphere => sample_uniform_hemisphere(u).0,
            ImportanceSampling::Cosine => diffuse::sample(u),
            ImportanceSampling::Brdf if u_lobe < self.specular_probability() => {
                AllLobes::sample(self, wo, u).unwrap_or_else(|| diffuse::sample(u))
            }
            ImportanceSampling::Brdf => diffuse::sample(u),
        };
        let (f, pdf) = self.eval_pdf(strategy, wo, wi);
        (wi, pdf, f)
    }
}

impl Material8 {
    /// Eight-lane [`Material::eval_pdf`].
    #[inline]
    pub fn eval_pdf(&self, strategy: ImportanceSampling, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        self.eval_pdf_k::<AllLobes>(strategy, wo, wi, active)
    }

    /// [`Material8::eval_pdf`] compiled for the lobe set `L` a scene has: bit-identical to it on
    /// lanes that satisfy the [`super::Lobes`] promise of `L`. Only the lobes present among the active
    /// lanes are evaluated. Masked lanes (opacity below 1, kernels with [`Mask`] only) scale both
    /// by their opacity (`bsdf::mask`).
    #[inline]
    pub fn eval_pdf_k<L: LobeSet>(
        &self,
        strategy: ImportanceSampling,
        wo: Vec3x8,
        wi: Vec3x8,
        active: Mask8,
    ) -> (Vec3x8, F8) {
        let r = self.eval_pdf_nested_k::<L>(strategy, wo, wi, active);
        if Self::masks::<L>() {
            let masked = self.masked(active);
            if masked.any() {
                return mask::eval_pdf_x8(self.bsdf.opacity, masked, r);
            }
        }
        r
    }

    /// Whether kernels of `L` compile masks in.
    #[inline(always)]
    fn masks<L: LobeSet>() -> bool {
        <L::Bsdfs as BsdfSet>::BITS & interface::bit(Mask::ID) != 0
    }

    /// The `active` lanes whose opacity is below 1.
    #[inline]
    fn masked(&self, active: Mask8) -> Mask8 {
        active & self.bsdf.opacity.simd_lt(F8::ONE)
    }

    /// [`Material8::eval_pdf_k`] without the mask: the nested BSDF of every lane.
    #[inline(always)]
    fn eval_pdf_nested_k<L: LobeSet>(
        &self,
        strategy: ImportanceSampling,
        wo: Vec3x8,
        wi: Vec3x8,
        active: Mask8,
    ) -> (Vec3x8, F8) {
        let (fs, ps) = L::eval_pdf_x8(self, wo, wi, active, (Vec3x8::ZERO, F8::ZERO));
        let up = active & wo.z.simd_gt(F8::ZERO) & wi.z.simd_gt(F8::ZERO);
        let f = Vec3x8::select(up, diffuse::eval_plus_x8(self.kd, fs), Vec3x8::ZERO);
        let pdf = match strategy {
            ImportanceSampling::Hemisphere => uniform_hemisphere_pdf_x8(wi, active),
            ImportanceSampling::Cosine => diffuse::pdf_x8(wi, active),
            ImportanceSampling::Brdf => {
                let t = self.specular_probability();
                and_mask(t.mul_add(ps, (F8::ONE - t) * diffuse::pdf_x8(wi, active)), active)
            }
        };
        if <L::Bsdfs as BsdfSet>::BITS != 0 {
            let general = self.general(active);
            let (f, pdf) = if general.any() {
                let (fb, pb) = interface::eval_pdf_x8::<L::Bsdfs>(&self.bsdf, self.back, wo, wi, general);
                (Vec3x8::select(general, fb, f), general.select(pb, pdf))
            } else {
                (f, pdf)
            };
            if let Some(m) = &self.frame_map {
                let k = m.factor(wi);
                return (f.scale(k), k.simd_gt(F8::ZERO).select(pdf, F8::ZERO));
            }
            return (f, pdf);
        }
        (f, pdf)
    }

    /// [`Material8::sample_k`] with the registry BSDFs of `L`: course lanes as `sample_k` (under
    /// `strategy`), the others through the BSDF interface (their own sampling, `u_lobe` picking the
    /// lobe; `strategy` does not apply). Masked lanes (kernels with [`Mask`] only) first choose
    /// between the nested BSDF and the null lobe by `u_lobe` (`bsdf::mask`: the null lanes come
    /// back as `general` lanes with the null sample; the nested ones with the nested sample, its
    /// pdf not scaled by the opacity, as Mitsuba's).
    #[inline(always)]
    pub fn sample_bsdf_k<L: LobeSet>(
        &self,
        strategy: ImportanceSampling,
        wo: Vec3x8,
        u: [F8; 2],
        u_lobe: F8,
        active: Mask8,
    ) -> Sampled8 {
        if Self::masks::<L>() {
            let masked = self.masked(active);
            if masked.any() {
                return self.sample_masked_k::<L>(strategy, wo, u, u_lobe, active, masked);
            }
        }
        self.sample_nested_k::<L>(strategy, wo, u, u_lobe, active)
    }

    /// [`Material8::sample_bsdf_k`] on a packet with `masked` lanes (out of line: scenes with
    /// masks only).
    #[inline(never)]
    fn sample_masked_k<L: LobeSet>(
        &self,
        strategy: ImportanceSampling,
        wo: Vec3x8,
        u: [F8; 2],
        u_lobe: F8,
        active: Mask8,
        masked: Mask8,
    ) -> Sampled8 {
        let opacity = self.bsdf.opacity;
        let (nested, u_lobe) = mask::choose_x8(opacity, masked, u_lobe);
        let mut s = self.sample_nested_k::<L>(strategy, wo, u, u_lobe, active & nested);
        // A nested sample's pdf is the masked one, opacity x nested (what `eval_pdf_k` gives and
        // next events weigh against, as Mitsuba's `mask`); f with it on the course lanes, so that
        // f cos / pdf (and the interface's weight) stay the nested BSDF's.
        let o = (masked & nested).select(opacity, F8::ONE);
        (s.f, s.pdf, s.bsdf.pdf) = (s.f.scale(o), s.pdf * o, s.bsdf.pdf * o);
        let null = active & !nested;
        s.bsdf = mask::sample_x8(opacity, null, wo, s.bsdf);
        s.wi = Vec3x8::select(null, s.bsdf.wi, s.wi);
        s.pdf = null.select(s.bsdf.pdf, s.pdf);
        s.f = Vec3x8::select(null, Vec3x8::ZERO, s.f);
        s.general |= null;
        s
    }

    /// [`Material8::sample_bsdf_k`] without the mask: the nested BSDF of every lane.
    #[inline(always)]
    fn sample_nested_k<L: LobeSet>(
        &self,
        strategy: ImportanceSampling,
        wo: Vec3x8,
        u: [F8; 2],
        u_lobe: F8,
        active: Mask8,
    ) -> Sampled8 {
        let (wi, pdf, f) = self.sample_k::<L>(strategy, wo, u, u_lobe, active);
        let mut s = Sampled8 { wi, pdf, f, general: F8::ZERO, bsdf: Sample8::NONE };
        if <L::Bsdfs as BsdfSet>::BITS != 0 {
            let general = self.general(active);
            if general.any() {
                let mut b = interface::sample_x8::<L::Bsdfs>(&self.bsdf, self.back, wo, u_lobe, u, general);
                if let Some(m) = &self.frame_map {
                    let k = m.factor(b.wi);
                    b.weight = b.weight.scale(k);
                    b.pdf = k.simd_gt(F8::ZERO).select(b.pdf, F8::ZERO);
                }
                s.wi = Vec3x8::select(general, b.wi, s.wi);
                s.pdf = general.select(b.pdf, s.pdf);
                s.general = general;
                s.bsdf = b;
            }
        }
        s
    }

    /// Eight-lane [`Material::eval`].
    #[inline]
    pub fn eval(&self, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> Vec3x8 {
        self.eval_pdf(ImportanceSampling::Hemisphere, wo, wi, active).0
    }

    /// Eight-lane [`Material::pdf`].
    #[inline]
    pub fn pdf(&self, strategy: ImportanceSampling, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> F8 {
        self.eval_pdf(strategy, wo, wi, active).1
    }

    /// Eight-lane [`Material::sample`]: (wi, pdf, f) per lane.
    #[inline]
    pub fn sample(
        &self,
        strategy: ImportanceSampling,
        wo: Vec3x8,
        u: [F8; 2],
        u_lobe: F8,
        active: Mask8,
    ) -> (Vec3x8, F8, Vec3x8) {
        self.sample_k::<AllLobes>(strategy, wo, u, u_lobe, active)
    }

    /// [`Material8::sample`] compiled for the lobe set `L` a scene has: bit-identical to it on lanes
    /// that satisfy the [`super::Lobes`] promise of `L`. The course lanes' nested material: a mask
    /// is applied by [`Material8::sample_bsdf_k`].
    #[inline(always)]
    pub fn sample_k<L: LobeSet>(
        &self,
        strategy: ImportanceSampling,
        wo: Vec3x8,
        u: [F8; 2],
        u_lobe: F8,
        active: Mask8,
    ) -> (Vec3x8, F8, Vec3x8) {
        let wi = match strategy {
            ImportanceSampling::Hemisphere => sample_uniform_hemisphere_x8(u, active).0,
            ImportanceSampling::Cosine => diffuse::sample_x8(u, active),
            ImportanceSampling::Brdf => {
                let spec = active & u_lobe.simd_lt(self.specular_probability());
                L::sample_x8(self, wo, u, spec, diffuse::sample_x8(u, active & !spec))
            }
        };
        let (f, pdf) = self.eval_pdf_nested_k::<L>(strategy, wo, wi, active);
        (wi, pdf, f)
    }
}

#[cfg(test)]
mod frame_map_tests {
    //! The normal/bump map terms ([`FrameMap8`]): the shadowing factor's range and limits, and a
    //! white furnace through a perturbed frame (no energy gain, no NaN) for the course's diffuse
    //! and an anisotropic rough mirror, grazing viewers and tilts up to 85 degrees included.

    use super::*;
    use crate::bsdf::interface::Params8;
    use crate::bsdf::microfacet::Distribution;
    use crate::bsdf::FrameMap8;
    use crate::sampling::chi2::Rng;
    use crate::simd::mask_all;

    fn factor(base: Vec3, a2: f32, wi: Vec3) -> f32 {
        FrameMap8 { base: Vec3x8::splat(base), a2: F8::splat(a2) }.factor(Vec3x8::splat(wi)).as_array()[0]
    }

    #[test]
    fn the_shadowing_factor_is_in_0_1_and_finite() {
        // No map (base = +z, a2 = 0): exactly 1 above, 0 below and at the horizon.
        assert_eq!(factor(Vec3::Z, 0.0, Vec3::new(0.6, 0.0, 0.8)), 1.0);
        assert_eq!(factor(Vec3::Z, 0.0, Vec3::new(1.0, 0.0, 0.0)), 0.0);
        // On different sides of the two normals: 0.
        let base = Vec3::new(0.8, 0.0, 0.6);
        assert_eq!(factor(base, 0.1, Vec3::new(-0.9, 0.0, 0.1).normalize()), 0.0);
        // Grazing to the unperturbed normal: tends to 0, finite; along it: 1.
        for a2 in [1e-6, 0.07, 1.0] {
            let g = factor(base, a2, Vec3::new(-0.6 + 1e-7, 0.0, 0.8).normalize());
            assert!(g.is_finite() && (0.0..=1.0).contains(&g), "{g}");
            assert_eq!(factor(base, a2, base), 1.0);
        }
        // Estevez et al.: a2 = 1/8 tan^2, G = 2 / (1 + sqrt(1 + a2 tan^2 wi)).
        let wi = Vec3::new(0.0, 0.6, 0.8);
        let tan2 = 0.36 / 0.64;
        assert!((factor(Vec3::Z, 0.5, wi) - 2.0 / (1.0 + (1.0f32 + 0.5 * tan2).sqrt())).abs() < 1e-6);
    }

    /// Mean and standard error of the sampled weight at `wo` for the material `m` of every lane.
    fn furnace(m: &Material8, wo: Vec3, rng: &mut Rng) -> (f64, f64) {
        let (mut sum, mut sum2, n) = (0.0f64, 0.0f64, 4096);
        for _ in 0..n / 8 {
            let u = [F8::new(std::array::from_fn(|_| rng.f32())), F8::new(std::array::from_fn(|_| rng.f32()))];
            let ul = F8::new(std::array::from_fn(|_| rng.f32()));
            let wo8 = Vec3x8::splat(wo);
            let s = m.sample_bsdf_k::<AllLobes>(ImportanceSampling::Cosine, wo8, u, ul, mask_all());
            let course = s.f.scale(s.wi.z / s.pdf);
            let w = Vec3x8::select(s.general, s.bsdf.weight, course);
            for i in 0..8 {
                let ok = s.pdf.as_array()[i] > 0.0;
                let x = if ok { w.lane(i).x as f64 } else { 0.0 };
                assert!(x.is_finite() && x >= 0.0, "wo {wo}: weight {x}");
                sum += x;
                sum2 += x * x;
            }
        }
        let mean = sum / n as f64;
        (mean, ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt())
    }

    #[test]
    fn a_perturbed_frame_gains_no_energy_and_makes_no_nan() {
        let mut rng = Rng::new(7);
        let mirror =
            crate::bsdf::roughconductor::params(Distribution::Ggx, 0.01, 1.0, true, Vec3::ZERO, Vec3::ZERO, Vec3::ONE);
        for bsdf in [Params8::COURSE, Params8::splat(&mirror)] {
            for tilt in [0.0f32, 20.0, 60.0, 85.0] {
                let t = tilt.to_radians();
                // The unperturbed normal in the perturbed frame, and the map's alpha^2.
                let base = Vec3::new(t.sin(), 0.0, t.cos());
                let a2 = (0.125 * t.tan() * t.tan()).min(1.0);
                let m = Material8 {
                    kd: Vec3x8::splat(Vec3::ONE),
                    ks: Vec3x8::ZERO,
                    shininess: F8::ONE,
                    alpha: F8::ONE,
                    ggx: F8::ZERO,
                    bsdf,
                    back: F8::ZERO,
                    frame_map: Some(FrameMap8 { base: Vec3x8::splat(base), a2: F8::splat(a2) }),
                };
                for (theta, phi) in [(0.0f32, 0.0f32), (45.0, 1.0), (80.0, 3.0), (89.9, 0.5), (89.999, 2.0)] {
                    let (th, ph) = (theta.to_radians(), phi);
                    let wo = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                    let (mean, se) = furnace(&m, wo, &mut rng);
                    assert!(mean <= 1.0 + 4.0 * se + 1e-6, "tilt {tilt}, wo {wo}: albedo {mean} +- {se}");
                }
            }
        }
    }
}

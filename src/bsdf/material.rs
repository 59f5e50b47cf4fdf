//! [`Material`] and [`Material8`] (their types in `material_types.rs`): the diffuse term plus the specular lobe of each material under the
//! format's strategies, evaluated and sampled in the local shading frame (see the `bsdf` module docs).
//! The specular lobes come from a [`LobeSet`]; scalar code and the `eval_pdf`/`sample` entry points
//! use [`AllLobes`], kernels the set compiled for the scene (`*_k::<L>`).

use super::interface::{self, BsdfSet, Sample8};
use super::lobe::{AllLobes, LobeSet};
use super::material_types::{Material, Material8, Sampled8};
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
    /// lanes are evaluated.
    #[inline]
    pub fn eval_pdf_k<L: LobeSet>(
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
            if general.any() {
                let (fb, pb) = interface::eval_pdf_x8::<L::Bsdfs>(&self.bsdf, self.back, wo, wi, general);
                return (Vec3x8::select(general, fb, f), general.select(pb, pdf));
            }
        }
        (f, pdf)
    }

    /// [`Material8::sample_k`] with the registry BSDFs of `L`: course lanes as `sample_k` (under
    /// `strategy`), the others through the BSDF interface (their own sampling, `u_lobe` picking the
    /// lobe; `strategy` does not apply).
    #[inline]
    pub fn sample_bsdf_k<L: LobeSet>(
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
                let b = interface::sample_x8::<L::Bsdfs>(&self.bsdf, self.back, wo, u_lobe, u, general);
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
    /// that satisfy the [`super::Lobes`] promise of `L`.
    #[inline]
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
        let (f, pdf) = self.eval_pdf_k::<L>(strategy, wo, wi, active);
        (wi, pdf, f)
    }
}

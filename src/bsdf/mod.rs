//! The format's BRDFs (FORMAT.md, "Materials"): modified Phong and GGX with Smith G and Schlick F, each
//! plus a Lambertian kd/pi, evaluated and importance-sampled in the local shading frame. Scalar
//! [`Material`] and eight-lane [`Material8`] mirror each other line by line.
//!
//! Conventions:
//! - Local shading frame, normal +z. `wo` points to the viewer, `wi` to the light or the sampled
//!   direction; both unit, both away from the surface. f is the BRDF value (RGB, per steradian, without
//!   the cosine); pdfs are per unit solid angle of wi.
//! - One-sided: f = 0 unless wo.z > 0 and wi.z > 0 (a caller wanting two-sided shading flips the frame).
//! - The pdf is the strategy's own density over the whole sphere. Directions below the horizon that a
//!   strategy can produce (the Phong lobe around a grazing mirror direction, a GGX reflection about a
//!   tilted half vector) keep their nonzero pdf and get f = 0: the estimate f cos/pdf is 0 there, the
//!   pdf integrates to 1, and the pdf of a light sample below the horizon is what the BRDF sampler
//!   would have had, as MIS requires.
//! - `importancesampling brdf`: the specular lobe is picked with probability t = avg(ks) / (avg(kd) +
//!   avg(ks)) (0 for a black material), for GGX t = max(0.25, t), the cosine lobe otherwise;
//!   pdf = t pdf_spec + (1 - t) pdf_cos. `hemisphere` and `cosine` use the plain warps.
//! - `sample` returns `eval_pdf` of the direction it drew, so its pdf equals `pdf(wo, wi)` bit for bit.
//! - x8: per-lane materials (kd, ks, shininess, alpha and a GGX mask), one strategy per packet,
//!   `active: Mask8` last; inactive lanes get zero f, pdf and direction.

mod ggx;
mod phong;
#[cfg(test)]
mod tests;

pub use crate::scene::desc::{BrdfKind, ImportanceSampling};

use crate::sampling::{
    cosine_hemisphere_pdf, cosine_hemisphere_pdf_x8, fmadd, mul_add3, sample_cosine_hemisphere,
    sample_cosine_hemisphere_x8, sample_uniform_hemisphere, sample_uniform_hemisphere_x8, uniform_hemisphere_pdf,
    uniform_hemisphere_pdf_x8,
};
use crate::simd::{and_mask, Mask8, Vec3x8, F8};
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

/// BRDF parameters of one surface: RGB reflectances kd (diffuse) and ks (specular), Phong exponent
/// `shininess`, GGX `alpha` (used as is, clamped below at `sampling::GGX_ALPHA_MIN`), and the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// diffuse reflectance kd
    pub kd: Vec3,
    /// specular reflectance ks (Phong lobe weight, GGX Fresnel at normal incidence)
    pub ks: Vec3,
    /// Phong exponent s >= 0
    pub shininess: f32,
    /// GGX roughness alpha
    pub alpha: f32,
    /// BRDF model
    pub kind: BrdfKind,
}

impl From<&crate::scene::desc::Material> for Material {
    fn from(m: &crate::scene::desc::Material) -> Self {
        Self { kd: m.diffuse, ks: m.specular, shininess: m.shininess, alpha: m.roughness, kind: m.brdf }
    }
}

impl Material {
    /// Probability t of picking the specular lobe under `importancesampling brdf` (see module docs).
    #[inline]
    pub fn specular_probability(&self) -> f32 {
        let (d, s) = (self.kd.x + self.kd.y + self.kd.z, self.ks.x + self.ks.y + self.ks.z);
        let t = if d + s > 0.0 { s / (d + s) } else { 0.0 };
        if self.kind == BrdfKind::Ggx {
            t.max(0.25)
        } else {
            t
        }
    }

    /// Specular term of f (RGB, before the horizon test) and the density of the specular sampler at
    /// wi, both in the local shading frame.
    #[inline]
    fn lobe(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        match self.kind {
            BrdfKind::Phong => phong::lobe(wo, wi, self.ks, self.shininess),
            BrdfKind::Ggx => ggx::lobe(wo, wi, self.ks, self.alpha),
        }
    }

    /// f(wo, wi) (RGB, per steradian) and the pdf of wi per unit solid angle under `strategy`; local
    /// shading frame. What an NEE/MIS light sample needs in one call.
    #[inline]
    pub fn eval_pdf(&self, strategy: ImportanceSampling, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (fs, ps) = self.lobe(wo, wi);
        let f = if wo.z > 0.0 && wi.z > 0.0 { mul_add3(self.kd, FRAC_1_PI, fs) } else { Vec3::ZERO };
        let pdf = match strategy {
            ImportanceSampling::Hemisphere => uniform_hemisphere_pdf(wi),
            ImportanceSampling::Cosine => cosine_hemisphere_pdf(wi),
            ImportanceSampling::Brdf => {
                let t = self.specular_probability();
                fmadd(t, ps, (1.0 - t) * cosine_hemisphere_pdf(wi))
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
            ImportanceSampling::Cosine => sample_cosine_hemisphere(u).0,
            ImportanceSampling::Brdf if u_lobe < self.specular_probability() => match self.kind {
                BrdfKind::Phong => phong::sample(wo, u, self.shininess),
                BrdfKind::Ggx => ggx::sample(wo, u, self.alpha),
            },
            ImportanceSampling::Brdf => sample_cosine_hemisphere(u).0,
        };
        let (f, pdf) = self.eval_pdf(strategy, wo, wi);
        (wi, pdf, f)
    }
}

/// Eight materials, one per lane, in the local shading frame of each lane: kd, ks (RGB), shininess,
/// alpha, and `ggx` set in the lanes whose model is GGX (the others are Phong).
#[derive(Clone, Copy, Debug)]
pub struct Material8 {
    /// diffuse reflectance kd per lane
    pub kd: Vec3x8,
    /// specular reflectance ks per lane
    pub ks: Vec3x8,
    /// Phong exponent per lane
    pub shininess: F8,
    /// GGX alpha per lane
    pub alpha: F8,
    /// lanes using GGX (all-ones) rather than Phong (all-zeros)
    pub ggx: Mask8,
}

impl Material8 {
    /// Gathers eight scalar materials into lanes.
    pub fn from_lanes(m: [Material; 8]) -> Self {
        Self {
            kd: Vec3x8::from_lanes(m.map(|m| m.kd)),
            ks: Vec3x8::from_lanes(m.map(|m| m.ks)),
            shininess: F8::new(m.map(|m| m.shininess)),
            alpha: F8::new(m.map(|m| m.alpha)),
            ggx: crate::simd::mask_from_bools(m.map(|m| m.kind == BrdfKind::Ggx)),
        }
    }

    /// Eight-lane [`Material::specular_probability`].
    #[inline]
    pub fn specular_probability(&self) -> F8 {
        let (d, s) = (self.kd.x + self.kd.y + self.kd.z, self.ks.x + self.ks.y + self.ks.z);
        let t = (d + s).simd_gt(F8::ZERO).select(s / (d + s), F8::ZERO);
        self.ggx.select(t.max(F8::splat(0.25)), t)
    }

    /// Eight-lane `Material::lobe`: only the models present among the active lanes are evaluated,
    /// and only those a kernel compiled in (`PHONG`, `GGX`; see [`Lobes`]).
    #[inline]
    fn lobe<const PHONG: bool, const GGX: bool>(&self, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        let (ph, gg) = (active & !self.ggx, active & self.ggx);
        let (mut f, mut p) = (Vec3x8::ZERO, F8::ZERO);
        if PHONG && ph.any() {
            let (fp, pp) = phong::lobe_x8(wo, wi, self.ks, self.shininess);
            (f, p) = (Vec3x8::select(ph, fp, f), ph.select(pp, p));
        }
        if GGX && gg.any() {
            let (fg, pg) = ggx::lobe_x8(wo, wi, self.ks, self.alpha);
            (f, p) = (Vec3x8::select(gg, fg, f), gg.select(pg, p));
        }
        (f, p)
    }

    /// Eight-lane [`Material::eval_pdf`].
    #[inline]
    pub fn eval_pdf(&self, strategy: ImportanceSampling, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        self.eval_pdf_k::<true, true>(strategy, wo, wi, active)
    }

    /// [`Material8::eval_pdf`] compiled for the lobes a scene has: bit-identical to it on lanes that
    /// satisfy the [`Lobes`] promise of `PHONG` and `GGX`.
    #[inline]
    pub fn eval_pdf_k<const PHONG: bool, const GGX: bool>(
        &self,
        strategy: ImportanceSampling,
        wo: Vec3x8,
        wi: Vec3x8,
        active: Mask8,
    ) -> (Vec3x8, F8) {
        let (fs, ps) = self.lobe::<PHONG, GGX>(wo, wi, active);
        let up = active & wo.z.simd_gt(F8::ZERO) & wi.z.simd_gt(F8::ZERO);
        let f = Vec3x8::select(up, self.kd.mul_add(F8::FRAC_1_PI, fs), Vec3x8::ZERO);
        let pdf = match strategy {
            ImportanceSampling::Hemisphere => uniform_hemisphere_pdf_x8(wi, active),
            ImportanceSampling::Cosine => cosine_hemisphere_pdf_x8(wi, active),
            ImportanceSampling::Brdf => {
                let t = self.specular_probability();
                and_mask(t.mul_add(ps, (F8::ONE - t) * cosine_hemisphere_pdf_x8(wi, active)), active)
            }
        };
        (f, pdf)
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
        self.sample_k::<true, true>(strategy, wo, u, u_lobe, active)
    }

    /// [`Material8::sample`] compiled for the lobes a scene has: bit-identical to it on lanes that
    /// satisfy the [`Lobes`] promise of `PHONG` and `GGX`.
    #[inline]
    pub fn sample_k<const PHONG: bool, const GGX: bool>(
        &self,
        strategy: ImportanceSampling,
        wo: Vec3x8,
        u: [F8; 2],
        u_lobe: F8,
        active: Mask8,
    ) -> (Vec3x8, F8, Vec3x8) {
        let wi = match strategy {
            ImportanceSampling::Hemisphere => sample_uniform_hemisphere_x8(u, active).0,
            ImportanceSampling::Cosine => sample_cosine_hemisphere_x8(u, active).0,
            ImportanceSampling::Brdf => {
                let spec = active & u_lobe.simd_lt(self.specular_probability());
                let (ph, gg) = (spec & !self.ggx, spec & self.ggx);
                let mut wi = sample_cosine_hemisphere_x8(u, active & !spec).0;
                if PHONG && ph.any() {
                    wi = Vec3x8::select(ph, phong::sample_x8(wo, u, self.shininess, ph), wi);
                }
                if GGX && gg.any() {
                    wi = Vec3x8::select(gg, ggx::sample_x8(wo, u, self.alpha, gg), wi);
                }
                wi
            }
        };
        let (f, pdf) = self.eval_pdf_k::<PHONG, GGX>(strategy, wo, wi, active);
        (wi, pdf, f)
    }
}

/// The specular lobes a scene's materials have, decided at load time; kernels are compiled for
/// them (`Material8::*_k::<PHONG, GGX>`).
///
/// The promise a kernel relies on: with `phong == false` every Phong material has ks = 0 (its lobe
/// is exactly zero and is never picked by BRDF sampling, since t = 0); with `ggx == false` no
/// material is GGX. Under that promise the compiled-out lobes change nothing, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lobes {
    /// some Phong material has a nonzero ks
    pub phong: bool,
    /// some material is GGX (whose Fresnel makes a lobe even with ks = 0)
    pub ggx: bool,
}

impl Lobes {
    /// Every lobe compiled in: the general kernel, right for any scene.
    pub const ALL: Self = Self { phong: true, ggx: true };

    /// The lobes of a set of materials.
    pub fn of<'a>(materials: impl IntoIterator<Item = &'a crate::scene::desc::Material>) -> Self {
        materials.into_iter().fold(Self { phong: false, ggx: false }, |l, m| match m.brdf {
            BrdfKind::Ggx => Self { ggx: true, ..l },
            BrdfKind::Phong if m.specular != glam::Vec3::ZERO => Self { phong: true, ..l },
            BrdfKind::Phong => l,
        })
    }
}

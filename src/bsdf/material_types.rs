//! The material types of the course's lanes: [`Material`] (one surface) and [`Material8`] (eight
//! lanes, course and registry BSDFs in one packet), [`Sampled8`], and what needs no lobe
//! (`specular_probability`, the registry lanes, a normal or bump map's [`FrameMap8`]). Their evaluation and sampling over a lobe set are
//! in `material.rs`, above the lobes (`lobe.rs`), which take these types.

use super::interface::{Params8, Sample8, COURSE};
use super::BrdfKind;
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;

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
    /// the registry BSDF of each lane ([`interface::COURSE`] lanes use the fields above)
    pub bsdf: Params8,
    /// lanes hit from the back of the surface (the frame faces the viewer; one-sided BSDFs are
    /// evaluated in the surface's own frame, see [`interface::flip_to_surface`])
    pub back: Mask8,
    /// the terms of a normal or bump map around the lanes' BSDFs (`None`: no lane has one; read
    /// only by kernels with registry BSDFs, which scenes with such maps run)
    pub frame_map: Option<FrameMap8>,
}

/// What Mitsuba 3's `normalmap` and `bumpmap` wrappers add to the BSDF they wrap, whose local
/// frame is already the perturbed one: a direction must leave on the same side of the
/// unperturbed shading normal as of the perturbed one (else f = 0, pdf = 0), and f (and a
/// sample's weight) is scaled by the shadowing term of Estevez et al. 2019 ("A Microfacet-Based
/// Shadowing Function to Solve the Bump Terminator Problem"), `2 / (1 + sqrt(1 + a2 tan^2))` with
/// `tan` the tangent of wi's angle to the unperturbed normal and `a2 = min(tan^2(perturbed normal) /
/// 8, 1)`. Lanes without a map have `base` = +z and `a2` = 0: factor 1.
#[derive(Clone, Copy, Debug)]
pub struct FrameMap8 {
    /// the unperturbed shading normal in the local (perturbed) frame
    pub base: Vec3x8,
    /// the shadowing term's alpha^2 (0 on lanes without a map)
    pub a2: F8,
}

impl FrameMap8 {
    /// The factor of f at local direction `wi`: 0 where wi is on different sides of the
    /// perturbed and the unperturbed normal, else the shadowing term (1 where `a2` = 0).
    #[inline]
    pub fn factor(&self, wi: Vec3x8) -> F8 {
        let c = self.base.dot(wi);
        let same_side = (c * wi.z).simd_gt(F8::ZERO);
        let c2 = c * c;
        let tan2 = (F8::ONE - c2).max(F8::ZERO) / c2;
        let g = F8::splat(2.0) / (F8::ONE + (F8::ONE + self.a2 * tan2).sqrt());
        let g = self.a2.simd_gt(F8::ZERO).select(g, F8::ONE);
        same_side.select(g, F8::ZERO)
    }
}

/// [`Material8::sample_bsdf_k`]'s result: the direction, pdf and value of every lane, and on the
/// `general` lanes (registry BSDFs) the interface's [`Sample8`] (weight, lobe flags, eta).
#[derive(Clone, Copy, Debug)]
pub struct Sampled8 {
    /// sampled direction (local frame)
    pub wi: Vec3x8,
    /// solid-angle pdf (delta lobes: the lobe probability, see `general.flags`)
    pub pdf: F8,
    /// f(wo, wi) on the course lanes
    pub f: Vec3x8,
    /// lanes sampled through the BSDF interface: use `bsdf.weight`, not f cos / pdf
    pub general: Mask8,
    /// the interface's sample on the `general` lanes
    pub bsdf: Sample8,
}

impl Material8 {
    /// Gathers eight scalar materials into lanes (the tests' x8-against-scalar checks; a render's
    /// lanes are written by the hit gather, `scene::gather`).
    #[cfg(test)]
    pub fn from_lanes(m: [Material; 8]) -> Self {
        Self {
            kd: Vec3x8::from_lanes(m.map(|m| m.kd)),
            ks: Vec3x8::from_lanes(m.map(|m| m.ks)),
            shininess: F8::new(m.map(|m| m.shininess)),
            alpha: F8::new(m.map(|m| m.alpha)),
            ggx: crate::simd::mask_from_bools(m.map(|m| m.kind == BrdfKind::Ggx)),
            bsdf: Params8::COURSE,
            back: F8::ZERO,
            frame_map: None,
        }
    }

    /// Eight-lane [`Material::specular_probability`].
    #[inline]
    pub fn specular_probability(&self) -> F8 {
        let (d, s) = (self.kd.x + self.kd.y + self.kd.z, self.ks.x + self.ks.y + self.ks.z);
        let t = (d + s).simd_gt(F8::ZERO).select(s / (d + s), F8::ZERO);
        self.ggx.select(t.max(F8::splat(0.25)), t)
    }

    /// The `active` lanes whose BSDF is a registry entry (not the course's material).
    #[inline]
    pub fn general(&self, active: Mask8) -> Mask8 {
        active & !self.bsdf.lanes_of(COURSE)
    }
}

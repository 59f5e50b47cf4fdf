//! Materials: the BSDF interface ([`interface`]: [`Bsdf`], its registry of one file per BSDF
//! listed by `registry!` below, Fresnel terms in [`fresnel`]) and the course's materials, registry
//! id 0: the format's BRDFs (FORMAT.md, "Materials"), modified Phong and GGX with Smith G and
//! Schlick F, each plus a Lambertian kd/pi, evaluated and importance-sampled in the local shading
//! frame. Scalar [`Material`] and eight-lane [`Material8`] mirror each other line by line;
//! [`Material8`] shades course lanes and registry lanes of one packet together
//! (`eval_pdf_k`, `sample_bsdf_k`).
//!
//! The rest of these docs describe the course's materials.
//!
//! Files: [`lobe`] (the [`Lobe`] trait, lobe sets, [`Lobes`]), [`diffuse`] (kd/pi and the cosine
//! sampler), `phong.rs` and `ggx.rs` (one lobe each), [`material`] (the mixture and strategies).
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

pub mod diffuse;
pub mod fresnel;
mod ggx;
pub mod interface;
pub mod lobe;
pub mod material;
pub mod material_types;
pub mod microfacet;
mod phong;
#[cfg(test)]
mod tests;

pub mod desc;
pub use desc::{BrdfKind, ImportanceSampling};
pub use ggx::Ggx;
pub use lobe::{AllLobes, Diffuse, DiffuseGgx, DiffusePhong, Lobe, LobeSet, Lobes};
pub use material_types::{FrameMap8, Material, Material8, Sampled8};
pub use phong::Phong;

/// The BSDF registry: one line per BSDF file (`file: Type,`): declares the module, re-exports the
/// type and appends it to [`AllBsdfs`], the list the general kernel compiles in (and the generic
/// tests of `bsdf/tests.rs` iterate).
macro_rules! registry {
    ($($file:ident: $ty:ident,)*) => {
        $(pub mod $file; pub use $file::$ty;)*
        /// Every registered BSDF (besides the course's materials): the general kernel's set.
        pub type AllBsdfs = registry!(@list $($ty)*);
    };
    (@list) => { () };
    (@list $h:ident $($t:ident)*) => { ($h, registry!(@list $($t)*)) };
}

registry! {
    conductor: Conductor,
    dielectric: Dielectric,
    plastic: Plastic,
    thindielectric: ThinDielectric,
    roughconductor: RoughConductor,
    roughdielectric: RoughDielectric,
    roughplastic: RoughPlastic,
    mask: Mask,
    blendbsdf: BlendBsdf,
    principled: Principled,
    principledthin: PrincipledThin,
}

pub use interface::{Bsdf, BsdfParams, BsdfSet, Params8, Sample8};
#[cfg(test)]
mod registry_tests;

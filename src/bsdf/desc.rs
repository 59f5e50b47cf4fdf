//! The material description as a scene declares it (plain data, re-exported by `scene::desc`),
//! and the direction-sampling strategy: the BSDF layer owns these types so that it imports nothing
//! above it.

use glam::Vec3;

/// `importancesampling hemisphere|cosine|brdf`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ImportanceSampling {
    /// Uniform hemisphere.
    #[default]
    Hemisphere,
    /// Cosine-weighted hemisphere.
    Cosine,
    /// Mixture of the BRDF's lobes.
    Brdf,
}

/// `brdf phong|ggx`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BrdfKind {
    /// Modified Phong.
    #[default]
    Phong,
    /// GGX microfacet with Schlick Fresnel.
    Ggx,
}

/// Material state in force when a primitive was declared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// kd (default 0)
    pub diffuse: Vec3,
    /// ks (default 0)
    pub specular: Vec3,
    /// Phong exponent s (default 1)
    pub shininess: f32,
    /// Emitted radiance added at every hit (default 0)
    pub emission: Vec3,
    /// Ambient term, raytracer only (default 0.2)
    pub ambient: Vec3,
    /// BRDF model (default Phong)
    pub brdf: BrdfKind,
    /// GGX alpha, used as is (default 1)
    pub roughness: f32,
    /// The BSDF of a registry entry other than the course's (`interface::COURSE`: kd, ks, brdf,
    /// shininess and roughness above are the BSDF)
    pub bsdf: super::interface::BsdfParams,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            diffuse: Vec3::ZERO,
            specular: Vec3::ZERO,
            shininess: 1.0,
            emission: Vec3::ZERO,
            ambient: Vec3::splat(0.2),
            brdf: BrdfKind::Phong,
            roughness: 1.0,
            bsdf: super::interface::BsdfParams::COURSE,
        }
    }
}

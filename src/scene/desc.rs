//! The parsed scene: plain data, world space, no Embree. Produced by `scene::parse`, consumed by
//! `scene::build` (which makes the Embree scene and the SoA shading tables).
//!
//! Conventions: right-handed world space; all geometry already transformed to world space except
//! spheres, which keep their object-to-world matrix (a unit sphere at the origin maps to the
//! ellipsoid). Radiance in linear RGB.

pub use crate::bsdf::desc::{BrdfKind, ImportanceSampling, Material};
pub use crate::light::desc::{DeltaLightDesc, EnvironmentDesc, RgbImage};
pub use crate::scene::sensor::{FilmCrop, FovAxis, PixelFilter, Projection, SensorDesc};
use glam::{Mat4, Vec2, Vec3};
use std::path::PathBuf;

/// Which integrator a scene asks for (`integrator` command).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum IntegratorKind {
    /// hw1 Whitted ray tracer (default of the format).
    #[default]
    RayTracer,
    /// Exact polygonal irradiance from quad lights, no visibility.
    AnalyticDirect,
    /// Area-light sampling with shadow rays.
    Direct,
    /// Unidirectional path tracer.
    PathTracer,
    /// Particle tracer: light paths from the emitters splatted onto the film (Mitsuba's
    /// `ptracer`).
    ParticleTracer,
}

/// `nexteventestimation off|on|mis`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Nee {
    /// Count emission at every hit.
    #[default]
    Off,
    /// Sample one light point per vertex; emission only on camera rays.
    On,
    /// Light and BRDF sampling combined with the power heuristic.
    Mis,
}

/// Implements the format's spelling of a keyword enum: `NAMES` (name, value) in the order the
/// format lists them, `name()` and an exact-match `parse()`. The one place these names are spelled.
macro_rules! spelled {
    ($t:ty, $what:literal, [$(($name:literal, $v:ident)),* $(,)?]) => {
        impl $t {
            #[doc = concat!("Every ", $what, " with its name as the format spells it.")]
            pub const NAMES: &'static [(&'static str, $t)] = &[$(($name, <$t>::$v)),*];

            #[doc = concat!("The ", $what, "'s name as the format spells it.")]
            pub fn name(self) -> &'static str {
                match self {
                    $(<$t>::$v => $name),*
                }
            }

            #[doc = concat!("Parses a ", $what, " name (exact spelling).")]
            pub fn parse(s: &str) -> Option<Self> {
                Self::NAMES.iter().find(|(n, _)| *n == s).map(|&(_, v)| v)
            }
        }
    };
}

spelled!(
    IntegratorKind,
    "integrator",
    [
        ("raytracer", RayTracer),
        ("analyticdirect", AnalyticDirect),
        ("direct", Direct),
        ("pathtracer", PathTracer),
        ("ptracer", ParticleTracer)
    ]
);
impl IntegratorKind {
    /// Integrators that trace paths of several bounces with the path layouts (`max_depth`,
    /// roulette): the path tracer and the particle tracer.
    pub fn traces_paths(self) -> bool {
        matches!(self, Self::PathTracer | Self::ParticleTracer)
    }
}

spelled!(Nee, "next event estimation mode", [("off", Off), ("on", On), ("mis", Mis)]);
spelled!(
    ImportanceSampling,
    "direction sampling strategy",
    [("hemisphere", Hemisphere), ("cosine", Cosine), ("brdf", Brdf)]
);

/// Look-at pinhole camera; `fovy_deg` is the full vertical field of view in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDesc {
    /// eye position
    pub eye: Vec3,
    /// look-at point
    pub center: Vec3,
    /// up hint
    pub up: Vec3,
    /// full vertical field of view, degrees
    pub fovy_deg: f32,
}

/// A triangle in world space; geometric normal (v1-v0)x(v2-v0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleDesc {
    /// vertices, world space
    pub v: [Vec3; 3],
    /// index into `SceneDesc::materials`
    pub material: u32,
}

/// A named attribute of the triangles `first..first + count` of `SceneDesc::triangles` (one mesh).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleAttrDesc {
    /// Mitsuba's name with its prefix (`vertex_color`, `face_weight`)
    pub name: String,
    /// values per corner or per face (1 or 3)
    pub dims: u32,
    /// true: `dims` values per corner (3 corners per triangle, in the order of its `v`), to be
    /// interpolated barycentrically; false: `dims` values per triangle
    pub per_corner: bool,
    /// the first triangle
    pub first: u32,
    /// how many triangles
    pub count: u32,
    /// `count * dims` (per face) or `count * 3 * dims` (per corner) values
    pub data: Vec<f32>,
}

/// Mitsuba's `shapegroup`: its triangles in the group's own space, stored once however many
/// [`InstanceDesc`]s place it (each instance is an Embree instance of one shared BVH).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GroupDesc {
    /// the group's `id` in the scene file (an instance finds its group by it)
    pub id: String,
    /// triangles, group space
    pub triangles: Vec<TriangleDesc>,
    /// per-corner unit shading normals of `triangles[i]` (group space), as
    /// `SceneDesc::triangle_normals`
    pub triangle_normals: Vec<[Vec3; 3]>,
    /// per-corner texture coordinates of `triangles[i]`, as `SceneDesc::triangle_uvs`
    pub triangle_uvs: Vec<[Vec2; 3]>,
    /// the group's spheres (group-space object-to-group map, material): each instance places a
    /// copy in `SceneDesc::spheres` (one matrix each, so nothing to share)
    pub spheres: Vec<(glam::Mat4, u32)>,
}

/// Mitsuba's `instance`: the group `SceneDesc::groups[group]` placed by `to_world`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InstanceDesc {
    /// index into `SceneDesc::groups`
    pub group: u32,
    /// group space to world space (affine, invertible)
    pub to_world: glam::Mat4,
}

/// A unit sphere at the origin mapped by `object_to_world` (= M * T(c) * S(r)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereDesc {
    /// object-to-world affine matrix
    pub object_to_world: Mat4,
    /// index into `SceneDesc::materials`
    pub material: u32,
}

/// A sphere light: the sphere `sphere` (an index into `SceneDesc::spheres`, which places and
/// shades it) with Mitsuba's one-sided `area` emitter of `radiance` on its outside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissiveSphereDesc {
    /// index into `SceneDesc::spheres` (its object-to-world map is a similarity)
    pub sphere: u32,
    /// centre, world space
    pub center: Vec3,
    /// radius, world space
    pub radius: f32,
    /// emitted radiance
    pub radiance: Vec3,
}

/// Parallelogram light a + u ab + v ac; one-sided radiance towards normalize(ac x ab).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadLightDesc {
    /// corner
    pub a: Vec3,
    /// first edge
    pub ab: Vec3,
    /// second edge
    pub ac: Vec3,
    /// emitted radiance
    pub radiance: Vec3,
}

/// An emissive triangle (an OBJ face whose MTL material has a non-zero `Ke`), world space: an area
/// light emitting `radiance` one-sided towards (v1-v0)x(v2-v0), black otherwise (like a quad light).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissiveTriangleDesc {
    /// vertices, world space
    pub v: [Vec3; 3],
    /// emitted radiance (the MTL `Ke`)
    pub radiance: Vec3,
}

/// Point light (raytracer only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLightDesc {
    /// world position (transformed by the current matrix when declared)
    pub position: Vec3,
    /// intensity
    pub color: Vec3,
    /// attenuation (c0, c1, c2) in force when declared
    pub attenuation: Vec3,
}

/// Directional light (raytracer only); `direction` points towards the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLightDesc {
    /// unit direction towards the light, world space
    pub direction: Vec3,
    /// radiance scale
    pub color: Vec3,
}

/// Everything a `.test` file says.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneDesc {
    /// file it came from (for messages)
    pub source: PathBuf,
    /// other files read to make it (an OBJ's MTL libraries): inputs no output may replace
    pub inputs: Vec<PathBuf>,
    /// image width in pixels
    pub width: u32,
    /// image height in pixels
    pub height: u32,
    /// `output` name, if given
    pub output: Option<String>,
    /// camera, if given
    pub camera: Option<CameraDesc>,
    /// samples per pixel (default 1)
    pub spp: u32,
    /// display gamma for 8-bit output (default 1)
    pub gamma: f32,
    /// integrator (default raytracer)
    pub integrator: IntegratorKind,
    /// max depth (default 5; -1 = unbounded)
    pub max_depth: i32,
    /// light samples per light for `direct` (default 1)
    pub light_samples: u32,
    /// `direct`: BSDF samples per shading point, combined with the light samples by MIS
    /// (Mitsuba's `bsdf_samples`; default 0: `.test` and OBJ scenes sample the lights alone).
    /// Hashed only when not 0.
    pub bsdf_samples: u32,
    /// `direct`: whether it samples the emitters at all (false: Mitsuba's `emitter_samples` 0,
    /// BSDF sampling alone; `light_samples` then stays 1). Hashed only when off.
    pub emitter_sampling: bool,
    /// `lightstratify on`
    pub light_stratify: bool,
    /// `lightselection all|uniform|power|spatial` (a strata extension; None: the session's default,
    /// `--light-selection` overrides it)
    pub light_selection: Option<crate::light::select::LightSelection>,
    /// next event estimation
    pub nee: Nee,
    /// Russian roulette
    pub russian_roulette: bool,
    /// the first path vertex (1: the camera hit) after which Russian roulette is played, when on
    /// (Mitsuba's `rr_depth`; 1 in `.test` scenes; hashed only when not 1)
    pub rr_depth: u32,
    /// Mitsuba's `hide_emitters`: camera rays see no emitter (area lights, emissive materials and
    /// the environment are black where a camera ray meets them; their light still reaches other
    /// surfaces). Hashed only when set.
    pub hide_emitters: bool,
    /// direction sampling of the path tracer
    pub importance_sampling: ImportanceSampling,
    /// distinct materials, referenced by index
    pub materials: Vec<Material>,
    /// triangles, world space
    pub triangles: Vec<TriangleDesc>,
    /// per-corner unit shading normals (OBJ `vn`, world space) of `triangles[i]` at index i, in
    /// the corner order of its `v`; `[Vec3::ZERO; 3]` or a missing entry (the table may be shorter
    /// than `triangles`, and is empty when no triangle has normals) means none: faceted shading
    pub triangle_normals: Vec<[Vec3; 3]>,
    /// per-corner texture coordinates of `triangles[i]` at index i, in the corner order of its `v`
    /// (Mitsuba meshes' uvs, `scene::mesh`); the table may be shorter than `triangles` and is empty
    /// when no triangle has uvs: a missing entry or `[Vec2::ZERO; 3]` means none (the uv is then
    /// the hit's barycentrics `(b1, b2)`, as Mitsuba gives a mesh without uvs)
    pub triangle_uvs: Vec<[Vec2; 3]>,
    /// named per-vertex or per-face attributes over runs of `triangles` (Mitsuba's
    /// `vertex_color`, `face_weight`, ...; read by the `mesh_attribute` texture); empty: none
    pub triangle_attrs: Vec<TriangleAttrDesc>,
    /// textures (`crate::texture`: Mitsuba's `bitmap`, `checkerboard`, ...), referenced by index
    /// from `diffuse_textures`; empty: none
    pub textures: Vec<crate::texture::Texture>,
    /// per material index: the texture that gives its diffuse reflectance (kd) at hits, or None
    /// (the table may be shorter than `materials`; empty: no textured material). The material's
    /// own `diffuse` should still be a representative nonzero value (e.g. the texture's mean):
    /// only hits read the texture
    pub diffuse_textures: Vec<Option<u32>>,
    /// per material index: the textures that give BSDF parameters at hits (a slot of the
    /// material's `bsdf` row and the texture's index; the row keeps a representative value). The
    /// table may be shorter than `materials`; empty: none
    pub param_textures: Vec<Vec<(crate::bsdf::interface::Slot, u32)>>,
    /// per material index: its shading-frame perturbation (Mitsuba's `normalmap` or `bumpmap`
    /// around it), or None (the table may be shorter than `materials`; empty: none)
    pub material_frames: Vec<Option<FrameMap>>,
    /// shapegroups' triangles, stored once each (placed only by `instances`); empty: none
    pub groups: Vec<GroupDesc>,
    /// instances of `groups` (Embree instances at build); empty: none
    pub instances: Vec<InstanceDesc>,
    /// spheres / ellipsoids
    pub spheres: Vec<SphereDesc>,
    /// quad area lights (not transformed by the stack)
    pub quad_lights: Vec<QuadLightDesc>,
    /// emissive triangles (area lights from OBJ faces with `Ke`)
    pub emissive_triangles: Vec<EmissiveTriangleDesc>,
    /// sphere lights (Mitsuba spheres with an `area` emitter; their spheres are in `spheres`)
    pub emissive_spheres: Vec<EmissiveSphereDesc>,
    /// materials black from behind (indices into `materials`): Mitsuba's one-sided `diffuse`
    /// (not wrapped in `twosided`); empty for `.test` and OBJ scenes, whose materials shade both
    /// sides
    pub one_sided: Vec<u32>,
    /// point lights
    pub point_lights: Vec<PointLightDesc>,
    /// directional lights
    pub directional_lights: Vec<DirectionalLightDesc>,
    /// the light at infinity: `constant` (`--sky`) or `envmap`; None: black background
    pub environment: Option<EnvironmentDesc>,
    /// a Mitsuba sensor; when given it replaces `camera`
    pub sensor: Option<SensorDesc>,
    /// the film's crop window, with a `sensor` only (`width` x `height` is the window)
    pub crop: Option<FilmCrop>,
    /// the pixel filter (box: uniform jitter, every `.test` scene)
    pub filter: PixelFilter,
    /// point, spot, directional and projector lights (Mitsuba's), sampled at every next event
    pub delta_lights: Vec<DeltaLightDesc>,
    /// the material each emissive triangle also reflects with (index into `materials`), by
    /// index; `u32::MAX` or a missing entry (the table may be shorter, and is empty for `.test`
    /// and OBJ scenes): black, emitting only
    pub emissive_materials: Vec<u32>,
    /// the texture of each emissive triangle's radiance (a Mitsuba area emitter with a bitmap
    /// `radiance`), by index: the image (index into `emission_images`) and the triangle's corner
    /// uvs; `u32::MAX` or a missing entry: untextured. Only the particle tracer renders them
    /// (`Scene::build` refuses them for the other integrators)
    pub emissive_textures: Vec<(u32, [glam::Vec2; 3])>,
    /// the images of textured area emitters (linear RGB, Mitsuba's bitmap addressing)
    pub emission_images: Vec<std::sync::Arc<RgbImage>>,
    /// the scene's sampler (a Mitsuba `<sampler>`); None: the session's default. `--sampler`
    /// overrides it
    pub sampler: Option<crate::sampler::SamplerKind>,
}

impl SceneDesc {
    /// FNV-1a digest of everything the scene renders but the image size (a render identity records
    /// that itself): settings, camera, materials, lights and all
    /// geometry, whatever file it came from: `.test`, an included OBJ or its MTL), so that a
    /// checkpoint is refused when any input file changed. Floats enter by their bits.
    pub fn content_hash(&self) -> u64 {
        struct Fnv(u64);
        impl Fnv {
            fn word(&mut self, w: u32) {
                self.0 = (self.0 ^ u64::from(w)).wrapping_mul(0x0000_0100_0000_01b3);
            }
            fn vec3(&mut self, v: Vec3) {
                v.to_array().iter().for_each(|x| self.word(x.to_bits()));
            }
        }
        impl std::fmt::Write for Fnv {
            fn write_str(&mut self, s: &str) -> std::fmt::Result {
                s.bytes().for_each(|b| self.word(u32::from(b)));
                Ok(())
            }
        }
        let mut h = Fnv(0xcbf2_9ce4_8422_2325);
        // Small parts through Debug (f32 Debug round-trips, so distinct values print differently).
        let _ = std::fmt::Write::write_fmt(
            &mut h,
            format_args!(
                "{:?}",
                (
                    (&self.output, &self.camera, self.spp, self.gamma.to_bits()),
                    (
                        self.integrator,
                        self.max_depth,
                        self.light_samples,
                        self.light_stratify,
                        self.nee,
                        self.russian_roulette,
                        self.importance_sampling
                    ),
                    (&self.materials, &self.spheres, &self.quad_lights, &self.point_lights, &self.directional_lights),
                )
            ),
        );
        // Meshes can be large: their bits directly.
        for t in &self.triangles {
            t.v.iter().for_each(|&v| h.vec3(v));
            h.word(t.material);
        }
        for t in &self.emissive_triangles {
            t.v.iter().for_each(|&v| h.vec3(v));
            h.vec3(t.radiance);
        }
        // Only when present, so that the hash of a scene without instances is unchanged.
        for g in &self.groups {
            h.word(0x6772_7000);
            g.triangles.iter().for_each(|t| {
                t.v.iter().for_each(|&v| h.vec3(v));
                h.word(t.material);
            });
            g.triangle_normals.iter().flatten().for_each(|&n| h.vec3(n));
            let _ = std::fmt::Write::write_fmt(&mut h, format_args!("{:?}", (&g.triangle_uvs, &g.spheres)));
        }
        for i in &self.instances {
            let _ = std::fmt::Write::write_fmt(&mut h, format_args!("{:?}", i));
        }
        // Only when present, so that the hash of a scene without a sky is unchanged.
        match &self.environment {
            None => {}
            Some(EnvironmentDesc::Constant(sky)) => {
                h.word(0x736b_7900);
                h.vec3(*sky);
            }
            Some(EnvironmentDesc::Envmap { image, scale, to_world }) => {
                h.word(0x656e_7600);
                let _ = std::fmt::Write::write_fmt(
                    &mut h,
                    format_args!("{:?}", (image.width, image.height, scale, to_world)),
                );
                image.texels.iter().for_each(|&t| h.vec3(t));
            }
        }
        // The Mitsuba-side fields, likewise only when set.
        if self.hide_emitters {
            h.word(0x6869_6465);
        }
        if self.rr_depth != 1 {
            h.word(0x7272_6400);
            h.word(self.rr_depth);
        }
        if self.bsdf_samples != 0 {
            h.word(0x6273_6466);
            h.word(self.bsdf_samples);
        }
        if !self.emitter_sampling {
            h.word(0x656d_6f66);
        }
        if self.sensor.is_some() || self.filter != PixelFilter::Box {
            let _ = std::fmt::Write::write_fmt(&mut h, format_args!("{:?}", (self.sensor, self.filter)));
        }
        if let Some(c) = self.crop {
            let _ = std::fmt::Write::write_fmt(&mut h, format_args!("{c:?}"));
        }
        for l in &self.delta_lights {
            match l {
                DeltaLightDesc::Spot { texture: Some(t), .. } | DeltaLightDesc::Projector { irradiance: t, .. } => {
                    t.texels.iter().for_each(|&t| h.vec3(t));
                }
                _ => {}
            }
            let short = match l {
                DeltaLightDesc::Spot { to_world, intensity, cutoff_deg, beam_width_deg, texture } => {
                    format!(
                        "spot{:?}",
                        (
                            to_world,
                            intensity,
                            cutoff_deg,
                            beam_width_deg,
                            texture.as_ref().map(|t| (t.width, t.height))
                        )
                    )
                }
                DeltaLightDesc::Projector { to_world, irradiance, scale, fov_x_deg } => {
                    format!("projector{:?}", (to_world, irradiance.width, irradiance.height, scale, fov_x_deg))
                }
                other => format!("{other:?}"),
            };
            let _ = std::fmt::Write::write_str(&mut h, &short);
        }
        // Only when present, so that the hash of a scene without normals is unchanged.
        if !self.triangle_normals.is_empty() {
            h.word(self.triangle_normals.len() as u32);
            self.triangle_normals.iter().flatten().for_each(|&n| h.vec3(n));
        }
        // Only when present, so that scenes shaded on both sides keep their hash.
        if !self.one_sided.is_empty() {
            h.word(0x6f6e_6500);
            self.one_sided.iter().for_each(|&m| h.word(m));
        }
        // Only when present, so that scenes without sphere lights keep their hash.
        if !self.emissive_spheres.is_empty() {
            h.word(0x7370_6800);
            let _ = std::fmt::Write::write_fmt(&mut h, format_args!("{:?}", self.emissive_spheres));
        }
        // Only when present, so that `.test` and OBJ scenes keep their hash.
        if !self.emissive_materials.is_empty() {
            h.word(0x656d_6d00);
            self.emissive_materials.iter().for_each(|&m| h.word(m));
        }
        if !self.emissive_textures.is_empty() {
            h.word(0x656d_7400);
            for (i, uv) in &self.emissive_textures {
                h.word(*i);
                uv.iter().for_each(|c| h.vec3(c.extend(0.0)));
            }
            for im in &self.emission_images {
                h.word(im.width);
                h.word(im.height);
                im.texels.iter().for_each(|&t| h.vec3(t));
            }
        }
        if let Some(s) = self.sampler {
            h.word(0x736d_7000);
            let _ = std::fmt::Write::write_str(&mut h, s.name());
        }
        // Likewise uvs and attributes (Mitsuba meshes only).
        if !self.triangle_uvs.is_empty() {
            h.word(0x7576_0000);
            h.word(self.triangle_uvs.len() as u32);
            self.triangle_uvs.iter().flatten().for_each(|uv| uv.to_array().iter().for_each(|x| h.word(x.to_bits())));
        }
        for a in &self.triangle_attrs {
            h.word(0x6174_7200);
            let _ = std::fmt::Write::write_str(&mut h, &a.name);
            [a.dims, u32::from(a.per_corner), a.first, a.count, a.data.len() as u32]
                .into_iter()
                .for_each(|w| h.word(w));
            a.data.iter().for_each(|x| h.word(x.to_bits()));
        }
        // Likewise textures (Mitsuba scenes only).
        if !self.textures.is_empty() || !self.diffuse_textures.is_empty() {
            h.word(0x7465_7800);
            h.word(self.textures.len() as u32);
            self.textures.iter().for_each(|t| t.digest(&mut |w| h.word(w)));
            self.diffuse_textures.iter().for_each(|t| h.word(t.unwrap_or(u32::MAX)));
        }
        if self.param_textures.iter().any(|p| !p.is_empty()) {
            h.word(0x7061_7200);
            for (m, params) in self.param_textures.iter().enumerate() {
                for (slot, t) in params {
                    let _ = std::fmt::Write::write_str(&mut h, &format!("{m}:{slot:?}:{t};"));
                }
            }
        }
        // Normal and bump maps (Mitsuba scenes only).
        if !self.material_frames.is_empty() {
            h.word(0x6e6d_6170);
            h.word(self.material_frames.len() as u32);
            for f in &self.material_frames {
                let (kind, texture, scale) = match *f {
                    None => (0, u32::MAX, 0.0),
                    Some(FrameMap::Normal { texture }) => (1, texture, 0.0),
                    Some(FrameMap::Bump { texture, scale }) => (2, texture, scale),
                };
                [kind, texture, f32::to_bits(scale)].into_iter().for_each(|w| h.word(w));
            }
        }
        h.0
    }
}

/// A material's shading-frame perturbation: Mitsuba 3's `normalmap` and `bumpmap` BSDF wrappers
/// (applied at hits, `scene/perturb.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameMap {
    /// tangent-space normals: the texture's raw RGB `t` gives the normal `2 t - 1` in the hit's
    /// shading frame
    Normal {
        /// index in `SceneDesc::textures`
        texture: u32,
    },
    /// a height field: the gradient of the texture's luminance in uv, times `scale`, displaces
    /// the surface along the shading normal
    Bump {
        /// index in `SceneDesc::textures`
        texture: u32,
        /// Mitsuba's `scale` (default 1)
        scale: f32,
    },
}

impl Default for SceneDesc {
    fn default() -> Self {
        Self {
            source: PathBuf::new(),
            inputs: Vec::new(),
            width: 640,
            height: 480,
            output: None,
            camera: None,
            spp: 1,
            gamma: 1.0,
            integrator: IntegratorKind::RayTracer,
            max_depth: 5,
            light_samples: 1,
            bsdf_samples: 0,
            emitter_sampling: true,
            light_stratify: false,
            light_selection: None,
            nee: Nee::Off,
            russian_roulette: false,
            hide_emitters: false,
            rr_depth: 1,
            importance_sampling: ImportanceSampling::Hemisphere,
            materials: Vec::new(),
            triangles: Vec::new(),
            groups: Vec::new(),
            instances: Vec::new(),
            spheres: Vec::new(),
            quad_lights: Vec::new(),
            emissive_triangles: Vec::new(),
            emissive_spheres: Vec::new(),
            one_sided: Vec::new(),
            triangle_normals: Vec::new(),
            triangle_uvs: Vec::new(),
            triangle_attrs: Vec::new(),
            textures: Vec::new(),
            diffuse_textures: Vec::new(),
            param_textures: Vec::new(),
            material_frames: Vec::new(),
            point_lights: Vec::new(),
            directional_lights: Vec::new(),
            environment: None,
            sensor: None,
            crop: None,
            filter: PixelFilter::Box,
            delta_lights: Vec::new(),
            emissive_materials: Vec::new(),
            emissive_textures: Vec::new(),
            emission_images: Vec::new(),
            sampler: None,
        }
    }
}

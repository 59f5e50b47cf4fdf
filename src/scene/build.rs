//! Builds a renderable [`Scene`] from a [`SceneDesc`]: the Embree scene (through `accel`), the
//! shading tables, the lights and the camera (the AoS -> SoA gather of hit records is in `gather.rs`).
//!
//! Conventions: world space; `ng` is the unit geometric normal as declared ((v1-v0)x(v2-v0) for
//! triangles, outward for ellipsoids); shading uses the normal flipped to face the incoming ray
//! (surfaces are shaded two-sided, so meshes of either winding render; lights stay one-sided).
//!
//! Shading normals: a triangle with per-corner normals (`SceneDesc::triangle_normals`, OBJ `vn`)
//! is shaded with `ns = normalize((1-u-v) n0 + u n1 + v n2)` at Embree's barycentrics (u, v),
//! turned to the side of the geometric normal facing the ray (so `vn` are read as directions up to
//! sign, as the two-sided geometric normal is). **Consistency guard:** where the ray arrives from
//! below that shading normal (`ns . wo <= 0`, although above the geometric one), or the
//! interpolation vanishes, the hit falls back to the geometric normal (no bending): a hit is never
//! shaded from the back of its shading frame. The geometric normal `ng` stays in the record for ray
//! offsets and for the side tests of integrators ([`super::gather::SurfaceHit8::smooth`] marks the lanes where
//! the two differ); light emission and facing use the geometric normals of the lights.

use crate::accel::{self, INVALID_ID};
use crate::light::emitters::{Emitter, Emitters};
use crate::scene::desc::{Material, SceneDesc};
use crate::simd::{Vec3x8, F8};
use glam::{Mat3, Mat4, Vec3, Vec4};

pub use super::lens::{Camera, Lens};

/// A renderable scene.
pub struct Scene {
    /// settings and geometry as parsed
    pub desc: SceneDesc,
    /// camera for the image size in `desc`
    pub camera: Camera,
    /// quad lights, then sphere lights (indices `0..lights.len()` of `emitters`)
    pub lights: Vec<Emitter>,
    /// every area light: the quad lights, then the emissive triangles; light selection
    pub emitters: Emitters,
    /// per emitter (index into `emitters.list`; the table may be shorter): its radiance texture,
    /// the image (index into `desc.emission_images`) and corner uvs; empty without textured
    /// emitters (the particle tracer's only)
    pub emitter_textures: Vec<Option<(u32, [glam::Vec2; 3])>>,
    /// the constant environment light (`--sky`, Mitsuba's `constant`), if any
    pub sky: Option<crate::light::sky::Sky>,
    /// the image environment light (Mitsuba's `envmap`), if any
    pub envmap: Option<crate::light::envmap::Envmap>,
    /// point, directional, spot and projector lights, sampled at every next event
    pub delta: Vec<crate::light::delta::DeltaLight>,
    /// materials (desc materials, then one black material per light)
    pub materials: Vec<Material>,
    /// per triangle: material index
    pub tri_material: Vec<u32>,
    /// per triangle: unit geometric normal
    pub tri_normal: Vec<Vec3>,
    /// per scene triangle (Embree's first primitives): its corner shading normals, `[ZERO; 3]` for
    /// none; empty when the scene has none (the desc's `triangle_normals` without the dropped
    /// triangles)
    pub tri_corner_normals: Vec<[Vec3; 3]>,
    /// the scene's textures (`desc.textures`, `mesh_attribute`s bound to `desc.triangle_attrs`)
    pub textures: Vec<crate::texture::Texture>,
    /// per material: the index in `textures` of its diffuse texture or
    /// [`NO_TEXTURE`]; empty when no material is textured (then gather reads
    /// no texture and builds no uv)
    pub material_texture: Vec<u32>,
    /// per material: its textured BSDF parameters (`SceneDesc::param_textures`); empty when no
    /// material has one (then no hit evaluates them); `material_texture` is filled whenever this
    /// is (hits then carry their texture query, [`SurfaceHit8::tex`])
    pub param_textures: Vec<Vec<(crate::bsdf::interface::Slot, u32)>>,
    /// per material: black from behind (`SceneDesc::one_sided`); empty when every material
    /// shades both sides (then gather checks no side)
    pub material_one_sided: Vec<bool>,
    /// some material is a registry BSDF (not the course's): hits then carry material ids and
    /// sides ([`super::gather::SurfaceHit8::material`], [`super::gather::SurfaceHit8::back`]), which only such BSDFs read
    pub registry_bsdfs: bool,
    /// per scene triangle: its corner uvs, `[ZERO; 3]` for none; empty when the scene has no
    /// uvs, or neither a textured material nor tangents
    pub tri_uv: Vec<[glam::Vec2; 3]>,
    /// per scene triangle: its index in `desc.triangles` (`NO_TRIANGLE` for lights); empty when
    /// the scene has neither a textured material nor tangents
    pub tri_source: Vec<u32>,
    /// per material: its normal or bump map (`scene/perturb.rs`); empty when no material has one
    pub material_frame: Vec<Option<crate::scene::desc::FrameMap>>,
    /// hits carry shading tangents ([`SurfaceHit8::s`], Mitsuba's frame from dp/du): scenes with
    /// registry BSDFs (anisotropic roughness turns with the frame) or normal/bump maps
    pub tangents: bool,
    /// the gather runs `Scene::extras` (textures, tangents, maps): some material is textured or
    /// the scene has tangents
    pub hit_extras: bool,
    /// zero-area triangles (scene and emissive) dropped at build: they can be neither hit nor
    /// sampled, and an exact ray through one would get no usable normal
    pub degenerate_dropped: usize,
    /// of [`Scene::degenerate_dropped`], the triangles dropped because their area overflows f32
    /// (finite corners, edges of about 1e19 or more), not because it is zero
    pub overflow_dropped: usize,
    /// what the intersection backend was set to (part of a render's identity)
    pub backend: Backend,
    /// per triangle: light index or u32::MAX
    pub tri_light: Vec<u32>,
    /// per sphere/ellipsoid of the desc: material index
    pub ell_material: Vec<u32>,
    /// per sphere/ellipsoid of the desc: light index (a sphere light) or `INVALID_ID`
    pub ell_light: Vec<u32>,
    /// desc sphere index of each Embree sphere point (primID of [`GEOM_SPHERES`])
    pub sphere_point_index: Vec<u32>,
    /// desc sphere index of each user-geometry ellipsoid (primID of [`GEOM_ELLIPSOIDS`])
    pub ellipsoid_index: Vec<u32>,
    /// per ellipsoid: world-to-object matrix
    pub ell_world_to_object: Vec<Mat4>,
    /// per ellipsoid: normal matrix (inverse transpose of the linear part)
    pub ell_normal: Vec<Mat3>,
    /// radius of the scene's bounding sphere (for offsets)
    pub extent: f32,
    /// Mitsuba's instances: their matrices and their groups' stored triangles (empty: none)
    pub instances: super::instances::Instances,
    /// the Embree scene
    pub accel: accel::Scene,
    _device: accel::Device,
}

/// Errors building a scene.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// Embree refused something.
    #[error("{0}")]
    Accel(#[from] accel::AccelError),
    /// A delta light that cannot be built.
    #[error("{}: {err}", .file.display())]
    Delta {
        /// the scene file
        file: std::path::PathBuf,
        /// what is wrong
        err: crate::light::delta::DeltaLightError,
    },
    /// An environment map that cannot be built.
    #[error("{}: {err}", .file.display())]
    Envmap {
        /// the scene file
        file: std::path::PathBuf,
        /// what is wrong
        err: crate::light::envmap::EnvmapError,
    },
    /// A material names a texture the scene does not have.
    #[error("{}: material {material} names texture {texture}, but the scene has {count}", path.display())]
    TextureIndex {
        /// The scene file.
        path: std::path::PathBuf,
        /// The material index.
        material: usize,
        /// The texture index it names.
        texture: u32,
        /// How many textures the scene has.
        count: usize,
    },
    /// A `mesh_attribute` texture names an attribute no mesh of the scene has.
    #[error("{}: mesh_attribute texture reads \"{name}\", which no mesh has (they have: {have})", path.display())]
    NoAttribute {
        /// The scene file.
        path: std::path::PathBuf,
        /// The attribute's name.
        name: String,
        /// The names the meshes have.
        have: String,
    },
    /// A scene feature the particle tracer does not support.
    #[error("{}: the particle tracer (`ptracer`) does not support {what}; use `path`", file.display())]
    ParticleTracer {
        /// the scene file
        file: std::path::PathBuf,
        /// the feature
        what: &'static str,
    },
    /// An area emitter with a bitmap `radiance` under an integrator other than `ptracer`.
    #[error("{}: a textured area emitter is rendered by the particle tracer (`ptracer`) only, not by `{integrator}`", file.display())]
    TexturedEmitter {
        /// the scene file
        file: std::path::PathBuf,
        /// the integrator asked for
        integrator: &'static str,
    },
    /// The scene has no `camera` command (the scene file).
    #[error("{}: no camera command", .0.display())]
    NoCamera(std::path::PathBuf),
    /// `STRATA_BVH` set to something other than `high` or `medium`.
    #[error("STRATA_BVH={0:?}: expected `high` or `medium` (or unset: by triangle count)")]
    Bvh(String),
    /// `STRATA_GATHER` set to something other than `auto`, `hardware` or `scalar`, or `hardware`
    /// in a build without AVX2.
    #[error("STRATA_GATHER={0:?}: expected `auto`, `hardware` or `scalar`{1}")]
    Gather(String, &'static str),
}

/// A two-way switch in the environment variable `name`: `on` (Some(true)), `off` (Some(false)),
/// unset, empty or one of `auto` (None); any other value (or one that is not Unicode, lossily) is
/// returned as the error.
fn env_switch(name: &str, on: &str, off: &str, auto: &[&str]) -> Result<Option<bool>, String> {
    match std::env::var(name) {
        Ok(v) if v == on => Ok(Some(true)),
        Ok(v) if v == off => Ok(Some(false)),
        Ok(v) if v.is_empty() || auto.contains(&v.as_str()) => Ok(None),
        Ok(v) => Err(v),
        Err(std::env::VarError::NotPresent) => Ok(None),
        Err(std::env::VarError::NotUnicode(v)) => Err(v.to_string_lossy().into_owned()),
    }
}

/// The BVH quality `STRATA_BVH` forces: `high` (true), `medium` (false), unset or empty (None:
/// by triangle count); anything else is refused (before, a misspelling was silently ignored).
pub fn forced_bvh() -> Result<Option<bool>, BuildError> {
    env_switch("STRATA_BVH", "high", "medium", &[]).map_err(BuildError::Bvh)
}

/// How table look-ups run (`accel::gather_u16`; the values are the same either way, only the
/// speed differs) as `STRATA_GATHER` says: `hardware` (Some(true): AVX2's gather), `scalar`
/// (Some(false)), `auto`, empty or unset (None: the gather on AMD CPUs); anything else is refused.
pub fn forced_gather() -> Result<Option<bool>, BuildError> {
    match env_switch("STRATA_GATHER", "hardware", "scalar", &["auto"]) {
        Ok(Some(true)) if !accel::hardware_gather_compiled() => {
            Err(BuildError::Gather("hardware".into(), " (this build has no AVX2: `scalar` or `auto`)"))
        }
        Ok(v) => Ok(v),
        Err(v) => Err(BuildError::Gather(v, "")),
    }
}

/// The intersection backend's settings that can change which hits a ray gets: each one is in a
/// render's identity, so that checkpoints and shards made under different settings never mix.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Backend {
    /// Embree's instruction set (`avx512` on a CPU with it, else `avx2`, unless `STRATA_EMBREE_CONFIG` pins one)
    pub isa: &'static str,
    /// the Embree library's version
    pub embree: String,
    /// the reciprocal approximations its kernels use on this CPU ([`crate::accel::approx_id`]):
    /// `exact` for AVX-512, else a fingerprint of this CPU's `vrcpps`/`vrsqrtps`
    pub approx: String,
    /// `high` or `medium` quality BVH (by triangle count, or `STRATA_BVH`)
    pub bvh: &'static str,
    /// `strata` (the user geometry) or `embree` (`STRATA_SPHERES=embree`: Embree's sphere points)
    pub spheres: &'static str,
}

/// The entry of `Scene::material_texture` of a material without a texture.
pub const NO_TEXTURE: u32 = u32::MAX;

/// A scene's textures (mesh attributes bound) and the texture index of each scene material.
type TexturingTables = (Vec<crate::texture::Texture>, Vec<u32>);

/// The textures of `desc` (mesh attributes bound) and the texture index of each of the
/// `n_materials` scene materials, or `None` when no material is textured.
fn texturing_tables(desc: &SceneDesc, n_materials: usize) -> Result<Option<TexturingTables>, BuildError> {
    use crate::texture::{AttrRun, Texture};
    let textured = desc.diffuse_textures.iter().any(Option::is_some);
    let params = desc.param_textures.iter().any(|p| !p.is_empty());
    if !textured && !params && desc.material_frames.iter().all(Option::is_none) {
        return Ok(None);
    }
    // Only normal or bump maps: the textures without a diffuse texture table (textured BSDF
    // parameters are evaluated where the reflectance textures are, so they need one).
    let mut material_texture = vec![NO_TEXTURE; if textured || params { n_materials } else { 0 }];
    for (m, t) in desc.diffuse_textures.iter().enumerate() {
        let Some(t) = *t else { continue };
        if t as usize >= desc.textures.len() || m >= desc.materials.len() {
            let (path, count) = (desc.source.clone(), desc.textures.len());
            return Err(BuildError::TextureIndex { path, material: m, texture: t, count });
        }
        material_texture[m] = t;
    }
    for (m, p) in desc.param_textures.iter().enumerate() {
        if let Some(&(_, t)) = p.iter().find(|(_, t)| *t as usize >= desc.textures.len()) {
            let (path, count) = (desc.source.clone(), desc.textures.len());
            return Err(BuildError::TextureIndex { path, material: m, texture: t, count });
        }
    }
    for (m, f) in desc.material_frames.iter().enumerate() {
        use crate::scene::desc::FrameMap;
        let t = match *f {
            Some(FrameMap::Normal { texture } | FrameMap::Bump { texture, .. }) => texture,
            None => continue,
        };
        if t as usize >= desc.textures.len() || m >= desc.materials.len() {
            let (path, count) = (desc.source.clone(), desc.textures.len());
            return Err(BuildError::TextureIndex { path, material: m, texture: t, count });
        }
    }
    let runs = || {
        desc.triangle_attrs.iter().map(|a| {
            let run = AttrRun {
                first: a.first,
                count: a.count,
                dims: a.dims,
                per_corner: a.per_corner,
                data: a.data.as_slice().into(),
            };
            (a.name.clone(), run)
        })
    };
    let mut textures = desc.textures.clone();
    for t in &mut textures {
        if let Texture::MeshAttribute(a) = t {
            if a.bind(runs()) == 0 {
                let mut have: Vec<&str> = desc.triangle_attrs.iter().map(|a| a.name.as_str()).collect();
                have.dedup();
                let (path, name) = (desc.source.clone(), a.name.clone());
                return Err(BuildError::NoAttribute { path, name, have: have.join(", ") });
            }
        }
    }
    Ok(Some((textures, material_texture)))
}

/// A triangle without a unit normal: zero area (collinear or repeated corners) or non-finite.
fn is_degenerate(v: &[Vec3; 3]) -> bool {
    (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero() == Vec3::ZERO
}

/// A degenerate triangle with finite corners whose edge cross product is not finite: its area
/// overflows f32 (it is huge, not zero).
fn area_overflows(v: &[Vec3; 3]) -> bool {
    v.iter().all(|p| p.is_finite()) && !(v[1] - v[0]).cross(v[2] - v[0]).is_finite()
}

impl Scene {
    /// Builds the scene. Quad lights become two triangles each, after the scene's triangles, then
    /// come the emissive triangles, then the shapegroups' (group space, `scene::instances`). Zero-area triangles (no unit normal: the cross product of two
    /// edges vanishes or is not finite) of either kind are dropped and counted in
    /// [`Scene::degenerate_dropped`].
    pub fn build(desc: SceneDesc) -> Result<Self, BuildError> {
        if let Some(what) = super::ptracer_check::refusal(&desc) {
            return Err(BuildError::ParticleTracer { file: desc.source.clone(), what });
        }
        let textured = desc.emissive_textures.iter().any(|t| t.0 != u32::MAX);
        if textured && desc.integrator != crate::scene::desc::IntegratorKind::ParticleTracer {
            return Err(BuildError::TexturedEmitter { file: desc.source.clone(), integrator: desc.integrator.name() });
        }
        let mut camera = match (&desc.sensor, desc.camera) {
            (Some(s), _) => match desc.crop {
                Some(c) => Camera::from_sensor(s, c.full_width, c.full_height).cropped(c, desc.width, desc.height),
                None => Camera::from_sensor(s, desc.width, desc.height),
            },
            (None, Some(c)) => Camera::new(&c, desc.width, desc.height),
            (None, None) => return Err(BuildError::NoCamera(desc.source.clone())),
        };
        camera.filter = crate::sampling::filter::FilterWarp::new(desc.filter);
        let mut materials = desc.materials.clone();
        let mut vertices = Vec::with_capacity(desc.triangles.len() * 3 + desc.quad_lights.len() * 4);
        let mut indices = Vec::with_capacity(desc.triangles.len() + desc.quad_lights.len() * 2);
        let mut tri_material = Vec::with_capacity(indices.capacity());
        let mut tri_light = Vec::with_capacity(indices.capacity());
        let mut tri_corner_normals = Vec::new();
        let texturing = texturing_tables(&desc, materials.len() + 1)?;
        let registry_bsdfs = materials
            .iter()
            .any(|m| m.bsdf.kind != crate::bsdf::interface::COURSE || crate::bsdf::mask::masked(&m.bsdf));
        let mut material_frame = desc.material_frames.clone();
        if material_frame.iter().all(Option::is_none) {
            material_frame.clear();
        } else {
            material_frame.resize(materials.len() + 1, None);
        }
        let tangents = registry_bsdfs || !material_frame.is_empty();
        let uvs = texturing.is_some() || tangents;
        let (mut tri_uv, mut tri_source) = (Vec::new(), Vec::new());
        let (mut degenerate_dropped, mut overflow_dropped) = (0, 0);
        for (k, t) in desc.triangles.iter().enumerate() {
            if is_degenerate(&t.v) {
                degenerate_dropped += 1;
                overflow_dropped += usize::from(area_overflows(&t.v));
                continue;
            }
            if !desc.triangle_normals.is_empty() {
                let none = [Vec3::ZERO; 3];
                tri_corner_normals.resize(indices.len(), none);
                tri_corner_normals.push(desc.triangle_normals.get(k).copied().unwrap_or(none));
            }
            if uvs {
                if !desc.triangle_uvs.is_empty() {
                    tri_uv.resize(indices.len(), [glam::Vec2::ZERO; 3]);
                    tri_uv.push(desc.triangle_uvs.get(k).copied().unwrap_or([glam::Vec2::ZERO; 3]));
                }
                tri_source.push(k as u32);
            }
            let base = vertices.len() as u32;
            vertices.extend_from_slice(&t.v);
            indices.push([base, base + 1, base + 2]);
            tri_material.push(t.material);
            tri_light.push(INVALID_ID);
        }
        let mut lights = Vec::with_capacity(desc.quad_lights.len());
        let black = materials.len() as u32;
        materials.push(Material { ambient: Vec3::ZERO, ..Material::default() });
        for (i, q) in desc.quad_lights.iter().enumerate() {
            let light = Emitter::quad(q.a, q.ab, q.ac, q.radiance);
            let base = vertices.len() as u32;
            vertices.extend_from_slice(&light.corners());
            indices.push([base, base + 1, base + 2]);
            indices.push([base, base + 2, base + 3]);
            tri_material.extend([black, black]);
            tri_light.extend([i as u32, i as u32]);
            lights.push(light);
        }
        // Sphere lights after the quads (their spheres are placed with the other spheres).
        let mut ell_light = vec![INVALID_ID; desc.spheres.len()];
        for s in &desc.emissive_spheres {
            if let Some(slot) = ell_light.get_mut(s.sphere as usize) {
                *slot = lights.len() as u32;
                lights.push(Emitter::sphere(s.center, s.radius, s.radiance));
            }
        }
        let mut tri_emitters = Vec::with_capacity(desc.emissive_triangles.len());
        let mut emitter_textures = Vec::new();
        for (k, t) in desc.emissive_triangles.iter().enumerate() {
            let e = Emitter::triangle(t.v, t.radiance);
            if !(e.area > 0.0 && e.area.is_finite()) || is_degenerate(&t.v) {
                degenerate_dropped += 1;
                overflow_dropped += usize::from(area_overflows(&t.v) || e.area == f32::INFINITY);
                continue;
            }
            let base = vertices.len() as u32;
            vertices.extend_from_slice(&t.v);
            indices.push([base, base + 1, base + 2]);
            // A Mitsuba area light also reflects with its shape's BSDF.
            let reflects = desc.emissive_materials.get(k).copied().filter(|&m| (m as usize) < materials.len());
            tri_material.push(reflects.unwrap_or(black));
            tri_light.push((lights.len() + tri_emitters.len()) as u32);
            if textured {
                emitter_textures.resize(lights.len() + tri_emitters.len(), None);
                emitter_textures.push(desc.emissive_textures.get(k).copied().filter(|t| t.0 != u32::MAX));
            }
            tri_emitters.push(e);
        }
        let emitters = Emitters::new(lights.iter().copied(), tri_emitters);
        let mut tri_normal: Vec<Vec3> = indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| vertices[i as usize]);
                (b - a).cross(c - a).normalize_or_zero()
            })
            .collect();
        let ell_o2w: Vec<Mat4> = desc.spheres.iter().map(|s| s.object_to_world).collect();
        let ell_world_to_object: Vec<Mat4> = ell_o2w.iter().map(|m| m.inverse()).collect();
        let ell_normal = ell_world_to_object.iter().map(|m| Mat3::from_mat4(*m).transpose()).collect();
        let ell_material = desc.spheres.iter().map(|s| s.material).collect();

        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        // Zero-area triangles are never hit; a stray one far away must not inflate the extent
        // (and with it every ray offset). Each vertex belongs to one triangle.
        for (t, n) in indices.iter().zip(&tri_normal) {
            if *n == Vec3::ZERO {
                continue;
            }
            for &i in t {
                let v = vertices[i as usize];
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        for m in &ell_o2w {
            let c = m.w_axis.truncate();
            let r = m.x_axis.truncate().length() + m.y_axis.truncate().length() + m.z_axis.truncate().length();
            lo = lo.min(c - Vec3::splat(r));
            hi = hi.max(c + Vec3::splat(r));
        }
        let extent = if lo.x.is_finite() { ((hi - lo).length() * 0.5).max(f32::MIN_POSITIVE) } else { 1.0 };

        // Spheres and ellipsoids go to one Embree user geometry (f32 SIMD with an f64 fallback,
        // `accel::ellipsoid`). With STRATA_SPHERES=embree, spheres under similarity transforms go
        // to Embree's own sphere points instead (for comparisons only): in this Embree 4.4 build
        // they are slower in packets (3x per ray against the sphere alone, `benches/ellipsoid.rs`;
        // hw2/sphere raw 24.6 against 60.9 Mrays/s, hw3/cornellSimple 11.2 against 16.6) and less
        // exact (hit/miss flips on grazing rays and rays from 1e5 radii away, inclusive interval
        // ends: `accel/sphere_points_tests.rs`).
        let embree_spheres = std::env::var("STRATA_SPHERES").is_ok_and(|v| v == "embree");
        let (mut points, mut sphere_point_index, mut ell_user, mut ellipsoid_index) = (vec![], vec![], vec![], vec![]);
        for (i, m) in ell_o2w.iter().enumerate() {
            match as_sphere(m).filter(|_| embree_spheres) {
                Some(p) => {
                    points.push(p);
                    sphere_point_index.push(i as u32);
                }
                None => {
                    ell_user.push(*m);
                    ellipsoid_index.push(i as u32);
                }
            }
        }
        let device = accel::Device::new()?;
        let mut b = accel::SceneBuilder::new(&device)?;
        let high = forced_bvh()?.unwrap_or(indices.len() >= HIGH_QUALITY_MIN_TRIANGLES);
        accel::set_hardware_gather(forced_gather()?);
        if high {
            b.high_quality();
        }
        b.add_triangles(&vertices, &indices)?;
        b.add_spheres(&points)?;
        b.add_ellipsoids(&ell_user)?;
        // Shapegroups: their triangles after every other, in group space, shared by instances.
        let base = indices.len();
        let (instances, groups, ilo, ihi) = super::instances::Instances::build(&desc, base as u32, &mut b)?;
        let n_group = groups.material.len();
        degenerate_dropped += groups.dropped;
        tri_material.extend_from_slice(&groups.material);
        tri_light.resize(base + n_group, INVALID_ID);
        tri_normal.extend_from_slice(&groups.normal);
        if !groups.corner_normals.is_empty() {
            tri_corner_normals.resize(base, [Vec3::ZERO; 3]);
            tri_corner_normals.extend_from_slice(&groups.corner_normals);
        }
        if uvs && !groups.uvs.is_empty() {
            tri_uv.resize(base, [glam::Vec2::ZERO; 3]);
            tri_uv.extend_from_slice(&groups.uvs);
        }
        let extent = if ilo.x.is_finite() {
            let (lo, hi) = if lo.x.is_finite() { (lo.min(ilo), hi.max(ihi)) } else { (ilo, ihi) };
            ((hi - lo).length() * 0.5).max(f32::MIN_POSITIVE)
        } else {
            extent
        };
        let accel = b.commit()?;
        let backend = Backend {
            isa: device.isa(),
            embree: device.version(),
            approx: crate::accel::approx_id(device.isa()),
            bvh: if high { "high" } else { "medium" },
            spheres: if embree_spheres { "embree" } else { "strata" },
        };
        use crate::scene::desc::EnvironmentDesc;
        let sky = match &desc.environment {
            Some(EnvironmentDesc::Constant(l)) => Some(crate::light::sky::Sky::new(*l)),
            _ => None,
        };
        let envmap = match &desc.environment {
            Some(EnvironmentDesc::Envmap { image, scale, to_world }) => Some(
                crate::light::envmap::Envmap::new(image, *scale, *to_world)
                    .map_err(|err| BuildError::Envmap { file: desc.source.clone(), err })?,
            ),
            _ => None,
        };
        let delta = desc
            .delta_lights
            .iter()
            .map(|d| {
                crate::light::delta::DeltaLight::new(d)
                    .map_err(|err| BuildError::Delta { file: desc.source.clone(), err })
            })
            .collect::<Result<Vec<_>, _>>()?;
        if uvs {
            // Light triangles carry no texture coordinates.
            tri_source.resize(indices.len() + n_group, crate::texture::NO_TRIANGLE);
        }
        let (textures, material_texture) = texturing.unwrap_or_default();
        let param_textures = if desc.param_textures.iter().any(|p| !p.is_empty()) {
            let mut t = desc.param_textures.clone();
            t.resize(materials.len(), Vec::new());
            t
        } else {
            Vec::new()
        };
        let hit_extras = !material_texture.is_empty() || tangents;
        let mut material_one_sided = Vec::new();
        if !desc.one_sided.is_empty() {
            material_one_sided = vec![false; materials.len()];
            for &m in &desc.one_sided {
                if let Some(slot) = material_one_sided.get_mut(m as usize) {
                    *slot = true;
                }
            }
        }
        Ok(Self {
            desc,
            camera,
            lights,
            emitters,
            emitter_textures,
            sky,
            envmap,
            delta,
            materials,
            tri_material,
            tri_normal,
            tri_corner_normals,
            textures,
            material_texture,
            param_textures,
            material_one_sided,
            registry_bsdfs,
            tri_uv,
            tri_source,
            material_frame,
            tangents,
            hit_extras,
            degenerate_dropped,
            overflow_dropped,
            backend,
            tri_light,
            ell_material,
            ell_light,
            sphere_point_index,
            ellipsoid_index,
            ell_world_to_object,
            ell_normal,
            extent,
            instances,
            accel,
            _device: device,
        })
    }

    /// Whether next events have anything to sample: area lights, the environment or delta lights.
    pub fn has_nee_lights(&self) -> bool {
        !self.emitters.is_empty() || self.sky.is_some() || self.envmap.is_some() || !self.delta.is_empty()
    }

    /// Offset distance for secondary-ray origins at points `p`: scales with the magnitude of the
    /// coordinates (float spacing) and with the scene extent.
    #[inline]
    pub fn offset_eps(&self, p: Vec3x8) -> F8 {
        let mag = p.x.abs().max(p.y.abs()).max(p.z.abs());
        mag.mul_add(F8::splat(3e-5), F8::splat(self.extent * 1e-5))
    }
}

/// Triangle count from which the Embree scene is built at high quality (spatial splits). On
/// hw4/dragon (100k triangles) high quality traced 1.4% faster in Embree alone (raw rays/s, five
/// interleaved pairs, all faster; instructions +0.1%) for 30-40 ms more build (about 80 -> 115 ms):
/// a gain for any render long enough for that to matter. On the Cornell boxes (tens of triangles)
/// it changes nothing measurable (identical instruction counts), so small scenes keep Embree's
/// medium build, and their images (one golden case, the OBJ Cornell box, would change bits).
/// `STRATA_BVH=high` / `STRATA_BVH=medium` force either (for measurements).
pub const HIGH_QUALITY_MIN_TRIANGLES: usize = 10_000;

/// Centre and radius if the affine map `m` takes the unit sphere to a sphere (its linear part is
/// a rotation times a uniform scale, to 1e-5 relative).
fn as_sphere(m: &Mat4) -> Option<Vec4> {
    let l = Mat3::from_mat4(*m);
    let g = l.transpose() * l; // = r^2 I for a similarity
    let r2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    if r2.is_nan() || r2 <= 0.0 || !r2.is_finite() {
        return None;
    }
    let off = (g - Mat3::from_diagonal(Vec3::splat(r2))).to_cols_array().iter().fold(0f32, |a, v| a.max(v.abs()));
    (off <= 1e-5 * r2).then(|| m.w_axis.truncate().extend(r2.sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn similarity_transforms_are_spheres_others_ellipsoids() {
        let m = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0))
            * Mat4::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.7)
            * Mat4::from_scale(Vec3::splat(0.25));
        let s = as_sphere(&m).unwrap();
        assert!((s - Vec4::new(1.0, 2.0, 3.0, 0.25)).abs().max_element() < 1e-6);
        assert!(as_sphere(&Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0))).is_none());
        assert!(as_sphere(&Mat4::from_scale(Vec3::ZERO)).is_none());
    }
}

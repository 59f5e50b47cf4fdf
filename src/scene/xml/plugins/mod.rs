//! The plugin registry: one line per Mitsuba plugin (`tag`, `type`, what reads it), and the
//! plugins the renderer does not do yet with the reason that names the missing feature. Each
//! plugin file reads its own Mitsuba properties through [`Props`] and writes the scene.

mod area;
mod blendbsdf;
mod bumpmap;
mod conductor;
mod constant;
mod cube;
mod cylinder;
mod dielectric;
mod diffuse;
mod direct;
mod directional;
mod disk;
mod envmap;
mod hdrfilm;
mod instance;
mod integrator_moment;
mod mask;
mod normalmap;
mod obj;
mod orthographic;
mod path;
mod perspective;
mod plastic;
mod ply;
mod point;
mod principled;
mod principledthin;
mod projector;
mod ptracer;
mod rectangle;
mod rfilter_box;
mod rfilter_gaussian;
mod roughconductor;
mod roughdielectric;
mod roughplastic;
mod sampler;
mod sdfgrid;
mod serialized;
mod shapegroup;
mod sphere;
mod spot;
mod tex_bitmap;
mod tex_checkerboard;
mod tex_mesh_attribute;
mod tex_rawconstant;
mod thindielectric;
mod twosided;

use super::doc::{Elem, Loc};
use super::props::{Color, Props};
use super::shape::ShapeOut;
use crate::bsdf::interface::Slot;
use crate::scene::desc::{EnvironmentDesc, FrameMap, Material, RgbImage, SceneDesc};
use crate::scene::error::SceneError;
use crate::scene::limits::Limits;
use glam::Vec3;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// What a plugin makes.
pub enum Run {
    /// writes into the scene (sensor, film, filter, sampler, integrator, top-level emitter)
    Scene(for<'e> fn(&mut Build<'e>, &Props<'e>) -> Result<(), SceneError>),
    /// a surface material
    Bsdf(for<'e> fn(&mut Build<'e>, &Props<'e>) -> Result<Material, SceneError>),
    /// a shape's geometry (placed by the caller with its material and emitter)
    Shape(for<'e> fn(&mut Build<'e>, &Props<'e>) -> Result<ShapeOut, SceneError>),
    /// a texture (of a material's reflectance)
    Texture(for<'e> fn(&mut Build<'e>, &Props<'e>) -> Result<crate::texture::Texture, SceneError>),
    /// an area emitter's radiance
    Area(for<'e> fn(&mut Build<'e>, &Props<'e>) -> Result<AreaEmission, SceneError>),
    /// known to Mitsuba, not rendered yet: the missing feature
    Refused(&'static str),
}

/// One registry entry.
pub struct Plugin {
    /// element tag (`shape`, `bsdf`, ...)
    pub tag: &'static str,
    /// `type` attribute
    pub kind: &'static str,
    /// what reads it
    pub run: Run,
}

const fn refused(tag: &'static str, kind: &'static str, why: &'static str) -> Plugin {
    Plugin { tag, kind, run: Run::Refused(why) }
}

const BSDFS: &str = "needs the BSDFs of issue 30";

/// Every plugin the XML front end knows, one line each.
pub const PLUGINS: &[Plugin] = &[
    perspective::PLUGIN,
    orthographic::PLUGIN,
    hdrfilm::PLUGIN,
    rfilter_box::PLUGIN,
    rfilter_gaussian::PLUGIN,
    sampler::INDEPENDENT,
    sampler::STRATIFIED,
    sampler::MULTIJITTER,
    sampler::LDSAMPLER,
    sampler::SOBOL,
    path::PLUGIN,
    direct::PLUGIN,
    integrator_moment::PLUGIN,
    ptracer::PLUGIN,
    obj::PLUGIN,
    ply::PLUGIN,
    serialized::PLUGIN,
    rectangle::PLUGIN,
    disk::PLUGIN,
    cube::PLUGIN,
    cylinder::PLUGIN,
    sphere::PLUGIN,
    sdfgrid::PLUGIN,
    shapegroup::PLUGIN,
    instance::PLUGIN,
    area::PLUGIN,
    point::PLUGIN,
    spot::PLUGIN,
    directional::PLUGIN,
    projector::PLUGIN,
    constant::PLUGIN,
    envmap::PLUGIN,
    diffuse::PLUGIN,
    twosided::PLUGIN,
    conductor::PLUGIN,
    roughconductor::PLUGIN,
    dielectric::PLUGIN,
    roughdielectric::PLUGIN,
    thindielectric::PLUGIN,
    plastic::PLUGIN,
    roughplastic::PLUGIN,
    mask::PLUGIN,
    blendbsdf::PLUGIN,
    principled::PLUGIN,
    principledthin::PLUGIN,
    bumpmap::PLUGIN,
    normalmap::PLUGIN,
    refused("bsdf", "null", BSDFS),
    tex_bitmap::PLUGIN,
    tex_checkerboard::PLUGIN,
    tex_mesh_attribute::PLUGIN,
    tex_rawconstant::PLUGIN,
];

/// The registry entry of `e` (by tag and type), or a file:line error naming the supported types.
pub fn lookup(e: &Elem) -> Result<&'static Plugin, SceneError> {
    let kind = e.need("type")?;
    if let Some(p) = PLUGINS.iter().find(|p| p.tag == e.tag && p.kind == kind) {
        if let Run::Refused(why) = p.run {
            return Err(e.at.err(format!("{} is not supported yet: it {why}", e.what())));
        }
        return Ok(p);
    }
    let known: Vec<&str> =
        PLUGINS.iter().filter(|p| p.tag == e.tag && !matches!(p.run, Run::Refused(_))).map(|p| p.kind).collect();
    if known.is_empty() {
        return Err(e.at.err(format!("unknown element <{}>", e.tag)));
    }
    Err(e.at.err(format!("unknown {} type \"{kind}\" (supported: {})", e.tag, known.join(", "))))
}

pub use super::shape::AreaEmission;

/// A shape's geometry, its material index and its area emitter (radiance, where declared).
pub type ShapeParts = (ShapeOut, u32, Option<(AreaEmission, Loc)>);

/// The state of one scene's conversion: the scene being filled, warnings, the ids.
pub struct Build<'e> {
    /// the scene
    pub desc: SceneDesc,
    /// `file:line: ...` warnings (unused properties, approximations)
    pub warnings: Vec<String>,
    /// objects declared with `id`
    pub ids: &'e HashMap<String, Elem>,
    /// resource caps
    pub limits: &'e Limits,
    /// `<path>` directories and the scene's, for file names
    pub search: Vec<PathBuf>,
    /// interned materials (by their Debug text: every field, and the texture index)
    materials: HashMap<String, u32>,
    /// textures already built, by the address of their element (a `<ref>`ed texture is one entry)
    textures: HashMap<usize, u32>,
    /// the reflectance texture of the material the last BSDF plugin made, if textured
    pub pending_texture: Option<u32>,
    /// the textured BSDF parameters of the material the last BSDF plugin made
    pub pending_params: Vec<(Slot, u32)>,
    /// the normal or bump map of the material the last BSDF plugin made, if wrapped in one
    pub pending_frame: Option<FrameMap>,
}

impl<'e> Build<'e> {
    /// A conversion into a fresh scene from `source`.
    pub fn new(source: PathBuf, ids: &'e HashMap<String, Elem>, limits: &'e Limits, search: Vec<PathBuf>) -> Self {
        let desc = SceneDesc {
            source,
            width: 768,
            height: 576,
            integrator: crate::scene::desc::IntegratorKind::PathTracer,
            ..SceneDesc::default()
        };
        Self {
            desc,
            warnings: Vec::new(),
            ids,
            limits,
            search,
            materials: HashMap::new(),
            textures: HashMap::new(),
            pending_texture: None,
            pending_params: Vec::new(),
            pending_frame: None,
        }
    }

    /// A file named in the scene, found as Mitsuba's resolver finds it.
    pub fn resolve(&self, name: &str) -> PathBuf {
        super::doc::resolve_in(&self.search, name)
    }

    /// The index of `m` with the reflectance texture `texture`, the textured parameters `params`
    /// and the frame map `frame` in the scene's materials (added once;
    /// `SceneDesc::diffuse_textures`, `param_textures` and `material_frames` stay empty until a
    /// material has one).
    pub fn intern(
        &mut self,
        m: Material,
        texture: Option<u32>,
        params: Vec<(Slot, u32)>,
        frame: Option<FrameMap>,
    ) -> u32 {
        let key = format!("{m:?}|{texture:?}|{params:?}|{frame:?}");
        let n = self.desc.materials.len() as u32;
        let i = *self.materials.entry(key).or_insert_with(|| {
            self.desc.materials.push(m);
            n
        });
        if let Some(t) = texture {
            let slots = &mut self.desc.diffuse_textures;
            slots.resize(slots.len().max(i as usize + 1), None);
            slots[i as usize] = Some(t);
        }
        if !params.is_empty() {
            let slots = &mut self.desc.param_textures;
            slots.resize(slots.len().max(i as usize + 1), Vec::new());
            slots[i as usize] = params;
        }
        if let Some(f) = frame {
            let slots = &mut self.desc.material_frames;
            slots.resize(slots.len().max(i as usize + 1), None);
            slots[i as usize] = Some(f);
        }
        i
    }

    /// A BSDF parameter `slot` given per hit by the texture `t` (a `<texture>` element) of the
    /// material being made; returns the texture's index.
    pub fn texture_param(&mut self, slot: Slot, t: &'e Elem) -> Result<u32, SceneError> {
        let i = self.texture(t)?;
        self.pending_params.retain(|(s, _)| *s != slot);
        self.pending_params.push((slot, i));
        Ok(i)
    }

    /// Colour property `name` of a BSDF where Mitsuba allows a texture: the constant (`default`
    /// when absent), or the mean of a texture that gives the row's `slot` per hit.
    pub fn color_param(&mut self, p: &Props<'e>, name: &str, default: Vec3, slot: Slot) -> Result<Vec3, SceneError> {
        match p.color(name, false)? {
            None => Ok(default),
            Some(Color::Rgb(c)) => Ok(c),
            Some(Color::Texture(t)) => {
                let i = self.texture_param(slot, t)?;
                Ok(self.desc.textures[i as usize].mean())
            }
        }
    }

    /// Float property `name` of a BSDF where Mitsuba allows a texture: the float (`default` when
    /// absent), or the mean luminance of a texture that gives the row's `slot` per hit
    /// (`slot` None: a texture is refused, naming the property).
    pub fn float_param(
        &mut self,
        p: &Props<'e>,
        name: &str,
        default: f32,
        slot: Option<Slot>,
    ) -> Result<f32, SceneError> {
        match p.get(name) {
            Some(t) if t.tag == "texture" => match slot {
                Some(slot) => {
                    let i = self.texture_param(slot, t)?;
                    Ok(crate::texture::luminance(self.desc.textures[i as usize].mean()))
                }
                None => Err(t.at.err(format!("{}: a texture for \"{name}\" is not supported", p.elem.what()))),
            },
            _ => p.float(name, default),
        }
    }

    /// The index in `SceneDesc::textures` of the `<texture>` element `e` (built once per element).
    pub fn texture(&mut self, e: &'e Elem) -> Result<u32, SceneError> {
        let key = e as *const Elem as usize;
        if let Some(&i) = self.textures.get(&key) {
            return Ok(i);
        }
        let p = lookup(e)?;
        let props = Props::new(e, self.ids)?;
        let t = match p.run {
            Run::Texture(f) => f(self, &props)?,
            _ => return Err(e.at.err(format!("{} is not a texture", e.what()))),
        };
        self.warnings.extend(props.unused());
        let i = self.desc.textures.len() as u32;
        self.desc.textures.push(t);
        self.textures.insert(key, i);
        Ok(i)
    }

    /// Runs the plugin of `e` for its effect on the scene (`Run::Scene`), with its unused
    /// properties reported.
    pub fn run_scene(&mut self, e: &'e Elem) -> Result<(), SceneError> {
        let p = lookup(e)?;
        let props = Props::new(e, self.ids)?;
        match p.run {
            Run::Scene(f) => f(self, &props)?,
            _ => return Err(e.at.err(format!("{} cannot appear here", e.what()))),
        }
        self.warnings.extend(props.unused());
        Ok(())
    }

    /// The material of a `<bsdf>` element.
    pub fn bsdf(&mut self, e: &'e Elem) -> Result<Material, SceneError> {
        let p = lookup(e)?;
        let props = Props::new(e, self.ids)?;
        let m = match p.run {
            Run::Bsdf(f) => f(self, &props)?,
            _ => return Err(e.at.err(format!("{} is not a BSDF", e.what()))),
        };
        self.warnings.extend(props.unused());
        Ok(m)
    }

    /// The radiance of an `<emitter>` nested in a shape.
    pub fn area(&mut self, e: &'e Elem) -> Result<AreaEmission, SceneError> {
        let p = lookup(e)?;
        let props = Props::new(e, self.ids)?;
        let r = match p.run {
            Run::Area(f) => f(self, &props)?,
            _ => return Err(e.at.err(format!("{} cannot be attached to a shape (only `area` can)", e.what()))),
        };
        self.warnings.extend(props.unused());
        Ok(r)
    }

    /// A shape: its geometry, material and area emitter, placed in the scene.
    pub fn shape(&mut self, e: &'e Elem) -> Result<(), SceneError> {
        let (out, material, emitter) = self.shape_parts(e)?;
        super::shape::place(&mut self.desc, self.limits, out, material, emitter, &e.at)
    }

    /// A shape's geometry (through its `to_world`), its material index and its area emitter,
    /// with its unused properties reported; not placed.
    pub fn shape_parts(&mut self, e: &'e Elem) -> Result<ShapeParts, SceneError> {
        let p = lookup(e)?;
        let props = Props::new(e, self.ids)?;
        let out = match p.run {
            Run::Shape(f) => f(self, &props)?,
            _ => return Err(e.at.err(format!("{} is not a shape", e.what()))),
        };
        self.pending_texture = None;
        self.pending_params.clear();
        self.pending_frame = None;
        let material = match props.object("bsdf")? {
            Some(b) => self.bsdf(b)?,
            None => diffuse::default_material(),
        };
        let texture = self.pending_texture.take();
        let params = std::mem::take(&mut self.pending_params);
        let frame = self.pending_frame.take();
        let emitter = match props.object("emitter")? {
            Some(em) => Some((self.area(em)?, em.at.clone())),
            None => None,
        };
        props.ignore("id");
        self.warnings.extend(props.unused());
        Ok((out, self.intern(material, texture, params, frame), emitter))
    }

    /// The file named by the plugin's `filename` string, resolved.
    pub fn file(&self, p: &Props) -> Result<PathBuf, SceneError> {
        let name = p
            .string("filename")?
            .ok_or_else(|| p.elem.at.err(format!("{} needs a `filename` string", p.elem.what())))?;
        Ok(self.resolve(name))
    }

    /// An emitter's colour property `name` (rgb, spectrum or float; Mitsuba's default, a
    /// uniform spectrum of 1, when absent).
    pub fn emitter_rgb(&self, p: &Props, name: &str) -> Result<Vec3, SceneError> {
        match p.color(name, true)? {
            Some(Color::Rgb(c)) => Ok(c),
            Some(Color::Texture(t)) => {
                Err(t.at.err(format!("a textured `{name}` is not supported for {}", p.elem.what())))
            }
            None => Ok(super::values::spectrum_default_emitter()),
        }
    }

    /// Sets the scene's one environment emitter.
    pub fn set_environment(&mut self, p: &Props, env: EnvironmentDesc) -> Result<(), SceneError> {
        if self.desc.environment.is_some() {
            return Err(p
                .elem
                .at
                .err("a second environment emitter (constant or envmap) is not supported (Mitsuba allows one)"));
        }
        self.desc.environment = Some(env);
        Ok(())
    }

    /// Decodes an image file for an emitter (8-bit sRGB decoded unless `raw`).
    pub fn load_image(&self, p: &Props, path: &std::path::Path, raw: bool) -> Result<Arc<RgbImage>, SceneError> {
        let opts = crate::texture::BitmapOptions { raw, ..Default::default() };
        let bmp = crate::texture::Bitmap::load(path, &opts, &crate::texture::BitmapLimits::default())
            .map_err(|e| p.elem.at.err(format!("{}: {e}", p.elem.what())))?;
        let texels = bmp.texels().iter().map(|&t| Vec3::from(t)).collect();
        Ok(Arc::new(RgbImage { width: bmp.width(), height: bmp.height(), texels }))
    }

    /// The image of a `<texture type="bitmap">` used by an emitter (`filename`, `raw`; bilinear,
    /// repeat as the emitters look it up).
    pub fn bitmap_image(&mut self, t: &'e Elem) -> Result<Arc<RgbImage>, SceneError> {
        if t.attr("type") != Some("bitmap") {
            return Err(t.at.err(format!("an emitter's texture must be a bitmap, not {}", t.what())));
        }
        let p = Props::new(t, self.ids)?;
        let path = self.file(&p)?;
        let raw = p.bool("raw", false)?;
        if p.string("filter_type")?.is_some_and(|f| f != "bilinear")
            || p.string("wrap_mode")?.is_some_and(|w| w != "repeat")
        {
            return Err(t.at.err("an emitter's bitmap is looked up bilinearly with repeat wrapping; other filter_type/wrap_mode are not supported"));
        }
        p.ignore("id");
        let img = self.load_image(&p, &path, raw)?;
        self.warnings.extend(p.unused());
        Ok(img)
    }

    /// A warning at `at`.
    pub fn warn(&mut self, at: &Loc, message: impl std::fmt::Display) {
        self.warnings.push(format!("{}: {message}", at.show()));
    }
}

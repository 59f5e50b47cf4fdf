//! Parser for the UCSD CSE168 `.test` scene format into a [`SceneDesc`].
//!
//! One command per line, `#` starts a comment, numbers are decimal floats. Geometry is transformed to
//! world space as it is read (spheres keep their object-to-world matrix); `quadLight` ignores the
//! transform stack. Every error carries the file and 1-based line; no input makes the parser panic, and
//! nothing is allocated in proportion to a number written in the file.
//!
//! The files: this one is the driver (lines to commands, the parser state, the command table);
//! `args.rs` splits and checks a command's arguments; `commands.rs` holds the commands that build
//! geometry, cameras and materials.

mod args;
mod commands;
#[cfg(test)]
mod tests;

pub use crate::scene::error::{LineError, SceneError};
pub use crate::scene::limits::{limit_hint, LimitError, Limits};

use crate::scene::desc::*;
use args::{hint, show, Args};
use commands::{non_negative, radiance};
use glam::{DMat4, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// Reads and parses a `.test` file. An unreadable file is an error on line 0.
pub fn parse_file(path: &Path, limits: &Limits) -> Result<SceneDesc, SceneError> {
    let error = |line, message: String| SceneError::new(path, line, message);
    let bytes = crate::scene::limits::read_bounded(path, "scene file", limits.max_file_bytes)
        .map_err(|(line, m)| error(line, m))?;
    let text = std::str::from_utf8(&bytes).map_err(|e| {
        let before = bytes.get(..e.valid_up_to()).unwrap_or_default();
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        error(line, "the file is not valid UTF-8 text".to_string())
    })?;
    parse_str(text, path, limits)
}

/// Parses the text of a `.test` file; `source` names it in errors and in `SceneDesc::source`.
pub fn parse_str(text: &str, source: &Path, limits: &Limits) -> Result<SceneDesc, SceneError> {
    let mut parser = Parser::new(limits, source);
    for (index, raw) in text.split('\n').enumerate() {
        let content = raw.split('#').next().unwrap_or_default();
        let mut tokens = content.split_ascii_whitespace();
        let Some(cmd) = tokens.next() else { continue };
        let args = Args::new(cmd, tokens);
        parser.command(&args).map_err(|e| e.at(source, index + 1))?;
    }
    Ok(parser.desc)
}

/// Every command the format knows (used only to suggest the right spelling).
#[rustfmt::skip]
const COMMANDS: [&str; 34] = [
    "size", "output", "camera", "spp", "gamma", "maxdepth", "maxverts", "vertex", "tri", "sphere",
    "pushTransform", "popTransform", "translate", "rotate", "scale", "diffuse", "specular",
    "shininess", "emission", "ambient", "brdf", "roughness", "quadLight", "point", "directional",
    "attenuation", "integrator", "lightsamples", "lightstratify", "nexteventestimation",
    "russianroulette", "importancesampling", "obj", "lightselection",
];

/// Parser state: the scene so far plus the transform stack, material state and vertex list.
struct Parser<'l> {
    limits: &'l Limits,
    desc: SceneDesc,
    vertices: Vec<Vec3>,
    matrix: DMat4,
    stack: Vec<DMat4>,
    material: Material,
    /// Index of `material` in `desc.materials`, if known (reset whenever the state changes).
    material_index: Option<u32>,
    /// Bit pattern of each material in `desc.materials` -> its index.
    material_lookup: HashMap<[u32; 15], u32>,
    attenuation: Vec3,
}

impl<'l> Parser<'l> {
    fn new(limits: &'l Limits, source: &Path) -> Self {
        Parser {
            limits,
            desc: SceneDesc { source: source.to_path_buf(), ..SceneDesc::default() },
            vertices: Vec::new(),
            matrix: DMat4::IDENTITY,
            stack: Vec::new(),
            material: Material::default(),
            material_index: None,
            material_lookup: HashMap::new(),
            attenuation: Vec3::new(1.0, 0.0, 0.0),
        }
    }

    fn command(&mut self, a: &Args) -> Result<(), LineError> {
        let limits = self.limits;
        let on_off = [("on", true), ("off", false)];
        match a.cmd {
            "size" => self.size(a.ints()?)?,
            "output" => {
                a.expect(1, "file name")?;
                self.desc.output = Some(a.token(0).to_string());
            }
            "camera" => self.camera(a.floats()?)?,
            "spp" => self.desc.spp = a.int_in(1, limits.max_spp.into(), "max_spp")? as u32,
            "gamma" => {
                let [g] = a.floats()?;
                if g <= 0.0 {
                    return Err(format!("gamma must be > 0, got {g}").into());
                }
                self.desc.gamma = g;
            }
            "maxdepth" => self.desc.max_depth = a.int_in(-1, limits.max_depth.into(), "max_depth")? as i32,
            "maxverts" => {
                // A hint only: validated, and used to reserve at most a small amount up front.
                let n = a.int_in(0, i64::MAX, "max_vertices")?;
                let n = usize::try_from(n).unwrap_or(usize::MAX).min(limits.max_vertices);
                self.vertices.reserve(n.min(1 << 16));
            }
            "vertex" => {
                let v = a.floats()?;
                if self.vertices.len() >= limits.max_vertices {
                    let n = limits.max_vertices;
                    return Err(format!("more than {n} vertices ({})", hint("max_vertices")).into());
                }
                self.vertices.push(Vec3::from_array(v));
            }
            "tri" => self.triangle(a.ints()?)?,
            "obj" => {
                a.expect(1, "file name")?;
                self.obj(a.token(0))?
            }
            "sphere" => self.sphere(a.floats()?)?,
            "pushTransform" => {
                a.expect(0, "argument")?;
                if self.stack.len() >= limits.max_transform_depth {
                    let n = limits.max_transform_depth;
                    return Err(format!(
                        "pushTransform nesting exceeds the limit of {n} ({})",
                        hint("max_transform_depth")
                    )
                    .into());
                }
                self.stack.push(self.matrix);
            }
            "popTransform" => {
                a.expect(0, "argument")?;
                self.matrix =
                    self.stack.pop().ok_or("popTransform without a matching pushTransform (the stack is empty)")?;
            }
            "translate" => {
                let t = a.floats()?;
                self.transform(DMat4::from_translation(Vec3::from_array(t).as_dvec3()))?;
            }
            "rotate" => {
                let [x, y, z, degrees] = a.floats()?;
                let axis = Vec3::new(x, y, z).as_dvec3().try_normalize().ok_or("rotate axis must be non-zero")?;
                self.transform(DMat4::from_axis_angle(axis, f64::from(degrees).to_radians()))?;
            }
            "scale" => {
                let s = a.floats()?;
                if s.contains(&0.0) {
                    let [x, y, z] = s;
                    return Err(format!("scale factors must be non-zero (degenerate geometry), got {x} {y} {z}").into());
                }
                self.transform(DMat4::from_scale(Vec3::from_array(s).as_dvec3()))?;
            }
            "diffuse" => self.set_material(Material { diffuse: Vec3::from_array(a.floats()?), ..self.material }),
            "specular" => self.set_material(Material { specular: Vec3::from_array(a.floats()?), ..self.material }),
            "emission" => {
                let [r, g, b] = a.floats()?;
                self.set_material(Material { emission: radiance("emission", r, g, b)?, ..self.material })
            }
            "ambient" => self.set_material(Material { ambient: Vec3::from_array(a.floats()?), ..self.material }),
            "shininess" => self.set_material(Material { shininess: non_negative(a)?, ..self.material }),
            "roughness" => self.set_material(Material { roughness: non_negative(a)?, ..self.material }),
            "brdf" => {
                let brdf = a.keyword(&[("phong", BrdfKind::Phong), ("ggx", BrdfKind::Ggx)])?;
                self.set_material(Material { brdf, ..self.material })
            }
            "quadLight" => self.quad_light(a.floats()?)?,
            "point" => {
                let [x, y, z, r, g, b] = a.floats()?;
                self.count_primitive()?;
                let position = self.to_world(Vec3::new(x, y, z))?;
                let color = radiance("point light colour", r, g, b)?;
                let light = PointLightDesc { position, color, attenuation: self.attenuation };
                self.desc.point_lights.push(light);
            }
            "directional" => {
                let [x, y, z, r, g, b] = a.floats()?;
                self.count_primitive()?;
                let direction = self.matrix.transform_vector3(Vec3::new(x, y, z).as_dvec3());
                let direction = direction.try_normalize().ok_or("directional light direction must be non-zero")?;
                let color = radiance("directional light colour", r, g, b)?;
                let light = DirectionalLightDesc { direction: direction.as_vec3(), color };
                self.desc.directional_lights.push(light);
            }
            "attenuation" => {
                let c = a.floats()?;
                if c.iter().any(|&v| v < 0.0) || c == [0.0; 3] {
                    let [c0, c1, c2] = c;
                    return Err(format!("attenuation expects c0 c1 c2 >= 0, not all zero; got {c0} {c1} {c2}").into());
                }
                self.attenuation = Vec3::from_array(c);
            }
            "integrator" => self.desc.integrator = a.keyword(IntegratorKind::NAMES)?,
            "lightsamples" => {
                let max = limits.max_light_samples.into();
                self.desc.light_samples = a.int_in(1, max, "max_light_samples")? as u32;
            }
            "lightstratify" => self.desc.light_stratify = a.keyword(&on_off)?,
            "lightselection" => {
                let names: Vec<_> = crate::light::select::LightSelection::every().map(|s| (s.name(), s)).collect();
                self.desc.light_selection = Some(a.keyword(&names)?);
            }
            "nexteventestimation" => self.desc.nee = a.keyword(Nee::NAMES)?,
            "russianroulette" => self.desc.russian_roulette = a.keyword(&on_off)?,
            "importancesampling" => self.desc.importance_sampling = a.keyword(ImportanceSampling::NAMES)?,
            other => {
                let mut message = format!("unknown command '{}'", show(other));
                if let Some(known) = COMMANDS.iter().find(|c| c.eq_ignore_ascii_case(other)) {
                    message += &format!(" (did you mean '{known}'?)");
                }
                return Err(message.into());
            }
        }
        Ok(())
    }
}

//! Parser for the UCSD CSE168 `.test` scene format into a [`SceneDesc`].
//!
//! One command per line, `#` starts a comment, numbers are decimal floats. Geometry is transformed to
//! world space as it is read (spheres keep their object-to-world matrix); `quadLight` ignores the
//! transform stack. Every error carries the file and 1-based line; no input makes the parser panic, and
//! nothing is allocated in proportion to a number written in the file.

use crate::scene::desc::*;
use crate::scene::obj;
use glam::{DMat4, DVec3, Vec3};
use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};

/// A scene-file error: file, 1-based line (0 when not tied to a line), and what was expected.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The file being parsed.
    pub file: PathBuf,
    /// 1-based line number; 0 when the error is not tied to a line (e.g. the file cannot be read).
    pub line: usize,
    /// What went wrong and what was expected.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}: {}", self.file.display(), self.message)
        } else {
            write!(f, "{}:{}: {}", self.file.display(), self.line, self.message)
        }
    }
}

impl std::error::Error for SceneError {}

/// Resource caps; `Limits::default()` is what the CLI uses.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Maximum width * height of the image.
    pub max_pixels: u64,
    /// Maximum image width and height.
    pub max_side: u32,
    /// Maximum number of `vertex` lines.
    pub max_vertices: usize,
    /// Maximum number of triangles + spheres + lights.
    pub max_primitives: usize,
    /// Maximum `spp`.
    pub max_spp: u32,
    /// Maximum `maxdepth` (-1, unbounded, is always allowed).
    pub max_depth: i32,
    /// Maximum `lightsamples`.
    pub max_light_samples: u32,
    /// Maximum nesting of `pushTransform`.
    pub max_transform_depth: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_pixels: 1 << 28,
            max_side: 65536,
            max_vertices: 50_000_000,
            max_primitives: 50_000_000,
            max_spp: 1 << 24,
            max_depth: 1_000_000,
            max_light_samples: 1 << 20,
            max_transform_depth: 4096,
        }
    }
}

impl Limits {
    /// Names of the limits, as `--limit NAME=VALUE` spells them (the field names).
    pub const NAMES: [&'static str; 8] = [
        "max_pixels",
        "max_side",
        "max_vertices",
        "max_primitives",
        "max_spp",
        "max_depth",
        "max_light_samples",
        "max_transform_depth",
    ];

    /// Sets one limit from `NAME=VALUE` (the `--limit` flag); VALUE is a non-negative integer that
    /// must fit the field. Errors name the known limits.
    pub fn set(&mut self, assignment: &str) -> Result<(), String> {
        let (name, value) = assignment.split_once('=').ok_or_else(|| {
            format!("--limit `{assignment}`: expected NAME=VALUE, NAME one of {}", Self::NAMES.join(", "))
        })?;
        let (name, value) = (name.trim(), value.trim());
        let v: u64 =
            value.parse().map_err(|_| format!("--limit {name}: expected a non-negative integer, got `{value}`"))?;
        let range = |max: u64| {
            if v <= max {
                Ok(v)
            } else {
                Err(format!("--limit {name}={v}: at most {max}"))
            }
        };
        match name {
            "max_pixels" => self.max_pixels = v,
            "max_side" => self.max_side = range(u32::MAX.into())? as u32,
            "max_vertices" => self.max_vertices = range(usize::MAX as u64)? as usize,
            "max_primitives" => self.max_primitives = range(usize::MAX as u64)? as usize,
            "max_spp" => self.max_spp = range(u32::MAX.into())? as u32,
            "max_depth" => self.max_depth = range(i32::MAX as u64)? as i32,
            "max_light_samples" => self.max_light_samples = range(u32::MAX.into())? as u32,
            "max_transform_depth" => self.max_transform_depth = range(usize::MAX as u64)? as usize,
            _ => return Err(format!("--limit: unknown limit `{name}` (one of {})", Self::NAMES.join(", "))),
        }
        Ok(())
    }
}

/// How to raise a limit: the `--limit` flag with the field's name (`Limits::set`).
pub fn limit_hint(field: &str) -> String {
    format!("raise it with --limit {field}=N")
}

/// Reads and parses a `.test` file. An unreadable file is an error on line 0.
pub fn parse_file(path: &Path, limits: &Limits) -> Result<SceneDesc, SceneError> {
    let error = |line, message| SceneError { file: path.to_path_buf(), line, message };
    let bytes = std::fs::read(path).map_err(|e| error(0, format!("cannot read scene file: {e}")))?;
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
        parser.command(&args).map_err(|message| SceneError { file: source.to_path_buf(), line: index + 1, message })?;
    }
    Ok(parser.desc)
}

/// Every command the format knows (used only to suggest the right spelling).
#[rustfmt::skip]
const COMMANDS: [&str; 33] = [
    "size", "output", "camera", "spp", "gamma", "maxdepth", "maxverts", "vertex", "tri", "sphere",
    "pushTransform", "popTransform", "translate", "rotate", "scale", "diffuse", "specular",
    "shininess", "emission", "ambient", "brdf", "roughness", "quadLight", "point", "directional",
    "attenuation", "integrator", "lightsamples", "lightstratify", "nexteventestimation",
    "russianroulette", "importancesampling", "obj",
];

/// Most arguments any command takes (`quadLight`).
const MAX_ARGS: usize = 12;

/// A token for an error message, shortened so a huge token cannot flood the output.
fn show(token: &str) -> String {
    match token.char_indices().nth(40) {
        Some((cut, _)) => format!("{}...", &token[..cut]),
        None => token.to_string(),
    }
}

/// How to raise a limit (see [`limit_hint`]).
fn hint(field: &str) -> String {
    limit_hint(field)
}

/// One command line split into its command and arguments.
struct Args<'a> {
    cmd: &'a str,
    tokens: [&'a str; MAX_ARGS],
    /// Number of arguments on the line (may exceed `MAX_ARGS`; only the first ones are kept).
    len: usize,
}

impl<'a> Args<'a> {
    fn new(cmd: &'a str, rest: impl Iterator<Item = &'a str>) -> Self {
        let mut args = Args { cmd, tokens: [""; MAX_ARGS], len: 0 };
        for token in rest {
            if let Some(slot) = args.tokens.get_mut(args.len) {
                *slot = token;
            }
            args.len += 1;
        }
        args
    }

    fn token(&self, i: usize) -> &'a str {
        self.tokens.get(i).copied().unwrap_or_default()
    }

    /// Checks that there are exactly `n` arguments; `what` is the singular noun for one of them.
    fn expect(&self, n: usize, what: &str) -> Result<(), String> {
        if self.len == n {
            return Ok(());
        }
        let s = if n == 1 { "" } else { "s" };
        Err(format!("{} expects {n} {what}{s}, got {}", self.cmd, self.len))
    }

    /// Exactly `N` finite numbers.
    fn floats<const N: usize>(&self) -> Result<[f32; N], String> {
        self.expect(N, "number")?;
        let mut out = [0.0; N];
        for (i, slot) in out.iter_mut().enumerate() {
            let token = self.token(i);
            let value: f32 = token
                .parse()
                .map_err(|_| format!("{} argument {}: expected a number, got '{}'", self.cmd, i + 1, show(token)))?;
            if !value.is_finite() {
                return Err(format!("{} argument {}: '{}' is not a finite number", self.cmd, i + 1, show(token)));
            }
            *slot = value;
        }
        Ok(out)
    }

    /// Exactly `N` integers (written as integers or as integral floats such as `2.0` or `1e3`).
    fn ints<const N: usize>(&self) -> Result<[i64; N], String> {
        self.expect(N, "integer")?;
        let mut out = [0; N];
        for (i, slot) in out.iter_mut().enumerate() {
            let token = self.token(i);
            let integral = |v: &f64| v.fract() == 0.0 && v.abs() <= 9.0e15;
            let value =
                token.parse::<i64>().ok().or_else(|| token.parse::<f64>().ok().filter(integral).map(|v| v as i64));
            *slot = value.ok_or_else(|| {
                format!("{} argument {}: expected an integer, got '{}'", self.cmd, i + 1, show(token))
            })?;
        }
        Ok(out)
    }

    /// One integer in `min..=max`; `limit` names the `Limits` field that sets `max`.
    fn int_in(&self, min: i64, max: i64, limit: &str) -> Result<i64, String> {
        let [v] = self.ints()?;
        if v < min {
            Err(format!("{} must be at least {min}, got {v}", self.cmd))
        } else if v > max {
            Err(format!("{} {v} exceeds the limit of {max} ({})", self.cmd, hint(limit)))
        } else {
            Ok(v)
        }
    }

    /// One keyword out of `options` (ASCII case-insensitive).
    fn keyword<T: Copy>(&self, options: &[(&str, T)]) -> Result<T, String> {
        let token = self.token(0);
        match options.iter().find(|(name, _)| name.eq_ignore_ascii_case(token)) {
            Some(&(_, value)) if self.len == 1 => Ok(value),
            _ => {
                let names: Vec<&str> = options.iter().map(|(name, _)| *name).collect();
                let got = if self.len == 1 { format!("'{}'", show(token)) } else { format!("{} arguments", self.len) };
                Err(format!("{} expects one of {}, got {got}", self.cmd, names.join("|")))
            }
        }
    }
}

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

    fn command(&mut self, a: &Args) -> Result<(), String> {
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
                    return Err(format!("gamma must be > 0, got {g}"));
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
                    return Err(format!("more than {n} vertices ({})", hint("max_vertices")));
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
                    ));
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
                    return Err(format!("scale factors must be non-zero (degenerate geometry), got {x} {y} {z}"));
                }
                self.transform(DMat4::from_scale(Vec3::from_array(s).as_dvec3()))?;
            }
            "diffuse" => self.set_material(Material { diffuse: Vec3::from_array(a.floats()?), ..self.material }),
            "specular" => self.set_material(Material { specular: Vec3::from_array(a.floats()?), ..self.material }),
            "emission" => self.set_material(Material { emission: Vec3::from_array(a.floats()?), ..self.material }),
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
                let light = PointLightDesc { position, color: Vec3::new(r, g, b), attenuation: self.attenuation };
                self.desc.point_lights.push(light);
            }
            "directional" => {
                let [x, y, z, r, g, b] = a.floats()?;
                self.count_primitive()?;
                let direction = self.matrix.transform_vector3(Vec3::new(x, y, z).as_dvec3());
                let direction = direction.try_normalize().ok_or("directional light direction must be non-zero")?;
                let light = DirectionalLightDesc { direction: direction.as_vec3(), color: Vec3::new(r, g, b) };
                self.desc.directional_lights.push(light);
            }
            "attenuation" => {
                let c = a.floats()?;
                if c.iter().any(|&v| v < 0.0) || c == [0.0; 3] {
                    let [c0, c1, c2] = c;
                    return Err(format!("attenuation expects c0 c1 c2 >= 0, not all zero; got {c0} {c1} {c2}"));
                }
                self.attenuation = Vec3::from_array(c);
            }
            "integrator" => self.desc.integrator = a.keyword(IntegratorKind::NAMES)?,
            "lightsamples" => {
                let max = limits.max_light_samples.into();
                self.desc.light_samples = a.int_in(1, max, "max_light_samples")? as u32;
            }
            "lightstratify" => self.desc.light_stratify = a.keyword(&on_off)?,
            "nexteventestimation" => self.desc.nee = a.keyword(Nee::NAMES)?,
            "russianroulette" => self.desc.russian_roulette = a.keyword(&on_off)?,
            "importancesampling" => self.desc.importance_sampling = a.keyword(ImportanceSampling::NAMES)?,
            other => {
                let mut message = format!("unknown command '{}'", show(other));
                if let Some(known) = COMMANDS.iter().find(|c| c.eq_ignore_ascii_case(other)) {
                    message += &format!(" (did you mean '{known}'?)");
                }
                return Err(message);
            }
        }
        Ok(())
    }

    fn size(&mut self, [w, h]: [i64; 2]) -> Result<(), String> {
        if w < 1 || h < 1 {
            return Err(format!("size expects positive integers, got {w} {h}"));
        }
        let pixels = w as u128 * h as u128;
        let (max_pixels, max_side) = (self.limits.max_pixels, self.limits.max_side);
        if pixels > u128::from(max_pixels) {
            return Err(format!("image {w}x{h} exceeds the limit of {max_pixels} pixels ({})", hint("max_pixels")));
        }
        let (Ok(width), Ok(height)) = (u32::try_from(w), u32::try_from(h)) else {
            return Err(format!("image {w}x{h} is too large"));
        };
        if width.max(height) > max_side {
            return Err(format!(
                "image {w}x{h} exceeds the limit of {max_side} pixels per side ({})",
                hint("max_side")
            ));
        }
        (self.desc.width, self.desc.height) = (width, height);
        Ok(())
    }

    fn camera(&mut self, c: [f32; 10]) -> Result<(), String> {
        let [ex, ey, ez, cx, cy, cz, ux, uy, uz, fovy_deg] = c;
        let (eye, center, up) = (Vec3::new(ex, ey, ez), Vec3::new(cx, cy, cz), Vec3::new(ux, uy, uz));
        if !(fovy_deg > 0.0 && fovy_deg < 180.0) {
            return Err(format!("camera fovy must be in (0, 180) degrees, got {fovy_deg}"));
        }
        let look = (center.as_dvec3() - eye.as_dvec3()).try_normalize().ok_or("camera eye and centre coincide")?;
        let up_dir = up.as_dvec3().try_normalize().ok_or("camera up vector must be non-zero")?;
        if look.cross(up_dir).length() < 1e-9 {
            return Err("camera up vector is parallel to the viewing direction".to_string());
        }
        self.desc.camera = Some(CameraDesc { eye, center, up, fovy_deg });
        Ok(())
    }

    fn triangle(&mut self, indices: [i64; 3]) -> Result<(), String> {
        let count = self.vertices.len();
        let mut v = [Vec3::ZERO; 3];
        for (slot, &i) in v.iter_mut().zip(&indices) {
            let vertex = usize::try_from(i).ok().and_then(|i| self.vertices.get(i));
            let vertex =
                vertex.ok_or_else(|| format!("tri index {i} out of range ({count} vertices defined so far)"))?;
            *slot = self.to_world(*vertex)?;
        }
        self.count_primitive()?;
        let material = self.material_index()?;
        self.desc.triangles.push(TriangleDesc { v, material });
        Ok(())
    }

    fn sphere(&mut self, [x, y, z, r]: [f32; 4]) -> Result<(), String> {
        if r <= 0.0 {
            return Err(format!("sphere radius must be > 0, got {r}"));
        }
        let m = self.matrix
            * DMat4::from_translation(DVec3::new(x.into(), y.into(), z.into()))
            * DMat4::from_scale(DVec3::splat(r.into()));
        let object_to_world = m.as_mat4();
        if !object_to_world.is_finite()
            || !object_to_world.determinant().is_normal()
            || !object_to_world.inverse().is_finite()
        {
            return Err("sphere transform is degenerate or out of range".to_string());
        }
        self.count_primitive()?;
        let material = self.material_index()?;
        self.desc.spheres.push(SphereDesc { object_to_world, material });
        Ok(())
    }

    fn quad_light(&mut self, q: [f32; 12]) -> Result<(), String> {
        let [ax, ay, az, bx, by, bz, cx, cy, cz, r, g, b] = q;
        let light = QuadLightDesc {
            a: Vec3::new(ax, ay, az),
            ab: Vec3::new(bx, by, bz),
            ac: Vec3::new(cx, cy, cz),
            radiance: Vec3::new(r, g, b),
        };
        let area = light.ab.cross(light.ac).length();
        if !(area > 0.0 && area.is_finite()) {
            return Err(format!("quadLight area |ab x ac| must be positive and finite, got {area}"));
        }
        self.count_primitive()?;
        self.desc.quad_lights.push(light);
        Ok(())
    }

    /// `obj FILE`: the OBJ's faces (path relative to the `.test` file's directory) under the current
    /// transform, with materials by the rule of `scene::obj` (MTL fields where given, the current
    /// material elsewhere; faces with `Ke` become emissive triangles).
    fn obj(&mut self, name: &str) -> Result<(), String> {
        let path = self.desc.source.parent().unwrap_or(Path::new("")).join(name);
        let mesh = obj::load(&path).map_err(|e| format!("obj '{}': {e}", show(name)))?;
        let d = &self.desc;
        let n = d.triangles.len() + d.emissive_triangles.len() + d.spheres.len() + d.quad_lights.len();
        if n + mesh.faces.len() > self.limits.max_primitives {
            let max = self.limits.max_primitives;
            return Err(format!(
                "obj '{}': more than {max} primitives and lights ({})",
                show(name),
                hint("max_primitives")
            ));
        }
        let (matrix, current, lookup) = (self.matrix, self.material, &mut self.material_lookup);
        obj::place(&mesh, &current, |p| to_world(&matrix, p), &mut self.desc, &mut |m, d| {
            intern_material(lookup, d, &m)
        })
        .map_err(|e| format!("obj '{}': {e}", show(name)))
    }

    /// Right-multiplies the current matrix: M <- M * x.
    fn transform(&mut self, x: DMat4) -> Result<(), String> {
        let m = self.matrix * x;
        if !m.is_finite() {
            return Err("the current transform overflows".to_string());
        }
        self.matrix = m;
        Ok(())
    }

    /// A point mapped by the current matrix, checked to stay finite in f32.
    fn to_world(&self, p: Vec3) -> Result<Vec3, String> {
        to_world(&self.matrix, p)
    }

    fn count_primitive(&self) -> Result<(), String> {
        let d = &self.desc;
        let n = d.triangles.len()
            + d.spheres.len()
            + d.quad_lights.len()
            + d.emissive_triangles.len()
            + d.point_lights.len()
            + d.directional_lights.len();
        if n >= self.limits.max_primitives {
            let max = self.limits.max_primitives;
            return Err(format!("more than {max} primitives and lights ({})", hint("max_primitives")));
        }
        Ok(())
    }

    /// Replaces the material state (forgetting its cached index if it changed).
    fn set_material(&mut self, material: Material) {
        if material != self.material {
            self.material = material;
            self.material_index = None;
        }
    }

    /// Index of the current material state in `desc.materials`, adding it if it is new.
    fn material_index(&mut self) -> Result<u32, String> {
        if let Some(i) = self.material_index {
            return Ok(i);
        }
        let index = intern_material(&mut self.material_lookup, &mut self.desc, &self.material)?;
        self.material_index = Some(index);
        Ok(index)
    }
}

/// A point mapped by `matrix`, checked to stay finite in f32.
fn to_world(matrix: &DMat4, p: Vec3) -> Result<Vec3, String> {
    let w = matrix.transform_point3(p.as_dvec3()).as_vec3();
    if w.is_finite() {
        Ok(w)
    } else {
        Err(format!("point {p} is out of range after the current transform"))
    }
}

/// Index of material `m` in `desc.materials` (`lookup` maps bit patterns to indices), adding it if new.
fn intern_material(lookup: &mut HashMap<[u32; 15], u32>, desc: &mut SceneDesc, m: &Material) -> Result<u32, String> {
    let vectors = [m.diffuse, m.specular, m.emission, m.ambient];
    let values = vectors.iter().flat_map(|v| v.to_array()).chain([m.shininess, m.roughness]);
    let mut key = [0u32; 15];
    for (k, v) in key.iter_mut().zip(values) {
        *k = (v + 0.0).to_bits(); // + 0.0 folds -0.0 into 0.0, as PartialEq does
    }
    key[14] = m.brdf as u32;
    Ok(match lookup.get(&key) {
        Some(&i) => i,
        None => {
            let i = u32::try_from(desc.materials.len()).map_err(|_| "too many distinct materials")?;
            desc.materials.push(*m);
            lookup.insert(key, i);
            i
        }
    })
}

/// One number that must be >= 0.
fn non_negative(a: &Args) -> Result<f32, String> {
    let [v] = a.floats()?;
    if v < 0.0 {
        return Err(format!("{} must be >= 0, got {v}", a.cmd));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;

    fn parse(text: &str) -> Result<SceneDesc, SceneError> {
        parse_str(text, Path::new("t.test"), &Limits::default())
    }

    fn parse_ok(text: &str) -> SceneDesc {
        parse(text).unwrap_or_else(|e| panic!("{e}"))
    }

    /// Parses `text`, expects an error on `line` whose message contains every one of `words`.
    fn expect_err(text: &str, line: usize, words: &[&str]) {
        let e = parse(text).expect_err(text);
        assert_eq!(e.line, line, "{e}");
        for w in words {
            assert!(e.message.contains(w), "message {:?} lacks {w:?}", e.message);
        }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5
    }

    /// The corpus folder, or `None` (with a printed reason) when it is absent.
    fn corpus() -> Option<PathBuf> {
        let dir = std::env::var_os("STRATA_CSE168")
            .map(PathBuf::from)
            .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/cse168")));
        if dir.is_dir() {
            Some(dir)
        } else {
            eprintln!("skipping: CSE168 corpus not found at {} (set STRATA_CSE168)", dir.display());
            None
        }
    }

    fn corpus_files(dir: &Path) -> Vec<PathBuf> {
        let mut files = Vec::new();
        for hw in ["hw1", "hw2", "hw3", "hw4"] {
            let Ok(entries) = std::fs::read_dir(dir.join(hw)) else { continue };
            files.extend(entries.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "test")));
        }
        files.sort();
        files
    }

    fn load(dir: &Path, name: &str) -> SceneDesc {
        parse_file(&dir.join(name), &Limits::default()).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn whole_corpus_parses() {
        let Some(dir) = corpus() else { return };
        let files = corpus_files(&dir);
        assert!(files.len() >= 20, "only {} corpus files", files.len());
        for f in &files {
            let d = parse_file(f, &Limits::default()).unwrap_or_else(|e| panic!("{e}"));
            assert!(d.camera.is_some(), "{}: no camera", f.display());
            let n = d.materials.len() as u32;
            assert!(d.triangles.iter().all(|t| t.material < n && t.v.iter().all(|v| v.is_finite())));
            assert!(d.spheres.iter().all(|s| s.material < n && s.object_to_world.is_finite()));
        }
    }

    #[test]
    fn corpus_facts() {
        let Some(dir) = corpus() else { return };
        let d = load(&dir, "hw2/analytic.test");
        assert_eq!((d.quad_lights.len(), d.integrator), (1, IntegratorKind::AnalyticDirect));
        assert_eq!((d.width, d.height), (640, 480));
        assert_eq!(d.camera.map(|c| c.fovy_deg), Some(45.0));
        assert_eq!(d.output.as_deref(), Some("analytic.png"));

        let d = load(&dir, "hw2/dragon.test");
        assert!((99_000..=101_000).contains(&d.triangles.len()), "{}", d.triangles.len());
        assert!(d.materials.len() < 10, "{} materials", d.materials.len());
        assert_eq!((d.light_samples, d.light_stratify, d.max_depth), (25, true, 5));

        let d = load(&dir, "hw4/mis.test");
        let mut ggx: Vec<f32> = d.materials.iter().filter(|m| m.brdf == BrdfKind::Ggx).map(|m| m.roughness).collect();
        ggx.dedup();
        assert_eq!(ggx, [0.0005, 0.008, 0.07, 0.15]);
        assert_eq!((d.nee, d.importance_sampling, d.russian_roulette), (Nee::Mis, ImportanceSampling::Brdf, false));
        assert_eq!((d.spp, d.gamma, d.quad_lights.len()), (32, 2.2, 5));

        let d = load(&dir, "hw4/ggx.test");
        assert_eq!(d.max_depth, -1);
        assert!(d.russian_roulette);

        let d = load(&dir, "hw1/scene6.test");
        assert_eq!(d.point_lights[0].attenuation, Vec3::new(1.0, 0.1, 0.05));
        assert!(close(d.directional_lights[0].direction, Vec3::new(0.0, 1.0, -1.0).normalize()));
    }

    #[test]
    fn corpus_spheres() {
        let Some(dir) = corpus() else { return };
        let centre = |s: &SphereDesc| s.object_to_world.transform_point3(Vec3::ZERO);
        // hw1/scene6: translate 0 -0.7 -1.5; scale 0.1; and an ellipsoid 0.3 x 0.6 x 0.3 at (0.5,-0.5,-2).
        let d = load(&dir, "hw1/scene6.test");
        assert_eq!(d.spheres.len(), 4);
        assert!(close(centre(&d.spheres[0]), Vec3::new(0.0, -0.7, -1.5)));
        assert!(close(d.spheres[0].object_to_world.transform_point3(Vec3::X), Vec3::new(0.1, -0.7, -1.5)));
        let e = d.spheres[3].object_to_world;
        assert!(close(centre(&d.spheres[3]), Vec3::new(0.5, -0.5, -2.0)));
        assert!(close(e.transform_point3(Vec3::Y), Vec3::new(0.5, 0.1, -2.0)));
        // hw1/scene5: nested translates -10 0 0 inside 0 -2 -5, radius 0.4.
        let d = load(&dir, "hw1/scene5.test");
        assert!(close(centre(&d.spheres[0]), Vec3::new(-10.0, -2.0, -5.0)));
        assert!(close(d.spheres[0].object_to_world.transform_point3(Vec3::Z), Vec3::new(-10.0, -2.0, -4.6)));
        // hw2/sphere: sphere 0 -0.25 0 0.5 with no transform.
        let d = load(&dir, "hw2/sphere.test");
        let expected = Mat4::from_translation(Vec3::new(0.0, -0.25, 0.0)) * Mat4::from_scale(Vec3::splat(0.5));
        assert!(d.spheres[0].object_to_world.abs_diff_eq(expected, 1e-6));
    }

    #[test]
    fn cornell_walls_face_into_the_box() {
        let Some(dir) = corpus() else { return };
        let d = load(&dir, "hw2/cornell.test");
        assert_eq!(d.triangles.len(), 22);
        let inside = Vec3::new(0.0, 1.0, 0.0);
        // The first 10 triangles are the five walls; the remaining 12 are a cube, facing outwards.
        for t in &d.triangles[..10] {
            let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
            let centroid = (t.v[0] + t.v[1] + t.v[2]) / 3.0;
            assert!(n.dot(inside - centroid) > 0.0, "{t:?} faces out");
        }
        // The ceiling light emits downwards (towards ac x ab).
        let q = d.quad_lights[0];
        assert!(q.ac.cross(q.ab).y < 0.0);
    }

    #[test]
    fn defaults_comments_and_line_endings() {
        let d = parse_ok("# only comments\r\n\r\n   \t\n size 10 20 # trailing\r\nspp 4#x\n");
        assert_eq!((d.width, d.height, d.spp), (10, 20, 4));
        assert_eq!((d.gamma, d.max_depth, d.integrator), (1.0, 5, IntegratorKind::RayTracer));
        assert_eq!(d.source, Path::new("t.test"));
        let d = parse_ok("size 1e2 2.0\ngamma 2.2\nmaxdepth -1\nlightsamples 9\nbrdf GGX\nvertex .5 -1. +2e0");
        assert_eq!((d.width, d.height, d.max_depth, d.light_samples), (100, 2, -1, 9));
        assert_eq!(parse_ok("").camera, None);
    }

    /// World-space first vertex of the one triangle made after `prefix`, from vertex (1, 0, 0).
    fn transformed_x(prefix: &str) -> Vec3 {
        let d = parse_ok(&format!("vertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\n{prefix}\ntri 0 1 2"));
        d.triangles[0].v[0]
    }

    #[test]
    fn transform_order() {
        assert!(close(transformed_x("translate 1 0 0\nscale 2 2 2"), Vec3::new(3.0, 0.0, 0.0)));
        assert!(close(transformed_x("scale 2 2 2\ntranslate 1 0 0"), Vec3::new(4.0, 0.0, 0.0)));
        assert!(close(transformed_x("rotate 0 1 0 90"), Vec3::new(0.0, 0.0, -1.0)));
        assert!(close(transformed_x("rotate 0 5 0 90"), Vec3::new(0.0, 0.0, -1.0)));
        assert!(close(transformed_x("translate 0 0 1\nrotate 0 0 1 90"), Vec3::new(0.0, 1.0, 1.0)));
        assert!(close(transformed_x("pushTransform\ntranslate 5 0 0\npopTransform"), Vec3::X));
        let nested = "translate 1 0 0\npushTransform\nscale 3 3 3\npushTransform\ntranslate 9 9 9\npopTransform";
        assert!(close(transformed_x(nested), Vec3::new(4.0, 0.0, 0.0)));
        // The transform in force when `tri` is read counts, not when the vertices were listed.
        let d = parse_ok("vertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\ntri 0 1 2\ntranslate 0 0 2\ntri 0 1 2");
        assert_eq!(d.triangles[0].v[0], Vec3::X);
        assert!(close(d.triangles[1].v[0], Vec3::new(1.0, 0.0, 2.0)));
    }

    #[test]
    fn lights_and_spheres_under_transforms() {
        let d = parse_ok(
            "translate 1 2 3\nscale 2 2 2\nattenuation 0 0 1\npoint 1 0 0 1 1 1\ndirectional 0 0 5 1 1 1\n\
             sphere 1 0 0 0.5\nquadLight 0 0 0 1 0 0 0 1 0 1 1 1",
        );
        let p = d.point_lights[0];
        assert!(close(p.position, Vec3::new(3.0, 2.0, 3.0)));
        assert_eq!(p.attenuation, Vec3::Z);
        assert!(close(d.directional_lights[0].direction, Vec3::Z));
        let s = d.spheres[0].object_to_world;
        assert!(close(s.transform_point3(Vec3::ZERO), Vec3::new(3.0, 2.0, 3.0)));
        assert!(close(s.transform_point3(Vec3::X), Vec3::new(4.0, 2.0, 3.0)));
        assert_eq!(d.quad_lights[0].a, Vec3::ZERO); // the stack does not apply to quad lights
        assert_eq!(d.quad_lights[0].ab, Vec3::X);
        // Default attenuation for point lights declared before any `attenuation`.
        assert_eq!(parse_ok("point 0 0 0 1 1 1").point_lights[0].attenuation, Vec3::X);
    }

    #[test]
    fn materials_are_deduplicated() {
        let mut text = String::from("vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n");
        for i in 0..1000 {
            text += if i % 2 == 0 { "diffuse 1 0 0\n" } else { "diffuse 0 1 0\n" };
            text += "tri 0 1 2\nsphere 0 0 0 1\n";
        }
        text += "brdf ggx\nroughness 0.3\ntri 0 1 2\nemission -0 0 0\nbrdf phong\nroughness 1\ntri 0 1 2\n";
        let d = parse_ok(&text);
        assert_eq!(d.materials.len(), 3);
        assert_eq!(d.materials[0], Material { diffuse: Vec3::X, ..Material::default() });
        assert_eq!(d.triangles[1].material, 1);
        assert_eq!(d.spheres[2].material, 0);
        assert_eq!(d.materials[2].roughness, 0.3);
        assert_eq!(d.triangles.last().map(|t| t.material), Some(1));
    }

    #[test]
    fn settings() {
        let d = parse_ok(
            "integrator pathtracer\nnexteventestimation on\nrussianroulette on\nimportancesampling cosine\n\
             lightstratify on\noutput out.png\ncamera 0 0 5 0 0 0 0 1 0 30\nmaxverts 1000000000000",
        );
        assert_eq!(
            (d.integrator, d.nee, d.importance_sampling),
            (IntegratorKind::PathTracer, Nee::On, ImportanceSampling::Cosine)
        );
        assert!(d.russian_roulette && d.light_stratify);
        assert_eq!(d.output.as_deref(), Some("out.png"));
        let c = d.camera.expect("camera");
        assert_eq!((c.eye, c.center, c.up, c.fovy_deg), (Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 30.0));
    }

    #[test]
    fn errors_name_line_and_cause() {
        expect_err("size 10 10\nfoo 1 2\n", 2, &["unknown command", "'foo'"]);
        expect_err("pushtransform", 1, &["unknown command", "did you mean 'pushTransform'"]);
        expect_err("# c\ncamera 0 0 0 0 0 -1 0 1 0", 2, &["camera expects 10 numbers, got 9"]);
        expect_err("vertex 1 2 3 4", 1, &["vertex expects 3 numbers, got 4"]);
        expect_err("\n\nvertex 1 x 2", 3, &["vertex", "argument 2", "expected a number", "'x'"]);
        expect_err("vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\ntri 0 1 3", 4, &["tri index 3", "3 vertices"]);
        expect_err("vertex 0 0 0\ntri 0 0 -1", 2, &["tri index -1", "1 vertices"]);
        expect_err("tri 0 1 2.5", 1, &["tri", "expected an integer", "'2.5'"]);
        expect_err("pushTransform\npopTransform\npopTransform", 3, &["popTransform", "empty"]);
        expect_err("size 1000000 1000000", 1, &["1000000x1000000", "268435456 pixels", "--limit max_pixels=N"]);
        expect_err("size 100000 2", 1, &["65536", "max_side"]);
        expect_err("size 0 10", 1, &["size", "positive"]);
        expect_err("scale 1 1 1\nscale 1 0 1", 2, &["scale", "non-zero"]);
        expect_err("spp -4", 1, &["spp", "at least 1", "-4"]);
        expect_err("spp 100000000", 1, &["spp", "max_spp"]);
        expect_err("lightsamples 0", 1, &["lightsamples", "at least 1"]);
        expect_err("maxdepth -2", 1, &["maxdepth", "at least -1"]);
        expect_err("maxverts -1", 1, &["maxverts", "at least 0"]);
        expect_err("vertex nan 0 0", 1, &["vertex", "'nan'", "finite"]);
        expect_err("sphere 0 0 0 1e39", 1, &["sphere", "finite"]);
        expect_err("gamma 0", 1, &["gamma", "> 0"]);
        expect_err("rotate 0 0 0 90", 1, &["rotate", "axis"]);
        expect_err("directional 0 0 0 1 1 1", 1, &["directional", "non-zero"]);
        expect_err("sphere 0 0 0 0", 1, &["sphere", "radius"]);
        expect_err("quadLight 0 0 0 1 0 0 2 0 0 1 1 1", 1, &["quadLight", "area"]);
        expect_err("integrator foo", 1, &["integrator", "raytracer|analyticdirect|direct|pathtracer", "'foo'"]);
        expect_err("lightstratify", 1, &["lightstratify", "on|off", "0 arguments"]);
        expect_err("attenuation 0 0 0", 1, &["attenuation"]);
        expect_err("shininess -1", 1, &["shininess", ">= 0"]);
        expect_err("camera 0 0 0 0 0 0 0 1 0 45", 1, &["camera", "coincide"]);
        expect_err("camera 0 0 0 0 0 -1 0 0 1 45", 1, &["camera", "parallel"]);
        expect_err("camera 0 0 0 0 0 -1 0 1 0 180", 1, &["fovy"]);
        expect_err("scale 1e30 1e30 1e30\nscale 1e30 1e30 1e30\nvertex 1 1 1\ntri 0 0 0", 4, &["out of range"]);
        expect_err("popTransform extra", 1, &["popTransform expects 0 arguments, got 1"]);
        expect_err(&format!("vertex {} 1 1", "9".repeat(100_000)), 1, &["finite", "..."]);
    }

    #[test]
    fn display_and_file_errors() {
        let e = parse_str("ok 1", Path::new("dir/x.test"), &Limits::default()).expect_err("error");
        assert_eq!(e.to_string(), "dir/x.test:1: unknown command 'ok'");
        let missing = Path::new("/nonexistent/strata/scene.test");
        let e = parse_file(missing, &Limits::default()).expect_err("missing file");
        assert_eq!(e.line, 0);
        assert!(e.to_string().starts_with("/nonexistent/strata/scene.test: cannot read"), "{e}");
        let path = std::env::temp_dir().join(format!("strata-parse-{}.test", std::process::id()));
        std::fs::write(&path, b"size 10 10\n\nvertex 1 \xff 2\n").expect("write temp file");
        let e = parse_file(&path, &Limits::default()).expect_err("bad utf-8");
        let _ = std::fs::remove_file(&path);
        assert_eq!(e.line, 3);
        assert!(e.message.contains("UTF-8"));
    }

    #[test]
    fn limits_are_enforced() {
        let limits = Limits { max_vertices: 3, max_primitives: 2, max_transform_depth: 2, ..Limits::default() };
        let run = |text: &str| parse_str(text, Path::new("t.test"), &limits);
        let e = run("vertex 0 0 0\nvertex 0 0 0\nvertex 0 0 0\nvertex 0 0 0").expect_err("vertices");
        assert!(e.line == 4 && e.message.contains("max_vertices"), "{e}");
        let e = run("sphere 0 0 0 1\npoint 0 0 0 1 1 1\nsphere 0 0 0 1").expect_err("primitives");
        assert!(e.line == 3 && e.message.contains("max_primitives"), "{e}");
        let e = run("pushTransform\npushTransform\npushTransform").expect_err("depth");
        assert!(e.line == 3 && e.message.contains("max_transform_depth"), "{e}");
        assert!(run("pushTransform\npushTransform\npopTransform\npushTransform").is_ok());
    }

    /// xorshift64*: a tiny deterministic generator for the robustness test.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n.max(1) as u64) as usize
        }
    }

    #[test]
    fn truncated_and_mutated_corpus_never_panics() {
        let Some(dir) = corpus() else { return };
        const NASTY: [&str; 24] = [
            "nan",
            "-inf",
            "1e39",
            "-1",
            "0",
            "-0",
            "99999999999999999999",
            "4294967296",
            "1e-45",
            "2.5",
            "x",
            "é",
            "#",
            "",
            "tri",
            "sphere",
            "pushTransform",
            "popTransform",
            "scale",
            "rotate",
            "size",
            "maxverts",
            "1e15",
            "\u{0}",
        ];
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for file in corpus_files(&dir) {
            let text = std::fs::read_to_string(&file).expect("corpus file is text");
            for _ in 0..50 {
                let mut cut = rng.below(text.len() + 1);
                while !text.is_char_boundary(cut) {
                    cut -= 1;
                }
                let _ = parse_str(&text[..cut], &file, &Limits::default());
            }
            let lines: Vec<&str> = text.lines().collect();
            for _ in 0..20 {
                // Mutate a few tokens in a window of at most 400 lines, so big files stay quick.
                let start = if rng.below(2) == 0 { 0 } else { rng.below(lines.len().saturating_sub(400)) };
                let mut window: Vec<Vec<&str>> =
                    lines.iter().skip(start).take(400).map(|l| l.split_ascii_whitespace().collect()).collect();
                for _ in 0..1 + rng.below(4) {
                    let l = rng.below(window.len());
                    if let Some(line) = window.get_mut(l) {
                        let t = rng.below(line.len() + 1);
                        let token = NASTY[rng.below(NASTY.len())];
                        if t < line.len() {
                            line[t] = token
                        } else {
                            line.push(token)
                        }
                    }
                }
                let mutated: Vec<String> = window.iter().map(|l| l.join(" ")).collect();
                let _ = parse_str(&mutated.join("\n"), &file, &Limits::default());
            }
        }
    }
}

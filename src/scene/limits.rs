//! Resource caps of the scene readers ([`Limits`], set from `--limit NAME=VALUE`).

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
    /// Maximum `--threads` (default 4x the cores).
    pub max_threads: usize,
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
            max_threads: 4 * std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// A `--limit NAME=VALUE` that cannot be applied.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LimitError {
    /// No `=` in the assignment.
    #[error("--limit `{0}`: expected NAME=VALUE, NAME one of {names}", names = Limits::NAMES.join(", "))]
    Syntax(String),
    /// VALUE is not a non-negative integer.
    #[error("--limit {name}: expected a non-negative integer, got `{value}`")]
    NotAnInteger {
        /// the limit's name
        name: String,
        /// the value as written
        value: String,
    },
    /// VALUE does not fit the field.
    #[error("--limit {name}={value}: at most {max}")]
    TooLarge {
        /// the limit's name
        name: String,
        /// the value asked for
        value: u64,
        /// the largest value the field holds
        max: u64,
    },
    /// NAME is not one of [`Limits::NAMES`].
    #[error("--limit: unknown limit `{0}` (one of {names})", names = Limits::NAMES.join(", "))]
    Unknown(String),
}

impl Limits {
    /// Names of the limits, as `--limit NAME=VALUE` spells them (the field names).
    pub const NAMES: [&'static str; 9] = [
        "max_pixels",
        "max_side",
        "max_vertices",
        "max_primitives",
        "max_spp",
        "max_depth",
        "max_light_samples",
        "max_transform_depth",
        "max_threads",
    ];

    /// Sets one limit from `NAME=VALUE` (the `--limit` flag); VALUE is a non-negative integer that
    /// must fit the field. Errors name the known limits.
    pub fn set(&mut self, assignment: &str) -> Result<(), LimitError> {
        let (name, value) = assignment.split_once('=').ok_or_else(|| LimitError::Syntax(assignment.to_string()))?;
        let (name, value) = (name.trim(), value.trim());
        let v: u64 =
            value.parse().map_err(|_| LimitError::NotAnInteger { name: name.to_string(), value: value.to_string() })?;
        let range = |max: u64| {
            if v <= max {
                Ok(v)
            } else {
                Err(LimitError::TooLarge { name: name.to_string(), value: v, max })
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
            "max_threads" => self.max_threads = range(usize::MAX as u64)? as usize,
            _ => return Err(LimitError::Unknown(name.to_string())),
        }
        Ok(())
    }
}

/// How to raise a limit: the `--limit` flag with the field's name (`Limits::set`).
pub fn limit_hint(field: &str) -> String {
    format!("raise it with --limit {field}=N")
}

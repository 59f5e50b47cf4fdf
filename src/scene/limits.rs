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
    /// Maximum bytes a render may use by its estimate (film, outputs, threads, scene, BVH;
    /// default [`default_max_memory`]: 80% of physical memory or of the cgroup's limit).
    pub max_memory: u64,
    /// Maximum size of a scene, OBJ or MTL file in bytes (default 4 GiB).
    pub max_file_bytes: u64,
}

/// 80% of the memory this process may use: physical memory (`MemTotal` of /proc/meminfo), or the
/// cgroup's limit (v2 `memory.max`, v1 `memory.limit_in_bytes`, as Slurm sets) when lower.
/// 64 GiB when neither can be read.
pub fn default_max_memory() -> u64 {
    static CACHE: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *CACHE.get_or_init(|| {
        let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
            let line = t.lines().find(|l| l.starts_with("MemTotal:"))?;
            let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
            Some(kib * 1024)
        });
        let cgroup = ["/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"]
            .iter()
            .filter_map(|f| std::fs::read_to_string(f).ok()?.trim().parse::<u64>().ok())
            .min();
        let total = match (meminfo, cgroup) {
            (Some(m), Some(c)) => m.min(c),
            (m, c) => m.or(c).unwrap_or(64 << 30),
        };
        total / 5 * 4
    })
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
            max_memory: default_max_memory(),
            max_file_bytes: 4 << 30,
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
    pub const NAMES: [&'static str; 11] = [
        "max_pixels",
        "max_side",
        "max_vertices",
        "max_primitives",
        "max_spp",
        "max_depth",
        "max_light_samples",
        "max_transform_depth",
        "max_threads",
        "max_memory",
        "max_file_bytes",
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
            "max_memory" => self.max_memory = v,
            "max_file_bytes" => self.max_file_bytes = v,
            _ => return Err(LimitError::Unknown(name.to_string())),
        }
        Ok(())
    }
}

/// How to raise a limit: the `--limit` flag with the field's name (`Limits::set`).
pub fn limit_hint(field: &str) -> String {
    format!("raise it with --limit {field}=N")
}

/// What [`read_bounded`] found wrong: a 1-based line (0: the file as a whole) and a message.
pub type ReadError = (usize, String);

/// The message of a text file holding a NUL byte (shared with the OBJ reader's decoding).
pub const NUL_BYTE: &str = "the file is not valid UTF-8 text (a NUL byte: UTF-16 or binary?)";

/// Reads `path` (`what` names its kind in messages) through the bounded reader's
/// [`crate::files::open_regular`] (a FIFO, device or directory is refused before it is opened, a
/// file over `max` before a byte is read), in chunks, refusing it as soon as it has more
/// than `max` bytes (`--limit max_file_bytes`) or a NUL byte (no scene, OBJ or MTL text has one;
/// a file starting with a UTF-16 byte-order mark is left to the decoder to name), so that
/// `/dev/zero`, a binary file or an endless pipe fails at once instead of filling memory.
pub fn read_bounded(path: &std::path::Path, what: &str, max: u64) -> Result<Vec<u8>, ReadError> {
    use std::io::Read;
    let io = |e: std::io::Error| (0, format!("cannot read {what}: {e}"));
    let (mut file, len) = crate::files::open_regular(path).map_err(io)?;
    if len > max {
        return Err((
            0,
            format!("{what} is larger than the limit of {max} bytes ({len} bytes; {})", limit_hint("max_file_bytes")),
        ));
    }
    let mut bytes = Vec::new();
    let mut chunk = vec![0u8; 1 << 20];
    let mut lines_before = 0;
    loop {
        let n = match file.read(&mut chunk) {
            Ok(0) => return Ok(bytes),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(io(e)),
        };
        let new = &chunk[..n];
        let utf16 = bytes.get(..2).or(new.get(..2)).is_some_and(|b| b == b"\xff\xfe" || b == b"\xfe\xff");
        if let Some(i) = new.iter().position(|&b| b == 0).filter(|_| !utf16) {
            let line = lines_before + new[..i].iter().filter(|&&b| b == b'\n').count() + 1;
            return Err((line, NUL_BYTE.to_string()));
        }
        if (bytes.len() + n) as u64 > max {
            return Err((
                0,
                format!("{what} is larger than the limit of {max} bytes ({})", limit_hint("max_file_bytes")),
            ));
        }
        lines_before += new.iter().filter(|&&b| b == b'\n').count();
        bytes.extend_from_slice(new);
    }
}

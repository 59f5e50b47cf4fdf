//! Image files: linear f32 EXR with an optional variance layer and text metadata, an 8-bit gamma
//! PNG preview, output names, and the atomic file writer they share.

use std::fs;
use std::io::{self, Cursor};
use std::path::{Path, PathBuf};

/// Key/value metadata written into the EXR header as text attributes (spp, seconds, sampler, seed,
/// version, ...). Keys must be unique, non-empty, without NUL and not a standard EXR attribute name.
pub type Metadata = Vec<(String, String)>;

/// An EXR image as read back by [`read_exr`].
#[derive(Clone, Debug, PartialEq)]
pub struct ExrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB, row-major, top row first.
    pub rgb: Vec<[f32; 3]>,
    /// The "variance" layer (channels `variance.R/G/B`), if the file has all three.
    pub variance: Option<Vec<[f32; 3]>>,
    /// All text attributes that are not standard EXR attributes, sorted by key.
    pub meta: Metadata,
}

/// Channel names of one RGB triple, in pixel order.
const RGB: [&str; 3] = ["R", "G", "B"];
/// The largest EXR read (8 GiB: a 2^28-pixel image, the largest a render makes, with its variance
/// layer as f32).
pub const MAX_EXR_BYTES: u64 = 8 << 30;

/// Channel-name prefix of the variance layer.
const VARIANCE_PREFIX: &str = "variance.";

/// Writes a linear full-float (f32) RGB EXR, ZIP-compressed (lossless) scan lines, with an optional
/// layer "variance" (channels `variance.R/G/B`, e.g. the per-pixel variance of the mean) and `meta`
/// as string attributes (UTF-8 bytes). Atomic, see [`write_atomic`].
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    variance: Option<&[[f32; 3]]>,
    meta: &Metadata,
) -> io::Result<()> {
    use exr::prelude::*;
    let bad = |msg: String| io::Error::new(io::ErrorKind::InvalidInput, format!("EXR {}: {msg}", path.display()));
    let n = width as usize * height as usize;
    if n == 0 {
        return Err(bad(format!("empty image {width}x{height}")));
    }
    for (what, len) in std::iter::once(("rgb", rgb.len())).chain(variance.map(|v| ("variance", v.len()))) {
        if len != n {
            return Err(bad(format!("{what} has {len} pixels, expected {width}x{height}")));
        }
    }
    let mut channels = SmallVec::<[AnyChannel<FlatSamples>; 4]>::new();
    for (prefix, px) in std::iter::once(("", rgb)).chain(variance.map(|v| (VARIANCE_PREFIX, v))) {
        for (c, name) in RGB.iter().enumerate() {
            let samples = FlatSamples::F32(px.iter().map(|p| p[c]).collect());
            channels.push(AnyChannel::new(format!("{prefix}{name}").as_str(), samples));
        }
    }
    let mut attributes = LayerAttributes::default();
    for (key, value) in meta {
        if key.is_empty() || key.contains('\0') {
            return Err(bad(format!("invalid metadata key {key:?}")));
        }
        let value = AttributeValue::Text(Text::from_bytes_unchecked(value.as_bytes().into()));
        if attributes.other.insert(Text::from_bytes_unchecked(key.as_bytes().into()), value).is_some() {
            return Err(bad(format!("duplicate metadata key {key:?}")));
        }
    }
    let layer = Layer::new(
        (width as usize, height as usize),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    let mut bytes = Cursor::new(Vec::new());
    Image::from_layer(layer).write().to_buffered(&mut bytes).map_err(|e| exr_error(e, path))?;
    write_atomic(path, bytes.get_ref())
}

/// Reads back an EXR written by [`write_exr`] (any EXR whose first layer has R, G and B channels):
/// size, RGB, the variance layer if present, and the text attributes. Read through the bounded
/// reader ([`crate::files::read_bounded`]): a regular file (not a FIFO or device) of at most
/// [`MAX_EXR_BYTES`], starting with the EXR magic number.
pub fn read_exr(path: &Path) -> io::Result<ExrImage> {
    use exr::prelude::*;
    let bytes = crate::files::read_bounded(path, MAX_EXR_BYTES)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
    if !bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        let msg = format!("{}: not an OpenEXR file (no EXR magic number)", path.display());
        return Err(io::Error::new(io::ErrorKind::InvalidData, msg));
    }
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| exr_error(e, path))?;
    let layer = image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    let channel = |name: String| -> Option<Vec<f32>> {
        let ch = layer.channel_data.list.iter().find(|c| c.name.as_slice() == name.as_bytes())?;
        Some(ch.sample_data.values_as_f32().collect())
    };
    let triple = |prefix: &str| -> Option<Vec<[f32; 3]>> {
        let [r, g, b] = RGB.map(|name| channel(format!("{prefix}{name}")));
        let (r, g, b) = (r?, g?, b?);
        Some((0..width * height).map(|i| [r[i], g[i], b[i]]).collect())
    };
    let rgb = triple("").ok_or_else(|| {
        io::Error::new(io::ErrorKind::InvalidData, format!("EXR {}: no R, G, B channels", path.display()))
    })?;
    let text = |t: &Text| String::from_utf8_lossy(t.as_slice()).into_owned();
    let mut meta: Metadata = layer
        .attributes
        .other
        .iter()
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(v) => Some((text(k), text(v))),
            _ => None,
        })
        .collect();
    meta.sort();
    Ok(ExrImage { width: width as u32, height: height as u32, rgb, variance: triple(VARIANCE_PREFIX), meta })
}

/// An `exr` error as an `io::Error` naming the file (I/O errors keep their kind).
fn exr_error(e: exr::error::Error, path: &Path) -> io::Error {
    let kind = match &e {
        exr::error::Error::Io(io) => io.kind(),
        _ => io::ErrorKind::InvalidData,
    };
    io::Error::new(kind, format!("EXR {}: {e}", path.display()))
}

/// How an 8-bit PNG value is made from `v^(1/gamma)` clamped to [0, 1] (times 255).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantize {
    /// `floor`: the CSE168 course's writer, `uchar(min(255, max(0, 255 * c)))` (the default for `.test` scenes)
    Truncate,
    /// nearest value ([`to_u8`]; the default for `.obj` scenes)
    Round,
}

impl Quantize {
    /// "truncate" | "round".
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim() {
            "truncate" => Some(Self::Truncate),
            "round" => Some(Self::Round),
            _ => None,
        }
    }

    /// Canonical name (accepted by `parse`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Truncate => "truncate",
            Self::Round => "round",
        }
    }
}

/// [`to_u8`] with the quantizer `q` (`Round` is `to_u8` itself).
pub fn to_u8_quantized(v: f32, gamma: f32, q: Quantize) -> u8 {
    match q {
        Quantize::Round => to_u8(v, gamma),
        Quantize::Truncate if !v.is_finite() || v <= 0.0 => 0,
        Quantize::Truncate => (v.powf(1.0 / gamma).min(1.0) * 255.0) as u8,
    }
}

/// The tone mapping of [`write_png`]: `v^(1/gamma)` clamped to [0, 1], times 255, rounded;
/// non-finite or negative values map to 0.
pub fn to_u8(v: f32, gamma: f32) -> u8 {
    if !v.is_finite() || v <= 0.0 {
        return 0;
    }
    (v.powf(1.0 / gamma).min(1.0) * 255.0).round() as u8
}

/// Writes an 8-bit RGB PNG preview (no sRGB curve, just [`to_u8`] with `gamma`). Atomic, see
/// [`write_atomic`].
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[[f32; 3]], gamma: f32) -> io::Result<()> {
    write_png_quantized(path, width, height, rgb, gamma, Quantize::Round)
}

/// [`write_png`] with the quantizer `q`.
pub fn write_png_quantized(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    gamma: f32,
    q: Quantize,
) -> io::Result<()> {
    write_atomic(path, &encode_png_quantized(path, width, height, rgb, gamma, q)?)
}

/// The bytes [`write_png_quantized`] writes to `path` (named in errors only), encoded in memory,
/// so that a caller can encode on one thread and write the file later.
pub fn encode_png_quantized(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    gamma: f32,
    q: Quantize,
) -> io::Result<Vec<u8>> {
    if rgb.len() != width as usize * height as usize {
        let msg = format!("PNG {}: {} pixels, expected {width}x{height}", path.display(), rgb.len());
        return Err(io::Error::new(io::ErrorKind::InvalidInput, msg));
    }
    let data: Vec<u8> = rgb.iter().flat_map(|p| p.map(|v| to_u8_quantized(v, gamma, q))).collect();
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    // fdeflate's PNG-tuned level: several times faster than the default `Balanced` for a few percent
    // more bytes; the decoded pixels are the same.
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&data)?;
    writer.finish()?;
    Ok(bytes)
}

pub use crate::files::{check_target, dir_of, write_atomic};

/// Refuses an output stem (`-o OUT`, which names OUT.exr and OUT.png) that names a directory:
/// ending in `/`, `.` or `..`, or an existing directory.
pub fn check_stem(out: &Path) -> io::Result<()> {
    let s = out.as_os_str().to_string_lossy();
    let names_dir = s.is_empty()
        || s.ends_with('/')
        || out.file_name().is_none()
        || s.ends_with("/.")
        || fs::metadata(out).is_ok_and(|m| m.is_dir());
    if names_dir {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "-o names a directory; give a file stem (-o DIR/NAME writes DIR/NAME.exr and DIR/NAME.png)",
        ));
    }
    let stem = stem_of(out);
    let name = stem.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    if name.is_empty() || s.ends_with("/.exr") || s.ends_with("/.png") {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "-o has an empty file stem (it would write hidden files .exr and .png); give a name, e.g. -o out.exr",
        ));
    }
    Ok(())
}

/// `o` without a trailing `.exr` or `.png` (the stem an output path names).
pub fn stem_of(o: &Path) -> PathBuf {
    let s = o.to_string_lossy();
    for ext in [".exr", ".png"] {
        if let Some(stripped) = s.strip_suffix(ext) {
            return PathBuf::from(stripped);
        }
    }
    o.to_path_buf()
}

/// `stem` with `.ext` appended (`out` + `exr` = `out.exr`, keeping any dots in the stem).
pub fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

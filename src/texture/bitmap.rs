//! [`Bitmap`]: an RGB image in memory, read from PNG/JPEG/BMP/HDR (the `image` crate) or OpenEXR
//! (the `exr` crate), looked up at a uv point with Mitsuba 3's conventions.
//!
//! Conventions (checked against Mitsuba 3.9.1's `bitmap` texture, see the tests):
//! - texel `(x, y)` is column x of row y, row 0 being the file's first (top) row; uv `(0, 0)` is
//!   the corner of texel (0, 0) and `v` grows with the row index (no flip here: Mitsuba's OBJ
//!   reader flips `v` when it reads a mesh, the texture lookup does not);
//! - `nearest`: texel `floor(uv * size)`; `bilinear`: texel centres at half-integers, so
//!   `p = uv * size - 0.5` and the four texels around `floor(p)` weighted by `p - floor(p)`;
//! - `wrap_mode` acts on texel indices: `repeat` (modulo the size), `mirror` (period twice the
//!   size, the second half reversed), `clamp` (to the edge texel);
//! - 8- and 16-bit images are sRGB-encoded and decoded to linear values unless `raw`; EXR and
//!   Radiance HDR values are linear and kept; grey images become three equal channels; alpha is
//!   dropped.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::simd::{Vec3x8, F8};

use super::{TexQuery, TexQuery8, TextureError, UvTransform};

/// How a lookup between texel centres is filtered (Mitsuba's `filter_type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FilterType {
    /// The texel containing the point.
    Nearest,
    /// Bilinear interpolation of the four nearest texel centres (Mitsuba's default).
    #[default]
    Bilinear,
}

impl FilterType {
    /// The Mitsuba name (`nearest`, `bilinear`) as a filter type, or `None`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "nearest" => Some(Self::Nearest),
            "bilinear" => Some(Self::Bilinear),
            _ => None,
        }
    }
}

/// What a lookup outside [0, 1)² reads (Mitsuba's `wrap_mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WrapMode {
    /// Tile the image (Mitsuba's default).
    #[default]
    Repeat,
    /// Tile the image mirrored every other period.
    Mirror,
    /// Repeat the edge texels.
    Clamp,
}

impl WrapMode {
    /// The Mitsuba name (`repeat`, `mirror`, `clamp`) as a wrap mode, or `None`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "repeat" => Some(Self::Repeat),
            "mirror" => Some(Self::Mirror),
            "clamp" => Some(Self::Clamp),
            _ => None,
        }
    }

    /// Texel index `i` of a row or column of `n` texels, wrapped into `[0, n)`.
    #[inline]
    fn index(self, i: i64, n: i64) -> usize {
        let t = match self {
            Self::Repeat => i.rem_euclid(n),
            Self::Clamp => i.clamp(0, n - 1),
            Self::Mirror => {
                let t = i.rem_euclid(2 * n);
                if t >= n {
                    2 * n - 1 - t
                } else {
                    t
                }
            }
        };
        t as usize
    }
}

/// How a bitmap is read and looked up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BitmapOptions {
    /// Keep 8/16-bit values as stored (no sRGB decoding): Mitsuba's `raw`.
    pub raw: bool,
    /// Filtering of lookups.
    pub filter: FilterType,
    /// Lookups outside the image.
    pub wrap: WrapMode,
}

/// Size caps checked from an image's header, before its texels are allocated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BitmapLimits {
    /// Maximum width and height.
    pub max_side: u32,
    /// Maximum width * height.
    pub max_texels: u64,
    /// Maximum size of the file in bytes (checked before it is read).
    pub max_file_bytes: u64,
}

impl Default for BitmapLimits {
    /// 65536 texels a side, 2^27 texels (1.5 GiB of RGB f32), files up to 4 GiB (the scene
    /// limit `max_file_bytes`' default).
    fn default() -> Self {
        Self { max_side: 65536, max_texels: 1 << 27, max_file_bytes: 4 << 30 }
    }
}

/// An RGB f32 image with its lookup settings (see the module documentation for the conventions).
/// Its `Debug` shows the size and settings, not the texels.
#[derive(Clone, PartialEq)]
pub struct Bitmap {
    width: u32,
    height: u32,
    /// Row-major linear RGB, row 0 first.
    texels: Vec<[f32; 3]>,
    filter: FilterType,
    wrap: WrapMode,
}

impl std::fmt::Debug for Bitmap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bitmap")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("filter", &self.filter)
            .field("wrap", &self.wrap)
            .finish_non_exhaustive()
    }
}

/// The sRGB transfer function inverted: an encoded value in [0, 1] to linear.
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The 256 linear values of 8-bit sRGB codes (computed in f64, rounded once).
fn srgb8_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f64 / 255.0) as f32))
}

impl Bitmap {
    /// A bitmap from `width * height` row-major linear RGB texels (row 0 first).
    /// Fails if the sizes disagree or a side is 0.
    pub fn from_texels(
        width: u32,
        height: u32,
        texels: Vec<[f32; 3]>,
        filter: FilterType,
        wrap: WrapMode,
    ) -> Result<Self, TextureError> {
        if width == 0 || height == 0 || texels.len() as u64 != width as u64 * height as u64 {
            return Err(TextureError::TexelCount { width, height, count: texels.len() });
        }
        Ok(Self { width, height, texels, filter, wrap })
    }

    /// Reads `path` (PNG, JPEG, BMP, Radiance HDR or OpenEXR, told by its first bytes, else by
    /// its extension), checking `limits` from the header before decoding. The file is read once,
    /// through `files::read_bounded` (a FIFO, device or directory is refused before opening; the
    /// size is checked before reading), and decoded from memory.
    pub fn load(path: &Path, options: &BitmapOptions, limits: &BitmapLimits) -> Result<Self, TextureError> {
        let bytes = crate::files::read_bounded(path, limits.max_file_bytes)
            .map_err(|source| TextureError::Io { path: path.to_path_buf(), source })?;
        let (width, height, texels) = if is_exr(path, &bytes) {
            read_exr(path, &bytes, limits)?
        } else {
            read_image(path, &bytes, options.raw, limits)?
        };
        Self::from_texels(width, height, texels, options.filter, options.wrap)
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The row-major texels (row 0 first), linear RGB.
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.texels
    }

    /// Texel `(x, y)` (column, row); panics out of range.
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        Vec3::from(self.texels[y as usize * self.width as usize + x as usize])
    }

    /// The mean of the texels (summed in f64).
    pub fn mean(&self) -> Vec3 {
        let sum = self.texels.iter().fold([0f64; 3], |a, t| [a[0] + t[0] as f64, a[1] + t[1] as f64, a[2] + t[2] as f64]);
        let n = self.texels.len() as f64;
        Vec3::new((sum[0] / n) as f32, (sum[1] / n) as f32, (sum[2] / n) as f32)
    }

    /// The filter of lookups.
    pub fn filter(&self) -> FilterType {
        self.filter
    }

    /// The wrap mode of lookups.
    pub fn wrap(&self) -> WrapMode {
        self.wrap
    }

    /// The texel at wrapped indices.
    #[inline]
    fn fetch(&self, x: i64, y: i64) -> [f32; 3] {
        let (w, h) = (self.width as i64, self.height as i64);
        let (x, y) = (self.wrap.index(x, w), self.wrap.index(y, h));
        self.texels[y * self.width as usize + x]
    }

    /// The filtered value at `uv` (a NaN coordinate reads as 0). Bit-identical to each lane of [`Bitmap::eval_x8`].
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        let (w, h) = (self.width as f32, self.height as f32);
        let uv = Vec2::new(sanitize(uv.x), sanitize(uv.y));
        match self.filter {
            FilterType::Nearest => {
                let (x, y) = ((uv.x * w).floor(), (uv.y * h).floor());
                Vec3::from(self.fetch(x as i64, y as i64))
            }
            FilterType::Bilinear => {
                let ([ax, ay, bx, by], corners) = bilinear(uv, w, h);
                let [v00, v10, v01, v11] = corners.map(|(x, y)| self.fetch(x, y));
                Vec3::from(std::array::from_fn::<f32, 3, _>(|c| {
                    let s0 = bx * v00[c] + ax * v10[c];
                    let s1 = bx * v01[c] + ax * v11[c];
                    by * s0 + ay * s1
                }))
            }
        }
    }

    /// The gradient in uv of the bilinearly filtered luminance (Rec. 709 weights, as Mitsuba's
    /// `luminance`) at `uv`: the derivative of the interpolation between the four texels around
    /// the point, in texels times the resolution (Mitsuba's `eval_1_grad`). Zero for a nearest
    /// lookup (piecewise constant).
    pub fn grad_luminance(&self, uv: Vec2) -> Vec2 {
        if self.filter == FilterType::Nearest {
            return Vec2::ZERO;
        }
        let (w, h) = (self.width as f32, self.height as f32);
        let uv = Vec2::new(sanitize(uv.x), sanitize(uv.y));
        let ([ax, ay, bx, by], corners) = bilinear(uv, w, h);
        let [f00, f10, f01, f11] = corners.map(|(x, y)| super::luminance(Vec3::from(self.fetch(x, y))));
        Vec2::new((by * (f10 - f00) + ay * (f11 - f01)) * w, (bx * (f01 - f00) + ax * (f11 - f10)) * h)
    }

    /// The filtered values at eight uv points (every lane is looked up; mask the result).
    pub fn eval_x8(&self, u: F8, v: F8) -> Vec3x8 {
        let (w, h) = (F8::splat(self.width as f32), F8::splat(self.height as f32));
        let (u, v) = (sanitize_x8(u), sanitize_x8(v));
        match self.filter {
            FilterType::Nearest => {
                let (x, y) = ((u * w).floor().to_array(), (v * h).floor().to_array());
                let t: [[f32; 3]; 8] = std::array::from_fn(|i| self.fetch(x[i] as i64, y[i] as i64));
                Vec3x8::new(F8::new(t.map(|c| c[0])), F8::new(t.map(|c| c[1])), F8::new(t.map(|c| c[2])))
            }
            FilterType::Bilinear => {
                let half = F8::splat(0.5);
                let (px, py) = (u * w - half, v * h - half);
                let (fx, fy) = (px.floor(), py.floor());
                let (ax, ay) = (px - fx, py - fy);
                let one = F8::splat(1.0);
                let (bx, by) = (one - ax, one - ay);
                let (fxa, fya) = (fx.to_array(), fy.to_array());
                // Per lane: the four texels, as [corner][channel][lane].
                let mut t = [[[0.0f32; 8]; 3]; 4];
                for i in 0..8 {
                    let (x0, y0) = (fxa[i] as i64, fya[i] as i64);
                    let (x1, y1) = (x0.saturating_add(1), y0.saturating_add(1));
                    for (k, (x, y)) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)].into_iter().enumerate() {
                        let c = self.fetch(x, y);
                        for ch in 0..3 {
                            t[k][ch][i] = c[ch];
                        }
                    }
                }
                let channel = |ch: usize| {
                    let [v00, v10, v01, v11] = [0, 1, 2, 3].map(|k| F8::new(t[k][ch]));
                    let s0 = bx * v00 + ax * v10;
                    let s1 = bx * v01 + ax * v11;
                    by * s0 + ay * s1
                };
                Vec3x8::new(channel(0), channel(1), channel(2))
            }
        }
    }
}

/// The `bitmap` texture plugin: a [`Bitmap`] (shared) looked up at the hit's uv mapped by `to_uv`.
#[derive(Debug, Clone, PartialEq)]
pub struct BitmapTexture {
    /// The image with its filter and wrap mode.
    pub bitmap: std::sync::Arc<Bitmap>,
    /// Mitsuba's `to_uv` (default identity).
    pub to_uv: UvTransform,
}

impl BitmapTexture {
    /// The value at one point.
    pub fn eval(&self, q: &TexQuery) -> Vec3 {
        self.bitmap.eval(self.to_uv.apply(q.uv))
    }

    /// The gradient in uv (before `to_uv`) of the luminance at one point
    /// ([`Bitmap::grad_luminance`] through `to_uv`).
    pub fn grad_luminance(&self, q: &TexQuery) -> Vec2 {
        self.to_uv.pull_back(self.bitmap.grad_luminance(self.to_uv.apply(q.uv)))
    }

    /// The values at eight points (bit-identical to [`BitmapTexture::eval`] per lane).
    pub fn eval_x8(&self, q: &TexQuery8) -> Vec3x8 {
        let (u, v) = self.to_uv.apply_x8(q.u, q.v);
        self.bitmap.eval_x8(u, v)
    }
}

/// Coordinates beyond this magnitude are clamped to it (far past where f32 resolves texels), so
/// lookups never meet infinities.
const UV_LIMIT: f32 = 1.0e7;

/// A uv coordinate made safe to look up: NaN reads as 0, the rest is clamped to `±UV_LIMIT`.
#[inline]
fn sanitize(x: f32) -> f32 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(-UV_LIMIT, UV_LIMIT)
    }
}

/// [`sanitize`] on eight lanes (bit-identical per lane).
#[inline]
fn sanitize_x8(x: F8) -> F8 {
    x.is_nan().select(F8::ZERO, x.max(F8::splat(-UV_LIMIT)).min(F8::splat(UV_LIMIT)))
}

/// Whether `path` is an OpenEXR file: by its magic number, or by its extension when shorter
/// than four bytes (then the EXR reader reports it truncated).
fn is_exr(path: &Path, bytes: &[u8]) -> bool {
    match bytes.get(..4) {
        Some(head) => head == [0x76, 0x2f, 0x31, 0x01],
        None => path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")),
    }
}

/// `width` x `height` against `limits`.
fn check_size(path: &Path, width: u64, height: u64, limits: &BitmapLimits) -> Result<(), TextureError> {
    if width == 0
        || height == 0
        || width > limits.max_side as u64
        || height > limits.max_side as u64
        || width * height > limits.max_texels
    {
        return Err(TextureError::TooLarge {
            path: path.to_path_buf(),
            width,
            height,
            max_side: limits.max_side,
            max_texels: limits.max_texels,
        });
    }
    Ok(())
}

/// A PNG/JPEG/BMP/HDR file through the `image` crate: header and size check, then decoding.
fn read_image(
    path: &Path,
    bytes: &[u8],
    raw: bool,
    limits: &BitmapLimits,
) -> Result<(u32, u32, Vec<[f32; 3]>), TextureError> {
    let decode = |e: image::ImageError| TextureError::Decode { path: path.to_path_buf(), message: e.to_string() };
    let reader = || -> Result<image::ImageReader<_>, TextureError> {
        let mut r = image::ImageReader::new(std::io::Cursor::new(bytes));
        if let Ok(format) = image::ImageFormat::from_path(path) {
            r.set_format(format);
        }
        let r = r.with_guessed_format().map_err(|source| TextureError::Io { path: path.to_path_buf(), source })?;
        if r.format().is_none() {
            return Err(TextureError::Format { path: path.to_path_buf() });
        }
        Ok(r)
    };
    let (w, h) = reader()?.into_dimensions().map_err(decode)?;
    check_size(path, w as u64, h as u64, limits)?;
    let mut r = reader()?;
    let mut caps = image::Limits::default();
    caps.max_image_width = Some(limits.max_side);
    caps.max_image_height = Some(limits.max_side);
    // Decoded at most 16-bit RGBA or f32 RGBA, plus the decoder's own buffers.
    caps.max_alloc = Some(limits.max_texels.saturating_mul(32).max(64 << 20));
    r.limits(caps);
    let img = r.decode().map_err(decode)?;
    if (img.width(), img.height()) != (w, h) {
        return Err(TextureError::Decode {
            path: path.to_path_buf(),
            message: format!("header says {w}x{h}, decoded {}x{}", img.width(), img.height()),
        });
    }
    use image::DynamicImage as D;
    let lut = srgb8_table();
    let t8 = |c: u8| if raw { c as f32 / 255.0 } else { lut[c as usize] };
    let t16 = |c: u16| {
        let x = c as f64 / 65535.0;
        (if raw { x } else { srgb_to_linear(x) }) as f32
    };
    let texels: Vec<[f32; 3]> = match &img {
        D::ImageLuma8(b) => b.pixels().map(|p| [t8(p.0[0]); 3]).collect(),
        D::ImageLumaA8(b) => b.pixels().map(|p| [t8(p.0[0]); 3]).collect(),
        D::ImageRgb8(b) => b.pixels().map(|p| p.0.map(t8)).collect(),
        D::ImageRgba8(b) => b.pixels().map(|p| [t8(p.0[0]), t8(p.0[1]), t8(p.0[2])]).collect(),
        D::ImageLuma16(b) => b.pixels().map(|p| [t16(p.0[0]); 3]).collect(),
        D::ImageLumaA16(b) => b.pixels().map(|p| [t16(p.0[0]); 3]).collect(),
        D::ImageRgb16(b) => b.pixels().map(|p| p.0.map(t16)).collect(),
        D::ImageRgba16(b) => b.pixels().map(|p| [t16(p.0[0]), t16(p.0[1]), t16(p.0[2])]).collect(),
        D::ImageRgb32F(b) => b.pixels().map(|p| p.0).collect(),
        D::ImageRgba32F(b) => b.pixels().map(|p| [p.0[0], p.0[1], p.0[2]]).collect(),
        other => other.to_rgb32f().pixels().map(|p| p.0).collect(),
    };
    Ok((w, h, texels))
}

/// An OpenEXR file's first layer (its R, G, B channels, or Y as grey), size checked from the
/// header before the pixels are read.
fn read_exr(path: &Path, bytes: &[u8], limits: &BitmapLimits) -> Result<(u32, u32, Vec<[f32; 3]>), TextureError> {
    use exr::prelude::*;
    let err = |e: exr::error::Error| TextureError::Decode { path: path.to_path_buf(), message: e.to_string() };
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false).map_err(err)?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| TextureError::Decode { path: path.to_path_buf(), message: "no layer".into() })?;
    let size = header.layer_size;
    check_size(path, size.width() as u64, size.height() as u64, limits)?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(err)?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    check_size(path, w as u64, h as u64, limits)?;
    let channel = |name: &str| -> Option<Vec<f32>> {
        let ch = layer.channel_data.list.iter().find(|c| c.name.as_slice() == name.as_bytes())?;
        Some(ch.sample_data.values_as_f32().collect())
    };
    let texels = match (channel("R"), channel("G"), channel("B"), channel("Y")) {
        (Some(r), Some(g), Some(b), _) => (0..w * h).map(|i| [r[i], g[i], b[i]]).collect(),
        (_, _, _, Some(y)) => y.into_iter().map(|v| [v; 3]).collect(),
        _ => return Err(TextureError::Channels { path: path.to_path_buf() }),
    };
    Ok((w as u32, h as u32, texels))
}

#[cfg(test)]
#[path = "bitmap_tests.rs"]
mod tests;

/// The bilinear lookup at `uv` of a `w` x `h` image (texel centres at half integers): the weights
/// `[ax, ay, 1 - ax, 1 - ay]` and the four texels `(x0, y0), (x1, y0), (x0, y1), (x1, y1)`.
#[inline]
fn bilinear(uv: Vec2, w: f32, h: f32) -> ([f32; 4], [(i64, i64); 4]) {
    let (px, py) = (uv.x * w - 0.5, uv.y * h - 0.5);
    let (fx, fy) = (px.floor(), py.floor());
    let (ax, ay) = (px - fx, py - fy);
    let (x0, y0) = (fx as i64, fy as i64);
    let (x1, y1) = (x0.saturating_add(1), y0.saturating_add(1));
    ([ax, ay, 1.0 - ax, 1.0 - ay], [(x0, y0), (x1, y0), (x0, y1), (x1, y1)])
}

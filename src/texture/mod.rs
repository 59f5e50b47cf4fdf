//! Textures: images and procedural patterns evaluated per lane at surface hits.
//!
//! # API (plain Rust; the Mitsuba XML front end builds these types)
//!
//! - [`Bitmap`] (`bitmap.rs`): an RGB f32 image. `Bitmap::load(path, &BitmapOptions { raw, filter,
//!   wrap }, &BitmapLimits::default())` reads PNG, JPEG, BMP, Radiance HDR (the `image` crate) or
//!   OpenEXR (the `exr` crate); 8/16-bit values are sRGB-decoded to linear unless `raw`; sizes are
//!   checked from the header before anything is allocated; errors are [`TextureError`]s naming
//!   the file. `Bitmap::from_texels` makes one in memory. `eval(uv)` and `eval_x8(u, v)` look it
//!   up (bit-identical per lane) with Mitsuba's filters (`FilterType::{Nearest, Bilinear}`),
//!   wrap modes (`WrapMode::{Repeat, Mirror, Clamp}`) and texel-centre convention; `width`,
//!   `height`, `texel(x, y)` and `texels()` give the raw data (for envmap sampling).

mod bitmap;

use std::path::PathBuf;

pub use bitmap::{srgb_to_linear, Bitmap, BitmapLimits, BitmapOptions, FilterType, WrapMode};

/// What goes wrong making a texture.
#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    /// The file could not be opened or read.
    #[error("texture {}: {source}", path.display())]
    Io {
        /// The image file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not an image format strata reads.
    #[error("texture {}: not a PNG, JPEG, BMP, HDR or OpenEXR image", path.display())]
    Format {
        /// The image file.
        path: PathBuf,
    },
    /// The decoder refused the file (truncated, corrupt, unsupported variant).
    #[error("texture {}: {message}", path.display())]
    Decode {
        /// The image file.
        path: PathBuf,
        /// The decoder's message.
        message: String,
    },
    /// The header's size is 0 or over the limits (checked before decoding).
    #[error(
        "texture {}: {width}x{height} texels is empty or over the limits ({max_side} a side, {max_texels} in all)",
        path.display()
    )]
    TooLarge {
        /// The image file.
        path: PathBuf,
        /// Width from the header.
        width: u64,
        /// Height from the header.
        height: u64,
        /// The side limit.
        max_side: u32,
        /// The texel-count limit.
        max_texels: u64,
    },
    /// An OpenEXR file without R, G, B or Y channels.
    #[error("texture {}: OpenEXR file without R, G, B (or Y) channels", path.display())]
    Channels {
        /// The image file.
        path: PathBuf,
    },
    /// In-memory texels that do not fill `width * height`.
    #[error("bitmap of {width}x{height} texels given {count} texels")]
    TexelCount {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Texels given.
        count: usize,
    },
}

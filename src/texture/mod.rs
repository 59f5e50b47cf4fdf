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
//! - The texture plugins, one file each, gathered in the enum [`Texture`] by one registry line
//!   each (`textures!` below): [`BitmapTexture`] (`bitmap.rs`: a `Bitmap` with `to_uv`),
//!   [`Checkerboard`] (`checkerboard.rs`: `color0` 0.4, `color1` 0.2, `to_uv`), [`MeshAttribute`]
//!   (`mesh_attribute.rs`: a named `vertex_*`/`face_*` attribute times `scale`; the scene binds its
//!   data with [`MeshAttribute::bind`]), [`RawConstant`] (`rawconstant.rs`: `value` as given).
//!   [`UvTransform`] is Mitsuba's 3x3 `to_uv` (`UvTransform::from_mat4` takes rows and columns
//!   0, 1, 3 of the XML's 4x4, as Mitsuba does).
//! - Evaluation: `Texture::eval(&TexQuery)` for one point and `Texture::eval_x8(&TexQuery8)` for
//!   eight lanes, bit-identical per lane. A query carries the hit's uv, its triangle index in
//!   `SceneDesc::triangles` (`NO_TRIANGLE` elsewhere) and Embree's barycentrics `(b1, b2)` (the
//!   weights of corners 1 and 2). Values are linear RGB; what a scene's material does with them
//!   is the scene's business (`scene/gather.rs`). `Texture::eval_1`/`eval_1_x8` are Mitsuba's
//!   float lookup (`eval_1`), which scalar parameters (roughness, opacity, weights) read: the
//!   value's [`scalar`] (a grey value's own, else its luminance), except that a checkerboard's
//!   colours come the other way round, as Mitsuba 3.9.1 has them.

mod query;

use std::path::PathBuf;

use glam::Vec3;

use crate::simd::{Vec3x8, F8};

pub use bitmap::{srgb_to_linear, Bitmap, BitmapLimits, BitmapOptions, FilterType, WrapMode};
pub use mesh_attribute::AttrRun;
pub use query::{TexQuery, TexQuery8, UvTransform, NO_TRIANGLE};

/// The registry: one line per texture plugin, `file: Type,` (declares `mod file;`, re-exports
/// `file::Type` and adds the `Texture::Type` variant with its dispatch).
macro_rules! textures {
    ($($file:ident: $ty:ident,)*) => {
        $(mod $file; pub use $file::$ty;)*

        /// A texture of the scene: one variant per plugin.
        #[derive(Debug, Clone, PartialEq)]
        pub enum Texture {
            $(
                #[doc = concat!("The `", stringify!($file), "` plugin.")]
                $ty($ty),
            )*
        }

        impl Texture {
            /// The value at one point.
            pub fn eval(&self, q: &TexQuery) -> Vec3 {
                match self {
                    $(Self::$ty(t) => t.eval(q),)*
                }
            }

            /// The values at eight points (every lane evaluated; bit-identical to `eval` per lane).
            pub fn eval_x8(&self, q: &TexQuery8) -> Vec3x8 {
                match self {
                    $(Self::$ty(t) => t.eval_x8(q),)*
                }
            }
        }
    };
}

/// Mitsuba's luminance of a linear sRGB value (what a scalar parameter reads from a colour
/// texture: `eval_1`).
pub fn luminance(c: Vec3) -> f32 {
    c.x * 0.212_671 + c.y * 0.715_160 + c.z * 0.072_169
}

/// The float a scalar parameter reads from a value: a grey value's own (bit for bit), else its
/// [`luminance`].
pub fn scalar(c: Vec3) -> f32 {
    if c.x == c.y && c.y == c.z {
        c.x
    } else {
        luminance(c)
    }
}

/// [`scalar`] of eight values (bit-identical per lane).
pub fn scalar_x8(c: Vec3x8) -> F8 {
    let grey = c.x.simd_eq(c.y) & c.y.simd_eq(c.z);
    let l = c.x * F8::splat(0.212_671) + c.y * F8::splat(0.715_160) + c.z * F8::splat(0.072_169);
    grey.select(c.x, l)
}

impl Texture {
    /// Mitsuba's float lookup (`eval_1`, what roughness, opacity and weights read) at one point:
    /// a checkerboard's [`Checkerboard::eval_1`] (its colours the other way round), the
    /// [`scalar`] of [`Texture::eval`] for the other plugins.
    pub fn eval_1(&self, q: &TexQuery) -> f32 {
        match self {
            Texture::Checkerboard(c) => c.eval_1(q),
            other => scalar(other.eval(q)),
        }
    }

    /// [`Texture::eval_1`] at eight points (bit-identical per lane).
    pub fn eval_1_x8(&self, q: &TexQuery8) -> F8 {
        match self {
            Texture::Checkerboard(c) => c.eval_1_x8(q),
            other => scalar_x8(other.eval_x8(q)),
        }
    }

    /// A representative value: a bitmap's texel mean, a checkerboard's two colours averaged, a
    /// constant's value, a mesh attribute's mean over its bound values (times `scale`; 0 before
    /// binding). For a textured material's own `diffuse` (lobe choice reads it).
    pub fn mean(&self) -> Vec3 {
        match self {
            Texture::BitmapTexture(t) => t.bitmap.mean(),
            Texture::Checkerboard(c) => (c.color0 + c.color1) * 0.5,
            Texture::RawConstant(c) => c.value,
            Texture::MeshAttribute(a) => {
                let (mut sum, mut n) = (glam::DVec3::ZERO, 0u64);
                for r in &a.runs {
                    for v in r.data.chunks_exact(r.dims as usize) {
                        sum += if r.dims == 3 {
                            glam::DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
                        } else {
                            glam::DVec3::splat(v[0] as f64)
                        };
                        n += 1;
                    }
                }
                if n == 0 {
                    Vec3::ZERO
                } else {
                    (sum / n as f64).as_vec3() * a.scale
                }
            }
        }
    }

    /// The gradient in uv of the texture's luminance at `q` (what Mitsuba's `bumpmap` reads):
    /// a bitmap's ([`Bitmap::grad_luminance`]), zero for a constant; `None` for the plugins
    /// without one (Mitsuba has none for them either).
    pub fn grad_luminance(&self, q: &TexQuery) -> Option<glam::Vec2> {
        match self {
            Texture::BitmapTexture(t) => Some(t.grad_luminance(q)),
            Texture::RawConstant(_) => Some(glam::Vec2::ZERO),
            Texture::Checkerboard(_) | Texture::MeshAttribute(_) => None,
        }
    }

    /// Feeds everything the texture renders, as 32-bit words, to `word` (for a scene's content
    /// hash): a bitmap's size, settings and texel bits; the other plugins' fields through `Debug`
    /// (f32 `Debug` round-trips, so distinct values print differently).
    pub fn digest(&self, word: &mut dyn FnMut(u32)) {
        match self {
            Texture::BitmapTexture(t) => {
                let b = &t.bitmap;
                word(0x6269_7400);
                [b.width(), b.height(), b.filter() as u32, b.wrap() as u32].into_iter().for_each(&mut *word);
                b.texels().iter().flatten().for_each(|x| word(x.to_bits()));
                format!("{:?}", t.to_uv).bytes().for_each(|c| word(u32::from(c)));
            }
            other => format!("{other:?}").bytes().for_each(|c| word(u32::from(c))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn means() {
        let b = Bitmap::from_texels(2, 1, vec![[0.0, 1.0, 2.0], [1.0, 1.0, 0.0]], FilterType::Nearest, WrapMode::Clamp)
            .unwrap();
        let t = Texture::BitmapTexture(BitmapTexture { bitmap: b.into(), to_uv: UvTransform::IDENTITY });
        assert_eq!(t.mean(), Vec3::new(0.5, 1.0, 1.0));
        assert!((Texture::Checkerboard(Checkerboard::default()).mean() - Vec3::splat(0.3)).abs().max_element() < 1e-7);
        assert_eq!(Texture::RawConstant(RawConstant { value: Vec3::X }).mean(), Vec3::X);
        let mut a = MeshAttribute::new("face_w", 2.0);
        let run = AttrRun { first: 0, count: 2, dims: 1, per_corner: false, data: vec![0.25, 0.75].into() };
        a.bind([("face_w".to_string(), run)]);
        assert_eq!(Texture::MeshAttribute(a).mean(), Vec3::ONE);
    }
}

textures! {
    bitmap: BitmapTexture,
    checkerboard: Checkerboard,
    mesh_attribute: MeshAttribute,
    rawconstant: RawConstant,
}

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

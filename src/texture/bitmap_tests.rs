//! Tests of `Bitmap`: decoding, lookups against Mitsuba 3.9.1's values and hand-computed texels,
//! x8 against scalar, hostile files.

use super::*;
use std::io::Write;

/// The 3x2 test image: row 0 = 0.1 0.2 0.3, row 1 = 0.4 0.5 0.6 (red channel; green = 2 red,
/// blue = -red to tell the channels apart).
fn image32(filter: FilterType, wrap: WrapMode) -> Bitmap {
    let t = [0.1f32, 0.2, 0.3, 0.4, 0.5, 0.6].map(|r| [r, 2.0 * r, -r]).to_vec();
    Bitmap::from_texels(3, 2, t, filter, wrap).unwrap()
}

const UVS: [(f32, f32); 6] = [(0.0, 0.0), (0.1, 0.1), (0.5, 0.9), (-0.3, 1.4), (1.7, -0.6), (0.99, 0.01)];

#[test]
fn lookups_match_mitsuba() {
    // Mitsuba 3.9.1, scalar_rgb: `bitmap` texture of this image with `raw`, `eval` at UVS
    // (printed to 5 decimals).
    let cases: [(WrapMode, FilterType, [f32; 6]); 6] = [
        (WrapMode::Repeat, FilterType::Nearest, [0.1, 0.1, 0.5, 0.3, 0.3, 0.3]),
        (WrapMode::Repeat, FilterType::Bilinear, [0.35, 0.23, 0.41, 0.35, 0.35, 0.35]),
        (WrapMode::Mirror, FilterType::Nearest, [0.1, 0.1, 0.5, 0.4, 0.4, 0.3]),
        (WrapMode::Mirror, FilterType::Bilinear, [0.1, 0.1, 0.5, 0.35, 0.35, 0.3]),
        (WrapMode::Clamp, FilterType::Nearest, [0.1, 0.1, 0.5, 0.4, 0.3, 0.3]),
        (WrapMode::Clamp, FilterType::Bilinear, [0.1, 0.1, 0.5, 0.4, 0.3, 0.3]),
    ];
    for (wrap, filter, want) in cases {
        let b = image32(filter, wrap);
        for ((u, v), w) in UVS.into_iter().zip(want) {
            let got = b.eval(Vec2::new(u, v));
            assert!((got.x - w).abs() < 1e-5, "{wrap:?} {filter:?} at ({u}, {v}): {got} != {w}");
            assert!((got.y - 2.0 * w).abs() < 2e-5 && (got.z + w).abs() < 1e-5, "channels {got}");
        }
    }
}

#[test]
fn bilinear_by_hand() {
    // (0.1, 0.1) on the repeat image: p = (0.3 - 0.5, 0.2 - 0.5) = (-0.2, -0.3), floor (-1, -1),
    // weights of the upper texels (0.8, 0.7); x: -1 -> 2, 0; y: -1 -> 1, 0.
    let b = image32(FilterType::Bilinear, WrapMode::Repeat);
    let t = |x: u32, y: u32| b.texel(x, y).x;
    let want = 0.3 * (0.2 * t(2, 1) + 0.8 * t(0, 1)) + 0.7 * (0.2 * t(2, 0) + 0.8 * t(0, 0));
    assert!((b.eval(Vec2::new(0.1, 0.1)).x - want).abs() < 1e-6);
    // At a texel centre bilinear returns the texel.
    assert_eq!(b.eval(Vec2::new(1.5 / 3.0, 0.25)).x, t(1, 0));
    // Mirror: index -1 reads 0, index 3 reads 2, index 4 reads 1 (second period reversed), 6 reads 0.
    let m = image32(FilterType::Nearest, WrapMode::Mirror);
    for (x, want) in [(-1, 0), (3, 2), (4, 1), (5, 0), (6, 0), (-4, 2)] {
        let u = (x as f32 + 0.5) / 3.0;
        assert_eq!(m.eval(Vec2::new(u, 0.25)).x, m.texel(want, 0).x, "mirror index {x}");
    }
}

#[test]
fn x8_is_bit_identical_to_scalar() {
    let mut s = 0x2545f491u32;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        (s as f32 / u32::MAX as f32) * 8.0 - 4.0
    };
    let specials = [0.0, f32::INFINITY, -1.0, 0.5, 1e9, -1e9, f32::NEG_INFINITY, f32::NAN];
    for filter in [FilterType::Nearest, FilterType::Bilinear] {
        for wrap in [WrapMode::Repeat, WrapMode::Mirror, WrapMode::Clamp] {
            let b = image32(filter, wrap);
            for round in 0..200 {
                let (u, v): ([f32; 8], [f32; 8]) = if round == 0 {
                    (specials, specials.map(|x| -x))
                } else {
                    (std::array::from_fn(|_| rnd()), std::array::from_fn(|_| rnd()))
                };
                let x8 = b.eval_x8(F8::new(u), F8::new(v));
                for i in 0..8 {
                    let (a, s) = (x8.lane(i), b.eval(Vec2::new(u[i], v[i])));
                    assert_eq!(a.to_array().map(f32::to_bits), s.to_array().map(f32::to_bits), "{filter:?} {wrap:?}");
                }
            }
        }
    }
}

#[test]
fn srgb_decoding() {
    // The sRGB curve at its ends, at the linear segment and values Mitsuba decodes
    // (247 -> 0.930111, 153 -> 0.318547).
    let t = srgb8_table();
    assert_eq!(t[0], 0.0);
    assert_eq!(t[255], 1.0);
    assert!((t[10] - 10.0 / 255.0 / 12.92).abs() < 1e-9);
    assert!((t[247] - 0.930111).abs() < 1e-6 && (t[153] - 0.318547).abs() < 1e-6);
    assert!((srgb_to_linear(0.5) - 0.214041).abs() < 1e-6);
}

/// `pixels` (RGB8, row-major) as a PNG file.
fn write_png(f: &mut tempfile::NamedTempFile, w: u32, h: u32, pixels: &[u8]) {
    let mut e = png::Encoder::new(f.as_file_mut(), w, h);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    let mut wr = e.write_header().unwrap();
    wr.write_image_data(pixels).unwrap();
}

#[test]
fn png_rows_and_srgb() {
    let mut f = tempfile::Builder::new().suffix(".png").tempfile().unwrap();
    // 2x2: top row red 255, 153; bottom row green 247, blue 0 / all 10.
    write_png(&mut f, 2, 2, &[255, 0, 0, 153, 0, 0, 0, 247, 0, 10, 10, 10]);
    let opts = BitmapOptions { filter: FilterType::Nearest, ..Default::default() };
    let b = Bitmap::load(f.path(), &opts, &BitmapLimits::default()).unwrap();
    assert_eq!((b.width(), b.height()), (2, 2));
    assert_eq!(b.texel(0, 0), Vec3::new(1.0, 0.0, 0.0));
    assert!((b.texel(1, 0).x - 0.318547).abs() < 1e-6);
    assert!((b.texel(0, 1).y - 0.930111).abs() < 1e-6);
    // v grows with the row: (0.25, 0.75) is row 1.
    assert_eq!(b.eval(Vec2::new(0.25, 0.75)), b.texel(0, 1));
    let raw = Bitmap::load(f.path(), &BitmapOptions { raw: true, ..opts }, &BitmapLimits::default()).unwrap();
    assert_eq!(raw.texel(1, 0).x, 153.0 / 255.0);
}

#[test]
fn corpus_png_matches_mitsuba() {
    // Mitsuba 3.9.1 on carrot.png (RGBA 10x9), nearest, at uv (0.3, 0.7): [1, 0.318547, 0], raw
    // [1, 0.6, 0]; texel (0, 0) decodes to 0.930111.
    let path = Path::new("../shared/corpora/mitsuba-tests/common/textures/carrot.png");
    assert!(path.exists(), "missing {} (the shared corpus)", path.display());
    let opts = BitmapOptions { filter: FilterType::Nearest, ..Default::default() };
    let b = Bitmap::load(path, &opts, &BitmapLimits::default()).unwrap();
    assert_eq!((b.width(), b.height()), (10, 9));
    let v = b.eval(Vec2::new(0.3, 0.7));
    assert!((v - Vec3::new(1.0, 0.318547, 0.0)).abs().max_element() < 1e-6, "{v}");
    assert!((b.texel(0, 0).x - 0.930111).abs() < 1e-6);
    let raw = Bitmap::load(path, &BitmapOptions { raw: true, ..opts }, &BitmapLimits::default()).unwrap();
    assert!((raw.eval(Vec2::new(0.3, 0.7)) - Vec3::new(1.0, 0.6, 0.0)).abs().max_element() < 1e-6);
}

#[test]
fn exr_is_linear_and_read_by_channel() {
    use exr::prelude::*;
    let f = tempfile::Builder::new().suffix(".exr").tempfile().unwrap();
    let img = Image::from_channels(
        (3, 2),
        SpecificChannels::rgb(|p: Vec2<usize>| (p.0 as f32 + 10.0 * p.1 as f32, 2.5f32, -1.0f32)),
    );
    img.write().to_file(f.path()).unwrap();
    let b = Bitmap::load(f.path(), &BitmapOptions::default(), &BitmapLimits::default()).unwrap();
    assert_eq!((b.width(), b.height()), (3, 2));
    assert_eq!(b.texel(2, 1), Vec3::new(12.0, 2.5, -1.0));
    // Truncated: a decode error naming the file.
    let bytes = std::fs::read(f.path()).unwrap();
    let mut t = tempfile::Builder::new().suffix(".exr").tempfile().unwrap();
    t.write_all(&bytes[..bytes.len() * 2 / 3]).unwrap();
    let e = Bitmap::load(t.path(), &BitmapOptions::default(), &BitmapLimits::default()).unwrap_err();
    assert!(matches!(e, TextureError::Decode { .. }), "{e}");
    assert!(e.to_string().contains(&t.path().display().to_string()));
}

#[test]
fn hostile_files_are_errors() {
    let opts = BitmapOptions::default();
    let lim = BitmapLimits::default();
    // A PNG whose header claims 100000 x 100000: refused before decoding.
    let mut f = tempfile::Builder::new().suffix(".png").tempfile().unwrap();
    {
        let mut e = png::Encoder::new(f.as_file_mut(), 100_000, 100_000);
        e.set_color(png::ColorType::Rgb);
        let mut w = e.write_header().unwrap();
        // The start of the image data (the reader wants an IDAT to report the header).
        w.write_chunk(png::chunk::IDAT, &[0x78, 0x9c, 0, 0]).unwrap();
        drop(w);
    }
    let e = Bitmap::load(f.path(), &opts, &lim).unwrap_err();
    assert!(matches!(e, TextureError::TooLarge { width: 100_000, .. }), "{e}");
    // Within the side limit but over the texel limit.
    let small = BitmapLimits { max_side: 65536, max_texels: 3, ..BitmapLimits::default() };
    let mut g = tempfile::Builder::new().suffix(".png").tempfile().unwrap();
    write_png(&mut g, 2, 2, &[0; 12]);
    assert!(matches!(Bitmap::load(g.path(), &opts, &small), Err(TextureError::TooLarge { .. })));
    // Truncated PNG.
    let bytes = std::fs::read(g.path()).unwrap();
    for cut in [8, 20, bytes.len() - 13] {
        let mut t = tempfile::Builder::new().suffix(".png").tempfile().unwrap();
        t.write_all(&bytes[..cut]).unwrap();
        let e = Bitmap::load(t.path(), &opts, &lim).unwrap_err();
        assert!(matches!(e, TextureError::Decode { .. }), "cut at {cut}: {e}");
    }
    // Not an image; empty file; missing file.
    let mut n = tempfile::Builder::new().suffix(".png").tempfile().unwrap();
    n.write_all(b"hello, this is no image at all").unwrap();
    assert!(matches!(
        Bitmap::load(n.path(), &opts, &lim),
        Err(TextureError::Format { .. } | TextureError::Decode { .. })
    ));
    let empty = tempfile::Builder::new().suffix(".jpg").tempfile().unwrap();
    assert!(Bitmap::load(empty.path(), &opts, &lim).is_err());
    let e = Bitmap::load(Path::new("/nonexistent/x.png"), &opts, &lim).unwrap_err();
    assert!(matches!(e, TextureError::Io { .. }) && e.to_string().contains("/nonexistent/x.png"));
    // A FIFO (nobody writes to it) is refused before it is opened, never waited on; a file over
    // the byte limit is refused before it is read.
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("f.png");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let e = Bitmap::load(&fifo, &opts, &lim).unwrap_err();
    assert!(matches!(e, TextureError::Io { .. }) && e.to_string().contains("is a FIFO"), "{e}");
    let tiny = BitmapLimits { max_file_bytes: 10, ..lim };
    let e = Bitmap::load(g.path(), &opts, &tiny).unwrap_err();
    assert!(e.to_string().contains("above the limit of 10 bytes"), "{e}");
    // In memory: sizes that disagree.
    assert!(Bitmap::from_texels(2, 2, vec![[0.0; 3]; 3], FilterType::Nearest, WrapMode::Clamp).is_err());
    assert!(Bitmap::from_texels(0, 0, vec![], FilterType::Nearest, WrapMode::Clamp).is_err());
}

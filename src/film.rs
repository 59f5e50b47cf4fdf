//! Sample accumulation (`Film`) and image output: linear f32 EXR with an optional variance layer and
//! text metadata, an 8-bit gamma PNG preview, and the atomic file writer they share.
//!
//! Pixels are row-major, top row first, index `y * width + x`. Every writer goes through
//! [`write_atomic`]: the bytes are built in memory, written to `<path>.tmp-<pid>`, fsynced and renamed
//! over `path`, so a reader never sees a partial file and a failed write leaves the old file intact.

use std::fs::{self, File};
use std::io::{self, Cursor, Write};
use std::path::{Path, PathBuf};

/// Per-pixel f64 accumulation: per-channel sum, per-channel sum of squares (second moment) and
/// sample count.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Per-pixel sum of the RGB samples.
    pub sum: Vec<[f64; 3]>,
    /// Per-pixel sum of the squared RGB samples, per channel.
    pub sum_sq: Vec<[f64; 3]>,
    /// Per-pixel number of samples.
    pub count: Vec<u32>,
}

impl Film {
    /// An empty film of `width * height` pixels.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self { width, height, sum: vec![[0.0; 3]; n], sum_sq: vec![[0.0; 3]; n], count: vec![0; n] }
    }

    /// Adds one sample value for pixel (x, y). Panics if the pixel is outside the film.
    pub fn add(&mut self, x: u32, y: u32, rgb: [f32; 3]) {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {}x{} film",
            self.width,
            self.height
        );
        let i = y as usize * self.width as usize + x as usize;
        for (c, &v) in rgb.iter().enumerate() {
            let v = f64::from(v);
            self.sum[i][c] += v;
            self.sum_sq[i][c] += v * v;
        }
        self.count[i] += 1;
    }

    /// Adds another film of the same size (pixelwise sums), e.g. merging tiles or passes.
    /// Panics if the sizes differ.
    pub fn merge(&mut self, other: &Film) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "merging films of different sizes"
        );
        let pixels = self.sum.iter_mut().zip(&mut self.sum_sq).zip(&mut self.count);
        for (i, ((s, q), n)) in pixels.enumerate() {
            for c in 0..3 {
                s[c] += other.sum[i][c];
                q[c] += other.sum_sq[i][c];
            }
            *n += other.count[i];
        }
    }

    /// Mean per pixel as f32 RGB, row-major, top row first (0 where count == 0).
    pub fn mean(&self) -> Vec<[f32; 3]> {
        self.per_channel(|n, s, _| if n > 0.0 { s / n } else { 0.0 })
    }

    /// Per-pixel variance of the mean estimate (unbiased sample variance / n), per channel; 0 where
    /// n < 2. Negative round-off is clamped to 0.
    pub fn variance_of_mean(&self) -> Vec<[f32; 3]> {
        self.per_channel(|n, s, q| if n >= 2.0 { ((q - s * s / n) / (n - 1.0)).max(0.0) / n } else { 0.0 })
    }

    /// Applies `f(count, sum, sum_sq)` to every channel of every pixel.
    fn per_channel(&self, f: impl Fn(f64, f64, f64) -> f64) -> Vec<[f32; 3]> {
        let pixels = self.count.iter().zip(&self.sum).zip(&self.sum_sq);
        pixels.map(|((&n, s), q)| std::array::from_fn(|c| f(f64::from(n), s[c], q[c]) as f32)).collect()
    }
}

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
    let bad =
        |msg: String| io::Error::new(io::ErrorKind::InvalidInput, format!("EXR {}: {msg}", path.display()));
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
/// size, RGB, the variance layer if present, and the text attributes.
pub fn read_exr(path: &Path) -> io::Result<ExrImage> {
    use exr::prelude::*;
    let image = read_first_flat_layer_from_file(path).map_err(|e| exr_error(e, path))?;
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
    if rgb.len() != width as usize * height as usize {
        let msg = format!("PNG {}: {} pixels, expected {width}x{height}", path.display(), rgb.len());
        return Err(io::Error::new(io::ErrorKind::InvalidInput, msg));
    }
    let data: Vec<u8> = rgb.iter().flat_map(|p| p.map(|v| to_u8(v, gamma))).collect();
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&data)?;
    writer.finish()?;
    write_atomic(path, &bytes)
}

/// Writes `bytes` to `path` atomically: to `<path>.tmp-<pid>` (created or truncated), fsync, rename
/// over `path`, then fsync the directory (best effort). On failure the temporary file is removed and
/// an existing file at `path` is left untouched. Two threads of one process must not write the same
/// `path` at the same time (they would share the temporary name).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".tmp-{}", std::process::id()));
    let tmp = PathBuf::from(tmp);
    let mut file = File::create(&tmp)?;
    let result = file.write_all(bytes).and_then(|()| file.sync_all()).and_then(|()| {
        drop(file);
        fs::rename(&tmp, path)
    });
    if let Err(e) = result {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh, empty scratch directory for one test.
    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("strata-film-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn tmp_of(path: &Path) -> PathBuf {
        PathBuf::from(format!("{}.tmp-{}", path.display(), std::process::id()))
    }

    #[test]
    fn mean_and_variance_of_known_samples() {
        let mut f = Film::new(3, 2);
        for v in [1.0, 2.0, 3.0] {
            f.add(2, 1, [v, 2.0 * v, -v]);
        }
        f.add(0, 0, [5.0, 5.0, 5.0]);
        let (m, var) = (f.mean(), f.variance_of_mean());
        assert_eq!(m[5], [2.0, 4.0, -2.0]);
        let third = 1.0f32 / 3.0;
        assert!((var[5][0] - third).abs() < 1e-7 && (var[5][1] - 4.0 * third).abs() < 1e-6);
        assert!((var[5][2] - third).abs() < 1e-7);
        assert_eq!((m[0], var[0]), ([5.0; 3], [0.0; 3]), "one sample: mean, no variance");
        assert_eq!((m[1], var[1]), ([0.0; 3], [0.0; 3]), "no samples");
        assert_eq!(f.count, vec![1, 0, 0, 0, 0, 3]);
        let mut g = Film::new(1, 1);
        (0..4).for_each(|_| g.add(0, 0, [0.1; 3]));
        assert_eq!(g.variance_of_mean()[0], [0.0; 3], "constant samples: no negative round-off");
    }

    #[test]
    fn merge_equals_adding_all_samples_to_one_film() {
        let (mut a, mut b, mut all) = (Film::new(4, 3), Film::new(4, 3), Film::new(4, 3));
        for i in 0..40u32 {
            let (x, y, v) = (i % 4, (i / 4) % 3, [i as f32 * 0.37, (i * i) as f32, 1.0 / (1 + i) as f32]);
            if i % 3 == 0 {
                a.add(x, y, v)
            } else {
                b.add(x, y, v)
            }
            all.add(x, y, v);
        }
        a.merge(&b);
        assert_eq!(a.count, all.count);
        assert_eq!(a.mean(), all.mean());
        for (p, q) in a.variance_of_mean().iter().zip(all.variance_of_mean()) {
            for c in 0..3 {
                assert!((p[c] - q[c]).abs() <= 1e-6 * q[c].abs().max(1e-6), "{p:?} vs {q:?}");
            }
        }
    }

    #[test]
    fn exr_round_trip_is_bit_exact_with_variance_and_metadata() {
        let d = scratch("exr");
        let (w, h) = (5u32, 3u32);
        let special =
            [0.0, -0.0, 1e-45, 1.2e-38, 3.0e38, f32::MAX, f32::INFINITY, f32::NAN, -7.25, 1.0 / 3.0];
        let rgb: Vec<[f32; 3]> =
            (0..15).map(|i| [special[i % 10], i as f32 * 0.1, special[(i * 7) % 10]]).collect();
        let var: Vec<[f32; 3]> = (0..15).map(|i| [1e-30 * i as f32, 2.5e-12, i as f32]).collect();
        let meta: Metadata = [("spp", "64"), ("sampler", "sobol"), ("seconds", "1.25"), ("note", "grüße, ✓")]
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .to_vec();
        let path = d.join("a.exr");
        write_exr(&path, w, h, &rgb, Some(&var), &meta).unwrap();
        let img = read_exr(&path).unwrap();
        assert_eq!((img.width, img.height), (w, h));
        let bits = |v: &[[f32; 3]]| v.iter().flat_map(|p| p.map(f32::to_bits)).collect::<Vec<_>>();
        assert_eq!(bits(&img.rgb), bits(&rgb));
        assert_eq!(bits(img.variance.as_ref().unwrap()), bits(&var));
        let mut sorted = meta.clone();
        sorted.sort();
        assert_eq!(img.meta, sorted);
        assert!(!tmp_of(&path).exists());

        // Without variance, overwriting the previous file.
        write_exr(&path, w, h, &rgb, None, &Vec::new()).unwrap();
        let img = read_exr(&path).unwrap();
        assert_eq!((bits(&img.rgb), img.variance, img.meta), (bits(&rgb), None, vec![]));
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn exr_rejects_bad_input_without_touching_the_target() {
        let d = scratch("exr-bad");
        let path = d.join("b.exr");
        assert!(write_exr(&path, 2, 2, &[[0.0; 3]; 3], None, &Vec::new()).is_err());
        assert!(write_exr(&path, 2, 2, &[[0.0; 3]; 4], Some(&[[0.0; 3]; 1]), &Vec::new()).is_err());
        let dup = vec![("k".to_string(), "1".to_string()), ("k".to_string(), "2".to_string())];
        assert!(write_exr(&path, 2, 2, &[[0.0; 3]; 4], None, &dup).is_err());
        let reserved = vec![("channels".to_string(), "x".to_string())];
        let e = write_exr(&path, 2, 2, &[[0.0; 3]; 4], None, &reserved).unwrap_err();
        assert!(e.to_string().contains("channels"), "{e}");
        assert!(!path.exists() && !tmp_of(&path).exists());
        fs::write(&path, b"not an exr").unwrap();
        assert!(read_exr(&path).is_err());
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn tone_mapping() {
        assert_eq!(to_u8(0.5, 2.2), (255.0 * 0.5f32.powf(1.0 / 2.2)).round() as u8);
        assert_eq!(to_u8(0.5, 1.0), 128);
        assert_eq!([to_u8(f32::NAN, 2.2), to_u8(f32::INFINITY, 2.2), to_u8(f32::NEG_INFINITY, 2.2)], [0; 3]);
        assert_eq!([to_u8(-0.5, 2.2), to_u8(0.0, 2.2), to_u8(1.0, 2.2), to_u8(7.0, 2.2)], [0, 0, 255, 255]);
    }

    #[test]
    fn png_round_trip_gives_to_u8_values() {
        let d = scratch("png");
        let (w, h) = (4u32, 3u32);
        let rgb: Vec<[f32; 3]> = (0..12).map(|i| [i as f32 / 11.0, f32::NAN, 2.0 - i as f32 * 0.2]).collect();
        let path = d.join("p.png");
        write_png(&path, w, h, &rgb, 2.2).unwrap();
        let decoder = png::Decoder::new(io::BufReader::new(File::open(&path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(
            (info.width, info.height, info.color_type, info.bit_depth),
            (w, h, png::ColorType::Rgb, png::BitDepth::Eight)
        );
        let expected: Vec<u8> = rgb.iter().flat_map(|p| p.map(|v| to_u8(v, 2.2))).collect();
        assert_eq!(&buf[..info.buffer_size()], &expected[..]);
        assert!(write_png(&path, w, h, &rgb[..11], 2.2).is_err());
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn atomic_write_failures_leave_nothing_and_keep_the_old_file() {
        let d = scratch("atomic");
        // Parent directory does not exist: error, nothing created.
        let missing = d.join("no-such-dir").join("x.bin");
        assert!(write_atomic(&missing, b"data").is_err());
        assert!(!d.join("no-such-dir").exists());
        // Parent is a regular file: error.
        fs::write(d.join("file"), b"f").unwrap();
        assert!(write_atomic(&d.join("file").join("x.bin"), b"data").is_err());
        // The temporary name is occupied by a directory: error, the existing target survives.
        let target = d.join("keep.exr");
        fs::write(&target, b"old").unwrap();
        fs::create_dir(tmp_of(&target)).unwrap();
        assert!(write_exr(&target, 1, 1, &[[1.0; 3]], None, &Vec::new()).is_err());
        assert!(write_png(&target, 1, 1, &[[1.0; 3]], 2.2).is_err());
        assert_eq!(fs::read(&target).unwrap(), b"old");
        fs::remove_dir(tmp_of(&target)).unwrap();
        // Success replaces the old file and leaves no temporary behind.
        write_atomic(&target, b"new").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new");
        assert_eq!(fs::read_dir(&d).unwrap().count(), 2, "only `file` and `keep.exr`");
        fs::remove_dir_all(&d).unwrap();
    }
}

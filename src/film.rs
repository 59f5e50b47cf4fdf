//! Sample accumulation (`Film`) and image output: linear f32 EXR with an optional variance layer and
//! text metadata, an 8-bit gamma PNG preview, and the atomic file writer they share.
//!
//! Pixels are row-major, top row first, index `y * width + x`. Every writer goes through
//! [`write_atomic`]: the bytes are built in memory, written to `<path>.tmp-<pid>`, fsynced and renamed
//! over `path`, so a reader never sees a partial file and a failed write leaves the old file intact.
//!
//! ## Order-independent accumulation (dyadic blocks)
//! f64 addition is not associative, so "sum of shard totals" differs in the last bits from one
//! sequential sum. A film therefore defines the value of the sample range `[lo, hi)` of a pixel
//! canonically: `[lo, hi)` is cut into its minimal set of aligned dyadic [`Block`]s (block (k, j)
//! holds samples `[j 2^k, (j+1) 2^k)`, as in a segment tree); a block's moments are the sum of its
//! two children's (a leaf is the sample's f64 value and its square); the range total is the fold of
//! its blocks in increasing sample order. Samples are inserted like a binary counter (a leaf, then
//! combine with the left sibling while it is present), and two films of adjacent ranges merge by
//! combining siblings bottom-up, which rebuilds exactly the blocks of one render of the union. So
//! passes, checkpoints and shards are bit-identical to one uninterrupted render. The block list is
//! the same for every pixel (it depends only on the range), so it is stored once; each live block
//! costs 48 bytes per pixel, and at most about 2 log2(hi - lo) blocks are live.

use std::fs::{self, File};
use std::io::{self, Cursor, Write};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// An aligned dyadic block of sample indices: samples `[j * 2^k, (j + 1) * 2^k)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Block {
    /// log2 of the number of samples
    pub k: u8,
    /// index of the block among the blocks of size 2^k
    pub j: u32,
}

impl Block {
    /// The leaf block of sample `s`.
    pub fn leaf(s: u32) -> Self {
        Self { k: 0, j: s }
    }

    /// First sample index.
    pub fn start(self) -> u64 {
        u64::from(self.j) << self.k
    }

    /// One past the last sample index.
    pub fn end(self) -> u64 {
        (u64::from(self.j) + 1) << self.k
    }

    /// Whether `self` is the left sibling of `right` (same size, `right` the odd one right after).
    pub fn is_left_sibling_of(self, right: Block) -> bool {
        self.k == right.k && right.j % 2 == 1 && self.j + 1 == right.j
    }

    /// The block made of this block and its sibling.
    pub fn parent(self) -> Block {
        Block { k: self.k + 1, j: self.j / 2 }
    }
}

/// Pushes `b` (which starts where the last block ends) onto a block list kept in increasing sample
/// order, combining it with its left sibling while that is the last block; returns how many
/// combinations were made (the caller combines the per-pixel moments the same way).
pub fn push_block(blocks: &mut Vec<Block>, mut b: Block) -> usize {
    let mut carries = 0;
    while let Some(&top) = blocks.last() {
        if !top.is_left_sibling_of(b) {
            break;
        }
        blocks.pop();
        b = b.parent();
        carries += 1;
    }
    blocks.push(b);
    carries
}

/// The canonical (minimal, aligned) dyadic blocks of the sample range `r`, in increasing order:
/// from the left, the largest aligned block that fits (what [`push_block`] builds sample by
/// sample), in O(log) steps.
pub fn canonical_blocks(r: Range<u32>) -> Vec<Block> {
    let (mut x, hi) = (u64::from(r.start), u64::from(r.end));
    let mut blocks = Vec::new();
    while x < hi {
        let mut k = x.trailing_zeros().min(32);
        while (1u64 << k) > hi - x {
            k -= 1;
        }
        blocks.push(Block { k: k as u8, j: (x >> k) as u32 });
        x += 1 << k;
    }
    blocks
}

/// Moments of one block of one pixel: sum of R, G, B, then sum of squares of R, G, B.
pub type Moments = [f64; 6];

/// Turns `right` into the moments of the block `left` + `right` (IEEE addition commutes, so the
/// order of the two operands inside one addition does not matter; the tree shape does).
#[inline(always)]
pub fn combine(left: &Moments, right: &mut Moments) {
    for q in 0..6 {
        right[q] += left[q];
    }
}

/// The leaf moments of one sample value.
#[inline(always)]
pub fn leaf_moments(rgb: [f32; 3]) -> Moments {
    let [r, g, b] = rgb.map(f64::from);
    [r, g, b, r * r, g * g, b * b]
}

/// Per-pixel f64 accumulation of a contiguous range of sample indices, kept as dyadic blocks (see
/// the module doc), with the per-pixel totals: per-channel sum, per-channel sum of squares (second
/// moment) and sample count.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Per-pixel sum of the RGB samples (the fold of the blocks; read-only view).
    pub sum: Vec<[f64; 3]>,
    /// Per-pixel sum of the squared RGB samples, per channel (read-only view).
    pub sum_sq: Vec<[f64; 3]>,
    /// Per-pixel number of samples (read-only view).
    pub count: Vec<u32>,
    /// sample indices held
    samples: Range<u32>,
    /// live blocks of `samples`, increasing
    blocks: Vec<Block>,
    /// block-major moments: `data[b * pixels + p]`
    data: Vec<Moments>,
}

impl Film {
    /// An empty film of `width * height` pixels.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            sum: vec![[0.0; 3]; n],
            sum_sq: vec![[0.0; 3]; n],
            count: vec![0; n],
            samples: 0..0,
            blocks: Vec::new(),
            data: Vec::new(),
        }
    }

    /// Number of pixels.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The sample indices accumulated (every pixel holds the same ones; empty for a new film).
    pub fn samples(&self) -> Range<u32> {
        self.samples.clone()
    }

    /// The live dyadic blocks, in increasing sample order.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    /// Moments of every live block, block-major: `block_data()[b * pixels() + p]`.
    pub fn block_data(&self) -> &[Moments] {
        &self.data
    }

    /// A film from its stored parts (a checkpoint): `blocks` must be the canonical blocks of
    /// `samples` and `data` hold `blocks.len() * width * height` moments.
    pub fn from_parts(
        width: u32,
        height: u32,
        samples: Range<u32>,
        blocks: Vec<Block>,
        data: Vec<Moments>,
    ) -> Result<Self, String> {
        if canonical_blocks(samples.clone()) != blocks {
            return Err(format!(
                "the block list is not the dyadic decomposition of samples {}..{}",
                samples.start, samples.end
            ));
        }
        let mut f = Film::new(width, height);
        if data.len() != blocks.len() * f.pixels() {
            return Err(format!(
                "{} block values, expected {} blocks x {}x{} pixels",
                data.len(),
                blocks.len(),
                width,
                height
            ));
        }
        f.samples = samples;
        f.blocks = blocks;
        f.data = data;
        f.refresh();
        Ok(f)
    }

    /// Replaces the block state (after a render) and recomputes the totals.
    pub(crate) fn set_state(&mut self, samples: Range<u32>, blocks: Vec<Block>, data: Vec<Moments>) {
        debug_assert_eq!(data.len(), blocks.len() * self.pixels());
        self.samples = samples;
        self.blocks = blocks;
        self.data = data;
        self.refresh();
    }

    /// Frees the block moments before [`Film::set_state`] replaces them (the totals stay).
    pub(crate) fn drop_block_data(&mut self) {
        self.data = Vec::new();
    }

    /// Adds sample index `s` for every pixel (`rgb[p]` for pixel p); `s` must be the next sample
    /// of the film's range (any index for an empty film). The scalar reference of the renderer's
    /// accumulation. Panics on a wrong index or length.
    pub fn add_sample(&mut self, s: u32, rgb: &[[f32; 3]]) {
        let n = self.pixels();
        assert_eq!(rgb.len(), n, "add_sample: {} values for {n} pixels", rgb.len());
        if self.samples.is_empty() {
            self.samples = s..s;
        }
        assert_eq!(s, self.samples.end, "add_sample: sample {s} does not continue {:?}", self.samples);
        let d = self.blocks.len();
        let c = push_block(&mut self.blocks, Block::leaf(s));
        self.data.resize((d + 1) * n, [0.0; 6]);
        for (p, v) in rgb.iter().enumerate() {
            let mut acc = leaf_moments(*v);
            for t in 0..c {
                combine(&self.data[(d - 1 - t) * n + p], &mut acc);
            }
            self.data[(d - c) * n + p] = acc;
        }
        self.data.truncate((d - c + 1) * n);
        self.samples.end = s + 1;
        self.refresh();
    }

    /// Merges a film of the same size holding the adjacent sample range (right after or right
    /// before this one): combines sibling blocks bottom-up, so the result has exactly the bits of
    /// one film that took all the samples. Errors if the sizes differ or the ranges do not touch.
    pub fn merge(&mut self, other: &Film) -> Result<(), String> {
        if (self.width, self.height) != (other.width, other.height) {
            return Err(format!(
                "merging a {}x{} film into a {}x{} one",
                other.width, other.height, self.width, self.height
            ));
        }
        if other.samples.is_empty() {
            return Ok(());
        }
        if self.samples.is_empty() {
            *self = other.clone();
            return Ok(());
        }
        let (left, right) = if self.samples.end == other.samples.start {
            (&*self, other)
        } else if other.samples.end == self.samples.start {
            (other, &*self)
        } else {
            return Err(format!(
                "sample ranges {}..{} and {}..{} are not adjacent",
                self.samples.start, self.samples.end, other.samples.start, other.samples.end
            ));
        };
        let n = self.pixels();
        let mut blocks = left.blocks.clone();
        let mut data = left.data.clone();
        for (b, &blk) in right.blocks.iter().enumerate() {
            let d = blocks.len();
            let c = push_block(&mut blocks, blk);
            data.resize((d + 1) * n, [0.0; 6]);
            for p in 0..n {
                let mut acc = right.data[b * n + p];
                for t in 0..c {
                    combine(&data[(d - 1 - t) * n + p], &mut acc);
                }
                data[(d - c) * n + p] = acc;
            }
            data.truncate((d - c + 1) * n);
        }
        let samples = left.samples.start..right.samples.end;
        self.set_state(samples, blocks, data);
        Ok(())
    }

    /// Recomputes the per-pixel totals: the fold of the blocks in increasing sample order.
    fn refresh(&mut self) {
        let n = self.pixels();
        let count = self.samples.len() as u32;
        for p in 0..n {
            let mut t = [0.0f64; 6];
            for b in 0..self.blocks.len() {
                let m = &self.data[b * n + p];
                if b == 0 {
                    t = *m;
                } else {
                    for q in 0..6 {
                        t[q] += m[q];
                    }
                }
            }
            self.sum[p] = [t[0], t[1], t[2]];
            self.sum_sq[p] = [t[3], t[4], t[5]];
            self.count[p] = count;
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
    if rgb.len() != width as usize * height as usize {
        let msg = format!("PNG {}: {} pixels, expected {width}x{height}", path.display(), rgb.len());
        return Err(io::Error::new(io::ErrorKind::InvalidInput, msg));
    }
    let data: Vec<u8> = rgb.iter().flat_map(|p| p.map(|v| to_u8_quantized(v, gamma, q))).collect();
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
            let mut px = [[0.0f32; 3]; 6];
            px[5] = [v, 2.0 * v, -v];
            px[0] = [5.0; 3];
            f.add_sample(10 + v as u32, &px);
        }
        let (m, var) = (f.mean(), f.variance_of_mean());
        assert_eq!(f.samples(), 11..14);
        assert_eq!(m[5], [2.0, 4.0, -2.0]);
        let third = 1.0f32 / 3.0;
        assert!((var[5][0] - third).abs() < 1e-7 && (var[5][1] - 4.0 * third).abs() < 1e-6);
        assert!((var[5][2] - third).abs() < 1e-7);
        assert_eq!((m[0], var[0]), ([5.0; 3], [0.0; 3]), "constant samples: mean, no variance");
        assert_eq!((m[1], var[1]), ([0.0; 3], [0.0; 3]), "zero samples");
        assert_eq!(f.count, vec![3; 6]);
        assert_eq!((Film::new(2, 1).mean(), Film::new(2, 1).count), (vec![[0.0; 3]; 2], vec![0, 0]), "no samples");
        let mut g = Film::new(1, 1);
        (0..4).for_each(|s| g.add_sample(s, &[[0.1; 3]]));
        assert_eq!(g.variance_of_mean()[0], [0.0; 3], "constant samples: no negative round-off");
    }

    /// A value with many significant bits, different per (sample, pixel, channel).
    fn value(s: u32, p: usize) -> [f32; 3] {
        let x = (s as f32 + 1.0) * 0.7310586 + p as f32 * 0.1234567;
        [x.sin() * 3.1 + 3.2, 1.0 / (1.0 + x), (x * 1.618034).fract() * 1e3]
    }

    fn film_of(r: Range<u32>, w: u32, h: u32) -> Film {
        let mut f = Film::new(w, h);
        for s in r {
            let px: Vec<[f32; 3]> = (0..(w * h) as usize).map(|p| value(s, p)).collect();
            f.add_sample(s, &px);
        }
        f
    }

    fn bits(f: &Film) -> Vec<u64> {
        f.sum.iter().chain(&f.sum_sq).flat_map(|p| p.map(f64::to_bits)).collect()
    }

    #[test]
    fn canonical_blocks_are_the_minimal_aligned_cover() {
        let b = |k, j| Block { k, j };
        assert_eq!(canonical_blocks(0..7), vec![b(2, 0), b(1, 2), b(0, 6)]);
        assert_eq!(canonical_blocks(3..13), vec![b(0, 3), b(2, 1), b(2, 2), b(0, 12)]);
        assert_eq!(canonical_blocks(0..64), vec![b(6, 0)]);
        assert_eq!(canonical_blocks(5..5), vec![]);
        assert_eq!(canonical_blocks(0..u32::MAX).len(), 32);
        assert_eq!(canonical_blocks(1 << 31..(1 << 31) + 1), vec![b(0, 1 << 31)]);
        for lo in 0..40u32 {
            for hi in lo..80 {
                let bl = canonical_blocks(lo..hi);
                // Contiguous cover, and no two neighbours are siblings (else it is not minimal).
                let mut at = u64::from(lo);
                for w in bl.windows(2) {
                    assert!(!w[0].is_left_sibling_of(w[1]), "{lo}..{hi}: {bl:?}");
                }
                for x in &bl {
                    assert_eq!(x.start(), at);
                    at = x.end();
                }
                assert_eq!(at, u64::from(hi));
                let mut counter = Vec::new();
                (lo..hi).for_each(|s| {
                    push_block(&mut counter, Block::leaf(s));
                });
                assert_eq!(counter, bl, "{lo}..{hi}: the binary counter builds the canonical blocks");
                assert!(
                    bl.len() <= 2 * (32 - (hi - lo).max(1).leading_zeros()) as usize,
                    "{lo}..{hi}: {} blocks",
                    bl.len()
                );
            }
        }
    }

    #[test]
    fn merge_of_any_split_is_bit_identical_to_one_film() {
        let (w, h) = (3, 2);
        let all = film_of(0..45, w, h);
        for cuts in [vec![1u32], vec![20], vec![7, 8, 9], vec![3, 16, 17, 31, 44], vec![32], (1..45).collect()] {
            let mut edges = vec![0];
            edges.extend(&cuts);
            edges.push(45);
            let parts: Vec<Film> = edges.windows(2).map(|e| film_of(e[0]..e[1], w, h)).collect();
            // Merge left to right, and also right to left: same bits, same blocks.
            let mut l = Film::new(w, h);
            parts.iter().for_each(|p| l.merge(p).unwrap());
            let mut r = Film::new(w, h);
            parts.iter().rev().for_each(|p| r.merge(p).unwrap());
            for m in [&l, &r] {
                assert_eq!(m.samples(), 0..45);
                assert_eq!(m.blocks(), all.blocks(), "cuts {cuts:?}");
                assert_eq!(bits(m), bits(&all), "cuts {cuts:?}");
                assert_eq!(m.count, all.count);
            }
        }
        // Not adjacent, or another size: refused.
        let mut a = film_of(0..4, w, h);
        assert!(a.merge(&film_of(5..9, w, h)).unwrap_err().contains("not adjacent"));
        assert!(a.merge(&film_of(4..9, 2, 2)).is_err());
        assert_eq!(a.samples(), 0..4, "a refused merge leaves the film as it was");
    }

    #[test]
    fn dyadic_sum_is_close_to_the_plain_sum_and_from_parts_checks_blocks() {
        let f = film_of(0..100, 2, 1);
        for p in 0..2 {
            let plain = (0..100).map(|s| f64::from(value(s, p)[1])).sum::<f64>();
            assert!((f.sum[p][1] - plain).abs() <= 1e-12 * plain.abs(), "{} vs {plain}", f.sum[p][1]);
        }
        let g = Film::from_parts(2, 1, 0..100, f.blocks().to_vec(), f.block_data().to_vec()).unwrap();
        assert_eq!(bits(&g), bits(&f));
        assert!(Film::from_parts(2, 1, 0..99, f.blocks().to_vec(), f.block_data().to_vec()).is_err());
        assert!(Film::from_parts(2, 1, 0..100, f.blocks().to_vec(), f.block_data()[1..].to_vec()).is_err());
    }

    #[test]
    fn exr_round_trip_is_bit_exact_with_variance_and_metadata() {
        let d = scratch("exr");
        let (w, h) = (5u32, 3u32);
        let special = [0.0, -0.0, 1e-45, 1.2e-38, 3.0e38, f32::MAX, f32::INFINITY, f32::NAN, -7.25, 1.0 / 3.0];
        let rgb: Vec<[f32; 3]> = (0..15).map(|i| [special[i % 10], i as f32 * 0.1, special[(i * 7) % 10]]).collect();
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
        let t = |v: f32| to_u8_quantized(v, 1.0, Quantize::Truncate);
        assert_eq!(
            [t(0.5), t(0.999 / 255.0), t(254.99 / 255.0), t(1.0), t(7.0), t(-1.0), t(f32::NAN)],
            [127, 0, 254, 255, 255, 0, 0]
        );
        assert_eq!(to_u8_quantized(0.5, 2.2, Quantize::Round), to_u8(0.5, 2.2));
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

//! Sample accumulation (`Film`) and image output: linear f32 EXR with an optional variance layer and
//! text metadata, an 8-bit gamma PNG preview, and the atomic file writer they share.
//!
//! Pixels are row-major, top row first, index `y * width + x`. Every writer goes through
//! [`write_atomic`]: the bytes are built in memory, written to a temporary file created exclusively
//! with an unpredictable name beside `path`, fsynced and renamed over `path`, so a reader never sees
//! a partial file, a failed write leaves the old file intact, and a planted link is never followed.
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

mod io;
pub use io::{
    check_stem, check_target, dir_of, encode_png_quantized, read_exr, stem_of, to_u8, to_u8_quantized, with_ext,
    write_atomic, write_exr, write_png, write_png_quantized, ExrImage, Metadata, Quantize,
};

use std::ops::Range;

/// Why two films cannot merge or stored parts do not make a film.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FilmError {
    /// [`Film::merge`] of films of different sizes.
    #[error("merging a {other_w}x{other_h} film into a {w}x{h} one")]
    SizeMismatch {
        /// width of the receiving film
        w: u32,
        /// height of the receiving film
        h: u32,
        /// width of the film merged in
        other_w: u32,
        /// height of the film merged in
        other_h: u32,
    },
    /// [`Film::merge`] of ranges that do not touch.
    #[error("sample ranges {}..{} and {}..{} are not adjacent", .a.start, .a.end, .b.start, .b.end)]
    NotAdjacent {
        /// the receiving film's range
        a: Range<u32>,
        /// the other film's range
        b: Range<u32>,
    },
    /// [`Film::from_parts`] with blocks that are not the canonical ones.
    #[error("the block list is not the dyadic decomposition of samples {}..{}", .0.start, .0.end)]
    NotCanonical(Range<u32>),
    /// [`Film::from_parts`] with the wrong number of moments.
    #[error("{values} block values, expected {blocks} blocks x {width}x{height} pixels")]
    DataLength {
        /// moments given
        values: usize,
        /// blocks given
        blocks: usize,
        /// image width
        width: u32,
        /// image height
        height: u32,
    },
}

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

/// [`leaf_moments`] of 8 sample values at once, `[moment][lane]` from `[channel][lane]`: the same
/// values per lane, computed channel by channel (the loops vectorize).
#[inline(always)]
pub fn leaf_moments8(rgb: [[f32; 8]; 3]) -> [[f64; 8]; 6] {
    let mut m = [[0.0; 8]; 6];
    for (c, v) in rgb.iter().enumerate() {
        for i in 0..8 {
            let x = f64::from(v[i]);
            m[c][i] = x;
            m[c + 3][i] = x * x;
        }
    }
    m
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
    ) -> Result<Self, FilmError> {
        if canonical_blocks(samples.clone()) != blocks {
            return Err(FilmError::NotCanonical(samples));
        }
        let mut f = Film::new(width, height);
        if data.len() != blocks.len() * f.pixels() {
            return Err(FilmError::DataLength { values: data.len(), blocks: blocks.len(), width, height });
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
    pub fn merge(&mut self, other: &Film) -> Result<(), FilmError> {
        if (self.width, self.height) != (other.width, other.height) {
            return Err(FilmError::SizeMismatch {
                w: self.width,
                h: self.height,
                other_w: other.width,
                other_h: other.height,
            });
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
            return Err(FilmError::NotAdjacent { a: self.samples.clone(), b: other.samples.clone() });
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

#[cfg(test)]
mod tests;

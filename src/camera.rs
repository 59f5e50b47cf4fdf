//! Camera rays of a tile: the pixels of one 4x2 packet ([`PixelPacket`]), the packets covering a
//! tile ([`tile_packets`]), and [`Camera`], which turns a packet and a pixel sample index into
//! primary rays (pixel jitter from the pixel sampler, then the scene's pinhole lens).
//!
//! Layer: above `scene` and `sampler`, below `integrator` and `render` (both import it).

use crate::sampler::{PointSet, SamplerKind, Stream};
use crate::sampling::filter::FilterWarp;
use crate::scene::build::Camera as Lens;
use crate::scene::pinhole::Pinhole8;
use crate::simd::{mask_from_bools, u8_to_f8, Mask8, Vec3x8, F8, U8};

/// Sampler dimension of the camera (pixel) jitter.
pub const DIM_CAMERA: u32 = 0;
/// Packet footprint: 4 pixels wide, 2 tall.
pub const PACKET_W: u32 = 4;
/// Packet footprint height.
pub const PACKET_H: u32 = 2;

/// The pixels of one 4x2 packet: linear pixel ids, pixel coordinates and the in-image mask.
#[derive(Clone, Copy, Debug)]
pub struct PixelPacket {
    /// linear pixel index y * width + x (0 for lanes outside the image)
    pub pixel: U8,
    /// pixel x
    pub x: F8,
    /// pixel y
    pub y: F8,
    /// lanes inside the image
    pub active: Mask8,
}

impl PixelPacket {
    /// Packet whose top-left pixel is (x0, y0), clipped to a `width` x `height` image.
    pub fn new(x0: u32, y0: u32, width: u32, height: u32) -> Self {
        let mut pix = [0u32; 8];
        let mut inside = [false; 8];
        let mut xs = [0u32; 8];
        let mut ys = [0u32; 8];
        for i in 0..8u32 {
            let (x, y) = (x0 + i % PACKET_W, y0 + i / PACKET_W);
            xs[i as usize] = x;
            ys[i as usize] = y;
            if x < width && y < height {
                inside[i as usize] = true;
                pix[i as usize] = y * width + x;
            }
        }
        Self {
            pixel: U8::new(pix),
            x: u8_to_f8(U8::new(xs)),
            y: u8_to_f8(U8::new(ys)),
            active: mask_from_bools(inside),
        }
    }
}

/// The 4x2 packets covering the `tw` x `th` tile at (x0, y0) of a `w` x `h` image, row by row.
pub fn tile_packets(x0: u32, y0: u32, tw: u32, th: u32, w: u32, h: u32) -> Vec<PixelPacket> {
    (0..th.div_ceil(PACKET_H))
        .flat_map(|py| (0..tw.div_ceil(PACKET_W)).map(move |px| (px, py)))
        .map(|(px, py)| PixelPacket::new(x0 + px * PACKET_W, y0 + py * PACKET_H, w, h))
        .collect()
}

/// Primary ray generation: the scene's pinhole lens with the pixel jitter of a pixel sampler.
#[derive(Clone, Copy, Debug)]
pub struct Camera<'a> {
    /// the scene's pinhole camera
    pub lens: &'a crate::scene::build::Camera,
    /// pixel sample layout (over the spp samples of a pixel)
    pub pixel_set: &'a PointSet,
    /// base seed
    pub seed: u64,
    /// where pixel sample 0 goes
    pub first_sample: FirstSample,
    /// sample 0 goes through the pixel centre (`FirstSample::Centre`, not `grid-center`)
    centre: bool,
    /// with the centre and the stratified layout: the stratum holding the centre (`centre_stratum`)
    swap: Option<u32>,
    /// the `.test` camera (pinhole, box filter): its constants, splatted once
    pinhole: Option<Pinhole8>,
}

/// Where pixel sample 0 goes (`--first-sample`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FirstSample {
    /// Sample 0 through the pixel centre, as the CSE168 course code does (the default for `.test`
    /// scenes; at spp 1 the render is the course's deterministic one). With the stratified layout
    /// sample 0 takes the stratum that holds the centre (whose own sample takes sample 0's stratum),
    /// so the other samples keep one jittered point per stratum: the estimate is biased by
    /// (f(centre) - mean of f over that stratum) / spp, O(1/spp). `grid-center` is unchanged.
    Centre,
    /// Sample 0 is jittered like the others: strata's unbiased layout (the default for `.obj` scenes).
    Jittered,
}

impl FirstSample {
    /// "centre" | "center" | "jittered".
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim() {
            "centre" | "center" => Some(Self::Centre),
            "jittered" => Some(Self::Jittered),
            _ => None,
        }
    }

    /// Canonical name (accepted by `parse`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Centre => "centre",
            Self::Jittered => "jittered",
        }
    }
}

/// The stratum of an n-point stratified set that holds (0.5, 0.5) (cell (nx/2, ny/2) of
/// `strata_shape(n)`): when sample 0 is at the centre, it is sample 0's, so its own sample takes
/// stratum 0; every other sample keeps its stratum.
fn centre_stratum(n: u32) -> u32 {
    let (nx, ny) = crate::sampler::strata_shape(n);
    (ny / 2) * nx + nx / 2
}

impl<'a> Camera<'a> {
    /// The camera of lens `lens` drawing its pixel jitter from `pixel_set` (with `seed`), pixel
    /// sample 0 placed by `first_sample`; what every packet shares is found here once.
    pub fn new(lens: &'a Lens, pixel_set: &'a PointSet, seed: u64, first_sample: FirstSample) -> Self {
        let centre = first_sample == FirstSample::Centre && pixel_set.kind() != SamplerKind::GRID_CENTER;
        // Stratified and multijitter keep pixel point k in coarse cell (k % nx, k / nx).
        let cells = [SamplerKind::STRATIFIED, SamplerKind::MULTIJITTER].contains(&pixel_set.kind());
        let swap = (centre && cells).then(|| centre_stratum(pixel_set.n()));
        let pinhole =
            (lens.filter.is_none() && lens.lens == crate::scene::build::Lens::Pinhole).then(|| lens.pinhole());
        Self { lens, pixel_set, seed, first_sample, centre, swap, pinhole }
    }
}

impl Camera<'_> {
    /// Point `k` of the pixel set for the pixels of `pk` (sample 0, dimension [`DIM_CAMERA`]):
    /// the jitter of pixel sample `k`. Integrators draw it through their sample handle
    /// (`integrator::samples`), which profiles and logs the call.
    #[inline]
    pub fn point(&self, pk: &PixelPacket, k: u32) -> (F8, F8) {
        self.pixel_set.point_x8(pk.pixel, U8::splat(0), DIM_CAMERA, U8::splat(k), self.seed)
    }

    /// The pixel-sample stream of the pixels of `pk` (sample 0, dimension [`DIM_CAMERA`]): the
    /// per-pixel hashing of [`Camera::point`] done once for a batch of samples; point k of the
    /// stream equals `point(pk, k)` bit for bit.
    #[inline]
    pub fn stream(&self, pk: &PixelPacket) -> Stream<U8> {
        self.pixel_set.stream_x8(pk.pixel, U8::splat(0), DIM_CAMERA, self.seed)
    }

    /// Whether pixel sample `s` draws from the pixel sampler (sample 0 through the centre does not).
    pub fn draws(&self, s: u32) -> bool {
        !(self.centre && s == 0)
    }

    /// The point k of the pixel set that pixel sample `s` draws (the same for every packet), or
    /// None when it draws none (sample 0 through the pixel centre).
    #[inline]
    pub fn pixel_k(&self, s: u32) -> Option<u32> {
        if self.centre && s == 0 {
            return None;
        }
        // Stratified: the sample whose stratum holds the centre takes sample 0's stratum.
        Some(match self.swap {
            Some(c) if s % self.pixel_set.n() == c => 0,
            _ => s,
        })
    }

    /// The rays of packet `pk` for pixel sample `s` (origins and unit directions), with `point(k)`
    /// the pixel set's point k of the packet's pixels ([`Camera::point`], or a point of
    /// [`Camera::stream`]); not called for a sample that does not draw ([`Camera::draws`]).
    #[inline]
    pub fn rays_with(&self, pk: &PixelPacket, s: u32, point: impl FnOnce(u32) -> (F8, F8)) -> (Vec3x8, Vec3x8) {
        self.rays_k(pk, self.pixel_k(s), point)
    }

    /// [`Camera::rays_with`] for the point `k` = [`Camera::pixel_k`] of the pixel sample, found
    /// once for all the packets drawing it. Inlined always: called from two camera loops
    /// (`integrator::primary`), LLVM kept it out of line (110 instructions a packet more, the
    /// rays returned through memory).
    #[inline(always)]
    pub fn rays_k(&self, pk: &PixelPacket, k: Option<u32>, point: impl FnOnce(u32) -> (F8, F8)) -> (Vec3x8, Vec3x8) {
        let (jx, jy) = match k {
            None => (F8::splat(0.5), F8::splat(0.5)),
            Some(k) => point(k),
        };
        // The `.test` camera (pinhole, box filter) exactly as it always was: no other work.
        if let Some(pinhole) = &self.pinhole {
            return (pinhole.eye, pinhole.dirs8(pk.x + jx, pk.y + jy));
        }
        let (x, y) = match &self.lens.filter {
            None => (pk.x + jx, pk.y + jy),
            Some(f) => filtered(f, pk, (jx, jy), self.lens.width as f32, self.lens.height as f32),
        };
        self.lens.rays8(x, y)
    }
}

/// Image positions of the pixels of `pk` for the jitter `(jx, jy)` under the filter warp `f`:
/// the pixel centre plus an offset per axis drawn from the filter truncated to the image.
#[inline(never)]
fn filtered(f: &FilterWarp, pk: &PixelPacket, (jx, jy): (F8, F8), w: f32, h: f32) -> (F8, F8) {
    let one = |c: f32, u: f32, n: f32| {
        let centre = c + 0.5;
        centre + f.sample(u, -centre, n - centre)
    };
    let (px, py, ux, uy) = (pk.x.to_array(), pk.y.to_array(), jx.to_array(), jy.to_array());
    (F8::new(std::array::from_fn(|i| one(px[i], ux[i], w))), F8::new(std::array::from_fn(|i| one(py[i], uy[i], h))))
}

impl Camera<'_> {
    /// The image position of pixel `(px, py)`'s sample with jitter `(jx, jy)` (scalar twin of the
    /// filtered jitter of [`Camera::rays_with`]).
    pub fn position(&self, px: u32, py: u32, jx: f32, jy: f32) -> (f32, f32) {
        match &self.lens.filter {
            None => (px as f32 + jx, py as f32 + jy),
            Some(f) => {
                let (cx, cy) = (px as f32 + 0.5, py as f32 + 0.5);
                let (w, h) = (self.lens.width as f32, self.lens.height as f32);
                (cx + f.sample(jx, -cx, w - cx), cy + f.sample(jy, -cy, h - cy))
            }
        }
    }
}

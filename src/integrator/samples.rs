//! The sample handle: the only way an integrator draws a number. [`Samples`] (in
//! [`super::context::TileCtx`]) turns a declared dimension, a pixel and a sample index into a
//! point of the integrator's layouts (pixel, light or path, see [`Integrator`]) and, as `Tracer`
//! does for Embree, times each draw in the phase profiler (`sampler: pixel/camera`, `sampler:
//! light`, `sampler: path`) and reports it to the sampler replay log (`sampler::replay`). No
//! integrator calls the profiler's sampler phases or the replay log itself.
//!
//! Each integrator declares the dimensions it draws as [`Dim`]s (`Estimator::DIMS`), listed in
//! `docs/ARCHITECTURE.md` (a test checks the list).

use super::settings::Integrator;
use crate::camera::{Camera, PixelPacket, DIM_CAMERA};
use crate::profile::{self, Phase};
use crate::sampler::{replay, PathDim, PointK, Stream};
use crate::simd::{Mask8, Vec3x8, F8, U8};

/// Which layout a declared dimension is drawn from (the flag that overrides it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// the pixel layout (`--pixel-sampler`)
    Pixel,
    /// the light layout (`--light-sampler`)
    Light,
    /// the path layout (`--sampler` only)
    Path,
}

impl Source {
    /// The name used in `docs/ARCHITECTURE.md`'s dimension tables.
    pub fn name(self) -> &'static str {
        match self {
            Source::Pixel => "pixel",
            Source::Light => "light",
            Source::Path => "sampler",
        }
    }
}

/// One 2D sampler dimension an integrator draws: `first` for its first use, then every `stride`
/// (per path vertex; 0: used once per sample).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dim {
    /// what it samples
    pub name: &'static str,
    /// the sampler dimension of its first use
    pub first: u32,
    /// the step between uses (per vertex), 0 if used once
    pub stride: u32,
    /// the layout it comes from
    pub source: Source,
}

impl Dim {
    /// The sampler dimension of use `i` (vertex `i + 1` of a path).
    pub const fn at(&self, i: u32) -> u32 {
        self.first + self.stride * i
    }
}

/// The pixel jitter: every integrator's first dimension.
pub const CAMERA: Dim = Dim { name: "pixel jitter", first: DIM_CAMERA, stride: 0, source: Source::Pixel };

/// The sample handle of one tile: the integrator's layouts and the camera, drawing through the
/// profiler and the replay log.
pub struct Samples<'a> {
    it: &'a Integrator,
    camera: Camera<'a>,
}

impl<'a> Samples<'a> {
    /// The handle of integrator `it` with its camera `camera`.
    pub fn new(it: &'a Integrator, camera: Camera<'a>) -> Self {
        Self { it, camera }
    }

    /// Whether pixel sample `s` draws the pixel jitter (sample 0 through the centre does not).
    #[inline]
    pub fn camera_draws(&self, s: u32) -> bool {
        self.camera.draws(s)
    }

    /// Camera rays (origins, unit directions) of packet `pk` for pixel sample `s`.
    #[inline]
    pub fn camera_rays(&self, pk: &PixelPacket, s: u32) -> (Vec3x8, Vec3x8) {
        self.camera.rays_with(pk, s, |k| {
            let _p = profile::leaf(Phase::SamplerPixel);
            replay::pixel_point(pk.pixel, U8::splat(0), DIM_CAMERA, U8::splat(k));
            self.camera.point(pk, k)
        })
    }

    /// The pixel-sample streams of the packets `pks` (one per packet, in order) into `out`, for
    /// [`Samples::camera_rays_in`]: the per-pixel hashing done once for a batch of samples.
    pub fn camera_streams(&self, pks: &[PixelPacket], out: &mut Vec<Stream<U8>>) {
        let _p = profile::scope(Phase::SamplerPixel);
        out.clear();
        out.extend(pks.iter().map(|pk| self.camera.stream(pk)));
        replay::camera_streams(pks.iter().map(|pk| pk.pixel), U8::splat(0), DIM_CAMERA);
    }

    /// [`Samples::camera_rays`] of packet `i` of the packets of [`Samples::camera_streams`] (`pk`
    /// that packet, `stream` its stream) for the pixel sample whose point is `k` (from
    /// [`Samples::camera_k`]): the same rays, bit for bit. `at` is [`Samples::camera_point_k`] of
    /// that sample: the per-k work done once for every packet. Inlined always (as
    /// `Camera::rays_k`).
    #[inline(always)]
    pub fn camera_rays_in(
        &self,
        pk: &PixelPacket,
        i: u32,
        stream: &Stream<U8>,
        k: Option<u32>,
        at: Option<&PointK>,
    ) -> (Vec3x8, Vec3x8) {
        self.camera.rays_k(pk, k, |k| {
            let _p = profile::leaf(Phase::SamplerPixel);
            replay::camera_point(i, k);
            match at {
                Some(at) if at.k() == k => stream.point_k(at),
                _ => stream.point(k),
            }
        })
    }

    /// The point of the pixel set that pixel sample `s` draws (none: through the pixel centre),
    /// the same for every packet, for [`Samples::camera_rays_in`].
    #[inline]
    pub fn camera_k(&self, s: u32) -> Option<u32> {
        self.camera.pixel_k(s)
    }

    /// The per-k part of pixel sample `s`'s point in the camera streams (none when it draws
    /// none), for [`Samples::camera_rays_in`].
    pub fn camera_point_k(&self, s: u32) -> Option<PointK> {
        self.camera.pixel_k(s).map(|k| self.camera.pixel_set.point_k(k))
    }

    /// The light-layout streams of dimension `dim` for pixel sample `s` of the packets of `pks`
    /// that have lanes to shade (`shade`), in packet order, into `out` (per-pixel-sample grids:
    /// [`Integrator::light_streams`]). `fresh`: a new stream table for the replay log; otherwise
    /// appended to the last one (a second stream per packet, numbered after the first ones).
    pub fn light_streams(
        &self,
        pks: &[PixelPacket],
        shade: &[Mask8],
        s: u32,
        dim: u32,
        fresh: bool,
        out: &mut Vec<Stream<U8>>,
    ) {
        let _p = profile::scope(Phase::SamplerLight);
        let (it, sample) = (self.it, U8::splat(s));
        let shading = || pks.iter().zip(shade).filter(|(_, m)| m.any()).map(|(pk, _)| pk.pixel);
        out.clear();
        out.extend(shading().map(|pixel| it.light_set.stream_x8(pixel, sample, dim, it.seed)));
        if fresh {
            replay::light_streams(shading(), sample, dim);
        } else {
            replay::light_streams_append(shading(), sample, dim);
        }
    }

    /// Point `k` (`point_k` = the light layout's `point_k(k)`) of light stream `j` of the stream
    /// table (`stream` is that stream).
    #[inline]
    pub fn light_stream_point(&self, stream: &Stream<U8>, j: u32, k: u32, point_k: &PointK) -> (F8, F8) {
        let _p = profile::leaf(Phase::SamplerLight);
        replay::light_point(j, k);
        stream.point_k(point_k)
    }

    /// Dimension `dim` of the light table (`light`) or the path table, over `n` samples per pixel.
    #[inline]
    pub fn table_dim(&self, light: bool, n: u32, dim: u32) -> PathDim {
        let it = self.it;
        if light { &it.light_table } else { &it.path_set }.path_dim(n, dim, it.seed)
    }

    /// The streams of table dimension `d` (from [`Samples::table_dim`] with the same `light`) for
    /// the pixels of each packet of `pks`, in order, into `out`, for [`Samples::table_stream_point`]:
    /// the per-pixel hashing done once for every index. False (and `out` empty) when the table's
    /// layout is a grid, whose points are drawn by [`Samples::table_point`] only.
    pub fn table_streams(&self, d: &PathDim, light: bool, pks: &[PixelPacket], out: &mut Vec<Stream<U8>>) -> bool {
        let _p = profile::scope(if light { Phase::SamplerLight } else { Phase::SamplerPath });
        let it = self.it;
        let table = if light { &it.light_table } else { &it.path_set };
        out.clear();
        for pk in pks {
            match table.path_stream_x8(d, pk.pixel) {
                Some(s) => out.push(s),
                None => {
                    out.clear();
                    return false;
                }
            }
        }
        replay::table_streams(pks.iter().map(|pk| pk.pixel), light, d.dim());
        true
    }

    /// [`Samples::table_point`] at the lane-uniform table index `index` from stream `j` of
    /// [`Samples::table_streams`]' list (`stream` is that stream): the same point, bit for bit,
    /// timed the same and logged as the stream point it is.
    #[inline(always)]
    pub fn table_stream_point(&self, phase: Phase, stream: &Stream<U8>, j: u32, index: u32) -> (F8, F8) {
        let _p = profile::leaf(phase);
        replay::table_point(j, index);
        let _ = self;
        stream.point(index)
    }

    /// [`Samples::table_point`] of two table dimensions (`d` of the light table or the path
    /// table as `light` says, `e` as `e_light` says) for the same pixel samples: the same points,
    /// bit for bit, drawn by one call where the tables share their set (two chains interleaved).
    #[inline(always)]
    pub fn table_point_pair(
        &self,
        (d, light): (&PathDim, bool),
        (e, e_light): (&PathDim, bool),
        phase: Phase,
        pixel: U8,
        index: U8,
    ) -> [(F8, F8); 2] {
        let _p = profile::leaf(phase);
        replay::path_point_pair(pixel, index, [(d.dim(), light), (e.dim(), e_light)]);
        let it = self.it;
        let table = |l: bool| if l { &it.light_table } else { &it.path_set };
        table(light).path_point_pair_x8(d, table(e_light), e, pixel, index)
    }

    /// The 2D point of table dimension `d` (from [`Samples::table_dim`] with the same `light`) for
    /// the pixels `pixel` at table indices `index`, timed as `phase`.
    #[inline(always)]
    pub fn table_point(&self, d: &PathDim, light: bool, phase: Phase, pixel: U8, index: U8) -> (F8, F8) {
        let _p = profile::leaf(phase);
        replay::path_point(pixel, index, d.dim(), light);
        let it = self.it;
        if light { &it.light_table } else { &it.path_set }.path_point_x8(d, pixel, index)
    }
}

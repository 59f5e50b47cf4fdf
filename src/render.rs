//! Tiles, threads and accumulation: the only place with threads. (The tile's packets are made in
//! `camera`, their radiance in `integrator`; this module imports both, neither imports it.)
//!
//! The image is cut into 16x16-pixel tiles; a tile is cut into 4x2-pixel packets. Tiles run in
//! parallel under rayon; each pixel's samples are accumulated in f64 dyadic blocks (see `film`) in
//! increasing sample order, and every sample value is a pure function of (pixel, sample,
//! dimension, seed), so the image is bit-identical whatever the thread count or tile schedule.

pub use crate::camera::{tile_packets, PixelPacket, PACKET_H, PACKET_W};
use crate::film::{Block, Film, Moments};
use crate::integrator::{Counters, Integrator, Scratch};
use crate::scene::build::Scene;
use crate::simd::Vec3x8;
use accumulate::{Moments8, PassBlocks};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Instant;

mod accumulate;

/// Tile side in pixels.
pub const TILE: u32 = 16;
/// Pixel samples of a tile traced as one wavefront.
pub const SAMPLE_BATCH: u32 = 16;
/// What a render produced besides the film.
#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    /// wall-clock seconds of the sampling loop (scene build excluded)
    pub seconds: f64,
    /// ray and packet counters summed over threads
    pub counters: Counters,
    /// worker threads used
    pub threads: usize,
    /// CPU seconds the worker threads spent rendering tiles, summed over the workers
    pub cpu_seconds: f64,
    /// nanoseconds per [`crate::profile::Phase`] summed over the workers (zero unless profiling)
    pub phase_ns: [u64; crate::profile::N_PHASES],
    /// nanoseconds between tile start and end summed over the tiles, plus the film merge after
    /// them (zero unless profiling): what the phases split
    pub profiled_ns: u64,
    /// camera samples rendered (pixels x samples per pixel of this render)
    pub samples: u64,
    /// CPU seconds of the whole process over the passes (every thread: the tiles, the workers'
    /// waits between tiles, copying the film into tiles and merging them back): what
    /// [`RenderStats::cpu_seconds`] is part of
    pub process_cpu_seconds: f64,
}

impl RenderStats {
    /// Adds another render's times, counters, phases and samples to these (threads unchanged).
    pub fn merge(&mut self, o: &RenderStats) {
        self.seconds += o.seconds;
        self.cpu_seconds += o.cpu_seconds;
        self.counters.merge(&o.counters);
        for (a, b) in self.phase_ns.iter_mut().zip(&o.phase_ns) {
            *a += b;
        }
        self.profiled_ns += o.profiled_ns;
        self.samples += o.samples;
        self.process_cpu_seconds += o.process_cpu_seconds;
    }

    /// The share of the process's CPU time over the passes not spent in the tiles making samples:
    /// copying the film into tiles and merging them back, pass set-up, workers waiting at a pass's
    /// end (0 when nothing was measured).
    pub fn overhead_share(&self) -> f64 {
        if self.process_cpu_seconds > 0.0 {
            (1.0 - self.cpu_seconds / self.process_cpu_seconds).max(0.0)
        } else {
            0.0
        }
    }

    /// Rays traced per second over all kinds, in millions.
    pub fn mrays_per_sec(&self) -> f64 {
        self.counters.total_rays() as f64 / self.seconds.max(1e-12) / 1e6
    }
}

/// Errors of the render layer.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// the worker pool could not be built (message: rayon's)
    #[error("{0}")]
    ThreadPool(#[from] rayon::ThreadPoolBuildError),
}

/// Builds a rayon pool of `threads` workers (0 = all cores), each with FTZ/DAZ set.
pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool, RenderError> {
    Ok(rayon::ThreadPoolBuilder::new().num_threads(threads).start_handler(|_| crate::accel::set_ftz_daz()).build()?)
}

/// Renders samples `samples.start..samples.end` of every pixel into `film`, which accumulates:
/// `samples` must continue the film's range (start where it ends; any start for an empty film).
/// Panics otherwise (callers check ranges before rendering).
pub fn render(
    scene: &Scene,
    integrator: &Integrator,
    film: &mut Film,
    samples: std::ops::Range<u32>,
    pool: &rayon::ThreadPool,
) -> RenderStats {
    render_counted(scene, integrator, film, samples, pool, &AtomicU64::new(0))
}

/// [`render`], adding 1 to `tiles_done` as each tile finishes (a progress bar polls it): the
/// film is cut into tiles ([`TiledFilm::from_film`]), rendered, and written back.
pub fn render_counted(
    scene: &Scene,
    integrator: &Integrator,
    film: &mut Film,
    samples: std::ops::Range<u32>,
    pool: &rayon::ThreadPool,
    tiles_done: &AtomicU64,
) -> RenderStats {
    let have = film.samples();
    assert!(
        have.is_empty() || have.end == samples.start,
        "render: samples {samples:?} do not continue the film's {have:?}"
    );
    if samples.is_empty() {
        return RenderStats { threads: pool.current_num_threads(), ..Default::default() };
    }
    let (mut tiled, cut) = TiledFilm::from_film(film);
    let mut stats = render_tiled(scene, integrator, &mut tiled, samples, pool, tiles_done);
    stats.merge(&cut);
    stats.merge(&tiled.write_to(film));
    stats
}

/// A film kept as its tiles' states across passes: a pass renders each tile in place, with no
/// copy of the film into tiles before it nor merge after it; [`TiledFilm::write_to`] merges them
/// once (at the end of a run, or for a checkpoint). The same bits as [`render`] pass by pass.
pub struct TiledFilm {
    width: u32,
    height: u32,
    /// sample indices held
    samples: std::ops::Range<u32>,
    /// live blocks of `samples` (every tile's)
    blocks: Vec<Block>,
    tiles: Vec<TileResult>,
    /// each worker thread's buffers (by rayon's worker index), kept across tiles and passes
    workers: Vec<Mutex<Worker>>,
}

/// A worker thread's buffers, made once per worker and reused by every tile it renders (no
/// allocation or first touch of fresh memory per tile): the integrators' scratch, the batch's
/// radiance and the packets' block stacks.
#[derive(Default)]
struct Worker {
    scratch: Scratch,
    radiance: Vec<Vec3x8>,
    /// `stacks[p * height + level]`: packet p's stack during a tile
    stacks: Vec<Moments8>,
}

impl TiledFilm {
    /// The tiles of `film`'s current state, with the stats of the copy (process CPU seconds, and
    /// the film phase when profiling).
    pub fn from_film(film: &Film) -> (Self, RenderStats) {
        let (t, t0) = (crate::profile::enabled().then(Instant::now), cpu_time::ProcessTime::now());
        let (w, h) = (film.width, film.height);
        let tiles = (0..h.div_ceil(TILE))
            .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx, ty)))
            .map(|(tx, ty)| TileResult::from_film(film, tx * TILE, ty * TILE))
            .collect();
        let blocks = film.blocks().to_vec();
        let tiled = TiledFilm { width: w, height: h, samples: film.samples(), blocks, tiles, workers: Vec::new() };
        (tiled, overhead_stats(t, t0))
    }

    /// The sample indices held.
    pub fn samples(&self) -> std::ops::Range<u32> {
        self.samples.clone()
    }

    /// Writes the tiles' state into `film` (of the same size), with the stats of the merge.
    pub fn write_to(&self, film: &mut Film) -> RenderStats {
        let (t, t0) = (crate::profile::enabled().then(Instant::now), cpu_time::ProcessTime::now());
        assert_eq!((film.width, film.height), (self.width, self.height), "TiledFilm::write_to: another size");
        let n = film.pixels();
        film.drop_block_data(); // the tiles hold the blocks: peak memory 2x the state, not 3x
        let mut data = vec![[0.0; 6]; self.blocks.len() * n];
        for tile in &self.tiles {
            tile.store(&mut data, self.width, n);
        }
        film.set_state(self.samples.clone(), self.blocks.clone(), data);
        overhead_stats(t, t0)
    }
}

/// The stats of work outside the tiles that began at `t` (when profiling) and `t0`: its process
/// CPU seconds, and when profiling its wall time in the film phase and the profiled total.
fn overhead_stats(t: Option<Instant>, t0: cpu_time::ProcessTime) -> RenderStats {
    let mut st = RenderStats { process_cpu_seconds: t0.elapsed().as_secs_f64(), ..Default::default() };
    if let Some(t) = t {
        let ns = t.elapsed().as_nanos() as u64;
        st.phase_ns[crate::profile::Phase::Film as usize] += ns;
        st.profiled_ns += ns;
    }
    st
}

/// Renders samples `samples` of every pixel into `tiled`, which accumulates: `samples` must
/// continue its range (any start when it holds none). Panics otherwise. Adds 1 to `tiles_done`
/// as each tile finishes.
pub fn render_tiled(
    scene: &Scene,
    integrator: &Integrator,
    tiled: &mut TiledFilm,
    samples: std::ops::Range<u32>,
    pool: &rayon::ThreadPool,
    tiles_done: &AtomicU64,
) -> RenderStats {
    if integrator.kind == crate::scene::desc::IntegratorKind::ParticleTracer {
        return render_light(scene, integrator, tiled, samples, pool, tiles_done);
    }
    render_source(scene, integrator, tiled, samples, pool, tiles_done, None)
}

/// [`render_tiled`] with the pixel samples taken from `images` (the particle tracer's splat
/// images, one per sample of `samples`) instead of the integrator's tiles.
fn render_source(
    scene: &Scene,
    integrator: &Integrator,
    tiled: &mut TiledFilm,
    samples: std::ops::Range<u32>,
    pool: &rayon::ThreadPool,
    tiles_done: &AtomicU64,
    images: Option<&SplatImages>,
) -> RenderStats {
    let have = tiled.samples();
    assert!(
        have.is_empty() || have.end == samples.start,
        "render: samples {samples:?} do not continue the film's {have:?}"
    );
    let (w, h) = (tiled.width, tiled.height);
    let mut stats = RenderStats { threads: pool.current_num_threads(), ..Default::default() };
    if samples.is_empty() {
        return stats;
    }
    stats.samples = u64::from(w) * u64::from(h) * samples.len() as u64;
    let tiles_x = w.div_ceil(TILE);
    let start = Instant::now();
    let process_start = cpu_time::ProcessTime::now();
    if have.is_empty() {
        tiled.samples = samples.start..samples.start;
    }
    // The pass's block steps, the same for every pixel.
    let pass = PassBlocks::push(&mut tiled.blocks, samples.clone());
    // One buffer set per worker for the whole render (rayon's `map_init` would make one per job
    // split: many per render, each allocated and first touched again).
    let threads = pool.current_num_threads();
    if tiled.workers.len() < threads {
        tiled.workers.resize_with(threads, Default::default);
    }
    let (tiles, workers) = (&mut tiled.tiles, &tiled.workers);
    type Done = (Counters, f64, [u64; crate::profile::N_PHASES], u64);
    let results: Vec<Done> = pool.install(|| {
        tiles
            .par_iter_mut()
            .map(|tile| {
                let me = rayon::current_thread_index().expect("tiles run on the pool's workers");
                // (Only a tile that ran inside another on the same worker, which nothing does
                // today, would find the buffers taken: it gets fresh ones. Buffers never change
                // the values, so the image is the same whichever worker renders a tile.)
                let (mut guard, mut spare) = (workers[me].try_lock().ok(), None);
                let worker = match guard.as_deref_mut() {
                    Some(w) => w,
                    None => spare.insert(Worker::default()),
                };
                let t0 = cpu_time::ThreadTime::now();
                let profiling = crate::profile::enabled();
                let w0 = profiling.then(Instant::now);
                crate::profile::tile_begin();
                crate::sampler::replay::tile_begin(tile.y0 / TILE * tiles_x + tile.x0 / TILE);
                let mut counters = Counters::default();
                render_tile(scene, integrator, tile, (&pass, samples.clone()), worker, &mut counters, images);
                crate::sampler::replay::tile_end();
                let phases = crate::profile::tile_end();
                let wall = w0.map_or(0, |w| w.elapsed().as_nanos() as u64);
                tiles_done.fetch_add(1, Ordering::Relaxed);
                (counters, t0.elapsed().as_secs_f64(), phases, wall)
            })
            .collect()
    });
    stats.seconds = start.elapsed().as_secs_f64();
    for (c, busy, phases, wall) in &results {
        stats.counters.merge(c);
        stats.cpu_seconds += busy;
        stats.profiled_ns += wall;
        for (a, b) in stats.phase_ns.iter_mut().zip(phases) {
            *a += b;
        }
    }
    tiled.samples.end = samples.end;
    stats.process_cpu_seconds = process_start.elapsed().as_secs_f64();
    stats
}

/// Bytes of splat images the particle tracer holds at once (a pass with more samples is cut
/// into chunks of samples).
const SPLAT_IMAGE_BYTES: u64 = 256 << 20;

/// The particle tracer's pass (see `integrator/ptracer.rs`): for every sample, each tile's light
/// paths traced as one block (in parallel), their splats summed into the sample's image in block
/// order, then the images accumulated as the pixels' samples. Bit-identical whatever the thread
/// count, and whatever the split of samples into passes.
fn render_light(
    scene: &Scene,
    integrator: &Integrator,
    tiled: &mut TiledFilm,
    samples: std::ops::Range<u32>,
    pool: &rayon::ThreadPool,
    tiles_done: &AtomicU64,
) -> RenderStats {
    let process_start = cpu_time::ProcessTime::now();
    let (w, h) = (tiled.width, tiled.height);
    let pixels = u64::from(w) * u64::from(h);
    let chunk = (SPLAT_IMAGE_BYTES / (pixels * 12).max(1)).clamp(1, u64::from(u32::MAX)) as u32;
    let mut stats = RenderStats { threads: pool.current_num_threads(), ..Default::default() };
    let paths = crate::integrator::LightPaths::new(scene);
    let tiles_x = w.div_ceil(TILE);
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE)).flat_map(|ty| (0..tiles_x).map(move |tx| (tx, ty))).collect();
    let mut start = samples.start;
    while start < samples.end {
        let part = start..samples.end.min(start.saturating_add(chunk));
        let t0 = Instant::now();
        let blocks: Vec<(u32, u32, u32)> =
            part.clone().flat_map(|s| tiles.iter().map(move |&(tx, ty)| (s, tx, ty))).collect();
        type Traced = (Vec<crate::integrator::Splat>, Counters, f64, [u64; crate::profile::N_PHASES], u64);
        let traced: Vec<Traced> = pool.install(|| {
            blocks
                .par_iter()
                .map(|&(s, tx, ty)| {
                    let c0 = cpu_time::ThreadTime::now();
                    let w0 = crate::profile::enabled().then(Instant::now);
                    crate::profile::tile_begin();
                    let (x0, y0) = (tx * TILE, ty * TILE);
                    let pks = tile_packets(x0, y0, TILE.min(w - x0), TILE.min(h - y0), w, h);
                    let (mut splats, mut counters) = (Vec::new(), Counters::default());
                    integrator.splat_tile(scene, &paths, &pks, s, &mut splats, &mut counters);
                    let phases = crate::profile::tile_end();
                    let wall = w0.map_or(0, |w| w.elapsed().as_nanos() as u64);
                    (splats, counters, c0.elapsed().as_secs_f64(), phases, wall)
                })
                .collect()
        });
        let mut images = SplatImages { start: part.start, data: vec![vec![[0.0; 3]; pixels as usize]; part.len()] };
        for (&(s, _, _), (splats, c, busy, phases, wall)) in blocks.iter().zip(&traced) {
            for (a, b) in stats.phase_ns.iter_mut().zip(phases) {
                *a += b;
            }
            stats.profiled_ns += wall;
            let im = &mut images.data[(s - part.start) as usize];
            for sp in splats {
                let px = &mut im[sp.pixel as usize];
                for (a, b) in px.iter_mut().zip(sp.rgb) {
                    *a += b;
                }
            }
            stats.counters.merge(c);
            stats.cpu_seconds += busy;
        }
        let traced_secs = t0.elapsed().as_secs_f64();
        let st = render_source(scene, integrator, tiled, part.clone(), pool, tiles_done, Some(&images));
        stats.merge(&st);
        stats.seconds += traced_secs;
        start = part.end;
    }
    stats.process_cpu_seconds = process_start.elapsed().as_secs_f64();
    stats
}

/// The particle tracer's images of samples `start..start + data.len()`: `data[s - start][pixel]`.
pub(crate) struct SplatImages {
    start: u32,
    data: Vec<Vec<[f32; 3]>>,
}

impl SplatImages {
    /// The samples `batch` of the packets `pks`, sample-major as `Integrator::radiance_tile`
    /// writes them (lanes outside the image zero).
    fn fill(&self, pks: &[PixelPacket], batch: std::ops::Range<u32>, out: &mut Vec<Vec3x8>) {
        out.clear();
        for s in batch {
            let im = &self.data[(s - self.start) as usize];
            for pk in pks {
                let (pix, on) = (pk.pixel.to_array(), crate::simd::mask_to_bools(pk.active));
                let lanes: [glam::Vec3; 8] =
                    std::array::from_fn(
                        |i| if on[i] { glam::Vec3::from(im[pix[i] as usize]) } else { glam::Vec3::ZERO },
                    );
                out.push(Vec3x8::from_lanes(lanes));
            }
        }
    }
}

/// Accumulated samples of one tile: the film's dyadic blocks continued (the blocks are
/// `TiledFilm::blocks`; moments level-major, `data[level * tw * th + pixel in the tile]`).
struct TileResult {
    x0: u32,
    y0: u32,
    tw: u32,
    th: u32,
    data: Vec<Moments>,
}

impl TileResult {
    /// The film's current blocks for the tile at (x0, y0): samples continue the same binary
    /// counter, so an image is bit-identical however its samples are split into passes.
    fn from_film(film: &Film, x0: u32, y0: u32) -> Self {
        let (tw, th) = (TILE.min(film.width - x0), TILE.min(film.height - y0));
        let n = film.pixels();
        let src = film.block_data();
        let mut data = Vec::with_capacity(film.blocks().len() * (tw * th) as usize);
        for b in 0..film.blocks().len() {
            for ty in 0..th {
                let row = b * n + ((y0 + ty) * film.width + x0) as usize;
                data.extend_from_slice(&src[row..row + tw as usize]);
            }
        }
        Self { x0, y0, tw, th, data }
    }

    /// Writes the tile's blocks into the film-wide block-major array (`n` pixels, width `w`).
    fn store(&self, data: &mut [Moments], w: u32, n: usize) {
        let tn = (self.tw * self.th) as usize;
        for b in 0..self.data.len() / tn {
            for ty in 0..self.th {
                let i = b * tn + (ty * self.tw) as usize;
                let j = b * n + ((self.y0 + ty) * w + self.x0) as usize;
                data[j..j + self.tw as usize].copy_from_slice(&self.data[i..i + self.tw as usize]);
            }
        }
    }
}

/// Renders the samples of `pass` (the pass's block steps, and its sample range) of one tile and
/// accumulates them into the tile's blocks: each packet's block stack stays in `worker` through
/// the batches, loaded from the tile before them and stored after them (see `accumulate`).
fn render_tile(
    scene: &Scene,
    integrator: &Integrator,
    tile: &mut TileResult,
    (pass, samples): (&PassBlocks, std::ops::Range<u32>),
    worker: &mut Worker,
    counters: &mut Counters,
    images: Option<&SplatImages>,
) {
    let (x0, y0, tw, th) = (tile.x0, tile.y0, tile.tw, tile.th);
    let (w, h) = (scene.desc.width, scene.desc.height);
    let packets = tile_packets(x0, y0, tw, th, w, h);
    let (tn, origin) = ((tw * th) as usize, (x0, y0, tw));
    let Worker { scratch, radiance, stacks } = worker;
    let height = pass.height.max(1);
    if stacks.len() < packets.len() * height {
        stacks.resize(packets.len() * height, [[0.0; 8]; 6]);
    }
    let stacks = &mut stacks[..packets.len() * height];
    {
        let _acc = crate::profile::scope(crate::profile::Phase::Accumulate);
        for (pk, st) in packets.iter().zip(stacks.chunks_exact_mut(height)) {
            accumulate::load(&mut st[..pass.depth], &tile.data, tn, pk, origin);
        }
    }
    let (mut top, mut start) = (pass.depth, samples.start);
    while start < samples.end {
        // A batch of samples is one wavefront (full packets for the path tracer); samples are
        // still accumulated in increasing order.
        let batch = start..samples.end.min(start + SAMPLE_BATCH);
        match images {
            None => integrator.radiance_tile(scene, &packets, batch.clone(), radiance, scratch, counters, None),
            Some(im) => im.fill(&packets, batch.clone(), radiance),
        }
        let _acc = crate::profile::scope(crate::profile::Phase::Accumulate);
        let k = (start - samples.start) as usize;
        let carries = &pass.carries[k..k + batch.len()];
        for (p, (pk, st)) in packets.iter().zip(stacks.chunks_exact_mut(height)).enumerate() {
            let active = pk.active.to_bitmask();
            accumulate::add_batch(st, top, carries, (&radiance[p..], packets.len()), active, counters);
        }
        top = accumulate::top_after(top, carries);
        start = batch.end;
    }
    debug_assert_eq!(top, pass.levels);
    let _acc = crate::profile::scope(crate::profile::Phase::Accumulate);
    // Every pixel of the tile is an active lane of one packet, so `store` overwrites every entry
    // of the live levels: only entries beyond the old length need a value first (clearing and
    // zero-filling the whole tile per pass was a memset of the film, ~15 MB at 640 x 480).
    tile.data.truncate(pass.levels * tn);
    tile.data.resize(pass.levels * tn, [0.0; 6]);
    for (pk, st) in packets.iter().zip(stacks.chunks_exact(height)) {
        accumulate::store(&st[..pass.levels], &mut tile.data, tn, pk, origin);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::{push_block, Block};

    /// The tile loop's steps for one batch as one call (what the tests below run): the stack of
    /// `depth` levels loaded from `data`, the batch added, the levels after it stored back.
    #[allow(clippy::too_many_arguments)]
    fn accumulate(
        data: &mut [Moments],
        tn: usize,
        depth: usize,
        carries: &[usize],
        pk: &PixelPacket,
        origin: (u32, u32, u32),
        radiance: (&[Vec3x8], usize),
        stack: &mut Vec<Moments8>,
        counters: &mut Counters,
    ) {
        let carries: Vec<u8> = carries.iter().map(|&c| c as u8).collect();
        stack.resize(depth + carries.len(), [[0.0; 8]; 6]);
        accumulate::load(&mut stack[..depth], data, tn, pk, origin);
        if pk.active.to_bitmask() != 0 {
            accumulate::add_batch(stack, depth, &carries, radiance, pk.active.to_bitmask(), counters);
        }
        let top = accumulate::top_after(depth, &carries);
        accumulate::store(&stack[..top], data, tn, pk, origin);
    }
    use crate::simd::{Vec3x8, F8};

    /// Batches of samples accumulated packet-wise give the same block moments, bit for bit, as
    /// `Film::add_sample` one sample at a time (the scalar reference), non-finite values as zero.
    #[test]
    fn batched_accumulation_matches_the_scalar_film() {
        let pk = PixelPacket::new(0, 0, 4, 2);
        let mut st = 7u64;
        let mut next = || {
            st = st.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((st >> 40) as f32 / 16_777_216.0) * 3.0 - 0.5
        };
        let mut film = Film::new(4, 2);
        let (mut blocks, mut data, mut stack, mut c) = (Vec::new(), Vec::new(), Vec::new(), Counters::default());
        let mut s = 0u32;
        for batch in [1u32, 3, 16, 5, 16, 2] {
            let vals: Vec<Vec3x8> = (0..batch)
                .map(|k| {
                    let mut x: [f32; 8] = std::array::from_fn(|_| next());
                    if k == 1 {
                        x[2] = f32::NAN;
                    }
                    Vec3x8::new(F8::new(x), F8::new(std::array::from_fn(|_| next())), F8::splat(next()))
                })
                .collect();
            for (k, v) in vals.iter().enumerate() {
                let ok = v.is_finite().to_bitmask();
                let px: Vec<[f32; 3]> = (0..8)
                    .map(|i| {
                        if ok & (1 << i) != 0 {
                            [v.x.to_array()[i], v.y.to_array()[i], v.z.to_array()[i]]
                        } else {
                            [0.0; 3]
                        }
                    })
                    .collect();
                film.add_sample(s + k as u32, &px);
            }
            let depth = blocks.len();
            let carries: Vec<usize> = (s..s + batch).map(|t| push_block(&mut blocks, Block::leaf(t))).collect();
            data.resize(depth.max(blocks.len()) * 8, [0.0; 6]);
            accumulate(&mut data, 8, depth, &carries, &pk, (0, 0, 4), (&vals, 1), &mut stack, &mut c);
            data.truncate(blocks.len() * 8);
            s += batch;
            assert_eq!(blocks, film.blocks());
            let bits = |d: &[Moments]| d.iter().flatten().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&data), bits(film.block_data()), "after {s} samples");
        }
        assert_eq!(c.nonfinite, 5, "one NaN in each batch of two or more samples");
    }

    /// A NaN or infinite lane is counted in `nonfinite` and accumulated as zero; finite lanes and
    /// inactive lanes are untouched. (Without the check the NaN would reach the film's sums.)
    #[test]
    fn nonfinite_samples_are_counted_and_never_reach_the_film() {
        let pk = PixelPacket::new(0, 0, 3, 2); // a 4x2 packet clipped to 3 columns: lanes 3, 7 inactive
        let bad = [f32::NAN, f32::INFINITY, -f32::INFINITY, 1.0, 2.0, f32::NAN, 0.5, f32::NAN];
        let l = Vec3x8::new(F8::new(bad), F8::splat(1.0), F8::splat(1.0));
        // One leaf per pixel of the 3x2 tile, at stack depth 0 (no carries).
        let mut data = vec![[0.0f64; 6]; 6];
        let mut c = Counters::default();
        accumulate(&mut data, 6, 0, &[0], &pk, (0, 0, 3), (std::slice::from_ref(&l), 1), &mut Vec::new(), &mut c);
        assert_eq!(c.nonfinite, 4, "lanes 0, 1, 2 and 5 (lane 3 and 7 are outside the image)");
        assert!(data.iter().flatten().all(|v: &f64| v.is_finite()));
        let sum: Vec<[f64; 3]> = data.iter().map(|m| [m[0], m[1], m[2]]).collect();
        // Pixels (row-major in the 3-wide tile) of lanes 0, 1, 2, 4, 5, 6.
        assert_eq!(sum.iter().map(|p| p[0]).collect::<Vec<_>>(), [0.0, 0.0, 0.0, 2.0, 0.0, 0.5]);
        assert_eq!(sum[0], [0.0; 3], "a rejected sample is zero in every channel");
        assert_eq!(sum[3], [2.0, 1.0, 1.0]);
    }
}

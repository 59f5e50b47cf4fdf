//! The replay of a [`Recording`]: the logged calls made again in log order (`replay.rs` logs
//! them; this file decodes and draws them).

use super::*;

impl Recording {
    /// Makes the logged calls again in log order, drawing from `sets`, on this thread. Returns
    /// the calls made and a checksum of the points (which keeps the work from being optimized
    /// away; equal for equal sets).
    pub fn replay(&self, sets: &ReplaySets, mode: ReplayMode) -> (u64, u32) {
        let mut streams: Vec<Stream<U8>> = Vec::new();
        let mut cam_streams: Vec<Stream<U8>> = Vec::new();
        let mut table_streams: Vec<TableStream> = Vec::new();
        // The render finds point k's per-k work once for all its streams (`PointSet::point_k`,
        // then `Stream::point_k`): so does the replay, for the last k seen.
        let mut point_k = sets.light.point_k(0);
        let mut last_k = 0u32;
        let mut path_dims: Vec<Option<PathDim>> = Vec::new();
        let mut light_dims: Vec<Option<PathDim>> = Vec::new();
        // After a pair marker: the pair's first point (its table, dimension, pixels, samples)
        // waits for the second, and the two are drawn by one call.
        let (mut pair_next, mut pair_first): (bool, Option<(bool, PathDim)>) = (false, None);
        let (mut calls, mut sum) = (0u64, 0u32);
        let sample_on = mode == ReplayMode::Sample;
        for t in &self.tiles {
            let w = &t.words[..];
            let (mut pixel, mut sample) = (U8::splat(0), U8::splat(0));
            let mut i = 0;
            while i < w.len() {
                let op = w[i];
                i += 1;
                calls += 1;
                if op & 3 == OP_STREAM_POINT {
                    if op & F_TABLE != 0 && op & F_TABLE_RESET != 0 {
                        // A marker, not a call.
                        calls -= 1;
                        table_streams.clear();
                        continue;
                    }
                    if op & F_TABLE != 0 && op & F_TABLE_PAIR != 0 {
                        // A marker, not a call.
                        calls -= 1;
                        pair_next = sample_on;
                        continue;
                    }
                    let (si, k) = (w[i], w[i + 1]);
                    i += 2;
                    if op & F_TABLE != 0 {
                        sum = match (sample_on, table_streams.get(si as usize)) {
                            (true, Some(t)) => {
                                let (x, y) = match &t.stream {
                                    Some(s) => s.point(k),
                                    None => {
                                        let table = if t.light { &sets.light_table } else { &sets.path };
                                        table.path_point_x8(&t.d, t.pixel, U8::splat(k))
                                    }
                                };
                                fold(sum, x.to_bits() ^ y.to_bits())
                            }
                            _ => fold(sum, U8::splat(std::hint::black_box(si ^ k))),
                        };
                        continue;
                    }
                    if op & F_CAMERA != 0 {
                        if let (true, Some(s)) = (sample_on, cam_streams.get(si as usize)) {
                            let (x, y) = s.point(k);
                            sum = fold(sum, x.to_bits() ^ y.to_bits());
                        } else {
                            sum = fold(sum, U8::splat(std::hint::black_box(si ^ k)));
                        }
                        continue;
                    }
                    if let (true, Some(s)) = (sample_on, streams.get(si as usize)) {
                        if k != last_k {
                            (point_k, last_k) = (sets.light.point_k(k), k);
                        }
                        let (x, y) = s.point_k(&point_k);
                        sum = fold(sum, x.to_bits() ^ y.to_bits());
                    } else {
                        sum = fold(sum, U8::splat(std::hint::black_box(si ^ k)));
                    }
                    continue;
                }
                let mut dim = op >> DIM_SHIFT;
                if dim == DIM_WIDE {
                    dim = w[i];
                    i += 1;
                }
                if op & F_PIXEL_BLOCK != 0 {
                    pixel = U8::new(block(w[i], w[i + 1]));
                    i += 2;
                } else if op & F_PIXEL != 0 {
                    pixel = U8::new(lanes(&w[i..]));
                    i += 8;
                }
                if op & F_SAMPLE_SPLAT != 0 {
                    sample = U8::splat(w[i]);
                    i += 1;
                } else if op & F_SAMPLE != 0 {
                    sample = U8::new(lanes(&w[i..]));
                    i += 8;
                }
                let seed = sets.seed;
                match op & 3 {
                    OP_POINT => {
                        let k = if op & F_K_SPLAT != 0 {
                            i += 1;
                            U8::splat(w[i - 1])
                        } else {
                            i += 8;
                            U8::new(lanes(&w[i - 8..]))
                        };
                        sum = if sample_on {
                            let (x, y) = sets.pixel.point_x8(pixel, sample, dim, k, seed);
                            fold(sum, x.to_bits() ^ y.to_bits())
                        } else {
                            fold(sum, std::hint::black_box(pixel ^ sample ^ k ^ U8::splat(dim)))
                        };
                    }
                    OP_STREAM => {
                        let (table, set) = if op & F_CAMERA != 0 {
                            (&mut cam_streams, &sets.pixel)
                        } else {
                            (&mut streams, &sets.light)
                        };
                        if op & F_RESET != 0 {
                            table.clear();
                        }
                        if sample_on {
                            table.push(set.stream_x8(pixel, sample, dim, seed));
                        } else {
                            sum = fold(sum, std::hint::black_box(pixel ^ sample ^ U8::splat(dim)));
                        }
                    }
                    _ => {
                        sum = if sample_on {
                            // The render hoists a dimension's lane-uniform work out of its
                            // packets (once per bounce): so does the replay, once per dim.
                            let (table, n, dims) = if op & F_LIGHT_TABLE != 0 {
                                (&sets.light_table, sets.light_table.set().n(), &mut light_dims)
                            } else {
                                (&sets.path, sets.path_n, &mut path_dims)
                            };
                            let at = dim as usize;
                            if dims.len() <= at {
                                dims.resize(at + 1, None);
                            }
                            let d = *dims[at].get_or_insert_with(|| table.path_dim(n, dim, seed));
                            if op & F_TABLE_STREAM != 0 {
                                // A grid layout (replaying another kind's log) has no streams:
                                // its points are drawn one by one, and this op makes no call.
                                let stream = table.path_stream_x8(&d, pixel);
                                if stream.is_none() {
                                    calls -= 1;
                                }
                                table_streams.push(TableStream { stream, light: op & F_LIGHT_TABLE != 0, d, pixel });
                                continue;
                            }
                            let light = op & F_LIGHT_TABLE != 0;
                            if std::mem::take(&mut pair_next) {
                                pair_first = Some((light, d));
                                continue;
                            }
                            if let Some((first_light, first)) = pair_first.take() {
                                let t = |l: bool| if l { &sets.light_table } else { &sets.path };
                                let [(x0, y0), (x1, y1)] =
                                    t(first_light).path_point_pair_x8(&first, t(light), &d, pixel, sample);
                                fold(fold(sum, x0.to_bits() ^ y0.to_bits()), x1.to_bits() ^ y1.to_bits())
                            } else {
                                let (x, y) = table.path_point_x8(&d, pixel, sample);
                                fold(sum, x.to_bits() ^ y.to_bits())
                            }
                        } else {
                            fold(sum, std::hint::black_box(pixel ^ sample ^ U8::splat(dim)))
                        };
                    }
                }
            }
        }
        (calls, sum)
    }
}

/// A logged table stream as the replay's sets draw it: the stream, or (a grid layout, which has
/// none) its points one by one from the table (the light table's or the path table's), dimension
/// and pixels.
struct TableStream {
    stream: Option<Stream<U8>>,
    light: bool,
    d: PathDim,
    pixel: U8,
}

#[inline]
fn lanes(w: &[u32]) -> [u32; 8] {
    std::array::from_fn(|j| w[j])
}

#[inline]
fn fold(sum: u32, v: U8) -> u32 {
    v.to_array().iter().fold(sum.rotate_left(5), |a, &b| a ^ b)
}

//! Generic tests over every registered sampler, and the shared helpers' tests.

use super::divisor::Divisor;
use super::grid::{cell_coord, cell_span, centre_offset, jittered, FIXED_ONE};
use super::halton::{POW3_15, RADIX2, RADIX3};
use super::hash::{fmix, hash, mix, unit};
use super::sobol::tests::lcg;
use super::*;

fn u8_from(f: impl FnMut(usize) -> u32) -> U8 {
    U8::new(std::array::from_fn(f))
}

#[test]
fn kinds_parse_name_and_bias() {
    for kind in SamplerKind::ALL {
        assert_eq!(SamplerKind::parse(kind.name()), Some(kind));
        assert_eq!(kind.is_biased(), kind == SamplerKind::GRID_CENTER);
    }
    assert_eq!(SamplerKind::parse("random"), Some(SamplerKind::INDEPENDENT));
    assert_eq!(SamplerKind::parse("Jittered"), Some(SamplerKind::STRATIFIED));
    assert_eq!(SamplerKind::parse("grid"), Some(SamplerKind::GRID_CENTER));
    assert_eq!(SamplerKind::parse(" center "), Some(SamplerKind::GRID_CENTER));
    assert_eq!(SamplerKind::parse("pmj"), Some(SamplerKind::PMJ02));
    assert_eq!(SamplerKind::parse("owen"), None);
}

#[test]
fn strata_shapes() {
    let cases = [
        (0, (1, 1)),
        (1, (1, 1)),
        (2, (1, 2)),
        (4, (2, 2)),
        (6, (2, 3)),
        (7, (1, 7)),
        (9, (3, 3)),
        (12, (3, 4)),
        (16, (4, 4)),
        (25, (5, 5)),
        (36, (6, 6)),
        (u32::MAX, (65535, 65537)),
        (4_294_967_291, (1, 4_294_967_291)), // largest u32 prime
    ];
    for (n, shape) in cases {
        assert_eq!(strata_shape(n), shape, "n = {n}");
    }
}

#[test]
fn divisor_is_exact() {
    let mut st = 1u64;
    let mut ds = vec![1, 2, 3, 5, 6, 7, 9, 16, 25, 255, 641, 65535, 65537, 1 << 24, (1 << 24) + 1];
    ds.extend([1 << 31, (1 << 31) + 1, u32::MAX - 1, u32::MAX]);
    ds.extend((0..200).map(|_| lcg(&mut st) >> (lcg(&mut st) % 32)).map(|d| d.max(1)));
    for d in ds {
        let dv = Divisor::new(d);
        let mut xs = vec![0, 1, d - 1, d, d.wrapping_add(1), u32::MAX, u32::MAX - 1, u32::MAX / d * d];
        xs.extend((0..200).map(|_| lcg(&mut st)));
        for chunk in xs.chunks(8) {
            let lanes = u8_from(|i| chunk[i % chunk.len()]);
            let (q8, r8) = dv.div_rem(lanes);
            for (i, &x) in lanes.to_array().iter().enumerate() {
                assert_eq!(dv.div_rem(x), (x / d, x % d), "{x} / {d}");
                assert_eq!((q8.to_array()[i], r8.to_array()[i]), (x / d, x % d));
            }
        }
    }
}

#[test]
fn hash_scalar_and_x8_agree() {
    let mut st = 7u64;
    for _ in 0..1000 {
        let w: [u32; 8] = std::array::from_fn(|_| lcg(&mut st));
        let h: [u32; 8] = std::array::from_fn(|_| lcg(&mut st));
        let (h8, w8) = (U8::new(h), U8::new(w));
        let (f8, m8) = (fmix(h8).to_array(), mix(h8, w8).to_array());
        let seed = u64::from(lcg(&mut st)) << 32 | u64::from(lcg(&mut st));
        let hx = hash(TAG_UNIFORM, seed, w[0], [h8, w8]).to_array();
        for i in 0..8 {
            assert_eq!(f8[i], fmix(h[i]));
            assert_eq!(m8[i], mix(h[i], w[i]));
            assert_eq!(hx[i], hash(TAG_UNIFORM, seed, w[0], [h[i], w[i]]));
        }
    }
    // Avalanche: flipping any one input bit (of the state or of the word) flips ~16 output bits.
    for bit in 0..32 {
        let (mut flips_h, mut flips_w) = (0u32, 0u32);
        for _ in 0..2000 {
            let (h, w) = (lcg(&mut st), lcg(&mut st));
            flips_h += (mix(h, w) ^ mix(h ^ 1 << bit, w)).count_ones();
            flips_w += (mix(h, w) ^ mix(h, w ^ 1 << bit)).count_ones();
        }
        for f in [flips_h, flips_w] {
            let mean = f as f64 / 2000.0;
            assert!((15.5..16.5).contains(&mean), "bit {bit}: {mean} bits flip on average");
        }
    }
}

fn interesting_n() -> Vec<u32> {
    vec![0, 1, 2, 3, 5, 6, 7, 16, 36, 1000, 1 << 20, (1 << 24) + 1, u32::MAX]
}

#[test]
fn all_values_in_unit_interval() {
    let specials = [0, 1, 2, 0x7fff_ffff, 0x8000_0000, u32::MAX - 1, u32::MAX];
    let ok = |v: f32| (0.0..1.0).contains(&v);
    let mut st = 3u64;
    for kind in SamplerKind::ALL {
        for n in interesting_n() {
            let set = PointSet::new(kind, n);
            for &seed in &[0, 1, u64::MAX, 0xdead_beef_0123_4567] {
                for &a in &specials {
                    for &b in &specials {
                        let k = lcg(&mut st);
                        for (p, s, d, k) in [(a, b, k, a), (b, a, a, b), (k, a, b, b), (a, a, a, k)] {
                            let [x, y] = set.point(p, s, d, k, seed);
                            assert!(ok(x) && ok(y), "{kind:?} n={n} ({p},{s},{d},{k}) -> {x},{y}");
                            assert!(ok(uniform_1d(p, s, d, k, seed)));
                        }
                    }
                }
            }
        }
    }
    // Largest possible fixed-point values still map below 1.
    assert!(ok(RADIX3.to_fixed24(POW3_15 as u32 - 1).unit24()));
    assert!(ok(RADIX2.to_fixed24(FIXED_ONE - 1).unit24()));
    assert!(ok(unit(u32::MAX)));
}

#[test]
fn x8_is_bit_identical_to_scalar() {
    let mut st = 11u64;
    for kind in SamplerKind::ALL {
        for n in interesting_n() {
            let set = PointSet::new(kind, n);
            for round in 0..40 {
                let seed = u64::from(lcg(&mut st)) << 32 | u64::from(lcg(&mut st));
                let dim = if round % 5 == 0 { u32::MAX } else { lcg(&mut st) % 64 };
                let pixel = u8_from(|i| if i == 7 { u32::MAX } else { lcg(&mut st) % 100_000 });
                let sample = u8_from(|i| if i == 6 { u32::MAX } else { lcg(&mut st) % 256 });
                let k = u8_from(|i| match i {
                    5 => u32::MAX,
                    4 => n.wrapping_add(3), // k >= n
                    _ => lcg(&mut st) % n.max(1),
                });
                let (x8, y8) = set.point_x8(pixel, sample, dim, k, seed);
                let (x8b, y8b) = point_2d_x8(kind, pixel, sample, dim, k, n, seed);
                let u8v = uniform_1d_x8(pixel, sample, dim, k, seed).to_array();
                let (p, s, kk) = (pixel.to_array(), sample.to_array(), k.to_array());
                for i in 0..8 {
                    let [x, y] = point_2d(kind, p[i], s[i], dim, kk[i], n, seed);
                    assert_eq!(x.to_bits(), x8.to_array()[i].to_bits(), "{kind:?} n={n} lane {i}");
                    assert_eq!(y.to_bits(), y8.to_array()[i].to_bits(), "{kind:?} n={n} lane {i}");
                    assert_eq!(x8b.to_array()[i].to_bits(), x.to_bits());
                    assert_eq!(y8b.to_array()[i].to_bits(), y.to_bits());
                    assert_eq!(uniform_1d(p[i], s[i], dim, kk[i], seed).to_bits(), u8v[i].to_bits());
                }
            }
        }
    }
}

#[test]
fn permute_x8_and_grid_table_equal_their_scalar_forms_bit_for_bit() {
    let mut st = 11u64;
    for n in interesting_n() {
        for _ in 0..20 {
            let i = u8_from(|l| if l == 7 { u32::MAX } else { lcg(&mut st) % (2 * n.max(1)) });
            let key = u8_from(|_| lcg(&mut st));
            let p = permute_x8(i, n, key).to_array();
            let (ia, ka) = (i.to_array(), key.to_array());
            for l in 0..8 {
                assert_eq!(p[l], permute(ia[l], n, ka[l]), "n={n} lane {l}");
            }
        }
        for kind in SamplerKind::ALL {
            let set = PointSet::new(kind, n);
            let table = GridTable::new(set);
            let seed = u64::from(lcg(&mut st)) << 32 | u64::from(lcg(&mut st));
            for dim in [0, 3, 64] {
                let pixel = u8_from(|_| lcg(&mut st) % 100_000);
                let sample = u8_from(|_| lcg(&mut st) % 64);
                let k = u8_from(|l| if l == 0 { u32::MAX } else { lcg(&mut st) % (3 * n.max(1)) });
                let (tx, ty) = table.point_x8(pixel, sample, dim, k, seed);
                let (sx, sy) = set.point_x8(pixel, sample, dim, k, seed);
                assert_eq!(tx.to_array().map(f32::to_bits), sx.to_array().map(f32::to_bits), "{kind:?} n={n}");
                assert_eq!(ty.to_array().map(f32::to_bits), sy.to_array().map(f32::to_bits), "{kind:?} n={n}");
                let (p, s, kk) = (pixel.to_array(), sample.to_array(), k.to_array());
                for l in 0..8 {
                    let q = table.point(p[l], s[l], dim, kk[l], seed);
                    assert_eq!(q.map(f32::to_bits), set.point(p[l], s[l], dim, kk[l], seed).map(f32::to_bits));
                }
            }
        }
    }
}

/// The path tracer's hoisted points (`GridTable::path_dim` + `path_point_x8`) equal the
/// per-call form `point_x8(pixel, 0, dim, shuffled_index_x8(..))` (grids) or
/// `point_x8(pixel, 0, dim, s)` (sequences) bit for bit, for every layout,
/// with the spp equal to, above and below the set's n (and the equal-time `u32::MAX`).
#[test]
fn path_points_with_hoisted_dimensions_equal_the_per_call_form() {
    let mut st = 29u64;
    for n in interesting_n() {
        for kind in SamplerKind::ALL {
            let table = GridTable::new(PointSet::new(kind, n));
            for spp in [n, n + 3, n / 2, u32::MAX] {
                let seed = u64::from(lcg(&mut st)) << 32 | u64::from(lcg(&mut st));
                for dim in [64, 65, 130] {
                    let d = table.path_dim(spp, dim, seed);
                    assert_eq!(d.dim(), dim);
                    let pixel = u8_from(|_| lcg(&mut st) % 100_000);
                    let s = u8_from(|l| if l == 7 { u32::MAX } else { lcg(&mut st) % spp.max(1) });
                    let k = shuffled_index_x8(s, spp, pixel, dim, seed);
                    assert_eq!(k.to_array(), ShuffleKey::new(spp, dim, seed).index_x8(s, pixel).to_array());
                    let k = if table.is_grid() { k } else { s };
                    let (ex, ey) = table.point_x8(pixel, U8::splat(0), dim, k, seed);
                    let (x, y) = table.path_point_x8(&d, pixel, s);
                    assert_eq!(x.to_array().map(f32::to_bits), ex.to_array().map(f32::to_bits), "{kind:?} n={n}");
                    assert_eq!(y.to_array().map(f32::to_bits), ey.to_array().map(f32::to_bits), "{kind:?} n={n}");
                }
            }
        }
    }
}

/// Two dimensions drawn by one call (`PointSet::point_pair_x8`, whose `multijitter` runs the two
/// chains interleaved on `Pair` lanes) equal two `point_x8` calls bit for bit, for every layout
/// and set size, with the camera's dimension (which skips `multijitter`'s index permutation) on
/// either side, equal dimensions, and indices at and beyond n; and the path tracer's pair across
/// two tables (`GridTable::path_point_pair_x8`) equals its two points, whether the tables share a
/// set (one call) or not (two).
#[test]
fn point_pairs_equal_two_points_bit_for_bit() {
    let bits = |p: (F8, F8)| (p.0.to_array().map(f32::to_bits), p.1.to_array().map(f32::to_bits));
    let mut st = 41u64;
    for n in interesting_n() {
        for kind in SamplerKind::ALL {
            let set = PointSet::new(kind, n);
            for dims in [[3, 4], [0, 7], [9, 0], [5, 5], [u32::MAX, 1]] {
                let seed = u64::from(lcg(&mut st)) << 32 | u64::from(lcg(&mut st));
                let pixel = u8_from(|_| lcg(&mut st) % 100_000);
                let sample = u8_from(|l| if l == 6 { u32::MAX } else { lcg(&mut st) % 64 });
                let k: [U8; 2] = std::array::from_fn(|_| {
                    u8_from(|l| match l {
                        5 => u32::MAX,
                        4 => n.wrapping_add(3),
                        _ => lcg(&mut st) % n.max(1),
                    })
                });
                let pair = set.point_pair_x8(pixel, sample, dims, k, seed);
                for j in 0..2 {
                    let one = set.point_x8(pixel, sample, dims[j], k[j], seed);
                    assert_eq!(bits(pair[j]), bits(one), "{kind:?} n={n} dims {dims:?} point {j}");
                }
            }
        }
        for (a, b, nb) in [
            (SamplerKind::MULTIJITTER, SamplerKind::MULTIJITTER, n),
            (SamplerKind::MULTIJITTER, SamplerKind::MULTIJITTER, n / 2 + 1),
            (SamplerKind::SOBOL, SamplerKind::MULTIJITTER, n),
            (SamplerKind::STRATIFIED, SamplerKind::STRATIFIED, n),
        ] {
            let (ta, tb) = (GridTable::new(PointSet::new(a, n)), GridTable::new(PointSet::new(b, nb)));
            let seed = u64::from(lcg(&mut st)) << 32 | u64::from(lcg(&mut st));
            let spp = n.max(1);
            let (d, e) = (ta.path_dim(spp, 64, seed), tb.path_dim(spp, 66, seed));
            let pixel = u8_from(|_| lcg(&mut st) % 100_000);
            let s = u8_from(|l| if l == 7 { u32::MAX } else { lcg(&mut st) % spp });
            let [p, q] = ta.path_point_pair_x8(&d, &tb, &e, pixel, s);
            assert_eq!(bits(p), bits(ta.path_point_x8(&d, pixel, s)), "{a:?} {b:?} n={n}");
            assert_eq!(bits(q), bits(tb.path_point_x8(&e, pixel, s)), "{a:?} {b:?} n={n}");
        }
    }
}

/// Unbiasedness of shuffled strata needs, for a fixed sample index, the strata two dimensions
/// give it to be jointly uniform over pixels (keys): chi-square of the (dim a, dim b) stratum
/// pairs over 20000 pixel keys, derived as the path tracer derives them, for every sample
/// index, at small n where a weak keyed family shows most.
#[test]
fn shuffled_strata_of_two_dimensions_are_jointly_uniform_over_pixels() {
    let pixels = 20_000u32;
    for n in [2u32, 3, 4, 5, 8, 10] {
        let cells = (n * n) as usize;
        for s in 0..n {
            let mut count = vec![0u32; cells];
            for p in 0..pixels {
                let key = |dim: u32| dim.wrapping_mul(0x85eb_ca77) ^ p.wrapping_mul(0x9e37_79b1);
                let (a, b) = (permute(s, n, key(66)), permute(s, n, key(67)));
                count[(a * n + b) as usize] += 1;
            }
            let e = f64::from(pixels) / cells as f64;
            let chi2: f64 = count.iter().map(|&c| (f64::from(c) - e).powi(2) / e).sum();
            // dof = n^2 - 1; accept below mean + 6 sd (false alarm far below 1e-6).
            let dof = (cells - 1) as f64;
            assert!(chi2 < dof + 6.0 * (2.0 * dof).sqrt(), "n={n} s={s}: chi2 {chi2:.0} on {dof} dof");
        }
    }
}

#[test]
fn permute_is_a_bijection_for_every_size_and_key() {
    for n in [1u32, 2, 3, 5, 7, 8, 9, 16, 17, 64, 100, 1000, 4097] {
        for key in [0u32, 1, 0xdead_beef, u32::MAX] {
            let mut seen = vec![false; n as usize];
            for i in 0..n {
                let p = permute(i, n, key);
                assert!(p < n && !seen[p as usize], "n={n} key={key} i={i}");
                seen[p as usize] = true;
            }
        }
    }
    // Different keys give different permutations (n = 16: all 16! are possible).
    let a: Vec<u32> = (0..16).map(|i| permute(i, 16, 1)).collect();
    let b: Vec<u32> = (0..16).map(|i| permute(i, 16, 2)).collect();
    assert_ne!(a, b);
    assert_ne!(a, (0..16).collect::<Vec<_>>());
}

#[test]
fn streams_equal_points_bit_for_bit() {
    let mut st = 5u64;
    for kind in SamplerKind::ALL {
        for n in interesting_n() {
            let set = PointSet::new(kind, n);
            for _ in 0..10 {
                let seed = u64::from(lcg(&mut st)) << 32 | u64::from(lcg(&mut st));
                let dim = lcg(&mut st) % 64;
                let pixel = u8_from(|i| if i == 7 { u32::MAX } else { lcg(&mut st) % 100_000 });
                let sample = u8_from(|_| lcg(&mut st) % 256);
                let st8 = set.stream_x8(pixel, sample, dim, seed);
                let (p, s) = (pixel.to_array(), sample.to_array());
                let st1 = set.stream_1(p[3], s[3], dim, seed);
                for k in [0, 1, n / 2, n.saturating_sub(1), n.wrapping_add(3), u32::MAX] {
                    let (x8, y8) = st8.point(k);
                    let (xk, yk) = st8.point_k(&set.point_k(k));
                    assert_eq!(
                        (x8.to_array().map(f32::to_bits), y8.to_array().map(f32::to_bits)),
                        (xk.to_array().map(f32::to_bits), yk.to_array().map(f32::to_bits)),
                        "point_k: {kind:?} n={n} k={k}"
                    );
                    let (xr, yr) = set.point_x8(pixel, sample, dim, U8::splat(k), seed);
                    assert_eq!(
                        x8.to_array().map(f32::to_bits),
                        xr.to_array().map(f32::to_bits),
                        "{kind:?} n={n} k={k}"
                    );
                    assert_eq!(
                        y8.to_array().map(f32::to_bits),
                        yr.to_array().map(f32::to_bits),
                        "{kind:?} n={n} k={k}"
                    );
                    let (x1, y1) = st1.point(k);
                    assert_eq!((x1.to_bits(), y1.to_bits()), (x8.to_array()[3].to_bits(), y8.to_array()[3].to_bits()));
                }
            }
        }
    }
}

#[test]
fn deterministic_and_sensitive_to_seed_and_dim() {
    for kind in SamplerKind::ALL {
        let set = PointSet::new(kind, 16);
        for pixel in 0..200 {
            let (s, k) = (pixel % 7, pixel % 16);
            let base = set.point(pixel, s, 3, k, 42);
            assert_eq!(base, set.point(pixel, s, 3, k, 42));
            assert_eq!(base, point_2d(kind, pixel, s, 3, k, 16, 42));
            let other_seed = set.point(pixel, s, 3, k, 43);
            let other_dim = set.point(pixel, s, 4, k, 42);
            if kind == SamplerKind::GRID_CENTER {
                // Centres do not depend on anything random.
                assert_eq!(base, other_seed);
                assert_eq!(base, other_dim);
                assert_eq!(base, set.point(pixel + 1, s + 1, 3, k, 42));
            } else {
                assert_ne!(base, other_seed, "{kind:?} pixel {pixel}");
                assert_ne!(base, other_dim, "{kind:?} pixel {pixel}");
            }
        }
    }
    let u = uniform_1d(5, 6, 7, 8, 9);
    assert_eq!(u, uniform_1d(5, 6, 7, 8, 9));
    assert_ne!(u, uniform_1d(5, 6, 7, 8, 10));
    assert_ne!(u, uniform_1d(5, 6, 8, 8, 9));
    // Different generators use different streams.
    assert_ne!(u, point_2d(SamplerKind::INDEPENDENT, 5, 6, 7, 8, 16, 9)[0]);
}

#[test]
fn zero_n_and_wrapping_k() {
    for kind in SamplerKind::ALL {
        for k in [0, 1, 5] {
            assert_eq!(point_2d(kind, 3, 4, 5, k, 0, 6), point_2d(kind, 3, 4, 5, k, 1, 6));
        }
    }
    for kind in [SamplerKind::STRATIFIED, SamplerKind::GRID_CENTER] {
        for n in [1, 6, 7, 16] {
            for k in 0..n {
                let p = point_2d(kind, 9, 2, 1, k, n, 77);
                assert_eq!(p, point_2d(kind, 9, 2, 1, k + n, n, 77));
                assert_eq!(p, point_2d(kind, 9, 2, 1, k + 5 * n, n, 77));
            }
        }
    }
    // Halton: k >= n continues into the next pixel sample's points.
    for k in 0..6 {
        assert_eq!(
            point_2d(SamplerKind::HALTON, 9, 3, 1, k, 6, 5),
            point_2d(SamplerKind::HALTON, 9, 2, 1, k + 6, 6, 5)
        );
    }
}

/// Exact cell of a coordinate on an m-cell axis (x is 24-bit fixed point, so f64 is exact).
fn cell(x: f32, m: u32) -> u32 {
    (f64::from(x) * f64::from(m)).floor() as u32
}

#[test]
fn stratified_one_point_per_cell_and_grid_centres() {
    for n in [1, 2, 4, 6, 9, 16, 25, 7, 12, 64, 1000] {
        let (nx, ny) = strata_shape(n);
        for pixel in [0, 1, 17, 123_456, u32::MAX] {
            for sample in [0, 3] {
                let mut seen = vec![false; n as usize];
                for k in 0..n {
                    let [x, y] = point_2d(SamplerKind::STRATIFIED, pixel, sample, 2, k, n, 99);
                    let (cx, cy) = (cell(x, nx), cell(y, ny));
                    assert_eq!((cx, cy), (k % nx, k / nx), "n={n} k={k}");
                    seen[(cy * nx + cx) as usize] = true;
                }
                assert!(seen.iter().all(|&s| s));
            }
        }
        for k in 0..n {
            let [x, y] = point_2d(SamplerKind::GRID_CENTER, 5, 0, 0, k, n, 1);
            let (ex, ey) = ((f64::from(k % nx) + 0.5) / f64::from(nx), (f64::from(k / nx) + 0.5) / f64::from(ny));
            // Exact for power-of-two axes, else the centre rounded down to the 2^-24 grid.
            let tol = 1.0 / f64::from(FIXED_ONE);
            assert!(f64::from(x) <= ex && ex - f64::from(x) < tol, "n={n} k={k} x={x} vs {ex}");
            assert!(f64::from(y) <= ey && ey - f64::from(y) < tol, "n={n} k={k} y={y} vs {ey}");
            if nx.is_power_of_two() && ny.is_power_of_two() {
                assert_eq!((f64::from(x), f64::from(y)), (ex, ey));
            }
        }
    }
    // Extreme jitter values stay inside their cells for many axis sizes.
    for m in [1, 2, 3, 7, 255, 256, 1000, 65535, 65537, (1 << 23) + 3, FIXED_ONE] {
        let dv = Divisor::new(m);
        for c in [0, 1, m / 2, m - 1] {
            for h in [0, 1, u32::MAX / 2, u32::MAX] {
                let c = c.min(m - 1);
                let y = (jittered(cell_span(c, dv), h) * FIXED_ONE as f32) as u32;
                assert!(u64::from(y) * u64::from(m) >= u64::from(c) << 24, "m={m} c={c}");
                assert!(u64::from(y) * u64::from(m) < u64::from(c + 1) << 24, "m={m} c={c}");
                let yc = cell_coord(c, dv, centre_offset(m));
                assert!(u64::from(yc) * u64::from(m) >= u64::from(c) << 24, "centre m={m} c={c}");
                assert!(u64::from(yc) * u64::from(m) < u64::from(c + 1) << 24, "centre m={m} c={c}");
            }
        }
    }
}

/// `cell_span` is `[ceil(c 2^24 / m), ceil((c+1) 2^24 / m))` exactly on both of its paths (two
/// digits of division and a carry up to 2^16 cells, long division above): every cell of every
/// axis up to 300 cells, 20,000 random cells of axes up to 2^16 + 300, the edges of 2^16, scalar
/// and per lane.
#[test]
fn cell_span_is_exact() {
    let ceil = |c: u32, m: u32| (u64::from(c) << 24).div_ceil(u64::from(m)) as u32;
    let want = |c: u32, m: u32| (ceil(c, m), ceil(c + 1, m));
    let mut cases: Vec<(u32, u32)> = (1..=300).flat_map(|m| (0..m).map(move |c| (c, m))).collect();
    for m in [(1 << 16) - 1, 1 << 16, (1 << 16) + 1] {
        cases.extend([0, 1, m / 2, m - 2, m - 1].map(|c| (c, m)));
    }
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for _ in 0..20_000 {
        let m = 1 + lcg(&mut state) % ((1 << 16) + 300);
        cases.push((lcg(&mut state) % m, m));
    }
    for &(c, m) in &cases {
        assert_eq!(cell_span(c, Divisor::new(m)), want(c, m), "m={m} c={c}");
    }
    for chunk in cases.chunks(8).filter(|ch| ch.iter().all(|&(_, m)| m == ch[0].1)) {
        let m = chunk[0].1;
        let c = u8_from(|i| chunk[i % chunk.len()].0);
        let (lo, hi) = cell_span(c, Divisor::new(m));
        for (i, (l, h)) in lo.to_array().into_iter().zip(hi.to_array()).enumerate() {
            assert_eq!((l, h), want(chunk[i % chunk.len()].0, m), "x8: m={m}");
        }
    }
}

#[test]
fn base3_fixed_point_stays_in_its_cell_exhaustively() {
    for r in 0..POW3_15 as u32 {
        let y = u64::from(RADIX3.to_fixed24(r));
        assert!(y * POW3_15 >= u64::from(r) << 24, "R = {r}");
        assert!(y * POW3_15 < u64::from(r + 1) << 24, "R = {r}");
    }
    assert_eq!(RADIX3.to_fixed24(0u32), 0);
    for r in [0, 1, 2, FIXED_ONE - 1, 12345] {
        assert_eq!(RADIX2.to_fixed24(r), r);
    }
    let rs = u8_from(|i| [0, 1, 2, 3, 4_782_969, 9_565_938, POW3_15 as u32 - 2, POW3_15 as u32 - 1][i]);
    let y8 = RADIX3.to_fixed24(rs).to_array();
    for (i, r) in rs.to_array().into_iter().enumerate() {
        assert_eq!(y8[i], RADIX3.to_fixed24(r));
    }
}

#[test]
fn radical_inverse_known_values() {
    let b2 = (0..4).map(|i| radical_inverse(2, i).unwrap()).collect::<Vec<_>>();
    assert_eq!(b2, [0.0, 0.5, 0.25, 0.75]);
    assert_eq!(radical_inverse(2, 5), Some(0.625));
    let expect3 = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0 / 9.0, 4.0 / 9.0, 7.0 / 9.0];
    for (i, e) in expect3.into_iter().enumerate() {
        let v = f64::from(radical_inverse(3, i as u32).unwrap());
        assert!(v >= e - 1e-12 && v - e < 1.0 / f64::from(FIXED_ONE), "base 3, i={i}: {v} vs {e}");
    }
    assert_eq!(radical_inverse(3, 0), Some(0.0));
    assert_eq!(radical_inverse(5, 1), None);
}

/// Checks one Halton point per 2^-a x 3^-b box in several blocks of n = 2^a 3^b consecutive points
/// (pixel samples 0, 1, 2, 7, 1000 of a set of size n).
fn check_elementary(a: u32, b: u32, pixel: u32, dim: u32, seed: u64) {
    let (nx, ny) = (1u32 << a, 3u32.pow(b));
    let n = nx * ny;
    let set = PointSet::new(SamplerKind::HALTON, n);
    for sample in [0, 1, 2, 7, 1000] {
        let mut seen = vec![false; n as usize];
        for k in 0..n {
            let [x, y] = set.point(pixel, sample, dim, k, seed);
            let c = (cell(y, ny) * nx + cell(x, nx)) as usize;
            assert!(!seen[c], "2^{a} x 3^{b}: box hit twice (pixel {pixel}, sample {sample})");
            seen[c] = true;
        }
    }
}

#[test]
fn halton_elementary_intervals() {
    // Dimension 0 is the classic (scrambled) sequence: every block of 2^a 3^b indices.
    for (a, b) in [(1, 1), (2, 2), (2, 1), (1, 2), (3, 2), (0, 3), (4, 0)] {
        for pixel in [0, 1, 99, u32::MAX] {
            for seed in [0, 7, u64::MAX] {
                check_elementary(a, b, pixel, 0, seed);
            }
        }
    }
    // Other dims shuffle the index keeping prefixes of 2^m: those are 2^a x 2^(m-a)... in base 2
    // and 1D-stratified in x.
    for m in 0..=8u32 {
        for (pixel, dim, seed) in [(0, 1, 0), (99, 13, 7), (u32::MAX, 70, u64::MAX)] {
            let set = PointSet::new(SamplerKind::HALTON, 1 << m);
            let mut seen = vec![false; 1 << m];
            for k in 0..1u32 << m {
                let x = set.point(pixel, 0, dim, k, seed)[0];
                assert!(!std::mem::replace(&mut seen[cell(x, 1 << m) as usize], true), "m {m} dim {dim}");
            }
        }
    }
    // Finest levels: the first 2^12 / 3^8 points of a long block are 1D-stratified per axis.
    let set = PointSet::new(SamplerKind::HALTON, 1);
    let mut sx = vec![false; 1 << 12];
    for i in 0..(1u32 << 12) {
        let x = set.point(4, i, 0, 0, 3)[0];
        assert!(!std::mem::replace(&mut sx[cell(x, 1 << 12) as usize], true));
    }
    let mut sy = vec![false; 6561];
    for i in 0..6561 {
        let y = set.point(4, i, 0, 0, 3)[1];
        assert!(!std::mem::replace(&mut sy[cell(y, 6561) as usize], true));
    }
}

#[test]
fn halton_is_scrambled_per_pixel() {
    let a = point_2d(SamplerKind::HALTON, 1, 0, 0, 0, 16, 0);
    let b = point_2d(SamplerKind::HALTON, 2, 0, 0, 0, 16, 0);
    assert_ne!(a, b);
    assert_ne!(a, [0.0, 0.0]);
}

fn integrand(u: f64, v: f64) -> f64 {
    (-((u - 0.3).powi(2) + (v - 0.6).powi(2)) * 8.0).exp()
}

/// Composite Simpson on [0, 1] with `m` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, m: usize) -> f64 {
    let h = 1.0 / m as f64;
    let inner: f64 = (1..m).map(|i| f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 }).sum();
    (f(0.0) + f(1.0) + inner) * h / 3.0
}

/// Mean and variance of the n-point estimate of the integrand over `pixels` independent sets.
fn estimate_stats(kind: SamplerKind, n: u32, pixels: u32, seed: u64) -> (f64, f64) {
    let set = PointSet::new(kind, n);
    let est: Vec<f64> = (0..pixels)
        .map(|p| {
            let sum: f64 =
                (0..n).map(|k| set.point(p, 0, 0, k, seed)).map(|[u, v]| integrand(f64::from(u), f64::from(v))).sum();
            sum / f64::from(n)
        })
        .collect();
    let mean = est.iter().sum::<f64>() / est.len() as f64;
    let var = est.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (est.len() - 1) as f64;
    (mean, var)
}

// Measured (seed 2024, n = 16, 2000 pixels): Var(independent) / Var(stratified) = 6.53 and
// Var(independent) / Var(halton) = 11.85 (seeds 0..20: 5.6..6.7 and 10.2..11.6); printed with
// `--nocapture`.
#[test]
fn integration_is_unbiased_and_stratification_reduces_variance() {
    // Separable integrand: exact value = product of two 1D integrals.
    let exact = simpson(|u| (-8.0 * (u - 0.3f64).powi(2)).exp(), 20_000)
        * simpson(|v| (-8.0 * (v - 0.6f64).powi(2)).exp(), 20_000);
    let (n, pixels, seed) = (16, 2000, 2024);
    let var_independent = estimate_stats(SamplerKind::INDEPENDENT, n, pixels, seed).1;
    for kind in SamplerKind::ALL.into_iter().filter(|k| !k.is_biased()) {
        let (mean, v) = estimate_stats(kind, n, pixels, seed);
        let se = (v / f64::from(pixels)).sqrt();
        assert!((mean - exact).abs() < 4.0 * se, "{kind:?}: mean {mean} vs exact {exact}, se {se}");
        let ratio = var_independent / v;
        println!("exact {exact:.6}; variance ratio independent/{} {ratio:.2}", kind.name());
        if kind != SamplerKind::INDEPENDENT {
            assert!(ratio >= 4.0, "{kind:?}: ratio {ratio}");
        }
    }
    // Grid centres: every pixel gives the midpoint rule on the 4 x 4 grid.
    let midpoint: f64 =
        (0..16).map(|k| integrand((f64::from(k % 4) + 0.5) / 4.0, (f64::from(k / 4) + 0.5) / 4.0)).sum::<f64>() / 16.0;
    let (mean, v) = estimate_stats(SamplerKind::GRID_CENTER, n, 50, seed);
    assert!((mean - midpoint).abs() < 1e-12 && v < 1e-24, "{mean} vs {midpoint}");
}

/// Upper 99.99% point of chi-square with `df` degrees of freedom (Wilson-Hilferty).
fn chi2_crit_9999(df: f64) -> f64 {
    let z = 3.719_016; // standard normal 0.9999 quantile
    let t = 2.0 / (9.0 * df);
    df * (1.0 - t + z * t.sqrt()).powi(3)
}

#[test]
fn independent_points_are_uniform() {
    let mut hist2 = vec![0u32; 256];
    let mut hist1 = vec![0u32; 256];
    let set = PointSet::new(SamplerKind::INDEPENDENT, 16);
    for p in 0..16_384 {
        for k in 0..16 {
            let [x, y] = set.point(p, 1, 5, k, 31);
            hist2[(cell(y, 16) * 16 + cell(x, 16)) as usize] += 1;
            hist1[cell(uniform_1d(p, 1, 5, k, 31), 256) as usize] += 1;
        }
    }
    let chi2 = |h: &[u32]| {
        let e = h.iter().sum::<u32>() as f64 / h.len() as f64;
        h.iter().map(|&c| (f64::from(c) - e).powi(2) / e).sum::<f64>()
    };
    let crit = chi2_crit_9999(255.0); // ~ 347.7
    let (c2, c1) = (chi2(&hist2), chi2(&hist1));
    println!("chi-square 2D {c2:.1}, 1D {c1:.1}, critical {crit:.1}");
    assert!(c2 < crit && c1 < crit, "chi2 {c2} {c1} >= {crit}");
}

#[test]
fn registry_names_are_unique_and_parse_to_their_kind() {
    let mut spellings = Vec::new();
    for kind in SamplerKind::ALL {
        let info = kind.info();
        assert_eq!(SamplerKind::named(info.name), kind);
        for name in std::iter::once(&info.name).chain(info.aliases) {
            assert_eq!(*name, name.trim().to_ascii_lowercase(), "registry spellings are lower case");
            assert_eq!(SamplerKind::parse(&name.to_ascii_uppercase()), Some(kind), "{name}");
            spellings.push(*name);
        }
        assert!(!info.description.is_empty());
        assert!(SamplerKind::help_list().contains(info.name));
    }
    let count = spellings.len();
    spellings.sort_unstable();
    spellings.dedup();
    assert_eq!(spellings.len(), count, "a spelling is registered twice");
    assert!(SamplerKind::help_list()
        .starts_with("independent (random), stratified, grid-center (biased), multijitter, halton"));
}

/// Every unbiased registered layout: the points of 16384 pixels (one per pixel, k = pixel mod 16 of
/// a 16-point set) are uniform over 16 x 16 cells by chi-square.
#[test]
fn every_unbiased_layout_is_uniform() {
    let crit = chi2_crit_9999(255.0);
    for kind in SamplerKind::ALL.into_iter().filter(|k| !k.is_biased()) {
        for width in [0, 100] {
            let set = PointSet::for_image(kind, 16, width);
            let mut hist = vec![0u32; 256];
            for p in 0..16_384 {
                let [x, y] = set.point(p, 1, 5, p % 16, 31);
                hist[(cell(y, 16) * 16 + cell(x, 16)) as usize] += 1;
            }
            let e = 64.0;
            let chi2: f64 = hist.iter().map(|&c| (f64::from(c) - e).powi(2) / e).sum();
            println!("{}: chi-square {chi2:.1} (critical {crit:.1})", kind.name());
            assert!(chi2 < crit, "{kind:?} width {width}: chi2 {chi2} >= {crit}");
        }
    }
}

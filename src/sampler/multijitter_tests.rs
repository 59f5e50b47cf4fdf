//! `multijitter`'s own tests: its strata (every 1D projection n-rooks, the 2D grid), uniformity
//! over pixels, and the decorrelation of the dimensions of one pixel. The registry's generic tests
//! (`sampler/tests.rs`: scalar == x8, stream == point, range, sensitivity, integration, chi-square)
//! cover it too.

use super::super::grid::strata_shape;
use super::super::permute::{permute, PermDomain};
use super::super::sobol::tests::lcg;
use super::super::{PointSet, SamplerKind};
use super::*;

const SIZES: [u32; 14] = [1, 2, 3, 5, 7, 8, 12, 16, 17, 36, 64, 100, 128, 256];

/// The n points of (pixel, sample, dim, seed), from the scalar and the x8 paths (asserted equal).
fn points(n: u32, pixel: u32, sample: u32, dim: u32, seed: u64) -> Vec<[f32; 2]> {
    let set = PointSet::new(SamplerKind::MULTIJITTER, n);
    let pts: Vec<[f32; 2]> = (0..n).map(|k| set.point(pixel, sample, dim, k, seed)).collect();
    for k0 in (0..n).step_by(8) {
        let ks = crate::simd::U8::new(std::array::from_fn(|i| (k0 + i as u32).min(n - 1)));
        let (x, y) = set.point_x8(crate::simd::U8::splat(pixel), crate::simd::U8::splat(sample), dim, ks, seed);
        for (i, k) in ks.to_array().into_iter().enumerate() {
            assert_eq!([x.to_array()[i], y.to_array()[i]], pts[k as usize], "x8 of point {k} of {n}");
        }
    }
    pts
}

const STREAMS: [(u32, u32, u32, u64); 6] =
    [(0, 0, 0, 0), (1, 0, 3, 7), (77, 2, 64, 3), (123_456, 0, 66, u64::MAX), (u32::MAX, 5, 2, 42), (9, 0, 16448, 1)];

#[test]
fn every_1d_projection_is_n_rooks_stratified() {
    for n in SIZES {
        for (pixel, sample, dim, seed) in STREAMS {
            let pts = points(n, pixel, sample, dim, seed);
            for axis in 0..2 {
                let mut seen = vec![false; n as usize];
                for p in &pts {
                    assert!((0.0..1.0).contains(&p[axis]));
                    let cell = ((f64::from(p[axis]) * f64::from(n)) as usize).min(n as usize - 1);
                    assert!(!seen[cell], "n = {n}, axis {axis}: two points in 1D stratum {cell}");
                    seen[cell] = true;
                }
            }
        }
    }
}

#[test]
fn every_2d_cell_of_the_strata_grid_has_one_point() {
    for n in SIZES {
        let (nx, ny) = strata_shape(n);
        for (pixel, sample, dim, seed) in STREAMS {
            let mut seen = vec![false; n as usize];
            for p in points(n, pixel, sample, dim, seed) {
                let cx = ((f64::from(p[0]) * f64::from(nx)) as u32).min(nx - 1);
                let cy = ((f64::from(p[1]) * f64::from(ny)) as u32).min(ny - 1);
                let cell = (cy * nx + cx) as usize;
                assert!(!seen[cell], "n = {n}: two points in cell ({cx}, {cy}) of {nx} x {ny}");
                seen[cell] = true;
            }
        }
    }
}

/// Upper bound for a chi-square statistic of `dof` degrees of freedom: mean + 6 standard deviations.
fn chi2_bound(dof: usize) -> f64 {
    dof as f64 + 6.0 * (2.0 * dof as f64).sqrt()
}

fn chi2(counts: &[u32], expected: f64) -> f64 {
    counts.iter().map(|&c| (f64::from(c) - expected).powi(2) / expected).sum()
}

/// Point k of every set is uniform over the square across pixels (a chi-square over 16 x 16
/// cells, for each k of a 16-point set), and the joint cells of two dimensions' points k are
/// uniform too (padding: no dimension's stratum tells another's).
#[test]
fn points_are_uniform_over_pixels_and_dimensions_are_independent() {
    let (n, pixels) = (16u32, 25_600u32);
    let set = PointSet::new(SamplerKind::MULTIJITTER, n);
    for k in [0, 5, 15] {
        let mut one = vec![0u32; 256];
        let mut joint = vec![0u32; 256];
        for pixel in 0..pixels {
            let [x, y] = set.point(pixel, 0, 64, k, 11);
            let [u, _] = set.point(pixel, 0, 66, k, 11);
            one[(y * 16.0) as usize * 16 + (x * 16.0) as usize] += 1;
            joint[(u * 16.0) as usize * 16 + (x * 16.0) as usize] += 1;
        }
        let e = f64::from(pixels) / 256.0;
        let (c1, c2) = (chi2(&one, e), chi2(&joint, e));
        assert!(c1 < chi2_bound(255), "k = {k}: point k not uniform over pixels (chi2 {c1:.0})");
        assert!(c2 < chi2_bound(255), "k = {k}: dims 64 and 66 not independent (chi2 {c2:.0})");
    }
}

/// Variance over pixels of the estimate of `f` over two dimensions of one pixel: with the
/// layout's own pairing of the dimensions' points, and with dim b's points re-paired by a
/// uniformly random permutation (a small LCG Fisher-Yates per pixel), i.e. perfect padding.
fn pairing_variances(n: u32, pixels: u32, f: impl Fn([f32; 2], [f32; 2]) -> f64) -> (f64, f64) {
    let set = PointSet::new(SamplerKind::MULTIJITTER, n);
    let mut state = 0x853c_49e6_748f_ea9bu64;
    let mut lcg = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 33) as u32
    };
    let (mut layout, mut shuffled) = (Vec::new(), Vec::new());
    for pixel in 0..pixels {
        let a: Vec<[f32; 2]> = (0..n).map(|k| set.point(pixel, 0, 64, k, 5)).collect();
        let mut b: Vec<[f32; 2]> = (0..n).map(|k| set.point(pixel, 0, 66, k, 5)).collect();
        layout.push(a.iter().zip(&b).map(|(p, q)| f(*p, *q)).sum::<f64>() / f64::from(n));
        for i in (1..b.len()).rev() {
            b.swap(i, lcg() as usize % (i + 1));
        }
        shuffled.push(a.iter().zip(&b).map(|(p, q)| f(*p, *q)).sum::<f64>() / f64::from(n));
    }
    let var = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64
    };
    (var(&layout), var(&shuffled))
}

/// Issue 33: the dimensions of one pixel are decorrelated as well as uniformly random pairings
/// would: functions coupling two dimensions (an edge between them, a smooth mix) have no more
/// variance than with a random re-pairing of the points. `permute`'s xorshift-multiply round
/// (the shuffle of `stratified`), once or twice per step, gave ratios of 1.17-1.18 at n = 16
/// here (and 1.04-1.07 at n = 64); 4000 pixels make the ratio's standard error about 3 %.
#[test]
fn dimensions_are_decorrelated_as_well_as_random_pairings() {
    type Pair = fn([f32; 2], [f32; 2]) -> f64;
    let cases: [(&str, Pair); 3] = [
        ("x_a < x_b", |a, b| f64::from(u8::from(a[0] < b[0]))),
        ("x_a + y_b < 1", |a, b| f64::from(u8::from(a[0] + b[1] < 1.0))),
        ("sin", |a, b| (6.0 * f64::from(a[0]) + 5.0 * f64::from(b[0]) + 4.0 * f64::from(a[1] * b[1])).sin()),
    ];
    let mut failures = Vec::new();
    for n in [8, 9, 16, 25, 64, 100, 128, 256] {
        for (name, f) in cases {
            let (layout, random) = pairing_variances(n, 4000, f);
            let ratio = layout / random;
            eprintln!("n = {n}, {name}: variance {layout:.3e}, with random pairings {random:.3e}, ratio {ratio:.3}");
            if !(ratio < 1.12) {
                failures.push(format!("n = {n}, {name}: dims correlated: variance ratio {ratio:.3} to random pairings"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The cheap span for power-of-two n equals `grid::cell_span`.
#[test]
fn power_of_two_spans_match_the_grid() {
    for b in 0..=24 {
        let n = Divisor::new(1 << b);
        for c in [0u32, 1, (1 << b) / 2, (1 << b) - 1].into_iter().filter(|&c| c < 1 << b) {
            assert_eq!(fine_span(c, n), cell_span(c, n), "n = 2^{b}, cell {c}");
        }
    }
}

/// `permute_lanes` is a permutation of 0..n for every key, its x8 lanes equal its scalar lanes,
/// and it is not `permute`.
#[test]
fn permute_lanes_is_a_permutation() {
    for n in [1u32, 2, 3, 4, 7, 8, 16, 17, 32, 64, 100, 128, 256, 512, 1000] {
        for key in [0u32, 1, 0xdead_beef, u32::MAX] {
            let mut seen = vec![false; n as usize];
            let d = PermDomain::new(n);
            for i in 0..n {
                let p = permute_lanes(i, &d, key);
                assert!(p < n && !seen[p as usize], "n = {n}, key {key}: {i} -> {p}");
                seen[p as usize] = true;
                let lanes = crate::simd::U8::new(std::array::from_fn(|j| (i + j as u32) % n));
                let keys = crate::simd::U8::new(std::array::from_fn(|j| key.wrapping_add(j as u32)));
                let p8 = permute_lanes(lanes, &d, keys).to_array();
                for (j, v) in p8.into_iter().enumerate() {
                    assert_eq!(v, permute_lanes((i + j as u32) % n, &d, key.wrapping_add(j as u32)));
                }
            }
        }
    }
    let differs = (0..64).any(|i| permute_lanes(i, &PermDomain::new(64), 5) != permute(i, 64, 5));
    assert!(differs);
}

/// A grid side's permutation on its compile-time domain (`side`) is the run-time domain's, for
/// every side up to 300 (the listed ones and the others), scalar and x8: the same bits.
#[test]
fn side_permutations_equal_the_run_time_domains() {
    for m in 1u32..=300 {
        let d = std::hint::black_box(PermDomain::new(m));
        for key in [0u32, 1, 0xdead_beef, u32::MAX] {
            for i in 0..m {
                assert_eq!(side(i, &d, key), permute_lanes(i, &d, key), "m = {m}, key {key}, i {i}");
            }
            for i0 in (0..m).step_by(8) {
                let lanes = crate::simd::U8::new(std::array::from_fn(|j| (i0 + j as u32) % m));
                let keys = crate::simd::U8::new(std::array::from_fn(|j| key.wrapping_add(j as u32)));
                assert_eq!(side(lanes, &d, keys).to_array(), permute_lanes(lanes, &d, keys).to_array(), "m = {m}");
            }
        }
    }
}

/// The sets on compile-time grids (`keyed_point`'s arms) give the run-time grid's points, bit for
/// bit: every listed size and its neighbours, the camera's dimension and another, four keys,
/// scalar and x8.
#[test]
fn compile_time_grids_equal_the_run_time_grid() {
    let sizes = [4u32, 8, 9, 16, 25, 32, 36, 64, 100, 128, 144, 256, 288, 400, 576, 800, 1152, 1600, 2304, 3200, 6400];
    for n in sizes.into_iter().flat_map(|n| [n - 1, n, n + 1]) {
        let set = PointSet::new(SamplerKind::MULTIJITTER, n).shape();
        let grid = std::hint::black_box(*set.grid());
        let ks: Vec<u32> = if n <= 300 { (0..n).collect() } else { (0..n).step_by(7).chain([n - 1]).collect() };
        for key in [0u32, 1, 0xdead_beef, u32::MAX] {
            for dim in [0, 3] {
                for &k in &ks {
                    let (a, b) = (keyed_point(&set, key, dim, k), grid_point(&grid, key, dim, k));
                    assert_eq!((a.0.to_bits(), a.1.to_bits()), (b.0.to_bits(), b.1.to_bits()), "n = {n}, k {k}");
                }
                let k8 = crate::simd::U8::new(std::array::from_fn(|j| ks[j % ks.len()]));
                let keys = crate::simd::U8::new(std::array::from_fn(|j| key.wrapping_add(j as u32)));
                let (a, b) = (keyed_point(&set, keys, dim, k8), grid_point(&grid, keys, dim, k8));
                assert_eq!((a.0.to_array(), a.1.to_array()), (b.0.to_array(), b.1.to_array()), "x8: n = {n}");
            }
        }
    }
}

/// The permutation domains are tight: 0..m in Z_a x Z_b with a * b == m where m has a factor
/// pair near its square root (no cycle walking: the x8 lanes walked in lockstep, 2-5 passes of
/// four hashes for 10 or 100 points in power-of-two domains of 16 and 128), else with fewer than
/// a spare cells; both halves at least 2 from m = 3 on. A domain beyond 2^31 is all of u32, and
/// its permutation maps sampled indices into 0..m without collisions.
#[test]
fn permutation_domains_are_tight() {
    for (m, want) in [(1, (1, 1)), (2, (2, 1)), (3, (2, 2)), (4, (2, 2)), (7, (4, 2)), (10, (5, 2)), (12, (4, 3))] {
        assert_eq!(PermDomain::new(m).shape(), want, "m = {m}");
    }
    for m in [16u32, 25, 64, 100, 256, 1024, 4096, 3 * 5 * 7 * 11] {
        let (a, b) = PermDomain::new(m).shape();
        assert_eq!(a * b, m, "m = {m}: {a} x {b}");
    }
    for m in 3..5000u32 {
        let (a, b) = PermDomain::new(m).shape();
        assert!(b >= 2 && a >= b && a * b >= m && a * b - m < a, "m = {m}: {a} x {b}");
    }
    // Small domains draw their rounds from tables of hashed words: 8 points from one word (was
    // five hashes), 64 from four, 9 and 25 from two and three (a word of their own for the
    // rotation off powers of two), 128 and 256 from five (two-word tables, one word and its
    // xorshift); larger ones keep the hashed rounds.
    let sizes = [2, 3, 4, 8, 9, 16, 25, 32, 64, 100, 128, 256, 512];
    let words: Vec<(u32, Option<u32>)> = sizes.map(|m| (m, PermDomain::new(m).words())).to_vec();
    let want = [
        (2, Some(1)),
        (3, Some(2)),
        (4, Some(1)),
        (8, Some(1)),
        (9, Some(2)),
        (16, Some(2)),
        (25, Some(3)),
        (32, Some(3)),
        (64, Some(4)),
        (100, None),
        (128, Some(5)),
        (256, Some(5)),
        (512, None),
    ];
    assert_eq!(words, want);
    let m = (1u32 << 31) + 12_345;
    assert_eq!(PermDomain::new(m).shape(), (1 << 16, 1 << 16));
    let d = PermDomain::new(m);
    let mut seen = std::collections::HashSet::new();
    for i in (0..m).step_by(104_729).chain(m - 100..m) {
        let p = permute_lanes(i, &d, 0x1234_5678 ^ i.rotate_left(7));
        assert!(p < m, "{i} -> {p} beyond {m}");
        let p = permute_lanes(i, &d, 0x1234_5678);
        assert!(p < m && seen.insert(p), "{i} -> {p}: out of range or twice");
    }
}

/// The camera's dimension keeps point k in coarse cell (k % nx, k / nx), as `stratified` does
/// (`--first-sample centre` relies on it); other dimensions shuffle k.
#[test]
fn camera_points_keep_their_coarse_cell() {
    for n in SIZES {
        let (nx, ny) = strata_shape(n);
        for (pixel, sample, _, seed) in STREAMS {
            for (k, p) in points(n, pixel, sample, DIM_CAMERA, seed).into_iter().enumerate() {
                let cell = ((f64::from(p[0]) * f64::from(nx)) as u32, (f64::from(p[1]) * f64::from(ny)) as u32);
                assert_eq!(cell, (k as u32 % nx, k as u32 / nx), "n = {n}, point {k}");
            }
        }
    }
    let moved = (0..64).any(|k| {
        let p = points(64, 3, 0, 66, 1)[k];
        ((p[0] * 8.0) as usize, (p[1] * 8.0) as usize) != (k % 8, k / 8)
    });
    assert!(moved, "dimension 66 keeps the index order");
}

/// Power-of-two sets run on compile-time grids (`keyed_point`'s specialisation): every point, for
/// the camera's dimension and others, lanes with different keys and indices past n, has the bits
/// of the same code on the grid made at run time.
#[test]
fn constant_grids_give_the_run_time_points() {
    use crate::simd::U8;
    let mut st = 0x9e37_79b9u64;
    let mut next = || lcg(&mut st);
    for n in [4u32, 8, 16, 32, 64, 128, 256] {
        let set = SetShape::new(n, 640);
        let grid = std::hint::black_box(Grid::new(n));
        for dim in [DIM_CAMERA, 1, 7, 66] {
            for _ in 0..64 {
                let key = U8::new(std::array::from_fn(|_| next()));
                let k = U8::new(std::array::from_fn(|i| if i == 7 { n + next() % (3 * n) } else { next() % n }));
                let (ax, ay) = keyed_point(&set, key, dim, k);
                let (bx, by) = grid_point(&grid, key, dim, k);
                assert_eq!((ax.to_array(), ay.to_array()), (bx.to_array(), by.to_array()), "n {n}, dim {dim}");
                let (key, k) = (key.to_array()[0], k.to_array()[0]);
                let (sa, sb) = (keyed_point(&set, key, dim, k), grid_point(&grid, key, dim, k));
                assert_eq!((sa.0.to_bits(), sa.1.to_bits()), (sb.0.to_bits(), sb.1.to_bits()), "scalar, n {n}");
            }
        }
    }
}

/// The grid's square roots are integer ones (`u32::isqrt`, so that `Grid::new` is a `const fn`):
/// the same as the float roots they replaced wherever those could differ (next to squares), and
/// the same strata shapes and permutation domains.
#[test]
fn integer_roots_are_the_float_roots_they_replaced() {
    for k in 1u64..=65_536 {
        for m in [k * k - 1, k * k, k * k + 1] {
            let Ok(m) = u32::try_from(m) else { continue };
            assert_eq!(m.isqrt(), (f64::from(m)).sqrt() as u32, "m = {m}");
        }
    }
    let float_shape = |n: u32| {
        let mut nx = (f64::from(n).sqrt() as u32).max(1);
        while !n.is_multiple_of(nx) {
            nx -= 1;
        }
        (nx, n / nx)
    };
    for n in (1..70_000u32).chain([1 << 24, (1 << 24) + 7, u32::MAX]) {
        assert_eq!(strata_shape(n), float_shape(n), "n = {n}");
    }
}

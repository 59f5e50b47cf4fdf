use super::*;

/// The centred m x m grid's L2 star discrepancy in closed form: Warnock's sums factor over the
/// axes, sum_i (1 - x_i^2) = 2m/3 + 1/(12m) and sum_ij (1 - max(x_i, x_j)) = m^2/3 + 1/6, so
/// D^2 = 1/(18 m^2) + 7/(288 m^4).
fn grid_discrepancy(m: usize) -> f64 {
    let m = m as f64;
    (1.0 / (18.0 * m * m) + 7.0 / (288.0 * m.powi(4))).sqrt()
}

fn grid(m: usize) -> Vec<[f64; 2]> {
    let c = |i: usize| (i as f64 + 0.5) / m as f64;
    (0..m * m).map(|i| [c(i % m), c(i / m)]).collect()
}

#[test]
fn discrepancy_matches_the_closed_form_on_the_regular_grid() {
    for m in [1, 2, 3, 4, 7, 16, 32] {
        let (got, want) = (l2_star_discrepancy(&grid(m)), grid_discrepancy(m));
        assert!((got - want).abs() < 1e-12 * want.max(1.0), "m {m}: {got} vs {want}");
    }
}

#[test]
fn discrepancy_matches_its_definition() {
    // D^2 = integral over anchored boxes [0, a) of (count/N - area)^2, by a fine midpoint rule.
    let pts = [[0.1, 0.7], [0.35, 0.2], [0.8, 0.9], [0.55, 0.45], [0.95, 0.05]];
    let g = 800;
    let mut sum = 0.0;
    for i in 0..g {
        for j in 0..g {
            let (a, b) = ((i as f64 + 0.5) / g as f64, (j as f64 + 0.5) / g as f64);
            let inside = pts.iter().filter(|p| p[0] < a && p[1] < b).count() as f64 / pts.len() as f64;
            sum += (inside - a * b).powi(2);
        }
    }
    let want = (sum / (g * g) as f64).sqrt();
    let got = l2_star_discrepancy(&pts);
    assert!((got - want).abs() < 2e-3, "{got} vs {want}");
}

#[test]
fn min_distance_is_toroidal_and_the_hex_bound_holds() {
    assert!((min_distance(&[[0.05, 0.5], [0.95, 0.5]]) - 0.1).abs() < 1e-12);
    let g = grid(8);
    assert!((min_distance(&g) - 0.125).abs() < 1e-12);
    assert!(min_distance(&g) <= max_min_distance(64));
}

#[test]
fn spectrum_of_white_noise_is_flat_and_of_a_grid_is_zero_below_its_frequency() {
    let white: Vec<Vec<[f64; 2]>> = (0..16)
        .map(|s| {
            let set = PointSet::new(SamplerKind::INDEPENDENT, 256);
            (0..256).map(|k| set.point(s, 0, 0, k, 3).map(f64::from)).collect()
        })
        .collect();
    let p = radial_spectrum(&white, 24);
    let mean = p[4..].iter().sum::<f64>() / (p.len() - 4) as f64;
    assert!((mean - 1.0).abs() < 0.1, "white noise mean power {mean}");
    // A 16 x 16 grid: power only at multiples of 16 (|f| >= 16).
    let g = radial_spectrum(&[grid(16)], 24);
    assert!(g[1..16].iter().all(|&v| v < 1e-9), "{g:?}");
    assert!(g[16] > 1.0);
}

#[test]
fn exact_integrals() {
    // Midpoint rule on a fine grid agrees with the closed forms.
    for f in Integrand::ALL {
        let g = 2000;
        let sum: f64 =
            (0..g * g).map(|i| f.eval(((i % g) as f64 + 0.5) / g as f64, ((i / g) as f64 + 0.5) / g as f64)).sum();
        let mid = sum / (g * g) as f64;
        assert!((mid - f.exact()).abs() < 1e-4, "{}: {mid} vs {}", f.name(), f.exact());
    }
}

/// The slopes of Christensen et al. 2018 (Figs. 7, 8 and their Table 1: random -0.5; jittered
/// -0.75 on the disk, -1.0 on the Gaussian; Owen-scrambled Sobol' and pmj02 -0.75 and -1.5).
#[test]
fn registry_slopes_match_theory_and_christensen_2018() {
    let ns: Vec<u32> = (1..=6).map(|k| 1 << (2 * k)).collect(); // 4, 16, ..., 4096
    let cases = [
        (SamplerKind::INDEPENDENT, -0.5, -0.5),
        (SamplerKind::STRATIFIED, -0.75, -1.0),
        (SamplerKind::SOBOL, -0.75, -1.5),
        (SamplerKind::PMJ02, -0.75, -1.5),
    ];
    for (kind, disk, gauss) in cases {
        let c = convergence(kind, &ns, 400, 2018);
        let (d, g) = (c[0].slope.unwrap(), c[1].slope.unwrap());
        println!("{kind:?}: disk {d:.3}, gaussian {g:.3}");
        assert!((d - disk).abs() < 0.1, "{kind:?} disk slope {d} (theory {disk})");
        assert!((g - gauss).abs() < 0.1, "{kind:?} gaussian slope {g} (theory {gauss})");
    }
}

#[test]
fn slope_fit() {
    let pts: Vec<(f64, f64)> = [4.0, 16.0, 64.0].iter().map(|&n: &f64| (n, 3.0 * n.powf(-0.75))).collect();
    assert!((loglog_slope(&pts) + 0.75).abs() < 1e-12);
}

/// Sets of registry layout `kind`: set j is pixel j's first `n` points (dimension 0).
fn layout_sets(kind: SamplerKind, sets: u32, n: u32) -> Vec<Vec<[f64; 2]>> {
    let set = PointSet::new(kind, n);
    (0..sets).map(|j| (0..n).map(|k| set.point(j, 0, 0, k, 2018).map(f64::from)).collect()).collect()
}

#[test]
fn progressiveness_tells_sequences_from_sets() {
    // Sequences (independent, Sobol', pmj02) are progressive; a Fibonacci lattice and a jittered
    // set in row order (their prefixes cover a strip of the square) are not.
    for (kind, sets) in [(SamplerKind::INDEPENDENT, 1), (SamplerKind::INDEPENDENT, 4), (SamplerKind::SOBOL, 4)] {
        for n in [64u32, 256, 1024] {
            let p = progressiveness(&layout_sets(kind, sets, n));
            assert!(p.progressive, "{} x{sets} of {n}: {:?}", kind.name(), p.prefixes);
        }
    }
    let pmj = SamplerKind::parse("pmj02").unwrap();
    assert!(progressiveness(&layout_sets(pmj, 4, 256)).progressive);
    for (n, g) in [(144usize, 89usize), (233, 144), (987, 610)] {
        let fib: Vec<[f64; 2]> = (0..n).map(|i| [i as f64 / n as f64, ((i * g) % n) as f64 / n as f64]).collect();
        let p = progressiveness(&[fib]);
        assert!(!p.progressive && p.prefixes.iter().any(|&(_, r)| r > 3.0), "fibonacci {n}: {:?}", p.prefixes);
    }
    let mut rng = 12345u64;
    let mut u = || {
        rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    let jittered: Vec<[f64; 2]> =
        (0..256).map(|i| [((i % 16) as f64 + u()) / 16.0, ((i / 16) as f64 + u()) / 16.0]).collect();
    let p = progressiveness(&[jittered]);
    assert!(!p.progressive, "{:?}", p.prefixes);
    // Too small to tell: used whole.
    assert!(!progressiveness(&[vec![[0.25, 0.25], [0.75, 0.75], [0.25, 0.75], [0.75, 0.25]]]).progressive);
}

//! Tests of light selection: chi-square of the choice against its pmf, pmf consistency with the
//! sampler, normalization, conservativeness of the light tree, x8 == scalar, degenerate inputs.

use super::tree::LightTree;
use super::*;
use crate::sampling::chi2::{gamma_q, statistic, Rng, CHI2_TESTS, SIGNIFICANCE};
use crate::simd::{mask_all, mask_from_bools};

/// The registered rules that pick one light.
fn picking() -> Vec<LightSelection> {
    LightSelection::every().filter(|s| s.picks_one()).collect()
}

fn unit(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE;
        let l2 = v.length_squared();
        if l2 > 1e-4 && l2 <= 1.0 {
            return v / l2.sqrt();
        }
    }
}

fn log_uniform(rng: &mut Rng, lo: f32, hi: f32) -> f32 {
    lo * (hi / lo).powf(rng.f32())
}

/// `n` emitters in a box of half-size `spread`: mixed quads, triangles and spheres, random orientation,
/// sizes and radiance log-uniform (2 and 3 decades), a few of power 0.
fn random_lights(rng: &mut Rng, n: usize, spread: f32) -> Vec<Emitter> {
    (0..n)
        .map(|k| {
            let c = (Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE) * spread;
            let nrm = unit(rng);
            let (s, t) = crate::simd::frame_from_normal(nrm);
            let size = log_uniform(rng, 0.01, 1.0) * spread.max(1.0) * 0.2;
            let aspect = log_uniform(rng, 0.3, 3.0);
            let rad = if k % 17 == 5 { Vec3::ZERO } else { Vec3::new(1.0, 0.8, 0.6) * log_uniform(rng, 0.1, 100.0) };
            let (ab, ac) = (s * size * aspect, t * size / aspect);
            if k % 11 == 7 {
                // A sphere light now and then (the same draws: the other lights are unchanged).
                Emitter::sphere(c, 0.5 * size, rad)
            } else if k % 3 == 2 {
                Emitter::triangle([c, c + ab, c + ac], rad)
            } else {
                // quad(): emits towards normalize(ac x ab) = -(s x t) = -nrm; flip to face nrm.
                Emitter::quad(c - 0.5 * (ab + ac), ac, ab, rad)
            }
        })
        .collect()
}

/// Can light `e` contribute at `p` for an integrand clamped by `max(0, n . wi)`? Planar and
/// one-sided: `p` strictly on the emitting side, and some corner strictly above the receiver's
/// plane (`n = 0`: no receiver bound). `margin` is relative to the distances involved.
fn can_contribute(e: &Emitter, p: Vec3, n: Vec3, margin: f32) -> bool {
    if !(e.power() > 0.0) {
        return false;
    }
    if e.sphere {
        // Outside the sphere, and some of it above the receiver's plane.
        let to = e.a - p;
        let d = to.length();
        return d - e.radius > margin * d && (n == Vec3::ZERO || to.dot(n) > -e.radius * (1.0 - margin) * n.length());
    }
    let front = (p - e.a).dot(e.normal) > margin * (p - e.a).length();
    let above = n == Vec3::ZERO || e.corners().iter().any(|&c| (c - p).dot(n) > margin * (c - p).length());
    front && above
}

/// Chi-square p-value of `n_samples` choices against the pmfs (last bin: "no light", expected
/// 1 - sum); bins expected below 5 are pooled; a pick with pmf 0 fails outright.
fn chi2_choice(name: &str, s: &LightSampler, p: Vec3, nrm: Vec3, n_samples: usize, seed: u64) -> f64 {
    let k = s.len();
    let mut expected: Vec<f64> = (0..k as u32).map(|i| s.pmf(p, nrm, i) as f64).collect();
    let sum: f64 = expected.iter().sum();
    expected.push((1.0 - sum).max(0.0));
    let mut observed = vec![0u64; k + 1];
    let mut rng = Rng::new(seed);
    for _ in 0..n_samples {
        match s.sample(rng.f32(), p, nrm) {
            Some((i, q)) => {
                assert!(q > 0.0 && expected[i as usize] > 0.0, "{name}: picked light {i} of pmf 0");
                observed[i as usize] += 1;
            }
            None => observed[k] += 1,
        }
    }
    let expected: Vec<f64> = expected.iter().map(|&e| e * n_samples as f64).collect();
    for (e, &o) in expected.iter().zip(&observed) {
        assert!(*e > 1e-9 || o == 0, "{name}: {o} picks in a bin of probability 0");
    }
    let (chi2, dof) = statistic(&observed, &expected, n_samples, name);
    let pv = gamma_q(0.5 * dof as f64, 0.5 * chi2);
    eprintln!("chi2 {name}: chi2 = {chi2:.1}, dof = {dof}, p = {pv:.4}, sum of pmf = {sum:.7}");
    pv
}

#[test]
fn registry_names_round_trip() {
    assert_eq!(LightSelection::names().collect::<Vec<_>>(), ["all", "uniform", "power", "spatial"]);
    for sel in LightSelection::every() {
        assert_eq!(LightSelection::from_name(sel.name()), Some(sel));
        assert_eq!(sel.name().parse::<LightSelection>(), Ok(sel));
        assert_eq!(LightSelection::named(sel.name()), sel);
        assert_eq!(sel.to_string(), sel.name());
        assert!(!sel.description().is_empty());
        assert!(LightSelection::help_list().contains(&format!("{} ({})", sel.name(), sel.description())));
    }
    assert_eq!("Spatial".parse::<LightSelection>(), Ok(LightSelection::named("spatial")));
    assert!("tree".parse::<LightSelection>().unwrap_err().to_string().contains("all, uniform, power, spatial"));
    assert!(!LightSelection::ALL.picks_one() && LightSelection::UNIFORM.picks_one());
}

/// Every rule of the registry, at several shading points (facing the lights, a random normal,
/// far away without a receiver cosine, inside the cloud of lights): the frequencies of `sample`
/// against `pmf` (chi-square). `all` picks nothing and gives every light pmf 1.
#[test]
fn chi_square_of_every_rule_against_its_pmf_at_several_points() {
    let alpha = SIGNIFICANCE / CHI2_TESTS as f64;
    let mut rng = Rng::new(11);
    let lights = random_lights(&mut rng, 60, 3.0);
    let points = [
        (Vec3::new(0.0, 0.0, 0.0), Vec3::Y),
        (Vec3::new(2.0, -1.0, 0.5), unit(&mut rng)),
        (Vec3::new(8.0, 4.0, -6.0), Vec3::ZERO),
        (Vec3::new(-1.5, 2.5, 1.0), -Vec3::X),
    ];
    for sel in LightSelection::every() {
        let s = LightSampler::new(&lights, sel);
        for (k, &(p, n)) in points.iter().enumerate() {
            let name = format!("{sel} at point {k}");
            if !sel.picks_one() {
                assert_eq!(s.sample(0.5, p, n), None, "{name}");
                assert!((0..60).all(|i| s.pmf(p, n, i) == 1.0), "{name}");
                continue;
            }
            let pv = chi2_choice(&name, &s, p, n, 400_000, 100 + k as u64);
            assert!(pv >= alpha, "{name}: chi-square rejects the choice (p = {pv:.3e} < {alpha:.1e})");
        }
    }
}

#[test]
fn pmf_equals_the_probability_sample_returns_bit_for_bit() {
    let mut rng = Rng::new(5);
    for (n_lights, spread) in [(1, 1.0), (7, 2.0), (300, 10.0)] {
        let lights = random_lights(&mut rng, n_lights, spread);
        for sel in picking() {
            let s = LightSampler::new(&lights, sel);
            for _ in 0..3000 {
                let p = (Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE) * spread * 1.5;
                let n = if rng.f32() < 0.2 { Vec3::ZERO } else { unit(&mut rng) };
                if let Some((i, q)) = s.sample(rng.f32(), p, n) {
                    assert!(q > 0.0 && (i as usize) < n_lights);
                    assert_eq!(s.pmf(p, n, i).to_bits(), q.to_bits(), "{sel}: light {i} at {p}, {n}");
                }
            }
        }
        let all = LightSampler::new(&lights, LightSelection::ALL);
        assert_eq!(all.sample(0.5, Vec3::ZERO, Vec3::Y), None);
        assert!((0..n_lights as u32).all(|i| all.pmf(Vec3::ZERO, Vec3::Y, i) == 1.0));
    }
}

/// Probability that the tree's descent ends in a node whose children both have importance 0.
fn lost_mass(t: &LightTree, p: Vec3, n: Vec3) -> f64 {
    t.wide.lost_mass(p, n)
}

#[test]
fn pmfs_sum_to_one() {
    let mut rng = Rng::new(21);
    let lights = random_lights(&mut rng, 500, 5.0);
    for sel in [LightSelection::UNIFORM, LightSelection::named("power")] {
        let s = LightSampler::new(&lights, sel);
        let sum: f64 = (0..500).map(|i| s.pmf(Vec3::ZERO, Vec3::ZERO, i) as f64).sum();
        assert!((sum - 1.0).abs() < 1e-5, "{sel}: {sum}");
    }
    let s = LightSampler::new(&lights, LightSelection::named("spatial"));
    let tree = LightTree::build(&lights);
    let (mut lossy, mut tested) = (0, 0);
    for _ in 0..400 {
        let p = (Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE) * 7.0;
        let n = if rng.f32() < 0.2 { Vec3::ZERO } else { unit(&mut rng) };
        let sum: f64 = (0..500).map(|i| s.pmf(p, n, i) as f64).sum();
        let lost = lost_mass(&tree, p, n);
        assert!((sum + lost - 1.0).abs() < 1e-4, "sum {sum} + lost {lost} at {p}, {n}");
        if lights.iter().any(|e| can_contribute(e, p, n, 0.0)) {
            tested += 1;
            assert!(sum > 0.0);
            lossy += (lost > 0.0) as usize;
        }
    }
    eprintln!("spatial: {tested} points with a contributing light; {lossy} lose mass to zero-importance pairs");
    assert!(tested > 300);
}

#[test]
fn every_light_that_can_contribute_has_positive_spatial_pmf() {
    let mut rng = Rng::new(33);
    let mut checked = 0usize;
    for scene in 0..40 {
        let n_lights = [1, 2, 5, 50, 400][scene % 5];
        let spread = [0.5, 2.0, 20.0][scene % 3];
        let mut lights = random_lights(&mut rng, n_lights, spread);
        if scene % 4 == 3 {
            // Clustered, nearly parallel lights (tight cones, ties in the split).
            let nrm = unit(&mut rng);
            let (s, t) = crate::simd::frame_from_normal(nrm);
            for (k, e) in lights.iter_mut().enumerate() {
                let c = nrm * 0.01 * k as f32 + s * (k % 7) as f32 * 0.1 + t * (k / 7) as f32 * 0.1;
                *e = Emitter::quad(c, t * 0.05, s * 0.05, e.radiance);
            }
        }
        let s = LightSampler::new(&lights, LightSelection::named("spatial"));
        for _ in 0..300 {
            let p = if rng.f32() < 0.3 {
                // Near a light, sometimes almost in its plane.
                let e = &lights[(rng.f32() * n_lights as f32) as usize % n_lights];
                e.point(rng.f32(), rng.f32())
                    + e.normal * log_uniform(&mut rng, 1e-4, 1.0) * spread
                    + unit(&mut rng) * 1e-3 * spread
            } else {
                (Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE) * spread * 2.0
            };
            let n = if rng.f32() < 0.1 { Vec3::ZERO } else { unit(&mut rng) };
            for (i, e) in lights.iter().enumerate() {
                if can_contribute(e, p, n, 1e-5) {
                    checked += 1;
                    let q = s.pmf(p, n, i as u32);
                    assert!(q > 0.0, "scene {scene}: light {i} ({e:?}) can light {p} (n {n}) but has pmf {q}");
                }
            }
        }
    }
    eprintln!("conservativeness: {checked} (point, light) pairs that can contribute, all with pmf > 0");
    assert!(checked > 10_000);
}

#[test]
fn x8_matches_scalar_bit_for_bit() {
    let mut rng = Rng::new(44);
    for n_lights in [1, 3, 200] {
        let lights = random_lights(&mut rng, n_lights, 3.0);
        for sel in LightSelection::every() {
            let s = LightSampler::new(&lights, sel);
            for round in 0..200 {
                let us: [f32; 8] = std::array::from_fn(|_| rng.f32());
                let ps: [Vec3; 8] =
                    std::array::from_fn(|_| (Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE) * 4.0);
                let ns: [Vec3; 8] = std::array::from_fn(|k| if k == 3 { Vec3::ZERO } else { unit(&mut rng) });
                let on: [bool; 8] = std::array::from_fn(|k| round % 2 == 0 || k % 3 != 1);
                let active = if round % 2 == 0 { mask_all() } else { mask_from_bools(on) };
                let (p8, n8) = (Vec3x8::from_lanes(ps), Vec3x8::from_lanes(ns));
                let (idx, pmf) = s.sample_x8(F8::new(us), p8, n8, active);
                let (idx, pmf) = (idx.to_array(), pmf.to_array());
                let ids: [u32; 8] = std::array::from_fn(|_| (rng.f32() * n_lights as f32) as u32);
                let q8 = s.pmf_x8(p8, n8, U8::new(ids), active).to_array();
                for l in 0..8 {
                    let want = if on[l] { s.sample(us[l], ps[l], ns[l]).unwrap_or((0, 0.0)) } else { (0, 0.0) };
                    assert_eq!((idx[l], pmf[l].to_bits()), (want.0, want.1.to_bits()), "{sel} lane {l}");
                    let q = if on[l] { s.pmf(ps[l], ns[l], ids[l]) } else { 0.0 };
                    assert_eq!(q8[l].to_bits(), q.to_bits(), "{sel} pmf lane {l}");
                }
            }
        }
    }
}

#[test]
fn degenerate_inputs() {
    let q = |c: Vec3, r: f32| Emitter::quad(c, Vec3::Z * 0.5, Vec3::X * 0.5, Vec3::splat(r)); // emits -y
                                                                                              // No lights.
    for sel in picking() {
        let s = LightSampler::new(&[], sel);
        assert!(s.is_empty() && s.sample(0.3, Vec3::ZERO, Vec3::Y).is_none() && s.pmf(Vec3::ZERO, Vec3::Y, 0) == 0.0);
        let (i, p) = s.sample_x8(F8::splat(0.5), Vec3x8::ZERO, Vec3x8::ZERO, mask_all());
        assert_eq!((i.to_array(), p.to_array()), ([0; 8], [0.0; 8]));
    }
    // One light: below it (facing) pmf 1; above it (behind) spatial gives none, pmf 0.
    let one = [q(Vec3::new(0.0, 2.0, 0.0), 5.0)];
    for sel in picking() {
        let s = LightSampler::new(&one, sel);
        assert_eq!(s.sample(0.99, Vec3::ZERO, Vec3::Y), Some((0, 1.0)), "{sel}");
        assert_eq!(s.pmf(Vec3::ZERO, Vec3::Y, 0), 1.0);
    }
    let s = LightSampler::new(&one, LightSelection::named("spatial"));
    assert_eq!(s.sample(0.5, Vec3::new(0.0, 3.0, 0.0), Vec3::Y), None);
    assert_eq!(s.pmf(Vec3::new(0.0, 3.0, 0.0), Vec3::Y, 0), 0.0);
    // Receiver facing away from the light: nothing can contribute.
    assert_eq!(s.sample(0.5, Vec3::new(0.0, 0.0, 0.0), -Vec3::Y), None);
    assert_eq!(s.pmf(Vec3::new(5.0, 0.0, 0.0), -Vec3::Y, 0), 0.0);

    // Zero-power lights are never chosen; all zero: power falls back to uniform, spatial to none.
    let mixed = [q(Vec3::new(0.0, 2.0, 0.0), 0.0), q(Vec3::new(1.0, 2.0, 0.0), 2.0), q(Vec3::new(2.0, 2.0, 0.0), 0.0)];
    for sel in [LightSelection::named("power"), LightSelection::named("spatial")] {
        let s = LightSampler::new(&mixed, sel);
        for k in 0..1000 {
            let u = (k as f32 + 0.5) / 1000.0;
            assert_eq!(s.sample(u, Vec3::ZERO, Vec3::Y), Some((1, 1.0)), "{sel}");
        }
        assert_eq!((s.pmf(Vec3::ZERO, Vec3::Y, 0), s.pmf(Vec3::ZERO, Vec3::Y, 2)), (0.0, 0.0));
    }
    let dark = [q(Vec3::ZERO, 0.0), q(Vec3::X, 0.0)];
    let s = LightSampler::new(&dark, LightSelection::named("power"));
    assert_eq!((s.sample(0.7, Vec3::ZERO, Vec3::Y), s.pmf(Vec3::ZERO, Vec3::Y, 0)), (Some((1, 0.5)), 0.5));
    let s = LightSampler::new(&dark, LightSelection::named("spatial"));
    assert_eq!((s.sample(0.7, -Vec3::Y, Vec3::Y), s.pmf(-Vec3::Y, Vec3::Y, 0)), (None, 0.0));

    // Coincident lights: a tree still builds (median split by index), equal pmfs summing to 1.
    let same = vec![q(Vec3::new(0.0, 2.0, 0.0), 1.0); 100];
    let s = LightSampler::new(&same, LightSelection::named("spatial"));
    assert!(LightTree::build(&same).path.iter().all(|&(_, d)| d <= 8));
    let pmfs: Vec<f32> = (0..100).map(|i| s.pmf(Vec3::ZERO, Vec3::Y, i)).collect();
    let sum: f32 = pmfs.iter().sum();
    assert!((sum - 1.0).abs() < 1e-5 && pmfs.iter().all(|&x| (x - 0.01).abs() < 1e-4), "{sum}");

    // p on a light (its centre, normal = its normal): that light cannot contribute (p is in its
    // plane), the others can; everything stays finite.
    let row: Vec<Emitter> = (0..5).map(|k| q(Vec3::new(k as f32, 2.0, 0.0), 1.0 + k as f32)).collect();
    let p_on = row[2].point(0.5, 0.5);
    let s = LightSampler::new(&row, LightSelection::named("spatial"));
    for n in [row[2].normal, -row[2].normal, Vec3::ZERO] {
        let qs: Vec<f32> = (0..5).map(|i| s.pmf(p_on, n, i)).collect();
        assert!(qs.iter().all(|x| x.is_finite() && *x >= 0.0 && *x <= 1.0), "{qs:?}");
        for k in 0..100 {
            if let Some((i, q)) = s.sample((k as f32 + 0.5) / 100.0, p_on, n) {
                assert_eq!(q.to_bits(), qs[i as usize].to_bits());
            }
        }
    }
    // Far below the row, every light contributes: all pmfs positive.
    assert!((0..5).all(|i| s.pmf(Vec3::new(2.0, -50.0, 0.0), Vec3::Y, i) > 0.0));
}

#[test]
fn tree_structure_and_spatial_preference() {
    let mut rng = Rng::new(55);
    let lights = random_lights(&mut rng, 10_000, 50.0);
    let t = &LightTree::build(&lights);
    let live = lights.iter().filter(|e| e.power() > 0.0).count();
    assert_eq!(t.nodes.iter().filter(|n| n.leaf).count(), live);
    assert_eq!(t.nodes.len(), 2 * live - 1);
    let max_depth = t.path.iter().filter(|p| p.1 != u8::MAX).map(|p| p.1).max().unwrap();
    eprintln!("tree over {live} lights: {} nodes, max depth {max_depth}", t.nodes.len());
    assert!(max_depth <= 64);
    for (i, e) in lights.iter().enumerate() {
        assert_eq!(t.path[i].1 == u8::MAX, !(e.power() > 0.0));
    }
    // A 100 x 100 grid of equal lights facing down: right below one of them, facing it, the tree
    // strongly prefers it over the uniform choice.
    let grid: Vec<Emitter> = (0..10_000)
        .map(|k| {
            let c = Vec3::new((k % 100) as f32, 2.0, (k / 100) as f32);
            Emitter::quad(c, Vec3::Z * 0.2, Vec3::X * 0.2, Vec3::ONE)
        })
        .collect();
    let s = LightSampler::new(&grid, LightSelection::named("spatial"));
    let mut gain = Vec::new();
    for i in (0..10_000).step_by(997) {
        let p = grid[i].point(0.5, 0.5) - Vec3::Y * 0.05;
        gain.push(s.pmf(p, Vec3::Y, i as u32) * 10_000.0);
    }
    eprintln!("spatial pmf of the light just above p / uniform: {gain:?}");
    assert!(gain.iter().all(|&g| g > 20.0), "{gain:?}");
}

/// The collapsed tree's 8-lane importance is the scalar bound of the binary nodes it holds, bit
/// for bit (the conservativeness argument of `LightTree::importance` carries over), and every
/// light is a leaf of exactly one slot.
#[test]
fn wide_importance_equals_the_binary_bound() {
    use super::wide::WideTree;
    let mut rng = Rng::new(66);
    let lights = random_lights(&mut rng, 300, 4.0);
    let tree = LightTree::build(&lights);
    let (bin, wide) = (&tree.nodes, &tree.wide);
    let mut leaves = 0;
    fn walk(bin: &[super::node::Node], wide: &WideTree, w: usize, k: usize, p: Vec3, n: Vec3, leaves: &mut usize) {
        let kids = WideTree::frontier(bin, k);
        let imp = WideTree::importance8(&wide.nodes[w], p, n);
        for (c, &got) in imp.iter().enumerate() {
            let want = kids.get(c).map_or(0.0, |&j| LightTree::importance(&bin[j], p, n));
            assert_eq!(got.to_bits(), want.to_bits(), "node {w} child {c} at {p}, {n}");
            if let Some(&j) = kids.get(c) {
                if wide.nodes[w].leaf & (1 << c) != 0 {
                    assert_eq!(wide.nodes[w].child[c], bin[j].link);
                    *leaves += 1;
                } else {
                    walk(bin, wide, wide.nodes[w].child[c] as usize, j, p, n, leaves);
                }
            }
        }
    }
    for round in 0..50 {
        let p = (Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE) * 6.0;
        let n = if round % 5 == 0 { Vec3::ZERO } else { unit(&mut rng) };
        walk(bin, wide, 0, 0, p, n, &mut leaves);
    }
    assert_eq!(leaves, 50 * lights.iter().filter(|e| e.power() > 0.0).count());
}

/// `--light-choice reuse`: `sample_remap` picks the light `sample` picks (uniform, spatial) or
/// one with the same pmf (power, through the same alias table); its remapped u lies in [0, 1) and
/// is uniform given the light (chi-square of 16 bins per light over stratified u); the x8 form
/// equals the scalar one lane by lane.
#[test]
fn reused_choice_remaps_u_uniformly_per_light() {
    let mut rng = Rng::new(77);
    let lights = random_lights(&mut rng, 12, 3.0);
    let emitters = Emitters::new(lights.clone(), std::iter::empty());
    for sel in picking() {
        let s = LightSampler::new(&lights, sel);
        let (p, nrm) = (Vec3::new(0.1, 0.2, 0.3), unit(&mut rng));
        let n = 1 << 16;
        let mut hist: Vec<[f64; 16]> = vec![[0.0; 16]; lights.len()];
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            let Some((l, pmf, r)) = s.sample_remap(u, p, nrm) else { continue };
            assert!((0.0..1.0).contains(&r), "{sel:?}: remapped {r}");
            assert_eq!(pmf.to_bits(), s.pmf(p, nrm, l).to_bits(), "{sel:?}");
            if sel != LightSelection::named("power") {
                assert_eq!(s.sample(u, p, nrm), Some((l, pmf)), "{sel:?} u {u}");
            }
            hist[l as usize][(r * 16.0) as usize] += 1.0;
        }
        for (l, h) in hist.iter().enumerate() {
            let total: f64 = h.iter().sum();
            if total < 16.0 * 50.0 {
                continue;
            }
            let e = total / 16.0;
            let chi2: f64 = h.iter().map(|&c| (c - e).powi(2) / e).sum();
            // Stratified u makes the bins near-exact; allow generous slack for interval ends.
            assert!(chi2 < 60.0, "{sel:?} light {l}: chi2 {chi2} over {total} samples");
        }
        // x8 == scalar per lane.
        let u = F8::new(std::array::from_fn(|_| rng.f32()));
        let v = F8::new(std::array::from_fn(|_| rng.f32()));
        let (ps, ns) = (Vec3x8::splat(p), Vec3x8::splat(nrm));
        let mut ls = LightSample8::ZERO;
        let ok = s.sample_point_reuse_x8(&emitters, ps, ns, mask_all(), (u, v), &mut ls);
        let (ua, va, oka) = (u.to_array(), v.to_array(), mask_to_bools(ok));
        let ys = ls.y.to_lanes();
        for k in 0..8 {
            match s.sample_remap(ua[k], p, nrm) {
                Some((l, _, r)) => {
                    assert!(oka[k]);
                    assert_eq!(ls.light.to_array()[k], l);
                    assert_eq!(ys[k], lights[l as usize].point(r, va[k]), "{sel:?} lane {k}");
                }
                None => assert!(!oka[k]),
            }
        }
    }
}

/// A rule that looks at the shading point, written against the trait alone (tests only): pmf
/// proportional to `1 / (1 + |p - c_i|^2)`, `c_i` light i's centre. It keeps the trait's x8
/// functions, which must evaluate each lane at its own point.
#[derive(Debug)]
struct Nearest {
    centers: Vec<Vec3>,
}

impl Nearest {
    fn weights(&self, p: Vec3) -> (Vec<f32>, f32) {
        let w: Vec<f32> = self.centers.iter().map(|c| 1.0 / (1.0 + (p - *c).length_squared())).collect();
        let sum = w.iter().sum();
        (w, sum)
    }
}

impl LightRule for Nearest {
    fn sample(&self, u: f32, p: Vec3, n: Vec3) -> Option<(u32, f32)> {
        self.sample_remap(u, p, n).map(|(i, q, _)| (i, q))
    }
    fn sample_remap(&self, u: f32, p: Vec3, _: Vec3) -> Option<(u32, f32, f32)> {
        let (w, sum) = self.weights(p);
        let mut lo = 0.0;
        for (i, &x) in w.iter().enumerate() {
            let q = x / sum;
            if u < lo + q || i + 1 == w.len() {
                return Some((i as u32, q, ((u - lo) / q).clamp(0.0, ONE_MINUS)));
            }
            lo += q;
        }
        None
    }
    fn pmf(&self, p: Vec3, _: Vec3, i: u32) -> f32 {
        let (w, sum) = self.weights(p);
        w[i as usize] / sum
    }
    fn needs_point(&self) -> bool {
        true
    }
}

/// The trait's x8 functions give a point-dependent rule each lane's own point: `sample_x8`,
/// `sample_remap_x8` and `pmf_x8` equal the scalar functions lane by lane at eight different
/// points (a `pmf_x8` that evaluated every lane at p = 0 fails here).
#[test]
fn default_x8_functions_use_each_lanes_point() {
    let mut rng = Rng::new(88);
    let lights = random_lights(&mut rng, 9, 3.0);
    let rule = Nearest { centers: lights.iter().map(|e| e.point(0.5, 0.5)).collect() };
    for round in 0..100 {
        let us: [f32; 8] = std::array::from_fn(|_| rng.f32());
        let ps: [Vec3; 8] =
            std::array::from_fn(|_| (Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE) * 4.0);
        let ns: [Vec3; 8] = std::array::from_fn(|_| unit(&mut rng));
        let ids: [u32; 8] = std::array::from_fn(|_| (rng.f32() * 9.0) as u32);
        let on: [bool; 8] = std::array::from_fn(|k| round % 2 == 0 || k % 3 != 1);
        let active = mask_from_bools(on);
        let (p8, n8) = (Vec3x8::from_lanes(ps), Vec3x8::from_lanes(ns));
        let q8 = rule.pmf_x8(p8, n8, U8::new(ids), active).to_array();
        let (i8, s8) = rule.sample_x8(F8::new(us), p8, n8, active);
        let (ri8, rq8, rr8) = rule.sample_remap_x8(F8::new(us), p8, n8, active);
        for l in 0..8 {
            let q = if on[l] { rule.pmf(ps[l], ns[l], ids[l]) } else { 0.0 };
            assert_eq!(q8[l].to_bits(), q.to_bits(), "pmf lane {l} at {}", ps[l]);
            let (i, s) = if on[l] { rule.sample(us[l], ps[l], ns[l]).unwrap() } else { (0, 0.0) };
            assert_eq!((i8.to_array()[l], s8.to_array()[l].to_bits()), (i, s.to_bits()), "sample lane {l}");
            let (i, s, r) = if on[l] { rule.sample_remap(us[l], ps[l], ns[l]).unwrap() } else { (0, 0.0, 0.0) };
            let got = (ri8.to_array()[l], rq8.to_array()[l].to_bits(), rr8.to_array()[l].to_bits());
            assert_eq!(got, (i, s.to_bits(), r.to_bits()), "sample_remap lane {l}");
        }
    }
}

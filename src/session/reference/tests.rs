//! The replicated reference's variance layer against the truth it estimates: two references of
//! other seeds differ by MSE = 2 x (their variance), so the layer's mean must match MSE / 2.

use super::*;
use crate::camera::FirstSample;
use crate::film::Film;
use crate::sampler::SamplerKind;
use crate::session::pass::render_passes;

/// The three scenes of the check: direct lighting (one light, three lights) and the path tracer.
const SCENES: [&str; 3] = ["cornell.test", "three_lights.test", "cornell_diffuse_path.test"];

fn opts(scene: &str, sampler: &str, seed: u64, spp: u32) -> RenderOptions {
    RenderOptions {
        scene: Some(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(scene)),
        size: Some((40, 30)),
        spp: Some(spp),
        seed,
        threads: 2,
        sampler: Some(SamplerKind::parse(sampler).expect("a registry sampler")),
        first_sample: Some(FirstSample::Jittered),
        ..Default::default()
    }
}

/// Mean over values of an image.
fn mean_of(img: &[[f32; 3]]) -> f64 {
    img.iter().flat_map(|p| p.iter().map(|&v| f64::from(v))).sum::<f64>() / (3 * img.len()) as f64
}

/// Half the mean squared difference of two images: the mean variance of one, if independent.
fn half_mse(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let sq = a.iter().zip(b).flat_map(|(p, q)| (0..3).map(move |c| (f64::from(p[c]) - f64::from(q[c])).powi(2)));
    sq.sum::<f64>() / (3 * a.len()) as f64 / 2.0
}

/// Seed-to-seed MSE/2 averaged over every pair of `refs` (= the mean over values of the unbiased
/// variance across them).
fn pairwise_half_mse(refs: &[Vec<[f32; 3]>]) -> f64 {
    let mut sum = 0.0;
    let mut pairs = 0.0;
    for i in 0..refs.len() {
        for j in i + 1..refs.len() {
            sum += half_mse(&refs[i], &refs[j]);
            pairs += 1.0;
        }
    }
    sum / pairs
}

/// References of seeds 11.. differ by MSE = 2 x their variance: the replicas' layer must say so,
/// for independent, stratified and Sobol references, on three scenes. Six references per case
/// (15 pairs): one pair alone scatters by +-40 % where a few pixels (light edges) carry the MSE.
#[test]
fn replica_layer_matches_seed_to_seed_mse() {
    let mut failures = Vec::new();
    for scene in SCENES {
        for sampler in ["independent", "stratified", "sobol"] {
            let refs: Vec<Replicated> =
                (11..17).map(|seed| render_replicas(&opts(scene, sampler, seed, 128), 8).unwrap()).collect();
            let layer = refs.iter().map(|r| mean_of(&r.variance)).sum::<f64>() / refs.len() as f64;
            let truth = pairwise_half_mse(&refs.iter().map(|r| r.mean.clone()).collect::<Vec<_>>());
            let ratio = layer / truth;
            eprintln!("{scene} {sampler}: layer {layer:.4e}, seed-to-seed MSE/2 {truth:.4e}, ratio {ratio:.3}");
            if !(0.7..=1.4).contains(&ratio) {
                failures.push(format!("{scene} {sampler}: ratio {ratio:.3}"));
            }
        }
    }
    assert!(failures.is_empty(), "replica variance layer off: {failures:?}");
}

/// The same check on the i.i.d. layer of one render (what `reference --replicas 1` writes, and
/// what every reference wrote before replicas) fails for stratified and Sobol samples: the check
/// is sharp.
#[test]
fn iid_layer_fails_the_same_check() {
    for sampler in ["stratified", "sobol"] {
        let films: Vec<Film> = (11..17)
            .map(|seed| render_passes(&opts("three_lights.test", sampler, seed, 128), false).unwrap().film)
            .collect();
        let layer = films.iter().map(|f| mean_of(&f.variance_of_mean())).sum::<f64>() / films.len() as f64;
        let ratio = layer / pairwise_half_mse(&films.iter().map(Film::mean).collect::<Vec<_>>());
        eprintln!("{sampler}: i.i.d. layer / seed-to-seed MSE/2 = {ratio:.3}");
        assert!(ratio > 1.4, "{sampler}: the i.i.d. layer should overstate its error: ratio {ratio:.3}");
    }
}

#[test]
fn replicas_refuse_what_they_cannot_do() {
    let o = opts("three_lights.test", "sobol", 1, 100);
    let e = render_replicas(&o, 8).err().expect("100 is not a multiple of 8").to_string();
    assert!(e.contains("--spp 100 is not a multiple of --replicas 8") && e.contains("--spp 104"), "{e}");
    let o = RenderOptions { time_budget: Some(1.0), ..opts("three_lights.test", "sobol", 1, 64) };
    let e = render_replicas(&o, 8).err().expect("budget refused").to_string();
    assert!(e.contains("--time-budget") && e.contains("--replicas 1"), "{e}");
    let e = render_replicas(&opts("three_lights.test", "sobol", 1, 64), 1).err().expect("one replica").to_string();
    assert!(e.contains("at least 2"), "{e}");
}

#[test]
fn replica_seeds_are_distinct() {
    let seeds: Vec<u64> = (0..4).flat_map(|base| (0..64).map(move |r| replica_seed(base, r))).collect();
    for (i, s) in seeds.iter().enumerate() {
        assert!(!seeds[..i].contains(s), "seed {i} repeats");
    }
}

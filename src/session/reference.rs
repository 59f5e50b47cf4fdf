//! `strata reference`: a high-spp render whose variance layer is its *own* error, estimated from
//! independent replicas.
//!
//! The i.i.d. formula (sample variance / n over one render's samples) is right for independent
//! samples only: stratified and low-discrepancy samples converge faster than 1/n, so it overstates
//! their error (26x for a stratified 256-spp hw2 sphere). A reference therefore renders
//! `--replicas R` independent renders of `spp / R` samples each, with independent seeds (so every
//! scramble, shift and hash of its sample streams is drawn afresh), and writes their mean. The
//! variance of that mean is estimated without any assumption on the sampler, from the replicas
//! alone (batch means): `s^2 / R`, with `s^2` the unbiased variance of the R replica means per
//! pixel and channel. It has R - 1 degrees of freedom per value; averaged over an image (what
//! `compare` uses) it is accurate to a few percent. The EXR says how it was made
//! (`strata.variance`, `strata.replicas`, `strata.replica_spp`, `strata.replica_seeds`).

use super::output::metadata;
use super::pass::{render_passes_from, RenderOutput, Resumed};
use super::stats::stats_json;
use super::{output_stem, RenderOptions, SessionError};
use crate::checkpoint;
use crate::film::{self, with_ext, Metadata};

/// The most replicas `strata reference` makes unless `--replicas` says otherwise.
pub const DEFAULT_REPLICAS: u32 = 8;

/// The replicas of a reference of `spp` samples unless `--replicas` says otherwise: the largest
/// divisor of `spp` from 2 to [`DEFAULT_REPLICAS`] (1 when there is none: then one render, and
/// the i.i.d. variance layer, which says so in `strata.variance`).
pub fn default_replicas(spp: u32) -> u32 {
    (2..=DEFAULT_REPLICAS).rev().find(|&r| spp.is_multiple_of(r)).unwrap_or(1)
}

/// What `strata reference` does to its render flags: a reference is unbiased, whatever the
/// scene's course conventions, so pixel sample 0 is jittered unless `--first-sample` says
/// otherwise. The CLI and the Python module both call this.
pub fn unbiased(opts: &mut RenderOptions) {
    opts.first_sample.get_or_insert(crate::integrator::FirstSample::Jittered);
}

/// The seed of replica `r` of a reference with base seed `base`: a SplitMix64 finalizer of both,
/// so replicas' streams are independent of each other and of `compare`'s runs (`run_seed`).
pub fn replica_seed(base: u64, r: u32) -> u64 {
    let mut z = base ^ 0x7265_706c_6963_6100u64.wrapping_add(u64::from(r).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A reference made of independent replicas.
pub struct Replicated {
    /// the last replica's render, with the statistics (times, rays, phases) of all of them
    pub out: RenderOutput,
    /// number of replicas
    pub replicas: u32,
    /// samples per pixel of each replica
    pub replica_spp: u32,
    /// the seed of each replica
    pub seeds: Vec<u64>,
    /// per pixel: the mean of the replicas' means (the reference image)
    pub mean: Vec<[f32; 3]>,
    /// per pixel: the variance of `mean`, estimated across the replicas (`s^2 / R`)
    pub variance: Vec<[f32; 3]>,
}

impl Replicated {
    /// Total samples per pixel (`replicas x replica_spp`).
    pub fn spp(&self) -> u32 {
        self.replicas * self.replica_spp
    }

    /// The `strata.variance` attribute: how the variance layer was estimated.
    pub fn variance_text(&self) -> String {
        format!(
            "replicas: variance of the mean across {} independent replicas of {} spp (separate seeds and scrambles; batch means, {} degrees of freedom per value)",
            self.replicas,
            self.replica_spp,
            self.replicas - 1
        )
    }
}

/// Renders `replicas` independent replicas of `opts.spp / replicas` samples each (seeds
/// [`replica_seed`]) and combines them. With `--checkpoint` (or `--resume`) the replicas'
/// states are written there after each replica, one record each; `--resume` continues them, with
/// a larger `--spp` too (extending every replica: bit-identical to rendering that spp at once).
/// Refuses what a replicated reference cannot do: an spp that is not a multiple of the replicas,
/// `--samples`, `--time-budget`, a checkpoint of more replicas than `replicas`.
pub fn render_replicas(opts: &RenderOptions, replicas: u32) -> Result<Replicated, SessionError> {
    replicas_with_lock(opts, replicas, false)
}

/// [`render_replicas`]; with `lock`, the output stem's lock is taken by the first replica and
/// held (in the returned output) until the outputs are written.
fn replicas_with_lock(opts: &RenderOptions, replicas: u32, lock: bool) -> Result<Replicated, SessionError> {
    let spp = opts.spp.ok_or(SessionError::Replicas { why: "it needs --spp".into() })?;
    if replicas < 2 {
        return Err(SessionError::Replicas {
            why: format!("--replicas {replicas}: at least 2 give an error estimate"),
        });
    }
    if !spp.is_multiple_of(replicas) {
        return Err(SessionError::Replicas {
            why: format!(
                "--spp {spp} is not a multiple of --replicas {replicas} (each replica renders spp / replicas samples; e.g. --spp {})",
                spp.div_ceil(replicas) * replicas
            ),
        });
    }
    let refused = [
        (opts.samples.is_some(), "--samples (shards)"),
        (opts.time_budget.is_some(), "--time-budget (a reference has a sample count)"),
    ];
    if let Some((_, what)) = refused.iter().find(|(set, _)| *set) {
        return Err(SessionError::Replicas {
            why: format!("{what} is not supported with replicas; use --replicas 1 (a single render whose variance layer is the i.i.d. estimate)"),
        });
    }
    let replica_spp = spp / replicas;
    // The checkpoint: one record per replica ([`checkpoint::write_replicas`]), rewritten after
    // each replica; `--resume` continues each replica from its record (a larger --spp extends
    // every replica: the same bits as rendering it at once, the seeds depending on r alone).
    let ckpt = opts.checkpoint.clone().or_else(|| opts.resume.clone());
    let mut prior: Vec<Option<Resumed>> = match &opts.resume {
        Some(p) => checkpoint::read_replicas(p)?.into_iter().map(|(h, f)| Some((p.clone(), h, f))).collect(),
        None => Vec::new(),
    };
    if prior.len() > replicas as usize {
        return Err(SessionError::Replicas {
            why: format!(
                "{} holds {} replicas, more than --replicas {replicas} (give --replicas {} and an --spp that is a multiple of it)",
                opts.resume.as_ref().map_or(String::new(), |p| p.display().to_string()),
                prior.len(),
                prior.len()
            ),
        });
    }
    let mut records: Vec<Vec<u8>> = prior.iter().flatten().map(|(_, h, f)| checkpoint::to_bytes(h, f)).collect();
    let (mut mean, mut m2, mut seeds) = (Vec::<[f64; 3]>::new(), Vec::<[f64; 3]>::new(), Vec::new());
    let mut last: Option<RenderOutput> = None;
    // The output stem's lock, taken by the first replica and held until the outputs are written.
    let mut stem_lock = None;
    for r in 0..replicas {
        let mut o = opts.clone();
        o.spp = Some(replica_spp);
        o.seed = replica_seed(opts.seed, r);
        (o.checkpoint, o.resume) = (None, None);
        seeds.push(o.seed);
        if opts.progress {
            eprintln!("strata: reference replica {}/{replicas} ({replica_spp} spp, seed {})", r + 1, o.seed);
        }
        let resumed = prior.get_mut(r as usize).and_then(Option::take);
        let mut out = render_passes_from(&o, lock && r == 0, resumed)?;
        if r == 0 {
            stem_lock = out.lock.take();
        }
        if let Some(p) = &ckpt {
            let bytes = checkpoint::to_bytes(&out.header, &out.film);
            match records.get_mut(r as usize) {
                Some(rec) => *rec = bytes,
                None => records.push(bytes),
            }
            checkpoint::write_replicas(p, &records)?;
        }
        if out.interrupted {
            return Err(SessionError::Replicas {
                why: match &ckpt {
                    Some(p) => format!(
                        "interrupted in replica {} of {replicas}; {} holds the replicas so far (continue with --resume)",
                        r + 1,
                        p.display()
                    ),
                    None => format!("interrupted in replica {} of {replicas}; nothing was written", r + 1),
                },
            });
        }
        // Welford's update per value: the replicas' mean and sum of squared deviations.
        let img = out.film.mean();
        if mean.is_empty() {
            (mean, m2) = (vec![[0.0; 3]; img.len()], vec![[0.0; 3]; img.len()]);
        }
        let k = f64::from(r + 1);
        for ((m, q), x) in mean.iter_mut().zip(&mut m2).zip(&img) {
            for c in 0..3 {
                let d = f64::from(x[c]) - m[c];
                m[c] += d / k;
                q[c] += d * (f64::from(x[c]) - m[c]);
            }
        }
        last = Some(match last.take() {
            None => out,
            Some(mut prev) => {
                let header = (prev.header.cpu_seconds, prev.header.render_seconds, prev.header.rays);
                prev.stats.merge(&out.stats);
                let mut next = RenderOutput { stats: prev.stats, ..out };
                next.header.cpu_seconds += header.0;
                next.header.render_seconds += header.1;
                next.header.rays += header.2;
                next
            }
        });
    }
    let mut out = last.expect("at least two replicas ran");
    out.lock = stem_lock;
    let rf = f64::from(replicas);
    let mean_img = mean.iter().map(|m| m.map(|v| v as f32)).collect();
    let variance = m2.iter().map(|q| q.map(|v| (v / (rf - 1.0) / rf).max(0.0) as f32)).collect();
    Ok(Replicated { out, replicas, replica_spp, seeds, mean: mean_img, variance })
}

/// Replaces the value of `key` in `meta` (or appends it).
fn set_meta(meta: &mut Metadata, key: &str, value: String) {
    match meta.iter_mut().find(|(k, _)| k == key) {
        Some(e) => e.1 = value,
        None => meta.push((key.into(), value)),
    }
}

/// The EXR metadata of a replicated reference: a render's, with the totals over the replicas,
/// the base seed, and how the variance layer was estimated.
pub fn replicated_metadata(rep: &Replicated, base_seed: u64) -> Metadata {
    let mut m = metadata(&rep.out);
    let h = &rep.out.header;
    set_meta(&mut m, "strata.spp", rep.spp().to_string());
    set_meta(&mut m, "strata.seed", base_seed.to_string());
    set_meta(&mut m, "strata.samples", format!("0..{} in each of {} replicas", rep.replica_spp, rep.replicas));
    set_meta(&mut m, "strata.render_seconds", format!("{:.6}", h.render_seconds));
    set_meta(&mut m, "strata.cpu_seconds", format!("{:.6}", h.cpu_seconds));
    set_meta(&mut m, "strata.rays", h.rays.to_string());
    set_meta(&mut m, "strata.variance", rep.variance_text());
    set_meta(&mut m, "strata.replicas", rep.replicas.to_string());
    set_meta(&mut m, "strata.replica_spp", rep.replica_spp.to_string());
    let seeds: Vec<String> = rep.seeds.iter().map(u64::to_string).collect();
    set_meta(&mut m, "strata.replica_seeds", seeds.join(" "));
    m
}

/// `strata reference` with replicas: renders them ([`render_replicas`]), writes OUT.exr (the mean,
/// and the replicas' variance of it as the variance layer) and OUT.png, the `--stats` JSON (with
/// `replicas`, `replica_spp` and `variance_estimate`) and the `--profile` JSON.
pub fn run_reference(opts: &RenderOptions, replicas: u32) -> Result<Replicated, SessionError> {
    let mut rep = replicas_with_lock(opts, replicas, true)?;
    let encode_start = std::time::Instant::now();
    let stem = output_stem(opts, &rep.out.scene.desc);
    let (w, h) = (rep.out.film.width, rep.out.film.height);
    let (exr, png) = (with_ext(&stem, "exr"), with_ext(&stem, "png"));
    let meta = replicated_metadata(&rep, opts.seed);
    film::write_exr(&exr, w, h, &rep.mean, Some(&rep.variance), &meta)
        .map_err(|source| SessionError::Output { path: exr.clone(), source })?;
    let quantize = super::options::default_quantize(opts);
    film::encode_png_quantized(&png, w, h, &rep.mean, rep.out.scene.desc.gamma, quantize)
        .and_then(|bytes| film::write_atomic(&png, &bytes))
        .map_err(|source| SessionError::Output { path: png.clone(), source })?;
    rep.out.out = Some(stem);
    if let Some(p) = &opts.profile {
        // The encoding ran on this thread after the replicas: its own phase, added to the total.
        let ns = encode_start.elapsed().as_nanos() as u64;
        rep.out.stats.phase_ns[crate::profile::Phase::Output as usize] += ns;
        rep.out.stats.profiled_ns += ns;
        let profile =
            super::profile::Profile::from_stats(&rep.out.scene.desc.source.display().to_string(), &rep.out.stats);
        super::profile::write_text(p, &serde_json::to_string_pretty(&profile)?)?;
    }
    if let Some(p) = &opts.stats {
        let text = serde_json::to_string_pretty(&replicated_stats(&rep, opts.seed))?;
        film::write_atomic(p, text.as_bytes()).map_err(|source| SessionError::Output { path: p.clone(), source })?;
    }
    Ok(rep)
}

/// The `--stats` JSON of a replicated reference: a render's, with the totals over the replicas,
/// the base seed, the replicas, their spp and seeds, and how the variance was estimated
/// (`variance_estimate`).
pub fn replicated_stats(rep: &Replicated, base_seed: u64) -> serde_json::Value {
    let mut j = stats_json(&rep.out);
    j["spp"] = rep.spp().into();
    j["seed"] = base_seed.into();
    j["total_render_seconds"] = rep.out.header.render_seconds.into();
    j["total_cpu_seconds"] = rep.out.header.cpu_seconds.into();
    j["replicas"] = rep.replicas.into();
    j["replica_spp"] = rep.replica_spp.into();
    j["replica_seeds"] = rep.seeds.clone().into();
    j["variance_estimate"] = rep.variance_text().into();
    j
}

/// The one-line summary of a replicated reference.
pub fn summary(rep: &Replicated) -> String {
    let spp = format!("{} spp ({} replicas x {})", rep.spp(), rep.replicas, rep.replica_spp);
    super::stats::summary_with_spp(&rep.out, &spp)
}

#[cfg(test)]
mod tests;

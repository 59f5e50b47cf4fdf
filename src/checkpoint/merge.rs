//! `strata merge`: the finished part files of `render --samples A..B` shards into one image,
//! bit-identical to one render of the whole range.

use super::{format, header_for, header_metadata, CheckpointError, Header};
use crate::film::{self, stem_of, with_ext, Film};
use std::path::{Path, PathBuf};

/// What `strata merge` produced.
pub struct MergeOutput {
    /// the merged state (identity, totals, parts)
    pub header: Header,
    /// the merged film
    pub film: Film,
    /// output stem written (OUT.exr, OUT.png)
    pub out: PathBuf,
}

/// `strata merge PARTS... -o OUT`: checks that the parts (checkpoint files of finished `--samples`
/// shards) belong to one render (scene hash, version, size, options) and cover its sample range
/// without overlap or gap, merges their dyadic blocks (bit-identical to one render of the whole
/// range) and writes OUT.exr (metadata: total spp, CPU seconds, the parts) and OUT.png. Parts
/// written by another build of strata are refused unless `allow_other_build` (the merged
/// `strata.build` then lists every build).
pub fn run_merge(parts: &[PathBuf], out: &Path, allow_other_build: bool) -> Result<MergeOutput, CheckpointError> {
    if parts.is_empty() {
        return Err(CheckpointError::NoParts);
    }
    film::check_stem(out).map_err(|source| CheckpointError::Output { path: out.to_path_buf(), source })?;
    let mut loaded: Vec<(PathBuf, Header, Film)> = Vec::new();
    for p in parts {
        let (h, f) = format::read(p)?;
        if h.target[1] == u32::MAX && h.samples != h.target {
            return Err(CheckpointError::TimeBudgetPart { path: p.clone(), samples: h.samples });
        }
        if h.samples != h.target {
            return Err(CheckpointError::Unfinished { path: p.clone(), samples: h.samples, target: h.target });
        }
        if let Some((p0, h0, _)) = loaded.first() {
            if let Some(why) = h.mismatch_allowing(h0, &p0.display().to_string(), allow_other_build) {
                return Err(CheckpointError::Foreign { path: p.clone(), first: p0.clone(), why });
            }
        }
        loaded.push((p.clone(), h, f));
    }
    loaded.sort_by_key(|(_, h, _)| h.samples);
    let want_end = match loaded[0].1.options.get("layout").and_then(|v| v.as_str()) {
        Some("spp") => loaded[0].1.options.get("spp").and_then(|v| v.as_u64()),
        _ => None,
    };
    let name = |p: &PathBuf, h: &Header| format!("{} ({}..{})", p.display(), h.samples[0], h.samples[1]);
    if loaded[0].1.samples[0] != 0 {
        return Err(CheckpointError::MissingStart(loaded[0].1.samples[0]));
    }
    for w in loaded.windows(2) {
        let ((pa, ha, _), (pb, hb, _)) = (&w[0], &w[1]);
        if hb.samples[0] < ha.samples[1] {
            return Err(CheckpointError::Overlap(name(pa, ha), name(pb, hb)));
        }
        if hb.samples[0] > ha.samples[1] {
            return Err(CheckpointError::Gap {
                from: ha.samples[1],
                to: hb.samples[0],
                a: name(pa, ha),
                b: name(pb, hb),
            });
        }
    }
    let last = loaded.last().map(|(_, h, _)| h.samples[1]).unwrap_or(0);
    if let Some(end) = want_end {
        if u64::from(last) != end {
            return Err(CheckpointError::MissingEnd { last: u64::from(last), end });
        }
    }
    let mut header = loaded[0].1.clone();
    let (w, h) = (header.width, header.height);
    let mut film = Film::new(w, h);
    (header.cpu_seconds, header.render_seconds, header.rays, header.parts) = (0.0, 0.0, 0, Vec::new());
    for (p, ph, f) in &loaded {
        film.merge(f).map_err(|source| CheckpointError::Film { path: p.clone(), source })?;
        header.cpu_seconds += ph.cpu_seconds;
        header.render_seconds += ph.render_seconds;
        header.rays += ph.rays;
        if !header.strata_build.split(" + ").any(|b| b == ph.strata_build) {
            header.strata_build = format!("{} + {}", header.strata_build, ph.strata_build);
        }
        if ph.parts.is_empty() {
            header.parts.push(name(p, ph));
        } else {
            header.parts.extend(ph.parts.iter().cloned());
        }
    }
    header.target = [0, last];
    header = header_for(header, &film);
    let stem = stem_of(out);
    let (mean, var) = (film.mean(), film.variance_of_mean());
    let exr = with_ext(&stem, "exr");
    film::write_exr(&exr, w, h, &mean, Some(&var), &header_metadata(&header))
        .map_err(|source| CheckpointError::Output { path: exr.clone(), source })?;
    let gamma = header.options.get("gamma").and_then(|v| v.as_f64()).unwrap_or(1.0) as f32;
    let png = with_ext(&stem, "png");
    // Parts written before `quantize` was recorded were rounded.
    let q = header.options.get("quantize").and_then(|v| v.as_str()).and_then(film::Quantize::parse);
    film::write_png_quantized(&png, w, h, &mean, gamma, q.unwrap_or(film::Quantize::Round))
        .map_err(|source| CheckpointError::Output { path: png.clone(), source })?;
    Ok(MergeOutput { header, film, out: stem })
}

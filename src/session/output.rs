//! The outputs of `strata render`: the output stem, EXR metadata, OUT.exr (with a variance layer),
//! OUT.png and the `--stats` file.

use super::pass::{render_passes, write_checkpoint};
use super::stats::stats_json;
use super::{RenderOptions, RenderOutput, SessionError};
use crate::checkpoint::header_metadata;
use crate::film::{self, stem_of, with_ext, Metadata};
use crate::scene::desc::SceneDesc;
use std::path::{Path, PathBuf};

/// Output stem: `-o OUT`, else the scene's `output` file name without extension (directories
/// stripped: a scene file never chooses where we write), else "strata".
pub fn output_stem(opts: &RenderOptions, desc: &SceneDesc) -> PathBuf {
    if let Some(o) = &opts.out {
        return stem_of(o);
    }
    desc.output
        .as_deref()
        .and_then(|n| Path::new(n).file_stem())
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("strata"))
}

/// The camera as `--camera` spells it, "ex ey ez cx cy cz ux uy uz fovy" (shortest round-trip
/// decimals), or `default` when the scene has none: the EXR attribute `strata.camera`.
pub fn camera_text(c: Option<&crate::scene::desc::CameraDesc>) -> String {
    c.map_or_else(
        || "default".into(),
        |c| {
            let v: Vec<String> = [c.eye.to_array(), c.center.to_array(), c.up.to_array()]
                .concat()
                .into_iter()
                .chain([c.fovy_deg])
                .map(|x| x.to_string())
                .collect();
            v.join(" ")
        },
    )
}

/// `strata.variance` of a render: the i.i.d. formula over its samples.
pub const VARIANCE_IID: &str =
    "iid: sample variance / n over the render's samples (exact for independent samples; overstated for stratified and low-discrepancy ones)";

/// Metadata written into the EXR header of a render ([`header_metadata`] and the thread count).
pub fn metadata(out: &RenderOutput) -> Metadata {
    let mut m = header_metadata(&out.header);
    m.push(("strata.threads".into(), out.stats.threads.to_string()));
    // The camera, so that `compare` can refuse a reference of another view.
    m.push(("strata.camera".into(), camera_text(out.scene.desc.camera.as_ref())));
    // How the variance layer was estimated (`strata reference` replaces it: replicas).
    m.push(("strata.variance".into(), VARIANCE_IID.into()));
    m
}

/// `strata render`: render, write OUT.exr (with a variance layer) and OUT.png, the stats JSON,
/// with `--profile` the profile JSON (the phases of the render and of the image encoding), then the
/// checkpoint (last: one that cannot be written is an error, the images stay). Non-finite samples
/// (counted as zero) are reported on stderr.
pub fn run_render(opts: &RenderOptions) -> Result<RenderOutput, SessionError> {
    let mut out = render_passes(opts, true)?;
    let nonfinite = out.stats.counters.nonfinite;
    if nonfinite > 0 {
        eprintln!(
            "strata: warning: {nonfinite} non-finite sample{} (NaN or infinite radiance) counted as zero: the image is \
             biased low where they fell (`nonfinite_samples` in --stats); check the scene's emission and material values",
            if nonfinite == 1 { "" } else { "s" }
        );
    }
    let encode_start = std::time::Instant::now();
    let stem = output_stem(opts, &out.scene.desc);
    let (w, h) = (out.film.width, out.film.height);
    let mean = out.film.mean();
    let var = out.film.variance_of_mean();
    let (exr, png) = (with_ext(&stem, "exr"), with_ext(&stem, "png"));
    let (gamma, quantize, meta) = (out.scene.desc.gamma, super::options::default_quantize(opts), metadata(&out));
    // The two encodes are independent: the PNG is encoded on a second thread while this one writes
    // the EXR (whose ZIP blocks dominate a short render's wall time), so encoding costs the longer
    // of the two, not their sum. The files are still written in order, atomically: the PNG only
    // once the EXR is in place (a failed EXR write leaves the old PNG), an error naming its file.
    let (exr_result, png_bytes) = std::thread::scope(|s| {
        let png_job = s.spawn(|| film::encode_png_quantized(&png, w, h, &mean, gamma, quantize));
        let exr_result = film::write_exr(&exr, w, h, &mean, Some(&var), &meta);
        (exr_result, png_job.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
    });
    // Every output is tried even when another failed (a full disk, a removed directory): the
    // finished render survives in whichever could be written, and the error says which.
    let mut failed: Vec<SessionError> = Vec::new();
    let mut written: Vec<PathBuf> = Vec::new();
    match exr_result {
        Ok(()) => {
            written.push(exr.clone());
            match png_bytes.and_then(|bytes| film::write_atomic(&png, &bytes)) {
                Ok(()) => written.push(png.clone()),
                Err(source) => failed.push(SessionError::Output { path: png.clone(), source }),
            }
        }
        Err(source) => failed.push(SessionError::Output { path: exr.clone(), source }),
    }
    if failed.is_empty() {
        out.out = Some(stem.clone());
    }
    if let Some(p) = &opts.profile {
        // The encoding ran on this thread after the render: its own phase, added to the total.
        let ns = encode_start.elapsed().as_nanos() as u64;
        out.stats.phase_ns[crate::profile::Phase::Output as usize] += ns;
        out.stats.profiled_ns += ns;
        let profile = super::profile::Profile::from_stats(&out.scene.desc.source.display().to_string(), &out.stats);
        match super::profile::write_text(p, &serde_json::to_string_pretty(&profile)?) {
            Ok(()) => written.push(p.clone()),
            Err(e) => failed.push(e),
        }
    }
    if let Some(p) = &opts.stats {
        let text = serde_json::to_string_pretty(&stats_json(&out))?;
        match film::write_atomic(p, text.as_bytes()) {
            Ok(()) => written.push(p.clone()),
            Err(source) => failed.push(SessionError::Output { path: p.clone(), source }),
        }
    }
    let ckpt = write_checkpoint(&out);
    drop(out.lock.take());
    match ckpt {
        Ok(()) if failed.is_empty() => return Ok(out),
        Ok(()) => written.extend(out.checkpoint.clone()),
        Err(e) if failed.is_empty() => {
            return Err(SessionError::CheckpointAfterImages { images: stem, source: Box::new(e) })
        }
        Err(e) => failed.push(e),
    }
    Err(SessionError::OutputsFailed {
        failed: failed.iter().map(ToString::to_string).collect::<Vec<_>>().join("; "),
        written: if written.is_empty() {
            "nothing was written".into()
        } else {
            let w: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
            let resume = match &out.checkpoint {
                Some(c) if written.contains(c) => {
                    format!(" (the finished render is in {}: --resume it to write the rest)", c.display())
                }
                _ => String::new(),
            };
            format!("written: {}{resume}", w.join(", "))
        },
    })
}

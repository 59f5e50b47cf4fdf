//! `direct`'s lights outside the light selection: the environment (`constant` / `--sky`, or
//! `envmap`) and the delta lights. At every shaded camera hit, each of the `lightsamples` light
//! samples draws one environment direction from the dimension [`ENVIRONMENT`] (for the constant
//! sky the cosine-weighted hemisphere of the shading normal, for the envmap its luminance
//! distribution) and adds `L f cos / (pdf N)` where the
//! shadow ray escapes (times its MIS weight against the BSDF samples, when `direct` draws
//! some: `direct_bsdf.rs`); each delta light adds `f cos li` once (its direction is fixed, so its N
//! samples would be equal; no BSDF sample finds it: weight 1). Light sampling alone is unbiased
//! for both on opaque surfaces (the sky's hemisphere and the envmap's distribution cover every
//! direction that brings light to the front of the surface); light through a transmitting
//! surface comes from the BSDF samples. Camera rays that escape see the environment directly
//! (`primary.rs`).

use super::{Batch, Lanes, LightTable, Mis, DIM_LIGHT_BASE, MIS_STRATEGY};
use crate::accel::Ray8;
use crate::bsdf::LobeSet;
use crate::integrator::context::{masked, shading_frame, TileCtx};
use crate::integrator::light_term::{env_sample, Shading, SkySampling};
use crate::integrator::samples::{Dim, Source};
use crate::integrator::settings::Integrator;
use crate::scene::desc::ImportanceSampling;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Mask8, Vec3x8, F8};

/// The environment direction (2D), with an environment light only.
pub const ENVIRONMENT: Dim =
    Dim { name: "environment direction", first: DIM_LIGHT_BASE - 8, stride: 0, source: Source::Light };

/// Adds the environment's and the delta lights' direct light at the hits `hits` (shading lanes
/// and shadow-ray offsets `lanes`) of pixel sample `s` to `out`; the environment's samples
/// weighted against `direct`'s BSDF samples when `mis` is given.
pub(super) fn shade_outside<L: LobeSet>(
    it: &Integrator,
    ctx: &mut TileCtx,
    hits: &[SurfaceHit8],
    lanes: &Lanes,
    s: u32,
    out: &mut [Vec3x8],
    mis: Option<Mis>,
) {
    let TileCtx { scene, pks, tracer, samples: smp } = ctx;
    let mut batch = Batch::default();
    let n_light = it.light_set.n();
    let inv_n = F8::splat(1.0 / n_light as f32);
    // No throughput: the light term itself (1 f is f, bit for bit).
    let one = Vec3x8::splat(glam::Vec3::ONE);
    let has_env = scene.sky.is_some() || scene.envmap.is_some();
    let table = has_env.then(|| LightTable::new(it, smp, ENVIRONMENT.first, s));
    // With BSDF samples too, each environment sample is weighted against them (power heuristic).
    let strategy = if mis.is_some() { MIS_STRATEGY } else { ImportanceSampling::Cosine };
    // The packet's frame and material once for all its samples (a camera packet's shadow packets
    // still reach the batch in the same order: the environment's k = 0..N, then the delta lights,
    // so its sum is the same bits as with a frame and material per sample).
    for (i, sh) in hits.iter().enumerate() {
        let shade = lanes.shade[i];
        if shade.none() {
            continue;
        }
        let frame = shading_frame::<L>(scene, sh);
        let o = sh.ng.mul_add(lanes.eps[i], sh.p);
        if let Some(table) = &table {
            let at = Shading::new(sh, &frame, strategy);
            for k in 0..n_light {
                let uv = table.point(smp, pks[i].pixel, k);
                let Some(e) = env_sample(scene, SkySampling::Cosine, at.frame, uv, shade) else { continue };
                let weight = |pdf_b: F8, lit: Mask8| match &mis {
                    Some(m) => inv_n * m.light(e.pdf, pdf_b, lit),
                    None => inv_n,
                };
                let Some((lit, wi, c)) = at.env_event::<L>(&e, one, shade, weight) else { continue };
                batch.contrib.push(masked(c, lit));
                batch.push(Ray8::new(o, wi, F8::ZERO, F8::splat(f32::INFINITY), lit), i);
            }
        }
        if !scene.delta.is_empty() {
            let at = Shading::new(sh, &frame, ImportanceSampling::Cosine);
            at.delta_events::<L>(scene, one, shade, |lit: Mask8, wi, tfar, c| {
                batch.contrib.push(masked(c, lit));
                batch.push(Ray8::new(o, wi, F8::ZERO, tfar, lit), i);
            });
        }
    }
    batch.trace(tracer, out);
}

//! `direct`'s lights outside the light selection: the environment (`constant` / `--sky`, or
//! `envmap`) and the delta lights. At every shaded camera hit, each of the `lightsamples` light
//! samples draws one environment direction from the dimension [`ENVIRONMENT`] (for the constant
//! sky the cosine-weighted hemisphere of the shading normal, for the envmap its luminance
//! distribution) and adds `L f cos / (pdf N)` where the
//! shadow ray escapes; each delta light adds `f cos li` once (its direction is fixed, so its N
//! samples would be equal). Light sampling alone is unbiased for both (the sky's hemisphere and
//! the envmap's distribution cover every direction that brings light to the front of an opaque
//! surface); camera rays that escape see
//! the environment directly (`primary.rs`).

use super::{Batch, Lanes, LightTable, DIM_LIGHT_BASE};
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
/// and shadow-ray offsets `lanes`) of pixel sample `s` to `out`.
pub(super) fn shade_outside<L: LobeSet>(
    it: &Integrator,
    ctx: &mut TileCtx,
    hits: &[SurfaceHit8],
    lanes: &Lanes,
    s: u32,
    out: &mut [Vec3x8],
) {
    let TileCtx { scene, pks, tracer, samples: smp } = ctx;
    let mut batch = Batch::default();
    let n_light = it.light_set.n();
    let inv_n = F8::splat(1.0 / n_light as f32);
    // No throughput: the light term itself (1 f is f, bit for bit).
    let one = Vec3x8::splat(glam::Vec3::ONE);
    if scene.sky.is_some() || scene.envmap.is_some() {
        let table = LightTable::new(it, smp, ENVIRONMENT.first, s);
        for k in 0..n_light {
            for (i, sh) in hits.iter().enumerate() {
                let shade = lanes.shade[i];
                if shade.none() {
                    continue;
                }
                let uv = table.point(smp, pks[i].pixel, k);
                let frame = shading_frame::<L>(scene, sh);
                let at = Shading::new(sh, &frame, ImportanceSampling::Cosine);
                let Some(e) = env_sample(scene, SkySampling::Cosine, at.frame, uv, shade) else { continue };
                let Some((lit, wi, c)) = at.env_event::<L>(&e, one, shade, |_, _| inv_n) else { continue };
                batch.contrib.push(masked(c, lit));
                let o = sh.ng.mul_add(lanes.eps[i], sh.p);
                batch.push(Ray8::new(o, wi, F8::ZERO, F8::splat(f32::INFINITY), lit), i);
            }
        }
    }
    if !scene.delta.is_empty() {
        for (i, sh) in hits.iter().enumerate() {
            let shade = lanes.shade[i];
            if shade.none() {
                continue;
            }
            let frame = shading_frame::<L>(scene, sh);
            let at = Shading::new(sh, &frame, ImportanceSampling::Cosine);
            let o = sh.ng.mul_add(lanes.eps[i], sh.p);
            at.delta_events::<L>(scene, one, shade, |lit: Mask8, wi, tfar, c| {
                batch.contrib.push(masked(c, lit));
                batch.push(Ray8::new(o, wi, F8::ZERO, tfar, lit), i);
            });
        }
    }
    batch.trace(tracer, out);
}

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

use super::{light_term_f, trace_shadow_batch, LightTable, DIM_LIGHT_BASE};
use crate::accel::Ray8;
use crate::bsdf::LobeSet;
use crate::integrator::context::{masked, TileCtx};
use crate::integrator::samples::{Dim, Source};
use crate::integrator::settings::Integrator;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Frame8, Mask8, Vec3x8, F8};

/// The environment direction (2D), with an environment light only.
pub const ENVIRONMENT: Dim =
    Dim { name: "environment direction", first: DIM_LIGHT_BASE - 8, stride: 0, source: Source::Light };

/// Adds the environment's and the delta lights' direct light at the hits `hits` (shading lanes
/// `shade`, shadow-ray offsets `eps`) of pixel sample `s` to `out`.
pub(super) fn shade_outside<L: LobeSet>(
    it: &Integrator,
    ctx: &mut TileCtx,
    hits: &[SurfaceHit8],
    shade: &[Mask8],
    eps: &[F8],
    s: u32,
    out: &mut [Vec3x8],
) {
    let TileCtx { scene, pks, tracer, samples: smp } = ctx;
    let (mut shadow, mut contrib, mut owner) = (Vec::new(), Vec::new(), Vec::new());
    let n_light = it.light_set.n();
    let inv_n = F8::splat(1.0 / n_light as f32);
    if scene.sky.is_some() || scene.envmap.is_some() {
        let table = LightTable::new(it, smp, ENVIRONMENT.first, s);
        for k in 0..n_light {
            for (i, sh) in hits.iter().enumerate() {
                if shade[i].none() {
                    continue;
                }
                let (u, v) = table.point(smp, pks[i].pixel, k);
                let frame = Frame8::from_normal(sh.n);
                let (wi, pdf, le) = {
                    let _p = crate::profile::leaf(crate::profile::Phase::Emitter);
                    match (&scene.sky, &scene.envmap) {
                        (Some(sky), _) => {
                            // Cosine-weighted about the shading normal: for a diffuse surface the
                            // estimate is `L kd` wherever the sky is visible (Mitsuba's MIS of
                            // light and BSDF samples comes close to it; uniform hemisphere samples
                            // had 12 times its variance on a plane, which its z-test rejects).
                            let (wl, pdf) = crate::sampling::sample_cosine_hemisphere_x8([u, v], shade[i]);
                            (frame.to_world(wl), pdf, Vec3x8::splat(sky.radiance))
                        }
                        (None, Some(env)) => env.sample_x8(u, v, shade[i]),
                        (None, None) => unreachable!("checked above"),
                    }
                };
                let ok = shade[i] & pdf.simd_gt(F8::ZERO);
                let Some((f, cos, lit)) = light_term_f::<L>(scene, sh, wi, ok) else { continue };
                contrib.push(masked(f.mul_elem(le).scale(cos / pdf * inv_n), lit));
                let o = sh.ng.mul_add(eps[i], sh.p);
                let (ray, lit) = Ray8::new(o, wi, F8::ZERO, F8::splat(f32::INFINITY), lit);
                shadow.push((ray, lit));
                owner.push(i as u32);
            }
        }
    }
    for light in &scene.delta {
        for (i, sh) in hits.iter().enumerate() {
            if shade[i].none() {
                continue;
            }
            let (wi, dist, li, ok) = {
                let _p = crate::profile::leaf(crate::profile::Phase::Emitter);
                light.sample_x8(sh.p, shade[i])
            };
            let Some((f, cos, lit)) = light_term_f::<L>(scene, sh, wi, ok) else { continue };
            contrib.push(masked(f.mul_elem(li).scale(cos), lit));
            let o = sh.ng.mul_add(eps[i], sh.p);
            let tfar = match light.position() {
                Some(y) => dist - scene.offset_eps(Vec3x8::splat(y)),
                None => F8::splat(f32::INFINITY),
            };
            let (ray, lit) = Ray8::new(o, wi, F8::ZERO, tfar, lit);
            shadow.push((ray, lit));
            owner.push(i as u32);
        }
    }
    trace_shadow_batch(tracer, &mut shadow, &contrib, &owner, out);
}

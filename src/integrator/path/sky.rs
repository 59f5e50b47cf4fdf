//! The path tracer's hooks for the lights outside the light selection: the constant environment
//! light ([`crate::light::sky`]) and the envmap ([`crate::light::envmap`]), each with the radiance
//! of escaped rays and a next event at a shaded vertex (MIS against the BSDF), and the delta
//! lights ([`crate::light::delta`]: a next event each, weight 1). Its sample points come
//! from their own dimensions, `DIM_SKY_BASE + (v - 1)` for vertex v, so a scene with a sky keeps
//! every other dimension of the path (and a scene without one renders exactly as before).

use crate::bsdf::interface::flags as lobe_flags;
use crate::bsdf::{BsdfSet, LobeSet, Material8};
use crate::integrator::settings::Integrator;
use crate::light::envmap::Envmap;
use crate::light::sky::Sky;
use crate::sampling::power_heuristic_x8;
use crate::scene::desc::Nee;
use crate::simd::{Frame8, Mask8, Vec3x8, F8};

/// First sampler dimension of the sky's next events (one per vertex, after every vertex's own:
/// `DIM_PATH_BASE + 4 MAX_VERTICES_UNBOUNDED`, checked where those are defined).
pub const DIM_SKY_BASE: u32 = 64 + 4 * 4096;

/// Sky radiance, weighted by the next-event mode, brought by the rays of vertex `v` that left the
/// scene (`missed`), their direction sampled with `pdf` (negative after a delta lobe: weighted as
/// at the camera vertex, no light sample could have found it).
#[inline]
pub(super) fn escaped<L: LobeSet>(it: &Integrator, sky: &Sky, v: u32, pdf: F8, missed: Mask8) -> Vec3x8 {
    let (on, mis) = (it.path.nee != Nee::Off, it.path.nee == Nee::Mis);
    let le = sky.escaped_x8(on, mis, v, pdf, missed);
    if <L::Bsdfs as BsdfSet>::FLAGS & lobe_flags::DELTA != 0 {
        let delta = missed & pdf.simd_lt(F8::ZERO);
        if delta.any() {
            return Vec3x8::select(delta, sky.escaped_x8(on, mis, 1, pdf, delta), le);
        }
    }
    le
}

/// The sky's next event at the shaded lanes `shade` of a vertex with throughput `beta`: one
/// direction uniform over the shading hemisphere from the sample `(u, w)`, MIS-weighted against
/// the BSDF. `leaves` tells the directions that also leave the geometric surface. Returns the lit
/// lanes, the world direction (a shadow ray to infinity) and the contribution, or None.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn next_event<L: LobeSet>(
    it: &Integrator,
    sky: &Sky,
    (u, w): (F8, F8),
    frame: &Frame8,
    wo: Vec3x8,
    mat: &Material8,
    beta: Vec3x8,
    shade: Mask8,
    leaves: impl Fn(Vec3x8) -> Mask8,
) -> Option<(Mask8, Vec3x8, Vec3x8)> {
    let (wi_l, pdf) = sky.sample_x8(u, w, shade);
    let wi = frame.to_world(wi_l);
    let lit = shade & wi_l.z.simd_gt(F8::ZERO) & pdf.simd_gt(F8::ZERO) & leaves(wi);
    if lit.none() {
        return None;
    }
    let (f, pdf_b) = {
        let _p = crate::profile::leaf(crate::profile::Phase::BsdfEval);
        mat.eval_pdf_k::<L>(it.path.strategy, wo, wi_l, lit)
    };
    let weight = Sky::nee_weight_x8(it.path.nee == Nee::Mis, pdf_b, lit);
    let g = lit.select(wi_l.z / pdf * weight, F8::ZERO);
    Some((lit, wi, beta.mul_elem(f).mul_elem(Vec3x8::splat(sky.radiance)).scale(g)))
}

/// Envmap radiance, weighted by the next-event mode as [`escaped`] weighs the sky's, brought by
/// the rays of vertex `v` that left the scene (`missed`) along `dir`, sampled with `pdf`.
#[inline]
pub(super) fn escaped_envmap<L: LobeSet>(
    it: &Integrator,
    env: &Envmap,
    v: u32,
    dir: Vec3x8,
    pdf: F8,
    missed: Mask8,
) -> Vec3x8 {
    let (le, p_env) = env.radiance_pdf_x8(dir, missed);
    let w = if v == 1 || it.path.nee == Nee::Off {
        missed.select(F8::ONE, F8::ZERO)
    } else if it.path.nee == Nee::Mis {
        power_heuristic_x8(pdf, p_env, missed)
    } else {
        F8::ZERO
    };
    let w = if <L::Bsdfs as BsdfSet>::FLAGS & lobe_flags::DELTA != 0 {
        (missed & pdf.simd_lt(F8::ZERO)).select(F8::ONE, w)
    } else {
        w
    };
    le.scale(w)
}

/// The envmap's next event at the shaded lanes `shade` (as [`next_event`] for the sky): one
/// direction drawn from the map's distribution, MIS-weighted against the BSDF.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn envmap_next_event<L: LobeSet>(
    it: &Integrator,
    env: &Envmap,
    (u, w): (F8, F8),
    frame: &Frame8,
    wo: Vec3x8,
    mat: &Material8,
    beta: Vec3x8,
    shade: Mask8,
    leaves: impl Fn(Vec3x8) -> Mask8,
) -> Option<(Mask8, Vec3x8, Vec3x8)> {
    let (wi, pdf, le) = {
        let _p = crate::profile::leaf(crate::profile::Phase::Emitter);
        env.sample_x8(u, w, shade)
    };
    let wi_l = frame.to_local(wi);
    let lit = shade & wi_l.z.simd_gt(F8::ZERO) & pdf.simd_gt(F8::ZERO) & leaves(wi);
    if lit.none() {
        return None;
    }
    let (f, pdf_b) = {
        let _p = crate::profile::leaf(crate::profile::Phase::BsdfEval);
        mat.eval_pdf_k::<L>(it.path.strategy, wo, wi_l, lit)
    };
    let weight = if it.path.nee == Nee::Mis { power_heuristic_x8(pdf, pdf_b, lit) } else { F8::ONE };
    let g = lit.select(wi_l.z / pdf * weight, F8::ZERO);
    Some((lit, wi, beta.mul_elem(f).mul_elem(le).scale(g)))
}

/// The delta lights' next events at the shaded lanes `shade` of a vertex at `p` (throughput
/// `beta`): each light once, weight 1 (no BSDF sampling can reach a delta light). Calls `push`
/// with (lit lanes, unit direction, shadow-ray length, contribution) per light that lights a lane.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn delta_next_events<L: LobeSet>(
    it: &Integrator,
    scene: &crate::scene::build::Scene,
    p: Vec3x8,
    frame: &Frame8,
    wo: Vec3x8,
    mat: &Material8,
    beta: Vec3x8,
    shade: Mask8,
    leaves: impl Fn(Vec3x8) -> Mask8,
    mut push: impl FnMut(Mask8, Vec3x8, F8, Vec3x8),
) {
    for light in &scene.delta {
        let (wi, dist, li, ok) = {
            let _p = crate::profile::leaf(crate::profile::Phase::Emitter);
            light.sample_x8(p, shade)
        };
        let wi_l = frame.to_local(wi);
        let lit = ok & wi_l.z.simd_gt(F8::ZERO) & leaves(wi);
        if lit.none() {
            continue;
        }
        let f = {
            let _p = crate::profile::leaf(crate::profile::Phase::BsdfEval);
            mat.eval_pdf_k::<L>(it.path.strategy, wo, wi_l, lit).0
        };
        // The shadow ray stops short of the light (a point; infinity for directional).
        let tfar = match light.position() {
            Some(y) => dist - scene.offset_eps(Vec3x8::splat(y)),
            None => F8::splat(f32::INFINITY),
        };
        let c = beta.mul_elem(f).mul_elem(li).scale(lit.select(wi_l.z, F8::ZERO));
        push(lit, wi, tfar, c);
    }
}

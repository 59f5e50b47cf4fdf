//! The path tracer's two hooks for the constant environment light ([`crate::light::sky`]): the
//! radiance of escaped rays, and the sky's next event at a shaded vertex. Its sample points come
//! from their own dimensions, `DIM_SKY_BASE + (v - 1)` for vertex v, so a scene with a sky keeps
//! every other dimension of the path (and a scene without one renders exactly as before).

use crate::bsdf::{LobeSet, Material8};
use crate::integrator::settings::Integrator;
use crate::light::sky::Sky;
use crate::scene::desc::Nee;
use crate::simd::{Frame8, Mask8, Vec3x8, F8};

/// First sampler dimension of the sky's next events (one per vertex, after every vertex's own:
/// `DIM_PATH_BASE + 4 MAX_VERTICES_UNBOUNDED`, checked where those are defined).
pub const DIM_SKY_BASE: u32 = 64 + 4 * 4096;

/// Sky radiance, weighted by the next-event mode, brought by the rays of vertex `v` that left the
/// scene (`missed`), their direction sampled with `pdf`.
#[inline]
pub(super) fn escaped(it: &Integrator, sky: &Sky, v: u32, pdf: F8, missed: Mask8) -> Vec3x8 {
    sky.escaped_x8(it.path.nee != Nee::Off, it.path.nee == Nee::Mis, v, pdf, missed)
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

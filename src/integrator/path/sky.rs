//! The path tracer's two hooks for the constant environment light ([`crate::light::sky`]): the
//! radiance of escaped rays, and the sky's next event at a shaded vertex. Its sample points come
//! from their own dimensions, `DIM_SKY_BASE + (v - 1)` for vertex v, so a scene with a sky keeps
//! every other dimension of the path (and a scene without one renders exactly as before).

use super::{bits, Bounce, Vertex, MAX_VERTICES_UNBOUNDED};
use super::{DIM_PATH_BASE, SHADOW_COLS, S_SLOT};
use crate::bsdf::{LobeSet, Material8};
use crate::integrator::Integrator;
use crate::light::sky::Sky;
use crate::sampler::PathDim;
use crate::scene::desc::Nee;
use crate::simd::{Frame8, Mask8, Vec3x8, F8};

use super::wave::{Columns, Pack};

/// First sampler dimension of the sky's next events (one per vertex, after every vertex's own).
pub const DIM_SKY_BASE: u32 = DIM_PATH_BASE + 4 * MAX_VERTICES_UNBOUNDED;

/// The sky's sampler dimension at vertex `v`, when the scene has a sky (a light dimension: drawn
/// from the light sampler's table).
pub(super) fn sky_dim(it: &Integrator, sky: Option<&Sky>, v: u32) -> Option<PathDim> {
    sky.map(|_| it.light_table.path_dim(it.spp, DIM_SKY_BASE + (v - 1), it.seed))
}

/// Sky radiance, weighted by the next-event mode, brought by the rays of vertex `v` that left the
/// scene (`missed`), their direction sampled with `pdf`.
#[inline]
pub(super) fn escaped(it: &Integrator, sky: &Sky, v: u32, pdf: F8, missed: Mask8) -> Vec3x8 {
    sky.escaped_x8(it.nee != Nee::Off, it.nee == Nee::Mis, v, pdf, missed)
}

impl Bounce<'_> {
    /// The sky's next event at the shaded lanes `shade` of `vx`: one direction uniform over the
    /// shading hemisphere, its contribution (MIS-weighted against the BSDF) pushed as a shadow ray
    /// to infinity from `o`. `leaves` tells the directions that also leave the geometric surface.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(super) fn sky_next_event<L: LobeSet>(
        &mut self,
        vx: &Vertex,
        frame: &Frame8,
        wo: Vec3x8,
        mat: &Material8,
        o: Vec3x8,
        shade: Mask8,
        leaves: impl Fn(Vec3x8) -> Mask8,
    ) {
        let (Some(sky), Some(dim)) = (self.scene.sky.as_ref(), self.dsky.as_ref()) else { return };
        let it = self.it;
        let (u, w) = it.path_point(dim, true, vx.pixel, vx.s);
        let (wi_l, pdf) = sky.sample_x8(u, w, shade);
        let wi = frame.to_world(wi_l);
        let lit = shade & wi_l.z.simd_gt(F8::ZERO) & pdf.simd_gt(F8::ZERO) & leaves(wi);
        if lit.none() {
            return;
        }
        let (f, pdf_b) = {
            let _p = crate::profile::leaf(crate::profile::Phase::BsdfEval);
            mat.eval_pdf_k::<L>(it.strategy, wo, wi_l, lit)
        };
        let weight = Sky::nee_weight_x8(it.nee == Nee::Mis, pdf_b, lit);
        let g = lit.select(wi_l.z / pdf * weight, F8::ZERO);
        let c = vx.beta.mul_elem(f).mul_elem(Vec3x8::splat(sky.radiance)).scale(g);
        let inf = F8::splat(f32::INFINITY);
        push_shadow(self.shadow, lit, &[bits(vx.slot), o.x, o.y, o.z, wi.x, wi.y, wi.z, inf, c.x, c.y, c.z]);
    }
}

/// The lanes `lit` of one shadow row, left-packed onto the bounce's shadow rays.
#[inline]
fn push_shadow(shadow: &mut Columns<SHADOW_COLS>, lit: Mask8, row: &[F8; SHADOW_COLS]) {
    let pack = Pack::of(lit);
    shadow.write(S_SLOT, &pack, row);
    shadow.advance(&pack);
}

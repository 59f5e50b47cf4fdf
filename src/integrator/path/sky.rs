//! The path tracer's escaped rays and the environment's dimensions: the radiance an escaped ray
//! brings from the constant environment light ([`crate::light::sky`]) or the envmap
//! ([`crate::light::envmap`]), weighted by the next-event mode. Their next events (and the delta
//! lights', weight 1) are the shared light term's ([`crate::integrator::light_term`]); their sample
//! points come from their own dimensions, `DIM_SKY_BASE + (v - 1)` for vertex v, so a scene with
//! an environment keeps every other dimension of the path (and a scene without one renders
//! exactly as before).

use crate::bsdf::interface::flags as lobe_flags;
use crate::bsdf::{BsdfSet, LobeSet};
use crate::integrator::settings::Integrator;
use crate::light::sky::escaped_weight_x8;
use crate::scene::desc::Nee;
use crate::simd::{Mask8, Vec3x8, F8};

/// First sampler dimension of the sky's next events (one per vertex, after every vertex's own:
/// `DIM_PATH_BASE + 4 MAX_VERTICES_UNBOUNDED`, checked where those are defined).
pub const DIM_SKY_BASE: u32 = 64 + 4 * 4096;

/// Environment radiance `le` (its next-event pdf `p_light`), weighted by the next-event mode,
/// brought by the rays of vertex `v` that left the scene (`missed`), their direction sampled with
/// `pdf` (negative after a delta lobe: weighted as at the camera vertex, no light sample could
/// have found it).
#[inline]
pub(super) fn escaped<L: LobeSet>(it: &Integrator, v: u32, le: Vec3x8, p_light: F8, pdf: F8, missed: Mask8) -> Vec3x8 {
    let (on, mis) = (it.path.nee != Nee::Off, it.path.nee == Nee::Mis);
    let w = escaped_weight_x8(on, mis, v, pdf, p_light, missed);
    let w = if <L::Bsdfs as BsdfSet>::FLAGS & lobe_flags::DELTA != 0 {
        (missed & pdf.simd_lt(F8::ZERO)).select(F8::ONE, w)
    } else {
        w
    };
    le.scale(w)
}

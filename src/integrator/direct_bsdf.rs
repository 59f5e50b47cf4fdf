//! `direct`'s BSDF samples (Mitsuba's `bsdf_samples`, strata's `--bsdf-samples`). At every
//! shaded camera hit, each of the `n_b` samples draws a direction from the material through the
//! one BSDF interface (`Material8::sample_bsdf_k`, the path tracer's: diffuse, glossy and delta
//! lobes, transmission, a mask's null lobe), traces it ([`BSDF_DIRECTION`], [`BSDF_LOBE`]) and
//! adds `weight Le w` for the emission it finds: an area light's (its emitting side), an emissive
//! material's, the environment's where the ray escapes. As Mitsuba's `direct`, `w` is the power
//! heuristic of the two strategies times their sample counts, `w = (n_b p_b)^2 / ((n_b p_b)^2 +
//! (n_e p_e)^2) / n_b`, where `p_e` is the pdf with which `direct`'s own light sampling draws the
//! direction (`light_term::light_pdf_at_hit_pmf`: the light's group under `all`, the selection's
//! pmf otherwise; the environment's cosine or luminance pdf). `p_e` is 0, so `w` is `1 / n_b`,
//! after a delta lobe (Mitsuba's `Delta` includes the null lobe: a pass-through of a mask finds
//! the emission behind it with weight 1), where light sampling cannot reach the direction (below
//! the shading or geometric surface: transmitted light is the BSDF samples' alone), for an
//! emissive material (never light-sampled) and without emitter sampling. A mask's nested sample
//! carries the masked pdf, the opacity times the nested one (`bsdf/mask.rs`), the `p_b` the light
//! samples weigh against too, so the two weights sum to 1.

use super::{Lanes, Mis, DIM_LIGHT_BASE, MIS_STRATEGY};
use crate::accel::{Hits8, RayHit8};
use crate::bsdf::interface::flags as lobe_flags;
use crate::bsdf::{BsdfSet, LobeSet};
use crate::integrator::context::{shading_frame, TileCtx};
use crate::integrator::light_term::{light_pdf_at_hit_pmf, Shading};
use crate::integrator::samples::{Dim, Source};
use crate::integrator::settings::Integrator;
use crate::integrator::stats::RayKind;
use crate::profile::{leaf, Phase};
use crate::scene::build::Scene;
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Mask8, Vec3x8, F8, U8};

/// The BSDF sample's direction (2D, `sample_bsdf_k`'s `u`), one per BSDF sample.
pub const BSDF_DIRECTION: Dim =
    Dim { name: "BSDF direction", first: DIM_LIGHT_BASE - 7, stride: 0, source: Source::Path };
/// The BSDF sample's lobe choice (x; the course's BRDF mixture, a registry BSDF's lobe).
pub const BSDF_LOBE: Dim = Dim { name: "lobe choice", first: DIM_LIGHT_BASE - 6, stride: 0, source: Source::Path };

/// Per-thread buffers of the BSDF samples, reused across samples and tiles.
#[derive(Default)]
pub(super) struct BsdfBuffers {
    rays: Vec<(RayHit8, Mask8)>,
    rows: Vec<Row>,
    hit: Option<SurfaceHit8>,
}

/// What a traced BSDF packet needs at its hits.
struct Row {
    /// the camera packet it adds to
    owner: u32,
    /// f |cos| / pdf of the sample
    weight: Vec3x8,
    /// the pdf it was drawn with
    pdf: F8,
    /// lanes light sampling could have drawn the direction from (not after a delta lobe, above
    /// the shading and geometric surfaces)
    reach: Mask8,
    /// cos(th_i) about the shading normal (the constant sky's cosine pdf)
    cos: F8,
    /// the shading points and normals (a point-dependent light selection's pmf)
    p: Vec3x8,
    n: Vec3x8,
}

/// Adds the BSDF samples' emission at the hits `hits` (shading lanes and offsets `lanes`) of
/// pixel sample `s` to `out` (see the module docs).
#[inline(never)]
pub(super) fn shade<L: LobeSet>(
    it: &Integrator,
    ctx: &mut TileCtx,
    hits: &[SurfaceHit8],
    lanes: &Lanes,
    buf: &mut BsdfBuffers,
    s: u32,
    out: &mut [Vec3x8],
) {
    let TileCtx { scene, pks, tracer, samples: smp } = ctx;
    let n_b = it.direct.bsdf_samples;
    let n_e = if it.direct.emitter_sampling { it.light_set.n() } else { 0 };
    let mis = Mis::new(n_e, n_b);
    // Drawn over the pixel's spp x n_b BSDF samples (sample b of pixel sample s: s n_b + b).
    let n = it.spp.saturating_mul(n_b);
    let (d_dir, d_lobe) = (smp.table_dim(false, n, BSDF_DIRECTION.first), smp.table_dim(false, n, BSDF_LOBE.first));
    let transmits = <L::Bsdfs as BsdfSet>::FLAGS & lobe_flags::TRANSMISSION != 0;
    let has_delta = <L::Bsdfs as BsdfSet>::FLAGS & lobe_flags::DELTA != 0;
    let hit = buf.hit.get_or_insert(SurfaceHit8::MISS);
    for b in 0..n_b {
        buf.rays.clear();
        buf.rows.clear();
        let index = U8::splat(s.wrapping_mul(n_b).wrapping_add(b));
        for (i, sh) in hits.iter().enumerate() {
            let shade = lanes.shade[i];
            if shade.none() {
                continue;
            }
            let pixel = pks[i].pixel;
            let u = smp.table_point(&d_dir, false, Phase::SamplerPath, pixel, index);
            let u_lobe = smp.table_point(&d_lobe, false, Phase::SamplerPath, pixel, index).0;
            let (frame, mat) = (shading_frame::<L>(scene, sh), &sh.mat);
            let at = Shading::new(sh, &frame, MIS_STRATEGY);
            let sampled = {
                let _p = leaf(Phase::BsdfSample);
                mat.sample_bsdf_k::<L>(MIS_STRATEGY, at.wo, [u.0, u.1], u_lobe, shade)
            };
            let (wi_l, pdf) = (sampled.wi, sampled.pdf);
            let wi = frame.to_world(wi_l);
            let cos = wi_l.z;
            // The course's lanes: f cos / pdf, reflection only.
            let above = shade & cos.simd_gt(F8::ZERO) & at.leaves(wi);
            let mut ok = above & pdf.simd_gt(F8::ZERO) & sampled.f.max_elem().simd_gt(F8::ZERO);
            let mut weight = sampled.f.scale(ok.select(cos / pdf, F8::ZERO));
            let mut delta = Mask8::default();
            let eps = lanes.eps[i];
            let mut o = sh.ng.mul_add(eps, sh.p);
            if <L::Bsdfs as BsdfSet>::BITS != 0 && sampled.general.any() {
                // Registry lanes: the interface's weight, either side of the surface.
                let (g, bs) = (sampled.general, &sampled.bsdf);
                let (a, c) = (sh.ng.dot(wi), sh.n.dot(wi));
                let both = (a.simd_gt(F8::ZERO) & c.simd_gt(F8::ZERO)) | (a.simd_lt(F8::ZERO) & c.simd_lt(F8::ZERO));
                let g_ok = g & bs.pdf.simd_gt(F8::ZERO) & bs.weight.max_elem().simd_gt(F8::ZERO) & (!sh.smooth | both);
                ok = (ok & !g) | g_ok;
                weight = Vec3x8::select(ok, Vec3x8::select(g, bs.weight, weight), Vec3x8::ZERO);
                if transmits {
                    o = Vec3x8::select(g & a.simd_lt(F8::ZERO), sh.ng.mul_add(-eps, sh.p), o);
                }
                if has_delta {
                    delta = g & bs.has(lobe_flags::DELTA);
                }
            }
            let ok = ok & weight.is_finite();
            if ok.none() {
                continue;
            }
            let mut rh = RayHit8::default();
            let traced = rh.ray.set(o, wi, F8::ZERO, F8::splat(f32::INFINITY), ok);
            buf.rays.push((rh, traced));
            let reach = above & !delta;
            buf.rows.push(Row { owner: i as u32, weight, pdf, reach, cos, p: sh.p, n: sh.n });
        }
        if buf.rays.is_empty() {
            continue;
        }
        tracer.intersect_all(&mut buf.rays, RayKind::Bounce);
        for ((rh, traced), row) in buf.rays.iter().zip(&buf.rows) {
            scene.gather_into(rh.ray.org(), rh.ray.dir(), &Hits8::from_rayhit(rh, *traced), hit);
            let le = emission(it, scene, hit, rh, *traced, row, &mis);
            out[row.owner as usize] += row.weight.mul_elem(le);
        }
    }
}

/// The MIS-weighted emission the BSDF packet `row` finds at its hits `sh` (of the rays `rh`,
/// `traced` lanes): area lights weighed against light sampling, emissive materials with
/// `1 / n_b`, the environment where the rays escaped.
#[inline]
fn emission(
    it: &Integrator,
    scene: &Scene,
    sh: &SurfaceHit8,
    rh: &RayHit8,
    traced: Mask8,
    row: &Row,
    mis: &Mis,
) -> Vec3x8 {
    let hit = traced & sh.valid;
    let mut le = crate::integrator::context::masked(sh.emitted, hit).scale(mis.bsdf(row.pdf, F8::ZERO, hit));
    let is_light = hit & F8::from_bits(!sh.light.simd_eq(U8::splat(u32::MAX)));
    if is_light.any() {
        let _p = leaf(Phase::Mis);
        let reach = is_light & row.reach;
        let p_e = if it.direct.emitter_sampling && reach.any() {
            let pmf = light_pmf(it, scene, sh, row, reach);
            light_pdf_at_hit_pmf(it, scene, sh, rh, reach, pmf)
        } else {
            F8::ZERO
        };
        le += crate::integrator::context::masked(sh.le, is_light).scale(mis.bsdf(row.pdf, p_e, is_light));
    }
    let missed = traced & !sh.valid;
    if missed.any() {
        let reach = missed & row.reach;
        let (l_env, p_env) = match (&scene.sky, &scene.envmap) {
            // `direct` samples the constant sky cosine-weighted about the shading normal.
            (Some(sky), _) => {
                (Vec3x8::splat(sky.radiance), reach.select(row.cos * F8::splat(std::f32::consts::FRAC_1_PI), F8::ZERO))
            }
            (None, Some(env)) => {
                let (l, p) = env.radiance_pdf_x8(rh.ray.dir(), missed);
                (l, reach.select(p, F8::ZERO))
            }
            (None, None) => return le,
        };
        let p_e = if it.direct.emitter_sampling { p_env } else { F8::ZERO };
        le += crate::integrator::context::masked(l_env, missed).scale(mis.bsdf(row.pdf, p_e, missed));
    }
    le
}

/// The probability that `direct`'s light sampling picks the light hit on lanes `reach` (its
/// emitter list index `sh.light`): the selection's pmf at the shading point under a one-light
/// selection; under `all` 1 for a quad (each its own group), the triangles' power choice for
/// an emissive triangle.
#[inline]
fn light_pmf(it: &Integrator, scene: &Scene, sh: &SurfaceHit8, row: &Row, reach: Mask8) -> F8 {
    if it.light_selection.picks_one() {
        return it.light_sampler.pmf_x8(row.p, row.n, sh.light, reach);
    }
    let n_quads = U8::splat(scene.emitters.n_quads as u32);
    // (Light ids are far below 2^31: the lanes' signed comparison is the unsigned one.)
    let quad: Mask8 = wide::bytemuck::cast(sh.light.simd_lt(n_quads));
    let quad = quad & reach;
    let tri = it.triangle_sampler.pmf_x8(row.p, row.n, sh.light - n_quads, reach & !quad);
    quad.select(F8::ONE, tri)
}

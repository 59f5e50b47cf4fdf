//! One bounce of the path wavefront: a vertex's emission (weighted by the next-event mode), its
//! next events (area lights, delta lights, the environment) pushed as shadow rays, and its
//! continuation (BSDF sampling, Russian roulette) pushed onto the next bounce's paths.

use super::columns::{PATH_COLS, PREV_P, SHADOW_COLS, SLOT, S_SLOT};
use super::wave::{bits, Columns, Pack};
use crate::accel::RayHit8;
use crate::bsdf::interface::flags as lobe_flags;
use crate::bsdf::{BsdfSet, LobeSet};
use crate::integrator::context::{masked, shading_frame};
use crate::integrator::light_term::{
    area_sample, env_sample, light_pdf_at_hit_pmf, point_shadow, towards, AreaChoice, EnvSample, PointTerm, Shading,
    SkySampling,
};
use crate::integrator::samples::Samples;
use crate::integrator::settings::Integrator;
use crate::light::emitters::LightSample8;
use crate::light::select::LightChoice;
use crate::light::sky::Sky;
use crate::profile::Phase;
use crate::sampler::PathDim;
use crate::sampling::power_heuristic_x8;
use crate::scene::build::Scene;
use crate::scene::desc::{BrdfKind, ImportanceSampling, Nee};
use crate::scene::gather::SurfaceHit8;
use crate::simd::{Mask8, Vec3x8, F8, U8};

/// Vertex of the path packet being shaded: where it is and what it carries.
pub(super) struct Vertex<'a> {
    pub(super) sh: &'a SurfaceHit8,
    pub(super) rh: &'a RayHit8,
    pub(super) slot: U8,
    pub(super) pixel: U8,
    pub(super) s: U8,
    pub(super) beta: Vec3x8,
}

/// Whether the course's BRDF mixture of some material can pick its specular lobe: under
/// `importancesampling brdf`, with a material whose specular probability (`Material8::
/// specular_probability`) is not exactly 0 (GGX, or a non-zero `specular`). Otherwise every lane's
/// pick `u_lobe < t` is false whatever `u_lobe`, and the dimension is not drawn (skipping it
/// changes no other, so no bit of the image).
pub(super) fn course_lobe_pick(it: &Integrator, scene: &Scene) -> bool {
    it.path.strategy == ImportanceSampling::Brdf
        && scene.materials.iter().any(|m| m.brdf == BrdfKind::Ggx || m.specular != glam::Vec3::ZERO)
}

/// +z in every lane.
pub(super) const Z: Vec3x8 = Vec3x8 { x: F8::ZERO, y: F8::ZERO, z: F8::ONE };

/// One bounce of the wavefront: what shading a packet reads and where it writes (the next
/// bounce's paths, this bounce's shadow rays).
pub(super) struct Bounce<'a> {
    pub(super) it: &'a Integrator,
    pub(super) smp: &'a Samples<'a>,
    pub(super) scene: &'a Scene,
    pub(super) v: u32,
    pub(super) max_v: u32,
    pub(super) dk: &'a [PathDim; 4],
    /// the sky's dimension of this vertex (with a sky)
    pub(super) dsky: Option<PathDim>,
    pub(super) keep_prev: bool,
    /// whether the course's BRDF mixture can pick its specular lobe ([`course_lobe_pick`])
    pub(super) course_lobe_pick: bool,
    pub(super) next: &'a mut Columns<PATH_COLS>,
    pub(super) next_prev: &'a mut Columns<6>,
    pub(super) shadow: &'a mut Columns<SHADOW_COLS>,
}

impl Bounce<'_> {
    /// Emission found at the vertex: materials always; area lights (quads, emissive triangles)
    /// by the NEE mode, weighted with MIS against the light-sampling pdf (`pdf` is the pdf the
    /// direction was sampled with, negative after a delta lobe: weight 1; `pp`, `pn` the previous
    /// vertex for a point-dependent choice).
    #[inline]
    pub(super) fn emission<L: LobeSet>(&self, vx: &Vertex, pdf: F8, pp: Vec3x8, pn: Vec3x8) -> Vec3x8 {
        let (it, sh, v) = (self.it, vx.sh, self.v);
        let hit = sh.valid;
        let mut le = masked(sh.emitted, hit);
        let is_light = hit & F8::from_bits(!sh.light.simd_eq(U8::splat(u32::MAX)));
        // No light hit: the area-light term is zero (sh.le and the weight are zero off lights).
        if is_light.none() {
            return le;
        }
        let light_w = match it.path.nee {
            Nee::Off => F8::ONE,
            Nee::On => F8::splat(if v == 1 { 1.0 } else { 0.0 }),
            Nee::Mis if v == 1 => F8::ONE,
            Nee::Mis => {
                let _p = crate::profile::leaf(crate::profile::Phase::Mis);
                let pmf = if it.light_selection.picks_one() {
                    it.light_sampler.pmf_x8(pp, pn, sh.light, is_light)
                } else {
                    // N points on every light: multi-sample MIS against N p_light.
                    F8::splat(it.light_set.n().max(1) as f32)
                };
                let p_light = light_pdf_at_hit_pmf(it, self.scene, sh, vx.rh, is_light, pmf);
                power_heuristic_x8(pdf, p_light, is_light)
            }
        };
        // A direction from a delta lobe: no light sample could have found the light.
        let light_w = if <L::Bsdfs as BsdfSet>::FLAGS & lobe_flags::DELTA != 0 {
            pdf.simd_lt(F8::ZERO).select(F8::ONE, light_w)
        } else {
            light_w
        };
        le += masked(sh.le, hit).scale(light_w);
        le
    }

    /// NEE and the continuation at the vertex's shaded lanes (hits off the lights): shadow rays
    /// into `shadow`, surviving paths into `next`.
    #[inline]
    pub(super) fn shade<L: LobeSet>(&mut self, vx: &Vertex) {
        let (it, scene, sh, v, max_v) = (self.it, self.scene, vx.sh, self.v, self.max_v);
        let (nee, n_lights) = (it.path.nee, scene.emitters.len() as u32);
        let is_light = F8::from_bits(!sh.light.simd_eq(U8::splat(u32::MAX)));
        // Shading frame: the normal faces wo, so wo.z > 0 in local coordinates.
        let shade = sh.valid & !is_light;
        let nee_here = nee != Nee::Off && scene.has_nee_lights() && v < max_v;
        // Delta lights are reached by next events only, whatever the NEE mode.
        let delta_here = !scene.delta.is_empty() && v < max_v;
        let bounce_here = match nee {
            Nee::On => v + 1 < max_v,
            _ => v < max_v,
        };
        if shade.none() || (!nee_here && !bounce_here && !delta_here) {
            return;
        }
        let (pixel, s, beta) = (vx.pixel, vx.s, vx.beta);
        let (frame, mat) = (shading_frame::<L>(scene, sh), &sh.mat);
        // Registry BSDFs that transmit: directions may cross the surface (compile-time).
        let transmits = <L::Bsdfs as BsdfSet>::FLAGS & lobe_flags::TRANSMISSION != 0;
        // The environment's and the delta lights' next events light transmitting lanes from
        // below too (the area lights' below; see `push`).
        let below = if transmits { transmitting_lanes::<L>(mat, shade) } else { F8::ZERO };
        let at = Shading::new(sh, &frame, it.path.strategy).with_below(below);
        let (frame, wo) = (at.frame, at.wo);
        let eps = scene.offset_eps(sh.p);
        // Offsets along the geometric normal (the shading one may point into the surface).
        let o = sh.ng.mul_add(eps, sh.p);
        // Smooth-shaded lanes: directions must also leave the geometric surface (on the side of
        // the shading normal they leave: transmitted ones below both).
        let leaves = |wi: Vec3x8| at.leaves(wi);
        let leaves_either = |wi: Vec3x8| {
            let (a, b) = (sh.ng.dot(wi), sh.n.dot(wi));
            !sh.smooth | (a.simd_gt(F8::ZERO) & b.simd_gt(F8::ZERO)) | (a.simd_lt(F8::ZERO) & b.simd_lt(F8::ZERO))
        };
        // The origin below the surface, for directions that cross it.
        let o_below = sh.ng.mul_add(-eps, sh.p);
        let general = if <L::Bsdfs as BsdfSet>::BITS != 0 { mat.general(shade) } else { F8::ZERO };
        // A light choice of its own: drawn only under `--light-choice dimension` with several
        // lights to pick from (skipping a dimension changes no other).
        let picks = it.light_selection.picks_one() && n_lights > 1;
        let own_choice = picks && it.light_choice == LightChoice::Dimension;

        // Shadow rays of directions below the geometric surface start below it.
        let from = (o, if transmits && below.any() { Some(o_below) } else { None });
        if nee_here {
            self.env_next_event::<L>(vx, &at, from, shade);
        }
        if delta_here {
            self.delta_next_events::<L>(vx, &at, from, shade);
        }
        let nee_lights = nee_here && n_lights > 0;
        // The light point and the bounce's direction, drawn by one call where both are used (the
        // layout may run the two points' chains side by side; the same bits either way).
        let (light_uw, bounce_u2) = if nee_lights && bounce_here {
            let [a, b] =
                self.smp.table_point_pair((&self.dk[0], true), (&self.dk[2], false), Phase::SamplerPath, pixel, s);
            (Some(a), Some(b))
        } else {
            (None, None)
        };
        if nee_lights {
            let u_choice = if own_choice {
                self.smp.table_point(&self.dk[1], true, Phase::SamplerPath, pixel, s).0
            } else {
                F8::ZERO
            };
            let (u, w) =
                light_uw.unwrap_or_else(|| self.smp.table_point(&self.dk[0], true, Phase::SamplerPath, pixel, s));
            let shadow = &mut *self.shadow;
            let mut push = |ls: &LightSample8, scale: Option<F8>, mis_n: Option<F8>, ok: Mask8| {
                let (y, l_rad, area, inv_pmf) = (ls.y, ls.radiance, ls.area, ls.inv_pmf);
                let PointTerm { wi, d2, inv_d, mut cos_i, cos_l, mut lit } = towards(sh, ls, ok);
                // Transmitting lanes: lights below the surface too.
                let below = if transmits && general.any() {
                    let below = ok & general & cos_i.simd_lt(F8::ZERO) & cos_l.simd_gt(F8::ZERO) & d2.simd_gt(F8::ZERO);
                    let below = below & leaves_either(wi);
                    lit |= below;
                    cos_i = cos_i.abs();
                    below
                } else {
                    F8::ZERO
                };
                if lit.none() {
                    return;
                }
                let (f, pdf_b) = at.eval::<L>(frame.to_local(wi), lit);
                // No shadow ray where a registry BSDF has no value (delta lobes only).
                let lit = if <L::Bsdfs as BsdfSet>::BITS != 0 {
                    lit & !(general & f.max_elem().simd_le(F8::ZERO))
                } else {
                    lit
                };
                if lit.none() {
                    return;
                }
                // L f cos_i / p_light with p_light = pmf d^2 / (A cos_l) (solid angle).
                let mut g = cos_i * cos_l * area * inv_pmf * inv_d * inv_d;
                if let Some(k) = scale {
                    g *= k;
                }
                // (The NEE side's weight is a few flops per lane: cheaper than a scope, so it
                // stays in `other`; the light-hit side is timed as `mis weights`.)
                let w_light = if nee == Nee::Mis {
                    let p_light = d2 / (area * cos_l * inv_pmf);
                    let p_light = if let Some(k) = mis_n { p_light * k } else { p_light };
                    power_heuristic_x8(p_light, pdf_b, lit)
                } else {
                    F8::ONE
                };
                let c = beta.mul_elem(f).mul_elem(l_rad).scale(g * w_light);
                let o = if transmits { Vec3x8::select(below, o_below, o) } else { o };
                let (d, tfar) = point_shadow(scene, o, y, inv_d);
                // The lit lanes, left-packed onto the bounce's shadow rays.
                let pack = Pack::of(lit);
                shadow.write(S_SLOT, &pack, &[bits(vx.slot), o.x, o.y, o.z, d.x, d.y, d.z, tfar, c.x, c.y, c.z]);
                shadow.advance(&pack);
            };
            if it.light_sampler.certain() {
                // The one light (pmf 1), a point on it uniform in area.
                let mut ls = LightSample8::ZERO;
                let ok = area_sample(it, scene, sh, shade, AreaChoice::Certain, (u, w), &mut ls);
                push(&ls, None, None, ok)
            } else if !it.light_selection.picks_one() {
                // Every light, N points each (a lattice rotated by (u, w)), each weighted 1/N
                // and, with MIS, against N p_light.
                {
                    let n_all = it.light_set.n().max(1);
                    let (scale, mis_n) = if n_all > 1 {
                        (Some(F8::splat(1.0 / n_all as f32)), Some(F8::splat(n_all as f32)))
                    } else {
                        (None, None)
                    };
                    for (e, row) in scene.emitters.list.iter().zip(&scene.emitters.warp_rows) {
                        for j in 0..n_all {
                            let (uj, wj) = lattice_point(u, w, j, n_all);
                            // (The sample stays where it is made: a block returning it copied its
                            // 448 bytes out.) The warp reads the light's row from the table.
                            let p = crate::profile::leaf(crate::profile::Phase::Emitter);
                            let mut ls = e.sample_x8(uj, wj);
                            row.warp_x8(it.light_warp, &mut ls, sh.p, shade);
                            drop(p);
                            push(&ls, scale, mis_n, shade);
                        }
                    }
                }
            } else {
                // One light from the light sampler (uniform 1/N over quads and triangles alike,
                // power or spatial), the choice reused from u or drawn on its own.
                let choice = if own_choice { AreaChoice::Drawn(u_choice) } else { AreaChoice::Reuse };
                let mut ls = LightSample8::ZERO;
                let ok = area_sample(it, scene, sh, shade, choice, (u, w), &mut ls);
                push(&ls, None, None, ok);
            }
        }

        // Continue the path: sample the BSDF, then Russian roulette.
        if bounce_here {
            // (Russian roulette, lobe choice): drawn only where one of them is used.
            // Registry BSDFs pick their lobe whatever the strategy.
            let lobe_pick = self.course_lobe_pick || <L::Bsdfs as BsdfSet>::BITS != 0;
            let (u_rr, u_lobe) = if it.path.russian_roulette || lobe_pick {
                self.smp.table_point(&self.dk[3], false, Phase::SamplerPath, pixel, s)
            } else {
                (F8::ZERO, F8::ZERO)
            };
            let u2 =
                bounce_u2.unwrap_or_else(|| self.smp.table_point(&self.dk[2], false, Phase::SamplerPath, pixel, s));
            let sampled = {
                let _p = crate::profile::leaf(crate::profile::Phase::BsdfSample);
                mat.sample_bsdf_k::<L>(it.path.strategy, wo, [u2.0, u2.1], u_lobe, shade)
            };
            let (wi_l, mut pdf, f) = (sampled.wi, sampled.pdf, sampled.f);
            let cos = wi_l.z;
            let wi = frame.to_world(wi_l);
            let mut ok =
                shade & pdf.simd_gt(F8::ZERO) & cos.simd_gt(F8::ZERO) & f.max_elem().simd_gt(F8::ZERO) & leaves(wi);
            let mut nb = beta.mul_elem(f).scale(ok.select(cos / pdf, F8::ZERO));
            let mut o = o;
            if <L::Bsdfs as BsdfSet>::BITS != 0 && sampled.general.any() {
                // Registry BSDF lanes: their weight f |cos| / pdf, either side of the surface.
                let (g, b) = (sampled.general, &sampled.bsdf);
                let g_ok = g & b.pdf.simd_gt(F8::ZERO) & b.weight.max_elem().simd_gt(F8::ZERO) & leaves_either(wi);
                ok = (ok & !g) | g_ok;
                nb = Vec3x8::select(g, beta.mul_elem(b.weight), nb);
                nb = Vec3x8::select(ok, nb, Vec3x8::ZERO);
                if transmits {
                    o = Vec3x8::select(g & sh.ng.dot(wi).simd_lt(F8::ZERO), o_below, o);
                }
                // A delta lobe's direction: the next hit's emission gets weight 1 (pdf < 0).
                pdf = (g & b.has(lobe_flags::DELTA)).select(F8::splat(-1.0), pdf);
            }
            let mut alive = ok & nb.max_elem().simd_gt(F8::ZERO) & nb.is_finite();
            if it.path.russian_roulette && v >= it.path.rr_depth {
                let q = nb.max_elem().min(F8::ONE);
                alive &= u_rr.simd_lt(q);
                nb = nb.scale(alive.select(F8::ONE / q, F8::ZERO));
            }
            if alive.any() {
                // The surviving lanes, left-packed onto the next bounce's paths.
                let pack = Pack::of(alive);
                let row = [bits(vx.slot), bits(pixel), bits(s), o.x, o.y, o.z, wi.x, wi.y, wi.z, nb.x, nb.y, nb.z, pdf];
                self.next.write(SLOT, &pack, &row);
                self.next.advance(&pack);
                if self.keep_prev {
                    let (p, n) = (sh.p, sh.n);
                    self.next_prev.write(PREV_P, &pack, &[p.x, p.y, p.z, n.x, n.y, n.z]);
                    self.next_prev.advance(&pack);
                }
            }
        }
    }
}

impl Bounce<'_> {
    /// The delta lights' next events at the shaded lanes `shade` of `vx`
    /// ([`Shading::delta_events`], from below too on `at.below` lanes), pushed as shadow rays
    /// from `from` (kept out of line: scenes without delta lights never run it).
    #[inline(never)]
    fn delta_next_events<L: LobeSet>(&mut self, vx: &Vertex, at: &Shading, from: From, shade: Mask8) {
        let shadow = &mut *self.shadow;
        at.delta_events::<L>(self.scene, vx.beta, shade, |lit, wi, tfar, c| {
            push_shadow(shadow, vx, origin(vx.sh, from, wi), wi, tfar, c, lit)
        });
    }

    /// The environment's next event at the shaded lanes `shade` of `vx` (the sky's own
    /// distribution or the envmap's, [`Shading::env_event`]), MIS-weighted against the BSDF and
    /// pushed as a shadow ray to infinity from `from`. The sky's samples cover the hemisphere
    /// above the shading normal; on `at.below` lanes (a transmitting BSDF) the same sample
    /// mirrored below is a second next event, of the same pdf `1 / (2 pi)` in its hemisphere, so
    /// an escaped ray's weight against `Sky::PDF` holds on either side. The envmap's cover the
    /// sphere.
    #[inline]
    fn env_next_event<L: LobeSet>(&mut self, vx: &Vertex, at: &Shading, from: From, shade: Mask8) {
        let Some(dim) = self.dsky.as_ref() else { return };
        let uw = self.smp.table_point(dim, true, Phase::SamplerPath, vx.pixel, vx.s);
        let Some(e) = env_sample(self.scene, SkySampling::Sky, at.frame, uw, shade) else { return };
        let mis = self.it.path.nee == Nee::Mis;
        let weight = |pdf_b: F8, lit: Mask8| match self.scene.sky {
            Some(_) => Sky::nee_weight_x8(mis, pdf_b, lit),
            None if mis => power_heuristic_x8(e.pdf, pdf_b, lit),
            None => F8::ONE,
        };
        if let Some((lit, wi, c)) = at.env_event::<L>(&e, vx.beta, shade, weight) {
            push_shadow(self.shadow, vx, origin(vx.sh, from, wi), wi, F8::splat(f32::INFINITY), c, lit);
        }
        let below = shade & at.below;
        if self.scene.sky.is_some() && below.any() {
            let wi_l = Vec3x8::new(e.wi_l.x, e.wi_l.y, -e.wi_l.z);
            let m = EnvSample { wi: at.frame.to_world(wi_l), wi_l, pdf: e.pdf, le: e.le };
            if let Some((lit, wi, c)) = at.env_event::<L>(&m, vx.beta, below, weight) {
                push_shadow(self.shadow, vx, origin(vx.sh, from, wi), wi, F8::splat(f32::INFINITY), c, lit);
            }
        }
    }
}

/// Where a next event's shadow rays start: above the surface, and (on kernels with transmitting
/// lanes) below it.
type From = (Vec3x8, Option<Vec3x8>);

/// The shadow-ray origins of the hits `sh` for directions `wi`: below the surface where `wi` goes
/// below the geometric normal and `from` has a point there, else above.
#[inline]
fn origin(sh: &SurfaceHit8, from: From, wi: Vec3x8) -> Vec3x8 {
    match from {
        (o, Some(o_below)) => Vec3x8::select(sh.ng.dot(wi).simd_lt(F8::ZERO), o_below, o),
        (o, None) => o,
    }
}

/// The `shade` lanes whose registry BSDF transmits and has a lobe a next event can find (diffuse
/// or glossy; per-lane kinds of the kernel's set `L::Bsdfs`): the smooth dielectrics' and the
/// null lobe's lanes would only trace shadow rays of value 0.
#[inline]
fn transmitting_lanes<L: LobeSet>(mat: &crate::bsdf::Material8, shade: Mask8) -> Mask8 {
    use lobe_flags::{DIFFUSE, GLOSSY, TRANSMISSION};
    let kinds = mat.bsdf.kind.to_array();
    let t = kinds.map(|k| {
        let f = <L::Bsdfs as BsdfSet>::flags_of(k);
        f & TRANSMISSION != 0 && f & (DIFFUSE | GLOSSY) != 0
    });
    shade & crate::simd::mask_from_bools(t)
}

/// A next event's shadow rays from `o` along `wi` up to `tfar`, adding `c` to the pixel samples
/// of `vx` if clear: the lit lanes, left-packed onto the bounce's shadow rays.
#[inline]
fn push_shadow(shadow: &mut Columns<SHADOW_COLS>, vx: &Vertex, o: Vec3x8, wi: Vec3x8, tfar: F8, c: Vec3x8, lit: Mask8) {
    let pack = Pack::of(lit);
    let row = [bits(vx.slot), o.x, o.y, o.z, wi.x, wi.y, wi.z, tfar, c.x, c.y, c.z];
    shadow.write(S_SLOT, &pack, &row);
    shadow.advance(&pack);
}

/// Point `j` of `n` on one light for `all`: a Fibonacci-like rank-1 lattice rotated by `(u, w)`
/// (every point uniform on the unit square; point 0 is `(u, w)` itself).
#[inline]
fn lattice_point(u: F8, w: F8, j: u32, n: u32) -> (F8, F8) {
    if j == 0 {
        return (u, w);
    }
    let fr = |x: F8| x - x.floor();
    let a = F8::splat(j as f32 / n as f32);
    let b = F8::splat((j as f32 * 0.618_034).fract());
    (fr(u + a).min(F8::splat(ONE_MINUS)), fr(w + b).min(F8::splat(ONE_MINUS)))
}

/// Largest f32 below 1.
const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

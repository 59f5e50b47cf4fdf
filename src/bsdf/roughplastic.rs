//! `roughplastic`: a rough dielectric coating over a Lambertian base (Mitsuba's `roughplastic`):
//! f = F(wi.h) D G / (4 wo.z wi.z) `specular_reflectance` + diff t(wo) t(wi) / (pi eta^2), where
//! t(mu) is the rough coating's transmittance at the cosine mu (the light refracted into the base
//! and not shadowed on the way, as Mitsuba's `eval_transmittance`: not 1 minus the reflectance,
//! since the shadowed light is in neither; tabulated at load at 64 cosines in [0, 1] and
//! interpolated linearly, as Mitsuba does) and the
//! base reflectance d is renormalized for the light the coating's inside reflects back:
//! diff = d / (1 - R_int) (linear) or d / (1 - d R_int) (`nonlinear`), R_int the coating's
//! internal diffuse reflectance (2 mean(reflectance_inside(mu) mu) over the same cosines). The
//! specular lobe is sampled (visible normals, reflected) with probability proportional to
//! (1 - t(wo)) w, the cosine lobe to t(wo) (1 - w), w = mean(specular) / (mean(diffuse) +
//! mean(specular)). Isotropic, one-sided.
//!
//! Slots: `color[0]` the diffuse reflectance d, `color[1]` the specular reflectance (both may
//! come from textures per hit: the renormalization of d is done at shading, as Mitsuba's),
//! `color[2].x` the id of the transmittance table (a process-wide list, one per distinct
//! (distribution, alpha, eta)), `color[2].y` 1 for `nonlinear` (0 otherwise), `scalar[0]` eta =
//! int_ior / ext_ior, `scalar[1]` alpha, `scalar[2]` the distribution's [`Distribution::code`],
//! `scalar[3]` w (from the reflectances' means, as Mitsuba's from the textures' means).

use super::fresnel::dielectric_x8;
use super::interface::{flags, flags_where, Bsdf, BsdfParams, Params8, Sample8};
use super::microfacet::{per_variant, Distribution, Microfacet, V3};
use super::roughconductor::reflection;
use crate::sampling::{cosine_hemisphere_pdf_x8, sample_cosine_hemisphere_x8};
use crate::simd::{Mask8, Vec3x8, F8};
use glam::Vec3;
use std::sync::RwLock;

/// Cosines of the transmittance table (Mitsuba's resolution).
const RES: usize = 64;
/// Quadrature points per axis of the coating's reflectance and transmittance.
const QUAD: usize = 64;

/// One transmittance table and what it was computed for.
struct Table {
    key: (u32, u32, u32),
    t: [f32; RES],
    internal: f32,
}

/// The process-wide list of transmittance tables ([`params`] adds, shading reads).
static TABLES: RwLock<Vec<Table>> = RwLock::new(Vec::new());

/// The rough plastic (see the module docs).
pub struct RoughPlastic;

/// The coating's directional reflectance (`transmit` false) or transmittance (`transmit` true)
/// at the cosines `mu` (eight lanes): E[F(wo.m) G1(wr)] or E[(1 - F(wo.m)) G1(wt)] over the
/// normals m visible from wo (a QUAD x QUAD midpoint grid of the sampler's square), wr = wo
/// reflected about m, wt = wo refracted through m (Mitsuba's `eval_reflectance` /
/// `eval_transmittance`). The transmittance counts only light that leaves the microsurface
/// unshadowed, so it is not 1 minus the reflectance: the energy lost to shadowing is in neither.
fn coating(mf: &Microfacet<F8>, eta: f32, mu: F8, transmit: bool) -> F8 {
    let wo = Vec3x8::new((F8::ONE - mu * mu).max(F8::ZERO).sqrt(), F8::ZERO, mu);
    let mut sum = F8::ZERO;
    for a in 0..QUAD {
        for b in 0..QUAD {
            let u = [F8::splat((a as f32 + 0.5) / QUAD as f32), F8::splat((b as f32 + 0.5) / QUAD as f32)];
            let m = Vec3x8::from(mf.sample(wo.into(), u).0);
            let wo_m = wo.dot(m);
            let (r, cos_t, _, eta_ti) = dielectric_x8(wo_m, F8::splat(eta));
            let (w, energy, below) = if transmit {
                let wt = m.scale(wo_m * eta_ti + cos_t) - wo.scale(eta_ti);
                (wt, F8::ONE - r, F8::ONE.simd_gt(F8::ZERO))
            } else {
                (m.scale(F8::splat(2.0) * wo_m) - wo, r, F8::ONE.simd_lt(F8::ZERO))
            };
            let area = mf.projected_area(V3::from(w));
            let side = below.select(-w.z, w.z);
            let ok = side.simd_gt(F8::ZERO) & wo_m.simd_gt(F8::ZERO) & area.simd_gt(F8::ZERO);
            sum += ok.select(energy * side / ok.select(area, F8::ONE), F8::ZERO);
        }
    }
    sum / F8::splat((QUAD * QUAD) as f32)
}

/// (transmittance table from outside, internal diffuse reflectance) of a coating.
fn tables(kind: Distribution, alpha: f32, eta: f32) -> ([f32; RES], f32) {
    let mf = Microfacet::new(kind, F8::splat(alpha), F8::splat(alpha), true);
    let (mut t, mut internal) = ([0.0f32; RES], 0.0f64);
    for c in 0..RES / 8 {
        let mu = F8::new(std::array::from_fn(|i| ((c * 8 + i) as f32 / (RES - 1) as f32).max(1e-6)));
        let outside = coating(&mf, eta, mu, true);
        let inside = coating(&mf, 1.0 / eta, mu, false);
        for i in 0..8 {
            t[c * 8 + i] = outside.to_array()[i];
            internal += (inside.to_array()[i] * mu.to_array()[i]) as f64;
        }
    }
    (t, (2.0 * internal / RES as f64) as f32)
}

/// The transmittance t(mu) of each lane's table, linearly interpolated.
#[inline]
fn transmittance(id: F8, mu: F8) -> F8 {
    let tables = TABLES.read().unwrap_or_else(|e| e.into_inner());
    let (ids, mus) = (id.to_array(), mu.to_array());
    F8::new(std::array::from_fn(|i| {
        let Some(t) = tables.get(ids[i] as usize) else { return 0.0 };
        let x = mus[i].clamp(0.0, 1.0) * (RES - 1) as f32;
        let k = (x as usize).min(RES - 2);
        let f = x - k as f32;
        t.t[k].mul_add(1.0 - f, t.t[k + 1] * f)
    }))
}

/// The diffuse term diff / (pi eta^2) per lane: the base reflectance `color[0]` renormalized for
/// the light the coating's inside reflects back (module docs).
#[inline]
fn diffuse_term(p: &Params8) -> Vec3x8 {
    let internal = {
        let tables = TABLES.read().unwrap_or_else(|e| e.into_inner());
        let ids = p.color[2].x.to_array();
        F8::new(std::array::from_fn(|i| tables.get(ids[i] as usize).map_or(0.0, |t| t.internal)))
    };
    let nonlinear = p.color[2].y.simd_gt(F8::ZERO);
    let scale = F8::splat(std::f32::consts::FRAC_1_PI) / (p.scalar[0] * p.scalar[0]);
    let renorm = |c: F8| c / (F8::ONE - nonlinear.select(c, F8::ONE) * internal) * scale;
    let d = p.color[0];
    Vec3x8::new(renorm(d.x), renorm(d.y), renorm(d.z))
}

/// (specular probability, transmittance at wo) per lane.
#[inline]
fn lobe_choice(p: &Params8, wo: Vec3x8) -> (F8, F8) {
    let t_o = transmittance(p.color[2].x, wo.z);
    let w = p.scalar[3];
    let ps = (F8::ONE - t_o) * w;
    let pd = t_o * (F8::ONE - w);
    let sum = ps + pd;
    (sum.simd_gt(F8::ZERO).select(ps / sum, F8::ZERO), t_o)
}

impl Bsdf for RoughPlastic {
    const ID: u32 = 12;
    const NAME: &'static str = "roughplastic";
    const FLAGS: u32 = flags::GLOSSY_REFLECTION | flags::DIFFUSE_REFLECTION;

    #[inline]
    fn eval_pdf(p: &Params8, wo: Vec3x8, wi: Vec3x8, active: Mask8) -> (Vec3x8, F8) {
        let up = active & wo.z.simd_gt(F8::ZERO) & wi.z.simd_gt(F8::ZERO);
        let (fs, ps_dir, cos_h) = per_variant(
            p.scalar[2],
            p.scalar[1],
            p.scalar[1],
            up,
            (F8::ZERO, F8::ZERO, F8::ZERO),
            |mf, lanes| reflection(mf, wo, wi, lanes),
            |m, a, b| (m.select(a.0, b.0), m.select(a.1, b.1), m.select(a.2, b.2)),
        );
        let fres = dielectric_x8(cos_h, p.scalar[0]).0;
        let (prob_s, t_o) = lobe_choice(p, wo);
        let t_i = transmittance(p.color[2].x, wi.z);
        let spec = p.color[1].scale(fres * fs);
        let diff = diffuse_term(p).scale(t_o * t_i);
        let f = Vec3x8::select(up, spec + diff, Vec3x8::ZERO);
        let pdf = prob_s * ps_dir + (F8::ONE - prob_s) * cosine_hemisphere_pdf_x8(wi, up);
        (f, up.select(pdf, F8::ZERO))
    }

    #[inline]
    fn sample(p: &Params8, wo: Vec3x8, u_lobe: F8, u: [F8; 2], active: Mask8) -> Sample8 {
        let active = active & wo.z.simd_gt(F8::ZERO);
        let (prob_s, _) = lobe_choice(p, wo);
        let spec = u_lobe.simd_lt(prob_s);
        let wr = per_variant(
            p.scalar[2],
            p.scalar[1],
            p.scalar[1],
            active & spec,
            Vec3x8::ZERO,
            |mf, _| {
                let m = Vec3x8::from(mf.sample(wo.into(), u).0);
                m.scale(F8::splat(2.0) * wo.dot(m)) - wo
            },
            Vec3x8::select,
        );
        let wd = sample_cosine_hemisphere_x8(u, active & !spec).0;
        let wi = Vec3x8::select(spec, wr, wd);
        let (f, pdf) = Self::eval_pdf(p, wo, wi, active);
        let ok = active & pdf.simd_gt(F8::ZERO) & wi.z.simd_gt(F8::ZERO);
        let weight = f.scale(ok.select(wi.z / ok.select(pdf, F8::ONE), F8::ZERO));
        Sample8 {
            wi: Vec3x8::select(ok, wi, Vec3x8::ZERO),
            weight: Vec3x8::select(ok, weight, Vec3x8::ZERO),
            pdf: ok.select(pdf, F8::ZERO),
            flags: flags_where(ok & spec, flags::GLOSSY_REFLECTION) | flags_where(ok & !spec, flags::DIFFUSE_REFLECTION),
            eta: F8::ONE,
        }
    }

    fn test_params() -> Vec<BsdfParams> {
        let d = Vec3::new(0.02, 0.2, 0.1);
        vec![
            params(Distribution::Ggx, 0.1, true, 1.5168, d, Vec3::ONE, false),
            params(Distribution::Ggx, 1.0, true, 1.5168, d, Vec3::ONE, true),
            params(Distribution::Beckmann, 0.3, true, 1.49, Vec3::ONE, Vec3::ONE, true),
            params(Distribution::Beckmann, 0.5, false, 1.9, Vec3::splat(0.5), Vec3::ONE, false),
            params(Distribution::Ggx, 0.2, true, 4.0, Vec3::ZERO, Vec3::ONE, false),
        ]
    }
}

/// A rough plastic row: distribution, alpha, visible-normal sampling, relative index, diffuse and
/// specular reflectance, `nonlinear`. Computes (once per distinct coating) the coating's
/// transmittance table and internal reflectance.
pub fn params(
    kind: Distribution,
    alpha: f32,
    sample_visible: bool,
    eta: f32,
    diffuse: Vec3,
    specular: Vec3,
    nonlinear: bool,
) -> BsdfParams {
    let alpha = alpha.max(super::microfacet::ALPHA_MIN);
    let key = (kind.code(false).to_bits(), alpha.to_bits(), eta.to_bits());
    let found = TABLES.read().unwrap_or_else(|e| e.into_inner()).iter().position(|t| t.key == key);
    let id = found.unwrap_or_else(|| {
        let (t, internal) = tables(kind, alpha, eta);
        let mut list = TABLES.write().unwrap_or_else(|e| e.into_inner());
        list.iter().position(|t| t.key == key).unwrap_or_else(|| {
            list.push(Table { key, t, internal });
            list.len() - 1
        })
    });
    let (dm, sm) = (diffuse.element_sum() / 3.0, specular.element_sum() / 3.0);
    let w = if dm + sm > 0.0 { sm / (dm + sm) } else { 0.0 };
    BsdfParams {
        kind: RoughPlastic::ID,
        twosided: false,
        color: [diffuse, specular, Vec3::new(id as f32, if nonlinear { 1.0 } else { 0.0 }, 0.0)],
        scalar: [eta, alpha, kind.code(sample_visible), w],
        opacity: 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::interface::Params8;
    use crate::simd::mask_all;

    /// Mitsuba 3's `roughplastic` (the peer at /work/shared/peers/mitsuba, variant scalar_rgb),
    /// loaded as in bsdf_spheres/test_roughplastic_*_path.xml: ggx, int_ior bk7, ext_ior air,
    /// diffuse_reflectance (0.02, 0.2, 0.1), specular 1. Rows: (alpha, nonlinear, [theta_o, phi_o,
    /// theta_i, phi_i] radians, f = eval / cos(theta_i), pdf), from `b.eval(ctx, si, wo) / wo.z`
    /// and `b.pdf(ctx, si, wo)` with Mitsuba's si.wi = strata's wo.
    type Row = (f32, bool, [f32; 4], [f32; 3], f32);

    #[rustfmt::skip]
    const MITSUBA: [Row; 24] = [
        (0.1, false, [0.3, 0.0, 0.5, 3.0], [9.66670e-02, 1.48779e-01, 1.19828e-01], 7.60546e-01),
        (0.1, false, [1.0, 0.0, 1.2, 1.0], [5.19097e-03, 4.92872e-02, 2.47893e-02], 6.36703e-02),
        (0.1, false, [0.1, 0.0, 0.2, 3.1], [2.18154e-01, 2.70411e-01, 2.41380e-01], 1.69213e+00),
        (0.1, false, [1.3, 0.5, 0.4, 2.0], [5.39496e-03, 4.77692e-02, 2.42279e-02], 9.02428e-02),
        (0.1, true, [0.3, 0.0, 0.5, 3.0], [9.34857e-02, 1.19895e-01, 1.04534e-01], 7.60546e-01),
        (0.1, true, [1.0, 0.0, 1.2, 1.0], [2.49906e-03, 2.48459e-02, 1.18480e-02], 6.36703e-02),
        (0.1, true, [0.1, 0.0, 0.2, 3.1], [2.14964e-01, 2.41447e-01, 2.26043e-01], 1.69213e+00),
        (0.1, true, [1.3, 0.5, 0.4, 2.0], [2.80816e-03, 2.42823e-02, 1.17920e-02], 9.02428e-02),
        (0.4, false, [0.3, 0.0, 0.5, 3.0], [2.52832e-02, 5.97648e-02, 4.06084e-02], 3.45473e-01),
        (0.4, false, [1.0, 0.0, 1.2, 1.0], [6.37689e-03, 3.44336e-02, 1.88465e-02], 6.96601e-02),
        (0.4, false, [0.1, 0.0, 0.2, 3.1], [2.39825e-02, 5.88894e-02, 3.94967e-02], 3.72400e-01),
        (0.4, false, [1.3, 0.5, 0.4, 2.0], [9.00109e-03, 3.75808e-02, 2.17032e-02], 1.68224e-01),
        (0.4, true, [0.3, 0.0, 0.5, 3.0], [2.39580e-02, 4.82128e-02, 3.43464e-02], 3.45473e-01),
        (0.4, true, [1.0, 0.0, 1.2, 1.0], [5.29860e-03, 2.50340e-02, 1.37513e-02], 6.96601e-02),
        (0.4, true, [0.1, 0.0, 0.2, 3.1], [2.26410e-02, 4.71949e-02, 3.31575e-02], 3.72400e-01),
        (0.4, true, [1.3, 0.5, 0.4, 2.0], [7.90270e-03, 2.80061e-02, 1.65130e-02], 1.68224e-01),
        (1.0, false, [0.3, 0.0, 0.5, 3.0], [5.87834e-03, 2.67846e-02, 1.51700e-02], 1.62913e-01),
        (1.0, false, [1.0, 0.0, 1.2, 1.0], [7.48516e-03, 1.84208e-02, 1.23455e-02], 1.05501e-01),
        (1.0, false, [0.1, 0.0, 0.2, 3.1], [5.72318e-03, 2.78280e-02, 1.55475e-02], 1.81100e-01),
        (1.0, false, [1.3, 0.5, 0.4, 2.0], [7.18354e-03, 1.94114e-02, 1.26182e-02], 1.41575e-01),
        (1.0, true, [0.3, 0.0, 0.5, 3.0], [5.60789e-03, 2.45286e-02, 1.39162e-02], 1.62913e-01),
        (1.0, true, [1.0, 0.0, 1.2, 1.0], [7.34369e-03, 1.72408e-02, 1.16896e-02], 1.05501e-01),
        (1.0, true, [0.1, 0.0, 0.2, 3.1], [5.43723e-03, 2.54426e-02, 1.42219e-02], 1.81100e-01),
        (1.0, true, [1.3, 0.5, 0.4, 2.0], [7.02536e-03, 1.80919e-02, 1.18848e-02], 1.41575e-01),
    ];

    fn dir(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    /// f and pdf match Mitsuba's to 1 % (the coating tables are quadratures on different grids).
    /// With the transmittance taken as 1 minus the reflectance (the first version) alpha = 1 was
    /// 30 % too bright.
    #[test]
    fn matches_mitsuba_peer() {
        // Mitsuba's ior table: bk7 1.5046, air 1.000277.
        let eta = 1.5046f32 / 1.000277;
        for (alpha, nonlinear, [to, po, ti, pi], want, want_pdf) in MITSUBA {
            let row = params(Distribution::Ggx, alpha, true, eta, Vec3::new(0.02, 0.2, 0.1), Vec3::ONE, nonlinear);
            let (wo, wi) = (Vec3x8::splat(dir(to, po)), Vec3x8::splat(dir(ti, pi)));
            let (f, pdf) = RoughPlastic::eval_pdf(&Params8::splat(&row), wo, wi, mask_all());
            let (f, pdf) = (f.lane(0).to_array(), pdf.to_array()[0]);
            for c in 0..3 {
                let rel = (f[c] - want[c]).abs() / want[c];
                assert!(rel < 1e-2, "alpha {alpha} nonlinear {nonlinear} ({to},{po})->({ti},{pi}) channel {c}: {} vs Mitsuba {}", f[c], want[c]);
            }
            let rel = (pdf - want_pdf).abs() / want_pdf;
            assert!(rel < 1e-2, "alpha {alpha} nonlinear {nonlinear} ({to},{po})->({ti},{pi}) pdf {pdf} vs Mitsuba {want_pdf}");
        }
    }
}

//! The ellipsoid (the unit sphere under an affine map: [`Ellipsoid`], with its scalar f64 hit) and
//! its packet intersection with up to 8 rays at once, in f32 SIMD, with a per-lane running error
//! bound: a lane whose f32 answer could differ from the exact one (hit vs miss, which root, or a
//! hit distance off by more than [`TAU`] relative) is recomputed by the scalar f64
//! [`Ellipsoid::hit`], which stays the reference.
//! Safe code only: the Embree callbacks in `accel/user_geometry.rs` load the SoA lanes and call
//! [`hits8`] (packets of 8, Embree's case for `rtcIntersect8`/`rtcOccluded8`) or [`packet_hits`]
//! (any other width, 8 lanes at a time).
//!
//! # Formulation
//! Object space with the ellipsoid's centre `C` (world) taken out first: `D = (o - C_hi) - C_lo`
//! (`C` as an f32 pair, so rays near an ellipsoid far from the world origin lose nothing). For a
//! sphere (A a similarity to 1e-6), `o' = D / r`, `d' = d / r`. Otherwise `o' = B D`, `d' = B d`
//! with `B = S V^T` from the SVD `A = U S V^T` of the world-to-object linear part (f64 Jacobi at
//! build): `|B x| = |A x|` for all x, so B describes the same unit sphere up to the rotation U,
//! which no distance sees, and B's rows do not mix the axes (rounding stays relative per axis).
//! Then, as the f64 path: `a = d'.d'`, `b = -(o'.d') / a` (closest approach), `f = o' + b d'`,
//! `disc = 1 - f.f`; roots `b -+ h`, `h = sqrt(disc / a)`, the one farther from 0 as
//! `q = b + sign(b) h` and the other as `(o'.o' - 1) / (a q)` (no cancellation in either).
//!
//! # Error bound (u = 2^-24; first order, constants rounded up; [`fast8`] follows it line by line)
//! 1. Inputs are exact f32. `D` has error <= 2u|D_i| per component (the `C_lo` residue is
//!    <= 2u^2|C|: `eps_c`). `o' = B D` with B rounded to f32 (u) and a 3-term FMA dot (3u):
//!    |do'| <= 6u |n| max|D_i| + eps_c =: E_o, n_i = sum_j |B_ij| (row i is s_i v_i, so this is
//!    relative to the axis' own scale). `d'`: E_d = 4u |n| max|d_i|. Spheres: (4u + dev) sqrt3/r
//!    and (2u + dev) sqrt3/r, dev = deviation of r^2 A^T A from I (measured in f64 at build).
//!    eta = E_d / |d'| is the relative direction error; lanes with eta > 1e-3 go to f64.
//! 2. Closest approach, exact function of (o', d'): `f = P o'` (P projects out d'). do' moves f
//!    by <= E_o; the direction error moves |f| by <= 1.1 |o'| eta (the part along d' is second
//!    order); rounding of the fma `f` adds u|f|: radial error E_r. The along-ray error of the
//!    closest approach `b |d'|` is E_b = E_o + 2 |o'| eta + 7u |o'| (p = o'.d' 3u, a 3u, /a u).
//!    An error in b moves f along d', orthogonal to the exact f, so it enters |f|^2 only squared.
//! 3. disc = 1 - f.f: |d disc| <= (2|f| + E_r) E_r + E_b (E_b + 2u|f|) + 4u (f.f + 1) =: E_disc.
//!    Certain miss if disc < -E_disc, certain real roots if disc > E_disc, otherwise (within the
//!    bound of tangency) f64.
//! 4. Roots: sqrt(disc) moves by <= E_disc / (sqrt(disc) + sqrt(disc - E_disc)), b by E_b/|d'|,
//!    |d'| by eta relative, plus rounding <= 8u (|b| + h): E_t. A lane goes to f64 if any root is
//!    within E_t of tnear or tfar (the interval test could flip), or if the chosen root has
//!    E_t > TAU |t|.
//!
//! Hence every lane answered in f32 has the same hit/miss and root choice as the exact
//! computation and |t - t_exact| <= TAU |t| + u|t| (final rounding); the f64 path is within a few
//! f64 ulps of exact and rounds to f32 (u), so |t - t64| <= 1e-5 |t64| holds. Rays exactly (or,
//! at the f32 bound, nearly) tangent, starting on the surface, coming from so far away that
//! u |o'| is comparable to 1 (1e6 radii), or with a degenerate/non-finite direction land in f64.
//! NaN anywhere makes every comparison false and sends the lane to f64, which rejects it.
//! A packet whose valid lanes are all certain misses by a cheaper, larger bound (`certain_misses`:
//! no square root) returns before steps 2-4's square roots and divisions, with the same answer.

// Index loops over small fixed matrices (the Jacobi rotations) read as the maths does.
#![allow(clippy::needless_range_loop)]

use crate::simd::{Mask8, Vec3x8, F8};
use glam::Mat4;

/// One ellipsoid: the unit sphere under an affine map, stored as the world-to-object map in f64.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ellipsoid {
    /// world-to-object linear part (row-major 3x3) and translation
    pub(super) inv: [[f64; 4]; 3],
    pub(super) lower: [f32; 3],
    pub(super) upper: [f32; 3],
    /// the f32 SIMD intersector's precomputed form (below)
    pub(super) fast: Fast,
}

impl Ellipsoid {
    /// The unit sphere under `m`, or None if `m` is singular.
    pub(super) fn new(m: &Mat4) -> Option<Self> {
        let md = glam::DMat4::from_cols_array(&m.to_cols_array().map(f64::from));
        let det = md.determinant();
        if !det.is_finite() || det.abs() < 1e-300 {
            return None;
        }
        let inv = md.inverse();
        let r = |i: usize| {
            let row = inv.row(i);
            [row.x, row.y, row.z, row.w]
        };
        // Bounds of the image of the unit ball: centre +- the row norms of the linear part, padded
        // by 2^-10 of the extent and 2^-20 of the larger of the centre's coordinate and the extent
        // (16x the f32 rounding of either end, so the f32 box holds the ellipsoid however the
        // casts round, even one smaller than an f32 step of its position; Embree's box test, which
        // decides which packets reach the callbacks, then rejects no ray that hits it).
        let (mut lower, mut upper) = ([0f32; 3], [0f32; 3]);
        for i in 0..3 {
            let row = md.row(i);
            let ext = (row.x * row.x + row.y * row.y + row.z * row.z).sqrt();
            let pad = ext / 1024.0 + row.w.abs().max(ext) / f64::from(1u32 << 20);
            lower[i] = (row.w - ext - pad) as f32;
            upper[i] = (row.w + ext + pad) as f32;
        }
        let inv = [r(0), r(1), r(2)];
        Some(Self { inv, lower, upper, fast: Fast::new(&inv) })
    }

    /// Nearest root t in (tnear, tfar) of |o' + t d'| = 1 in object space, if any.
    #[inline]
    pub(super) fn hit(&self, o: [f32; 3], d: [f32; 3], tnear: f32, tfar: f32) -> Option<f32> {
        let m = &self.inv;
        let (o, d) = (o.map(f64::from), d.map(f64::from));
        let oo: [f64; 3] = std::array::from_fn(|i| m[i][0] * o[0] + m[i][1] * o[1] + m[i][2] * o[2] + m[i][3]);
        let dd: [f64; 3] = std::array::from_fn(|i| m[i][0] * d[0] + m[i][1] * d[1] + m[i][2] * d[2]);
        let a = dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2];
        if a.is_nan() || a <= 0.0 {
            return None;
        }
        // Numerically robust form: the discriminant from the distance of the closest approach.
        let b = -(oo[0] * dd[0] + oo[1] * dd[1] + oo[2] * dd[2]) / a; // t of the closest approach
        let f: [f64; 3] = std::array::from_fn(|i| oo[i] + b * dd[i]);
        let disc = 1.0 - (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        if disc < 0.0 {
            return None;
        }
        let h = (disc / a).sqrt();
        let (t0, t1) = (b - h, b + h);
        let (tn, tf) = (f64::from(tnear), f64::from(tfar));
        let t = if t0 > tn && t0 < tf {
            t0
        } else if t1 > tn && t1 < tf {
            t1
        } else {
            return None;
        };
        Some(t as f32).filter(|t| *t > tnear && *t < tfar)
    }
}

/// Largest relative error bound on a hit distance answered in f32 (bigger goes to f64).
pub(super) const TAU: f32 = 9e-6;
/// Unit roundoff of f32, rounded up.
const U: f32 = 5.97e-8;

/// Per-ellipsoid f32 data for [`fast8`], precomputed in f64 from the world-to-object map.
#[derive(Clone, Copy, Debug)]
pub(super) struct Fast {
    /// B = S V^T of the SVD A = U S V^T of the world-to-object linear part, rows (unused for spheres)
    b: [[f32; 3]; 3],
    /// world centre as hi + lo
    c_hi: [f32; 3],
    c_lo: [f32; 3],
    /// |do'| <= k_o max|D_i| + eps_c, |dd'| <= k_d max|d_i|
    k_o: f32,
    k_d: f32,
    eps_c: f32,
    /// Some(1/r) for spheres (A a similarity up to 1e-6 relative)
    inv_r: Option<f32>,
    /// false if anything is non-finite or out of range: every lane takes the f64 path
    usable: bool,
}

/// Eigen-decomposition of a symmetric 3x3 matrix (cyclic Jacobi): eigenvalues and eigenvectors
/// (columns of the returned matrix).
fn sym_eigen(m: glam::DMat3) -> ([f64; 3], glam::DMat3) {
    let mut a = m.to_cols_array_2d(); // a[col][row], symmetric
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if !(off > 1e-36 * diag) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let (c, s) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
            // a = J^T a J with J the rotation in the (p, q) plane.
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let vm = glam::DMat3::from_cols_array_2d(&[
        [v[0][0], v[1][0], v[2][0]],
        [v[0][1], v[1][1], v[2][1]],
        [v[0][2], v[1][2], v[2][2]],
    ]);
    ([a[0][0], a[1][1], a[2][2]], vm)
}

impl Fast {
    /// From the world-to-object rows (linear part and translation) of the f64 path.
    pub(super) fn new(inv: &[[f64; 4]; 3]) -> Self {
        let a64 = glam::DMat3::from_cols_array(&[
            inv[0][0], inv[1][0], inv[2][0], inv[0][1], inv[1][1], inv[2][1], inv[0][2], inv[1][2], inv[2][2],
        ]);
        let t64 = glam::DVec3::new(inv[0][3], inv[1][3], inv[2][3]);
        // Centre: A C + t = 0.
        let c = -(a64.inverse() * t64);
        let c_hi = c.to_array().map(|v| v as f32);
        let c_lo: [f32; 3] = std::array::from_fn(|i| (c[i] - f64::from(c_hi[i])) as f32);
        let u = f64::from(U);
        // Similarity? r^2 A^T A = I up to dev (relative); then |A x - R x / r| <= dev |x| / r.
        let g = a64.transpose() * a64;
        let r2inv = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
        let dev = (g - glam::DMat3::from_diagonal(glam::DVec3::splat(r2inv)))
            .to_cols_array()
            .iter()
            .fold(0f64, |m, v| m.max(v.abs()))
            / r2inv;
        let mut b = [[0f32; 3]; 3];
        let (k_o, k_d, nrm, inv_r) = if dev <= 1e-6 && r2inv > 0.0 {
            // o' = D / r: D (2u), times 1/r (u), 1/r rounded (u), plus dev; |D| <= sqrt 3 max|D_i|.
            let ir = r2inv.sqrt();
            let k = 3f64.sqrt() * ir * 1.01;
            ((4.0 * u + dev) * k, (2.0 * u + dev) * k, k, Some(ir as f32))
        } else {
            // A^T A = V S^2 V^T; |A x| = |S V^T x| for every x, so B = S V^T serves as A (the
            // rotation U changes no distance). Row i of B is s_i v_i: its rounding error is
            // relative to s_i, not mixed with the other axes as in A.
            let (ev, v) = sym_eigen(g);
            let mut n = 0.0;
            for i in 0..3 {
                let si = ev[i].max(0.0).sqrt();
                let vi = v.col(i);
                b[i] = [(si * vi.x) as f32, (si * vi.y) as f32, (si * vi.z) as f32];
                let row = si * (vi.x.abs() + vi.y.abs() + vi.z.abs());
                n += row * row;
            }
            // B's own error (the eigen solve in f64) is ~1e-15 relative: inside the 1.01.
            let k = n.sqrt() * 1.01;
            // D (2u) + B rounded (u) + 3-term dot (3u); d' with exact d: 4u.
            (6.0 * u * k, 4.0 * u * k, k, None)
        };
        let cmax = c.abs().max_element();
        let eps_c = (4.0 * u * u * cmax * nrm) as f32;
        let (k_o, k_d) = (k_o as f32, k_d as f32);
        let finite = b.iter().flatten().chain(&c_hi).chain(&c_lo).all(|v| v.is_finite())
            && [k_o, k_d, eps_c].iter().all(|v| v.is_finite())
            && inv_r.is_none_or(|r| r.is_finite() && r > 0.0);
        // Keep |o'|^2 and the error terms far from f32 overflow and underflow.
        let usable = finite && nrm < 1e15 && nrm > 1e-15;
        Self { b, c_hi, c_lo, k_o, k_d, eps_c, inv_r, usable }
    }
}

/// f32 SIMD result of one packet: lanes hit (with distance `t`) and lanes it cannot decide.
#[derive(Clone, Copy, Debug)]
pub(super) struct Fast8 {
    /// lanes with a certain hit in (tnear, tfar), distance `t` within TAU relative
    pub hit: Mask8,
    /// hit distance where `hit`
    pub t: F8,
    /// lanes to recompute in f64 (never overlaps `hit`)
    pub unsure: Mask8,
}

#[inline(always)]
fn max_abs(v: Vec3x8) -> F8 {
    v.x.abs().max(v.y.abs()).max(v.z.abs())
}

/// The f32 SIMD pass over the `valid` lanes (see the module doc for the bound).
#[inline(always)]
pub(super) fn fast8(e: &Fast, org: Vec3x8, dir: Vec3x8, tnear: F8, tfar: F8, valid: Mask8) -> Fast8 {
    fast8_with(e, org, dir, tnear, tfar, valid, true)
}

/// A packet's rays in the unit sphere's frame, as [`fast8`] and [`certain_misses`] read them:
/// the error bounds of the origin (`e_o`, object units) and direction (`e_d`), `a = d.d` and its
/// inverse, `oo = o.o`, the closest approach's parameter `b` and `ff = f.f` at that point.
struct Approach {
    e_o: F8,
    e_d: F8,
    a: F8,
    inv_a: F8,
    oo: F8,
    b: F8,
    ff: F8,
}

/// The [`Approach`] of rays `org + t dir` to the ellipsoid `e` (one code path for the kernel and
/// its tests).
#[inline(always)]
fn approach(e: &Fast, org: Vec3x8, dir: Vec3x8) -> Approach {
    let s = |v: f32| F8::splat(v);
    let dd = (org - Vec3x8::new(s(e.c_hi[0]), s(e.c_hi[1]), s(e.c_hi[2])))
        - Vec3x8::new(s(e.c_lo[0]), s(e.c_lo[1]), s(e.c_lo[2]));
    let (o, d) = match e.inv_r {
        Some(ir) => (dd * s(ir), dir * s(ir)),
        None => {
            let m = |v: Vec3x8| {
                let row = |r: &[f32; 3]| s(r[0]).mul_add(v.x, s(r[1]).mul_add(v.y, s(r[2]) * v.z));
                Vec3x8::new(row(&e.b[0]), row(&e.b[1]), row(&e.b[2]))
            };
            (m(dd), m(dir))
        }
    };
    let e_o = s(e.k_o).mul_add(max_abs(dd), s(e.eps_c));
    let e_d = s(e.k_d) * max_abs(dir);
    let a = d.dot(d);
    let oo = o.dot(o);
    let inv_a = F8::ONE / a;
    let b = -o.dot(d) * inv_a;
    let f = d.mul_add(b, o);
    let ff = f.dot(f);
    Approach { e_o, e_d, a, inv_a, oo, b, ff }
}

/// [`fast8`], with (`early`) or without the early return of a packet whose valid lanes are all
/// [`certain_misses`] (the same answer either way; the tests compare the two).
#[inline(always)]
fn fast8_with(e: &Fast, org: Vec3x8, dir: Vec3x8, tnear: F8, tfar: F8, valid: Mask8, early: bool) -> Fast8 {
    let none = F8::ZERO;
    if !e.usable {
        return Fast8 { hit: none, t: none, unsure: valid };
    }
    let s = |v: f32| F8::splat(v);
    let Approach { e_o, e_d, a, inv_a, oo, b, ff } = approach(e, org, dir);
    let disc = F8::ONE - ff;
    if early && (valid & !certain_misses(e_o, e_d, a, inv_a, oo, ff, disc)).none() {
        return Fast8 { hit: none, t: none, unsure: none };
    }
    let (dlen, olen, flen) = (a.sqrt(), oo.sqrt(), ff.sqrt());
    let eta = e_d / dlen;
    // Along-ray error of the closest approach (object units), and radial error of f.
    let e_b = e_o + olen * (s(2.0) * eta + s(7.0 * U));
    let e_r = e_o + olen * (s(1.1) * eta) + s(U) * flen;
    let e_disc = (s(2.0) * flen + e_r).mul_add(e_r, e_b * (e_b + s(2.0 * U) * flen)) + s(4.0 * U) * (ff + F8::ONE);
    // eta <= 1e-3 is false for NaN and for a == 0 (eta = inf or NaN).
    let ok = valid & eta.simd_le(s(1e-3)) & olen.simd_lt(s(1e18)) & a.simd_gt(s(1e-30)) & a.simd_lt(s(1e30));
    let miss = ok & disc.simd_lt(-e_disc);
    let two_roots = ok & disc.simd_gt(e_disc);
    let mut unsure = valid & !miss & !two_roots;
    if two_roots.none() {
        return Fast8 { hit: none, t: none, unsure };
    }
    let disc = two_roots.select(disc, F8::ONE);
    let sd = disc.sqrt();
    let h = sd / dlen;
    // Stable roots: q = b + sign(b) h has no cancellation; the other root is c / (a q).
    let q = b + b.simd_lt(F8::ZERO).select(-h, h);
    let r2 = (oo - F8::ONE) * inv_a / q;
    let t_lo = q.min(r2);
    let t_hi = q.max(r2);
    // |sqrt(x') - sqrt(x)| <= e / (sqrt x + sqrt(x - e)) for |x' - x| <= e < x.
    let e_sqrt = e_disc / (sd + (disc - e_disc).max(F8::ZERO).sqrt());
    let e_t = (e_b + e_sqrt) / dlen + (s(1.1) * eta + s(8.0 * U)) * (b.abs() + h);
    let near = |t: F8, x: F8| (t - x).abs().simd_le(e_t);
    let edge = near(t_lo, tnear) | near(t_lo, tfar) | near(t_hi, tnear) | near(t_hi, tfar);
    let in_lo = t_lo.simd_gt(tnear) & t_lo.simd_lt(tfar);
    let in_hi = t_hi.simd_gt(tnear) & t_hi.simd_lt(tfar);
    let t = in_lo.select(t_lo, t_hi);
    let any = in_lo | in_hi;
    // NaN in e_t (or t) fails the <= test and goes to f64 too.
    let loose = any & !e_t.simd_le(s(TAU) * t.abs());
    let bad = two_roots & (edge | loose | !e_t.is_finite());
    unsure |= bad;
    let hit = two_roots & any & !bad;
    Fast8 { hit, t: hit.select(t, none), unsure }
}

/// Lanes that [`fast8`]'s bound answers as certain misses (`ok` and `disc < -e_disc`), found by
/// a cheaper, larger bound with no square root or division of its own (a packet whose lanes all
/// miss returns before the bound's 3 square roots and 2 divisions; most packets that reach a
/// small sphere's callback miss it). With F = |f|, O = |o'|, eta as in [`fast8`] and eps = 2^-10,
/// `2 F e_r <= eps F^2 + e_r^2 / eps` (AM-GM), `e_r^2 <= 3 (e_o^2 + 1.21 O^2 eta^2 + u^2 F^2)`,
/// `e_b^2 <= 2 e_o^2 + 4 O^2 (4 eta^2 + 49 u^2)` and `2u F e_b <= u (F^2 + e_b^2)`, so
/// `e_disc <= (eps + 5u) F^2 + (1 + 1/eps) e_r^2 + (1 + u) e_b^2 + 4u`; evaluated with
/// `O^2 = o'.o'`, `F^2 = f.f`, `eta^2 = e_d^2 / a` and doubled, it stays above the f32 `e_disc`
/// (whose own roundings are a few u relative). `e_d^2 <= 0.99e-6 a` gives eta <= 1e-3 and
/// `o'.o' < 1e35` gives |o'| < 1e18, so these lanes are `ok`. NaN anywhere fails a comparison:
/// such a lane is not a certain miss here, and [`fast8`] decides it as before.
#[inline(always)]
fn certain_misses(e_o: F8, e_d: F8, a: F8, inv_a: F8, oo: F8, ff: F8, disc: F8) -> Mask8 {
    let s = |v: f32| F8::splat(v);
    let ed2 = e_d * e_d;
    let eta2 = ed2 * inv_a;
    let eo2 = e_o * e_o;
    let e_r2 = s(3.0) * (eo2 + s(1.21) * oo * eta2 + s(U * U) * ff);
    let e_b2 = s(2.0) * eo2 + s(4.0) * oo * (s(4.0) * eta2 + s(49.0 * U * U));
    const EPS: f32 = 1.0 / 1024.0;
    let bound = ff * s(EPS + 5.0 * U) + s(1.0 + 1.0 / EPS) * e_r2 + s(1.0 + U) * e_b2 + s(4.0 * U);
    let ok = ed2.simd_le(s(0.99e-6) * a) & oo.simd_lt(s(1e35)) & a.simd_gt(s(1e-30)) & a.simd_lt(s(1e30));
    ok & disc.simd_lt(-(s(2.0) * bound))
}

/// Intersects the ellipsoid with the `live` lanes of an 8-ray packet (Embree's fields as SoA
/// vectors): f32 SIMD ([`fast8`]), with f64 ([`Ellipsoid::hit`]) for the lanes it leaves unsure.
/// Returns the lanes hit inside (tnear, tfar) and their distances (0 in the other lanes).
#[inline(always)]
pub(super) fn hits8(e: &Ellipsoid, org: Vec3x8, dir: Vec3x8, tnear: F8, tfar: F8, live: Mask8) -> (Mask8, F8) {
    let r = fast8(&e.fast, org, dir, tnear, tfar, live);
    let unsure = r.unsure.to_bitmask();
    if unsure == 0 {
        return (r.hit, r.t);
    }
    hits8_f64(e, org, dir, tnear, tfar, r, unsure)
}

/// [`hits8`]'s f64 pass over the lanes `unsure` (bits) that [`fast8`] left (out of line: rare).
#[cold]
#[inline(never)]
fn hits8_f64(e: &Ellipsoid, org: Vec3x8, dir: Vec3x8, tnear: F8, tfar: F8, r: Fast8, unsure: u32) -> (Mask8, F8) {
    let (mut hit, mut t) = (r.hit.to_bitmask(), r.t.to_array());
    let mut bits = unsure;
    while bits != 0 {
        let i = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        let (o, d) = (org.lane(i), dir.lane(i));
        if let Some(ti) = e.hit(o.to_array(), d.to_array(), tnear.as_array()[i], tfar.as_array()[i]) {
            t[i] = ti;
            hit |= 1 << i;
        }
    }
    (crate::simd::mask_from_bools(std::array::from_fn(|i| hit & (1 << i) != 0)), F8::new(t))
}

/// Intersects the ellipsoid with the `m <= 8` lanes of a packet: `load(field)` returns the first
/// `m` floats of Embree ray field `field` (0-2 org, 3 tnear, 4-6 dir, 8 tfar; lanes >= m
/// anything finite), `valid(i)` whether lane i is active. Calls `on_hit(lane, t)` for every lane
/// hit inside (tnear, tfar), in lane order ([`hits8`]).
#[inline]
pub(super) fn packet_hits(
    e: &Ellipsoid,
    m: usize,
    load: impl Fn(usize) -> [f32; 8],
    valid: impl Fn(usize) -> bool,
    mut on_hit: impl FnMut(usize, f32),
) {
    let live = crate::simd::mask_from_bools(std::array::from_fn(|i| i < m && valid(i)));
    if live.none() {
        return;
    }
    let v3 = |f: usize| Vec3x8::new(F8::new(load(f)), F8::new(load(f + 1)), F8::new(load(f + 2)));
    let (hit, t) = hits8(e, v3(0), v3(4), F8::new(load(3)), F8::new(load(8)), live);
    let (mut bits, t) = (hit.to_bitmask(), t.to_array());
    while bits != 0 {
        let i = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        on_hit(i, t[i]);
    }
}

/// Old (f64 per lane) and new (f32 packet) intersection of one ellipsoid, and the deterministic
/// ray generator and packet layout shared by `benches/ellipsoid.rs` and the tests.
#[doc(hidden)]
pub mod bench {
    use super::{packet_hits, Ellipsoid};
    use glam::{Mat4, Vec3};

    /// One ellipsoid, the unit sphere under `object_to_world`.
    pub struct Prim(Ellipsoid);

    /// 8 rays in Embree field order (0-2 org, 3 tnear, 4-6 dir, 8 tfar).
    pub type Packet = [[f32; 8]; 9];

    /// xorshift64*: deterministic, no dependency (the state must not be 0).
    pub struct Rng(pub u64);

    impl Rng {
        /// Uniform in [0, 1), 24 bits.
        pub fn unit(&mut self) -> f32 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32) / (1u64 << 24) as f32
        }

        /// Uniform in [-1, 1).
        pub fn sym(&mut self) -> f32 {
            2.0 * self.unit() - 1.0
        }

        /// A uniformly distributed unit direction (rejection from the cube).
        pub fn dir(&mut self) -> Vec3 {
            loop {
                let v = Vec3::new(self.sym(), self.sym(), self.sym());
                if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                    return v.normalize();
                }
            }
        }
    }

    /// Up to 8 rays `(origin, direction, tnear, tfar)` as a [`Packet`]; missing lanes are zero.
    pub fn pack(rays: &[(Vec3, Vec3, f32, f32)]) -> Packet {
        let mut p = [[0f32; 8]; 9];
        for (i, &(o, d, tn, tf)) in rays.iter().enumerate() {
            let v = [o.x, o.y, o.z, tn, d.x, d.y, d.z, 0.0, tf];
            for (f, x) in v.into_iter().enumerate() {
                p[f][i] = x;
            }
        }
        p
    }

    impl Prim {
        /// None if the map is singular.
        pub fn new(object_to_world: &Mat4) -> Option<Self> {
            Ellipsoid::new(object_to_world).map(Self)
        }
        /// The f64 path lane by lane; returns the number of hits and the sum of their distances.
        pub fn scalar64(&self, p: &Packet) -> (u32, f32) {
            let (mut n, mut s) = (0, 0.0);
            for i in 0..8 {
                let l = |f: usize| p[f][i];
                if let Some(t) = self.0.hit([l(0), l(1), l(2)], [l(4), l(5), l(6)], l(3), l(8)) {
                    n += 1;
                    s += t;
                }
            }
            (n, s)
        }
        /// The f32 packet path (with its f64 fallback); same result as [`Prim::scalar64`].
        pub fn packet(&self, p: &Packet) -> (u32, f32) {
            let (mut n, mut s) = (0, 0.0);
            packet_hits(
                &self.0,
                8,
                |f| p[f],
                |_| true,
                |_, t| {
                    n += 1;
                    s += t;
                },
            );
            (n, s)
        }
        /// Lanes of `p` the f32 pass leaves to f64.
        pub fn unsure(&self, p: &Packet) -> u32 {
            use crate::simd::{mask_all, Vec3x8, F8};
            let v3 = |f: usize| Vec3x8::new(F8::new(p[f]), F8::new(p[f + 1]), F8::new(p[f + 2]));
            let r = super::fast8(&self.0.fast, v3(0), v3(4), F8::new(p[3]), F8::new(p[8]), mask_all());
            r.unsure.to_bitmask().count_ones()
        }
    }
}

#[cfg(test)]
#[cfg(test)]
#[path = "ellipsoid_tests.rs"]
mod tests;

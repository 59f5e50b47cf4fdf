//! `--light-warp area|solid-angle`: how a point is placed on the chosen area light.
//!
//! `area` (the default) places it uniformly in area (`emitters.rs`). `solid-angle` places it
//! uniformly in the solid angle S the light subtends at the shading point: spherical rectangles
//! for rectangular quad lights (`sampling::spherical_rect`), spherical triangles for emissive
//! triangles (`sampling::spherical_tri`), the cone of the visible cap for sphere lights
//! (`sampling::spherical_cap`, from outside the sphere; from inside, area sampling as Mitsuba and
//! pbrt do, and a one-sided sphere light sends nothing inwards anyway). The 2D point is the same sampler point the area warp
//! would have used ([`LightSample8::uv`]), so stratification and low discrepancy carry through.
//!
//! A lane is warped where the light is a rectangle, a triangle or a sphere (a skewed parallelogram
//! quad is not: area sampling), the point lies on the light's emitting side (outside a sphere),
//! and S >= [`OMEGA_MIN`] ([`SPHERE_OMEGA_MIN`] for a sphere);
//! elsewhere the area sample stays (below `OMEGA_MIN` the f32 warp no longer resolves the light,
//! see the constant). The decision is a function of (light, point) only, so the pdf of a
//! BSDF-sampled light hit ([`Emitters::solid_angle_x8`]) is the one next event estimation used.
//!
//! A warped sample keeps the integrators' area form: its `area` becomes `S d^2 / cos_l`, so
//! `cos_l / (d^2 area) = 1 / S` is its pdf per unit area converted to solid angle and
//! `L f cos_i cos_l area / d^2 = L f cos_i S` its estimate.

use super::emitters::{Emitter, Emitters, LightSample8, WarpRow};
use super::lane_table::LaneTable;
use crate::sampling::spherical_cap::SphericalCap8;
use crate::sampling::spherical_rect::SphericalRect8;
use crate::sampling::spherical_tri::SphericalTri8;
use crate::simd::{Mask8, Vec3x8, F8, U8};

/// Smallest solid angle (sr) sampled by the warps; a light subtending less is sampled by area.
///
/// Measured (`light::warp::tests::f32_warp_error_by_solid_angle`, `--nocapture`): the largest
/// distance between the f32 warps' points and the same warps in f64, over a 65 x 65 grid of
/// (u, v), relative to the size of a unit light seen head-on. The rectangle's error grows as 1/S
/// (its `au = u S + k` keeps `ulp(k) / S` of u's resolution): 2.2e-5 at S = 1e-2, 1.7e-4 at
/// 1.1e-3, 2.6e-3 at 1e-4, 2.6e-2 at 1.1e-5 (with the one-division `atan2` and the multiplied-out
/// column of `sampling::spherical_rect`; the three-step form read 2.1e-3 and 1.7e-2 there). The
/// triangle's (half-angle form, see `sampling::spherical_tri`) stays below 2e-5 down to 1e-6 sr. At 3e-4 sr the rectangle is
/// within 1e-3 of its light; a unit light is then 58 units away, where area sampling's density
/// is within 3e-4 of uniform in solid angle anyway, so nothing is lost by falling back there.
pub const OMEGA_MIN: f32 = 3e-4;

/// Smallest solid angle (sr) of a sphere light sampled by its cone; a sphere subtending less is
/// sampled by area.
///
/// The cap warp keeps its digits far below [`OMEGA_MIN`] (it is written in `1 - cos` and sine
/// ratios, `sampling::spherical_cap`). Measured by
/// `sampling::spherical_cap::tests::f32_cap_warp_error_by_solid_angle` (`--nocapture`) for a unit
/// sphere against an f64 ray-sphere construction: S within 3e-7 relative from 1.6 sr down to
/// 3e-16 sr; the points within 5e-6 r down to 3e-4 sr, then growing as `4e-8 d / r` (4e-3 r at
/// 3e-10 sr, 1 r at 3e-16 sr): that is the rounding of f32 positions about a centre at distance
/// d, which area sampling's points `c + r n` share, so falling back would not help. The warp's
/// own limit is the squared ratio `(r / d)^2`, which leaves f32's normal range below 1.2e-38:
/// the threshold 1e-30 sr (`r / d` about 5.6e-16) keeps it clear of that.
pub const SPHERE_OMEGA_MIN: f32 = 1e-30;

/// How next event estimation places a point on an area light (`--light-warp`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum LightWarp {
    /// uniform in area (the course's convention; the default)
    #[default]
    Area,
    /// uniform in the solid angle the light subtends (spherical rectangles, triangles and the
    /// cones of sphere lights)
    SolidAngle,
}

impl LightWarp {
    /// Every warp with its name, in a fixed order.
    pub const ALL: [(LightWarp, &'static str); 2] = [(Self::Area, "area"), (Self::SolidAngle, "solid-angle")];

    /// Name (`area`, `solid-angle`).
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|(c, _)| *c == self).map(|(_, n)| *n).unwrap_or("area")
    }
}

impl std::str::FromStr for LightWarp {
    type Err = super::select::UnknownName;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL.iter().find(|(_, n)| n.eq_ignore_ascii_case(s.trim())).map(|(c, _)| *c).ok_or_else(|| {
            super::select::UnknownName {
                what: "light warp",
                name: s.into(),
                known: Self::ALL.map(|(_, n)| n).join(", "),
            }
        })
    }
}

/// Eight lanes' lights ([`WarpRow`]s), splatted or gathered.
struct Lights8 {
    a: Vec3x8,
    /// a rectangle's unit edges, a triangle's edges
    ex: Vec3x8,
    ey: Vec3x8,
    normal: Vec3x8,
    lx: F8,
    ly: F8,
    radius: F8,
    tri: Mask8,
    rect: Mask8,
    sphere: Mask8,
    any_tri: bool,
    any_rect: bool,
    any_sphere: bool,
}

impl Lights8 {
    /// From the 16 columns of eight [`WarpRow`]s.
    #[inline]
    fn from_cols(c: [F8; 16]) -> Self {
        let v = |k: usize| Vec3x8::new(c[k], c[k + 1], c[k + 2]);
        let (tri, rect, sphere) = (
            c[15].simd_eq(F8::splat(WarpRow::TRI)),
            c[15].simd_eq(F8::splat(WarpRow::RECT)),
            c[15].simd_eq(F8::splat(WarpRow::SPHERE)),
        );
        Self {
            a: v(0),
            ex: v(3),
            ey: v(6),
            normal: v(9),
            lx: c[12],
            ly: c[13],
            radius: c[14],
            tri,
            rect,
            sphere,
            any_tri: tri.any(),
            any_rect: rect.any(),
            any_sphere: sphere.any(),
        }
    }

    #[inline]
    fn one(row: &WarpRow) -> Self {
        Self::from_cols(row.0.map(F8::splat))
    }

    /// The lights `ids` (rows of `rows`, whose last row is the empty one) on lanes `active`; the
    /// other lanes get the empty row.
    #[inline]
    fn lanes(rows: &[WarpRow], table: Option<&LaneTable<16>>, ids: U8, active: Mask8) -> Self {
        let last = rows.len() - 1;
        if let Some(t) = table {
            // Inactive lanes and out-of-range ids read the empty last row, as below.
            let rows = active.to_bits().select(ids.min(U8::splat(last as u32)), U8::splat(last as u32));
            return Self::from_cols(std::array::from_fn(|k| t.field(k, rows)));
        }
        let ids = ids.to_array();
        if ids.iter().all(|&i| i == ids[0]) && (ids[0] as usize) < last {
            return Self::one(&rows[ids[0] as usize]);
        }
        let on = active.to_bitmask();
        let r: [&[f32; 16]; 8] =
            std::array::from_fn(|i| &rows[if on & (1 << i) != 0 { (ids[i] as usize).min(last) } else { last }].0);
        Self::from_cols(std::array::from_fn(|k| F8::new(std::array::from_fn(|i| r[i][k]))))
    }

    /// The lights seen from `p` on lanes `active`: the warps, S per lane and the lanes warped.
    #[inline(always)]
    fn subtend(&self, p: Vec3x8, active: Mask8) -> Subtended {
        // Only the emitting side is lit; there every point of the (planar) light has cos_l > 0.
        let front = self.normal.dot(p - self.a).simd_gt(F8::ZERO);
        let rect = self.any_rect.then(|| SphericalRect8::new(p, self.a, self.ex, self.ey, self.lx, self.ly));
        let tri = self.any_tri.then(|| SphericalTri8::new(p, self.a, self.a + self.ex, self.a + self.ey));
        let s_rect = rect.map_or(F8::ZERO, |r| self.rect.select(r.solid_angle(), F8::ZERO));
        let s_tri = tri.map_or(F8::ZERO, |t| self.tri.select(t.solid_angle(), F8::ZERO));
        let omega = self.tri.select(s_tri, s_rect);
        let warped = active & front & (self.tri | self.rect) & omega.simd_ge(F8::splat(OMEGA_MIN));
        if !self.any_sphere {
            return Subtended { rect, tri, cap: None, omega, warped };
        }
        // Spheres: S is 0 from inside (not warped).
        let cap = SphericalCap8::new(p, self.a, self.radius);
        let s_cap = cap.solid_angle();
        let omega = self.sphere.select(s_cap, omega);
        let cap_ok = active & self.sphere & s_cap.simd_ge(F8::splat(SPHERE_OMEGA_MIN));
        let warped = (warped & !self.sphere) | cap_ok;
        Subtended { rect, tri, cap: Some(cap), omega, warped }
    }
}

/// Lights seen from a point ([`Lights8::subtend`]).
struct Subtended {
    rect: Option<SphericalRect8>,
    tri: Option<SphericalTri8>,
    cap: Option<SphericalCap8>,
    omega: F8,
    warped: Mask8,
}

/// Places the points of `ls` again, uniformly in solid angle about `p`, on the lanes of `active`
/// that the warp covers (see the module docs); the other lanes keep their area sample.
#[inline(always)]
fn rewarp(l: &Lights8, ls: &mut LightSample8, p: Vec3x8, active: Mask8) {
    let sub = l.subtend(p, active);
    if sub.warped.none() {
        return;
    }
    let (u, v) = ls.uv;
    let mut y = ls.y;
    if let Some(r) = sub.rect {
        y = Vec3x8::select(sub.warped & l.rect, r.sample(u, v), y);
    }
    if let Some(t) = sub.tri {
        y = Vec3x8::select(sub.warped & l.tri, t.sample(u, v), y);
    }
    let mut normal = l.normal;
    if let Some(c) = sub.cap {
        let (yc, nc) = c.sample(u, v);
        let on = sub.warped & l.sphere;
        y = Vec3x8::select(on, yc, y);
        normal = Vec3x8::select(on, nc, normal);
    }
    let to = y - p;
    let d2 = to.length_squared();
    let cos_l_d = -normal.dot(to);
    // S d^2 / cos_l with cos_l = cos_l_d / d.
    let area = sub.omega * d2 * d2.sqrt() / cos_l_d;
    let ok = sub.warped & area.simd_gt(F8::ZERO) & area.is_finite();
    ls.y = Vec3x8::select(ok, y, ls.y);
    ls.area = ok.select(area, ls.area);
    if l.any_sphere {
        ls.normal = Vec3x8::select(ok & l.sphere, normal, ls.normal);
    }
}

impl Emitter {
    /// [`Emitter::sample_x8`]'s points `ls` (of this light) placed again by solid angle about `p`
    /// where the warp applies (module docs), on the lanes `active`.
    #[inline]
    pub fn warp_x8(&self, warp: LightWarp, ls: &mut LightSample8, p: Vec3x8, active: Mask8) {
        // The row is computed only where it is used.
        if warp == LightWarp::SolidAngle {
            self.warp_row().warp_x8(warp, ls, p, active);
        }
    }
}

impl WarpRow {
    /// [`Emitter::warp_x8`] of the light whose row this is (from [`Emitters::warp_rows`] rather
    /// than computed again).
    #[inline(always)]
    pub fn warp_x8(&self, warp: LightWarp, ls: &mut LightSample8, p: Vec3x8, active: Mask8) {
        if warp == LightWarp::SolidAngle && self.0[15] != WarpRow::NONE {
            rewarp(&Lights8::one(self), ls, p, active);
        }
    }
}

impl Emitters {
    /// Points `ls` of the lights `ls.light` (per lane) placed again by solid angle about `p`
    /// where the warp applies (module docs), on the lanes `active`.
    #[inline]
    pub fn warp_x8(&self, warp: LightWarp, ls: &mut LightSample8, p: Vec3x8, active: Mask8) {
        if warp == LightWarp::SolidAngle && active.any() {
            rewarp(&Lights8::lanes(&self.warp_rows, self.warp_lanes.as_ref(), ls.light, active), ls, p, active);
        }
    }

    /// [`Emitter::warp_x8`] of light `i` (its [`WarpRow`] from the table rather than computed
    /// again).
    #[inline]
    pub fn warp_one_x8(&self, i: usize, warp: LightWarp, ls: &mut LightSample8, p: Vec3x8, active: Mask8) {
        self.warp_rows[i].warp_x8(warp, ls, p, active);
    }

    /// The solid angle S of lights `ids` seen from `p` and the lanes of `active` where
    /// `solid-angle` sampling places points by it (pdf 1 / S per unit solid angle there): what
    /// a BSDF-sampled hit of a light weighs its MIS with.
    #[inline]
    pub fn solid_angle_x8(&self, ids: U8, p: Vec3x8, active: Mask8) -> (F8, Mask8) {
        let sub = Lights8::lanes(&self.warp_rows, self.warp_lanes.as_ref(), ids, active).subtend(p, active);
        (sub.omega, sub.warped)
    }
}

#[cfg(test)]
#[path = "warp_sphere_tests.rs"]
mod sphere_tests;
#[cfg(test)]
#[path = "warp_tests.rs"]
mod tests;

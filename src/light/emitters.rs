//! Every area light of a scene in one list (quad lights first, in file order, then sphere lights
//! (Mitsuba `sphere` shapes with an `area` emitter), then emissive triangles from OBJ faces with
//! `Ke` and Mitsuba meshes), and how a light is chosen and a point sampled on it.
//!
//! Geometry: an emitter is `a + u ab + v ac`, over the unit square for a quad light and over the
//! triangle `u, v >= 0, u + v <= 1` for an emissive triangle (a square sample is folded onto the
//! triangle: `(u, v) -> (1 - u, 1 - v)` when `u + v > 1`, which keeps it uniform). A sphere light
//! is its centre `a` and `radius` (`ab`, `ac` zero): by area a point is uniform on the whole sphere
//! (`z = 1 - 2u`, azimuth `2 pi v`), its normal outward, the points the shading point cannot see
//! getting `cos_l <= 0` (no contribution); `light::warp` samples its visible cap by solid angle.
//! A sphere emits outwards (Mitsuba's one-sided area emitter), its `normal` field is an unused
//! `+z` (the normal at a point is [`Emitter::normal_at`]). Emission is
//! one-sided, towards `normal`: `normalize(ac x ab)` for a quad light (the format's rule) and
//! `normalize(ab x ac) = normalize((v1 - v0) x (v2 - v0))` for a triangle (the side its winding
//! faces, counter-clockwise seen from the lit side, as OBJ meshes are written).
//!
//! Which light a sample picks is the one light-choice interface, `light::select::LightSampler`
//! (uniform, power, spatial; also `direct`'s power choice among the emissive triangles); this
//! file places the point on the chosen light ([`Emitters::place_into_x8`]).

use super::lane_table::LaneTable;
use crate::simd::{Mask8, Vec3x8, F8, U8};
use glam::Vec3;

/// One area light: `a + u ab + v ac`, a parallelogram or (with `triangle`) a triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emitter {
    /// corner (v0 of a triangle)
    pub a: Vec3,
    /// first edge (v1 - v0)
    pub ab: Vec3,
    /// second edge (v2 - v0)
    pub ac: Vec3,
    /// emitted radiance on the emitting side
    pub radiance: Vec3,
    /// unit emitting normal
    pub normal: Vec3,
    /// area (|ab x ac|, half that for a triangle)
    pub area: f32,
    /// triangle rather than parallelogram
    pub triangle: bool,
    /// a sphere of centre `a` and radius `radius` (then `ab`, `ac` are zero)
    pub sphere: bool,
    /// radius of a sphere light (0 for polygons)
    pub radius: f32,
}

impl Emitter {
    /// The quad light `a + u ab + v ac`, emitting towards `normalize(ac x ab)`.
    pub fn quad(a: Vec3, ab: Vec3, ac: Vec3, radiance: Vec3) -> Self {
        let cross = ab.cross(ac);
        Self {
            a,
            ab,
            ac,
            radiance,
            normal: (-cross).normalize_or_zero(),
            area: cross.length(),
            triangle: false,
            sphere: false,
            radius: 0.0,
        }
    }

    /// The sphere light of centre `center` and radius `radius`, emitting outwards.
    pub fn sphere(center: Vec3, radius: f32, radiance: Vec3) -> Self {
        Self {
            a: center,
            ab: Vec3::ZERO,
            ac: Vec3::ZERO,
            radiance,
            normal: Vec3::Z,
            area: 4.0 * std::f32::consts::PI * radius * radius,
            triangle: false,
            sphere: true,
            radius,
        }
    }

    /// Unit emitting normal at the point `y` of the light: `normal` for a polygon, the outward
    /// normal `(y - a) / radius` (normalized) for a sphere.
    #[inline]
    pub fn normal_at(&self, y: Vec3) -> Vec3 {
        if self.sphere {
            (y - self.a).normalize_or_zero()
        } else {
            self.normal
        }
    }

    /// The emissive triangle `v`, emitting towards `normalize((v1 - v0) x (v2 - v0))`.
    pub fn triangle(v: [Vec3; 3], radiance: Vec3) -> Self {
        let (ab, ac) = (v[1] - v[0], v[2] - v[0]);
        let cross = ab.cross(ac);
        Self {
            a: v[0],
            ab,
            ac,
            radiance,
            normal: cross.normalize_or_zero(),
            area: 0.5 * cross.length(),
            triangle: true,
            sphere: false,
            radius: 0.0,
        }
    }

    /// Polygon for [`crate::light::polygonal::polygon_phi`], wound so that its right-hand normal is
    /// opposite to the emitting normal, as for a quad light: a quad's corners `[a, a+ab, a+ab+ac,
    /// a+ac]`, a triangle's `[v0, v2, v1, v1]` (the zero-length edge adds nothing).
    pub fn corners(&self) -> [Vec3; 4] {
        if self.triangle {
            [self.a, self.a + self.ac, self.a + self.ab, self.a + self.ab]
        } else {
            [self.a, self.a + self.ab, self.a + self.ab + self.ac, self.a + self.ac]
        }
    }

    /// Power used to choose among lights: `area * mean(max(radiance, 0))` (the constant pi dropped).
    pub fn power(&self) -> f32 {
        self.area * self.radiance.max(Vec3::ZERO).element_sum() / 3.0
    }

    /// Point of the light for a unit-square sample `(u, v)`, uniform in area.
    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        if self.sphere {
            let (y, _) = sphere_point_x8(Vec3x8::splat(self.a), F8::splat(self.radius), F8::splat(u), F8::splat(v));
            return y.lane(0);
        }
        let (u, v) = if self.triangle && u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
        self.ac.mul_add(Vec3::splat(v), self.ab.mul_add(Vec3::splat(u), self.a))
    }

    /// Eight points of this light for unit-square samples `(u, v)` (uniform in area), as a light
    /// sample of this light alone (`inv_pmf` 1, index 0); bit-identical to the gathered
    /// [`Emitters::sample_x8`] of the same light.
    #[inline]
    pub fn sample_x8(&self, u: F8, v: F8) -> LightSample8 {
        let (u0, v0) = (u, v);
        let s = Vec3x8::splat;
        if self.sphere {
            let (y, normal) = sphere_point_x8(s(self.a), F8::splat(self.radius), u, v);
            return LightSample8 {
                y,
                normal,
                radiance: s(self.radiance),
                area: F8::splat(self.area),
                inv_pmf: F8::ONE,
                light: U8::splat(0),
                uv: (u0, v0),
            };
        }
        let fold = if self.triangle { (u + v).simd_gt(F8::ONE) } else { Mask8::splat(0.0) };
        let (u, v) = (fold.select(F8::ONE - u, u), fold.select(F8::ONE - v, v));
        LightSample8 {
            y: s(self.ac).mul_add(v, s(self.ab).mul_add(u, s(self.a))),
            normal: s(self.normal),
            radiance: s(self.radiance),
            area: F8::splat(self.area),
            inv_pmf: F8::ONE,
            light: U8::splat(0),
            uv: (u0, v0),
        }
    }
}

/// A point sampled on a light, for 8 lanes.
#[derive(Clone, Copy, Debug)]
pub struct LightSample8 {
    /// the point, world space
    pub y: Vec3x8,
    /// unit emitting normal of the chosen light
    pub normal: Vec3x8,
    /// its radiance
    pub radiance: Vec3x8,
    /// 1 / (the point's pdf per unit area on its light): the light's area when the point is
    /// uniform in area, `S d^2 / cos_l` where `light::warp` placed it uniformly in the solid
    /// angle S the light subtends (its pdf per unit area is then 1 / (area * inv_pmf) either way)
    pub area: F8,
    /// 1 / probability of having chosen it
    pub inv_pmf: F8,
    /// index into [`Emitters::list`]
    pub light: U8,
    /// the unit-square sample the point was placed from (after a `reuse` remap of u, before a
    /// triangle's fold), for `light::warp` to place it again by solid angle
    pub uv: (F8, F8),
}

impl LightSample8 {
    /// A sample of nothing (zero everywhere): a buffer for the calls that fill one in place.
    pub const ZERO: Self = Self {
        y: Vec3x8::ZERO,
        normal: Vec3x8::ZERO,
        radiance: Vec3x8::ZERO,
        area: F8::ZERO,
        inv_pmf: F8::ZERO,
        light: U8::ZERO,
        uv: (F8::ZERO, F8::ZERO),
    };
}

/// The scene's area lights.
#[derive(Clone, Debug, PartialEq)]
pub struct Emitters {
    /// quad lights (indices `0..n_quads`), then emissive triangles
    pub list: Vec<Emitter>,
    /// number of lights sampled one by one at the front of `list`: the quad lights, then the
    /// sphere lights (everything but the emissive triangles)
    pub n_quads: usize,
    /// some light is a sphere
    pub any_sphere: bool,
    /// each light's [`WarpRow`], then an all-zero row (kind [`WarpRow::NONE`]) that lanes
    /// without a light gather
    pub warp_rows: Vec<WarpRow>,
    /// the lights' fields ([`place_row`]) as lane columns, where they fit ([`LaneTable`])
    place_lanes: Option<LaneTable<PLACE_FIELDS>>,
    /// `warp_rows` as lane columns, where they fit
    pub(super) warp_lanes: Option<LaneTable<16>>,
}

/// Fields of a light that placing a point on it reads ([`place_row`]).
const PLACE_FIELDS: usize = 19;

/// A light's fields for [`Emitters::place_lanes_x8`] as bits: corner, edges, normal, radiance
/// (3 each), area, radius, then the triangle and sphere flags as lane masks (all ones or zero).
fn place_row(e: &Emitter) -> [u32; PLACE_FIELDS] {
    let mut r = [0; PLACE_FIELDS];
    for (k, v) in [e.a, e.ab, e.ac, e.normal, e.radiance].iter().enumerate() {
        for (c, x) in v.to_array().iter().enumerate() {
            r[3 * k + c] = x.to_bits();
        }
    }
    let flag = |b: bool| if b { u32::MAX } else { 0 };
    r[15..].copy_from_slice(&[e.area.to_bits(), e.radius.to_bits(), flag(e.triangle), flag(e.sphere)]);
    r
}

/// Relative tolerance of `|ab . ac| / (|ab| |ac|)` for a quad light to count as a rectangle.
const RECT_TOL: f32 = 1e-4;

impl Emitter {
    /// A quad light whose edges are orthogonal (within [`RECT_TOL`]): sampled by spherical
    /// rectangles under `--light-warp solid-angle`.
    pub fn is_rectangle(&self) -> bool {
        !self.triangle && !self.sphere && self.ab.dot(self.ac).abs() <= RECT_TOL * self.ab.length() * self.ac.length()
    }

    /// This light's constants for the solid-angle warp ([`WarpRow`]), computed once.
    pub fn warp_row(&self) -> WarpRow {
        let mut r = [0.0; 16];
        let mut put = |k: usize, v: Vec3| r[k..k + 3].copy_from_slice(&v.to_array());
        put(0, self.a);
        put(9, self.normal);
        let kind = if self.sphere {
            WarpRow::SPHERE
        } else if self.triangle {
            put(3, self.ab);
            put(6, self.ac);
            WarpRow::TRI
        } else if self.is_rectangle() {
            // The unit edges and lengths in the x8 arithmetic the warp used per lane (same bits).
            let (ab, ac) = (Vec3x8::splat(self.ab), Vec3x8::splat(self.ac));
            let (lx, ly) = (ab.length(), ac.length());
            put(3, ab.scale(F8::ONE / lx).lane(0));
            put(6, ac.scale(F8::ONE / ly).lane(0));
            r[12] = lx.as_array()[0];
            r[13] = ly.as_array()[0];
            WarpRow::RECT
        } else {
            WarpRow::NONE
        };
        r[14] = self.radius;
        r[15] = kind;
        WarpRow(r)
    }
}

/// One light's constants for `light::warp`, 16 f32 so that eight lanes' lights gather as rows
/// (a transpose) rather than field by field: `[a; ex; ey; normal; lx, ly, radius, kind]`. `a` is
/// the corner (a sphere's centre); `ex`, `ey` a rectangle's unit edges (`lx`, `ly` their lengths)
/// or a triangle's edges `ab`, `ac`; `kind` one of [`WarpRow::RECT`], [`WarpRow::TRI`],
/// [`WarpRow::SPHERE`] or [`WarpRow::NONE`] (a skewed quad: area sampling).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[repr(C, align(64))]
pub struct WarpRow(pub [f32; 16]);

impl WarpRow {
    /// kind: not warped (a parallelogram that is not a rectangle)
    pub const NONE: f32 = 0.0;
    /// kind: rectangle (spherical rectangle)
    pub const RECT: f32 = 1.0;
    /// kind: triangle (spherical triangle)
    pub const TRI: f32 = 2.0;
    /// kind: sphere (cone of its visible cap)
    pub const SPHERE: f32 = 3.0;
}

impl Emitters {
    /// From the quad lights and the emissive triangles of a scene, in that order.
    pub fn new(quads: impl IntoIterator<Item = Emitter>, triangles: impl IntoIterator<Item = Emitter>) -> Self {
        let mut list: Vec<Emitter> = quads.into_iter().collect();
        let n_quads = list.len();
        list.extend(triangles);
        let any_sphere = list.iter().any(|e| e.sphere);
        let warp_rows: Vec<WarpRow> = list.iter().map(Emitter::warp_row).chain([WarpRow::default()]).collect();
        let place_lanes = LaneTable::new(&list.iter().map(place_row).collect::<Vec<_>>());
        let warp_lanes = LaneTable::new(&warp_rows.iter().map(|r| r.0.map(f32::to_bits)).collect::<Vec<_>>());
        Self { list, n_quads, any_sphere, warp_rows, place_lanes, warp_lanes }
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// No lights at all.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Number of emissive triangles.
    pub fn n_triangles(&self) -> usize {
        self.list.len() - self.n_quads
    }

    /// [`Emitters::place_into_x8`]'s sample, returned (for the tests).
    #[cfg(test)]
    pub(crate) fn place_x8(&self, idx: U8, inv_pmf: F8, u: F8, v: F8) -> LightSample8 {
        let mut ls = LightSample8::ZERO;
        self.place_into_x8(idx, inv_pmf, u, v, &mut ls);
        ls
    }

    /// The points `(u, v)` on lights `idx` (per lane), carrying `inv_pmf`, written into `out` (each
    /// branch's call writes it in place; a returned sample was copied out with `memcpy`).
    #[inline]
    pub(crate) fn place_into_x8(&self, idx: U8, inv_pmf: F8, u: F8, v: F8, out: &mut LightSample8) {
        let ids = idx.to_array();
        if ids.iter().all(|&i| i == ids[0]) {
            // One light on every lane (one light in the scene, or a coherent choice): its fields
            // splatted, the same values the per-lane gather below makes.
            *out = self.place_one_x8(ids[0], inv_pmf, u, v);
        } else {
            self.place_lanes_x8(idx, inv_pmf, u, v, out);
        }
    }

    /// [`Emitters::place_into_x8`], each lane's light gathered on its own.
    fn place_lanes_x8(&self, idx: U8, inv_pmf: F8, u: F8, v: F8, out: &mut LightSample8) {
        if let Some(t) = &self.place_lanes {
            let f = |k: usize| t.field(k, idx);
            let v3 = |k: usize| Vec3x8::new(f(k), f(k + 1), f(k + 2));
            let la = v3(0);
            let mut y = point_x8(la, v3(3), v3(6), f(17), u, v);
            let mut normal = v3(9);
            if self.any_sphere {
                let (ys, ns) = sphere_point_x8(la, f(16), u, v);
                let sph = f(18);
                y = Vec3x8::select(sph, ys, y);
                normal = Vec3x8::select(sph, ns, normal);
            }
            *out = LightSample8 { y, normal, radiance: v3(12), area: f(15), inv_pmf, light: idx, uv: (u, v) };
            return;
        }
        let es = idx.to_array().map(|i| &self.list[i as usize]);
        let la = Vec3x8::from_lanes(es.map(|e| e.a));
        let lab = Vec3x8::from_lanes(es.map(|e| e.ab));
        let lac = Vec3x8::from_lanes(es.map(|e| e.ac));
        let tri = crate::simd::mask_from_bools(es.map(|e| e.triangle));
        let mut y = point_x8(la, lab, lac, tri, u, v);
        let mut normal = Vec3x8::from_lanes(es.map(|e| e.normal));
        if self.any_sphere {
            let sph = crate::simd::mask_from_bools(es.map(|e| e.sphere));
            let (ys, ns) = sphere_point_x8(la, F8::new(es.map(|e| e.radius)), u, v);
            y = Vec3x8::select(sph, ys, y);
            normal = Vec3x8::select(sph, ns, normal);
        }
        *out = LightSample8 {
            y,
            normal,
            radiance: Vec3x8::from_lanes(es.map(|e| e.radiance)),
            area: F8::new(es.map(|e| e.area)),
            inv_pmf,
            light: idx,
            uv: (u, v),
        };
    }

    /// [`Emitters::place_into_x8`]'s sample with light `i` on every lane.
    #[inline]
    pub(crate) fn place_one_x8(&self, i: u32, inv_pmf: F8, u: F8, v: F8) -> LightSample8 {
        let e = &self.list[i as usize];
        if e.sphere {
            return LightSample8 { inv_pmf, light: U8::splat(i), ..e.sample_x8(u, v) };
        }
        let tri = crate::simd::mask_from_bools([e.triangle; 8]);
        LightSample8 {
            y: point_x8(Vec3x8::splat(e.a), Vec3x8::splat(e.ab), Vec3x8::splat(e.ac), tri, u, v),
            normal: Vec3x8::splat(e.normal),
            radiance: Vec3x8::splat(e.radiance),
            area: F8::splat(e.area),
            inv_pmf,
            light: U8::splat(i),
            uv: (u, v),
        }
    }
}

/// Points uniform in area on 8 spheres (centres `c`, radii `r`) for the unit-square samples
/// `(u, v)`, and their outward unit normals: `z = 1 - 2u`, azimuth `2 pi v`.
#[inline]
fn sphere_point_x8(c: Vec3x8, r: F8, u: F8, v: F8) -> (Vec3x8, Vec3x8) {
    let z = F8::splat(-2.0).mul_add(u, F8::ONE);
    let rho = (F8::ONE - z * z).max(F8::ZERO).sqrt();
    let (sin_p, cos_p) = (v * F8::splat(2.0 * std::f32::consts::PI)).sin_cos();
    let n = Vec3x8::new(rho * cos_p, rho * sin_p, z);
    (n.mul_add(r, c), n)
}

/// Points a + u ab + v ac of 8 lights (a, ab, ac per lane) for the unit-square samples (u, v),
/// folded onto the triangle where the lane's light is one (`tri`) and u + v > 1.
#[inline]
fn point_x8(a: Vec3x8, ab: Vec3x8, ac: Vec3x8, tri: Mask8, u: F8, v: F8) -> Vec3x8 {
    let fold = tri & (u + v).simd_gt(F8::ONE);
    let (u, v) = (fold.select(F8::ONE - u, u), fold.select(F8::ONE - v, v));
    ac.mul_add(v, ab.mul_add(u, a))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lights() -> Emitters {
        let q = Emitter::quad(Vec3::new(-1.0, 2.0, -1.0), Vec3::X * 2.0, Vec3::Z * 2.0, Vec3::splat(1.0));
        let t1 = Emitter::triangle([Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::new(3.0, 0.0, 0.0));
        let t2 = Emitter::triangle([Vec3::Z, Vec3::Z + Vec3::Y * 2.0, Vec3::Z + Vec3::X * 2.0], Vec3::splat(0.5));
        let dark = Emitter::triangle([Vec3::ZERO, Vec3::Y, Vec3::Z], Vec3::ZERO);
        let ball = Emitter::sphere(Vec3::new(0.5, 1.0, 3.0), 0.4, Vec3::new(2.0, 1.0, 0.5));
        Emitters::new([q, ball], [t1, t2, dark])
    }

    #[test]
    fn triangle_normal_follows_winding_and_quad_the_format() {
        let t = Emitter::triangle([Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::ONE);
        assert_eq!(t.normal, Vec3::Z);
        assert_eq!(t.area, 0.5);
        let q = Emitter::quad(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE);
        assert_eq!(q.normal, -Vec3::Z);
        assert_eq!(q.area, 1.0);
        // Irradiance vector of the corners points towards the light from its emitting side.
        for e in [t, q] {
            let x = e.a + 0.25 * (e.ab + e.ac) + e.normal;
            let phi = crate::light::polygonal::polygon_phi(x, &e.corners());
            assert!(phi.dot(-e.normal) > 0.1, "{phi}");
        }
    }

    #[test]
    fn placement_of_one_light_on_every_lane_matches_the_per_lane_gather() {
        let e = lights();
        let us = F8::new([0.0, 0.1, 0.62, 0.7, 0.8, 0.95, 0.999_999_94, 0.5]);
        let vs = F8::new([0.9, 0.3, 0.77, 0.05, 0.6, 0.99, 0.2, 0.5]);
        let inv = F8::new([1.0, 2.0, 3.0, 4.0, 0.5, 0.25, 8.0, 1.5]);
        let bits = |v: Vec3x8| [v.x, v.y, v.z].map(|c| c.to_array().map(f32::to_bits));
        for i in 0..e.list.len() as u32 {
            let mut lanes = LightSample8::ZERO;
            e.place_lanes_x8(U8::splat(i), inv, us, vs, &mut lanes);
            let one = e.place_x8(U8::splat(i), inv, us, vs);
            assert_eq!(bits(one.y), bits(lanes.y), "light {i}");
            assert_eq!(bits(one.normal), bits(lanes.normal));
            assert_eq!(bits(one.radiance), bits(lanes.radiance));
            assert_eq!(one.area.to_array().map(f32::to_bits), lanes.area.to_array().map(f32::to_bits));
            assert_eq!(one.inv_pmf.to_array().map(f32::to_bits), inv.to_array().map(f32::to_bits));
            assert_eq!(one.light.to_array(), [i; 8]);
        }
    }

    #[test]
    fn lane_table_and_per_lane_gather_place_the_same_points() {
        // The same five lights, then (in `many`) dark triangles enough to leave the lane table.
        let few = lights();
        let dark = Emitter::triangle([Vec3::ZERO, Vec3::Y, Vec3::Z], Vec3::ZERO);
        let many = Emitters::new(few.list[..2].to_vec(), few.list[2..].iter().copied().chain([dark; 6]));
        assert!(few.place_lanes.is_some() && few.warp_lanes.is_some());
        assert!(many.place_lanes.is_none() && many.warp_lanes.is_none());
        let us = F8::new([0.0, 0.1, 0.62, 0.7, 0.8, 0.95, 0.999_999_94, 0.5]);
        let vs = F8::new([0.9, 0.3, 0.77, 0.05, 0.6, 0.99, 0.2, 0.5]);
        let bits = |v: Vec3x8| [v.x, v.y, v.z].map(|c| c.to_array().map(f32::to_bits));
        for idx in [U8::new([4, 0, 3, 1, 2, 1, 0, 4]), U8::new([1, 1, 2, 3, 0, 0, 4, 2])] {
            let (mut a, mut b) = (LightSample8::ZERO, LightSample8::ZERO);
            few.place_lanes_x8(idx, F8::ONE, us, vs, &mut a);
            many.place_lanes_x8(idx, F8::ONE, us, vs, &mut b);
            assert_eq!(bits(a.y), bits(b.y));
            assert_eq!(bits(a.normal), bits(b.normal));
            assert_eq!(bits(a.radiance), bits(b.radiance));
            assert_eq!(a.area.to_array().map(f32::to_bits), b.area.to_array().map(f32::to_bits));
            // The solid-angle warp's rows of these lights, looked up both ways.
            let p = Vec3x8::splat(Vec3::new(0.3, 0.2, -1.0));
            for active in [crate::simd::mask_all(), crate::simd::mask_first(5)] {
                let (sa, wa) = few.solid_angle_x8(idx, p, active);
                let (sb, wb) = many.solid_angle_x8(idx, p, active);
                assert_eq!(sa.to_array().map(f32::to_bits), sb.to_array().map(f32::to_bits));
                assert_eq!(wa.to_bitmask(), wb.to_bitmask());
            }
        }
    }

    #[test]
    fn folded_triangle_samples_are_uniform() {
        // Chi-square of a 4x4 stratified grid of square samples folded onto a triangle, counted in
        // the 4 congruent sub-triangles (midpoint subdivision): equal areas, equal expected counts.
        let e = Emitters::new([], [Emitter::triangle([Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::ONE)]);
        let n = 200;
        let mut count = [0f64; 4];
        for i in 0..n {
            for j in 0..n {
                let y = e.list[0].point((i as f32 + 0.5) / n as f32, (j as f32 + 0.37) / n as f32);
                let (x, y) = (y.x, y.y);
                let k = if x > 0.5 {
                    1
                } else if y > 0.5 {
                    2
                } else if x + y < 0.5 {
                    0
                } else {
                    3
                };
                count[k] += 1.0;
            }
        }
        let expect = (n * n) as f64 / 4.0;
        let chi2: f64 = count.iter().map(|c| (c - expect).powi(2) / expect).sum();
        assert!(chi2 < 16.27, "chi2 {chi2} (3 dof, p = 0.001), counts {count:?}");
    }
}

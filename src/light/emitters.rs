//! Every area light of a scene in one list (quad lights first, in file order, then emissive
//! triangles from OBJ faces with `Ke`), and how a light is chosen and a point sampled on it.
//!
//! Geometry: an emitter is `a + u ab + v ac`, over the unit square for a quad light and over the
//! triangle `u, v >= 0, u + v <= 1` for an emissive triangle (a square sample is folded onto the
//! triangle: `(u, v) -> (1 - u, 1 - v)` when `u + v > 1`, which keeps it uniform). Emission is
//! one-sided, towards `normal`: `normalize(ac x ab)` for a quad light (the format's rule) and
//! `normalize(ab x ac) = normalize((v1 - v0) x (v2 - v0))` for a triangle (the side its winding
//! faces, counter-clockwise seen from the lit side, as OBJ meshes are written).
//!
//! Choice of a light ([`Selection`]): scenes whose only emitters are quad lights keep the format's
//! uniform choice (probability `1 / #lights`, computed exactly as before triangles existed). As soon
//! as a scene has an emissive triangle, lights are chosen in proportion to their power
//! `area * mean(max(radiance, 0))` by inverting a CDF: a pure function of the sample `u`, which is
//! also rescaled inside the chosen interval so the same number can place the point (used by `direct`).

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
}

impl Emitter {
    /// The quad light `a + u ab + v ac`, emitting towards `normalize(ac x ab)`.
    pub fn quad(a: Vec3, ab: Vec3, ac: Vec3, radiance: Vec3) -> Self {
        let cross = ab.cross(ac);
        Self { a, ab, ac, radiance, normal: (-cross).normalize_or_zero(), area: cross.length(), triangle: false }
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
        let (u, v) = if self.triangle && u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
        self.ac.mul_add(Vec3::splat(v), self.ab.mul_add(Vec3::splat(u), self.a))
    }

    /// Eight points of this light for unit-square samples `(u, v)` (uniform in area), as a light
    /// sample of this light alone (`inv_pmf` 1, index 0); bit-identical to the gathered
    /// [`Emitters::sample_x8`] of the same light.
    pub fn sample_x8(&self, u: F8, v: F8) -> LightSample8 {
        let fold = if self.triangle { (u + v).simd_gt(F8::ONE) } else { Mask8::splat(0.0) };
        let (u, v) = (fold.select(F8::ONE - u, u), fold.select(F8::ONE - v, v));
        let s = Vec3x8::splat;
        LightSample8 {
            y: s(self.ac).mul_add(v, s(self.ab).mul_add(u, s(self.a))),
            normal: s(self.normal),
            radiance: s(self.radiance),
            area: F8::splat(self.area),
            inv_pmf: F8::ONE,
            light: U8::splat(0),
        }
    }
}

/// How one of `n` items is chosen from a uniform number: uniformly, or by a discrete CDF.
#[derive(Clone, Debug, PartialEq)]
pub enum Selection {
    /// `floor(u n)`, probability `1/n`.
    Uniform(u32),
    /// Inverse of the normalized CDF (`cdf[i]` = sum of `pmf[..=i]`, last entry 1).
    Cdf {
        /// cumulative probabilities
        cdf: Vec<f32>,
        /// probability of each item
        pmf: Vec<f32>,
    },
}

impl Selection {
    /// Proportional to `weights` (negative or non-finite weights count as 0); uniform when they sum to 0.
    pub fn by_weight(weights: &[f32]) -> Self {
        let w: Vec<f64> = weights.iter().map(|&w| if w.is_finite() && w > 0.0 { w as f64 } else { 0.0 }).collect();
        let total: f64 = w.iter().sum();
        if total <= 0.0 {
            return Selection::Uniform(weights.len() as u32);
        }
        let mut acc = 0.0;
        let mut cdf: Vec<f32> = w
            .iter()
            .map(|&x| {
                acc += x;
                (acc / total) as f32
            })
            .collect();
        // The last non-empty interval ends exactly at 1 (and so do empty ones after it).
        let last = w.iter().rposition(|&x| x > 0.0).unwrap_or(0);
        cdf[last..].iter_mut().for_each(|c| *c = 1.0);
        let pmf = w.iter().map(|&x| (x / total) as f32).collect();
        Selection::Cdf { cdf, pmf }
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        match self {
            Selection::Uniform(n) => *n as usize,
            Selection::Cdf { pmf, .. } => pmf.len(),
        }
    }

    /// No items.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Probability of item `i` (0 outside the range).
    pub fn pmf(&self, i: u32) -> f32 {
        match self {
            Selection::Uniform(n) => {
                if i < *n {
                    1.0 / *n as f32
                } else {
                    0.0
                }
            }
            Selection::Cdf { pmf, .. } => pmf.get(i as usize).copied().unwrap_or(0.0),
        }
    }

    /// `1 / pmf(i)` as the estimators use it (`n` exactly for the uniform choice; infinite for
    /// probability 0, which is never chosen).
    pub fn inv_pmf(&self, i: u32) -> f32 {
        match self {
            Selection::Uniform(n) => *n as f32,
            Selection::Cdf { pmf, .. } => 1.0 / pmf.get(i as usize).copied().unwrap_or(0.0),
        }
    }

    /// Item chosen by `u` in [0, 1), `1 / pmf`, and `u` rescaled to [0, 1) inside the item's interval.
    pub fn pick(&self, u: f32) -> (u32, f32, f32) {
        match self {
            Selection::Uniform(n) => {
                let x = u * *n as f32;
                let i = (x as u32).min(n.saturating_sub(1));
                (i, *n as f32, (x - i as f32).clamp(0.0, ONE_MINUS))
            }
            Selection::Cdf { cdf, pmf } => {
                let i = cdf.partition_point(|&c| c <= u).min(cdf.len() - 1);
                let lo = if i == 0 { 0.0 } else { cdf[i - 1] };
                let p = pmf[i];
                (i as u32, 1.0 / p, ((u - lo) / p).clamp(0.0, ONE_MINUS))
            }
        }
    }

    /// Eight-lane twin of [`Selection::pick`]; inactive lanes give item 0, 1/pmf 1, u 0.
    pub fn pick_x8(&self, u: F8, active: Mask8) -> (U8, F8, F8) {
        if let Selection::Uniform(n) = self {
            // Exactly the arithmetic of the quad-light-only path tracer (bit-identical images).
            let x = u * F8::splat(*n as f32);
            let idx = x.to_array().map(|x| (x as u32).min(n.saturating_sub(1)));
            let r = (x - F8::new(idx.map(|i| i as f32))).max(F8::ZERO).min(F8::splat(ONE_MINUS));
            let inv = F8::splat(*n as f32);
            return (active_u(U8::new(idx), active), active.select(inv, F8::ONE), active.select(r, F8::ZERO));
        }
        let (us, on) = (u.to_array(), crate::simd::mask_to_bools(active));
        let mut idx = [0u32; 8];
        let mut inv = [1f32; 8];
        let mut r = [0f32; 8];
        for l in 0..8 {
            if on[l] {
                (idx[l], inv[l], r[l]) = self.pick(us[l]);
            }
        }
        (U8::new(idx), F8::new(inv), F8::new(r))
    }
}

/// Largest f32 below 1.
const ONE_MINUS: f32 = 1.0 - f32::EPSILON / 2.0;

fn active_u(v: U8, active: Mask8) -> U8 {
    let on = crate::simd::mask_to_bools(active);
    let a = v.to_array();
    U8::new(std::array::from_fn(|i| if on[i] { a[i] } else { 0 }))
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
    /// its area (the point's pdf is 1 / (area * inv_pmf) per unit area)
    pub area: F8,
    /// 1 / probability of having chosen it
    pub inv_pmf: F8,
    /// index into [`Emitters::list`]
    pub light: U8,
}

/// Scalar twin of [`LightSample8`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// the point, world space
    pub y: Vec3,
    /// unit emitting normal of the chosen light
    pub normal: Vec3,
    /// its radiance
    pub radiance: Vec3,
    /// its area
    pub area: f32,
    /// 1 / probability of having chosen it
    pub inv_pmf: f32,
    /// index into [`Emitters::list`]
    pub light: u32,
}

/// The scene's area lights with the two ways `direct` and `pathtracer` choose among them.
#[derive(Clone, Debug, PartialEq)]
pub struct Emitters {
    /// quad lights (indices `0..n_quads`), then emissive triangles
    pub list: Vec<Emitter>,
    /// number of quad lights at the front of `list`
    pub n_quads: usize,
    /// choice among all lights (path tracer NEE): uniform without triangles, else by power
    pub all: Selection,
    /// choice among the emissive triangles only, by power (`direct`'s triangle group)
    pub triangles: Selection,
}

impl Emitters {
    /// From the quad lights and the emissive triangles of a scene, in that order.
    pub fn new(quads: impl IntoIterator<Item = Emitter>, triangles: impl IntoIterator<Item = Emitter>) -> Self {
        let mut list: Vec<Emitter> = quads.into_iter().collect();
        let n_quads = list.len();
        list.extend(triangles);
        let powers: Vec<f32> = list.iter().map(Emitter::power).collect();
        let all =
            if list.len() == n_quads { Selection::Uniform(n_quads as u32) } else { Selection::by_weight(&powers) };
        let triangles = Selection::by_weight(&powers[n_quads..]);
        Self { list, n_quads, all, triangles }
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

    /// `1 / probability` that the path tracer's choice ([`Emitters::all`]) picks light `l`, per
    /// lane; 1 on inactive lanes.
    pub fn inv_pmf_x8(&self, l: U8, active: Mask8) -> F8 {
        if let Selection::Uniform(n) = self.all {
            return active.select(F8::splat(n as f32), F8::ONE);
        }
        let (ids, on) = (l.to_array(), crate::simd::mask_to_bools(active));
        F8::new(std::array::from_fn(|i| if on[i] { self.all.inv_pmf(ids[i]) } else { 1.0 }))
    }

    /// Path-tracer light sample: `u_choice` picks a light from [`Emitters::all`], `(u, v)` places
    /// the point. Needs at least one light; inactive lanes sample light 0 and stay finite.
    pub fn sample_x8(&self, u_choice: F8, u: F8, v: F8, active: Mask8) -> LightSample8 {
        if let [e] = self.list.as_slice() {
            // One light: nothing to choose (1/pmf = 1 either way) and nothing to gather.
            return e.sample_x8(u, v);
        }
        let (idx, inv_pmf, _) = self.all.pick_x8(u_choice, active);
        self.place_x8(idx, inv_pmf, u, v)
    }

    /// Scalar twin of [`Emitters::sample_x8`].
    pub fn sample(&self, u_choice: f32, u: f32, v: f32) -> LightSample {
        let (i, inv_pmf, _) = self.all.pick(u_choice);
        self.place(i, inv_pmf, u, v)
    }

    /// `direct`'s sample of the emissive-triangle group: `u` picks a triangle by power and, rescaled
    /// inside its interval, places the point together with `v`. Needs at least one triangle.
    pub fn sample_triangles_x8(&self, u: F8, v: F8, active: Mask8) -> LightSample8 {
        let (idx, inv_pmf, u2) = self.triangles.pick_x8(u, active);
        self.place_x8(idx + U8::splat(self.n_quads as u32), inv_pmf, u2, v)
    }

    /// Scalar twin of [`Emitters::sample_triangles_x8`].
    pub fn sample_triangles(&self, u: f32, v: f32) -> LightSample {
        let (i, inv_pmf, u2) = self.triangles.pick(u);
        self.place(i + self.n_quads as u32, inv_pmf, u2, v)
    }

    fn place(&self, i: u32, inv_pmf: f32, u: f32, v: f32) -> LightSample {
        let e = &self.list[i as usize];
        LightSample { y: e.point(u, v), normal: e.normal, radiance: e.radiance, area: e.area, inv_pmf, light: i }
    }

    pub(crate) fn place_x8(&self, idx: U8, inv_pmf: F8, u: F8, v: F8) -> LightSample8 {
        let ids = idx.to_array();
        if ids.iter().all(|&i| i == ids[0]) {
            // One light on every lane (one light in the scene, or a coherent choice): its fields
            // splatted, the same values the per-lane gather below makes.
            return self.place_one_x8(ids[0], inv_pmf, u, v);
        }
        self.place_lanes_x8(idx, inv_pmf, u, v)
    }

    /// [`Emitters::place_x8`], each lane's light gathered on its own.
    fn place_lanes_x8(&self, idx: U8, inv_pmf: F8, u: F8, v: F8) -> LightSample8 {
        let es = idx.to_array().map(|i| &self.list[i as usize]);
        let la = Vec3x8::from_lanes(es.map(|e| e.a));
        let lab = Vec3x8::from_lanes(es.map(|e| e.ab));
        let lac = Vec3x8::from_lanes(es.map(|e| e.ac));
        let tri = crate::simd::mask_from_bools(es.map(|e| e.triangle));
        LightSample8 {
            y: point_x8(la, lab, lac, tri, u, v),
            normal: Vec3x8::from_lanes(es.map(|e| e.normal)),
            radiance: Vec3x8::from_lanes(es.map(|e| e.radiance)),
            area: F8::new(es.map(|e| e.area)),
            inv_pmf,
            light: idx,
        }
    }

    /// [`Emitters::place_x8`] with light `i` on every lane.
    #[inline]
    pub(crate) fn place_one_x8(&self, i: u32, inv_pmf: F8, u: F8, v: F8) -> LightSample8 {
        let e = &self.list[i as usize];
        let tri = crate::simd::mask_from_bools([e.triangle; 8]);
        LightSample8 {
            y: point_x8(Vec3x8::splat(e.a), Vec3x8::splat(e.ab), Vec3x8::splat(e.ac), tri, u, v),
            normal: Vec3x8::splat(e.normal),
            radiance: Vec3x8::splat(e.radiance),
            area: F8::splat(e.area),
            inv_pmf,
            light: U8::splat(i),
        }
    }
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
    use crate::simd::{mask_all, mask_from_bools};

    fn lights() -> Emitters {
        let q = Emitter::quad(Vec3::new(-1.0, 2.0, -1.0), Vec3::X * 2.0, Vec3::Z * 2.0, Vec3::splat(1.0));
        let t1 = Emitter::triangle([Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::new(3.0, 0.0, 0.0));
        let t2 = Emitter::triangle([Vec3::Z, Vec3::Z + Vec3::Y * 2.0, Vec3::Z + Vec3::X * 2.0], Vec3::splat(0.5));
        let dark = Emitter::triangle([Vec3::ZERO, Vec3::Y, Vec3::Z], Vec3::ZERO);
        Emitters::new([q], [t1, t2, dark])
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
    fn power_selection_probabilities_and_uniform_without_triangles() {
        let e = lights();
        // Powers: quad 4 * 1, t1 0.5 * 1, t2 2 * 0.5, dark 0.
        let total = 4.0 + 0.5 + 1.0;
        let want = [4.0 / total, 0.5 / total, 1.0 / total, 0.0];
        for (i, w) in want.iter().enumerate() {
            assert!((e.all.pmf(i as u32) - w).abs() < 1e-6);
        }
        assert!((e.triangles.pmf(0) - 1.0 / 3.0).abs() < 1e-6 && (e.triangles.pmf(1) - 2.0 / 3.0).abs() < 1e-6);
        assert_eq!(e.triangles.pmf(2), 0.0);
        // Frequencies on a fine grid of u match the pmf; the dark triangle is never chosen.
        let n = 100_000;
        let mut count = [0usize; 4];
        for k in 0..n {
            let (i, inv, r) = e.all.pick((k as f32 + 0.5) / n as f32);
            assert!((inv * e.all.pmf(i) - 1.0).abs() < 1e-5 && (0.0..1.0).contains(&r));
            count[i as usize] += 1;
        }
        for i in 0..4 {
            assert!((count[i] as f32 / n as f32 - want[i]).abs() < 1e-4, "{count:?}");
        }
        let quads = Emitters::new([Emitter::quad(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE); 3], []);
        assert_eq!(quads.all, Selection::Uniform(3));
        assert_eq!(quads.all.pick(0.7).0, 2);
    }

    #[test]
    fn sample_x8_matches_scalar_per_lane_and_lies_on_the_light() {
        let e = lights();
        let us = [0.0, 0.1, 0.62, 0.7, 0.8, 0.95, 0.999, 0.5];
        let vs = [0.9, 0.3, 0.77, 0.05, 0.6, 0.99, 0.2, 0.5];
        let cs = [0.0, 0.2, 0.5, 0.65, 0.75, 0.85, 0.999_99, 0.33];
        let active = mask_from_bools([true, true, true, true, true, true, true, false]);
        let s8 = e.sample_x8(F8::new(cs), F8::new(us), F8::new(vs), active);
        let t8 = e.sample_triangles_x8(F8::new(us), F8::new(vs), mask_all());
        for i in 0..7 {
            let s = e.sample(cs[i], us[i], vs[i]);
            assert_eq!(s8.light.to_array()[i], s.light);
            assert!((s8.y.lane(i) - s.y).length() < 1e-6, "lane {i}");
            assert_eq!(s8.inv_pmf.to_array()[i], s.inv_pmf);
            assert_eq!(s8.area.to_array()[i], s.area);
            let t = e.sample_triangles(us[i], vs[i]);
            assert_eq!(t8.light.to_array()[i], t.light);
            assert!((t8.y.lane(i) - t.y).length() < 1e-6);
            // The point is on its light: in its plane and inside it.
            for p in [s, t] {
                let l = &e.list[p.light as usize];
                let d = p.y - l.a;
                assert!(d.dot(l.normal).abs() < 1e-5);
                let m = glam::Mat3::from_cols(l.ab, l.ac, l.normal).inverse() * d;
                let inside = if l.triangle { m.x + m.y <= 1.0 + 1e-5 } else { m.x <= 1.0 + 1e-5 && m.y <= 1.0 + 1e-5 };
                assert!(m.x >= -1e-5 && m.y >= -1e-5 && inside, "{m}");
            }
        }
        assert!(s8.y.is_finite().to_bitmask() == 0xff && s8.inv_pmf.to_array()[7] == 1.0);
    }

    #[test]
    fn one_light_fast_path_matches_the_general_placement_bit_for_bit() {
        let us = F8::new([0.0, 0.1, 0.62, 0.7, 0.8, 0.95, 0.999_999_94, 0.5]);
        let vs = F8::new([0.9, 0.3, 0.77, 0.05, 0.6, 0.99, 0.2, 0.5]);
        let cs = F8::new([0.0, 0.2, 0.5, 0.65, 0.75, 0.85, 0.999_99, 0.33]);
        let active = mask_from_bools([true, true, false, true, true, true, true, true]);
        let q = Emitter::quad(Vec3::new(-1.0, 2.0, -1.0), Vec3::X * 2.0, Vec3::Z * 2.0, Vec3::splat(4.0));
        let t = Emitter::triangle([Vec3::ZERO, Vec3::X, Vec3::Y], Vec3::new(3.0, 0.0, 0.0));
        for e in [Emitters::new([q], []), Emitters::new([], [t])] {
            let fast = e.sample_x8(cs, us, vs, active);
            let (idx, inv, _) = e.all.pick_x8(cs, active);
            let general = e.place_x8(idx, inv, us, vs);
            let bits = |v: Vec3x8| [v.x, v.y, v.z].map(|c| c.to_array().map(f32::to_bits));
            assert_eq!(bits(fast.y), bits(general.y));
            assert_eq!(bits(fast.normal), bits(general.normal));
            assert_eq!(bits(fast.radiance), bits(general.radiance));
            assert_eq!(fast.area.to_array(), general.area.to_array());
            assert_eq!(fast.inv_pmf.to_array(), general.inv_pmf.to_array());
            assert_eq!(fast.light.to_array(), general.light.to_array());
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
            let (one, lanes) = (e.place_x8(U8::splat(i), inv, us, vs), e.place_lanes_x8(U8::splat(i), inv, us, vs));
            assert_eq!(bits(one.y), bits(lanes.y), "light {i}");
            assert_eq!(bits(one.normal), bits(lanes.normal));
            assert_eq!(bits(one.radiance), bits(lanes.radiance));
            assert_eq!(one.area.to_array().map(f32::to_bits), lanes.area.to_array().map(f32::to_bits));
            assert_eq!(one.inv_pmf.to_array().map(f32::to_bits), inv.to_array().map(f32::to_bits));
            assert_eq!(one.light.to_array(), [i; 8]);
        }
    }

    #[test]
    fn uniform_choice_x8_matches_scalar_and_inv_pmf() {
        let quads: Vec<Emitter> =
            (0..3).map(|i| Emitter::quad(Vec3::X * i as f32, Vec3::X, Vec3::Z, Vec3::ONE)).collect();
        let e = Emitters::new(quads, []);
        let cs = [0.0, 0.1, 0.34, 0.5, 0.66, 0.67, 0.999_99, 0.2];
        let (u, v) = (F8::splat(0.3), F8::splat(0.6));
        let active = mask_from_bools([true, true, true, true, true, true, true, false]);
        let s8 = e.sample_x8(F8::new(cs), u, v, active);
        let inv8 = e.inv_pmf_x8(s8.light, active).to_array();
        for i in 0..7 {
            let s = e.sample(cs[i], 0.3, 0.6);
            assert_eq!((s8.light.to_array()[i], s8.inv_pmf.to_array()[i], inv8[i]), (s.light, 3.0, 3.0));
            assert_eq!(s.light, (cs[i] * 3.0) as u32);
            assert!((s8.y.lane(i) - s.y).length() < 1e-6);
        }
        for (ui, want) in [(0.2f32, 0.6f32), (0.5, 0.5), (0.9, 0.7)] {
            let (i, _, r) = e.all.pick(ui);
            let (i8, _, r8) = e.all.pick_x8(F8::splat(ui), mask_all());
            assert_eq!(i8.to_array()[0], i);
            assert!((r - want).abs() < 1e-5 && (r8.to_array()[0] - r).abs() < 1e-6, "{ui}: {r}");
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
                let s = e.sample_triangles((i as f32 + 0.5) / n as f32, (j as f32 + 0.37) / n as f32);
                let (x, y) = (s.y.x, s.y.y);
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

//! Eight-lane structure-of-arrays types over `wide`: `F8`, `U8`, `Mask8`, `Vec3x8`, `Frame8`.
//!
//! Conventions: a `Mask8` is an `F8` whose lanes are all-ones (active) or all-zeros (inactive), as
//! produced by `simd_lt` and friends. Functions that take a mask take it last and leave inactive lanes
//! finite (usually zero). Every vector function here has a scalar twin in `glam::Vec3`, and the tests
//! check that they agree per lane.

use glam::Vec3;
pub use wide::{f32x8, i32x8, u32x8};

pub mod math;

/// Eight f32 lanes.
pub type F8 = f32x8;
/// Eight u32 lanes.
pub type U8 = u32x8;
/// Eight lane mask: all bits set = active, all clear = inactive (same type as `F8`).
pub type Mask8 = f32x8;

/// Number of lanes in a packet.
pub const LANES: usize = 8;

/// Mask with every lane active.
#[inline]
pub fn mask_all() -> Mask8 {
    F8::ZERO.simd_eq(F8::ZERO)
}

/// Mask with the first `n` lanes active (n <= 8).
#[inline]
pub fn mask_first(n: usize) -> Mask8 {
    let mut a = [0.0f32; 8];
    for (i, v) in a.iter_mut().enumerate() {
        *v = if i < n { f32::from_bits(u32::MAX) } else { 0.0 };
    }
    F8::new(a)
}

/// Mask from per-lane booleans.
#[inline]
pub fn mask_from_bools(b: [bool; 8]) -> Mask8 {
    F8::new(b.map(|x| if x { f32::from_bits(u32::MAX) } else { 0.0 }))
}

/// Per-lane booleans of a mask.
#[inline]
pub fn mask_to_bools(m: Mask8) -> [bool; 8] {
    let bits = m.to_bitmask();
    std::array::from_fn(|i| bits & (1 << i) != 0)
}

/// Embree's valid array for a mask: -1 for active lanes, 0 for inactive (each lane's sign bit,
/// which `to_bitmask` reads, spread over the lane by an arithmetic shift: no per-lane loop).
#[inline]
pub fn mask_to_valid(m: Mask8) -> [i32; 8] {
    (wide::bytemuck::cast::<Mask8, i32x8>(m) >> 31u32).to_array()
}

/// Lanes of `v` where `m` is set, `0.0` elsewhere.
#[inline]
pub fn and_mask(v: F8, m: Mask8) -> F8 {
    m.select(v, F8::ZERO)
}

/// Converts u32 lanes to f32 (exact below 2^24).
#[inline]
pub fn u8_to_f8(v: U8) -> F8 {
    let a = v.to_array();
    F8::new(a.map(|x| x as f32))
}

/// Lane `idx[j] % 8` of `v` in lane j: an 8-entry table look-up per lane (AVX2: one `vpermd`).
#[cfg(target_feature = "avx2")]
#[inline]
pub fn permute_lanes(v: U8, idx: U8) -> U8 {
    use wide::bytemuck::cast;
    cast(safe_arch::shuffle_av_i32_all_m256i(cast(v), cast(idx)))
}

/// Lane `idx[j] % 8` of `v` in lane j (portable form).
#[cfg(not(target_feature = "avx2"))]
#[inline]
pub fn permute_lanes(v: U8, idx: U8) -> U8 {
    let (a, i) = (v.to_array(), idx.to_array());
    U8::new(std::array::from_fn(|j| a[i[j] as usize & 7]))
}

/// Three coordinates of eight vectors, structure of arrays.
#[derive(Clone, Copy, Debug, Default)]
pub struct Vec3x8 {
    /// x lanes
    pub x: F8,
    /// y lanes
    pub y: F8,
    /// z lanes
    pub z: F8,
}

impl Vec3x8 {
    /// All-zero vectors.
    pub const ZERO: Self = Self { x: F8::ZERO, y: F8::ZERO, z: F8::ZERO };

    /// From three lane vectors.
    #[inline]
    pub fn new(x: F8, y: F8, z: F8) -> Self {
        Self { x, y, z }
    }
    /// The same vector in every lane.
    #[inline]
    pub fn splat(v: Vec3) -> Self {
        Self { x: F8::splat(v.x), y: F8::splat(v.y), z: F8::splat(v.z) }
    }
    /// Gathers eight scalar vectors into lanes.
    #[inline]
    pub fn from_lanes(v: [Vec3; 8]) -> Self {
        Self { x: F8::new(v.map(|p| p.x)), y: F8::new(v.map(|p| p.y)), z: F8::new(v.map(|p| p.z)) }
    }
    /// Lane `i` as a scalar vector.
    #[inline]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.as_array()[i], self.y.as_array()[i], self.z.as_array()[i])
    }
    /// Scatters lanes into scalar vectors.
    #[inline]
    pub fn to_lanes(&self) -> [Vec3; 8] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        std::array::from_fn(|i| Vec3::new(x[i], y[i], z[i]))
    }
    /// Per-lane dot product.
    #[inline]
    pub fn dot(self, o: Self) -> F8 {
        self.x.mul_add(o.x, self.y.mul_add(o.y, self.z * o.z))
    }
    /// Per-lane cross product.
    #[inline]
    pub fn cross(self, o: Self) -> Self {
        Self { x: self.y * o.z - self.z * o.y, y: self.z * o.x - self.x * o.z, z: self.x * o.y - self.y * o.x }
    }
    /// Per-lane squared length.
    #[inline]
    pub fn length_squared(self) -> F8 {
        self.dot(self)
    }
    /// Per-lane length.
    #[inline]
    pub fn length(self) -> F8 {
        self.length_squared().sqrt()
    }
    /// Per-lane normalization; zero-length lanes stay zero (never NaN).
    #[inline]
    pub fn normalize_or_zero(self) -> Self {
        let l2 = self.length_squared();
        let ok = l2.simd_gt(F8::splat(f32::MIN_POSITIVE));
        let inv = ok.select(F8::ONE / l2.sqrt(), F8::ZERO);
        self * inv
    }
    /// Per-lane scale by a lane vector.
    #[inline]
    pub fn scale(self, s: F8) -> Self {
        Self { x: self.x * s, y: self.y * s, z: self.z * s }
    }
    /// `self * s + o`, per lane.
    #[inline]
    pub fn mul_add(self, s: F8, o: Self) -> Self {
        Self { x: self.x.mul_add(s, o.x), y: self.y.mul_add(s, o.y), z: self.z.mul_add(s, o.z) }
    }
    /// Lanes of `self` where `m` is set, `other` elsewhere.
    #[inline]
    pub fn select(m: Mask8, a: Self, b: Self) -> Self {
        Self { x: m.select(a.x, b.x), y: m.select(a.y, b.y), z: m.select(a.z, b.z) }
    }
    /// Component-wise product.
    #[inline]
    pub fn mul_elem(self, o: Self) -> Self {
        Self { x: self.x * o.x, y: self.y * o.y, z: self.z * o.z }
    }
    /// Largest component, per lane.
    #[inline]
    pub fn max_elem(self) -> F8 {
        self.x.max(self.y).max(self.z)
    }
    /// Mask of lanes whose three components are all finite.
    #[inline]
    pub fn is_finite(self) -> Mask8 {
        self.x.is_finite() & self.y.is_finite() & self.z.is_finite()
    }
}

impl std::ops::Add for Vec3x8 {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}
impl std::ops::Sub for Vec3x8 {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}
impl std::ops::Neg for Vec3x8 {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self { x: -self.x, y: -self.y, z: -self.z }
    }
}
impl std::ops::Mul<F8> for Vec3x8 {
    type Output = Self;
    #[inline]
    fn mul(self, s: F8) -> Self {
        self.scale(s)
    }
}
impl std::ops::AddAssign for Vec3x8 {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

/// Per-lane orthonormal frame (tangent `s`, bitangent `t`, normal `n`), built without branches from a
/// unit normal (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
#[derive(Clone, Copy, Debug)]
pub struct Frame8 {
    /// tangent
    pub s: Vec3x8,
    /// bitangent
    pub t: Vec3x8,
    /// normal
    pub n: Vec3x8,
}

impl Frame8 {
    /// Frame around unit normals `n`.
    #[inline]
    pub fn from_normal(n: Vec3x8) -> Self {
        // copysign(1, n.z) without a branch: take the sign bit of n.z onto 1.0.
        let sign_bit = n.z.to_bits() & U8::splat(0x8000_0000);
        let sign = F8::from_bits(F8::ONE.to_bits() | sign_bit);
        let a = -F8::ONE / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3x8::new(F8::ONE + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3x8::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }
    /// Frame around unit normals `n` with its tangent along `tangent` made orthogonal to `n`
    /// (Gram-Schmidt, as Mitsuba builds its shading frame from dp/du), `t = n x s`; lanes whose
    /// tangent is zero or along `n` get [`Frame8::from_normal`]'s.
    #[inline]
    pub fn from_normal_tangent(n: Vec3x8, tangent: Vec3x8) -> Self {
        let d = Self::from_normal(n);
        let s = tangent - n.scale(n.dot(tangent));
        let l2 = s.dot(s);
        let ok = l2.simd_gt(F8::splat(1e-20)) & l2.is_finite();
        let s = s.scale(F8::ONE / ok.select(l2, F8::ONE).sqrt());
        let t = n.cross(s);
        Self { s: Vec3x8::select(ok, s, d.s), t: Vec3x8::select(ok, t, d.t), n }
    }
    /// Local (s, t, n) coordinates to world, per lane.
    #[inline]
    pub fn to_world(&self, l: Vec3x8) -> Vec3x8 {
        self.s.scale(l.x) + self.t.scale(l.y) + self.n.scale(l.z)
    }
    /// World to local (s, t, n) coordinates, per lane.
    #[inline]
    pub fn to_local(&self, w: Vec3x8) -> Vec3x8 {
        Vec3x8::new(w.dot(self.s), w.dot(self.t), w.dot(self.n))
    }
}

/// Scalar twin of [`Frame8::from_normal`]: (s, t) for a unit normal `n`.
pub fn frame_from_normal(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lanes() -> [Vec3; 8] {
        [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.3, -0.4, 0.866).normalize(),
            Vec3::new(-0.7, 0.1, -0.2).normalize(),
            Vec3::new(0.0, 1.0, -1e-8).normalize(),
            Vec3::new(1e-7, -1.0, 0.0).normalize(),
            Vec3::new(-0.577, 0.577, 0.577).normalize(),
        ]
    }

    #[test]
    fn frame_x8_matches_scalar_and_is_orthonormal() {
        let ns = lanes();
        let f = Frame8::from_normal(Vec3x8::from_lanes(ns));
        for (i, n) in ns.iter().enumerate() {
            let (s, t) = frame_from_normal(*n);
            assert!((f.s.lane(i) - s).abs().max_element() < 1e-6, "lane {i}");
            assert!((f.t.lane(i) - t).abs().max_element() < 1e-6, "lane {i}");
            assert!((s.length() - 1.0).abs() < 1e-5 && (t.length() - 1.0).abs() < 1e-5);
            assert!(s.dot(t).abs() < 1e-5 && s.dot(*n).abs() < 1e-5 && t.dot(*n).abs() < 1e-5);
            assert!((s.cross(t) - *n).length() < 1e-5, "right-handed, lane {i}");
        }
    }

    #[test]
    fn vec_ops_match_scalar_per_lane() {
        let a = lanes();
        let b: [Vec3; 8] = std::array::from_fn(|i| Vec3::new(i as f32, 2.0 - i as f32, 0.5 * i as f32));
        let (va, vb) = (Vec3x8::from_lanes(a), Vec3x8::from_lanes(b));
        let d = va.dot(vb).to_array();
        let c = va.cross(vb);
        let n = vb.normalize_or_zero();
        for i in 0..8 {
            assert!((d[i] - a[i].dot(b[i])).abs() < 1e-5);
            assert!((c.lane(i) - a[i].cross(b[i])).length() < 1e-5);
            assert!((n.lane(i) - b[i].normalize_or_zero()).length() < 1e-6);
        }
        assert_eq!(Vec3x8::ZERO.normalize_or_zero().lane(3), Vec3::ZERO);
    }

    #[test]
    fn permute_lanes_looks_up_every_lane() {
        let v = U8::new([10, 11, 12, 13, 14, 15, 16, 0xffff_ffff]);
        for r in 0..8u32 {
            let idx = U8::new(std::array::from_fn(|j| (j as u32 * 5 + r) % 8 + if j == 3 { 8 * r } else { 0 }));
            let want: [u32; 8] = std::array::from_fn(|j| v.to_array()[idx.to_array()[j] as usize % 8]);
            assert_eq!(permute_lanes(v, idx).to_array(), want);
        }
    }

    #[test]
    fn masks_round_trip_and_map_to_embree_valid() {
        let b = [true, false, true, true, false, false, true, false];
        let m = mask_from_bools(b);
        assert_eq!(mask_to_bools(m), b);
        assert_eq!(mask_to_valid(m), [-1, 0, -1, -1, 0, 0, -1, 0]);
        // Any lane bits: the sign bit decides, as for `to_bitmask`.
        let odd = F8::new([-0.0, 1.5, -2.0, 0.0, f32::NAN, -f32::NAN, f32::from_bits(0x8000_0001), f32::MIN_POSITIVE]);
        let bits = odd.to_bitmask();
        assert_eq!(mask_to_valid(odd), std::array::from_fn(|i| if bits & (1 << i) != 0 { -1 } else { 0 }));
        assert_eq!(mask_to_bools(mask_first(3)), [true, true, true, false, false, false, false, false]);
        assert!(mask_all().all());
    }
}

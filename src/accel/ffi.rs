//! The packet structs in Embree 4.4's layout (checked at compile time), the query arguments, and the
//! finiteness test every query applies first.

use super::INVALID_ID;
use crate::simd::{Mask8, Vec3x8, F8};
use embree4_sys as sys;
use std::ffi::c_void;

/// A packet of 8 rays, Embree 4.4 `RTCRay8` layout (384 bytes, 32-byte aligned).
#[repr(C, align(32))]
#[derive(Clone, Copy, Debug)]
pub struct Ray8 {
    /// origin x, world space
    pub org_x: [f32; 8],
    /// origin y
    pub org_y: [f32; 8],
    /// origin z
    pub org_z: [f32; 8],
    /// start of the ray interval (distance in units of |dir|)
    pub tnear: [f32; 8],
    /// direction x (need not be unit; t is in units of |dir|)
    pub dir_x: [f32; 8],
    /// direction y
    pub dir_y: [f32; 8],
    /// direction z
    pub dir_z: [f32; 8],
    /// motion-blur time (unused, 0)
    pub time: [f32; 8],
    /// end of the interval; on return the hit distance (intersect) or -inf if occluded (occluded)
    pub tfar: [f32; 8],
    /// ray mask, always u32::MAX
    pub mask: [u32; 8],
    /// ray id (unused)
    pub id: [u32; 8],
    /// ray flags (unused, 0)
    pub flags: [u32; 8],
}

/// Hit record of 8 rays, Embree 4.4 `RTCHit8` layout with one instance level (288 bytes).
#[repr(C, align(32))]
#[derive(Clone, Copy, Debug)]
pub struct Hit8 {
    /// unnormalized geometric normal x (object space of the hit geometry)
    pub ng_x: [f32; 8],
    /// normal y
    pub ng_y: [f32; 8],
    /// normal z
    pub ng_z: [f32; 8],
    /// barycentric u
    pub u: [f32; 8],
    /// barycentric v
    pub v: [f32; 8],
    /// primitive id within the geometry
    pub prim_id: [u32; 8],
    /// geometry id (within the instanced scene for instance hits)
    pub geom_id: [u32; 8],
    /// instance geometry id in the top scene, or INVALID_ID
    pub inst_id: [[u32; 8]; 1],
    /// instance-array primitive id (Embree 4.4 field; the reason these structs exist)
    pub inst_prim_id: [[u32; 8]; 1],
}

/// Ray and hit of 8 rays, Embree 4.4 `RTCRayHit8` layout (672 bytes).
#[repr(C, align(32))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RayHit8 {
    /// rays
    pub ray: Ray8,
    /// hits
    pub hit: Hit8,
}

/// Embree 4.4 `RTCRayQueryContext` with one instance level (8 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RayQueryContext {
    /// instance id stack
    pub inst_id: [u32; 1],
    /// instance primitive id stack
    pub inst_prim_id: [u32; 1],
}

/// The valid-lane array of an 8-wide query: Embree loads it with an aligned 32-byte AVX load, so it
/// must be 32-byte aligned (an unaligned `[i32; 8]` on the stack segfaults inside Embree).
#[repr(C, align(32))]
pub(super) struct Valid8(pub(super) [i32; 8]);

/// `RTCIntersectArguments` / `RTCOccludedArguments` (identical layout), with room for the optional
/// `minWidthDistanceFactor` of builds that enable it.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub(super) struct QueryArgs {
    flags: u32,
    feature_mask: u32,
    context: *mut RayQueryContext,
    filter: *const c_void,
    callback: *const c_void,
    min_width_distance_factor: f32,
}

/// Words of a ray (origin, tnear, direction, time, tfar, mask, id, flags) and of a hit (normal,
/// u, v, primitive, geometry, instance, instance primitive) in Embree 4.4's structs.
pub const RAY_WORDS: usize = 12;
/// Words of an Embree 4.4 hit with one instance level.
pub const HIT_WORDS: usize = 9;

/// 16 rays and hits, Embree 4.4 `RTCRayHit16` layout (1344 bytes, 64-byte aligned): word `k` of
/// lane `j` at `16 k + j`, the 12 ray words, then the 9 hit words. Only `strata rays`' replay at
/// Embree's other packet width uses it (rendering traces 8 wide).
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug)]
pub struct RayHit16(pub [u32; 16 * (RAY_WORDS + HIT_WORDS)]);

/// One ray and hit, Embree 4.4 `RTCRayHit` layout (96 bytes, 16-byte aligned: the 12 ray words,
/// the 9 hit words, 3 words of padding), for `strata rays`' one-by-one replay.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug)]
pub struct RayHit1(pub [u32; 24]);

/// The valid-lane array of a 16-wide query (64-byte aligned for Embree's aligned loads).
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug)]
pub struct Valid16(pub [i32; 16]);

impl RayHit16 {
    /// Up to 16 rays' words (see [`RAY_WORDS`]) in lanes `0..rays.len()`, hits unset (invalid
    /// ids), and the valid array of those lanes.
    pub fn new(rays: &[[u32; RAY_WORDS]]) -> (Self, Valid16) {
        assert!(rays.len() <= 16, "a 16-wide block holds at most 16 rays");
        let mut b = Self([0; 16 * (RAY_WORDS + HIT_WORDS)]);
        let mut valid = Valid16([0; 16]);
        for (j, r) in rays.iter().enumerate() {
            for (k, w) in r.iter().enumerate() {
                b.0[16 * k + j] = *w;
            }
            valid.0[j] = -1;
        }
        for k in RAY_WORDS + 5..RAY_WORDS + HIT_WORDS {
            b.0[16 * k..16 * (k + 1)].fill(INVALID_ID);
        }
        (b, valid)
    }

    /// Lane `j`'s `tfar` (the hit distance after an intersect, -inf if occluded).
    pub fn tfar(&self, j: usize) -> f32 {
        f32::from_bits(self.0[16 * 8 + j])
    }
}

impl RayHit1 {
    /// One ray's words, hit unset (invalid ids).
    pub fn new(ray: &[u32; RAY_WORDS]) -> Self {
        let mut b = Self([0; 24]);
        b.0[..RAY_WORDS].copy_from_slice(ray);
        b.0[RAY_WORDS + 5..RAY_WORDS + HIT_WORDS].fill(INVALID_ID);
        b
    }

    /// The ray's `tfar` (the hit distance after an intersect, -inf if occluded).
    pub fn tfar(&self) -> f32 {
        f32::from_bits(self.0[8])
    }
}

impl Ray8 {
    /// Lane `j`'s words in Embree's order (see [`RAY_WORDS`]).
    pub fn lane_words(&self, j: usize) -> [u32; RAY_WORDS] {
        [
            self.org_x[j].to_bits(),
            self.org_y[j].to_bits(),
            self.org_z[j].to_bits(),
            self.tnear[j].to_bits(),
            self.dir_x[j].to_bits(),
            self.dir_y[j].to_bits(),
            self.dir_z[j].to_bits(),
            self.time[j].to_bits(),
            self.tfar[j].to_bits(),
            self.mask[j],
            self.id[j],
            self.flags[j],
        ]
    }
}

const _: () = assert!(std::mem::size_of::<RayHit16>() == 1344 && std::mem::align_of::<RayHit16>() == 64);
const _: () = assert!(std::mem::size_of::<RayHit1>() == 96 && std::mem::align_of::<RayHit1>() == 16);
const _: () = assert!(std::mem::size_of::<Valid16>() == 64 && std::mem::align_of::<Valid16>() == 64);
const _: () = assert!(std::mem::size_of::<sys::RTCRayHit16>() <= std::mem::size_of::<RayHit16>());
const _: () = assert!(std::mem::size_of::<sys::RTCRayHit>() <= std::mem::size_of::<RayHit1>());
const _: () = assert!(std::mem::size_of::<Ray8>() == 384);
const _: () = assert!(std::mem::size_of::<Hit8>() == 288);
const _: () = assert!(std::mem::size_of::<RayHit8>() == 672);
const _: () = assert!(std::mem::align_of::<RayHit8>() == 32);
const _: () = assert!(std::mem::size_of::<RayQueryContext>() == 8);
const _: () = assert!(std::mem::align_of::<Valid8>() == 32 && std::mem::align_of::<Ray8>() == 32);
// The crate's args structs are a prefix of ours; we pass a pointer to ours.
const _: () = assert!(std::mem::size_of::<sys::RTCIntersectArguments>() <= std::mem::size_of::<QueryArgs>());
const _: () = assert!(std::mem::size_of::<sys::RTCOccludedArguments>() <= std::mem::size_of::<QueryArgs>());

impl Default for Ray8 {
    fn default() -> Self {
        Self {
            org_x: [0.0; 8],
            org_y: [0.0; 8],
            org_z: [0.0; 8],
            tnear: [0.0; 8],
            dir_x: [0.0; 8],
            dir_y: [0.0; 8],
            dir_z: [1.0; 8],
            time: [0.0; 8],
            tfar: [0.0; 8],
            mask: [u32::MAX; 8],
            id: [0; 8],
            flags: [0; 8],
        }
    }
}

impl Default for Hit8 {
    fn default() -> Self {
        Self {
            ng_x: [0.0; 8],
            ng_y: [0.0; 8],
            ng_z: [0.0; 8],
            u: [0.0; 8],
            v: [0.0; 8],
            prim_id: [INVALID_ID; 8],
            geom_id: [INVALID_ID; 8],
            inst_id: [[INVALID_ID; 8]],
            inst_prim_id: [[INVALID_ID; 8]],
        }
    }
}

impl Ray8 {
    /// The packet's origins, world space (zero in lanes that were inactive when it was set).
    #[inline]
    pub fn org(&self) -> Vec3x8 {
        Vec3x8::new(F8::new(self.org_x), F8::new(self.org_y), F8::new(self.org_z))
    }

    /// The packet's directions as set, world space (zero in lanes that were inactive).
    #[inline]
    pub fn dir(&self) -> Vec3x8 {
        Vec3x8::new(F8::new(self.dir_x), F8::new(self.dir_y), F8::new(self.dir_z))
    }

    /// Fills the packet from SoA origins/directions and the interval [tnear, tfar]; returns the
    /// lanes that are `active` and finite (NaN must never reach Embree). Inactive lanes get a
    /// harmless ray. Resets mask, id, flags.
    #[inline]
    pub fn set(&mut self, org: Vec3x8, dir: Vec3x8, tnear: F8, tfar: F8, active: Mask8) -> Mask8 {
        // Field by field in place (a whole new packet and a 384-byte copy cost more than the
        // stores; `new` fills a default packet through here, and the default's stores fold away).
        let ok = active & org.is_finite() & dir.is_finite() & tnear.is_finite() & !tfar.is_nan();
        let z = F8::ZERO;
        self.org_x = ok.select(org.x, z).to_array();
        self.org_y = ok.select(org.y, z).to_array();
        self.org_z = ok.select(org.z, z).to_array();
        self.tnear = ok.select(tnear, z).to_array();
        self.dir_x = ok.select(dir.x, z).to_array();
        self.dir_y = ok.select(dir.y, z).to_array();
        self.dir_z = ok.select(dir.z, F8::ONE).to_array();
        self.time = [0.0; 8];
        self.tfar = ok.select(tfar, z).to_array();
        self.mask = [u32::MAX; 8];
        self.id = [0; 8];
        self.flags = [0; 8];
        ok
    }

    /// A packet from SoA origins/directions and the interval [tnear, tfar], as [`Ray8::set`]:
    /// also returns the lanes that are `active` and finite.
    #[inline]
    pub fn new(org: Vec3x8, dir: Vec3x8, tnear: F8, tfar: F8, active: Mask8) -> (Self, Mask8) {
        let mut ray = Self::default();
        let ok = ray.set(org, dir, tnear, tfar, active);
        (ray, ok)
    }
}

/// The query arguments of one 8-wide call: coherent or incoherent rays, no filters.
pub(super) fn query_args(coherent: bool, ctx: &mut RayQueryContext) -> QueryArgs {
    QueryArgs {
        flags: if coherent { sys::RTCRayQueryFlags::COHERENT.0 } else { sys::RTCRayQueryFlags::INCOHERENT.0 },
        feature_mask: u32::MAX,
        context: ctx,
        filter: std::ptr::null(),
        callback: std::ptr::null(),
        min_width_distance_factor: 0.0,
    }
}

/// Lanes whose origin, direction and `tnear` are finite and `tfar` is not NaN.
#[inline]
pub(super) fn finite_ray(r: &Ray8) -> Mask8 {
    let f = |a: &[f32; 8]| F8::new(*a).is_finite();
    f(&r.org_x)
        & f(&r.org_y)
        & f(&r.org_z)
        & f(&r.dir_x)
        & f(&r.dir_y)
        & f(&r.dir_z)
        & f(&r.tnear)
        & !F8::new(r.tfar).is_nan()
}

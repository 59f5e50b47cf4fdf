//! The ellipsoid user geometry's Embree callbacks (bounds, intersect, occluded) over the
//! [`Ellipsoid`]s of `accel/ellipsoid.rs` (the shape, its f64 hit and its f32 packet intersector).

use super::ellipsoid::Ellipsoid;
use super::ffi::RayQueryContext;
use crate::simd::{Mask8, Vec3x8, F8, U8};
use embree4_sys as sys;
use std::cell::Cell;
use std::ffi::c_void;
use std::sync::atomic::{AtomicBool, Ordering};

/// Whether the callbacks time themselves (set by the phase profiler, `crate::profile`).
static CALLBACK_TIMING: AtomicBool = AtomicBool::new(false);

thread_local! {
    /// Time-stamp ticks this thread spent in intersect/occluded callbacks since the last take.
    static CALLBACK_TICKS: Cell<u64> = const { Cell::new(0) };
}

/// Turns the callbacks' self-timing on or off for every thread (the profiler's switch).
pub fn set_callback_timing(on: bool) {
    CALLBACK_TIMING.store(on, Ordering::SeqCst);
}

/// Returns and clears the ticks ([`super::timestamp`]) this thread spent in sphere/ellipsoid
/// intersect and occluded callbacks since the last call (0 unless timing is on). The profiler
/// moves them out of the Embree phase the callbacks ran in.
#[inline]
pub fn take_callback_ticks() -> u64 {
    CALLBACK_TICKS.with(|c| c.replace(0))
}

/// Runs one callback invocation (a packet of up to N rays against one primitive), adding its
/// ticks to this thread's count when timing is on.
#[inline]
fn timed(f: impl FnOnce()) {
    if !CALLBACK_TIMING.load(Ordering::Relaxed) {
        return f();
    }
    let t0 = super::timestamp();
    f();
    let dt = super::timestamp().wrapping_sub(t0);
    CALLBACK_TICKS.with(|c| c.set(c.get() + dt));
}

pub(super) unsafe extern "C" fn ellipsoid_bounds(args: *const sys::RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes valid arguments; the user pointer is the Vec<Ellipsoid> set in
    // add_ellipsoids (never empty) and primID < the primitive count we declared (its length, one more
    // with the sentinel).
    unsafe {
        let a = &*args;
        let prims = &*(a.geometryUserPtr as *const Vec<Ellipsoid>);
        let (lower, upper) = match prims.get(a.primID as usize) {
            Some(e) => (e.lower, e.upper),
            None => {
                let p = sentinel_point(&prims[0]);
                (p, p)
            }
        };
        let b = &mut *a.bounds_o;
        (b.lower_x, b.lower_y, b.lower_z) = (lower[0], lower[1], lower[2]);
        (b.upper_x, b.upper_y, b.upper_z) = (upper[0], upper[1], upper[2]);
    }
}

/// Where the sentinel primitive of a lone ellipsoid sits (`SceneBuilder::add_ellipsoids`): a
/// point box outside the ellipsoid's box, below its lower corner by the box's size plus one.
/// Its callbacks answer no hit, so where it sits changes no image; a point that is not finite
/// makes Embree drop the sentinel, which only costs the box test it buys.
fn sentinel_point(e: &Ellipsoid) -> [f32; 3] {
    std::array::from_fn(|i| e.lower[i] - (e.upper[i] - e.lower[i]) - 1.0)
}

/// Float at 4-byte word `field * n + lane` of an Embree SoA ray/hit block of width `n`.
#[inline]
unsafe fn soa(base: *mut u32, n: usize, field: usize, lane: usize) -> *mut u32 {
    // SAFETY: the caller guarantees base points to an RTCRayHitN/RTCRayN of width n with at least
    // `field + 1` fields.
    unsafe { base.add(field * n + lane) }
}

/// The ellipsoid `prim` of the Vec<Ellipsoid> behind `user`; None for the sentinel primitive
/// (`prim` = its length; see `SceneBuilder::add_ellipsoids`), which no ray hits.
///
/// # Safety
/// `user` must be the Vec<Ellipsoid> set in add_ellipsoids.
#[inline]
unsafe fn ellipsoid<'a>(user: *mut c_void, prim: u32) -> Option<&'a Ellipsoid> {
    #[cfg(test)]
    CALLBACK_CALLS.with(|c| c.set(c.get() + 1));
    // SAFETY: guaranteed by the caller; the Vec lives as long as the scene that calls us.
    unsafe { (&*(user as *const Vec<Ellipsoid>)).get(prim as usize) }
}

#[cfg(test)]
thread_local! {
    /// Intersect and occluded callback invocations on this thread (tests count them).
    pub(super) static CALLBACK_CALLS: Cell<u64> = const { Cell::new(0) };
}

/// Field `field` (8 lanes) of an Embree SoA ray/hit block of width 8.
///
/// # Safety
/// `base` must point to an RTCRayHit8/RTCRay8 with more than `field` fields.
#[inline]
unsafe fn row8(base: *mut u32, field: usize) -> *mut [f32; 8] {
    // SAFETY: guaranteed by the caller.
    unsafe { base.add(field * 8) as *mut [f32; 8] }
}

/// Writes `v` into field `field` of a width-8 block on the lanes of `m` (others unchanged).
///
/// # Safety
/// As [`row8`].
#[inline]
unsafe fn blend8(base: *mut u32, field: usize, m: Mask8, v: F8) {
    // SAFETY: guaranteed by the caller (Embree's blocks need no 32-byte alignment; [u32; 8] needs
    // 4). The read is volatile so that LLVM keeps a whole load, blend and store rather than fusing
    // them into a masked store (microcoded on AMD: several times slower).
    unsafe {
        let p = row8(base, field);
        std::ptr::write_unaligned(p, m.select(v, F8::new(std::ptr::read_volatile(p))).to_array());
    }
}

/// Runs the ellipsoid against a width-8 Embree SoA ray block (the `rtcIntersect8`/`rtcOccluded8`
/// case, one SIMD pass): the lanes hit inside (tnear, tfar) and their distances.
///
/// # Safety
/// `valid` must hold 8 ints and `base` point to an RTCRay8 (or the ray part of an RTCRayHit8).
#[inline]
unsafe fn ellipsoid_hits8(e: &Ellipsoid, valid: *const i32, base: *mut u32) -> (Mask8, F8) {
    // SAFETY: guaranteed by the caller; Embree's valid ints are -1 (active) or 0.
    unsafe {
        let bits = U8::new(std::ptr::read_unaligned(valid as *const [u32; 8]));
        let live = F8::from_bits(bits.simd_eq(U8::MAX));
        if live.none() {
            return (live, F8::ZERO);
        }
        let f = |field: usize| F8::new(std::ptr::read_unaligned(row8(base, field)));
        let v3 = |field: usize| Vec3x8::new(f(field), f(field + 1), f(field + 2));
        super::ellipsoid::hits8(e, v3(0), v3(4), f(3), f(8), live)
    }
}

/// Runs the ellipsoid `e` against every valid lane of an Embree SoA ray block of width `n` (any
/// width, 8 lanes at a time) and calls `on_hit(lane, t)` for each lane it hits inside (tnear, tfar).
///
/// # Safety
/// `valid` must hold `n` ints and `base` point to an RTCRayN (or the ray part of an RTCRayHitN) of
/// width `n`.
unsafe fn each_ellipsoid_hit(
    e: &Ellipsoid,
    valid: *const i32,
    base: *mut u32,
    n: usize,
    mut on_hit: impl FnMut(usize, f32),
) {
    // SAFETY: guaranteed by the caller (see the function's contract).
    unsafe {
        for start in (0..n).step_by(8) {
            let m = (n - start).min(8);
            let load = |field: usize| {
                let mut v = [0f32; 8];
                std::ptr::copy_nonoverlapping(soa(base, n, field, start) as *const f32, v.as_mut_ptr(), m);
                v
            };
            let valid = |i: usize| *valid.add(start + i) == -1;
            super::ellipsoid::packet_hits(e, m, load, valid, |i, t| on_hit(start + i, t));
        }
    }
}

pub(super) unsafe extern "C" fn ellipsoid_intersect(args: *const sys::RTCIntersectFunctionNArguments) {
    // SAFETY: Embree passes `valid` with N ints, `rayhit` as an RTCRayHitN of width N in the 4.4
    // layout (12 ray fields then 9 hit fields, one instance level), the user pointer set in
    // add_ellipsoids, and primID < the primitive count.
    timed(|| unsafe {
        let a = &*args;
        let (n, base) = (a.N as usize, a.rayhit as *mut u32);
        let ctx = &*(a.context as *const RayQueryContext);
        let Some(e) = ellipsoid(a.geometryUserPtr, a.primID) else { return };
        // Hit record: t, Ng and u, v zero (strata computes its own normals), the ids.
        let ids = [a.primID, a.geomID, ctx.inst_id[0], ctx.inst_prim_id[0]];
        if n == 8 {
            let (hit, t) = ellipsoid_hits8(e, a.valid, base);
            if hit.none() {
                return;
            }
            blend8(base, 8, hit, t);
            for field in 12..17 {
                blend8(base, field, hit, F8::ZERO);
            }
            for (field, id) in (17..21).zip(ids) {
                blend8(base, field, hit, F8::from_bits(U8::splat(id)));
            }
            return;
        }
        each_ellipsoid_hit(e, a.valid, base, n, |lane, t| {
            *soa(base, n, 8, lane) = t.to_bits();
            for field in 12..17 {
                *soa(base, n, field, lane) = 0;
            }
            for (field, id) in (17..21).zip(ids) {
                *soa(base, n, field, lane) = id;
            }
        });
    })
}

pub(super) unsafe extern "C" fn ellipsoid_occluded(args: *const sys::RTCOccludedFunctionNArguments) {
    // SAFETY: as in ellipsoid_intersect, with `ray` an RTCRayN of width N (12 fields).
    timed(|| unsafe {
        let a = &*args;
        let (n, base) = (a.N as usize, a.ray as *mut u32);
        let Some(e) = ellipsoid(a.geometryUserPtr, a.primID) else { return };
        if n == 8 {
            let (hit, _) = ellipsoid_hits8(e, a.valid, base);
            if hit.any() {
                blend8(base, 8, hit, F8::splat(f32::NEG_INFINITY));
            }
            return;
        }
        each_ellipsoid_hit(e, a.valid, base, n, |lane, _| {
            *soa(base, n, 8, lane) = f32::NEG_INFINITY.to_bits();
        });
    })
}

#[cfg(test)]
#[path = "user_geometry_tests.rs"]
mod tests;

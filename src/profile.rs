//! Phase profiler of the worker threads (`strata profile`): a thread-local phase word and one
//! nanosecond accumulator per phase, like pbrt-v3's profiler but timed instead of sampled.
//!
//! Time is exclusive: entering a [`scope`] charges the clock since the last switch to the phase
//! that was running and makes the scope's phase current; leaving charges the scope and restores
//! the outer phase. Every nanosecond between [`tile_begin`] and [`tile_end`] therefore lands in
//! exactly one phase (code in no scope is [`Phase::Other`]: shading arithmetic and ray setup), so
//! the phases cover the tile. One phase nests below the scopes: Embree calls the sphere/ellipsoid
//! callbacks from inside `rtcIntersect8`/`rtcOccluded8`, where no scope can be entered (`accel`
//! sits below this module), so `accel::user_geometry` counts the callbacks' ticks itself
//! ([`crate::accel::take_callback_ticks`]) and the switch out of an Embree phase moves them from
//! that phase to [`Phase::UserGeometry`]. The clock is the CPU's time-stamp counter ([`crate::accel::timestamp`],
//! a few ns a read), converted to nanoseconds with a rate calibrated against `Instant` when
//! profiling is turned on, and the sum is checked against the tiles' `Instant` time measured
//! independently. Work outside the tiles that a profile covers is timed with `Instant` and added
//! to both the phase and the total: the film merge after the tiles ([`Phase::Film`], in
//! `render`) and the image encoding of the commands that write one ([`Phase::Output`], in
//! `session`). Scopes sit at batch granularity (one 8-lane packet call or one tile loop),
//! never per lane. Profiling off (the default) costs one
//! relaxed atomic load per scope; it never changes what is computed, so images are bit-identical.

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// The phases a worker thread's time is split into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(usize)]
pub enum Phase {
    /// code in no other phase: shading arithmetic, ray setup, path bookkeeping
    Other = 0,
    /// sample generation of the pixel/camera dimensions
    SamplerPixel,
    /// sample generation of the light dimensions (direct lighting)
    SamplerLight,
    /// sample generation of the path dimensions (bounce, lobe and light choice)
    SamplerPath,
    /// emitter sampling (a point on a light from the unit-square sample)
    Emitter,
    /// Embree closest-hit queries (camera and bounce packets), user geometry callbacks excluded
    EmbreeIntersect,
    /// Embree occlusion queries (shadow packets), user geometry callbacks excluded
    EmbreeOccluded,
    /// hit gather: Embree hit records (AoS) to SoA shading records
    Gather,
    /// accumulation of samples into the tile's dyadic blocks
    Accumulate,
    /// BSDF sampling: lobe choice and the direction warp (path tracer)
    BsdfSample,
    /// BSDF evaluation: value and pdf for a given direction (NEE, direct lighting, Blinn-Phong)
    BsdfEval,
    /// multiple importance sampling weights where a BSDF-sampled ray hits a light (the light's
    /// pdf and pmf there, power heuristic); the NEE side's few-flop weight stays in `Other`
    Mis,
    /// sphere/ellipsoid intersection callbacks, run by Embree inside its queries (with
    /// `STRATA_SPHERES=embree`, spheres that are Embree sphere points stay in the Embree phases)
    UserGeometry,
    /// film: copying the film's blocks into a tile and merging the tiles back
    Film,
    /// encoding and writing the output images (commands that write them)
    Output,
}

/// Number of phases.
pub const N_PHASES: usize = 15;

/// Every phase in table order.
pub const PHASES: [Phase; N_PHASES] = [
    Phase::SamplerPixel,
    Phase::SamplerLight,
    Phase::SamplerPath,
    Phase::Emitter,
    Phase::EmbreeIntersect,
    Phase::EmbreeOccluded,
    Phase::UserGeometry,
    Phase::Gather,
    Phase::BsdfSample,
    Phase::BsdfEval,
    Phase::Mis,
    Phase::Accumulate,
    Phase::Film,
    Phase::Output,
    Phase::Other,
];

impl Phase {
    /// The phase's name in tables and JSON (a name starting with `sampler` is sample generation).
    pub fn name(self) -> &'static str {
        match self {
            Phase::Other => "other (shading, ray setup)",
            Phase::SamplerPixel => "sampler: pixel/camera",
            Phase::SamplerLight => "sampler: light",
            Phase::SamplerPath => "sampler: path (bounce, lobe, light choice)",
            Phase::Emitter => "emitter sampling",
            Phase::EmbreeIntersect => "embree intersect",
            Phase::EmbreeOccluded => "embree occluded",
            Phase::Gather => "hit gather",
            Phase::Accumulate => "accumulate",
            Phase::BsdfSample => "bsdf sampling (lobe choice, warp)",
            Phase::BsdfEval => "bsdf eval (value, pdf)",
            Phase::Mis => "mis weights",
            Phase::UserGeometry => "user geometry (sphere/ellipsoid callbacks)",
            Phase::Film => "film (tile copy and merge)",
            Phase::Output => "output encode (exr, png)",
        }
    }
}

static ENABLED: AtomicBool = AtomicBool::new(false);
/// nanoseconds per tick, as f64 bits (0: not calibrated yet)
static NS_PER_TICK: AtomicU64 = AtomicU64::new(0);

/// A thread's profiler state, in one thread-local (one lookup per switch, no array copies).
struct State {
    /// the running phase
    current: Cell<usize>,
    /// tick of the last switch
    since: Cell<u64>,
    /// ticks per phase
    acc: [Cell<u64>; N_PHASES],
}

thread_local! {
    static STATE: State = const {
        State { current: Cell::new(0), since: Cell::new(0), acc: [const { Cell::new(0) }; N_PHASES] }
    };
}

/// Turns profiling on or off for every thread (set it before a render, not during one). The first
/// time it is turned on, the tick clock is calibrated against `Instant` (about 20 ms).
pub fn set_enabled(on: bool) {
    if on && NS_PER_TICK.load(Ordering::SeqCst) == 0 {
        let (t, c) = (Instant::now(), crate::accel::timestamp());
        while t.elapsed().as_millis() < 20 {
            std::hint::spin_loop();
        }
        let (ns, ticks) = (t.elapsed().as_nanos() as f64, crate::accel::timestamp().wrapping_sub(c));
        NS_PER_TICK.store((ns / ticks.max(1) as f64).to_bits(), Ordering::SeqCst);
    }
    ENABLED.store(on, Ordering::SeqCst);
    crate::accel::set_callback_timing(on);
}

/// Profiling held on until the guard drops (then off for every thread), so an early return
/// never leaves it on.
#[must_use = "profiling turns off when the guard drops"]
pub struct Enabled(());

impl Drop for Enabled {
    fn drop(&mut self) {
        set_enabled(false);
    }
}

/// Turns profiling on (see [`set_enabled`]) until the returned guard drops.
pub fn enable() -> Enabled {
    set_enabled(true);
    Enabled(())
}

/// Nanoseconds per tick of the profiler's clock (1 before calibration).
pub fn ns_per_tick() -> f64 {
    match NS_PER_TICK.load(Ordering::Relaxed) {
        0 => 1.0,
        b => f64::from_bits(b),
    }
}

/// Whether profiling is on.
#[inline]
pub fn enabled() -> bool {
    ENABLED.load(Ordering::Relaxed)
}

/// Charges the ticks since the last switch to the current phase and makes `next` current; the
/// user-geometry callbacks' ticks counted meanwhile (inside the Embree call that just ended) go to
/// [`Phase::UserGeometry`] instead.
#[inline]
fn switch(next: usize) -> usize {
    let now = crate::accel::timestamp();
    STATE.with(|st| {
        let prev = st.current.replace(next);
        let spent = now.saturating_sub(st.since.replace(now));
        // Callbacks only run inside Embree calls: only a switch out of an Embree phase has any.
        let embree = prev == Phase::EmbreeIntersect as usize || prev == Phase::EmbreeOccluded as usize;
        let nested = if embree { crate::accel::take_callback_ticks().min(spent) } else { 0 };
        let add = |i: usize, t: u64| st.acc[i].set(st.acc[i].get() + t);
        add(prev, spent - nested);
        if nested > 0 {
            add(Phase::UserGeometry as usize, nested);
        }
        prev
    })
}

/// A running phase; dropping it restores the outer phase.
pub struct Scope {
    outer: Option<usize>,
}

impl Drop for Scope {
    #[inline]
    fn drop(&mut self) {
        if let Some(o) = self.outer {
            switch(o);
        }
    }
}

/// Enters `phase` until the returned guard drops (nothing when profiling is off).
#[inline]
#[must_use = "the phase ends when the guard drops"]
pub fn scope(phase: Phase) -> Scope {
    if !enabled() {
        return Scope { outer: None };
    }
    Scope { outer: Some(switch(phase as usize)) }
}

/// Starts timing a tile on this thread, in phase [`Phase::Other`].
#[inline]
pub fn tile_begin() {
    if enabled() {
        crate::accel::take_callback_ticks();
        STATE.with(|st| {
            st.current.set(0);
            st.acc.iter().for_each(|a| a.set(0));
            st.since.set(crate::accel::timestamp());
        });
    }
}

/// Stops timing the tile and returns (and clears) this thread's nanoseconds per phase.
#[inline]
pub fn tile_end() -> [u64; N_PHASES] {
    if !enabled() {
        return [0; N_PHASES];
    }
    switch(0);
    let k = ns_per_tick();
    STATE.with(|st| std::array::from_fn(|i| (st.acc[i].replace(0) as f64 * k) as u64))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spin(ns: u128) {
        let t = Instant::now();
        while t.elapsed().as_nanos() < ns {
            std::hint::black_box(0);
        }
    }

    /// Nested scopes are exclusive: the inner phase's time is not also charged to the outer one,
    /// and the phases add up to the tile's duration.
    #[test]
    fn nested_scopes_are_exclusive_and_sum_to_the_tile() {
        set_enabled(true);
        let t = Instant::now();
        tile_begin();
        {
            let _a = scope(Phase::EmbreeIntersect);
            spin(2_000_000);
            {
                let _b = scope(Phase::SamplerPath);
                spin(3_000_000);
            }
        }
        spin(1_000_000);
        let acc = tile_end();
        let total = t.elapsed().as_nanos() as u64;
        set_enabled(false);
        let sum: u64 = acc.iter().sum();
        assert!(sum <= total && sum as f64 > 0.99 * total as f64, "sum {sum} of {total}");
        // TSC ticks are converted with a rate calibrated against `Instant`: allow 5% for it.
        let sp = acc[Phase::SamplerPath as usize];
        assert!(sp >= 2_850_000, "inner scope: {sp} ns of 3 ms");
        let ei = acc[Phase::EmbreeIntersect as usize];
        assert!((1_900_000..2_900_000).contains(&ei), "inner time not charged to the outer scope: {ei}");
        assert!(acc[Phase::Other as usize] >= 950_000);
    }
}

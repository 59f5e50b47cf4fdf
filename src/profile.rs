//! Phase profiler of the worker threads (`strata profile`): a thread-local phase word and one
//! nanosecond accumulator per phase, like pbrt-v3's profiler but timed instead of sampled.
//!
//! Time is exclusive: entering a [`scope`] charges the clock since the last switch to the phase
//! that was running and makes the scope's phase current; leaving charges the scope and restores
//! the outer phase. Every nanosecond between [`tile_begin`] and [`tile_end`] therefore lands in
//! exactly one phase (code in no scope is [`Phase::Other`]: shading, BSDFs, warps, MIS), so the
//! phases cover the tile; the clock is the CPU's time-stamp counter ([`crate::accel::timestamp`],
//! a few ns a read), converted to nanoseconds with a rate calibrated against `Instant` when
//! profiling is turned on, and the sum is checked against the tiles' `Instant` time measured
//! independently. Scopes sit at batch granularity (one 8-lane packet call or one tile loop),
//! never per lane. Profiling off (the default) costs one
//! relaxed atomic load per scope; it never changes what is computed, so images are bit-identical.

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// The phases a worker thread's time is split into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(usize)]
pub enum Phase {
    /// code in no other phase: shading, BSDF sampling and eval, warps, MIS, ray setup
    Other = 0,
    /// sample generation of the pixel/camera dimensions
    SamplerPixel,
    /// sample generation of the light dimensions (direct lighting)
    SamplerLight,
    /// sample generation of the path dimensions (bounce, lobe and light choice)
    SamplerPath,
    /// emitter sampling (a point on a light from the unit-square sample)
    Emitter,
    /// Embree closest-hit queries (camera and bounce packets), user geometry callbacks included
    EmbreeIntersect,
    /// Embree occlusion queries (shadow packets)
    EmbreeOccluded,
    /// hit gather: Embree hit records (AoS) to SoA shading records
    Gather,
    /// accumulation of samples into the tile's dyadic blocks
    Accumulate,
}

/// Number of phases.
pub const N_PHASES: usize = 9;

/// Every phase in table order.
pub const PHASES: [Phase; N_PHASES] = [
    Phase::SamplerPixel,
    Phase::SamplerLight,
    Phase::SamplerPath,
    Phase::Emitter,
    Phase::EmbreeIntersect,
    Phase::EmbreeOccluded,
    Phase::Gather,
    Phase::Accumulate,
    Phase::Other,
];

impl Phase {
    /// The phase's name in tables and JSON (a name starting with `sampler` is sample generation).
    pub fn name(self) -> &'static str {
        match self {
            Phase::Other => "other (shading, bsdf, warps, mis)",
            Phase::SamplerPixel => "sampler: pixel/camera",
            Phase::SamplerLight => "sampler: light",
            Phase::SamplerPath => "sampler: path (bounce, lobe, light choice)",
            Phase::Emitter => "emitter sampling",
            Phase::EmbreeIntersect => "embree intersect",
            Phase::EmbreeOccluded => "embree occluded",
            Phase::Gather => "hit gather",
            Phase::Accumulate => "accumulate",
        }
    }
}

static ENABLED: AtomicBool = AtomicBool::new(false);
/// nanoseconds per tick, as f64 bits (0: not calibrated yet)
static NS_PER_TICK: AtomicU64 = AtomicU64::new(0);

thread_local! {
    static CURRENT: Cell<usize> = const { Cell::new(0) };
    static SINCE: Cell<u64> = const { Cell::new(0) };
    static ACC: Cell<[u64; N_PHASES]> = const { Cell::new([0; N_PHASES]) };
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

/// Charges the ticks since the last switch to the current phase and makes `next` current.
#[inline]
fn switch(next: usize) -> usize {
    let now = crate::accel::timestamp();
    let prev = CURRENT.with(|c| c.replace(next));
    let since = SINCE.with(|s| s.replace(now));
    ACC.with(|a| {
        let mut v = a.get();
        v[prev] += now.saturating_sub(since);
        a.set(v);
    });
    prev
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
        CURRENT.with(|c| c.set(0));
        SINCE.with(|s| s.set(crate::accel::timestamp()));
        ACC.with(|a| a.set([0; N_PHASES]));
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
    ACC.with(|a| a.replace([0; N_PHASES])).map(|t| (t as f64 * k) as u64)
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

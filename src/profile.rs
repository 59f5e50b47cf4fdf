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
//! that phase to [`Phase::UserGeometry`]. The clock is the CPU's time-stamp counter
//! ([`crate::accel::timestamp`], a few ns a read), converted to nanoseconds with a rate
//! calibrated against `Instant` when profiling is turned on, and the sum is checked against the
//! tiles' `Instant` time measured independently. Work outside the tiles that a profile covers is
//! timed with `Instant` and added to both the phase and the total: the film merge after the tiles
//! ([`Phase::Film`], in `render`) and the image encoding of the commands that write one
//! ([`Phase::Output`], in `session`).
//!
//! Scopes sit at batch granularity (a batch of packets traced back to back, one tile loop), never
//! per lane; a scope of the phase already running costs no clock read, so a batch scope makes the
//! per-packet scopes inside it free. Short, frequent spans (one sampler or emitter call, one hit
//! gather) are [`leaf`] spans: one in [`LEAF_RATE`], picked at random, is timed and stands for
//! `LEAF_RATE` spans, and the estimate moves from the phase the span ran in to the leaf's phase
//! when the tile ends (an unbiased estimate, so the phases still sum to the tile; a clock read
//! costs about 20 ns on a VM, which timing every span would pay twice per call). Profiling off
//! (the default) costs one relaxed atomic load per scope; it never changes what is computed, so
//! images are bit-identical.

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
/// ticks two back-to-back clock reads are apart at least (the clock's own cost, taken off leaf spans)
static EMPTY_TICKS: AtomicU64 = AtomicU64::new(0);

/// ticks from which a [`leaf`] span is long enough to time every time (2 us)
static EXACT_TICKS: AtomicU64 = AtomicU64::new(u64::MAX);

/// A short [`leaf`] span is timed once in `LEAF_RATE` on average (gaps drawn uniformly from
/// 1..2 `LEAF_RATE`, independently of the spans) and then counts `LEAF_RATE` times.
pub const LEAF_RATE: u64 = 16;

/// Leaf spans of a phase whose last timed span took at least this long are all timed (the clock's
/// cost is then under 2% of the span, and preemption is charged as exactly as in a [`scope`]).
pub const LEAF_EXACT_NS: f64 = 2000.0;

#[cfg(test)]
thread_local! {
    /// Test builds: a clock the test drives (0: the real one), on this thread only.
    static FAKE_CLOCK: Cell<u64> = const { Cell::new(0) };
}

/// The profiler's clock: the time-stamp counter (a test's fake clock in test builds).
#[inline]
fn now() -> u64 {
    #[cfg(test)]
    {
        let f = FAKE_CLOCK.with(|c| c.get());
        if f != 0 {
            return f;
        }
    }
    crate::accel::timestamp()
}

/// A thread's profiler state: the running phase, the last switch, exclusive ticks per phase, and
/// the leaf estimates (ticks of leaf phase `j` measured inside phase `i`: `est[i * N + j]`).
struct State {
    current: Cell<usize>,
    since: Cell<u64>,
    switches: Cell<u32>,
    rng: Cell<u32>,
    /// leaf spans until the next timed one
    countdown: Cell<u32>,
    /// bit p: the last timed leaf span of phase p was long, so each of its spans is timed
    exact: Cell<u32>,
    acc: [Cell<u64>; N_PHASES],
    est: [Cell<u64>; N_PHASES * N_PHASES],
}

thread_local! {
    static STATE: State = const {
        State {
            current: Cell::new(0),
            since: Cell::new(0),
            switches: Cell::new(0),
            rng: Cell::new(0x9e37_79b9),
            countdown: Cell::new(1),
            exact: Cell::new(0),
            acc: [const { Cell::new(0) }; N_PHASES],
            est: [const { Cell::new(0) }; N_PHASES * N_PHASES],
        }
    };
}

/// An `Instant` and the tick count at the same moment: of 64 tries, the one whose `Instant` read
/// sits between the two closest tick readings (their midpoint is returned).
fn paired_reading() -> (Instant, u64) {
    let mut best = (Instant::now(), 0u64, u64::MAX);
    for _ in 0..64 {
        let a = now();
        let i = Instant::now();
        let b = now();
        let width = b.wrapping_sub(a);
        if width < best.2 {
            best = (i, a + width / 2, width);
        }
    }
    (best.0, best.1)
}

/// Turns profiling on or off for every thread (set it before a render, not during one). The first
/// time it is turned on, the tick clock is calibrated against `Instant` (about 20 ms).
pub fn set_enabled(on: bool) {
    if on && NS_PER_TICK.load(Ordering::SeqCst) == 0 {
        // Both ends are tick readings bracketing an `Instant` reading, the tightest of several:
        // a thread preempted between the two clocks' readings (a millisecond on a loaded machine,
        // 5 % of the 20 ms) would otherwise skew every phase against the wall-clock total.
        let (t, c) = paired_reading();
        while t.elapsed().as_millis() < 20 {
            std::hint::spin_loop();
        }
        let (t1, c1) = paired_reading();
        let (ns, ticks) = (t1.duration_since(t).as_nanos() as f64, c1.wrapping_sub(c));
        NS_PER_TICK.store((ns / ticks.max(1) as f64).to_bits(), Ordering::SeqCst);
        let empty = (0..1000)
            .map(|_| {
                let a = now();
                now().wrapping_sub(a)
            })
            .min()
            .unwrap_or(0);
        EMPTY_TICKS.store(empty, Ordering::SeqCst);
        EXACT_TICKS.store((LEAF_EXACT_NS / ns_per_tick()) as u64, Ordering::SeqCst);
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
fn switch(st: &State, next: usize) -> usize {
    let now = now();
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
    st.switches.set(st.switches.get().wrapping_add(1));
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
            STATE.with(|st| switch(st, o));
        }
    }
}

/// Enters `phase` until the returned guard drops (nothing when profiling is off, or when `phase`
/// is already running: a scope around a batch makes the per-packet scopes inside it free).
#[inline]
#[must_use = "the phase ends when the guard drops"]
pub fn scope(phase: Phase) -> Scope {
    if !enabled() {
        return Scope { outer: None };
    }
    STATE.with(|st| {
        if st.current.get() == phase as usize {
            return Scope { outer: None };
        }
        Scope { outer: Some(switch(st, phase as usize)) }
    })
}

/// A sampled span of a leaf phase; see [`leaf`].
pub struct Leaf {
    /// start tick (0: this span is not timed)
    t0: u64,
    phase: usize,
    switches: u32,
    /// spans this one stands for (1 / its probability of being timed)
    weight: u64,
}

impl Drop for Leaf {
    #[inline]
    fn drop(&mut self) {
        if self.t0 != 0 {
            leaf_end(self);
        }
    }
}

#[inline(never)]
fn leaf_end(l: &Leaf) {
    let now = now();
    STATE.with(|st| {
        // A scope inside the span already charged its time: the estimate would count it twice.
        if st.switches.get() != l.switches {
            return;
        }
        let d = now.wrapping_sub(l.t0).saturating_sub(EMPTY_TICKS.load(Ordering::Relaxed));
        let bit = 1u32 << l.phase;
        let long = d >= EXACT_TICKS.load(Ordering::Relaxed);
        st.exact.set(if long { st.exact.get() | bit } else { st.exact.get() & !bit });
        let e = &st.est[st.current.get() * N_PHASES + l.phase];
        e.set(e.get() + d * l.weight);
    })
}

/// Enters leaf phase `phase` until the returned guard drops: for short, frequent spans (one
/// sampler or emitter call, one hit gather) that contain no [`scope`]. One span in
/// [`LEAF_RATE`] (random gaps of a per-thread stream, one counter decrement per span untimed) is
/// timed and counts `LEAF_RATE` times, or every span when the phase's last timed span took
/// [`LEAF_EXACT_NS`] or more (unbiased either way: whether a span is timed is settled before it
/// starts, independently of its length). At [`tile_end`] the
/// estimate moves from the phase the span ran in to `phase`, so the phases still sum to the
/// tile. Nothing when profiling is off.
#[inline]
#[must_use = "the phase ends when the guard drops"]
pub fn leaf(phase: Phase) -> Leaf {
    const UNTIMED: Leaf = Leaf { t0: 0, phase: 0, switches: 0, weight: 0 };
    if !enabled() {
        return UNTIMED;
    }
    STATE.with(|st| {
        let weight = if st.exact.get() & (1 << phase as u32) != 0 {
            1
        } else {
            let c = st.countdown.get();
            if c > 1 {
                st.countdown.set(c - 1);
                return UNTIMED;
            }
            let mut x = st.rng.get();
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            st.rng.set(x);
            st.countdown.set(1 + x % (2 * LEAF_RATE as u32 - 1));
            LEAF_RATE
        };
        Leaf { t0: now().max(1), phase: phase as usize, switches: st.switches.get(), weight }
    })
}

/// Starts timing a tile on this thread, in phase [`Phase::Other`].
#[inline]
pub fn tile_begin() {
    if enabled() {
        crate::accel::take_callback_ticks();
        STATE.with(|st| {
            st.current.set(0);
            st.since.set(now());
            st.acc.iter().chain(&st.est).for_each(|c| c.set(0));
        });
    }
}

/// Stops timing the tile and returns (and clears) this thread's nanoseconds per phase.
#[inline]
pub fn tile_end() -> [u64; N_PHASES] {
    if !enabled() {
        return [0; N_PHASES];
    }
    let k = ns_per_tick();
    STATE.with(|st| {
        switch(st, 0);
        let mut acc: [u64; N_PHASES] = std::array::from_fn(|i| st.acc[i].replace(0));
        let est: [u64; N_PHASES * N_PHASES] = std::array::from_fn(|i| st.est[i].replace(0));
        // Leaf estimates move out of the phase they ran in (at most all of its time).
        for (i, row) in est.chunks_exact(N_PHASES).enumerate() {
            let want: u64 = row.iter().sum();
            if want == 0 {
                continue;
            }
            let take = want.min(acc[i]);
            let mut moved = 0;
            for (j, &e) in row.iter().enumerate() {
                let m = (e as u128 * take as u128 / want as u128) as u64;
                acc[j] += m;
                moved += m;
            }
            acc[i] -= moved;
        }
        acc.map(|t| (t as f64 * k) as u64)
    })
}

/// Test builds: profiling (and sampler recording) are process-wide switches; the library's tests
/// that turn them on take turns with this lock.
#[cfg(test)]
pub(crate) static TEST_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[cfg(test)]
mod tests {
    use super::*;

    /// Nested scopes are exclusive: the inner phase's time is not also charged to the outer one,
    /// and the phases add up to the tile's duration. On a clock the test drives (this thread's
    /// fake clock), so the split is exact whatever the machine's speed or load.
    #[test]
    fn nested_scopes_are_exclusive_and_sum_to_the_tile() {
        let _g = TEST_LOCK.lock().unwrap_or_else(|e| e.into_inner());
        set_enabled(true); // calibrates on the real clock
        let tick = |dt: u64| FAKE_CLOCK.with(|c| c.set(c.get() + dt));
        FAKE_CLOCK.with(|c| c.set(1_000_000));
        tile_begin();
        tick(700); // other
        {
            let _a = scope(Phase::EmbreeIntersect);
            tick(2_000);
            {
                let _b = scope(Phase::SamplerPath);
                tick(3_000);
                // Re-entering the running phase is free: no switch, nothing charged twice.
                let _c = scope(Phase::SamplerPath);
                tick(400);
            }
            tick(500); // back in the outer scope
        }
        tick(1_000); // other again
        let acc = tile_end();
        FAKE_CLOCK.with(|c| c.set(0));
        set_enabled(false);
        let ns = |ticks: u64| (ticks as f64 * ns_per_tick()) as u64;
        assert_eq!(acc[Phase::SamplerPath as usize], ns(3_400), "inner scope");
        assert_eq!(acc[Phase::EmbreeIntersect as usize], ns(2_500), "inner time charged to the outer scope");
        assert_eq!(acc[Phase::Other as usize], ns(1_700));
        let sum: u64 = acc.iter().sum();
        assert_eq!(sum, ns(3_400) + ns(2_500) + ns(1_700), "phases besides the three: {acc:?}");
        let total = ns(7_600);
        assert!(sum <= total && total - sum <= 2, "sum {sum} of {total}");
    }

    /// Leaf spans on a clock the test drives (deterministic: the random stream is the thread's
    /// own): short spans, one in `LEAF_RATE` timed, and long ones, all timed, each give the leaf
    /// phase about the time spent in them, taken out of the phase they ran in; the phases sum to
    /// the tile exactly.
    #[test]
    fn leaf_spans_are_estimated_from_a_sample_and_sum_to_the_tile() {
        let _g = TEST_LOCK.lock().unwrap_or_else(|e| e.into_inner());
        set_enabled(true); // calibrates on the real clock
        let (exact, empty) = (EXACT_TICKS.load(Ordering::SeqCst), EMPTY_TICKS.load(Ordering::SeqCst));
        let tick = |dt: u64| FAKE_CLOCK.with(|c| c.set(c.get() + dt));
        for (span, n, tol) in [(exact / 2, 6400u64, 0.15), (exact * 4, 400, 0.05)] {
            FAKE_CLOCK.with(|c| c.set(1_000_000));
            tile_begin();
            for _ in 0..n {
                let l = leaf(Phase::SamplerPixel);
                tick(span);
                drop(l);
                tick(span / 3);
            }
            let acc = tile_end();
            let k = ns_per_tick();
            let total = (n * (span + span / 3)) as f64 * k;
            let sum: u64 = acc.iter().sum();
            assert!((sum as f64 / total - 1.0).abs() < 1e-5, "sum {sum} of {total}");
            let want = (n * (span - empty)) as f64 * k;
            let got = acc[Phase::SamplerPixel as usize] as f64;
            assert!((got / want - 1.0).abs() < tol, "span {span}: leaf {got} of {want}");
            assert!(acc[Phase::Other as usize] > 0);
        }
        FAKE_CLOCK.with(|c| c.set(0));
        set_enabled(false);
    }
}

//! A counting global allocator for tests that cap memory (tests/hostile_input.rs installs it with
//! `#[global_allocator]`). It forwards to the system allocator and keeps, per thread, the bytes
//! currently allocated by that thread and their peak, so a test can measure what one call
//! allocated while other tests run on other threads. It lives here because it needs `unsafe`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The counting allocator: install with `#[global_allocator] static A: CountingAlloc = CountingAlloc;`.
pub struct CountingAlloc;

thread_local! {
    static LIVE: Cell<usize> = const { Cell::new(0) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

fn grow(n: usize) {
    // try_with: nothing to count while the thread's locals are being torn down.
    let _ = LIVE.try_with(|live| {
        let v = live.get().saturating_add(n);
        live.set(v);
        let _ = PEAK.try_with(|p| p.set(p.get().max(v)));
    });
}

fn shrink(n: usize) {
    // Memory freed by another thread than the one that allocated it saturates at 0.
    let _ = LIVE.try_with(|live| live.set(live.get().saturating_sub(n)));
}

impl CountingAlloc {
    /// Starts a measurement on this thread: resets the peak to the bytes live now and returns them
    /// (the baseline to pass to [`CountingAlloc::peak_above`]).
    pub fn start() -> usize {
        let live = LIVE.with(Cell::get);
        PEAK.with(|p| p.set(live));
        live
    }

    /// The most bytes live on this thread since [`CountingAlloc::start`], above its `baseline`.
    pub fn peak_above(baseline: usize) -> usize {
        PEAK.with(Cell::get).saturating_sub(baseline)
    }

    /// Bytes currently allocated by this thread (and not freed).
    pub fn live() -> usize {
        LIVE.with(Cell::get)
    }
}

// SAFETY: every method forwards to `System` with the caller's arguments unchanged and only adds
// bookkeeping in thread-locals that never allocate (const-initialised `Cell<usize>`), so the
// `GlobalAlloc` contract holds exactly as it does for `System`.
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller upholds `GlobalAlloc::alloc`'s contract, which `System` shares.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            grow(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as for `alloc`.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            grow(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` was allocated by this allocator, i.e. by `System`, with `layout`.
        unsafe { System.dealloc(ptr, layout) };
        shrink(layout.size());
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: `ptr` was allocated by `System` with `layout`; the caller upholds the rest.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            shrink(layout.size());
            grow(new_size);
        }
        p
    }
}

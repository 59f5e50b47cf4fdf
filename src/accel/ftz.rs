//! Flush-to-zero / denormals-are-zero for rendering threads (Embree asks for both).

/// Sets flush-to-zero and denormals-are-zero on the calling thread (x86_64; no-op elsewhere).
pub fn set_ftz_daz() {
    #[cfg(target_arch = "x86_64")]
    {
        // MXCSR bit 15 = FTZ, bit 6 = DAZ. Read-modify-write through inline asm-free intrinsics
        // is deprecated in std; use stmxcsr/ldmxcsr via core::arch::asm. Embree asks
        // for both in every rendering thread.
        let mut csr: u32 = 0;
        // SAFETY: stmxcsr/ldmxcsr only read/write the MXCSR control register of this thread and
        // the 4-byte local `csr`; setting FTZ/DAZ changes denormal handling only.
        unsafe {
            core::arch::asm!("stmxcsr [{}]", in(reg) &mut csr, options(nostack));
            csr |= (1 << 15) | (1 << 6);
            core::arch::asm!("ldmxcsr [{}]", in(reg) &csr, options(nostack));
        }
    }
}

/// The CPU's time-stamp counter (x86_64; elsewhere nanoseconds of a monotonic clock): a cheap
/// clock for the phase profiler (`crate::profile`), which calibrates it against `Instant`.
#[inline]
pub fn timestamp() -> u64 {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: rdtsc reads the time-stamp counter; it has no memory effects and is available
        // on every x86_64 CPU.
        unsafe { core::arch::x86_64::_rdtsc() }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        use std::sync::OnceLock;
        static T0: OnceLock<std::time::Instant> = OnceLock::new();
        T0.get_or_init(std::time::Instant::now).elapsed().as_nanos() as u64
    }
}

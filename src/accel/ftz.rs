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

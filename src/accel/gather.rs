//! Eight table look-ups at once ([`gather_u16`]): AVX2's `vpgatherdd` where it is measured faster
//! than eight scalar loads (AMD), scalar loads elsewhere; the same values either way.
//!
//! Why: Halton's base-3 digit tables (`sampler::halton`) take five look-ups of eight lanes per
//! point. Measured on an AMD EPYC (Zen 4) with `strata profile cse168/hw2/sphere.test --size 80x60
//! --spp 64 --sampler sobol --light-selection uniform` (its "every call by" table, Halton's time
//! over Sobol's): scalar loads with a bounds check per lane 2.09-2.12x; scalar loads of an index
//! masked into a padded table (no check) 1.71-1.80x; the gather 1.61-1.67x. pmj02's two-word
//! look-ups measured slower gathered (1.11-1.15x against 0.96x), so they stay scalar. On Intel
//! CPUs the gather is not used: the microcode against Gather Data Sampling ("Downfall", 2023)
//! slows `vpgatherdd` several-fold on many Xeons, and no Intel machine was at hand to measure it;
//! there the masked scalar loads run. `STRATA_GATHER=hardware|scalar` overrides the choice
//! ([`set_hardware_gather`], from `scene::build::forced_gather`) to measure both on a new CPU.

use crate::simd::U8;
use std::sync::atomic::{AtomicU8, Ordering};

/// The look-up form: 0 not yet chosen, 1 scalar loads, 2 the hardware gather.
static USE: AtomicU8 = AtomicU8::new(0);

/// Whether [`gather_u16`] should use the hardware gather: as [`set_hardware_gather`] chose, else
/// (nothing chosen yet) on an x86_64 CPU with AVX2 from AMD. Cached in a relaxed atomic: one load
/// per call.
#[inline]
pub fn hardware_gather() -> bool {
    match USE.load(Ordering::Relaxed) {
        0 => set_hardware_gather(None),
        v => v == 2,
    }
}

/// Chooses the look-up form for the process: `Some(true)` the hardware gather (where AVX2 is
/// compiled in; scalar loads otherwise), `Some(false)` scalar loads, `None` by the CPU (AMD with
/// AVX2: the gather). Returns whether the gather is used. Only speed depends on it (the values are
/// the same); `STRATA_GATHER` sets it for a render (`scene::build::forced_gather`).
pub fn set_hardware_gather(on: Option<bool>) -> bool {
    let yes = hardware_gather_compiled() && on.unwrap_or_else(detect_amd_avx2);
    USE.store(1 + u8::from(yes), Ordering::Relaxed);
    yes
}

/// Whether this build can run the hardware gather (AVX2 compiled in).
pub fn hardware_gather_compiled() -> bool {
    cfg!(all(target_arch = "x86_64", target_feature = "avx2"))
}

/// CPUID says "AuthenticAMD" and AVX2 is available.
#[cold]
fn detect_amd_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        let v = std::arch::x86_64::__cpuid(0);
        let amd = [v.ebx, v.edx, v.ecx] == [0x6874_7541, 0x6974_6e65, 0x444d_4163]; // "AuthenticAMD"
        amd && std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `table[i & (N - 2)]` per lane of `idx`, widened to u32, by the hardware gather if `hardware`
/// (pass [`hardware_gather`], read once for several look-ups; AVX2 compiled in) and by scalar
/// loads otherwise. `N - 1` must be a power of two: the last entry is padding that only the
/// 4-byte hardware reads touch (the index mask keeps every read inside the table, whatever `idx`
/// holds).
#[inline(always)]
pub fn gather_u16<const N: usize>(table: &[u16; N], idx: U8, hardware: bool) -> U8 {
    const { assert!(N >= 2 && (N - 1).is_power_of_two()) };
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    if hardware {
        use std::arch::x86_64::{__m256i, _mm256_i32gather_epi32};
        let v: __m256i = wide::bytemuck::cast(idx & U8::splat((N - 2) as u32));
        // SAFETY: AVX2 is enabled at compile time (this cfg). Lane i reads the 4 bytes at
        // `table + 2 * idx_i` with idx_i <= N - 2 (masked above), i.e. bytes up to 2N: inside
        // the table, whose alignment of 2 is all an unaligned gather element needs.
        let g = unsafe { _mm256_i32gather_epi32::<2>(table.as_ptr().cast::<i32>(), v) };
        // The low half of each 4-byte read is the entry (x86 is little-endian).
        return wide::bytemuck::cast::<__m256i, U8>(g) & U8::splat(0xffff);
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    let _ = hardware;
    // Masked per lane (a vector mask before taking the lanes apart would leave the compiler its
    // bounds checks).
    U8::new(idx.to_array().map(|i| u32::from(table[i as usize & (N - 2)])))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The look-up equals indexing, lane by lane, on every entry and with high index bits set
    /// (masked away), by the hardware gather (where AVX2 is compiled in) and by scalar loads.
    #[test]
    fn gather_equals_scalar_indexing() {
        let table: [u16; 4097] = std::array::from_fn(|i| (i as u16).wrapping_mul(40_503) ^ 0x5a5a);
        for hardware in [true, false] {
            for base in (0..4096u32).step_by(8).chain([4088, u32::MAX - 7, 1 << 31]) {
                let idx = U8::new(std::array::from_fn(|l| base.wrapping_add(l as u32 * 517)));
                let got = gather_u16(&table, idx, hardware).to_array();
                for (l, i) in idx.to_array().into_iter().enumerate() {
                    assert_eq!(got[l], u32::from(table[i as usize & 4095]), "lane {l} index {i} ({hardware})");
                }
            }
            // The last entry (the hardware read there also covers the padding entry).
            let last = gather_u16(&table, U8::splat(4095), hardware).to_array();
            assert_eq!(last, [u32::from(table[4095]); 8]);
        }
    }
}

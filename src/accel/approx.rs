//! Which approximate-reciprocal instructions Embree's kernels run on this CPU, as part of a
//! render's identity. Embree's AVX2 kernels start reciprocals and reciprocal square roots from
//! `vrcpps`/`vrsqrtps`, whose results are implementation-specific (only their error bound is
//! specified), then refine them with a Newton step: hit distances and barycentrics can differ in
//! their last bits between CPU models, and so do the pixels (seen: 20 of the 21 golden images
//! differ between two AVX-512 machines running Embree's AVX2 kernels). Its AVX-512 kernels use
//! `vrcp14ps`/`vrsqrt14ps`, which every AVX-512 CPU computes bit for bit the same (the same
//! two machines agree on every golden image).

use std::sync::OnceLock;

/// The identity of the reciprocal approximations Embree's kernels of instruction set `isa` use
/// here: `exact` for `avx512` (architecturally specified), else `rcpps-` and a hash of this CPU's
/// `vrcpps` and `vrsqrtps` results over every 14-bit mantissa prefix of two binades. Two CPUs
/// whose ids differ may render different pixels with the same Embree kernels.
pub fn approx_id(isa: &str) -> String {
    if isa == "avx512" {
        return "exact".into();
    }
    static ID: OnceLock<String> = OnceLock::new();
    ID.get_or_init(|| format!("rcpps-{:016x}", fingerprint())).clone()
}

/// FNV-1a over the bits of `vrcpps(x)` and `vrsqrtps(x)` for x in [1, 4), 2^14 points per binade
/// (the instructions' tables are indexed by the leading mantissa bits; the mid-point of each
/// prefix's interval is used).
fn fingerprint() -> u64 {
    use std::arch::x86_64::{__m256, _mm256_rcp_ps, _mm256_rsqrt_ps};
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for exp in [127u32, 128] {
        for chunk in 0..(1u32 << 14) / 8 {
            let x: [f32; 8] = std::array::from_fn(|l| {
                let prefix = chunk * 8 + l as u32;
                f32::from_bits(exp << 23 | prefix << 9 | 1 << 8)
            });
            // SAFETY: `[f32; 8]` and `__m256` have the same size and every bit pattern is valid
            // for both; the intrinsics need AVX, which the crate is compiled for (x86-64-v3) and
            // `strata` checks at start-up.
            let (r, s) = unsafe {
                let v: __m256 = std::mem::transmute::<[f32; 8], __m256>(x);
                (
                    std::mem::transmute::<__m256, [f32; 8]>(_mm256_rcp_ps(v)),
                    std::mem::transmute::<__m256, [f32; 8]>(_mm256_rsqrt_ps(v)),
                )
            };
            for v in r.iter().chain(&s) {
                for b in v.to_bits().to_le_bytes() {
                    h = (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
                }
            }
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The id is stable within a process, `exact` for AVX-512, and the approximations it hashes
    /// are within their documented error bound (1.5 * 2^-12 relative), so it hashes what it says.
    #[test]
    fn the_id_is_stable_and_hashes_approximations_within_their_bound() {
        assert_eq!(approx_id("avx512"), "exact");
        let a = approx_id("avx2");
        assert!(a.starts_with("rcpps-") && a.len() == 22, "{a}");
        assert_eq!(a, approx_id("avx2"));
        assert_eq!(fingerprint(), fingerprint());
        use std::arch::x86_64::{__m256, _mm256_rcp_ps};
        let x = [1.0f32, 1.1, 1.37, 1.5, 1.999, 2.5, 3.3, 3.99];
        // SAFETY: as in `fingerprint`.
        let r = unsafe {
            std::mem::transmute::<__m256, [f32; 8]>(_mm256_rcp_ps(std::mem::transmute::<[f32; 8], __m256>(x)))
        };
        for (x, r) in x.iter().zip(r) {
            assert!((r * x - 1.0).abs() <= 1.5 / 4096.0, "rcp({x}) = {r}");
        }
    }
}

//! The path wavefront's structure-of-arrays lanes: columns of 32-bit lanes (f32, or u32 by bits)
//! in packets of 8, appended a packet at a time by left-packing the lanes of a mask (one lane
//! permute and one store per column) at a running offset. Live paths and shadow rays so stay in
//! packets from one bounce to the next, with no per-lane copies.

use crate::simd::{Mask8, Vec3x8, F8, U8};
use wide::bytemuck;

/// Permutation that moves the set lanes of a mask to the front, in order, per 8-bit mask.
static LEFT_PACK: [[u32; 8]; 256] = left_pack_table();

const fn left_pack_table() -> [[u32; 8]; 256] {
    let mut t = [[0u32; 8]; 256];
    let mut m = 0;
    while m < 256 {
        let (mut i, mut j) = (0, 0);
        while i < 8 {
            if m & (1 << i) != 0 {
                t[m][j] = i as u32;
                j += 1;
            }
            i += 1;
        }
        m += 1;
    }
    t
}

/// The lanes of one mask, left-packed: the permutation and how many lanes it keeps.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pack {
    idx: U8,
    count: usize,
}

impl Pack {
    /// The left-pack of the set lanes of `m`.
    #[inline]
    pub(super) fn of(m: Mask8) -> Self {
        let bits = m.to_bitmask() as usize & 0xff;
        Self { idx: U8::new(LEFT_PACK[bits]), count: bits.count_ones() as usize }
    }

    /// Lanes kept.
    #[cfg(test)]
    pub(super) fn count(&self) -> usize {
        self.count
    }
}

/// Lane `idx[j]` of `v` in lane j.
#[inline]
fn permute(v: F8, idx: U8) -> F8 {
    bytemuck::cast(crate::simd::permute_lanes(bytemuck::cast(v), idx))
}

/// `K` columns of lanes in packets of 8, each column one run of lanes (column `c`'s packet `p` is
/// `lanes[c * cap + p]`). An append stores the left-packed lanes of a packet whole, unaligned, at
/// the column's running length: the lanes past the kept ones land beyond `len`, where the next
/// append (or [`Columns::fill_tail`]) overwrites them, so no lane below `len` is ever blended or
/// rewritten. (Packet-by-packet rows needed a blend into the last packet, which LLVM turns into
/// masked stores, microcoded on AMD: 30 % of the path tracer's shading time.)
pub(super) struct Columns<const K: usize> {
    lanes: Vec<F8>,
    /// packets per column
    cap: usize,
    len: usize,
}

impl<const K: usize> Default for Columns<K> {
    fn default() -> Self {
        Self { lanes: Vec::new(), cap: 0, len: 0 }
    }
}

impl<const K: usize> Columns<K> {
    /// No lanes (buffers kept).
    #[inline]
    pub(super) fn clear(&mut self) {
        self.len = 0;
    }

    /// Lanes held.
    #[inline]
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// Packets of 8 covering the lanes.
    #[inline]
    pub(super) fn packets(&self) -> usize {
        self.len.div_ceil(8)
    }

    /// Exactly `n` full packets, to be written with [`Columns::set`].
    pub(super) fn set_packets(&mut self, n: usize) {
        self.grow(n + 1);
        self.len = 8 * n;
    }

    /// Makes room for `n` packets (and the spill of a write past them) ahead of the writes.
    pub(super) fn reserve_packets(&mut self, n: usize) {
        self.grow(n + 1);
    }

    /// Makes room for at least `packets` packets per column, keeping every column's packets.
    #[cold]
    fn grow(&mut self, packets: usize) {
        if self.cap < packets {
            let cap = packets.max(2 * self.cap).max(64);
            let mut lanes = vec![F8::ZERO; K * cap];
            if self.cap > 0 {
                for (to, from) in lanes.chunks_exact_mut(cap).zip(self.lanes.chunks_exact(self.cap)) {
                    to[..self.cap].copy_from_slice(from);
                }
            }
            self.lanes = lanes;
            self.cap = cap;
        }
    }

    /// Writes packet `p` of column `c` (p below [`Columns::packets`]).
    #[inline]
    pub(super) fn set(&mut self, c: usize, p: usize, v: F8) {
        self.lanes[c * self.cap + p] = v;
    }

    /// Packet `p` of column `c`.
    #[inline]
    pub(super) fn get(&self, c: usize, p: usize) -> F8 {
        self.lanes[c * self.cap + p]
    }

    /// Packet `p` of column `c` as u32 lanes.
    #[inline]
    pub(super) fn get_u(&self, c: usize, p: usize) -> U8 {
        bytemuck::cast(self.get(c, p))
    }

    /// Packet `p` of columns `c..c + 3` as vectors.
    #[inline]
    pub(super) fn get3(&self, c: usize, p: usize) -> Vec3x8 {
        Vec3x8::new(self.get(c, p), self.get(c + 1, p), self.get(c + 2, p))
    }

    /// Appends the lanes `pack` keeps of `vals` to the columns `first..first + M` at the end;
    /// [`Columns::advance`] then counts them (so several calls can fill one row of columns).
    /// Per column one permute and one whole-packet store at lane `len` (it spills past the kept
    /// lanes, never below `len`).
    #[inline(always)]
    pub(super) fn write<const M: usize>(&mut self, first: usize, pack: &Pack, vals: &[F8; M]) {
        if self.cap < self.len / 8 + 2 {
            self.grow(self.len / 8 + 2);
        }
        let (cap, len) = (8 * self.cap, self.len);
        let flat: &mut [f32] = bytemuck::cast_slice_mut(&mut self.lanes);
        for (j, v) in vals.iter().enumerate() {
            let at = (first + j) * cap + len;
            flat[at..at + 8].copy_from_slice(permute(*v, pack.idx).as_array());
        }
    }

    /// Counts the lanes of the last [`Columns::write`]s.
    #[inline]
    pub(super) fn advance(&mut self, pack: &Pack) {
        self.len += pack.count;
    }

    /// Sets the lanes of column `c` past `len` up to the packet boundary to `v`.
    pub(super) fn fill_tail(&mut self, c: usize, v: F8) {
        let p = self.len / 8;
        if !self.len.is_multiple_of(8) {
            let keep = crate::simd::mask_first(self.len % 8);
            self.set(c, p, keep.select(self.get(c, p), v));
        }
    }
}

/// u32 lanes as the f32 lanes of a column.
#[inline]
pub(super) fn bits(v: U8) -> F8 {
    bytemuck::cast(v)
}

/// Lanes where `v` is not zero (any component; NaN counts as not zero). Adding a zero to a sum
/// that started at +0.0 leaves it unchanged, so these are the lanes worth adding.
#[inline]
pub(super) fn nonzero(v: Vec3x8) -> Mask8 {
    !(v.x.simd_eq(F8::ZERO) & v.y.simd_eq(F8::ZERO) & v.z.simd_eq(F8::ZERO))
}

/// Adds lane i of `v` to pixel sample `slot[i]` of `radiance` (sample `s` is lane `s % 8` of
/// packet `s / 8`) on the lanes of `m` where `v` is not zero.
#[inline]
pub(super) fn add_lanes(radiance: &mut [Vec3x8], slot: U8, v: Vec3x8, m: Mask8) {
    let mut b = (m & nonzero(v)).to_bitmask();
    if b == 0 {
        return;
    }
    let (s, x, y, z) = (slot.to_array(), v.x.to_array(), v.y.to_array(), v.z.to_array());
    while b != 0 {
        let i = b.trailing_zeros() as usize;
        b &= b - 1;
        let (p, l) = (s[i] as usize / 8, s[i] as usize % 8);
        if let Some(r) = radiance.get_mut(p) {
            r.x.as_mut_array()[l] += x[i];
            r.y.as_mut_array()[l] += y[i];
            r.z.as_mut_array()[l] += z[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::mask_from_bools;

    fn lcg(s: &mut u64) -> u32 {
        *s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (*s >> 33) as u32
    }

    /// Appending packets under every mask keeps exactly the masked lanes, in order, across packet
    /// boundaries, bit for bit (NaN payloads included), as a per-lane push would.
    #[test]
    fn left_packed_appends_equal_per_lane_pushes() {
        let mut st = 5u64;
        let mut cols = Columns::<2>::default();
        let mut want: Vec<(u32, u32)> = Vec::new();
        for round in 0..3 {
            cols.clear();
            want.clear();
            for m in 0..256u32 {
                let bools: [bool; 8] = std::array::from_fn(|i| m & (1 << i) != 0);
                let a = U8::new(std::array::from_fn(|_| lcg(&mut st)));
                let b = U8::new(std::array::from_fn(|i| if i == 3 { 0x7fc0_1234 } else { lcg(&mut st) }));
                let pack = Pack::of(mask_from_bools(bools));
                assert_eq!(pack.count(), m.count_ones() as usize);
                cols.write(0, &pack, &[bits(a)]);
                cols.write(1, &pack, &[bits(b)]);
                cols.advance(&pack);
                let (a, b) = (a.to_array(), b.to_array());
                want.extend((0..8).filter(|&i| bools[i]).map(|i| (a[i], b[i])));
            }
            assert_eq!(cols.len(), want.len(), "round {round}");
            cols.fill_tail(0, bits(U8::splat(u32::MAX)));
            for (j, &(a, b)) in want.iter().enumerate() {
                assert_eq!(cols.get_u(0, j / 8).to_array()[j % 8], a);
                assert_eq!(cols.get_u(1, j / 8).to_array()[j % 8], b);
            }
            for j in want.len()..cols.packets() * 8 {
                assert_eq!(cols.get_u(0, j / 8).to_array()[j % 8], u32::MAX);
            }
        }
    }

    /// `add_lanes` adds exactly the masked, non-zero lanes (NaN included) to their samples.
    #[test]
    fn add_lanes_adds_masked_nonzero_lanes_to_their_samples() {
        let mut r = vec![Vec3x8::ZERO; 3];
        let slot = U8::new([0, 9, 23, 5, 17, 1, 2, 3]);
        let v = Vec3x8::new(
            F8::new([1.0, 2.0, 0.0, f32::NAN, 5.0, 0.0, 7.0, 8.0]),
            F8::new([1.0, 0.0, 0.0, 0.0, 5.0, 0.0, 7.0, 8.0]),
            F8::new([1.0, 0.0, 3.0, 0.0, 5.0, -0.0, 7.0, 8.0]),
        );
        add_lanes(&mut r, slot, v, mask_from_bools([true, true, true, true, true, true, false, true]));
        let x = |s: usize| r[s / 8].x.to_array()[s % 8];
        let z = |s: usize| r[s / 8].z.to_array()[s % 8];
        assert_eq!((x(0), x(9), z(23), x(17), x(3)), (1.0, 2.0, 3.0, 5.0, 8.0));
        assert!(x(5).is_nan());
        assert_eq!(x(2), 0.0);
        assert_eq!(z(1).to_bits(), 0.0f32.to_bits());
    }
}

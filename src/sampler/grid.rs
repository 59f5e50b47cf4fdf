//! Grid helpers: the strata shape of an n-point set, its divisors, and exact 24-bit fixed-point
//! cell spans, jitter and centres (used by the stratified and grid-centre layouts and by
//! [`GridTable`](super::GridTable)).

use super::divisor::Divisor;
use super::lanes::Lanes;
use super::permute::PermDomain;

/// Grid shape used for n strata: (nx, ny) with nx * ny == n, nx <= ny, nx the largest divisor of n
/// that is <= sqrt(n). Any n; n == 0 acts as 1, giving (1, 1).
/// A `const fn` (the integer square root is exact), so that [`Grid::new`] can run at compile
/// time for the common set sizes (`multijitter`'s specialised points).
pub const fn strata_shape(n: u32) -> (u32, u32) {
    let n = if n == 0 { 1 } else { n };
    let mut nx = n.isqrt();
    while !n.is_multiple_of(nx) {
        nx -= 1;
    }
    (nx, n / nx)
}

/// Divisors for the set size and the `strata_shape` axes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Grid {
    /// n
    pub(super) n: Divisor,
    /// columns
    pub(super) nx: Divisor,
    /// rows
    pub(super) ny: Divisor,
    /// the domains of keyed permutations of 0..n, 0..nx and 0..ny (`multijitter`'s shuffles)
    pub(super) perm: [PermDomain; 3],
}

impl Grid {
    /// The `strata_shape(n)` grid of n cells (n == 0 acts as 1).
    pub(super) const fn new(n: u32) -> Self {
        let (nx, ny) = strata_shape(n);
        let perm = [PermDomain::new(n), PermDomain::new(nx), PermDomain::new(ny)];
        Self { n: Divisor::new(n), nx: Divisor::new(nx), ny: Divisor::new(ny), perm }
    }
}

/// 1.0 in 24-bit fixed point.
pub(super) const FIXED_ONE: u32 = 1 << 24;

/// 24-bit fixed-point coordinate `floor((c * 2^24 + v) / m)` in cell `c < m` of an m-cell axis, by
/// long division in 8-bit digits (each partial remainder stays < m * 2^8 <= 2^32). For
/// v in [m - 1, 2^24) the result y satisfies c/m <= y/2^24 < (c+1)/m exactly. Cells narrower
/// than 2^-24 (m > 2^24) give `floor(c * 2^24 / m)`, their lower edge rounded down to the grid.
#[inline]
pub(super) fn cell_coord<L: Lanes>(c: L, m: Divisor, v: L) -> L {
    if m.d > FIXED_ONE {
        return c.mulhi(L::splat(((1u64 << 56) / u64::from(m.d)) as u32));
    }
    let (mut y, mut r) = (L::splat(0), c);
    for shift in [16, 8, 0] {
        let (q, rem) = m.div_rem(r.shl(8).or(v.shr(shift).and(L::splat(0xff))));
        y = y.shl(8).or(q);
        r = rem;
    }
    y
}

/// The 24-bit fixed-point points of cell `c` of an m-cell axis: `[lo, hi)` with
/// lo = ceil(c 2^24 / m) and hi = ceil((c+1) 2^24 / m), so every y in it has c/m <= y 2^-24 < (c+1)/m.
/// (Cells narrower than 2^-24 collapse onto their lower edge.)
///
/// Up to 2^16 cells (every grid a sampler draws from in practice: `multijitter`'s fine cells are
/// the set's n, `direct`'s light tables spp x light samples) `lo` is two digits of long division
/// (base 2^16, then 2^8: `c 2^16` fits in 32 bits) and `hi` follows from it: with `2^24 = q m +
/// r`, `c 2^24 + m - 1 = lo m + rem` gives `(c+1) 2^24 + m - 1 = (lo + q) m + rem + r`, and `rem + r
/// < 2m`, so `hi = lo + q + [rem + r >= m]` (2^24 itself for the last cell). Two divisions where
/// [`cell_coord`] twice took six; the same integers, so the same bits.
#[inline(always)]
pub(super) fn cell_span<L: Lanes>(c: L, m: Divisor) -> (L, L) {
    if m.d <= 1 << 16 {
        let v = m.d - 1;
        let (q1, r1) = m.div_rem(c.shl(16).or(L::splat(v >> 8)));
        let (q2, rem) = m.div_rem(r1.shl(8).or(L::splat(v & 0xff)));
        let lo = q1.shl(8).or(q2);
        let (q, r) = (FIXED_ONE / m.d, FIXED_ONE % m.d);
        let carry = rem.add(L::splat(r)).lt_select(L::splat(m.d), L::splat(0), L::splat(1));
        return (lo, lo.add(L::splat(q)).add(carry));
    }
    let v = L::splat(m.d.min(FIXED_ONE) - 1);
    let next = c.add(L::splat(1));
    // cell_coord needs its cell below m: the top edge of the last cell is 2^24 itself.
    let hi = next.lt_select(L::splat(m.d), cell_coord(next, m, v), L::splat(FIXED_ONE));
    (cell_coord(c, m, v), hi)
}

/// A point of `span` picked by the 32-bit hash `h` (uniform up to 2^-32 relative), as f32 in [0, 1).
#[inline]
pub(super) fn jittered<L: Lanes>((lo, hi): (L, L), h: L) -> L::F {
    let w = hi.sub(lo);
    lo.add(h.mulhi(w)).unit24()
}

/// Centre of cell `c` of an m-cell axis in 24-bit fixed point (rounded down).
#[inline]
pub(super) fn cell_centre<L: Lanes>(c: L, m: Divisor) -> L {
    cell_coord(c, m, L::splat(centre_offset(m.d)))
}

/// Offset that puts `cell_coord` at the cell centre (rounded down to the 2^-24 grid).
pub(super) fn centre_offset(m: u32) -> u32 {
    (FIXED_ONE / 2).max(m.min(FIXED_ONE) - 1)
}

//! Per-lane look-ups of a few lights' constants by lane permutes.
//!
//! Next event estimation with one light chosen per lane reads that light's constants (corner,
//! edges, normal, radiance, the warp's row) for each of the 8 lanes: 8 scalar loads and inserts
//! per field, over 100 per packet. A scene of at most 8 rows (lights) keeps each field as one
//! 8-lane column instead, lane j holding row j, and a lane's value is one `vpermps` of the column
//! by the lanes' row numbers ([`crate::simd::permute_lanes`]). The values are the rows' own, so
//! the arithmetic downstream sees the same bits as with the scalar loads.

use crate::simd::{permute_lanes, F8, U8};

/// Most rows a [`LaneTable`] holds (one per lane of a column).
pub const MAX_ROWS: usize = 8;

/// `K` fields of up to [`MAX_ROWS`] rows, stored column by column.
#[derive(Clone, Debug, PartialEq)]
pub struct LaneTable<const K: usize> {
    cols: [U8; K],
}

impl<const K: usize> LaneTable<K> {
    /// The table of `rows` (field bits), or `None` for more than [`MAX_ROWS`] rows. Lanes past
    /// the last row hold zero bits.
    pub fn new(rows: &[[u32; K]]) -> Option<Self> {
        if rows.len() > MAX_ROWS {
            return None;
        }
        let cols = std::array::from_fn(|k| U8::new(std::array::from_fn(|j| rows.get(j).map_or(0, |r| r[k]))));
        Some(Self { cols })
    }

    /// Field `k` of row `rows[j]` in lane j (rows are taken modulo 8).
    #[inline(always)]
    pub fn field(&self, k: usize, rows: U8) -> F8 {
        F8::from_bits(permute_lanes(self.cols[k], rows))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_the_rows_bits_in_every_lane() {
        let rows: Vec<[u32; 3]> = (0..5u32).map(|r| [r, (r as f32 * 1.5).to_bits(), u32::MAX - r]).collect();
        let t = LaneTable::new(&rows).expect("5 rows fit");
        let pick = U8::new([4, 0, 3, 3, 1, 2, 0, 4]);
        for (k, want) in (0..3).map(|k| (k, pick.to_array().map(|j| rows[j as usize][k]))) {
            let got = t.field(k, pick).to_bits().to_array();
            assert_eq!(got, want, "field {k}");
        }
        assert!(LaneTable::<3>::new(&[[0; 3]; 9]).is_none(), "9 rows do not fit a column");
    }
}

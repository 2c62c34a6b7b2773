//! The residual noise of a match by range: range noise grows with the distance on
//! real lasers (σ = a + b·r: the RPLIDAR's 3 mm + 0.5 %·r is 53 mm at 10 m), so one
//! spread for the whole scan is the noise of the near points, and the covariance of a
//! displacement that only far points determine (along a corridor, toward an end wall)
//! comes out many times too small.
//!
//! The correspondences are split by the range of their current point into bins of
//! equal count, and each bin's residual variance is its robust spread (median-based,
//! over every correspondence within the gate: not truncated by the trimming, which
//! would keep of the noisy far points only those that happen to fit).

use crate::consistency::robust_spread;

/// Fewest correspondences in one range bin (the spread of fewer is too noisy).
const MIN_PER_BIN: usize = 20;
/// Most range bins. Enough that the far tail of a scan gets a bin of its own: on the
/// simulated TurtleBot 4 (RPLIDAR to 12 m, σ = 3 mm + 0.5 %·r) the few far local lines
/// (4–6 m) decide the directions along corridors, and bins of 40 or more (6 at most)
/// mixed them with nearer points: 62 of 838 accepted pairs had an error beyond their
/// covariance's 99.7 % level, 42 of 851 with bins of 20 or more (12 at most).
const MAX_BINS: usize = 12;

/// Scratch and result of [`RangeBins::variances`] (reused: no allocation per match
/// once warmed up).
#[derive(Debug, Clone, Default)]
pub(crate) struct RangeBins {
    /// Range of each correspondence's current point (m).
    pub ranges: Vec<f64>,
    /// Squared weighted residual of each correspondence.
    pub squared: Vec<f64>,
    keys: Vec<u64>,
    edges: Vec<usize>,
    scratch: Vec<f64>,
    variance: Vec<f64>,
}

impl RangeBins {
    /// Empties the inputs.
    pub fn clear(&mut self) {
        self.ranges.clear();
        self.squared.clear();
    }

    /// Adds a correspondence: its current point's range and squared weighted residual.
    pub fn push(&mut self, range: f64, squared: f64) {
        self.ranges.push(range);
        self.squared.push(squared);
    }

    /// For each correspondence pushed (in order): the variance of its weighted
    /// residual, the squared robust spread of its range bin (bins of equal count in
    /// the order of the ranges, equal ranges in the order pushed).
    pub fn variances(&mut self) -> &[f64] {
        let m = self.ranges.len().min(self.squared.len());
        // Integers that order as `f32::total_cmp` orders the ranges (to a part in 10⁷,
        // a tenth of a micrometre at 1 m), ties by the order pushed: each range's key
        // with its index in the low bits. A bin is a set of ranks, so the keys are
        // only split at the bins' edges, not sorted.
        self.keys.clear();
        self.keys.extend(
            self.ranges[..m]
                .iter()
                .enumerate()
                .map(|(k, &r)| (u64::from(total_order_key(r as f32)) << 32) | k as u64),
        );
        let bins = (m / MIN_PER_BIN).clamp(1, MAX_BINS);
        self.edges.clear();
        self.edges.extend((1..bins).map(|b| b * m / bins));
        split_at_ranks(&mut self.keys, &self.edges, 0);
        self.variance.clear();
        self.variance.resize(m, 0.0);
        let index = |key: u64| (key & u64::from(u32::MAX)) as usize;
        for b in 0..bins {
            let members = &self.keys[b * m / bins..(b + 1) * m / bins];
            self.scratch.clear();
            self.scratch
                .extend(members.iter().map(|&key| self.squared[index(key)]));
            let spread = robust_spread(&mut self.scratch);
            for &key in members {
                self.variance[index(key)] = spread * spread;
            }
        }
        &self.variance
    }
}

/// Reorders `keys` (the keys of ranks `offset..offset + keys.len()`) so that each
/// rank in `ranks` (increasing, within those) holds the key of that rank, the smaller
/// keys before it and the larger after: the keys between two ranks are then exactly
/// those a sort would put there, found in fewer comparisons.
fn split_at_ranks(keys: &mut [u64], ranks: &[usize], offset: usize) {
    if ranks.is_empty() || keys.is_empty() {
        return;
    }
    let mid = ranks.len() / 2;
    let r = (ranks[mid] - offset).min(keys.len() - 1);
    let (below, _, above) = keys.select_nth_unstable(r);
    split_at_ranks(below, &ranks[..mid], offset);
    split_at_ranks(above, &ranks[mid + 1..], offset + r + 1);
}

/// An unsigned integer that orders as `f32::total_cmp` orders `x`: its bits with the
/// magnitude bits of negative numbers flipped (the transformation `total_cmp` makes),
/// then the sign bit flipped so that negatives come first as unsigned numbers.
fn total_order_key(x: f32) -> u32 {
    let bits = x.to_bits() as i32;
    ((bits ^ ((((bits >> 31) as u32) >> 1) as i32)) as u32) ^ (1 << 31)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::consistency::robust_spread;
    use proptest::prelude::*;

    /// `RangeBins::variances` by its definition: a stable sort comparing the ranges
    /// themselves, as `f32` (ties in the order pushed).
    fn variances_by_range_sort(ranges: &[f64], squared: &[f64]) -> Vec<f64> {
        let m = ranges.len();
        let mut order: Vec<u32> = (0..m as u32).collect();
        order.sort_by(|&a, &b| (ranges[a as usize] as f32).total_cmp(&(ranges[b as usize] as f32)));
        let mut variance = vec![0.0; m];
        let bins = (m / MIN_PER_BIN).clamp(1, MAX_BINS);
        for b in 0..bins {
            let members = &order[b * m / bins..(b + 1) * m / bins];
            let mut scratch: Vec<f64> = members.iter().map(|&k| squared[k as usize]).collect();
            let spread = robust_spread(&mut scratch);
            for &k in members {
                variance[k as usize] = spread * spread;
            }
        }
        variance
    }

    proptest! {
        /// Bit for bit the variances of the sort by range, with many ties (few
        /// distinct ranges, as from a laser reporting millimetres) across the bin
        /// boundaries, and negative zeros, infinities and NaNs among the ranges.
        #[test]
        fn variances_are_those_of_the_sort_by_range(
            pairs in prop::collection::vec((0u16..400, 0u32..1000), 0..700),
            odd in prop::collection::vec(
                prop::sample::select(vec![-0.0, 0.0, f64::INFINITY, f64::NAN, -1.0]),
                0..5,
            ),
        ) {
            let mut bins = RangeBins::default();
            for &(r, e) in &pairs {
                bins.push(f64::from(r) * 0.01, f64::from(e) * 1e-7);
            }
            for &r in &odd {
                bins.push(r, 1e-6);
            }
            let want = variances_by_range_sort(&bins.ranges, &bins.squared);
            let got = bins.variances().to_vec();
            // Compared as bits: NaN spreads must match too.
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
            prop_assert_eq!(bits(&got), bits(&want));
        }

        /// The keys order as `f32::total_cmp` does, on any bit patterns.
        #[test]
        fn keys_order_as_total_cmp(a in any::<u32>(), b in any::<u32>()) {
            let (x, y) = (f32::from_bits(a), f32::from_bits(b));
            prop_assert_eq!(total_order_key(x).cmp(&total_order_key(y)), x.total_cmp(&y));
        }
    }

    #[test]
    fn far_noisy_points_get_their_own_variance() {
        let mut bins = RangeBins::default();
        // 200 near points with residuals ±1 mm, 200 far ones with ±10 mm, interleaved.
        for i in 0..400 {
            let far = i % 2 == 1;
            let e: f64 = if far { 0.010 } else { 0.001 } * if i % 4 < 2 { 1.0 } else { -1.0 };
            bins.push(if far { 5.0 + i as f64 * 1e-3 } else { 1.0 }, e * e);
        }
        let v = bins.variances().to_vec();
        let sigma = |k: usize| v[k].sqrt() / 1.482_602_218_505_602;
        assert!((sigma(0) - 0.001).abs() < 1e-9, "{}", sigma(0));
        assert!((sigma(1) - 0.010).abs() < 1e-9, "{}", sigma(1));
    }

    #[test]
    fn few_correspondences_share_one_bin() {
        let mut bins = RangeBins::default();
        for i in 0..30 {
            bins.push(i as f64, 1e-6 * (1 + i % 3) as f64);
        }
        let v = bins.variances();
        assert!(v.iter().all(|&x| x == v[0]));
    }
}

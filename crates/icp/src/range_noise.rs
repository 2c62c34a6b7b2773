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
    order: Vec<u32>,
    keys: Vec<i64>,
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
    /// residual, the squared robust spread of its range bin.
    pub fn variances(&mut self) -> &[f64] {
        let m = self.ranges.len().min(self.squared.len());
        // The sort compares integer keys that order as `f64::total_cmp` orders the
        // ranges: the same comparisons, hence the same order (ties included), as
        // comparing the ranges themselves, without converting both at every one.
        self.keys.clear();
        self.keys
            .extend(self.ranges[..m].iter().map(|&r| total_order_key(r)));
        let keys = &self.keys;
        self.order.clear();
        self.order.extend(0..m as u32);
        self.order
            .sort_unstable_by(|&a, &b| keys[a as usize].cmp(&keys[b as usize]));
        self.variance.clear();
        self.variance.resize(m, 0.0);
        let bins = (m / MIN_PER_BIN).clamp(1, MAX_BINS);
        for b in 0..bins {
            let members = &self.order[b * m / bins..(b + 1) * m / bins];
            self.scratch.clear();
            self.scratch
                .extend(members.iter().map(|&k| self.squared[k as usize]));
            let spread = robust_spread(&mut self.scratch);
            for &k in members {
                self.variance[k as usize] = spread * spread;
            }
        }
        &self.variance
    }
}

/// An integer that orders as `f64::total_cmp` orders `x` (its bits, with the
/// magnitude bits of negative numbers flipped: the transformation `total_cmp` makes).
fn total_order_key(x: f64) -> i64 {
    let bits = x.to_bits() as i64;
    bits ^ ((((bits >> 63) as u64) >> 1) as i64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::consistency::robust_spread;
    use proptest::prelude::*;

    /// `RangeBins::variances` as it was, sorting by comparing the ranges themselves.
    fn variances_by_range_sort(ranges: &[f64], squared: &[f64]) -> Vec<f64> {
        let m = ranges.len();
        let mut order: Vec<u32> = (0..m as u32).collect();
        order.sort_unstable_by(|&a, &b| ranges[a as usize].total_cmp(&ranges[b as usize]));
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

        /// The keys order as `f64::total_cmp` does, on any bit patterns.
        #[test]
        fn keys_order_as_total_cmp(a in any::<u64>(), b in any::<u64>()) {
            let (x, y) = (f64::from_bits(a), f64::from_bits(b));
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

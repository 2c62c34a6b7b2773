//! Outlier trimming rules: which samples to keep after a solve, given their
//! residuals `ŝ_pred − ŝ`.

use serde::{Deserialize, Serialize};

/// How outliers are removed between closed-form solves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Trim {
    /// ICRA 2008: drop the `fraction` of samples with the largest normalized
    /// residual, re-solve; `rounds` times.
    Icra {
        /// Fraction dropped per round (0.05 in the paper).
        fraction: f64,
        /// Number of rounds (3 in the paper).
        rounds: usize,
    },
    /// The original package (T-RO 2013): per round, thresholds at index
    /// `round((1 − p)·n)` of the sorted `|e_xy|` and of the sorted `|e_θ|`; drop the
    /// samples above either threshold, re-solve; `rounds` times.
    Tro {
        /// Outlier fraction `p` (0.01 in the package).
        p: f64,
        /// Number of rounds (4 in the published results).
        rounds: usize,
    },
    /// Keep every sample.
    None,
}

impl Trim {
    /// The ICRA 2008 rule: 5 %, three rounds.
    pub const ICRA: Trim = Trim::Icra {
        fraction: 0.05,
        rounds: 3,
    };
    /// The original package's rule: p = 1 %, four rounds.
    pub const TRO: Trim = Trim::Tro { p: 0.01, rounds: 4 };

    /// Number of trimming rounds.
    pub fn rounds(&self) -> usize {
        match *self {
            Trim::Icra { rounds, .. } | Trim::Tro { rounds, .. } => rounds,
            Trim::None => 0,
        }
    }

    /// Which of the samples (with these residuals) survive one round of this rule.
    pub fn keep(&self, residuals: &[[f64; 3]]) -> Vec<bool> {
        match *self {
            Trim::Icra { fraction, .. } => icra_keep(residuals, fraction),
            Trim::Tro { p, .. } => tro_keep(residuals, p),
            Trim::None => vec![true; residuals.len()],
        }
    }
}

/// The value at index `index` of `values` once sorted (ascending).
fn order_statistic(values: &mut [f64], index: usize) -> f64 {
    let (_, v, _) = values.select_nth_unstable_by(index, f64::total_cmp);
    *v
}

/// The T-RO rule: keep a sample when `|e_xy|` and `|e_θ|` are both at most the
/// value found at index `round((1 − p)·n)` of their sorted lists (clamped to the
/// last index).
pub fn tro_keep(residuals: &[[f64; 3]], p: f64) -> Vec<bool> {
    let n = residuals.len();
    if n == 0 {
        return Vec::new();
    }
    let index = (((1.0 - p) * n as f64).round() as usize).min(n - 1);
    // Squared |e_xy|: same order, no square root.
    let xy2 = |e: &[f64; 3]| e[0] * e[0] + e[1] * e[1];
    let mut xy: Vec<f64> = residuals.iter().map(xy2).collect();
    let mut th: Vec<f64> = residuals.iter().map(|e| e[2].abs()).collect();
    let t_xy = order_statistic(&mut xy, index);
    let t_th = order_statistic(&mut th, index);
    residuals
        .iter()
        .map(|e| xy2(e) <= t_xy && e[2].abs() <= t_th)
        .collect()
}

/// The ICRA rule: drop the `round(fraction·n)` samples with the largest residual,
/// each component normalized by its root mean square over the samples.
pub fn icra_keep(residuals: &[[f64; 3]], fraction: f64) -> Vec<bool> {
    let n = residuals.len();
    let drop = ((fraction * n as f64).round() as usize).min(n);
    if drop == 0 {
        return vec![true; n];
    }
    let mut rms = [0.0; 3];
    for e in residuals {
        for c in 0..3 {
            rms[c] += e[c] * e[c];
        }
    }
    for r in &mut rms {
        *r = (*r / n as f64).sqrt();
        if r.is_nan() || *r <= 0.0 {
            *r = 1.0;
        }
    }
    let score: Vec<f64> = residuals
        .iter()
        .map(|e| (0..3).map(|c| (e[c] / rms[c]).powi(2)).sum())
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.select_nth_unstable_by(n - drop, |&a, &b| score[a].total_cmp(&score[b]));
    let mut keep = vec![true; n];
    for &k in &order[n - drop..] {
        keep[k] = false;
    }
    keep
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tro_threshold_index() {
        // 200 samples with |e_xy| = k and |e_θ| = 0: index round(0.99·200) = 198 →
        // threshold 198, so only the sample with 199 goes.
        let r: Vec<[f64; 3]> = (0..200).map(|k| [k as f64, 0.0, 0.0]).collect();
        let keep = tro_keep(&r, 0.01);
        assert_eq!(keep.iter().filter(|&&k| !k).count(), 1);
        assert!(!keep[199]);
        // Either threshold drops: a θ outlier with small xy goes too.
        let mut r2 = r.clone();
        r2[3][2] = 1.0;
        r2[4][2] = 0.5;
        let keep = tro_keep(&r2, 0.01);
        assert!(!keep[199] && !keep[3] && keep[4]);
    }

    #[test]
    fn icra_drops_the_worst_fraction() {
        let r: Vec<[f64; 3]> = (0..100).map(|k| [0.0, 0.0, k as f64]).collect();
        let keep = icra_keep(&r, 0.05);
        assert_eq!(keep.iter().filter(|&&k| !k).count(), 5);
        assert!(keep[..95].iter().all(|&k| k));
    }
}

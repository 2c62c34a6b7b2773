//! Clocks that go backwards within a stream. The reader sorts each stream by
//! timestamp; here the file order (by line) is looked at again. Small steps back are
//! records out of order (sorting them is right). A large step back is the clock being
//! reset: records on both sides of it cannot share one time line with the other
//! stream, so only the longest stretch between jumps is kept.

use super::in_file_order;
use crate::finding::{Finding, FindingKind};
use odocal_log::{Origin, Stream};

/// A step back larger than this many median periods (and at least
/// [`MIN_JUMP_S`]) is a clock jump, not records out of order.
pub const JUMP_PERIODS: f64 = 20.0;
/// The smallest step back (s) taken for a clock jump.
pub const MIN_JUMP_S: f64 = 1.0;

/// Keeps the longest stretch of `records` (sorted by time) between clock jumps of
/// their stream (found in file order); reports the jumps and the records out of order.
pub fn keep_longest_run<T: Copy>(
    records: &mut Vec<T>,
    origin: &Origin,
    stream: Stream,
    time: impl Fn(&T) -> f64,
    line: impl Fn(&T) -> u64,
) -> Vec<Finding> {
    let n = records.len();
    if n < 3 || records.iter().all(|r| line(r) == 0) {
        return Vec::new();
    }
    let order = in_file_order(records, &line);
    let times: Vec<f64> = order.iter().map(&time).collect();
    let Some(period) = crate::sync::median_period(&times) else {
        return Vec::new();
    };
    let threshold = (JUMP_PERIODS * period).max(MIN_JUMP_S);
    // Runs of the file order between clock jumps: [start, end) indices.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    let mut small_steps = 0u64;
    let mut first_small: Option<usize> = None;
    let mut jumps: Vec<(usize, f64)> = Vec::new();
    for k in 1..n {
        let step = times[k] - times[k - 1];
        if step < -threshold {
            runs.push((start, k));
            start = k;
            // Back from where the record should have been: one period after the last.
            jumps.push((k, period - step));
        } else if step < 0.0 {
            small_steps += 1;
            first_small.get_or_insert(k);
        }
    }
    runs.push((start, n));
    let mut findings = Vec::new();
    if small_steps > 0 {
        let k = first_small.unwrap_or(0);
        findings.push(
            Finding::note(
                FindingKind::OutOfOrder,
                format!(
                    "{small_steps} {} are out of timestamp order (small steps back, first at \
                     {}); the stream was sorted by timestamp",
                    origin.records(stream),
                    origin.at(stream, line(&order[k]), times[k])
                ),
            )
            .count(small_steps)
            .at(line(&order[k]), times[k]),
        );
    }
    if jumps.is_empty() {
        return findings;
    }
    let (ks, ke) = runs
        .iter()
        .copied()
        .max_by_key(|(s, e)| (e - s, usize::MAX - s))
        .unwrap_or((0, n));
    let (lo, hi) = (line(&order[ks]), line(&order[ke - 1]));
    let dropped = n - (ke - ks);
    records.retain(|r| (lo..=hi).contains(&line(r)));
    let (k, back) = jumps[0];
    let at = line(&order[k]);
    let place = origin.at(stream, at, times[k]);
    findings.push(
        Finding::warning(
            FindingKind::ClockJump,
            format!(
                "the {} clock jumps back {back:.3} s at {place} ({} jump(s) in all); records \
                 on the two sides cannot be put on one time line with the other stream, so \
                 only the longest stretch (from {} to {}) is used and {dropped} {} were left \
                 out; fix the clock (no clock steps while logging) or cut the log at {place}",
                origin.stream(stream),
                jumps.len(),
                origin.at(stream, lo, times[ks]),
                origin.at(stream, hi, times[ke - 1]),
                origin.records(stream)
            ),
        )
        .count(jumps.len() as u64)
        .at(at, times[k]),
    );
    findings
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_jump_back_keeps_the_longest_stretch() {
        // (t, line): 0.0 … 5.9 then the clock back to 1.0 … 3.9.
        let mut r: Vec<(f64, u64)> = (0..60).map(|k| (k as f64 * 0.1, k as u64 + 1)).collect();
        r.extend((0..30).map(|k| (1.0 + k as f64 * 0.1, 61 + k as u64)));
        r.sort_by(|a, b| a.0.total_cmp(&b.0));
        let f = keep_longest_run(&mut r, &Origin::Text, Stream::Scans, |x| x.0, |x| x.1);
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].kind, FindingKind::ClockJump);
        assert_eq!(f[0].first_line, Some(61));
        assert_eq!(r.len(), 60);
        assert!(r.iter().all(|x| x.1 <= 60));
        assert!(r.windows(2).all(|w| w[0].0 <= w[1].0));
    }

    #[test]
    fn small_steps_back_are_out_of_order_only() {
        let mut r: Vec<(f64, u64)> = (0..50).map(|k| (k as f64 * 0.1, k as u64 + 1)).collect();
        r[10].0 = 0.85;
        r.sort_by(|a, b| a.0.total_cmp(&b.0));
        let f = keep_longest_run(&mut r, &Origin::Text, Stream::Wheels, |x| x.0, |x| x.1);
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].kind, FindingKind::OutOfOrder);
        assert_eq!(r.len(), 50);
    }
}

//! Holes in a stream: intervals much longer than its usual period. Pairs across an
//! encoder gap are discarded by the synchronization; this names them.

use super::since;
use crate::finding::{Finding, FindingKind, Severity};
use odocal_log::{Origin, Stream};

/// A step longer than this many median periods (and at least [`MIN_GAP_S`]) is a gap.
pub const GAP_PERIODS: f64 = 5.0;
/// The shortest step (s) reported as a gap.
pub const MIN_GAP_S: f64 = 0.05;

/// Finds the gaps of a stream sorted by time.
pub fn find<T>(
    records: &[T],
    origin: &Origin,
    stream: Stream,
    time: impl Fn(&T) -> f64,
    line: impl Fn(&T) -> u64,
) -> Option<Finding> {
    let times: Vec<f64> = records.iter().map(&time).collect();
    let period = crate::sync::median_period(&times)?;
    let threshold = (GAP_PERIODS * period).max(MIN_GAP_S);
    let (mut count, mut total, mut longest) = (0u64, 0.0f64, (0.0f64, 0usize));
    for k in 1..times.len() {
        let d = times[k] - times[k - 1];
        if d > threshold {
            count += 1;
            total += d;
            if d > longest.0 {
                longest = (d, k);
            }
        }
    }
    if count == 0 {
        return None;
    }
    let span = times[times.len() - 1] - times[0];
    let k = longest.1;
    let share = total / span.max(f64::MIN_POSITIVE);
    Some(
        Finding::new(
            FindingKind::Gap,
            if share > 0.2 {
                Severity::Warning
            } else {
                Severity::Info
            },
            format!(
                "the {} stream has {count} gap(s) longer than {threshold:.3} s ({:.0} % of its \
                 {span:.1} s); the longest, {:.3} s, ends at {} ({}); scan pairs across a gap \
                 are discarded; check the logger for dropped messages",
                origin.stream(stream),
                100.0 * share,
                longest.0,
                origin.at(stream, line(&records[k]), times[k]),
                since(times[k - 1], times[0])
            ),
        )
        .count(count)
        .at(line(&records[k]), times[k - 1]),
    )
}

//! Records logged twice (identical, dropped) and different records sharing one
//! timestamp (timestamps rounded by the logger: encoder records merged, scans kept
//! once), which would otherwise be used twice or give zero-length intervals.

use crate::finding::{Finding, FindingKind};
use odocal_log::{EncoderRecord, Origin, ScanMeta, ScanStore, Stream};

/// True when two scans have the same geometry and bit-identical ranges.
pub(crate) fn same_ranges(store: &ScanStore, a: &ScanMeta, b: &ScanMeta) -> bool {
    if a.geometry != b.geometry {
        return false;
    }
    let n = store
        .geometries
        .get(a.geometry as usize)
        .map_or(0, |g| g.num_readings());
    match (
        store.ranges.get(a.offset..a.offset + n),
        store.ranges.get(b.offset..b.offset + n),
    ) {
        (Some(x), Some(y)) => x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits()),
        _ => false,
    }
}

/// The smallest positive step between consecutive distinct timestamps (s).
fn resolution(times: impl Iterator<Item = f64>) -> f64 {
    let mut prev: Option<f64> = None;
    let mut best = f64::INFINITY;
    for t in times {
        if let Some(p) = prev {
            if t > p {
                best = best.min(t - p);
            }
        }
        prev = Some(t);
    }
    best
}

/// The mean of one wheel's counts over a group, rounded; taken relative to the first
/// count in integer arithmetic, so that counts above 2^53 keep every tick (a mean of
/// the counts as `f64` rounded them to multiples of 16 at 2^56).
fn mean_count(group: &[EncoderRecord], count: impl Fn(&EncoderRecord) -> i64) -> i64 {
    let base = group.first().map_or(0, &count);
    let sum: i128 = group
        .iter()
        .map(|r| i128::from(count(r)) - i128::from(base))
        .sum();
    let mean = (sum as f64 / group.len().max(1) as f64).round() as i128;
    i64::try_from(i128::from(base) + mean).unwrap_or(base)
}

/// Drops exact repeats of encoder records and merges records sharing a timestamp into
/// one (their mean count). `records` is sorted by time.
pub fn encoders(records: &mut Vec<EncoderRecord>, origin: &Origin) -> Vec<Finding> {
    let mut out: Vec<EncoderRecord> = Vec::with_capacity(records.len());
    let (mut repeats, mut merged) = (0u64, 0u64);
    let (mut first_repeat, mut first_merged): (Option<EncoderRecord>, Option<EncoderRecord>) =
        (None, None);
    let mut group: Vec<EncoderRecord> = Vec::new();
    let flush = |group: &mut Vec<EncoderRecord>, out: &mut Vec<EncoderRecord>| {
        if let Some(first) = group.first().copied() {
            out.push(EncoderRecord {
                left: mean_count(group, |r| r.left),
                right: mean_count(group, |r| r.right),
                ..first
            });
        }
        group.clear();
    };
    for rec in records.iter() {
        match group.last() {
            Some(last) if last.t == rec.t => {
                if group
                    .iter()
                    .any(|g| g.left == rec.left && g.right == rec.right)
                {
                    repeats += 1;
                    first_repeat.get_or_insert(*rec);
                } else {
                    merged += 1;
                    first_merged.get_or_insert(*rec);
                    group.push(*rec);
                }
            }
            _ => {
                flush(&mut group, &mut out);
                group.push(*rec);
            }
        }
    }
    flush(&mut group, &mut out);
    let mut findings = Vec::new();
    if let Some(r) = first_repeat {
        findings.push(
            Finding::warning(
                FindingKind::Duplicate,
                format!(
                    "{repeats} {} repeat an earlier one exactly (same timestamp and counts, \
                     first at {}); the repeats were dropped; check that the logger writes each \
                     message once",
                    origin.records(Stream::Wheels),
                    origin.at(Stream::Wheels, r.line, r.t)
                ),
            )
            .count(repeats)
            .at(r.line, r.t),
        );
    }
    if let Some(r) = first_merged {
        let res = resolution(out.iter().map(|r| r.t));
        findings.push(
            Finding::warning(
                FindingKind::TimestampCollision,
                format!(
                    "{merged} {} share their timestamp with a different record (first at \
                     {}; the timestamps step by {res:.3} s at least, as if rounded); the \
                     records of each timestamp were merged into one (their mean count), which \
                     blurs the encoder timing; log timestamps to the microsecond",
                    origin.records(Stream::Wheels),
                    origin.at(Stream::Wheels, r.line, r.t)
                ),
            )
            .count(merged)
            .at(r.line, r.t),
        );
    }
    *records = out;
    findings
}

/// Drops scans repeated exactly (same timestamp and ranges) and keeps only the first
/// of different scans sharing a timestamp. `scans` is sorted by time.
pub fn scans(scans: &mut Vec<ScanMeta>, store: &ScanStore, origin: &Origin) -> Vec<Finding> {
    let mut out: Vec<ScanMeta> = Vec::with_capacity(scans.len());
    let (mut repeats, mut collisions) = (0u64, 0u64);
    let (mut first_repeat, mut first_collision): (Option<ScanMeta>, Option<ScanMeta>) =
        (None, None);
    for s in scans.iter() {
        match out.last() {
            Some(last) if last.t == s.t => {
                if same_ranges(store, last, s) {
                    repeats += 1;
                    first_repeat.get_or_insert(*s);
                } else {
                    collisions += 1;
                    first_collision.get_or_insert(*s);
                }
            }
            _ => out.push(*s),
        }
    }
    let mut findings = Vec::new();
    if let Some(s) = first_repeat {
        findings.push(
            Finding::warning(
                FindingKind::Duplicate,
                format!(
                    "{repeats} {} repeat an earlier one exactly (same timestamp and ranges, \
                     first at {}); the repeats were dropped (used twice they would make the σ's \
                     too small); check that the logger writes each message once",
                    origin.records(Stream::Scans),
                    origin.at(Stream::Scans, s.line, s.t)
                ),
            )
            .count(repeats)
            .at(s.line, s.t),
        );
    }
    if let Some(s) = first_collision {
        findings.push(
            Finding::warning(
                FindingKind::TimestampCollision,
                format!(
                    "{collisions} {} share their timestamp with a different scan (first at \
                     {}); only the first scan of each timestamp was kept; log timestamps to the \
                     microsecond",
                    origin.records(Stream::Scans),
                    origin.at(Stream::Scans, s.line, s.t)
                ),
            )
            .count(collisions)
            .at(s.line, s.t),
        );
    }
    *scans = out;
    findings
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_above_2_pow_53_keep_every_tick() {
        let base = 1i64 << 56;
        let mut recs: Vec<EncoderRecord> = (0..10)
            .map(|k| EncoderRecord {
                t: k as f64 * 0.01,
                left: base + 3 * k,
                right: base - 5 * k,
                line: k as u64 + 1,
            })
            .collect();
        // Two records at one instant: merged into their mean.
        recs.insert(
            5,
            EncoderRecord {
                left: base + 3 * 4 + 2,
                right: base - 5 * 4,
                line: 100,
                ..recs[4]
            },
        );
        let _ = encoders(&mut recs, &Origin::Text);
        assert_eq!(recs.len(), 10);
        for (k, r) in recs.iter().enumerate() {
            let k = k as i64;
            let merged = if k == 4 { 1 } else { 0 };
            assert_eq!(r.left - base, 3 * k + merged, "record {k}");
            assert_eq!(r.right - base, -5 * k, "record {k}");
        }
    }
}

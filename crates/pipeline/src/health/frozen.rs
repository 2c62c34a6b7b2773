//! A laser driver repeating one frozen scan: consecutive scans with different
//! timestamps but bit-identical ranges (a real range finder's noise makes that
//! impossible). The repeats say the robot stood still while the wheels turned.

use super::duplicates::same_ranges;
use super::since;
use crate::finding::{Finding, FindingKind};
use odocal_log::{Origin, ScanMeta, ScanStore, Stream};

/// Drops scans identical to the scan before them. `scans` is sorted by time.
pub fn scans(scans: &mut Vec<ScanMeta>, store: &ScanStore, origin: &Origin) -> Vec<Finding> {
    let total = scans.len();
    let mut out: Vec<ScanMeta> = Vec::with_capacity(total);
    let mut dropped = 0u64;
    let mut first: Option<ScanMeta> = None;
    let (mut run_start, mut longest) = (0.0f64, 0.0f64);
    for s in scans.iter() {
        match out.last() {
            Some(last) if same_ranges(store, last, s) => {
                dropped += 1;
                first.get_or_insert(*s);
                longest = longest.max(s.t - run_start);
            }
            _ => {
                run_start = s.t;
                out.push(*s);
            }
        }
    }
    let Some(f) = first else {
        return Vec::new();
    };
    let t0 = scans.first().map_or(f.t, |s| s.t);
    *scans = out;
    vec![Finding::warning(
        FindingKind::FrozenScan,
        format!(
            "{dropped} of {total} {} are identical to the scan before them (first at {}, {}; \
             the longest frozen stretch lasts {longest:.1} s): the laser driver delivered a \
             frozen scan; the repeats were left out; check the laser's driver and connection",
            origin.records(Stream::Scans),
            origin.at(Stream::Scans, f.line, f.t),
            since(f.t, t0)
        ),
    )
    .count(dropped)
    .at(f.line, f.t)]
}

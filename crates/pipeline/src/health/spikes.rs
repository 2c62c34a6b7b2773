//! Encoder counts that jump at a wheel speed no robot has: an isolated bad record
//! (out and back: dropped) or a jump that stays (a counter reset: bridged with the
//! neighbouring speed, so that no interval sees it).

use super::wraps::steps;
use crate::finding::{Finding, FindingKind};
use odocal_log::{EncoderRecord, Origin, Stream};
use std::f64::consts::TAU;

/// A wheel speed this many times the 99th percentile of the log's speeds is
/// impossible (and at least [`MIN_IMPOSSIBLE_RAD_S`]).
pub const SPEED_FACTOR: f64 = 20.0;
/// The smallest wheel speed (rad/s) taken as impossible: one revolution per 0.1 s.
pub const MIN_IMPOSSIBLE_RAD_S: f64 = 10.0 * TAU;

/// Per step (between records `k`, `k + 1`) and wheel: ticks per second.
fn rates(records: &[EncoderRecord], st: &[[i128; 2]]) -> Vec<[f64; 2]> {
    records
        .windows(2)
        .zip(st)
        .map(|(w, s)| {
            let dt = w[1].t - w[0].t;
            if dt > 0.0 {
                [s[0] as f64 / dt, s[1] as f64 / dt]
            } else {
                [0.0; 2]
            }
        })
        .collect()
}

/// The speed limit (ticks/s) of the log.
fn limit(rates: &[[f64; 2]], ticks_per_revolution: Option<f64>) -> f64 {
    let mut a: Vec<f64> = rates
        .iter()
        .flat_map(|r| [r[0].abs(), r[1].abs()])
        .collect();
    if a.is_empty() {
        return f64::INFINITY;
    }
    let k = ((a.len() - 1) as f64 * 0.99).round() as usize;
    let (_, p99, _) = a.select_nth_unstable_by(k, f64::total_cmp);
    let floor = match ticks_per_revolution {
        Some(t) => MIN_IMPOSSIBLE_RAD_S * t / TAU,
        None => 1000.0,
    };
    (SPEED_FACTOR * *p99).max(floor)
}

/// Drops isolated impossible records and bridges impossible jumps; `records` sorted.
pub fn repair(
    records: &mut Vec<EncoderRecord>,
    ticks_per_revolution: Option<f64>,
    origin: &Origin,
) -> Option<Finding> {
    if records.len() < 3 {
        return None;
    }
    let st = steps(records);
    let rt = rates(records, &st);
    let lim = limit(&rt, ticks_per_revolution);
    // Timestamp jitter can make an ordinary step look fast: a jump must also be large.
    let big = 50.0 * (super::wraps::typical_step(&st) + 1.0);
    let bad = |k: usize, w: usize| rt[k][w].abs() > lim && st[k][w].unsigned_abs() as f64 > big;
    // Isolated spikes: an impossible step out and one back that cancel.
    let mut drop = vec![false; records.len()];
    let mut first: Option<EncoderRecord> = None;
    let mut worst = 0.0f64;
    let mut k = 0;
    while k + 1 < st.len() {
        let spike = (0..2).any(|w| bad(k, w))
            && (0..2).all(|w| {
                !bad(k, w)
                    || (bad(k + 1, w) && {
                        let back = st[k][w] + st[k + 1][w];
                        let dt = records[k + 2].t - records[k].t;
                        dt > 0.0 && (back as f64 / dt).abs() <= lim
                    })
            });
        if spike {
            drop[k + 1] = true;
            first.get_or_insert(records[k + 1]);
            worst = worst.max(rt[k][0].abs()).max(rt[k][1].abs());
            k += 2;
        } else {
            k += 1;
        }
    }
    let spikes = drop.iter().filter(|&&d| d).count() as u64;
    let mut kept: Vec<EncoderRecord> = records
        .iter()
        .zip(&drop)
        .filter(|(_, &d)| !d)
        .map(|(r, _)| *r)
        .collect();
    // Jumps that stay: replace the step by the speed around it.
    let st = steps(&kept);
    let rt = rates(&kept, &st);
    let mut bridged = 0u64;
    let mut counts: Vec<[i128; 2]> = vec![[kept[0].left as i128, kept[0].right as i128]];
    for (k, s) in st.iter().enumerate() {
        let mut next = [0i128; 2];
        for w in 0..2 {
            let mut d = s[w];
            if rt[k][w].abs() > lim && s[w].unsigned_abs() as f64 > big {
                let around: Vec<f64> = [k.checked_sub(1), Some(k + 1)]
                    .into_iter()
                    .flatten()
                    .filter_map(|j| rt.get(j).map(|r| r[w]))
                    .filter(|r| r.abs() <= lim)
                    .collect();
                let rate = around.iter().sum::<f64>() / around.len().max(1) as f64;
                d = (rate * (kept[k + 1].t - kept[k].t)).round() as i128;
                bridged += 1;
                first.get_or_insert(kept[k + 1]);
                worst = worst.max(rt[k][w].abs());
            }
            next[w] = counts[k][w] + d;
        }
        counts.push(next);
    }
    if spikes == 0 && bridged == 0 {
        return None;
    }
    if counts
        .iter()
        .any(|c| i64::try_from(c[0]).is_err() || i64::try_from(c[1]).is_err())
    {
        return None;
    }
    for (r, c) in kept.iter_mut().zip(&counts) {
        r.left = c[0] as i64;
        r.right = c[1] as i64;
    }
    *records = kept;
    let f = first?;
    let speed = match ticks_per_revolution {
        Some(t) => format!("{:.3e} rad/s", worst * TAU / t),
        None => format!("{worst:.3e} ticks/s"),
    };
    Some(
        Finding::warning(
            FindingKind::EncoderSpike,
            format!(
                "the {} jump at a physically impossible wheel speed (up to {speed}, first at \
                 {}): {spikes} isolated bad record(s) were dropped and {bridged} lasting \
                 jump(s) (counter resets) bridged with the speed around them; check the encoder \
                 wiring and the logger",
                origin.records(Stream::Wheels),
                origin.at(Stream::Wheels, f.line, f.t)
            ),
        )
        .count(spikes + bridged)
        .at(f.line, f.t),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recs(n: usize) -> Vec<EncoderRecord> {
        (0..n)
            .map(|k| EncoderRecord {
                t: k as f64 * 0.02,
                left: 3 * k as i64,
                right: -(2 * k as i64),
                line: k as u64 + 1,
            })
            .collect()
    }

    #[test]
    fn an_isolated_spike_is_dropped() {
        let mut r = recs(200);
        r[74].left += 1_000_000_000_000;
        r[90].right = i64::MAX;
        let f = repair(&mut r, Some(1000.0), &Origin::Text).expect("a finding");
        assert_eq!(f.count, 2);
        assert_eq!(f.first_line, Some(75));
        assert_eq!(r.len(), 198);
        assert!(r.windows(2).all(|w| (w[1].left - w[0].left).abs() <= 6));
    }

    #[test]
    fn a_lasting_jump_is_bridged() {
        let mut r = recs(200);
        for x in &mut r[100..] {
            x.left += 5_000_000;
        }
        let f = repair(&mut r, Some(1000.0), &Origin::Text).expect("a finding");
        assert_eq!(f.count, 1);
        assert_eq!(r.len(), 200);
        assert!(r.windows(2).all(|w| w[1].left - w[0].left == 3));
    }

    #[test]
    fn ordinary_counts_are_left_alone() {
        let mut r = recs(200);
        assert!(repair(&mut r, Some(1000.0), &Origin::Text).is_none());
    }
}

//! Encoder counters that wrap (16- or 32-bit registers) in a log that does not give
//! the modulus: the modulus is inferred from the jumps — the power of two they are
//! away from an ordinary step — and the counts are unwrapped.

use crate::finding::{Finding, FindingKind};
use odocal_log::{EncoderRecord, Origin, Stream};

/// Smallest modulus considered: 2^8.
const MIN_BITS: u32 = 8;
/// Largest modulus considered: 2^62.
const MAX_BITS: u32 = 62;

/// The 99th percentile of the absolute steps of both wheels.
pub(crate) fn typical_step(steps: &[[i128; 2]]) -> f64 {
    let mut a: Vec<f64> = steps
        .iter()
        .flat_map(|s| [s[0].unsigned_abs() as f64, s[1].unsigned_abs() as f64])
        .collect();
    if a.is_empty() {
        return 0.0;
    }
    let k = ((a.len() - 1) as f64 * 0.99).round() as usize;
    let (_, v, _) = a.select_nth_unstable_by(k, f64::total_cmp);
    *v
}

/// Per-record steps (left, right) of records sorted by time.
pub(crate) fn steps(records: &[EncoderRecord]) -> Vec<[i128; 2]> {
    records
        .windows(2)
        .map(|w| {
            [
                w[1].left as i128 - w[0].left as i128,
                w[1].right as i128 - w[0].right as i128,
            ]
        })
        .collect()
}

/// The power of two `|step|` is closest to, when `step` minus it is an ordinary step.
fn modulus_of(step: i128, ordinary: f64) -> Option<i128> {
    let a = step.unsigned_abs() as f64;
    let bits = a.log2().round();
    if !(MIN_BITS as f64..=MAX_BITS as f64).contains(&bits) {
        return None;
    }
    let m = 1i128 << bits as u32;
    ((a - m as f64).abs() <= ordinary).then_some(m)
}

/// Infers a counter modulus from jumps of about ±2^k ticks and unwraps the counts.
pub fn unwrap(records: &mut [EncoderRecord], origin: &Origin) -> Option<Finding> {
    let st = steps(records);
    let typical = typical_step(&st);
    let ordinary = 4.0 * (typical + 1.0);
    let big = (50.0 * (typical + 1.0)).max(128.0);
    let jumps: Vec<(usize, i128)> = st
        .iter()
        .enumerate()
        .flat_map(|(k, s)| [(k, s[0]), (k, s[1])])
        .filter(|(_, d)| d.unsigned_abs() as f64 > big)
        .collect();
    let mut moduli: Vec<i128> = jumps
        .iter()
        .filter_map(|(_, d)| modulus_of(*d, ordinary))
        .collect();
    moduli.sort_unstable();
    // The most frequent candidate.
    let m = moduli
        .chunk_by(|a, b| a == b)
        .max_by_key(|c| c.len())
        .map(|c| c[0])?;
    let mut offset = [0i128; 2];
    let mut wraps = 0u64;
    let mut first: Option<usize> = None;
    let mut unwrapped: Vec<[i128; 2]> = Vec::with_capacity(records.len());
    unwrapped.push([records[0].left as i128, records[0].right as i128]);
    for (k, s) in st.iter().enumerate() {
        let mut next = [0i128; 2];
        for w in 0..2 {
            let d = s[w];
            if 2 * d > m && modulus_of(d, ordinary) == Some(m) {
                offset[w] -= m;
                wraps += 1;
                first.get_or_insert(k + 1);
            } else if 2 * d < -m && modulus_of(d, ordinary) == Some(m) {
                offset[w] += m;
                wraps += 1;
                first.get_or_insert(k + 1);
            }
            let raw = if w == 0 {
                records[k + 1].left
            } else {
                records[k + 1].right
            };
            next[w] = raw as i128 + offset[w];
        }
        unwrapped.push(next);
    }
    if unwrapped
        .iter()
        .any(|u| i64::try_from(u[0]).is_err() || i64::try_from(u[1]).is_err())
    {
        return None;
    }
    for (r, u) in records.iter_mut().zip(&unwrapped) {
        r.left = u[0] as i64;
        r.right = u[1] as i64;
    }
    let k = first?;
    let rec = records[k];
    let bits = m.trailing_zeros();
    Some(
        Finding::warning(
            FindingKind::EncoderWrap,
            format!(
                "the encoder counters wrap at {m} (2^{bits}): {wraps} jump(s) of ±{m} ticks, \
                 first at {}, and the log gives no modulus; the counts were unwrapped; add \
                 `PARAM robot_encoder_modulus {m}` to the log or pass `--encoder-modulus {m}`",
                origin.at(Stream::Wheels, rec.line, rec.t)
            ),
        )
        .count(wraps)
        .at(rec.line, rec.t),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recs(counts: &[(i64, i64)]) -> Vec<EncoderRecord> {
        counts
            .iter()
            .enumerate()
            .map(|(k, &(l, r))| EncoderRecord {
                t: k as f64 * 0.02,
                left: l,
                right: r,
                line: k as u64 + 1,
            })
            .collect()
    }

    #[test]
    fn sixteen_bit_counters_are_unwrapped() {
        let truth: Vec<(i64, i64)> = (0..400).map(|k| (65000 + 7 * k, -65000 - 5 * k)).collect();
        let wrapped: Vec<(i64, i64)> = truth
            .iter()
            .map(|&(l, r)| (l.rem_euclid(65536), r.rem_euclid(65536)))
            .collect();
        let mut r = recs(&wrapped);
        let f = unwrap(&mut r, &Origin::Text).expect("a finding");
        assert_eq!(f.kind, FindingKind::EncoderWrap);
        assert!(f.message.contains("65536"), "{}", f.message);
        for (a, b) in r.windows(2).zip(truth.windows(2)) {
            assert_eq!(a[1].left - a[0].left, b[1].0 - b[0].0);
            assert_eq!(a[1].right - a[0].right, b[1].1 - b[0].1);
        }
    }

    #[test]
    fn ordinary_counts_are_left_alone() {
        let mut r = recs(&(0..300).map(|k| (3 * k, -2 * k)).collect::<Vec<_>>());
        let before = r.clone();
        assert!(unwrap(&mut r, &Origin::Text).is_none());
        assert_eq!(r, before);
    }
}

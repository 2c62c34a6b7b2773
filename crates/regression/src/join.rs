//! Joined rows as true joins: a row named `k22-k29` is the calibration of the logs
//! k22 … k29 together ("multiple logs can be joined together", ICRA 2008). Its
//! reproduction simulates one log per component row of the table — each sized as
//! its share of the joined row's samples, all with the joined row's parameters as
//! the truth (one robot) — and calibrates them jointly
//! ([`odocal_pipeline::calibrate_logs`]), each log with its own stages.

use crate::reproduce::Reproduction;
use crate::table::PublishedRow;
use odocal_log::{read_carmen_from, ReadOptions};
use odocal_pipeline::{calibrate_logs, Estimate, JointError, NoProgress, Options, PipelineError};

/// Fewest samples a component log is simulated with; a join whose parts would be
/// smaller is reproduced as one log of the joined row's size.
pub const MIN_COMPONENT_SAMPLES: usize = 100;

/// `"k22"` → `("k", 22)`.
fn numbered(name: &str) -> Option<(&str, u32)> {
    let digits = name.find(|c: char| c.is_ascii_digit())?;
    let (prefix, number) = name.split_at(digits);
    Some((prefix, number.parse().ok()?))
}

/// The component rows of a joined row (`k22-k29`: the rows `k22` … `k29` of `rows`,
/// in table order) with the samples each is simulated with: `target` shared in
/// proportion to their published samples. Empty when `row` is not a join, when no
/// component is in `rows`, or when a part would have fewer than
/// [`MIN_COMPONENT_SAMPLES`].
pub fn join_parts<'a>(
    row: &PublishedRow,
    rows: &'a [PublishedRow],
    target: usize,
) -> Vec<(&'a PublishedRow, usize)> {
    let Some((first, last)) = row.name.split_once('-') else {
        return Vec::new();
    };
    let (Some((prefix, lo)), Some((prefix_hi, hi))) = (numbered(first), numbered(last)) else {
        return Vec::new();
    };
    if prefix != prefix_hi {
        return Vec::new();
    }
    let parts: Vec<&PublishedRow> = rows
        .iter()
        .filter(|r| {
            numbered(&r.name).is_some_and(|(p, n)| p == prefix && (lo..=hi).contains(&n))
                && r.name.len() == first.len()
        })
        .collect();
    let total: u64 = parts.iter().map(|r| r.samples).sum();
    if total == 0 {
        return Vec::new();
    }
    let sized: Vec<(&PublishedRow, usize)> = parts
        .into_iter()
        .map(|r| {
            let n = (target as f64 * r.samples as f64 / total as f64).round() as usize;
            (r, n)
        })
        .collect();
    if sized.iter().any(|(_, n)| *n < MIN_COMPONENT_SAMPLES) {
        return Vec::new();
    }
    sized
}

/// Calibrates the simulated component logs `parts` (name, samples asked, Carmen
/// text) of the joined `row` jointly and returns the comparison material.
pub fn reproduce_join_from_texts(
    row: &PublishedRow,
    parts: &[(String, usize, Vec<u8>)],
    opts: &Options,
) -> Result<Reproduction, JointError> {
    let mut logs = Vec::with_capacity(parts.len());
    for (index, (name, _, text)) in parts.iter().enumerate() {
        let log = read_carmen_from(&text[..], name, &ReadOptions::default()).map_err(|e| {
            JointError::Log {
                index,
                name: name.clone(),
                source: PipelineError::Log(e),
            }
        })?;
        logs.push(log);
    }
    let named: Vec<(&str, &odocal_log::Log)> = parts
        .iter()
        .map(|(n, _, _)| n.as_str())
        .zip(&logs)
        .collect();
    let joint = calibrate_logs(&named, opts, &NoProgress)?;
    Ok(Reproduction {
        row: row.clone(),
        truth: row.truth(),
        target_samples: parts.iter().map(|(_, n, _)| n).sum(),
        estimate: Estimate::of(&joint.joint),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::{parse_table_document, workspace_table_path};

    #[test]
    fn joined_rows_find_their_components() {
        let text = std::fs::read_to_string(workspace_table_path()).unwrap();
        let rows = parse_table_document(&text, &workspace_table_path())
            .unwrap()
            .rows;
        let row = |n: &str| rows.iter().find(|r| r.name == n).unwrap();
        let parts = join_parts(row("k22-k29"), &rows, 10987);
        let names: Vec<&str> = parts.iter().map(|(r, _)| r.name.as_str()).collect();
        assert_eq!(names, ["k22", "k23", "k27", "k28", "k29"]);
        let total: usize = parts.iter().map(|(_, n)| n).sum();
        assert!(total.abs_diff(10987) <= parts.len());
        // k06-k15 misses k06, k09-k11 in the table: the parts it has share its size.
        assert_eq!(join_parts(row("k06-k15"), &rows, 5728).len(), 6);
        // A single row is no join; a join too small for its parts falls back.
        assert!(join_parts(row("k22"), &rows, 2243).is_empty());
        assert!(join_parts(row("k22-k29"), &rows, 1000).is_empty());
    }
}

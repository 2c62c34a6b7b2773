//! Synchronization of the encoder stream with the scan stream.
//!
//! A sample needs, for a pair of scans taken at `t0` and `t1` (laser clock), the wheel
//! rotations over `[t0 − δ, t1 − δ]` on the encoder clock (δ = laser clock − encoder clock, 0
//! unless estimated). Cumulative ticks are interpolated linearly between the two
//! encoder records around each instant; the encoder *profile* inside the interval —
//! the pieces between consecutive encoder records, clipped to the interval — is kept
//! for the non-constant-speed formulas.

use odocal_log::EncoderRecord;
use serde::Serialize;
use std::collections::BTreeMap;

/// Why a scan pair did not become a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DiscardReason {
    /// Both wheels turned less than the stillness threshold over the interval.
    RobotStill,
    /// No encoder record close enough around a scan timestamp (or inside the
    /// interval), or the instant lies outside the encoder stream.
    EncoderGap,
    /// The scan matcher failed (no convergence, too few correspondences, …).
    MatchFailed,
    /// The two scans are further apart in time than allowed (dropped scans).
    IntervalTooLong,
}

impl DiscardReason {
    /// Every reason, in report order.
    pub const ALL: [DiscardReason; 4] = [
        DiscardReason::RobotStill,
        DiscardReason::EncoderGap,
        DiscardReason::MatchFailed,
        DiscardReason::IntervalTooLong,
    ];

    /// The snake_case key used in reports and JSON.
    pub fn key(self) -> &'static str {
        match self {
            DiscardReason::RobotStill => "robot_still",
            DiscardReason::EncoderGap => "encoder_gap",
            DiscardReason::MatchFailed => "match_failed",
            DiscardReason::IntervalTooLong => "interval_too_long",
        }
    }
}

/// How many scan pairs were discarded, per reason (every reason present, possibly 0).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct DiscardCounts(pub BTreeMap<&'static str, usize>);

impl Default for DiscardCounts {
    fn default() -> Self {
        DiscardCounts(DiscardReason::ALL.iter().map(|r| (r.key(), 0)).collect())
    }
}

impl DiscardCounts {
    /// Counts one more discarded pair.
    pub fn add(&mut self, reason: DiscardReason) {
        *self.0.entry(reason.key()).or_insert(0) += 1;
    }

    /// The count for one reason.
    pub fn get(&self, reason: DiscardReason) -> usize {
        self.0.get(reason.key()).copied().unwrap_or(0)
    }

    /// Total over all reasons.
    pub fn total(&self) -> usize {
        self.0.values().sum()
    }
}

/// Two scans that form a candidate sample: indices into the scan store and their
/// timestamps (laser clock, s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanPair {
    /// Index of the first (reference) scan.
    pub first: usize,
    /// Index of the second (current) scan.
    pub second: usize,
    /// Timestamp of the first scan (laser clock).
    pub t0: f64,
    /// Timestamp of the second scan (laser clock).
    pub t1: f64,
}

/// The wanted time between the two scans of a pair (s): long enough that one
/// encoder tick is a small relative error, short enough that scans overlap well.
pub const TARGET_INTERVAL_S: f64 = 0.4;

/// Median of the positive differences between consecutive values (s), `None` when
/// there are fewer than two values or no positive difference.
pub fn median_period(times: &[f64]) -> Option<f64> {
    let mut d: Vec<f64> = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0 && d.is_finite())
        .collect();
    if d.is_empty() {
        return None;
    }
    let mid = d.len() / 2;
    let (_, m, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*m)
}

/// The default stride: the number of scan periods closest to [`TARGET_INTERVAL_S`]
/// (at least 1), so that intervals fall within about 0.3–0.5 s whatever the scan rate.
pub fn default_stride(scan_times: &[f64]) -> usize {
    match median_period(scan_times) {
        Some(p) => ((TARGET_INTERVAL_S / p).round() as usize).max(1),
        None => 1,
    }
}

/// The stride to pair scans taken at `scan_times` at: the one given, or
/// [`default_stride`]; a stride of 0 is refused.
pub fn chosen_stride(
    given: Option<usize>,
    scan_times: &[f64],
) -> Result<usize, crate::PipelineError> {
    match given {
        Some(0) => Err(crate::PipelineError::InvalidSetting(
            "the stride must be at least 1".into(),
        )),
        Some(k) => Ok(k),
        None => Ok(default_stride(scan_times)),
    }
}

/// Pairs of scans `stride` apart, not overlapping: (0, k), (k, 2k), … so that every
/// scan used serves at most twice and consecutive samples chain into a trajectory.
pub fn scan_pairs(scan_times: &[f64], stride: usize) -> Vec<ScanPair> {
    let k = stride.max(1);
    let mut pairs = Vec::with_capacity(scan_times.len() / k);
    let mut i = 0;
    while i + k < scan_times.len() {
        pairs.push(ScanPair {
            first: i,
            second: i + k,
            t0: scan_times[i],
            t1: scan_times[i + k],
        });
        i += k;
    }
    pairs
}

/// One piece of the encoder profile: a duration and the wheel rotations over it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ProfilePiece {
    /// Duration (s).
    pub dt: f64,
    /// Left wheel rotation over the piece (rad).
    pub dphi_l: f64,
    /// Right wheel rotation over the piece (rad).
    pub dphi_r: f64,
}

/// The wheel half of a sample: what the encoders say about one interval.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WheelMotion {
    /// Interval start on the encoder clock (s).
    pub t0: f64,
    /// Interval length (s).
    pub dt: f64,
    /// Left wheel rotation (rad).
    pub dphi_l: f64,
    /// Right wheel rotation (rad).
    pub dphi_r: f64,
    /// The profile inside the interval; the pieces sum to `dt`, `dphi_l`, `dphi_r`.
    pub profile: Vec<ProfilePiece>,
}

/// Thresholds of the synchronization.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyncLimits {
    /// Largest allowed time between the encoder records around an instant, and between
    /// consecutive records inside an interval (s).
    pub max_encoder_gap: f64,
    /// A pair is "still" when both wheels turned less than this many ticks.
    pub still_ticks: f64,
    /// Longest allowed interval between the two scans of a pair (s).
    pub max_interval: f64,
}

impl SyncLimits {
    /// Defaults derived from the streams: encoder gaps up to 5 median encoder periods
    /// (at least 50 ms), stillness below one tick on both wheels, intervals up to 1.5×
    /// the nominal `stride` scan periods.
    pub fn from_streams(encoder_times: &[f64], scan_times: &[f64], stride: usize) -> Self {
        let enc_period = median_period(encoder_times).unwrap_or(0.01);
        let scan_period = median_period(scan_times).unwrap_or(0.1);
        SyncLimits {
            max_encoder_gap: (5.0 * enc_period).max(0.05),
            still_ticks: 1.0,
            max_interval: 1.5 * stride.max(1) as f64 * scan_period,
        }
    }
}

/// Longest piece (s) of an encoder profile: sparser records (counts stored with each
/// scan at 10 Hz, say) are cut into pieces of at most this length on the interpolating
/// curve, so that the profile follows the speed within the span; records at 50 Hz and
/// more are pieces as they are.
pub const MAX_PIECE_S: f64 = 0.025;

/// Most pieces one span between two encoder records is cut into, whatever its length
/// in seconds: the profile's memory stays proportional to the number of records
/// (timestamps in the wrong unit, say nanoseconds, make spans of 10⁸ "seconds" that
/// would otherwise be cut into billions of pieces).
pub const MAX_PIECES_PER_SPAN: usize = 64;

/// A count relative to `base`, exact while the difference is below 2^53 ticks
/// (however large the counts themselves are).
fn relative(count: i64, base: i64) -> f64 {
    (i128::from(count) - i128::from(base)) as f64
}

/// The count rates (ticks/s, left and right) at record `k`: the three-point derivative
/// from the two neighbouring records (the secant of the one segment at the ends of the
/// stream or next to colliding timestamps).
fn slope_at(records: &[EncoderRecord], k: usize) -> (f64, f64) {
    let secant = |j: usize| -> Option<(f64, f64, f64)> {
        let (p, q) = (records.get(j)?, records.get(j + 1)?);
        let h = q.t - p.t;
        (h > 0.0).then(|| {
            (
                h,
                relative(q.left, p.left) / h,
                relative(q.right, p.right) / h,
            )
        })
    };
    let before = k.checked_sub(1).and_then(secant);
    match (before, secant(k)) {
        (Some((h0, l0, r0)), Some((h1, l1, r1))) => (
            (h1 * l0 + h0 * l1) / (h0 + h1),
            (h1 * r0 + h0 * r1) / (h0 + h1),
        ),
        (Some((_, l, r)), None) | (None, Some((_, l, r))) => (l, r),
        (None, None) => (0.0, 0.0),
    }
}

/// The encoder stream, ready for interpolation: each record's counts relative to the
/// first record's, and the count rates at each record, computed once (interpolating at
/// an instant then costs a binary search and a cubic, not integer re-basing and two
/// secants per call: the clock-offset check interpolates some 10⁶ times).
#[derive(Debug, Clone)]
pub struct EncoderTrack<'a> {
    records: &'a [EncoderRecord],
    rad_per_tick: f64,
    /// Every record's counts (left, right) relative to the first record's, taken in
    /// integer arithmetic before they become `f64` (counts above 2^53 would lose
    /// ticks).
    counts: Vec<(f64, f64)>,
    /// The count rates (ticks/s) at every record, from [`slope_at`].
    slopes: Vec<(f64, f64)>,
}

impl<'a> EncoderTrack<'a> {
    /// A track over records sorted by time, with the wheel's ticks per revolution.
    pub fn new(records: &'a [EncoderRecord], ticks_per_revolution: f64) -> Self {
        let base = records.first().map_or((0, 0), |r| (r.left, r.right));
        EncoderTrack {
            records,
            rad_per_tick: std::f64::consts::TAU / ticks_per_revolution,
            counts: records
                .iter()
                .map(|r| (relative(r.left, base.0), relative(r.right, base.1)))
                .collect(),
            slopes: (0..records.len()).map(|k| slope_at(records, k)).collect(),
        }
    }

    /// Record `i`'s counts (left, right) relative to the first record's.
    #[inline]
    fn counts(&self, i: usize) -> (f64, f64) {
        self.counts[i]
    }

    /// The count rates (ticks/s, left and right) at record `k`.
    #[inline]
    fn slope(&self, k: usize) -> (f64, f64) {
        self.slopes[k]
    }

    /// Radians of wheel rotation per tick.
    pub fn rad_per_tick(&self) -> f64 {
        self.rad_per_tick
    }

    /// Index `i` of the records bracketing `t`: `records[i-1].t ≤ t < records[i].t`
    /// (or `t` equal to the last record's time, bracketed by the last two).
    fn bracket(&self, t: f64, max_gap: f64) -> Result<usize, DiscardReason> {
        self.bracket_near(t, max_gap, 0)
    }

    /// [`EncoderTrack::bracket`], trying first the index `hint` and its neighbours
    /// (the answer for a nearby instant) before a binary search; the same answer.
    fn bracket_near(&self, t: f64, max_gap: f64, hint: usize) -> Result<usize, DiscardReason> {
        let n = self.records.len();
        if n < 2 || !t.is_finite() {
            return Err(DiscardReason::EncoderGap);
        }
        // Records sorted by time: `records[j-1].t ≤ t < records[j].t` makes `j` the
        // partition point.
        let brackets =
            |j: usize| j >= 1 && j < n && self.records[j - 1].t <= t && t < self.records[j].t;
        let mut i = [hint, hint.wrapping_sub(1), hint + 1]
            .into_iter()
            .find(|&j| brackets(j))
            .unwrap_or_else(|| self.records.partition_point(|r| r.t <= t));
        if i == n && self.records[n - 1].t == t {
            i = n - 1;
        }
        if i == 0 || i == n {
            return Err(DiscardReason::EncoderGap);
        }
        if self.records[i].t - self.records[i - 1].t > max_gap {
            return Err(DiscardReason::EncoderGap);
        }
        Ok(i)
    }

    /// Cumulative ticks (left, right) at `t` between records `i-1` and `i`: the cubic
    /// Hermite curve through the two records with the slopes of
    /// [`slope_at`]. Exact on counts that grow with constant acceleration
    /// (linear interpolation is not: with encoder records 0.1 s apart, as when the counts
    /// are stored with each scan, its error at the ends of the intervals biased the wheel
    /// radii by about 1σ per 75 s of a 0.6 m/s robot).
    fn ticks_between(&self, i: usize, t: f64) -> (f64, f64) {
        let a = &self.records[i - 1];
        let b = &self.records[i];
        let span = b.t - a.t;
        let (pa, pb) = (self.counts(i - 1), self.counts(i));
        if span.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return pb;
        }
        let u = ((t - a.t) / span).clamp(0.0, 1.0);
        let (sa, sb) = (self.slope(i - 1), self.slope(i));
        let h00 = (1.0 + 2.0 * u) * (1.0 - u) * (1.0 - u);
        let h10 = u * (1.0 - u) * (1.0 - u);
        let h01 = u * u * (3.0 - 2.0 * u);
        let h11 = u * u * (u - 1.0);
        let curve = |pa: f64, pb: f64, ma: f64, mb: f64| {
            h00 * pa + h10 * span * ma + h01 * pb + h11 * span * mb
        };
        (curve(pa.0, pb.0, sa.0, sb.0), curve(pa.1, pb.1, sa.1, sb.1))
    }

    /// Appends the motion from `from` to `to` (time, left and right ticks), both
    /// within the span of records `seg − 1` and `seg`, as pieces of at most
    /// [`MAX_PIECE_S`], their counts read on the interpolating curve.
    fn push_pieces(
        &self,
        profile: &mut Vec<ProfilePiece>,
        seg: usize,
        from: (f64, f64, f64),
        to: (f64, f64, f64),
    ) {
        let n = ((to.0 - from.0) / MAX_PIECE_S - 1e-9)
            .ceil()
            .clamp(1.0, MAX_PIECES_PER_SPAN as f64) as usize;
        let mut prev = from;
        for k in 1..=n {
            let next = if k == n {
                to
            } else {
                let t = from.0 + (to.0 - from.0) * k as f64 / n as f64;
                let (l, r) = self.ticks_between(seg, t);
                (t, l, r)
            };
            profile.push(self.piece(next.0 - prev.0, next.1 - prev.1, next.2 - prev.2));
            prev = next;
        }
    }

    /// Cumulative ticks (left, right) at `t` relative to the first record's counts,
    /// or why they are not known well enough.
    pub fn ticks_at(&self, t: f64, max_gap: f64) -> Result<(f64, f64), DiscardReason> {
        let i = self.bracket(t, max_gap)?;
        Ok(self.ticks_between(i, t))
    }

    /// [`EncoderTrack::ticks_at`] for a run of nearby instants: `hint` holds the
    /// record index found for the previous one (start with 0) and is updated. The
    /// same values, without a binary search per instant.
    pub fn ticks_at_near(
        &self,
        t: f64,
        max_gap: f64,
        hint: &mut usize,
    ) -> Result<(f64, f64), DiscardReason> {
        let i = self.bracket_near(t, max_gap, *hint)?;
        *hint = i;
        Ok(self.ticks_between(i, t))
    }

    /// The wheel motion over `[t0, t1]` (encoder clock), with its profile.
    pub fn motion(
        &self,
        t0: f64,
        t1: f64,
        limits: &SyncLimits,
    ) -> Result<WheelMotion, DiscardReason> {
        if t1.partial_cmp(&t0) != Some(std::cmp::Ordering::Greater) || t1 - t0 > limits.max_interval
        {
            return Err(DiscardReason::IntervalTooLong);
        }
        let i0 = self.bracket(t0, limits.max_encoder_gap)?;
        let i1 = self.bracket(t1, limits.max_encoder_gap)?;
        let (l0, r0) = self.ticks_between(i0, t0);
        let (l1, r1) = self.ticks_between(i1, t1);
        let (dl, dr) = (l1 - l0, r1 - r0);
        if dl.abs() < limits.still_ticks && dr.abs() < limits.still_ticks {
            return Err(DiscardReason::RobotStill);
        }
        // Records strictly inside (t0, t1) are records[i0 .. i1] (those with t ≤ t1
        // after i0); the last may sit exactly at t1, which then closes the interval.
        let mut profile = Vec::with_capacity(i1 - i0 + 1);
        let (mut tp, mut lp, mut rp) = (t0, l0, r0);
        for (k, rec) in self.records[i0..i1].iter().enumerate() {
            if rec.t >= t1 {
                break;
            }
            if rec.t - tp > limits.max_encoder_gap {
                return Err(DiscardReason::EncoderGap);
            }
            // A record at the same instant as the last (colliding timestamps) adds
            // its counts to the next piece, so that the pieces still sum up.
            if rec.t > tp {
                let (l, r) = self.counts(i0 + k);
                self.push_pieces(&mut profile, i0 + k, (tp, lp, rp), (rec.t, l, r));
                (tp, lp, rp) = (rec.t, l, r);
            }
        }
        if t1 > tp {
            self.push_pieces(&mut profile, i1, (tp, lp, rp), (t1, l1, r1));
        }
        Ok(WheelMotion {
            t0,
            dt: t1 - t0,
            dphi_l: dl * self.rad_per_tick,
            dphi_r: dr * self.rad_per_tick,
            profile,
        })
    }

    fn piece(&self, dt: f64, dl: f64, dr: f64) -> ProfilePiece {
        ProfilePiece {
            dt,
            dphi_l: dl * self.rad_per_tick,
            dphi_r: dr * self.rad_per_tick,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(t: f64, left: i64, right: i64) -> EncoderRecord {
        EncoderRecord {
            t,
            left,
            right,
            line: 0,
        }
    }

    fn limits() -> SyncLimits {
        SyncLimits {
            max_encoder_gap: 0.05,
            still_ticks: 1.0,
            max_interval: 1.0,
        }
    }

    /// Records every 10 ms of a left wheel at 100 ticks/s and right at −50 ticks/s.
    fn linear_records(n: usize) -> Vec<EncoderRecord> {
        (0..n)
            .map(|k| rec(k as f64 * 0.01, k as i64, -(k as i64 / 2)))
            .collect()
    }

    #[test]
    fn default_stride_aims_at_0_4_seconds() {
        let t10: Vec<f64> = (0..100).map(|i| i as f64 * 0.1).collect();
        assert_eq!(default_stride(&t10), 4);
        let t5: Vec<f64> = (0..100).map(|i| i as f64 * 0.2).collect();
        assert_eq!(default_stride(&t5), 2);
        let t1: Vec<f64> = (0..100).map(|i| i as f64 * 1.0).collect();
        assert_eq!(default_stride(&t1), 1);
        assert_eq!(default_stride(&[1.0]), 1);
    }

    #[test]
    fn pairs_do_not_overlap() {
        let t: Vec<f64> = (0..10).map(|i| i as f64).collect();
        let p = scan_pairs(&t, 3);
        let idx: Vec<(usize, usize)> = p.iter().map(|p| (p.first, p.second)).collect();
        assert_eq!(idx, vec![(0, 3), (3, 6), (6, 9)]);
        assert_eq!(scan_pairs(&t, 1).len(), 9);
        assert!(scan_pairs(&t[..1], 1).is_empty());
    }

    #[test]
    fn ticks_near_a_hint_are_the_ticks_at_the_instant() {
        // Irregular records with a repeated timestamp; instants walked both ways in
        // steps shorter and longer than the records' spacing, from stale hints too,
        // and beyond both ends.
        let mut recs: Vec<EncoderRecord> = (0..60)
            .map(|k| rec(k as f64 * 0.02 + 0.003 * (k % 3) as f64, 7 * k * k, -5 * k))
            .collect();
        recs[30].t = recs[29].t;
        let track = EncoderTrack::new(&recs, 100.0);
        for step in [0.004, 0.01, 0.03, -0.01, -0.05] {
            for start_hint in [0, 17, 59, 200] {
                let mut hint = start_hint;
                for k in 0..400 {
                    let t = if step > 0.0 { -0.1 } else { 1.3 } + step * k as f64;
                    for gap in [0.05, f64::INFINITY] {
                        let mut h = hint;
                        let near = track.ticks_at_near(t, gap, &mut h);
                        assert_eq!(near, track.ticks_at(t, gap), "t {t}, gap {gap}");
                        if gap.is_infinite() {
                            hint = h;
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn interpolation_is_exact_on_linear_ticks() {
        let recs: Vec<EncoderRecord> = (0..101)
            .map(|k| rec(k as f64 * 0.01, 3 * k, -2 * k))
            .collect();
        let track = EncoderTrack::new(&recs, 100.0);
        let (l, r) = track.ticks_at(0.123, 0.05).unwrap();
        assert!((l - 36.9).abs() < 1e-9 && (r + 24.6).abs() < 1e-9);
        let m = track.motion(0.105, 0.5055, &limits()).unwrap();
        let per = std::f64::consts::TAU / 100.0;
        assert!((m.dt - 0.4005).abs() < 1e-12);
        assert!((m.dphi_l - 300.0 * 0.4005 * per).abs() < 1e-9);
        assert!((m.dphi_r + 200.0 * 0.4005 * per).abs() < 1e-9);
        // Profile: partial piece, 39 whole pieces, partial piece; sums match.
        assert_eq!(m.profile.len(), 41);
        let s: (f64, f64, f64) = m.profile.iter().fold((0.0, 0.0, 0.0), |a, p| {
            (a.0 + p.dt, a.1 + p.dphi_l, a.2 + p.dphi_r)
        });
        assert!((s.0 - m.dt).abs() < 1e-12);
        assert!((s.1 - m.dphi_l).abs() < 1e-9 && (s.2 - m.dphi_r).abs() < 1e-9);
        assert!(m.profile.iter().all(|p| p.dt > 0.0 && p.dt <= 0.01 + 1e-12));
    }

    #[test]
    fn profile_follows_speed_changes() {
        // Left wheel: 0 ticks/record for 20 records then 10 ticks/record.
        let recs: Vec<EncoderRecord> = (0..60)
            .map(|k| rec(k as f64 * 0.01, if k < 20 { 0 } else { 10 * (k - 20) }, k))
            .collect();
        let track = EncoderTrack::new(&recs, 1000.0);
        let m = track.motion(0.1, 0.4, &limits()).unwrap();
        let per = std::f64::consts::TAU / 1000.0;
        assert!((m.dphi_l - 200.0 * per).abs() < 1e-12);
        let early: f64 = m.profile.iter().take(10).map(|p| p.dphi_l).sum();
        assert_eq!(early, 0.0);
        assert!(m.profile[15].dphi_l > 0.0);
    }

    #[test]
    fn sparse_records_are_interpolated_exactly_under_constant_acceleration() {
        // Counts at 10 Hz of wheels accelerating uniformly (as stored with each scan):
        // the motion between instants off the records, and every piece of its
        // profile, are exact (linear interpolation is off by a·Δt²/8 at the ends).
        let angle = |t: f64| 3.0 * t + 40.0 * t * t;
        let recs: Vec<EncoderRecord> = (0..30)
            .map(|k| {
                let t = k as f64 * 0.1;
                rec(t, (1e6 * angle(t)) as i64, (2e6 * angle(t)) as i64)
            })
            .collect();
        let track = EncoderTrack::new(&recs, 1e6 * std::f64::consts::TAU);
        let lim = SyncLimits {
            max_encoder_gap: 0.2,
            ..limits()
        };
        let (t0, t1) = (1.033, 1.433);
        let m = track.motion(t0, t1, &lim).unwrap();
        assert!(
            (m.dphi_l - (angle(t1) - angle(t0))).abs() < 1e-5,
            "{}",
            m.dphi_l
        );
        assert!((m.dphi_r - 2.0 * (angle(t1) - angle(t0))).abs() < 1e-5);
        let mut t = t0;
        for p in &m.profile {
            assert!(p.dt <= MAX_PIECE_S + 1e-12);
            assert!((p.dphi_l - (angle(t + p.dt) - angle(t))).abs() < 1e-5);
            t += p.dt;
        }
        assert!((t - t1).abs() < 1e-12);
    }

    #[test]
    fn records_at_the_interval_ends() {
        let recs: Vec<EncoderRecord> = (0..11)
            .map(|k| rec(k as f64 * 0.1, 10 * k, 10 * k))
            .collect();
        let track = EncoderTrack::new(&recs, 100.0);
        let lim = SyncLimits {
            max_encoder_gap: 0.2,
            ..limits()
        };
        let m = track.motion(0.2, 1.0, &lim).unwrap();
        // Eight record spans of 0.1 s, each cut into four pieces of 25 ms.
        assert_eq!(m.profile.len(), 32);
        assert!((m.dphi_l - 80.0 * std::f64::consts::TAU / 100.0).abs() < 1e-12);
        assert!(track.motion(0.2, 1.0001, &lim).is_err());
    }

    #[test]
    fn pieces_per_span_are_capped_whatever_the_time_unit() {
        // Timestamps in milliseconds read as seconds (records 2000 "s" apart, an
        // interval of 40000 "s"): uncapped, each span would be cut into 80000 pieces
        // (with nanoseconds, 8e10 of them: gigabytes, then an abort).
        let recs: Vec<EncoderRecord> = (0..40)
            .map(|k| rec(k as f64 * 2e3, 10 * k, 10 * k))
            .collect();
        let track = EncoderTrack::new(&recs, 100.0);
        let lim = SyncLimits {
            max_encoder_gap: 1e4,
            still_ticks: 1.0,
            max_interval: 1e5,
        };
        let m = track.motion(1e3, 4.1e4, &lim).unwrap();
        assert!(
            m.profile.len() <= 21 * MAX_PIECES_PER_SPAN,
            "{}",
            m.profile.len()
        );
        let sum: f64 = m.profile.iter().map(|p| p.dt).sum();
        assert!((sum - m.dt).abs() < 1e-6 * m.dt);
    }

    #[test]
    fn counts_above_2_pow_53_keep_every_tick() {
        // The same motion with counts starting at 0 and at 2^56 (where an f64 steps by
        // 16 ticks): the wheel rotations and every piece agree.
        let make = |base: i64| -> Vec<EncoderRecord> {
            (0..60)
                .map(|k| rec(k as f64 * 0.01, base + 7 * k + k * k / 3, base - 5 * k))
                .collect()
        };
        let (small, huge) = (make(0), make(1 << 56));
        let a = EncoderTrack::new(&small, 1000.0)
            .motion(0.105, 0.5, &limits())
            .unwrap();
        let b = EncoderTrack::new(&huge, 1000.0)
            .motion(0.105, 0.5, &limits())
            .unwrap();
        assert_eq!(a.profile.len(), b.profile.len());
        assert!(
            (a.dphi_l - b.dphi_l).abs() < 1e-12,
            "{} {}",
            a.dphi_l,
            b.dphi_l
        );
        assert!((a.dphi_r - b.dphi_r).abs() < 1e-12);
        for (p, q) in a.profile.iter().zip(&b.profile) {
            assert!((p.dphi_l - q.dphi_l).abs() < 1e-12 && (p.dphi_r - q.dphi_r).abs() < 1e-12);
        }
    }

    #[test]
    fn discard_reasons() {
        let recs = linear_records(200);
        let track = EncoderTrack::new(&recs, 100.0);
        let lim = limits();
        // Outside the stream.
        assert_eq!(
            track.motion(-0.5, 0.1, &lim).unwrap_err(),
            DiscardReason::EncoderGap
        );
        assert_eq!(
            track.motion(1.8, 2.5, &lim).unwrap_err(),
            DiscardReason::EncoderGap
        );
        // Too long.
        assert_eq!(
            track.motion(0.1, 1.5, &lim).unwrap_err(),
            DiscardReason::IntervalTooLong
        );
        assert_eq!(
            track.motion(0.5, 0.5, &lim).unwrap_err(),
            DiscardReason::IntervalTooLong
        );
        // Still: less than one tick on each wheel.
        assert_eq!(
            track.motion(0.101, 0.1085, &lim).unwrap_err(),
            DiscardReason::RobotStill
        );
        // A hole in the stream around a scan timestamp and inside an interval.
        let mut holed = linear_records(200);
        holed.drain(50..60);
        let track = EncoderTrack::new(&holed, 100.0);
        assert_eq!(
            track.ticks_at(0.55, 0.05).unwrap_err(),
            DiscardReason::EncoderGap
        );
        assert_eq!(
            track.motion(0.3, 0.55, &lim).unwrap_err(),
            DiscardReason::EncoderGap
        );
        let wide = SyncLimits {
            max_encoder_gap: 0.2,
            ..lim
        };
        assert!(track.motion(0.3, 0.7, &wide).is_ok());
        let strict = SyncLimits {
            max_encoder_gap: 0.05,
            ..lim
        };
        assert_eq!(
            track.motion(0.3, 0.7, &strict).unwrap_err(),
            DiscardReason::EncoderGap
        );
    }

    #[test]
    fn duplicate_timestamps_do_not_divide_by_zero() {
        let recs = vec![
            rec(0.0, 0, 0),
            rec(0.1, 5, 5),
            rec(0.1, 6, 6),
            rec(0.2, 10, 10),
        ];
        let track = EncoderTrack::new(&recs, 100.0);
        let m = track
            .motion(
                0.05,
                0.15,
                &SyncLimits {
                    max_encoder_gap: 0.2,
                    ..limits()
                },
            )
            .unwrap();
        assert!(m.dphi_l.is_finite() && m.profile.iter().all(|p| p.dphi_l.is_finite()));
    }

    #[test]
    fn counts_have_every_reason() {
        let mut c = DiscardCounts::default();
        c.add(DiscardReason::MatchFailed);
        c.add(DiscardReason::MatchFailed);
        assert_eq!(c.get(DiscardReason::MatchFailed), 2);
        assert_eq!(c.total(), 2);
        let json = serde_json::to_string(&c).unwrap();
        assert_eq!(
            json,
            r#"{"encoder_gap":0,"interval_too_long":0,"match_failed":2,"robot_still":0}"#
        );
    }
}

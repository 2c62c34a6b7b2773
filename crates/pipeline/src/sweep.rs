//! Sweep (motion) compensation: a range finder takes its rays one after another
//! (`time_increment` seconds apart, ray 0 at the scan's timestamp), and a robot that
//! moves during the sweep bends the scan. Before matching, every ray is moved into the
//! sensor frame at the scan's *reference time* — the middle of the sweep — using the
//! wheel motion inside the sweep: the encoder profile (wheel speeds constant between
//! encoder records) turned into robot motion with the current estimate of the
//! parameters (`r_L`, `r_R`, `b` for the robot, `ℓ` to carry it to the sensor).
//!
//! The reference time is also the time the synchronization uses for the scan
//! ([`reference_time`]), so the sample's interval runs between the two scans'
//! reference times. Without a sweep (`time_increment` 0) the reference time is the
//! timestamp and nothing is compensated.

use crate::sync::{EncoderTrack, ProfilePiece, SyncLimits};
use odocal_geom::{one_minus_cos_over_x, sin_over_x, wrap_angle, Pose2};
use odocal_log::{ScanRef, ScanStore};
use odocal_solver::Params;

/// The time (s, laser clock) a scan stands for: the middle of its sweep,
/// `timestamp + (n − 1) · time_increment / 2` (the timestamp itself without a sweep).
pub fn reference_time(scan: &ScanRef<'_>) -> f64 {
    scan.t + 0.5 * scan.geometry.sweep_duration()
}

/// True when some scan of the store was swept (a non-zero `time_increment`).
pub fn has_sweep(scans: &ScanStore) -> bool {
    scans.geometries.iter().any(|g| g.time_increment != 0.0)
}

/// The robot's displacement while the wheels turn by `dphi_l`, `dphi_r` (rad) at
/// constant speeds: an arc.
fn wheel_arc(params: &Params, dphi_l: f64, dphi_r: f64) -> Pose2 {
    let (sl, sr) = (params.r_l * dphi_l, params.r_r * dphi_r);
    let ds = 0.5 * (sl + sr);
    let dtheta = (sr - sl) / params.b;
    Pose2::new(
        ds * sin_over_x(dtheta),
        ds * one_minus_cos_over_x(dtheta),
        dtheta,
    )
}

/// Robot poses at the increasing `times` (s, from the start of `profile`), relative to
/// the pose at the start of the profile, integrating the pieces as arcs.
fn poses_along(profile: &[ProfilePiece], params: &Params, times: &[f64]) -> Vec<Pose2> {
    let mut out = Vec::with_capacity(times.len());
    let (mut start, mut at_start) = (0.0, Pose2::IDENTITY);
    let mut k = 0;
    for &t in times {
        // Whole pieces that end before t (the last piece takes whatever is left).
        while k + 1 < profile.len() && start + profile[k].dt <= t {
            let p = &profile[k];
            at_start = at_start.compose(&wheel_arc(params, p.dphi_l, p.dphi_r));
            start += p.dt;
            k += 1;
        }
        let pose = match profile.get(k) {
            Some(p) if p.dt > 0.0 => {
                let u = ((t - start) / p.dt).clamp(0.0, 1.0);
                at_start.compose(&wheel_arc(params, u * p.dphi_l, u * p.dphi_r))
            }
            _ => at_start,
        };
        out.push(pose);
    }
    out
}

/// The scan's ranges and angles as seen from the sensor at the reference time, or
/// `None` when the encoders do not cover the sweep (`time_offset`: laser clock minus
/// encoder clock).
pub fn compensate_scan(
    scan: &ScanRef<'_>,
    track: &EncoderTrack<'_>,
    limits: &SyncLimits,
    params: &Params,
    time_offset: f64,
) -> Option<(Vec<f32>, Vec<f64>)> {
    let g = scan.geometry;
    let n = g.num_readings();
    let sweep = g.sweep_duration();
    if n < 2 || sweep == 0.0 {
        return Some((scan.ranges.to_vec(), g.angles.to_vec()));
    }
    // Times from the first ray fired (ray 0, or the last one when the increment is
    // negative), on the encoder clock.
    let t_first = scan.t - time_offset + sweep.min(0.0);
    let span = sweep.abs();
    let whole = SyncLimits {
        max_interval: f64::INFINITY,
        still_ticks: 0.0,
        ..*limits
    };
    let motion = track.motion(t_first, t_first + span, &whole).ok()?;
    // Query times: every ray in firing order, then the reference (middle).
    let order: Vec<usize> = if g.time_increment > 0.0 {
        (0..n).collect()
    } else {
        (0..n).rev().collect()
    };
    let mut times: Vec<f64> = order
        .iter()
        .map(|&i| g.ray_time_offset(i) - sweep.min(0.0))
        .collect();
    let middle = 0.5 * span;
    let at_middle = times.partition_point(|&t| t < middle);
    times.insert(at_middle, middle);
    let mut robot = poses_along(&motion.profile, params, &times);
    let reference = robot.remove(at_middle).inverse();
    let laser = params.laser;
    let laser_inverse = laser.inverse();
    let mut ranges = scan.ranges.to_vec();
    let mut angles = g.angles.to_vec();
    for (&i, pose) in order.iter().zip(&robot) {
        let r = f64::from(scan.ranges[i]);
        if !(r.is_finite() && r > 0.0) {
            continue;
        }
        let sensor = laser_inverse
            .compose(&reference.compose(pose))
            .compose(&laser);
        let a = g.angles[i];
        let p = sensor.transform_point([r * a.cos(), r * a.sin()]);
        ranges[i] = p[0].hypot(p[1]) as f32;
        angles[i] = a + wrap_angle(p[1].atan2(p[0]) - a);
    }
    Some((ranges, angles))
}

/// The scans as matching should see them for `pairs` (`(first, second)` scan
/// indices): a copy of the store in which every scan of a pair is compensated with
/// `params` (each with its own angle table; other scans are left as they are), and for
/// each pair whether both its scans could be (the encoders cover their sweeps).
pub fn compensated_pairs(
    scans: &ScanStore,
    pairs: &[(usize, usize)],
    track: &EncoderTrack<'_>,
    limits: &SyncLimits,
    params: &Params,
    time_offset: f64,
) -> (ScanStore, Vec<bool>) {
    let mut out = scans.clone();
    let mut covered = vec![None; scans.len()];
    let mut compensate = |i: usize, out: &mut ScanStore| -> bool {
        if let Some(Some(done)) = covered.get(i) {
            return *done;
        }
        let done = compensate_into(out, scans, i, track, limits, params, time_offset);
        if let Some(c) = covered.get_mut(i) {
            *c = Some(done);
        }
        done
    };
    let ok = pairs
        .iter()
        .map(|&(a, b)| {
            let first = compensate(a, &mut out);
            compensate(b, &mut out) && first
        })
        .collect();
    (out, ok)
}

/// Compensates scan `i` of `source` into `out`, a copy of `source` (same scans, same
/// layout): its ranges replaced and its own angle table added. False, and `out` left
/// as it is, when the encoders do not cover the sweep or there is no scan `i`. What
/// [`compensated_pairs`] does for each scan of its pairs, for scans needed later (the
/// intermediate scans of a chain, [`crate::chained`]).
pub fn compensate_into(
    out: &mut ScanStore,
    source: &ScanStore,
    i: usize,
    track: &EncoderTrack<'_>,
    limits: &SyncLimits,
    params: &Params,
    time_offset: f64,
) -> bool {
    let Some(s) = source.get(i) else {
        return false;
    };
    let Some((ranges, angles)) = compensate_scan(&s, track, limits, params, time_offset) else {
        return false;
    };
    let meta = &mut out.scans[i];
    out.ranges[meta.offset..meta.offset + ranges.len()].copy_from_slice(&ranges);
    let mut g =
        odocal_log::ScanGeometry::from_angles(angles, s.geometry.max_range, s.geometry.min_range);
    g.laser_type = s.geometry.laser_type;
    meta.geometry = out.geometries.len() as u32;
    out.geometries.push(g);
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_log::{EncoderRecord, LaserFields, ScanGeometry, ScanKind};

    /// Encoder records (every 10 ms, 100 000 ticks per revolution) of a robot spinning
    /// in place at `omega` rad/s.
    fn spinning_track(params: &Params, omega: f64) -> Vec<EncoderRecord> {
        let ticks_per_rad = 100_000.0 / std::f64::consts::TAU;
        let wheel = omega * params.b / 2.0; // m/s of each wheel rim
        (0..200)
            .map(|k| {
                let t = k as f64 * 0.01;
                EncoderRecord {
                    t,
                    left: (-(wheel / params.r_l) * t * ticks_per_rad).round() as i64,
                    right: ((wheel / params.r_r) * t * ticks_per_rad).round() as i64,
                    line: 0,
                }
            })
            .collect()
    }

    #[test]
    fn a_spin_during_the_sweep_is_undone() {
        // A sensor 0.1 m ahead of the axle, spinning at 1 rad/s and sweeping 0.2 s in
        // front of the wall x = 2 (robot frame at the reference time): compensated,
        // every ray lands on the wall; as logged, the ends of the sweep miss it.
        let params = Params {
            r_l: 0.05,
            r_r: 0.05,
            b: 0.4,
            laser: Pose2::new(0.1, 0.0, 0.0),
        };
        let omega = 1.0;
        let records = spinning_track(&params, omega);
        let track = EncoderTrack::new(&records, 100_000.0);
        let limits = SyncLimits {
            max_encoder_gap: 0.05,
            still_ticks: 1.0,
            max_interval: 1.0,
        };
        let n = 181;
        let fields = LaserFields {
            laser_type: 2,
            start_angle: -1.2,
            fov: 2.4,
            resolution: 2.4 / 180.0,
            max_range: 10.0,
            min_range: 0.0,
            accuracy: 0.0,
            remission_mode: 0,
        };
        let wall_error = |r: &[f32], a: &[f64]| {
            (0..n)
                .map(|i| (0.1 + r[i] as f64 * a[i].cos() - 2.0).abs())
                .fold(0.0, f64::max)
        };
        // Ray 0 first (t0 = 0.5), or, with a negative increment (a driver stamping
        // the last ray), ray 0 last (t0 = 0.7): the reference time is 0.6 either way,
        // and ray i is fired with the robot turned by ω (t0 + i·dt − 0.6).
        for (dt, t0) in [(0.2 / 180.0, 0.5), (-0.2 / 180.0, 0.7)] {
            let geometry = ScanGeometry::new(fields, n).with_timing(dt, 0.0);
            let ranges: Vec<f32> = (0..n)
                .map(|i| {
                    let turn = omega * (t0 + i as f64 * dt - 0.6);
                    let a = geometry.angles[i] + turn;
                    ((2.0 - 0.1 * turn.cos()) / a.cos()) as f32
                })
                .collect();
            let mut store = ScanStore::default();
            store.push(t0, &geometry, &ranges, ScanKind::RawLaser1, 0);
            let scan = store.get(0).unwrap();
            assert!((reference_time(&scan) - 0.6).abs() < 1e-12);
            let (r, a) = compensate_scan(&scan, &track, &limits, &params, 0.0).unwrap();
            // Encoder ticks are whole (1e-5 rev): some 1e-5 m of error remain.
            let compensated = wall_error(&r, &a);
            assert!(compensated < 2e-4, "dt {dt}: compensated {compensated}");
            let raw = wall_error(&ranges, &geometry.angles);
            assert!(raw > 0.1, "dt {dt}: as logged {raw}");
        }
        let geometry = ScanGeometry::new(fields, n).with_timing(0.2 / 180.0, 0.0);
        let ranges = vec![2.0f32; n];
        // Outside the encoder stream: not compensated.
        let mut late = ScanStore::default();
        late.push(5.0, &geometry, &ranges, ScanKind::RawLaser1, 0);
        assert!(compensate_scan(&late.get(0).unwrap(), &track, &limits, &params, 0.0).is_none());
    }

    #[test]
    fn zero_increment_changes_nothing() {
        let g = ScanGeometry::urg_04lx();
        let mut store = ScanStore::default();
        let ranges = vec![1.5f32; g.num_readings()];
        store.push(3.0, &g, &ranges, ScanKind::RawLaser1, 0);
        assert!(!has_sweep(&store));
        let s = store.get(0).unwrap();
        assert_eq!(reference_time(&s), 3.0);
        let track = EncoderTrack::new(&[], 100.0);
        let limits = SyncLimits {
            max_encoder_gap: 0.05,
            still_ticks: 1.0,
            max_interval: 1.0,
        };
        let (r, a) =
            compensate_scan(&s, &track, &limits, &Params::from_vector([0.1; 6]), 0.0).unwrap();
        assert_eq!(r, ranges);
        assert_eq!(a[..], g.angles[..]);
    }
}

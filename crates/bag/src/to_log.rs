//! The chosen topics as an [`odocal_log::Log`], the same model Carmen logs are read
//! into: scans with their geometry (sweep timing kept), wheel angles as encoder
//! records at [`WHEEL_TICKS_PER_REVOLUTION`], odometry poses as `ODOM` records.

use crate::collect::{Collected, JointRecord, ScanRecord, Skipped};
use crate::error::{self, BagError};
use crate::scan_check::scan_problem;
use crate::select::{Selection, WheelSource};
use odocal_log::{
    ticks_of_angle, BagClock, EncoderRecord, LaserFields, Log, OdomRecord, Origin, ReadOptions,
    ScanGeometry, ScanKind, ValueSource, WHEEL_TICKS_PER_REVOLUTION,
};
use std::collections::BTreeMap;

/// Which clock stamps the messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Clock {
    /// The message's header stamp: when the data was acquired (default).
    #[default]
    Header,
    /// When the bag recorded the message (`--use-receive-time`).
    Receive,
}

fn seconds(clock: Clock, stamp_ns: i64, receive_ns: u64) -> f64 {
    match clock {
        Clock::Header => stamp_ns as f64 * 1e-9,
        Clock::Receive => receive_ns as f64 * 1e-9,
    }
}

/// The geometry of one LaserScan, overrides applied.
fn geometry(rec: &ScanRecord, opts: &ReadOptions) -> ScanGeometry {
    let f = &rec.fields;
    let fields = LaserFields {
        laser_type: 0,
        start_angle: f.angle_min as f64,
        fov: f.angle_max as f64 - f.angle_min as f64,
        resolution: f.angle_increment as f64,
        max_range: f.range_max as f64,
        min_range: opts.min_range.unwrap_or(f.range_min as f64),
        accuracy: 0.0,
        remission_mode: 0,
    };
    let time_increment = opts.time_increment.unwrap_or(f.time_increment as f64);
    ScanGeometry::new(fields, rec.len).with_timing(time_increment, f.scan_time as f64)
}

/// True when two scans have the same geometry fields.
fn same_fields(a: &ScanRecord, b: &ScanRecord) -> bool {
    let (x, y) = (&a.fields, &b.fields);
    a.len == b.len
        && x.angle_min.to_bits() == y.angle_min.to_bits()
        && x.angle_max.to_bits() == y.angle_max.to_bits()
        && x.angle_increment.to_bits() == y.angle_increment.to_bits()
        && x.time_increment.to_bits() == y.time_increment.to_bits()
        && x.scan_time.to_bits() == y.scan_time.to_bits()
        && x.range_min.to_bits() == y.range_min.to_bits()
        && x.range_max.to_bits() == y.range_max.to_bits()
}

/// Time (s), wheel positions (rad) and wheel velocities (rad/s), left and right.
type WheelSample = (f64, (f64, f64), (f64, f64));

/// The wheel angles (rad) of one JointState message, when it has both wheels.
fn wheel_values(rec: &JointRecord, left: u32, right: u32) -> Option<((f64, f64), (f64, f64))> {
    let find = |j| rec.values.iter().find(|v| v.joint == j);
    let (l, r) = (find(left)?, find(right)?);
    Some(((l.position, r.position), (l.velocity, r.velocity)))
}

/// Builds the log of the selected topics.
pub(crate) fn build_log(
    file: &str,
    c: &Collected,
    sel: &Selection,
    clock: Clock,
    opts: &ReadOptions,
) -> Result<Log, BagError> {
    let mut log = Log::default();
    log.stats.source = file.to_string();
    log.stats.origin = Origin::Bag {
        scan_topic: sel.scan_topic.clone(),
        wheel_topic: match &sel.wheels {
            WheelSource::JointStates { topic, .. } | WheelSource::Odometry { topic } => {
                topic.clone()
            }
        },
        clock: match clock {
            Clock::Header => BagClock::HeaderStamp,
            Clock::Receive => BagClock::ReceiveTime,
        },
    };
    let mut messages = BTreeMap::new();

    // Scans.
    let scan_i = c
        .topic_index(&sel.scan_topic)
        .filter(|i| c.scans.contains_key(i));
    let Some(scan_i) = scan_i else {
        return Err(BagError::choice(
            file,
            format!("topic {}: no scan was decoded", sel.scan_topic),
        ));
    };
    let topic = &c.scans[&scan_i];
    let own_time_increment = opts.time_increment.is_none();
    let mut skipped = topic.undecodable.clone();
    let mut last: Option<(&ScanRecord, ScanGeometry)> = None;
    let mut used = 0u64;
    for (k, rec) in topic.records.iter().enumerate() {
        let g = match &last {
            Some((prev, g)) if same_fields(prev, rec) => g.clone(),
            _ => {
                if let Some(why) = scan_problem(&rec.fields, rec.len, own_time_increment) {
                    let mut bad = Skipped::default();
                    bad.add(k as u64, rec.receive_ns, || why);
                    skipped.merge(&bad);
                    continue;
                }
                geometry(rec, opts)
            }
        };
        let t = seconds(clock, rec.fields.stamp_ns, rec.receive_ns);
        let ranges = &topic.ranges[rec.offset..rec.offset + rec.len];
        log.scans
            .push(t, &g, ranges, ScanKind::LaserScan, k as u64 + 1);
        used += 1;
        last = Some((rec, g));
    }
    if let Some((index, receive_ns, why)) = &skipped.first {
        let text = format!(
            "topic {}: {} malformed scan message(s) skipped, the first (message {index}, \
             received at {} s): {why}",
            sel.scan_topic,
            skipped.count,
            error::seconds(*receive_ns)
        );
        if used == 0 {
            return Err(BagError::choice(
                file,
                format!("{text}; no usable scan remains: choose another topic with --scan-topic"),
            ));
        }
        log.stats.warnings.push(text);
    }
    messages.insert(format!("LaserScan {}", sel.scan_topic), used);
    if let Some(g) = log.scans.geometries.first() {
        log.params.laser_min_range = g.min_range;
        log.params.laser_time_increment = Some(g.time_increment);
    }

    // Wheels.
    match &sel.wheels {
        WheelSource::JointStates {
            topic: name,
            left,
            right,
            integrated_velocities,
        } => {
            let i = c.topic_index(name);
            let joints = i.and_then(|i| c.joints.get(&i));
            let ids = joints.and_then(|j| Some((j.joint(left)?, j.joint(right)?)));
            let (Some(joints), Some((li, ri))) = (joints, ids) else {
                return Err(BagError::choice(
                    file,
                    format!("topic {name}: no wheel joints"),
                ));
            };
            let mut angle = (0.0, 0.0);
            let mut prev: Option<(f64, (f64, f64))> = None;
            let mut used = 0u64;
            let mut without = 0u64;
            let mut samples: Vec<WheelSample> = joints
                .records
                .iter()
                .filter_map(|rec| {
                    let v = wheel_values(rec, li, ri);
                    if v.is_none() {
                        without += 1;
                    }
                    let (p, w) = v?;
                    Some((seconds(clock, rec.stamp_ns, rec.receive_ns), p, w))
                })
                .collect();
            // Velocities are integrated in time order.
            samples.sort_by(|a, b| a.0.total_cmp(&b.0));
            for (k, (t, p, w)) in samples.iter().enumerate() {
                let a = if *integrated_velocities {
                    if !(w.0.is_finite() && w.1.is_finite()) {
                        return Err(velocity_missing(file, name, k));
                    }
                    if let Some((t0, w0)) = prev {
                        let dt = t - t0;
                        angle.0 += 0.5 * (w0.0 + w.0) * dt;
                        angle.1 += 0.5 * (w0.1 + w.1) * dt;
                    }
                    prev = Some((*t, *w));
                    angle
                } else {
                    *p
                };
                let (Some(l), Some(r)) = (ticks_of_angle(a.0), ticks_of_angle(a.1)) else {
                    return Err(BagError::choice(
                        file,
                        format!(
                            "topic {name}: wheel message {k} has no finite position for {left} \
                             and {right}; choose other joints with --wheel-joints or the \
                             odometry with --odom-topic"
                        ),
                    ));
                };
                log.encoders.push(EncoderRecord {
                    t: *t,
                    left: l,
                    right: r,
                    line: k as u64 + 1,
                });
                used += 1;
            }
            if used == 0 {
                return Err(BagError::choice(
                    file,
                    format!(
                        "topic {name}: no message carries both {left} and {right}; choose the \
                         joints with --wheel-joints LEFT,RIGHT"
                    ),
                ));
            }
            if without > 0 {
                log.stats.warnings.push(format!(
                    "{without} message(s) of {name} without both wheel joints were skipped"
                ));
            }
            if *integrated_velocities {
                log.stats.warnings.push(format!(
                    "{name} carries no joint positions: the wheel velocities of {left} and \
                     {right} were integrated (trapezoid rule)"
                ));
            }
            log.params.ticks_per_revolution =
                Some((WHEEL_TICKS_PER_REVOLUTION, ValueSource::Convention));
            messages.insert(format!("JointState {name}"), used);
        }
        WheelSource::Odometry { topic: name } => {
            let recs = c.topic_index(name).and_then(|i| c.odom.get(&i));
            let Some(recs) = recs else {
                return Err(BagError::choice(
                    file,
                    format!("topic {name}: no odometry decoded"),
                ));
            };
            for (k, (m, receive_ns)) in recs.iter().enumerate() {
                log.odom.push(OdomRecord {
                    t: seconds(clock, m.stamp_ns, *receive_ns),
                    pose: odocal_geom::Pose2 {
                        x: m.x,
                        y: m.y,
                        theta: m.yaw,
                    },
                    tv: m.v,
                    rv: m.w,
                    accel: 0.0,
                    line: k as u64 + 1,
                });
            }
            log.odom.sort_by(|a, b| a.t.total_cmp(&b.t));
            messages.insert(format!("Odometry {name}"), recs.len() as u64);
        }
    }

    log.encoders.sort_by(|a, b| a.t.total_cmp(&b.t));
    log.scans.sort_by_time();
    log.stats.messages = messages;
    log.stats.warnings.extend(c.warnings.iter().cloned());
    log.stats.invalid_readings = log.scans.count_invalid_readings();
    Ok(log)
}

fn velocity_missing(file: &str, topic: &str, k: usize) -> BagError {
    BagError::choice(
        file,
        format!(
            "topic {topic}: wheel message {k} has neither positions nor velocities for the \
             wheel joints; use the odometry with --odom-topic"
        ),
    )
}

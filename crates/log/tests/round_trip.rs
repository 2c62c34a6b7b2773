//! Write → read is exact: every timestamp, tick count, reading, remission and geometry
//! field comes back bit for bit.

use odocal_geom::Pose2;
use odocal_log::{
    read_carmen_from, write_log, LaserFields, LogWriter, OdomRecord, ReadOptions, RobotLaserPoses,
    ScanGeometry, ScanKind,
};
use proptest::prelude::*;

/// One record to write.
#[derive(Debug, Clone)]
enum Record {
    Encoder(i64, i64),
    Scan {
        geometry: usize,
        robot: bool,
        ranges: Vec<f32>,
        remissions: Vec<f32>,
    },
    FLaser(Vec<f32>),
    Odom([f64; 6]),
}

fn same_f32(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

fn geometry_strategy() -> impl Strategy<Value = ScanGeometry> {
    (
        0i32..5,
        -4.0f64..0.0,
        1e-4f64..0.1,
        prop_oneof![Just(4.0f64), 0.5f64..100.0, Just(f64::INFINITY)],
        any::<f64>().prop_filter("finite", |v| v.is_finite()),
        0i32..3,
        0usize..40,
    )
        .prop_map(|(lt, start, res, max, acc, rm, n)| {
            let fields = LaserFields {
                laser_type: lt,
                start_angle: start,
                fov: n.saturating_sub(1) as f64 * res,
                resolution: res,
                max_range: max,
                min_range: 0.02,
                accuracy: acc,
                remission_mode: rm,
            };
            ScanGeometry::new(fields, n)
        })
}

fn records_strategy() -> impl Strategy<Value = (Vec<ScanGeometry>, Vec<(f64, Record)>)> {
    let ranges = prop::collection::vec(any::<f32>(), 0..40);
    (
        prop::collection::vec(geometry_strategy(), 1..3),
        prop::collection::vec(
            (
                0u8..4,
                any::<(i64, i64)>(),
                0usize..2,
                any::<bool>(),
                ranges.clone(),
                prop::collection::vec(any::<f32>(), 0..4),
                any::<[f64; 6]>(),
                1e-6f64..1.0,
            ),
            0..40,
        ),
    )
        .prop_map(|(geoms, raw)| {
            let mut t = 1.19e9;
            let recs = raw
                .into_iter()
                .map(|(k, ticks, g, robot, ranges, rem, odom, dt)| {
                    t += dt;
                    let g = g % geoms.len();
                    let rec = match k {
                        0 => Record::Encoder(ticks.0, ticks.1),
                        1 => {
                            let n = geoms[g].num_readings();
                            let mut r: Vec<f32> = ranges.into_iter().take(n).collect();
                            r.resize(n, 1.5);
                            Record::Scan {
                                geometry: g,
                                robot,
                                ranges: r,
                                remissions: rem,
                            }
                        }
                        2 => Record::FLaser(ranges),
                        _ => Record::Odom(odom.map(|v| if v.is_finite() { v } else { 0.5 })),
                    };
                    (t, rec)
                })
                .collect();
            (geoms, recs)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn writer_output_reads_back_exactly((geoms, recs) in records_strategy()) {
        let mut w = LogWriter::new(Vec::new(), "robot 1");
        w.comment("generated\nby a property test").unwrap();
        w.param("robot_wheel_ticks_per_revolution", 2764.8).unwrap();
        for (t, r) in &recs {
            match r {
                Record::Encoder(l, rr) => w.encoder(*t, *l, *rr).unwrap(),
                Record::Scan { geometry, robot: false, ranges, remissions } => w
                    .rawlaser1_with_remissions(*t, &geoms[*geometry], ranges, remissions)
                    .unwrap(),
                Record::Scan { geometry, robot: true, ranges, remissions } => w
                    .robotlaser1_with_remissions(*t, &geoms[*geometry], ranges, remissions, &RobotLaserPoses::default())
                    .unwrap(),
                Record::FLaser(ranges) => w.flaser(*t, ranges, Pose2::default(), Pose2::new(1.0, 2.0, 0.5)).unwrap(),
                Record::Odom(o) => w.odom(&OdomRecord {
                    t: *t,
                    pose: Pose2 { x: o[0], y: o[1], theta: o[2] },
                    tv: o[3],
                    rv: o[4],
                    accel: o[5],
                    line: 0,
                }).unwrap(),
            }
        }
        let bytes = w.into_inner();
        let log = read_carmen_from(&bytes[..], "rt", &ReadOptions::default()).unwrap();
        prop_assert_eq!(log.stats.lines as usize, recs.len() + 3);
        prop_assert_eq!(log.params.ticks_per_revolution.as_ref().map(|p| p.0), Some(2764.8));
        let (mut ie, mut is, mut io) = (0, 0, 0);
        for (t, r) in &recs {
            match r {
                Record::Encoder(l, rr) => {
                    let e = log.encoders[ie];
                    prop_assert_eq!((e.t, e.left, e.right), (*t, *l, *rr));
                    ie += 1;
                }
                Record::Scan { geometry, robot, ranges, remissions } => {
                    let s = log.scans.get(is).unwrap();
                    is += 1;
                    prop_assert_eq!(s.t, *t);
                    prop_assert_eq!(s.kind, if *robot { ScanKind::RobotLaser1 } else { ScanKind::RawLaser1 });
                    prop_assert_eq!(s.geometry, &geoms[*geometry]);
                    prop_assert!(s.ranges.len() == ranges.len() && s.ranges.iter().zip(ranges).all(|(a, b)| same_f32(*a, *b)));
                    prop_assert!(s.remissions.len() == remissions.len() && s.remissions.iter().zip(remissions).all(|(a, b)| same_f32(*a, *b)));
                }
                Record::FLaser(ranges) => {
                    let s = log.scans.get(is).unwrap();
                    is += 1;
                    prop_assert_eq!(s.t, *t);
                    prop_assert_eq!(s.kind, ScanKind::FLaser);
                    prop_assert!(s.ranges.len() == ranges.len() && s.ranges.iter().zip(ranges).all(|(a, b)| same_f32(*a, *b)));
                }
                Record::Odom(o) => {
                    let rec = log.odom[io];
                    io += 1;
                    prop_assert_eq!(rec.t, *t);
                    prop_assert_eq!([rec.pose.x, rec.pose.y, rec.pose.theta, rec.tv, rec.rv, rec.accel], *o);
                }
            }
        }
        prop_assert_eq!((ie, is, io), (log.encoders.len(), log.scans.len(), log.odom.len()));

        // And a whole Log written by write_log reads back to the same records.
        let mut again = Vec::new();
        write_log(&mut again, &log).unwrap();
        let log2 = read_carmen_from(&again[..], "rt2", &ReadOptions::default()).unwrap();
        let strip = |l: &odocal_log::Log| l.encoders.iter().map(|e| (e.t, e.left, e.right)).collect::<Vec<_>>();
        prop_assert_eq!(strip(&log), strip(&log2));
        prop_assert_eq!(log.scans.len(), log2.scans.len());
        for (a, b) in log.scans.iter().zip(log2.scans.iter()) {
            prop_assert_eq!(a.t, b.t);
            prop_assert_eq!(a.kind, b.kind);
            prop_assert_eq!(a.geometry, b.geometry);
            prop_assert!(a.ranges.iter().zip(b.ranges).all(|(x, y)| same_f32(*x, *y)));
            prop_assert!(a.remissions.iter().zip(b.remissions).all(|(x, y)| same_f32(*x, *y)));
        }
        prop_assert_eq!(log.odom.len(), log2.odom.len());
        for (a, b) in log.odom.iter().zip(&log2.odom) {
            prop_assert_eq!((a.t, a.pose, a.tv, a.rv, a.accel), (b.t, b.pose, b.tv, b.rv, b.accel));
        }
    }
}

#[test]
fn writer_rejects_what_the_format_cannot_hold() {
    let mut w = LogWriter::new(Vec::new(), "");
    let g = ScanGeometry::urg_04lx();
    assert!(w.rawlaser1(1.0, &g, &[1.0; 3]).is_err());
    assert!(w.encoder(f64::NAN, 1, 2).is_err());
    assert!(w.param("two words", 1).is_err());
    let uneven = ScanGeometry::from_angles(vec![0.0, 0.1, 0.3], 4.0, 0.02);
    assert!(w.rawlaser1(1.0, &uneven, &[1.0; 3]).is_err());
    w.encoder(1.0, 1, 2).unwrap();
    w.raw_line("garbage !!").unwrap();
    let text = String::from_utf8(w.into_inner()).unwrap();
    assert_eq!(text, "ENCODER 1 2 1 odocal 1\ngarbage !!\n");
}

#[test]
fn urg_04lx_scan_line_matches_the_spec_layout() {
    let g = ScanGeometry::urg_04lx();
    let ranges = vec![1.25f32; 681];
    let mut w = LogWriter::new(Vec::new(), "khepera");
    w.rawlaser1(1190000000.5, &g, &ranges).unwrap();
    let text = String::from_utf8(w.into_inner()).unwrap();
    let tokens: Vec<&str> = text.split_whitespace().collect();
    assert_eq!(tokens.len(), 1 + 8 + 681 + 1 + 3);
    assert_eq!(tokens[0], "RAWLASER1");
    assert_eq!(tokens[1], "2");
    assert_eq!(tokens[8], "681");
    assert_eq!(
        tokens[tokens.len() - 3..],
        ["1190000000.5", "khepera", "1190000000.5"]
    );
    let log = read_carmen_from(text.as_bytes(), "urg", &ReadOptions::default()).unwrap();
    assert_eq!(log.scans.geometries[0], g);
    assert!(log.stats.warnings.is_empty(), "{:?}", log.stats.warnings);
}

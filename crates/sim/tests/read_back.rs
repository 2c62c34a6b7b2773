//! Simulated logs read back with `odocal-log`: what the reader sees is what the truth
//! says was written.

use odocal_log::{read_carmen_from, LogError, ReadOptions};
use odocal_sim::{simulate, GroundTruth, SimConfig};

fn written(c: &SimConfig) -> (odocal_sim::SimRun, Vec<u8>, GroundTruth) {
    let run = simulate(c).unwrap();
    let mut log = Vec::new();
    let summary = run.write_log(&mut log, &[]).unwrap();
    let mut truth = Vec::new();
    run.write_truth(&summary, &mut truth).unwrap();
    (run, log, serde_json::from_slice(&truth).unwrap())
}

#[test]
fn reader_sees_every_record_exactly() {
    let mut c = SimConfig::preset("khepera").unwrap();
    c.seed = 31;
    c.duration = 10.0;
    c.encoder.modulus = Some(65536);
    c.encoder.initial_ticks = [65_400, 200];
    c.faults.clock_offset = -0.012;
    let (run, log, truth) = written(&c);
    let read = read_carmen_from(&log[..], "sim.log", &ReadOptions::default()).unwrap();
    assert_eq!(read.params.ticks_per_revolution.as_ref().unwrap().0, 2764.8);
    assert_eq!(read.params.encoder_modulus, Some(65536.0));
    assert_eq!(read.encoders.len(), run.encoders.len());
    for (r, e) in read.encoders.iter().zip(&run.encoders) {
        assert_eq!(r.t, e.t);
        assert_eq!(
            r.left - read.encoders[0].left,
            e.ticks[0] - run.encoders[0].ticks[0]
        );
        assert_eq!(
            r.right - read.encoders[0].right,
            e.ticks[1] - run.encoders[0].ticks[1]
        );
    }
    assert!(read.stats.encoder_wraps > 0);
    assert_eq!(read.scans.len(), truth.scans.len());
    for (i, (s, t)) in read.scans.iter().zip(&truth.scans).enumerate() {
        assert_eq!(s.t, t.t);
        assert_eq!(s.ranges, &run.scans[i].ranges[..]);
        assert!(s.geometry.same_rays(&run.geometry()));
    }
    assert_eq!(read.odom.len(), run.odom.len());
}

#[test]
fn garbage_is_skipped_in_lenient_mode_and_stops_strict_mode() {
    let mut c = SimConfig::preset("khepera").unwrap();
    c.seed = 32;
    c.duration = 20.0;
    c.faults.garbage_fraction = 0.03;
    c.faults.drop_fraction = 0.05;
    let (_, log, truth) = written(&c);
    let garbage = &truth.faults.garbage_lines;
    assert!(garbage.len() > 5);
    let read = read_carmen_from(&log[..], "sim.log", &ReadOptions::lenient()).unwrap();
    assert_eq!(read.stats.skipped_lines, garbage.len() as u64);
    for (skipped, expected) in read.stats.first_skipped.iter().zip(garbage) {
        assert_eq!(skipped.0, *expected);
    }
    assert_eq!(read.encoders.len(), truth.log.encoder_records);
    assert_eq!(read.scans.len(), truth.log.scans);
    assert!(read.stats.unknown.is_empty());
    match read_carmen_from(&log[..], "sim.log", &ReadOptions::default()) {
        Err(e) => {
            let text = e.to_string();
            assert!(text.contains(&garbage[0].to_string()), "{text}");
            let _: &LogError = &e;
        }
        Ok(_) => panic!("strict mode accepted a malformed line"),
    }
}

#[test]
fn in_memory_log_matches_the_written_one() {
    let mut c = SimConfig::preset("khepera-displaced").unwrap();
    c.seed = 33;
    c.duration = 8.0;
    c.faults.drop_fraction = 0.05;
    c.faults.clock_offset = 0.3; // reorders scans relative to encoder records
    let (run, log, _) = written(&c);
    let read = read_carmen_from(&log[..], "sim.log", &ReadOptions::default()).unwrap();
    let mem = run.to_log();
    assert_eq!(mem.params.ticks_per_revolution.as_ref().unwrap().0, 2764.8);
    assert_eq!(mem.encoders.len(), read.encoders.len());
    for (a, b) in mem.encoders.iter().zip(&read.encoders) {
        assert_eq!((a.t, a.left, a.right), (b.t, b.left, b.right));
    }
    assert_eq!(mem.scans.len(), read.scans.len());
    for (a, b) in mem.scans.iter().zip(read.scans.iter()) {
        assert_eq!(a.t, b.t);
        assert_eq!(a.ranges, b.ranges);
        assert!(a.geometry.same_rays(b.geometry));
    }
    assert_eq!(mem.odom.len(), read.odom.len());
    for (a, b) in mem.odom.iter().zip(&read.odom) {
        assert_eq!((a.t, a.pose, a.tv, a.rv), (b.t, b.pose, b.tv, b.rv));
    }
}

#[test]
fn swept_scans_read_back_with_their_time_increment() {
    for (preset, laser) in [
        ("turtlebot", "lds"),
        ("pioneer", "urg-04lx"),
        ("pioneer", "sick"),
    ] {
        let mut c = SimConfig::preset(preset).unwrap();
        c.laser = odocal_sim::LaserConfig::model(laser).unwrap();
        c.seed = 34;
        c.duration = 3.0;
        let (run, log, _) = written(&c);
        let read = read_carmen_from(&log[..], "sim.log", &ReadOptions::default()).unwrap();
        let dt = c.laser.time_increment;
        assert!(dt > 0.0);
        assert_eq!(read.params.laser_time_increment, Some(dt), "{laser}");
        let mem = run.to_log();
        assert_eq!(mem.params.laser_time_increment, Some(dt));
        assert_eq!(mem.scans.len(), read.scans.len());
        for (a, b) in mem.scans.iter().zip(read.scans.iter()) {
            assert_eq!((a.t, a.ranges), (b.t, b.ranges));
            assert!(a.geometry.same_rays(b.geometry), "{laser}");
            assert_eq!(b.geometry.time_increment, dt);
            assert_eq!(b.geometry.angles[..], c.laser.angles()[..]);
        }
    }
}

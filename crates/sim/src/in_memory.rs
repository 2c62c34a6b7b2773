//! A [`SimRun`] as an in-memory [`Log`], for tests and benchmarks that want the
//! reader's data model without writing and parsing text.

use crate::simulation::SimRun;
use odocal_log::{EncoderRecord, Log, Params, ScanKind, ValueSource};

impl SimRun {
    /// The records the written log holds (dropped messages left out, no garbage), as
    /// the reader's data model: ticks per revolution (source: the caller), encoder
    /// records with their cumulative, unwrapped counts, RAWLASER1 scans, ODOM records
    /// when enabled. Line numbers are 0 and the statistics count the messages only.
    pub fn to_log(&self) -> Log {
        let c = &self.config;
        let mut params = Params {
            ticks_per_revolution: Some((c.encoder.ticks_per_revolution, ValueSource::CommandLine)),
            encoder_modulus: c.encoder.modulus.map(|m| m as f64),
            laser_min_range: c.laser.min_range,
            ..Params::default()
        };
        params.all.insert(
            "robot_wheel_ticks_per_revolution".into(),
            c.encoder.ticks_per_revolution.to_string(),
        );
        if c.laser.time_increment != 0.0 {
            params.laser_time_increment = Some(c.laser.time_increment);
        }
        let mut log = Log {
            params,
            ..Log::default()
        };
        for (i, e) in self.encoders.iter().enumerate().filter(|(_, e)| !e.dropped) {
            log.encoders.push(EncoderRecord {
                t: e.t,
                left: e.ticks[0],
                right: e.ticks[1],
                line: 0,
            });
            if c.write_odom {
                log.odom.push(self.odom[i]);
            }
        }
        let geometry = self.geometry();
        let mut scans: Vec<_> = self.logged_scans().collect();
        scans.sort_by(|a, b| a.t.total_cmp(&b.t));
        for s in scans {
            log.scans
                .push(s.t, &geometry, &s.ranges, ScanKind::RawLaser1, 0);
        }
        let counts = [
            ("ENCODER", log.encoders.len()),
            ("RAWLASER1", log.scans.len()),
            ("ODOM", log.odom.len()),
        ];
        for (name, n) in counts {
            if n > 0 {
                log.stats.messages.insert(name.to_string(), n as u64);
            }
        }
        log
    }
}

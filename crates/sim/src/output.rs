//! Writing a [`SimRun`] as a Carmen-style log (with the garbage-line fault), and its
//! ground truth as JSON.

use crate::error::SimError;
use crate::simulation::{rng_for, SimRun, Stream};
use crate::truth::GroundTruth;
use odocal_log::LogWriter;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::io::Write;

/// What was written: counts and the line numbers of the injected garbage.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LogSummary {
    /// Lines written, comments included.
    pub lines: u64,
    /// ENCODER lines written.
    pub encoder_records: usize,
    /// RAWLASER1 lines written.
    pub scans: usize,
    /// ODOM lines written.
    pub odom_records: usize,
    /// 1-based line numbers of the malformed lines injected.
    pub garbage_lines: Vec<u64>,
}

/// A message to write, in logged-timestamp order.
enum Message {
    Encoder(usize),
    Scan(usize),
}

impl SimRun {
    /// Writes the log: `header` lines as comments, the PARAMs
    /// (`robot_wheel_ticks_per_revolution`, `robot_encoder_modulus` when counters wrap,
    /// `laser_front_laser_min_range`, `laser_front_laser_time_increment` for a swept
    /// laser), then ENCODER (each followed by its ODOM when
    /// enabled) and RAWLASER1 messages merged by logged timestamp, encoder first on
    /// ties. Dropped messages are left out; garbage lines are inserted after messages
    /// at the configured rate.
    pub fn write_log<W: Write>(&self, w: W, header: &[String]) -> Result<LogSummary, SimError> {
        let c = &self.config;
        let mut out = LogWriter::new(w, &c.hostname);
        let mut sum = LogSummary::default();
        let mut garbage = rng_for(c.seed, Stream::Garbage);
        out.comment("CARMEN Logfile")?;
        out.comment("message_name [message contents] timestamp hostname logger_timestamp")?;
        sum.lines += 2;
        for h in header {
            out.comment(h)?;
            sum.lines += h.split('\n').count() as u64;
        }
        out.param(
            "robot_wheel_ticks_per_revolution",
            c.encoder.ticks_per_revolution,
        )?;
        sum.lines += 1;
        if let Some(m) = c.encoder.modulus {
            out.param("robot_encoder_modulus", m)?;
            sum.lines += 1;
        }
        out.param("laser_front_laser_min_range", c.laser.min_range)?;
        sum.lines += 1;
        if c.laser.time_increment != 0.0 {
            out.param("laser_front_laser_time_increment", c.laser.time_increment)?;
            sum.lines += 1;
        }

        let mut order: Vec<(f64, u8, Message)> =
            Vec::with_capacity(self.encoders.len() + self.scans.len());
        order.extend(
            self.encoders
                .iter()
                .enumerate()
                .filter(|(_, e)| !e.dropped)
                .map(|(i, e)| (e.t, 0, Message::Encoder(i))),
        );
        order.extend(
            self.scans
                .iter()
                .enumerate()
                .filter(|(_, s)| !s.dropped)
                .map(|(i, s)| (s.t, 1, Message::Scan(i))),
        );
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));

        let geometry = self.geometry();
        for (_, _, m) in &order {
            let t = match *m {
                Message::Encoder(i) => {
                    let e = &self.encoders[i];
                    out.encoder(
                        e.t,
                        c.encoder.counter_value(e.ticks[0]),
                        c.encoder.counter_value(e.ticks[1]),
                    )?;
                    sum.lines += 1;
                    sum.encoder_records += 1;
                    if c.write_odom {
                        out.odom(&self.odom[i])?;
                        sum.lines += 1;
                        sum.odom_records += 1;
                    }
                    e.t
                }
                Message::Scan(i) => {
                    let s = &self.scans[i];
                    out.rawlaser1(s.t, &geometry, &s.ranges)?;
                    sum.lines += 1;
                    sum.scans += 1;
                    s.t
                }
            };
            if c.faults.garbage_fraction > 0.0
                && garbage.random::<f64>() < c.faults.garbage_fraction
            {
                out.raw_line(&garbage_line(
                    &mut garbage,
                    t,
                    &c.hostname,
                    geometry.num_readings(),
                ))?;
                sum.lines += 1;
                sum.garbage_lines.push(sum.lines);
            }
        }
        out.flush()?;
        Ok(sum)
    }

    /// The ground truth of this run as written by [`SimRun::write_log`] (whose
    /// summary gives the garbage line numbers).
    pub fn ground_truth(&self, summary: &LogSummary) -> GroundTruth {
        GroundTruth::new(self, summary)
    }

    /// Writes the ground truth as JSON (one line).
    pub fn write_truth<W: Write>(&self, summary: &LogSummary, mut w: W) -> Result<(), SimError> {
        serde_json::to_writer(&mut w, &self.ground_truth(summary)).map_err(std::io::Error::from)?;
        w.write_all(b"\n")?;
        w.flush()?;
        Ok(())
    }
}

/// A malformed line of a known message kind, which a strict reader must reject and a
/// lenient one skip: wrong token counts, a non-numeric field, too few readings.
fn garbage_line(rng: &mut ChaCha8Rng, t: f64, host: &str, rays: usize) -> String {
    let a: i64 = rng.random_range(0..100_000);
    let b: i64 = rng.random_range(0..100_000);
    match rng.random_range(0..5) {
        0 => format!("ENCODER {a} {b} {t} {host}"),
        1 => format!("ENCODER {a} x{b} {t} {host} {t}"),
        2 => format!("ENCODER {a}"),
        3 => {
            let n = rng.random_range(1..rays.max(2));
            let readings = vec!["1.5"; n].join(" ");
            format!("RAWLASER1 2 -2.0862 4.1724 0.0061 4 0.01 0 {rays} {readings} 0 {t} {host} {t}")
        }
        _ => {
            let readings = vec!["1.5"; rays.saturating_sub(1)].join(" ");
            format!("RAWLASER1 2 -2.0862 4.1724 0.0061 4 0.01 0 {rays} 1.2.3 {readings} 0 {t} {host} {t}")
        }
    }
}

//! Assembling a [`Log`] from records as a reader finds them: per-stream order checks,
//! encoder unwrapping, skipped-line bookkeeping, and the final sort and summary counts.

use crate::error::LogError;
use crate::model::{EncoderRecord, Log, OdomRecord, ValueSource};
use crate::options::{Mode, ReadOptions};

/// How many skipped lines are remembered with their error text.
pub(crate) const FIRST_SKIPPED_KEPT: usize = 5;

/// The three timestamped streams of a log.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Stream {
    Encoder = 0,
    Scan = 1,
    Odom = 2,
}

const STREAM_NAMES: [&str; 3] = ["encoder", "laser", "odom"];

/// Order bookkeeping for one stream.
#[derive(Debug, Default, Clone, Copy)]
struct OrderCheck {
    last_t: Option<f64>,
    out_of_order: u64,
    first_line: u64,
}

/// Encoder counter unwrapping state.
#[derive(Debug, Default)]
struct Unwrapper {
    previous_raw: Option<(i64, i64)>,
    offset: (i128, i128),
}

/// Collects records into a [`Log`].
pub(crate) struct LogBuilder<'o> {
    pub(crate) log: Log,
    pub(crate) opts: &'o ReadOptions,
    order: [OrderCheck; 3],
    unwrap: Unwrapper,
}

impl<'o> LogBuilder<'o> {
    pub(crate) fn new(name: &str, opts: &'o ReadOptions) -> Self {
        let mut log = Log::default();
        log.stats.source = name.to_string();
        LogBuilder {
            log,
            opts,
            order: [OrderCheck::default(); 3],
            unwrap: Unwrapper::default(),
        }
    }

    /// Notes a timestamp of `stream` read at `line`, counting it when it goes back.
    pub(crate) fn check_order(&mut self, stream: Stream, t: f64, line: u64) {
        let o = &mut self.order[stream as usize];
        if let Some(last) = o.last_t {
            if t < last {
                if o.out_of_order == 0 {
                    o.first_line = line;
                }
                o.out_of_order += 1;
            }
        }
        o.last_t = Some(t);
    }

    /// The encoder modulus in force now (command line, else the latest PARAM).
    fn modulus(&self) -> Option<i128> {
        self.opts
            .encoder_modulus
            .or(self.log.params.encoder_modulus)
            .map(|m| m as i128)
    }

    /// Adds an encoder record with raw (possibly wrapped) counters. Returns the reason
    /// when the unwrapped count does not fit in an `i64`.
    pub(crate) fn add_encoder(
        &mut self,
        t: f64,
        left: i64,
        right: i64,
        line: u64,
    ) -> Result<(), String> {
        let modulus = self.modulus();
        let u = &mut self.unwrap;
        let mut offset = u.offset;
        let mut wraps = 0;
        if let (Some(m), Some((pl, pr))) = (modulus, u.previous_raw) {
            for (raw, prev, off) in [(left, pl, &mut offset.0), (right, pr, &mut offset.1)] {
                let delta = raw as i128 - prev as i128;
                if 2 * delta > m {
                    *off -= m;
                    wraps += 1;
                } else if 2 * delta < -m {
                    *off += m;
                    wraps += 1;
                }
            }
        }
        let l = i64::try_from(left as i128 + offset.0);
        let r = i64::try_from(right as i128 + offset.1);
        let (Ok(l), Ok(r)) = (l, r) else {
            return Err("unwrapped encoder counts to fit in a 64-bit integer".into());
        };
        u.offset = offset;
        u.previous_raw = Some((left, right));
        self.log.stats.encoder_wraps += wraps;
        self.check_order(Stream::Encoder, t, line);
        self.log.encoders.push(EncoderRecord {
            t,
            left: l,
            right: r,
            line,
        });
        Ok(())
    }

    /// Adds an odometry record.
    pub(crate) fn add_odom(&mut self, rec: OdomRecord) {
        self.check_order(Stream::Odom, rec.t, rec.line);
        self.log.odom.push(rec);
    }

    /// Handles a malformed line: an error in strict mode, counted in lenient mode.
    pub(crate) fn reject(&mut self, err: LogError) -> Result<(), LogError> {
        match self.opts.mode {
            Mode::Strict => Err(err),
            Mode::Lenient => {
                let stats = &mut self.log.stats;
                stats.skipped_lines += 1;
                if stats.first_skipped.len() < FIRST_SKIPPED_KEPT {
                    // The line number is kept apart; the text is "MESSAGE: expected …".
                    let text = match &err {
                        LogError::Parse {
                            message, expected, ..
                        } => format!("{message}: {expected}"),
                        other => other.to_string(),
                    };
                    stats.first_skipped.push((err.line().unwrap_or(0), text));
                }
                Ok(())
            }
        }
    }

    /// Adds a warning.
    pub(crate) fn warn(&mut self, text: String) {
        self.log.stats.warnings.push(text);
    }

    /// Applies the command-line overrides, sorts each stream by timestamp, and counts
    /// invalid readings.
    pub(crate) fn finish(mut self) -> Log {
        let opts = self.opts;
        let log = &mut self.log;
        if let Some(t) = opts.ticks_per_revolution {
            log.params.ticks_per_revolution = Some((t, ValueSource::CommandLine));
        }
        if let Some(m) = opts.encoder_modulus {
            log.params.encoder_modulus = Some(m);
        }
        if let Some(r) = opts.min_range {
            log.params.laser_min_range = r;
        }
        if let Some(dt) = opts.time_increment {
            log.params.laser_time_increment = Some(dt);
        }
        let min_range = log.params.laser_min_range;
        let time_increment = log.params.laser_time_increment;
        for g in &mut log.scans.geometries {
            g.min_range = min_range;
            if let Some(dt) = time_increment {
                g.time_increment = dt;
            }
        }
        for (k, o) in self.order.iter().enumerate() {
            if o.out_of_order == 0 {
                continue;
            }
            let name = STREAM_NAMES[k];
            log.stats
                .out_of_order
                .insert(name.to_string(), o.out_of_order);
            log.stats.warnings.push(format!(
                "{} {name} record(s) out of timestamp order (first at line {}); the {name} \
                 stream was sorted by timestamp",
                o.out_of_order, o.first_line
            ));
        }
        if self.order[Stream::Encoder as usize].out_of_order > 0 {
            log.encoders.sort_by(|a, b| a.t.total_cmp(&b.t));
        }
        if self.order[Stream::Odom as usize].out_of_order > 0 {
            log.odom.sort_by(|a, b| a.t.total_cmp(&b.t));
        }
        if self.order[Stream::Scan as usize].out_of_order > 0 {
            log.scans.sort_by_time();
        }
        log.stats.invalid_readings = log.scans.count_invalid_readings();
        // Memory ≈ the ranges themselves: drop the growth slack of the packed stores.
        log.scans.ranges.shrink_to_fit();
        log.scans.remissions.shrink_to_fit();
        log.scans.scans.shrink_to_fit();
        log.encoders.shrink_to_fit();
        self.log
    }
}

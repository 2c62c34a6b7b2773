//! What the diagnostic examples share: a log, the parameters given on the command
//! line, and the odometry guess of a scan pair.

use odocal_geom::Pose2;
use odocal_log::Log;
use odocal_pipeline::sweep::reference_time;
use odocal_pipeline::sync::EncoderTrack;
use odocal_solver::Params;

/// A log and the arguments `LOG STRIDE OFFSET r_l r_r b l_x l_y l_theta`.
pub struct Setup {
    /// The log read.
    pub log: Log,
    /// Pairs are `stride` scans apart.
    pub stride: usize,
    /// Time offset of the encoders (s).
    pub offset: f64,
    /// The calibration parameters the guesses use.
    pub params: Params,
    /// Encoder ticks per wheel revolution.
    pub ticks: f64,
    /// Each scan's reference time (s).
    pub times: Vec<f64>,
}

impl Setup {
    /// Reads the log and parses the arguments (`a[0]` is the program).
    pub fn from_args(a: &[String]) -> Result<Setup, Box<dyn std::error::Error>> {
        if a.len() < 10 {
            return Err("usage: LOG STRIDE OFFSET r_l r_r b l_x l_y l_theta".into());
        }
        let log = odocal_log::read_log(std::path::Path::new(&a[1]), &Default::default())?;
        let v: Vec<f64> = a[4..10]
            .iter()
            .map(|s| s.parse())
            .collect::<Result<_, _>>()?;
        let params = Params {
            r_l: v[0],
            r_r: v[1],
            b: v[2],
            laser: Pose2::new(v[3], v[4], v[5]),
        };
        let ticks = log
            .params
            .ticks_per_revolution
            .as_ref()
            .map_or(2000.0, |t| t.0);
        let times = (0..log.scans.len())
            .map(|i| {
                log.scans
                    .get(i)
                    .map_or(log.scans.scans[i].t, |s| reference_time(&s))
            })
            .collect();
        Ok(Setup {
            stride: a[2].parse()?,
            offset: a[3].parse()?,
            log,
            params,
            ticks,
            times,
        })
    }

    /// The encoders' times (s).
    pub fn encoder_times(&self) -> Vec<f64> {
        self.log.encoders.iter().map(|e| e.t).collect()
    }

    /// ŝ predicted by odometry for the scans `i` and `j` (None when the encoders do
    /// not cover them).
    pub fn guess(&self, track: &EncoderTrack<'_>, i: usize, j: usize) -> Option<Pose2> {
        let p = &self.params;
        let rpt = track.rad_per_tick();
        let t0 = track.ticks_at(self.times[i] - self.offset, 0.2).ok()?;
        let t1 = track.ticks_at(self.times[j] - self.offset, 0.2).ok()?;
        let (sl, sr) = (p.r_l * rpt * (t1.0 - t0.0), p.r_r * rpt * (t1.1 - t0.1));
        let (ds, dth) = (0.5 * (sl + sr), (sr - sl) / p.b);
        let robot = Pose2::new(ds * (0.5 * dth).cos(), ds * (0.5 * dth).sin(), dth);
        Some(p.laser.inverse().compose(&robot).compose(&p.laser))
    }
}

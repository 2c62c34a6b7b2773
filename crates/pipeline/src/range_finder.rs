//! Common range finders recognised from what a log or bag says about its scans (ray
//! count and spacing, field of view, range limits, the Carmen laser type, the ROS
//! frame), each with the range-scale uncertainty its data sheet states.
//!
//! The scale matters because the laser's range scale is the scale of every
//! calibrated distance (see [`odocal_solver::with_range_scale`]); the data cannot
//! tell it. A data sheet's accuracy bound proportional to the range is taken as one σ
//! of a systematic scale (a maker does not state its unit-to-unit spread, so this is
//! the conservative reading). A sheet that states only an absolute error (mm, not %)
//! gives no scale term: the sensor is named, and the distances assume its scale exact.

use odocal_log::{Log, ScanGeometry};
use std::f64::consts::TAU;

/// What a log or bag says about one laser's scans: what the recognition looks at.
#[derive(Debug, Clone, PartialEq)]
pub struct LaserSignature {
    /// Rays per scan.
    pub rays: usize,
    /// Angle between consecutive rays (rad, positive).
    pub spacing: f64,
    /// Angle the rays cover, `rays · spacing` (rad).
    pub coverage: f64,
    /// Minimum valid range (m).
    pub min_range: f64,
    /// Maximum valid range (m).
    pub max_range: f64,
    /// The Carmen laser type code (2: Hokuyo URG); 0 when unknown or from a bag.
    pub laser_type: i32,
    /// The scans' frame (a ROS `header.frame_id`), when the input tells it.
    pub frame_id: Option<String>,
}

impl LaserSignature {
    /// The signature of `geometry`, with the scans' frame when known.
    pub fn of_geometry(geometry: &ScanGeometry, frame_id: Option<&str>) -> LaserSignature {
        let rays = geometry.num_readings();
        let spacing = geometry.resolution.abs();
        LaserSignature {
            rays,
            spacing,
            coverage: rays as f64 * spacing,
            min_range: geometry.min_range,
            max_range: geometry.max_range,
            laser_type: geometry.laser_type,
            frame_id: frame_id.map(str::to_string),
        }
    }

    /// The signature of the geometry most of `log`'s scans have; `None` without scans.
    pub fn of_log(log: &Log, frame_id: Option<&str>) -> Option<LaserSignature> {
        let store = &log.scans;
        let mut counts = vec![0usize; store.geometries.len()];
        for s in &store.scans {
            if let Some(c) = counts.get_mut(s.geometry as usize) {
                *c += 1;
            }
        }
        let (most, _) = counts
            .iter()
            .enumerate()
            .filter(|(_, &c)| c > 0)
            .max_by_key(|(_, &c)| c)?;
        Some(Self::of_geometry(&store.geometries[most], frame_id))
    }

    /// The range (m) below which scan matching uses the readings of this laser: the
    /// maximum range its scans declare, shortened to the data sheet's rated range
    /// when the range finder is recognised (a URG-04LX's 5.6 m to 4 m, where its
    /// stated accuracy ends); [`UNDECLARED_MATCHING_RANGE`] when it is not recognised
    /// and declares no maximum.
    ///
    /// Far readings are what fixes a displacement along a corridor or a long wall: on
    /// the simulated TurtleBot 4 (RPLIDAR, 12 m) a fixed 4 m cap refused 113 of 306
    /// pairs of one log as ill-conditioned.
    pub fn matching_range(&self) -> f64 {
        match recognise(self) {
            Some(r) => self.max_range.min(r.finder.rated_range),
            None if self.max_range.is_finite() => self.max_range,
            None => UNDECLARED_MATCHING_RANGE,
        }
    }

    /// In words: "682 rays 0.352° apart over 239.8°, 0.02–5.6 m" (and the laser type
    /// and frame when known).
    pub fn describe(&self) -> String {
        let mut s = format!(
            "{} rays {:.3}° apart over {:.1}°, {}–{} m",
            self.rays,
            self.spacing.to_degrees(),
            self.coverage.to_degrees(),
            metres(self.min_range),
            metres(self.max_range)
        );
        if self.laser_type == 2 {
            s.push_str(", Carmen laser type 2 (Hokuyo URG)");
        }
        if let Some(f) = &self.frame_id {
            s.push_str(&format!(", frame `{f}`"));
        }
        s
    }
}

/// A range in metres to the millimetre, without trailing zeros (a bag's `f32`
/// 0.12 reads 0.11999999731779099 as `f64`).
pub(crate) fn metres(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// One range finder of the table: its name, what identifies it, and its data sheet's
/// range-proportional accuracy.
#[derive(Debug, Clone, Copy)]
pub struct RangeFinder {
    /// The sensor's name.
    pub name: &'static str,
    /// One σ of the range scale, relative (0.01: 1 %); 0 when the data sheet states
    /// no range-proportional error.
    pub scale_sigma: f64,
    /// What the data sheet says, and where it says it.
    pub data_sheet: &'static str,
    /// The range (m) up to which the data sheet states the accuracy; readings beyond
    /// it (a URG-04LX reports up to 5.6 m, rated to 4 m) are left out of scan
    /// matching (see [`LaserSignature::matching_range`]). ∞: the whole range the scans declare.
    pub rated_range: f64,
    /// What identifies it in a log: the signature it must match.
    identifies: fn(&LaserSignature) -> bool,
}

/// `a` within `tol` (relative) of `b`.
fn near(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs()
}

/// Rays `step` apart (a tenth of a per cent), i.e. `steps` rays per turn.
fn spaced(s: &LaserSignature, steps: f64) -> bool {
    near(s.spacing, TAU / steps, 1e-3)
}

/// A full turn of rays (360°, give or take two rays).
fn full_turn(s: &LaserSignature) -> bool {
    (s.coverage - TAU).abs() <= 2.0 * s.spacing + 1e-9
}

/// The frame's name contains `word` (case-insensitive).
fn frame_has(s: &LaserSignature, word: &str) -> bool {
    s.frame_id
        .as_deref()
        .is_some_and(|f| f.to_ascii_lowercase().contains(word))
}

/// The recognised range finders, most specific first.
pub const RANGE_FINDERS: [RangeFinder; 8] = [
    RangeFinder {
        name: "Hokuyo URG-04LX",
        scale_sigma: 0.01,
        data_sheet: "Hokuyo URG-04LX data sheet: accuracy ±10 mm from 0.06 to 1 m, ±1 % of the \
                     measurement from 1 to 4 m",
        // 1024 steps per turn, at most 769 of them (240°), 4 m (5.6 m in SCIP 2.0:
        // `DMAX:5600`) maximum range.
        rated_range: 4.0,
        identifies: |s| {
            spaced(s, 1024.0) && s.rays <= 769 && (3.9..=5.7).contains(&s.max_range)
        },
    },
    RangeFinder {
        name: "Hokuyo UTM-30LX",
        scale_sigma: 0.0,
        data_sheet: "Hokuyo UTM-30LX data sheet: accuracy ±30 mm from 0.1 to 10 m, ±50 mm from \
                     10 to 30 m (an absolute error: no range-proportional figure)",
        // 1440 steps per turn, 1081 rays over 270°, 30 m (60 m in some drivers).
        rated_range: 30.0,
        identifies: |s| spaced(s, 1440.0) && s.rays <= 1081 && (29.0..=61.0).contains(&s.max_range),
    },
    RangeFinder {
        name: "SICK LMS1xx",
        scale_sigma: 0.0,
        data_sheet: "SICK LMS1xx operating instructions: systematic error ±30 mm (an absolute \
                     error: no range-proportional figure)",
        // 270° at 0.5° or 0.25°, 20 m (LMS11x) or 50 m (LMS15x).
        rated_range: f64::INFINITY,
        identifies: |s| {
            (spaced(s, 720.0) || spaced(s, 1440.0))
                && near(s.coverage, 270f64.to_radians(), 0.01)
                && (near(s.max_range, 20.0, 0.05) || near(s.max_range, 50.0, 0.05))
        },
    },
    RangeFinder {
        name: "SICK LMS2xx",
        scale_sigma: 0.0,
        data_sheet: "SICK LMS200/291 technical description: systematic error ±15 mm (mm mode; \
                     an absolute error: no range-proportional figure)",
        // 180° (or 100°) at 1°, 0.5° or 0.25°; Carmen laser type 0.
        rated_range: f64::INFINITY,
        identifies: |s| {
            (spaced(s, 360.0) || spaced(s, 720.0) || spaced(s, 1440.0))
                && (near(s.coverage, TAU / 2.0, 0.01) || near(s.coverage, 100f64.to_radians(), 0.01))
                && (7.9..=81.92).contains(&s.max_range)
        },
    },
    RangeFinder {
        name: "ROBOTIS LDS-01 (HLS-LFCD2)",
        scale_sigma: 0.05,
        data_sheet: "ROBOTIS LDS-01 specification (TurtleBot3 e-Manual): accuracy ±15 mm from \
                     0.12 to 0.5 m, ±5.0 % from 0.5 to 3.5 m",
        // hls_lfcd_lds_driver: 360 rays at 1°, range 0.12–3.5 m, frame `base_scan` on a
        // TurtleBot3.
        rated_range: 3.5,
        identifies: |s| {
            spaced(s, 360.0)
                && full_turn(s)
                && near(s.max_range, 3.5, 0.02)
                && (near(s.min_range, 0.12, 0.05) || frame_has(s, "base_scan"))
        },
    },
    RangeFinder {
        name: "ROBOTIS LDS-02",
        scale_sigma: 0.03,
        data_sheet: "ROBOTIS LDS-02 specification (TurtleBot3 e-Manual): accuracy ±10 mm from \
                     0.16 to 0.3 m, ±3.0 % from 0.3 to 6 m",
        rated_range: 6.0,
        identifies: |s| {
            spaced(s, 360.0)
                && full_turn(s)
                && near(s.min_range, 0.16, 0.05)
                && near(s.max_range, 8.0, 0.02)
        },
    },
    RangeFinder {
        name: "Neato XV-11 LDS",
        scale_sigma: 0.01,
        data_sheet: "no maker's data sheet; its design paper (Konolige et al., \"A low-cost laser \
                     distance sensor\", ICRA 2008) states 3 cm accuracy out to 6 m, a triangulation \
                     error growing with range: taken as 1 % of the range, as the RPLIDAR A1's",
        // xv_11_laser_driver: 360 rays at 1°, 0.06–5 m, frame `neato_laser`.
        rated_range: 6.0,
        identifies: |s| {
            spaced(s, 360.0)
                && full_turn(s)
                && (near(s.min_range, 0.06, 0.05) || frame_has(s, "neato"))
                && near(s.max_range, 5.0, 0.02)
        },
    },
    RangeFinder {
        name: "Slamtec RPLIDAR A1",
        scale_sigma: 0.01,
        data_sheet: "Slamtec RPLIDAR A1M8 data sheet: distance resolution below 1 % of the \
                     distance over the whole range (accuracy 1 % of the range to 3 m, 2 % from 3 \
                     to 5 m in its first revisions; indoor scans lie mostly within 3 m)",
        // rplidar_ros: a full turn, range_min 0.15 m, range_max 6, 8 or 12 m by
        // driver version.
        rated_range: 12.0,
        identifies: |s| {
            full_turn(s)
                && near(s.min_range, 0.15, 0.05)
                && [6.0, 8.0, 12.0].iter().any(|&m| near(s.max_range, m, 0.02))
        },
    },
];

/// Readings at or beyond this range (m) are left out of scan matching when a laser
/// is not recognised and its scans declare no maximum range (a Carmen `FLASER` log
/// without `laser_front_laser_max_range`): a laser that reports "no return" as a
/// large number would otherwise put a wall there. The URG-04LX's rated range.
pub const UNDECLARED_MATCHING_RANGE: f64 = 4.0;

/// A range finder recognised in a log, and why.
#[derive(Debug, Clone)]
pub struct Recognised {
    /// The table's entry.
    pub finder: RangeFinder,
    /// What the log says that identifies it.
    pub why: String,
}

/// The range finder of the table whose signature `signature` matches, if any.
pub fn recognise(signature: &LaserSignature) -> Option<Recognised> {
    RANGE_FINDERS
        .iter()
        .find(|f| (f.identifies)(signature))
        .map(|f| Recognised {
            finder: *f,
            why: signature.describe(),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use odocal_log::LaserFields;

    fn geometry(rays: usize, spacing: f64, min: f64, max: f64, laser_type: i32) -> ScanGeometry {
        let fields = LaserFields {
            laser_type,
            start_angle: -(rays as f64 - 1.0) / 2.0 * spacing,
            fov: rays as f64 * spacing,
            resolution: spacing,
            max_range: max,
            min_range: min,
            accuracy: 0.01,
            remission_mode: 0,
        };
        ScanGeometry::new(fields, rays)
    }

    fn name_of(g: &ScanGeometry, frame: Option<&str>) -> Option<&'static str> {
        recognise(&LaserSignature::of_geometry(g, frame)).map(|r| r.finder.name)
    }

    #[test]
    fn urg_04lx_carmen_log_is_recognised() {
        // The MinesRover logs' RAWLASER1: 682 rays 2π/1024 apart, 5.6 m, type 2.
        let g = geometry(682, TAU / 1024.0, 0.01, 5.6, 2);
        let r = recognise(&LaserSignature::of_geometry(&g, None)).unwrap();
        assert_eq!(r.finder.name, "Hokuyo URG-04LX");
        assert_eq!(r.finder.scale_sigma, 0.01);
        assert!(r.why.contains("682 rays 0.352° apart"), "{}", r.why);
        // The simulator's and the reference robot's 681 rays to 4 m too.
        assert_eq!(
            name_of(&ScanGeometry::urg_04lx(), None),
            Some("Hokuyo URG-04LX")
        );
    }

    #[test]
    fn lds_and_lidars_of_ros_bags_are_recognised() {
        let one_degree = TAU / 360.0;
        assert_eq!(
            name_of(&geometry(360, one_degree, 0.12, 3.5, 0), Some("base_scan")),
            Some("ROBOTIS LDS-01 (HLS-LFCD2)")
        );
        assert_eq!(
            name_of(
                &geometry(360, one_degree, 0.06, 5.0, 0),
                Some("neato_laser")
            ),
            Some("Neato XV-11 LDS")
        );
        // The simulator's Neato: 361 rays 1° apart (a full turn, the first ray twice).
        assert_eq!(
            name_of(&geometry(361, one_degree, 0.06, 5.0, 0), None),
            Some("Neato XV-11 LDS")
        );
        assert_eq!(
            name_of(
                &geometry(720, one_degree / 2.0, 0.15, 12.0, 0),
                Some("laser")
            ),
            Some("Slamtec RPLIDAR A1")
        );
        assert_eq!(
            name_of(&geometry(1081, TAU / 1440.0, 0.1, 30.0, 0), None),
            Some("Hokuyo UTM-30LX")
        );
        assert_eq!(
            name_of(&geometry(181, -one_degree, 0.05, 8.0, 0), None),
            Some("SICK LMS2xx")
        );
    }

    #[test]
    fn unknown_lasers_are_not_guessed() {
        let one_degree = TAU / 360.0;
        // A 1° full-turn lidar with limits no table entry has.
        assert_eq!(
            name_of(&geometry(360, one_degree, 0.2, 10.0, 0), None),
            None
        );
        // URG spacing but a 30 m range: not an URG-04LX.
        assert_eq!(
            name_of(&geometry(682, TAU / 1024.0, 0.02, 30.0, 0), None),
            None
        );
        // 2π/1024 over more than 240°: not an URG-04LX.
        assert_eq!(
            name_of(&geometry(1024, TAU / 1024.0, 0.02, 5.6, 0), None),
            None
        );
    }

    #[test]
    fn sheets_without_a_scale_figure_add_none() {
        for f in RANGE_FINDERS {
            assert!(f.scale_sigma >= 0.0 && f.scale_sigma < 0.1, "{}", f.name);
            assert_eq!(
                f.scale_sigma == 0.0,
                f.data_sheet.contains("no range-proportional figure"),
                "{}",
                f.name
            );
        }
    }

    #[test]
    fn matching_uses_the_rated_or_declared_range() {
        let range = |g: &ScanGeometry| LaserSignature::of_geometry(g, None).matching_range();
        let one_degree = TAU / 360.0;
        // An URG-04LX reporting to 5.6 m is rated to 4 m.
        assert_eq!(range(&geometry(682, TAU / 1024.0, 0.02, 5.6, 2)), 4.0);
        // An RPLIDAR A1 to its 12 m; an LDS-02 declaring 8 m is rated to 6.
        assert_eq!(range(&geometry(720, TAU / 720.0, 0.15, 12.0, 0)), 12.0);
        assert_eq!(range(&geometry(360, one_degree, 0.16, 8.0, 0)), 6.0);
        // A laser the table does not know: what it declares.
        assert_eq!(range(&geometry(360, one_degree, 0.2, 10.0, 0)), 10.0);
        // … and when it declares no maximum (a Carmen FLASER without the PARAM), the
        // cap that keeps a "no return" code from being taken for a wall.
        assert_eq!(
            range(&geometry(181, one_degree, 0.0, f64::INFINITY, 0)),
            UNDECLARED_MATCHING_RANGE
        );
        for f in RANGE_FINDERS {
            assert!(f.rated_range > 0.0, "{}", f.name);
        }
    }
}

//! Motion coverage: each sample in the (v, ω) plane, coloured by the kind of motion
//! and so by the parameters it informs, with the sentence saying which motion is
//! missing — the answer to "how should I drive?".

use super::data::FigureData;
use super::style::{legend_column, range, svg, xy_chart, Mark, LEGEND_W, WIDTH};
use super::{DrawError, Figure};
use odocal_solver::MOTION_CLASS_RATIO;
use plotters::prelude::*;

/// The kind of motion of one sample (the classes of the solver's `MotionContent`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionClass {
    /// Turning in place.
    Spin,
    /// Going straight.
    Straight,
    /// Turning while translating.
    Arc,
    /// (Almost) still.
    Still,
}

impl MotionClass {
    const ALL: [MotionClass; 4] = [
        MotionClass::Spin,
        MotionClass::Straight,
        MotionClass::Arc,
        MotionClass::Still,
    ];

    /// The class of a motion with forward travel `f` and turning travel `t` (m).
    pub fn of(f: f64, t: f64, scale: f64) -> MotionClass {
        let (fa, ta) = (f.abs(), t.abs());
        if fa.max(ta) <= 1e-6 * scale {
            MotionClass::Still
        } else if fa < MOTION_CLASS_RATIO * ta {
            MotionClass::Spin
        } else if ta < MOTION_CLASS_RATIO * fa {
            MotionClass::Straight
        } else {
            MotionClass::Arc
        }
    }

    /// In words, with what it informs.
    pub fn label(self) -> &'static str {
        match self {
            MotionClass::Spin => "spin in place: b, ℓx, ℓy",
            MotionClass::Straight => "straight: r_L/r_R, scale, ℓθ",
            MotionClass::Arc => "arc: all six, decorrelated",
            MotionClass::Still => "still: nothing",
        }
    }

    fn color(self) -> RGBColor {
        match self {
            MotionClass::Spin => RGBColor(148, 103, 189),
            MotionClass::Straight => RGBColor(44, 160, 44),
            MotionClass::Arc => RGBColor(255, 127, 14),
            MotionClass::Still => RGBColor(150, 150, 150),
        }
    }
}

/// What to drive next time, from the kinds of motion nearly absent (names as the
/// solver's `MotionContent::missing` gives them).
pub fn coverage_advice(missing: &[&str]) -> String {
    if missing.is_empty() {
        return "The log has spins in place, straight runs and arcs: every parameter has the \
                motion it needs."
            .into();
    }
    let why: Vec<String> = missing
        .iter()
        .map(|m| match *m {
            "spins in place" => "spins in place (they determine b and the laser's ℓx, ℓy)".into(),
            "straight runs" => {
                "straight runs (they determine the wheel radii's scale and the laser's ℓθ)".into()
            }
            "turning while translating" => {
                "turns while driving (arcs: they separate the radii from b and ℓ)".into()
            }
            other => other.to_string(),
        })
        .collect();
    format!(
        "How to drive next time: add {} — a few minutes of each, in both directions.",
        why.join(" and ")
    )
}

/// The coverage figure.
pub fn figure(d: &FigureData) -> Result<Figure, DrawError> {
    let p = &d.params;
    let scale = 0.5 * (p.r_l.abs() + p.r_r.abs());
    let points: Vec<(f64, f64, MotionClass)> = d
        .pairs
        .iter()
        .map(|s| {
            let w = &s.wheel;
            let f = 0.5 * (p.r_l * w.dphi_l + p.r_r * w.dphi_r);
            let t = 0.5 * (p.r_r * w.dphi_r - p.r_l * w.dphi_l);
            let class = MotionClass::of(f, t, scale);
            (f / w.dt, (2.0 * t / p.b / w.dt).to_degrees(), class)
        })
        .collect();
    let count = |c: MotionClass| points.iter().filter(|p| p.2 == c).count();
    let xr = range(points.iter().map(|p| p.0).chain([0.0]));
    let yr = range(points.iter().map(|p| p.1).chain([0.0]));
    let svg = svg(480, |root| {
        let (plot, legend) = root.split_horizontally(WIDTH - LEGEND_W);
        let mut chart = xy_chart(&plot, xr, yr, "forward speed v (m/s)", "turn rate ω (°/s)")?;
        for class in MotionClass::ALL {
            chart.draw_series(
                points
                    .iter()
                    .filter(|p| p.2 == class)
                    .map(|p| Circle::new((p.0, p.1), 2, class.color().mix(0.75).filled())),
            )?;
        }
        let entries: Vec<(Mark, String)> = MotionClass::ALL
            .iter()
            .map(|c| {
                (
                    Mark::Dot(c.color()),
                    format!("{} ({})", c.label(), count(*c)),
                )
            })
            .collect();
        legend_column(&legend, &entries)
    })?;
    Ok(Figure {
        name: "motion_coverage",
        title: "Motion coverage: how should I drive?".into(),
        caption: coverage_advice(&d.missing),
        svg,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes_follow_the_travel_ratio() {
        assert_eq!(MotionClass::of(0.0, 0.1, 0.02), MotionClass::Spin);
        assert_eq!(MotionClass::of(0.1, 0.001, 0.02), MotionClass::Straight);
        assert_eq!(MotionClass::of(0.1, 0.05, 0.02), MotionClass::Arc);
        assert_eq!(MotionClass::of(0.0, 0.0, 0.02), MotionClass::Still);
    }

    #[test]
    fn advice_names_what_is_missing_and_why() {
        let a = coverage_advice(&["spins in place"]);
        assert!(a.contains("spins in place") && a.contains("b and"), "{a}");
        assert!(coverage_advice(&[]).contains("every parameter"));
    }
}

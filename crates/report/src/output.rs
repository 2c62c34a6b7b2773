//! Files written by `--out DIR`: results.json, samples.tuple and the SVG figures.

use crate::report::Report;
use crate::svg::{histogram, plot, Figure, Series};
use odocal_geom::Pose2;
use odocal_pipeline::{write_bytes_atomically, write_tuples, Options, Outcome};
use odocal_solver::{Params, Predictor};
use std::fs;
use std::io;
use std::path::Path;

/// Writes `results.json`, `samples.tuple` and, with `plots`, the figures into `dir`
/// (created if needed); each file atomically (a temporary file renamed).
pub fn write_outputs(
    dir: &Path,
    opts: &Options,
    outcome: &Outcome,
    report: &Report,
    plots: bool,
) -> io::Result<()> {
    fs::create_dir_all(dir)?;
    let json = serde_json::to_string_pretty(report).map_err(io::Error::other)?;
    write_bytes_atomically(&dir.join("results.json"), (json + "\n").as_bytes())?;
    write_tuples(&dir.join("samples.tuple"), &outcome.synced.samples)?;
    if plots {
        for (name, svg) in figures(opts, outcome) {
            write_bytes_atomically(&dir.join(name), svg.as_bytes())?;
        }
    }
    Ok(())
}

/// Parameters a user would start from without calibration, when no nominal ones are
/// given: equal radii (the mean of the estimate), the estimated wheel distance, the
/// laser at the robot's origin.
pub fn nominal_params(estimate: &Params) -> Params {
    let r = (estimate.r_l + estimate.r_r) / 2.0;
    Params {
        r_l: r,
        r_r: r,
        b: estimate.b,
        laser: Pose2::IDENTITY,
    }
}

fn chain(steps: impl Iterator<Item = Pose2>) -> Vec<(f64, f64)> {
    let mut p = Pose2::IDENTITY;
    let mut out = vec![(0.0, 0.0)];
    for s in steps {
        p = p.compose(&s);
        out.push((p.x, p.y));
    }
    out
}

/// The figures as (file name, SVG text).
pub fn figures(opts: &Options, outcome: &Outcome) -> Vec<(&'static str, String)> {
    let c = &outcome.calibration;
    let samples: Vec<_> = outcome
        .synced
        .samples
        .iter()
        .map(|s| s.to_solver(opts.use_profile, opts.use_icp_covariance))
        .collect();
    let used: Vec<usize> = (0..samples.len())
        .filter(|&k| c.used.get(k).copied().unwrap_or(false))
        .collect();
    let predictor = Predictor::new(&c.params, opts.use_profile);
    let residuals: Vec<[f64; 3]> = samples.iter().map(|s| predictor.residual(s)).collect();
    let mut out = Vec::new();

    let units = [("x", 1e3, "mm"), ("y", 1e3, "mm"), ("theta", 1e3, "mrad")];
    let names = ["residuals_x.svg", "residuals_y.svg", "residuals_theta.svg"];
    for (comp, (axis, scale, unit)) in units.iter().enumerate() {
        let values: Vec<f64> = used.iter().map(|&k| residuals[k][comp] * scale).collect();
        let fig = Figure {
            title: format!("Residual ŝ_pred − ŝ, {axis} (samples used)"),
            x_label: format!("{axis} residual ({unit})"),
            y_label: "samples".into(),
            equal_axes: false,
        };
        out.push((names[comp], histogram(&fig, &values, 40, "steelblue")));
    }

    let t0 = outcome
        .synced
        .samples
        .first()
        .map(|s| s.pair.t0)
        .unwrap_or(0.0);
    let colors = ["crimson", "seagreen", "navy"];
    let series: Vec<Series> = (0..3)
        .map(|comp| Series {
            label: format!("{} ({})", units[comp].0, units[comp].2),
            color: colors[comp],
            points: used
                .iter()
                .map(|&k| {
                    (
                        outcome.synced.samples[k].pair.t0 - t0,
                        residuals[k][comp] * units[comp].1,
                    )
                })
                .collect(),
            line: false,
        })
        .collect();
    let fig = Figure {
        title: "Residuals over time (samples used)".into(),
        x_label: "time since first sample (s)".into(),
        y_label: "residual (mm, mrad)".into(),
        equal_axes: false,
    };
    out.push(("residuals_time.svg", plot(&fig, &series)));

    let (nominal, nominal_label) = match &opts.initial_params {
        Some(p) => (*p, "odometry, nominal parameters"),
        None => (
            nominal_params(&c.params),
            "odometry, nominal (equal radii, laser at origin)",
        ),
    };
    let nominal = Predictor::new(&nominal, opts.use_profile);
    let trajectories = vec![
        Series {
            label: "scan matching".into(),
            color: "black",
            points: chain(samples.iter().map(|s| s.sm)),
            line: true,
        },
        Series {
            label: "odometry, calibrated".into(),
            color: "seagreen",
            points: chain(
                samples
                    .iter()
                    .map(|s| Pose2::from_array(predictor.predict(s))),
            ),
            line: true,
        },
        Series {
            label: nominal_label.into(),
            color: "crimson",
            points: chain(
                samples
                    .iter()
                    .map(|s| Pose2::from_array(nominal.predict(s))),
            ),
            line: true,
        },
    ];
    let fig = Figure {
        title: "Sensor trajectory: chained displacements".into(),
        x_label: "x (m)".into(),
        y_label: "y (m)".into(),
        equal_axes: true,
    };
    out.push(("trajectory.svg", plot(&fig, &trajectories)));
    out
}

//! The laser's range scale in σ (issue 20 item 5): on the `mines-rover` preset, whose
//! URG-04LX model reads ranges with a bias of 3 mm + 4 mm/m²·r² (locally a 1–2 %
//! distance scale), r_L, r_R and b come out about 1 % large. With the data's σ alone
//! that was 3.1–3.8σ (labelled well determined); with the URG-04LX's data-sheet scale
//! (±1 %, recognised from the scans) composed in, the errors lie within 3σ.

use odocal_pipeline::{calibrate_log, Estimate, NoProgress, Options, RangeScaleSource};
use odocal_sim::{simulate_in, SimConfig, World};

/// Calibrates `preset` (120 s, `seed`) in memory: the estimate, the truth, and the
/// run's range scale.
fn calibrate_preset(preset: &str, seed: u64, opts: &Options) -> (Estimate, [f64; 6], String) {
    let mut config = SimConfig::preset(preset).unwrap();
    config.seed = seed;
    config.duration = 120.0;
    let world = World::preset(&config.world).unwrap();
    let run = simulate_in(&config, &world).unwrap();
    let truth = odocal_geom::FlatParams::from(config.robot).to_array();
    let log = run.to_log();
    let outcome = calibrate_log(&log, opts, &NoProgress).unwrap();
    let sensor = outcome.range_scale.sensor.clone().unwrap_or_default();
    assert_eq!(outcome.range_scale.source, RangeScaleSource::DataSheet);
    (Estimate::of(&outcome), truth, sensor)
}

#[test]
fn mines_rover_radii_and_wheel_distance_within_3_sigma_of_data_and_scale() {
    for seed in [1, 2] {
        // The verdicts are not what is tested here (the matcher's error makes some
        // weak on seed 1): the numbers and their σ are.
        let opts = Options {
            accept_weak: true,
            ..Options::default()
        };
        let (e, truth, sensor) = calibrate_preset("mines-rover", seed, &opts);
        assert_eq!(sensor, "Hokuyo URG-04LX", "seed {seed}");
        for (i, name) in ["r_L", "r_R", "b"].iter().enumerate() {
            let err = e.params[i] - truth[i];
            // The scale term is 1 % of the value, on top of the data's.
            let scale = 0.01 * e.params[i];
            assert!((e.sigma_range_scale[i] - scale).abs() < 1e-12, "{name}");
            assert!(e.sigma_total[i] > e.sigma[i]);
            eprintln!(
                "mines-rover seed {seed} {name}: error {:+.3} mm = {:+.2}σ data, {:+.2}σ total",
                err * 1e3,
                err / e.sigma[i],
                err / e.sigma_total[i]
            );
            assert!(
                err.abs() <= 3.0 * e.sigma_total[i],
                "seed {seed} {name}: error {err:+.6} m beyond 3 × {:.6} m",
                e.sigma_total[i]
            );
        }
        // ℓθ carries no scale term.
        assert_eq!(e.sigma_range_scale[5], 0.0);
        assert_eq!(e.sigma_total[5], e.sigma[5]);
    }
}

#[test]
fn a_stated_scale_replaces_the_data_sheet() {
    let opts = Options {
        laser_range_scale: Some(0.0),
        ..Options::default()
    };
    let mut config = SimConfig::preset("khepera").unwrap();
    config.duration = 60.0;
    let world = World::preset(&config.world).unwrap();
    let log = simulate_in(&config, &world).unwrap().to_log();
    let outcome = calibrate_log(&log, &opts, &NoProgress).unwrap();
    assert_eq!(outcome.range_scale.source, RangeScaleSource::Stated);
    let e = Estimate::of(&outcome);
    assert_eq!(e.sigma_total, e.sigma);
    assert_eq!(e.covariance_total, e.covariance);
}

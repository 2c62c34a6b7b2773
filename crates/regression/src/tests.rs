//! Unit tests of the published-table mechanisms, on a made-up table.

use crate::*;
use odocal_geom::Pose2;
use std::path::Path;

// Made-up numbers throughout: these test the mechanisms, not a published table.
const TABLE: &str = r#"{"citation": "made up", "rows": [
    {"name": "swapped", "samples": 1200,
     "si": {"r_l": 0.0212, "r_r": 0.0208, "b": 0.09, "l_x": 0.01, "l_y": -0.02, "l_theta": 0.3},
     "J11": 0.0104, "J12": 0.0106, "J21": -0.2311111, "J22": 0.2355556,
     "sigma": {"r_l": 4e-5, "r_r": 4e-5, "b": 2e-4, "l_x": 8e-5, "l_y": 1e-4, "l_theta": 1.5e-3}},
    {"name": "plain", "samples": 900,
     "si": {"r_l": 0.0208, "r_r": 0.0212, "b": 0.09, "l_x": 0.0, "l_y": 0.0, "l_theta": 0.0},
     "j21": -0.2311111, "j22": 0.2355556},
    {"name": "no-j", "samples": 10,
     "si": {"r_l": 0.0208, "r_r": 0.0212, "b": 0.09, "l_x": 0.0, "l_y": 0.0, "l_theta": 0.0}}
], "label": "Made-up table",
"table_ii": {"note": "made up", "rows": [
    {"trial": "1", "b": 0.09, "r_l": 0.0212, "r_r": 0.0208, "E_b": 1.0,
     "j11": 0.0106, "j12": 0.0104, "j21": -0.2355556, "j22": 0.2311111},
    {"trial": "2", "b": 0.08, "r_l": 0.02, "r_r": 0.02}
]}}"#;

fn table() -> Vec<PublishedRow> {
    parse_table(TABLE, Path::new("made-up.json")).unwrap()
}

#[test]
fn table_rows_parse_and_j_is_authoritative_for_the_radii() {
    let rows = table();
    assert_eq!(rows.len(), 3);
    // r_L = −b·J21, r_R = b·J22, whatever the printed radius columns say.
    for row in &rows[..2] {
        let t = row.truth();
        assert!((t.r_l - 0.0208).abs() < 1e-8, "{}", t.r_l);
        assert!((t.r_r - 0.0212).abs() < 1e-8, "{}", t.r_r);
    }
    assert_eq!(rows[0].sigma.unwrap()[2], 2e-4);
    assert_eq!(rows[2].truth().r_l, 0.0208);
    assert_eq!(rows[1].scaled_samples(0.5), 450);
}

#[test]
fn umbmark_trials_parse_and_compare() {
    let t = parse_table_document(TABLE, Path::new("made-up.json")).unwrap();
    assert_eq!(t.rows[0].source, "Made-up table");
    assert_eq!(t.umbmark_note.as_deref(), Some("made up"));
    assert_eq!(t.umbmark.len(), 2);
    assert_eq!(t.umbmark[0].e_b, Some(1.0));
    assert_eq!(t.umbmark[1].e_d, None);
    let c = umbmark_j_consistency(&t.umbmark[0], 1e-3).unwrap();
    assert_eq!(c.reading, JReading::AsPrinted);
    assert!(c.abs_deviation_as_printed < 1e-6, "{c:?}");
    assert!(umbmark_j_consistency(&t.umbmark[1], 1e-3).is_none());
    let cal = OdometryLine {
        name: "cal".into(),
        b: 0.08,
        r_l: 0.019,
        r_r: 0.021,
    };
    let md = format_umbmark(&t.umbmark, &[], &[cal]);
    // Trial 2 against the calibration: same b and mean radius, r_R/r_L 1 vs 21/19.
    assert!(
        md.contains("| 2 | cal | +0.00 | +0.00 | +0.000 | +0.00 | +0.00 | -9.524 |"),
        "{md}"
    );
    let e = parse_table_document(
        r#"{"rows": [], "table_ii": {"rows": [{"trial": "x", "b": -1, "r_l": 0.02, "r_r": 0.02}]}}"#,
        Path::new("t.json"),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("trial 'x'") && e.contains("positive"), "{e}");
}

#[test]
fn row_seeds_depend_on_the_name_only() {
    assert_eq!(row_seed(1, "k07"), row_seed(1, "k07"));
    assert_ne!(row_seed(1, "k07"), row_seed(1, "k08"));
    assert_ne!(row_seed(1, "k07"), row_seed(2, "k07"));
}

#[test]
fn consistency_check_tells_the_heading_swap() {
    let rows = table();
    let c = j_consistency(&rows[0], 1e-3).unwrap();
    assert_eq!(c.reading, JReading::HeadingsSwapped);
    assert!(c.deviation_swapped < 1e-6 && c.deviation_as_printed > 1e-2);
    let c = j_consistency(&rows[1], 1e-3).unwrap();
    assert_eq!(c.reading, JReading::AsPrinted);
    assert!(c.printed[0].is_nan());
    assert!(j_consistency(&rows[2], 1e-3).is_none());
    // Equal radii cannot tell the readings apart; wrong J fits neither.
    let mut equal = rows[1].clone();
    equal.printed.r_r = equal.printed.r_l;
    equal.j = Some(PrintedJ {
        j11: None,
        j12: None,
        j21: -0.0208 / 0.09,
        j22: 0.0208 / 0.09,
    });
    assert_eq!(
        j_consistency(&equal, 1e-3).unwrap().reading,
        JReading::Ambiguous
    );
    equal.j.as_mut().unwrap().j22 = 0.3;
    assert_eq!(
        j_consistency(&equal, 1e-3).unwrap().reading,
        JReading::Neither
    );
}

#[test]
fn bad_tables_are_clear_errors() {
    let p = Path::new("t.json");
    let e = parse_table("{\"rows\": 3}", p).unwrap_err().to_string();
    assert!(
        e.contains("t.json") && e.contains("expected an array"),
        "{e}"
    );
    let row = |extra: &str| {
        format!(
            r#"[{{"name": "x", "samples": 5, "si": {{"r_l": 0.02, "r_r": 0.02, "b": 0.09,
               "l_x": 0, "l_y": 0, "l_theta": 0}}{extra}}}]"#
        )
    };
    let e = parse_table(&row(r#", "j21": -0.2"#), p)
        .unwrap_err()
        .to_string();
    assert!(e.contains("both j21 and j22"), "{e}");
    let e = parse_table(&row(r#", "j21": 0.2, "j22": 0.2"#), p)
        .unwrap_err()
        .to_string();
    assert!(e.contains("row 'x'") && e.contains("positive"), "{e}");
    let twice = format!("[{0}, {0}]", &row("")[1..row("").len() - 1]);
    let e = parse_table(&twice, p).unwrap_err().to_string();
    assert!(e.contains("twice"), "{e}");
}

#[test]
fn the_tro_reference_reads_the_published_numbers() {
    let dir = workspace_reference_dir();
    if !dir.join("lstraight_results.json").exists() {
        println!("skipped: no reference data at {}", dir.display());
        return;
    }
    let rows = read_tro_reference(&dir).unwrap();
    let names: Vec<&str> = rows.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["lstraight", "l90", "lmov"]);
    // The published numbers quoted in docs/method.md and the reference README.
    let a = &rows[0];
    assert_eq!(a.samples, 4396);
    assert_eq!(rows[1].samples, 3295);
    assert_eq!(rows[2].samples, 4345);
    let t = a.truth();
    assert_eq!(t.b, 0.0890519);
    // `l_diam`, `r_diam` are diameters: 0.0417709 / 2, 0.0418957 / 2.
    assert!((t.r_l - 0.02088545).abs() < 1e-12 && (t.r_r - 0.02094785).abs() < 1e-12);
    assert_eq!(t.laser, Pose2::new(-0.00581279, 0.000185606, 0.00949588));
    assert!((a.sigma.unwrap()[2] - 4.38323e-08f64.sqrt()).abs() < 1e-12);
}

//! `results.html`: the whole report on one self-contained page (inline SVG and CSS, no
//! script, no network), written with the `maud` template macro.
//!
//! Every number on the page is rendered from `results.json`'s values and carries
//! where it came from: `data-json` (a JSON pointer into results.json), `data-scale`
//! (the factor from the JSON's unit to the shown one) and `data-digits` (decimals
//! shown; absent when the value is printed in full). The page's test reads them back.
//! Fields the page has no section for (added by later features) are still shown,
//! under "Further results".

use crate::figures::{coverage_advice, Figure};
use crate::report::Report;
use maud::{html, Markup, PreEscaped, DOCTYPE};
use serde_json::Value;

const CSS: &str = include_str!("report.css");

/// Top-level results.json keys shown in a section of their own.
const SHOWN: [&str; 19] = [
    "log",
    "range_scale",
    "logs",
    "lasers",
    "r_l",
    "r_r",
    "b",
    "l_x",
    "l_y",
    "l_theta",
    "sigma",
    "j",
    "nominal",
    "nominal_laser",
    "odometry_only",
    "correction_factors",
    "health",
    "checks",
    "provenance",
];

/// A number with its origin: JSON pointer, unit scale and decimals.
pub(crate) fn num(pointer: &str, value: f64, scale: f64, digits: usize) -> Markup {
    html! {
        span.num data-json=(pointer) data-scale=(scale) data-digits=(digits) {
            (format!("{:.*}", digits, value * scale))
        }
    }
}

/// The parameters as the page names them.
pub(crate) const PARAMETER_LABELS: [&str; 6] = ["r_L", "r_R", "b", "ℓx", "ℓy", "ℓθ"];

/// Significant digits of the numbers shown without a unit of their own.
const SIGNIFICANT: usize = 6;

/// `x` with [`SIGNIFICANT`] significant digits: integers in full, plain notation from
/// 1e-4 to 1e6, scientific notation outside.
fn significant(x: f64) -> String {
    let a = x.abs();
    if x.fract() == 0.0 && a < 1e15 {
        format!("{x}")
    } else if (1e-4..1e6).contains(&a) {
        let decimals = (SIGNIFICANT as i32 - 1 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.*e}", SIGNIFICANT - 1)
    }
}

/// A number with its origin and unit scale, shown to [`SIGNIFICANT`] digits (for
/// values whose size varies, as covariances).
pub(crate) fn scaled(pointer: &str, value: f64, scale: f64) -> Markup {
    html! {
        span.num data-json=(pointer) data-scale=(scale) data-sig=(SIGNIFICANT) {
            (significant(value * scale))
        }
    }
}

/// A JSON value (numbers to [`SIGNIFICANT`] digits): scalars as text, arrays of numbers inline, arrays of arrays
/// as a matrix, arrays of objects as a table, objects as a key–value table.
pub(crate) fn json(v: &Value, pointer: &str) -> Markup {
    match v {
        Value::Number(n) => html! {
            span.num data-json=(pointer) data-sig=(SIGNIFICANT) { (significant(n.as_f64().unwrap_or(f64::NAN))) }
        },
        Value::String(s) => html! { (s) },
        Value::Bool(b) => html! { (if *b { "yes" } else { "no" }) },
        Value::Null => html! { "—" },
        Value::Array(items) if items.is_empty() => html! { "none" },
        Value::Array(items) if items.iter().all(|i| i.is_array()) && !items.is_empty() => html! {
            table.matrix {
                @for (i, row) in items.iter().enumerate() {
                    tr { @for (k, x) in row.as_array().into_iter().flatten().enumerate() {
                        td { (json(x, &format!("{pointer}/{i}/{k}"))) }
                    } }
                }
            }
        },
        Value::Array(items) if items.iter().all(|i| i.is_object()) && !items.is_empty() => {
            let mut cols: Vec<&String> = Vec::new();
            for i in items {
                for k in i.as_object().into_iter().flat_map(|o| o.keys()) {
                    if !cols.contains(&k) {
                        cols.push(k);
                    }
                }
            }
            html! {
                table { tr { @for c in &cols { th { (words(c)) } } }
                    @for (i, item) in items.iter().enumerate() { tr {
                        @for c in &cols { td { @if let Some(x) = item.get(c.as_str()) {
                            (json(x, &format!("{pointer}/{i}/{}", escape_pointer(c))))
                        } } }
                    } }
                }
            }
        }
        Value::Array(items) => html! {
            @for (i, x) in items.iter().enumerate() {
                @if i > 0 { ", " } (json(x, &format!("{pointer}/{i}")))
            }
        },
        Value::Object(map) => html! {
            table.kv { @for (k, x) in map {
                tr { th { (words(k)) } td { (json(x, &format!("{pointer}/{}", escape_pointer(k)))) } }
            } }
        },
    }
}

/// A JSON pointer token for `key`.
pub(crate) fn escape_pointer(key: &str) -> String {
    key.replace('~', "~0").replace('/', "~1")
}

/// `snake_case` in words.
pub(crate) fn words(key: &str) -> String {
    key.replace('_', " ")
}

/// What was given about parameter `i` (`--fix` / `--prior`), read from the results'
/// `settings.constraints` (`--fix`, `--prior`): `"free"`, `{"held": v}`,
/// `{"prior": {mean, sigma}}`.
fn given(v: &Value, i: usize, scale: f64, digits: usize) -> Markup {
    let c = &v["settings"]["constraints"];
    let c = c.get(i);
    let p = format!("/settings/constraints/{i}");
    match c {
        Some(x) if x.get("held").is_some_and(Value::is_number) => html! {
            "held at " (num(&format!("{p}/held"), x["held"].as_f64().unwrap_or(f64::NAN), scale, digits))
        },
        Some(x) if x.get("prior").is_some() => {
            let m = x["prior"]["mean"].as_f64().unwrap_or(f64::NAN);
            let s = x["prior"]["sigma"].as_f64().unwrap_or(f64::NAN);
            html! {
                "prior " (num(&format!("{p}/prior/mean"), m, scale, digits))
                " ± " (num(&format!("{p}/prior/sigma"), s, scale, digits))
            }
        }
        Some(x) if x.as_str() == Some("free") => html! { "free" },
        Some(x) => json(x, &p),
        None => html! { "free" },
    }
}

/// The parameters table.
fn parameters(r: &Report, v: &Value) -> Markup {
    const KEYS: [&str; 6] = ["r_l", "r_r", "b", "l_x", "l_y", "l_theta"];
    let values = r.values();
    let has_constraints = v["settings"]["constraints"]
        .as_array()
        .is_some_and(|a| a.iter().any(|c| c.as_str() != Some("free")));
    let has_scale = r.range_scale.scale.applies();
    html! {
        table.params {
            tr {
                th { "parameter" } th { "estimate" } th { @if has_scale { "σ (data)" } @else { "σ" } }
                @if has_scale { th { "σ (" (r.range_scale.scale.label()) ")" } th { "σ together" } }
                th { "unit" } th { "verdict" }
                @if r.nominal.is_some() { th { "nominal" } th { "correction" } }
                @if has_constraints { th { "given" } }
            }
            @for i in 0..6 {
                @let (scale, digits, unit) = if i == 5 { (180.0 / std::f64::consts::PI, 4, "°") } else { (1e3, 4, "mm") };
                @let held = v["settings"]["constraints"][i].get("held").is_some();
                @let verdict = if held { "held (--fix)" } else { r.observability.parameters.get(i).map(|p| p.verdict.as_str()).unwrap_or("") };
                tr {
                    th { (PARAMETER_LABELS[i]) }
                    td { (num(&format!("/{}", KEYS[i]), values[i], scale, digits)) }
                    td { "± " (num(&format!("/sigma/{i}"), r.sigma[i], scale, digits)) }
                    @if has_scale {
                        td { "± " (num(&format!("/range_scale/sigma_from_scale/{i}"), r.range_scale.sigma_from_scale[i], scale, digits)) }
                        td { "± " (num(&format!("/range_scale/sigma_total/{i}"), r.range_scale.sigma_total[i], scale, digits)) }
                    }
                    td { (unit) }
                    td { span class=(format!("verdict {}", verdict.split(" (").next().unwrap_or("").replace(' ', "-"))) { (verdict) } }
                    @if let Some(n) = r.nominal {
                        td { (num(&format!("/nominal/{i}"), n[i], scale, digits)) }
                        td { @if let Some(c) = r.correction_factors.filter(|_| i < 3) {
                            "× " (num(&format!("/correction_factors/{i}"), c[i], 1.0, 6))
                        } @else { "—" } }
                    }
                    @if has_constraints { td.given { (given(v, i, scale, digits)) } }
                }
            }
            @if let Some(offset) = r.time_offset_s {
                tr #clock-offset {
                    th { "clock offset (laser − encoders)" }
                    td { (num("/time_offset_s", offset, 1e3, 2)) }
                    td { @match v.get("time_offset_sigma_s").and_then(Value::as_f64) {
                        Some(sd) => { "± " (num("/time_offset_sigma_s", sd, 1e3, 2)) },
                        None => "—",
                    } }
                    @if has_scale { td { "—" } td { "—" } }
                    td { "ms" }
                    td { "estimated" }
                    @if r.nominal.is_some() { td { "—" } td { "—" } }
                    @if has_constraints { td.given { "—" } }
                }
            }
        }
        p.note #range-scale { "Laser range scale: " (r.range_scale.statement) "." }
        @if let Some(m) = &r.settings.matching_range_statement {
            p.note #matching-range { "Scan matching used " (m) "." }
        }
        @if r.odometry_only {
            p.warning #odometry-only {
                "Odometry-only mode: the input has odometry poses, no wheel encoders; the wheel rotations were recovered from the poses with the nominal r_L, r_R and b (--nominal). The absolute radii and wheel distance are only as good as those nominal values; the correction factors (estimate / nominal) are what the data determine."
            }
        }
        @if let Some(l) = &r.nominal_laser {
            p.note #nominal-laser {
                "The bag's " (l.source) " puts the laser frame " code { (l.laser_frame) } " in " code { (l.base_frame) } " at "
                (num("/nominal_laser/l_x", l.l_x, 1e3, 1)) " mm, " (num("/nominal_laser/l_y", l.l_y, 1e3, 1)) " mm, "
                (num("/nominal_laser/l_theta", l.l_theta, 180.0 / std::f64::consts::PI, 2)) "°; the calibrated pose differs by "
                (format!("{:.1} mm, {:.1} mm, {:.2}°", (values[3] - l.l_x) * 1e3, (values[4] - l.l_y) * 1e3, (values[5] - l.l_theta).to_degrees()))
                " (ℓ is relative to the wheel-axle midpoint, which is " code { (l.base_frame) } " only if the robot's description puts it there: docs/frames.md)."
            }
        }
    }
}

/// The list of findings under `key` of the results, or the sentence for none.
fn findings(v: &Value, key: &str, none: &str) -> Markup {
    match v.get(key) {
        Some(Value::Array(items)) if !items.is_empty() => html! {
            ul.findings { @for (i, f) in items.iter().enumerate() {
                @let sev = f["severity"].as_str().unwrap_or("info");
                li class=(format!("finding {sev}")) {
                    span.badge { (sev) } " "
                    code { (f["kind"].as_str().unwrap_or("")) } " "
                    @if let Some(n) = f.get("count") { "×" (json(n, &format!("/{key}/{i}/count"))) " " }
                    @if let Some(l) = f.get("first_line") { "(line " (json(l, &format!("/{key}/{i}/first_line"))) ") " }
                    (f["message"].as_str().unwrap_or(""))
                }
            } }
        },
        Some(other) if !other.is_array() => json(other, &format!("/{key}")),
        _ => html! { p.none { (none) } },
    }
}

/// One figure with its title and caption.
fn figure(f: &Figure) -> Markup {
    html! {
        figure id=(format!("fig-{}", f.name)) {
            figcaption { strong { (f.title) } " " (f.caption) }
            (PreEscaped(&f.svg))
        }
    }
}

/// The results in ROS terms, ready to paste: the diff_drive_controller parameters and
/// the laser joint's URDF origin (the files `--out DIR` and `odocal export` write).
fn ros_terms(r: &Report) -> Markup {
    let files = [
        (
            crate::export::DIFF_DRIVE_FILE,
            crate::export::diff_drive_controller_yaml(&r.params),
        ),
        (
            crate::export::URDF_FILE,
            crate::export::laser_joints_urdf(&r.params, &r.laser_poses()),
        ),
    ];
    html! {
        section #ros {
            h2 { "In ROS terms" }
            p { "Ready to paste (the same as the files " code { "--out DIR" } " writes and "
                code { "odocal export results.json" } " prints). ℓ is relative to the wheel-axle midpoint; see docs/frames.md when base_link is elsewhere." }
            @for (name, body) in &files {
                h3 { code { (name) } }
                @match body {
                    Ok(text) => pre { code { (text) } },
                    Err(e) => p.warning { (e.to_string()) },
                }
            }
        }
    }
}

/// The page of `report` with `figures`.
pub fn page(report: &Report, figures: &[Figure]) -> String {
    page_with_results(
        report,
        &serde_json::to_value(report).unwrap_or(Value::Null),
        figures,
    )
}

/// The page, its numbers taken from `results` (the report as results.json holds it,
/// possibly with fields the typed report does not know: they appear under "Further
/// results", and `settings.constraints` fills the parameters table's "given" column).
pub fn page_with_results(report: &Report, results: &Value, figures: &[Figure]) -> String {
    let v = results;
    let r = report;
    let further: Vec<(&String, &Value)> = v
        .as_object()
        .into_iter()
        .flatten()
        .filter(|(k, _)| {
            !SHOWN.contains(&k.as_str())
                && !crate::data_section::ROWS
                    .iter()
                    .any(|row| row.key == k.as_str())
        })
        .collect();
    let missing = r.observability.motion.missing();
    let halves_short = matches!(
        r.consistency,
        odocal_pipeline::consistency::Consistency::NotAvailable { .. }
    );
    // The whole log may have every motion while each half alone lacks some: then the
    // coverage sentence must not say all is well next to the two-halves note.
    let advice = if missing.is_empty() && halves_short {
        "The log as a whole has spins in place, straight runs and arcs, but its halves \
         could not be checked against each other (see the two-halves note under \
         Consistency checks): drive each kind of motion several times, spread over the run."
            .to_string()
    } else {
        coverage_advice(&missing)
    };
    html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                meta name="viewport" content="width=device-width, initial-scale=1";
                title { "odocal calibration — " (r.log) }
                style { (PreEscaped(CSS)) }
            }
            body {
                header {
                    h1 { "Calibration of " code { (r.log) } }
                    p.verdict { (r.observability.sentence) }
                    @if let Some(w) = &r.observability.wheel_signs { p.warning { (w) } }
                    p.advice { (advice) }
                }
                section #parameters {
                    h2 { "Parameters" }
                    (parameters(r, v))
                    p.note { "σ from the covariance of the estimate (the data's; the laser range scale's, when known, in its own column and in σ together); verdicts from the data's σ relative to the value (radii, b), to b (ℓx, ℓy), or in degrees (ℓθ): how well the drive determines each parameter, the scale aside." }
                }
                @if let Some(logs) = v.get("logs") {
                    section #logs {
                        h2 { "Logs calibrated together" }
                        p { "Each log's own estimate (own, own σ; m, rad), the samples it brought, its share of the information on r_L, r_R, b, ℓx, ℓy, ℓθ, and χ² of its own estimate against the joint one (agree: within 3σ)." }
                        (json(logs, "/logs"))
                    }
                }
                @if let Some(lasers) = v.get("lasers") {
                    section #lasers {
                        h2 { "Lasers" }
                        p { "One row per laser, the wheels shared: its pose ℓ (m, rad) with σ and covariance from the joint covariance, the logs and samples it brought, and its pose in the first laser's frame (from_first: ℓ₁⁻¹ ⊕ ℓ, with its covariance)." }
                        (json(lasers, "/lasers"))
                    }
                }
                (ros_terms(r))
                section #j-matrix {
                    h2 { "J matrix" }
                    p { "J = [[r_L/2, r_R/2], [−r_L/b, r_R/b]] maps wheel rotations (rad) to forward travel (m) and turn (rad)." }
                    table.matrix {
                        @for i in 0..2 { tr { @for k in 0..2 {
                            td { (num(&format!("/j/{i}/{k}"), r.j[i][k], 1.0, 8)) }
                        } } }
                    }
                }
                section #health {
                    h2 { "Data health" }
                    (findings(v, "health", "No data-health findings were reported for this log."))
                }
                section #consistency {
                    h2 { "Consistency checks" }
                    (findings(v, "checks", "No consistency check was run for this result."))
                }
                section #figures {
                    h2 { "Figures" }
                    @for f in figures { (figure(f)) }
                }
                section #data {
                    h2 { "Data and solution" }
                    (crate::data_section::section(v))
                }
                @if !further.is_empty() {
                    section #further {
                        h2 { "Further results" }
                        table.kv { @for (k, x) in &further {
                            tr { th { (words(k)) } td { (json(x, &format!("/{}", escape_pointer(k)))) } }
                        } }
                    }
                }
                section #run {
                    h2 { "Run" }
                    table.kv {
                        @if let Some(p) = v.get("provenance") {
                            tr { th { "command line" } td { code { (p["command_line"].as_str().unwrap_or("")) } } }
                            tr { th { "odocal version" } td { (p["version"].as_str().unwrap_or("")) } }
                            tr { th { "input SHA-256" } td { code { (p["input_sha256"].as_str().unwrap_or("")) } } }
                            tr { th { "input size (bytes)" } td { (json(&p["input_bytes"], "/provenance/input_bytes")) } }
                            tr { th { "wall time (s)" } td { (num("/provenance/wall_time_s", r.provenance.as_ref().map_or(f64::NAN, |p| p.wall_time_s), 1.0, 3)) } }
                        }
                    }
                }
            }
        }
    }
    .into_string()
}

//! The page's "Data and solution" section: the values of results.json that describe the
//! data and the solution, each under a human label with a one-line meaning, in the
//! summary's units (mm and ° for the parameters, mm and mrad for covariances), the
//! observability and two-halves values as labelled tables and sentences.

use crate::html::{escape_pointer, json, num, scaled, words, PARAMETER_LABELS};
use maud::{html, Markup};
use serde_json::Value;

/// Degrees per radian.
const DEG: f64 = 180.0 / std::f64::consts::PI;

/// One row of the section: results.json key, label, what the value means.
pub(crate) struct Row {
    /// Top-level results.json key.
    pub key: &'static str,
    /// What the page calls it.
    pub label: &'static str,
    /// What it means, in one line.
    pub meaning: &'static str,
}

/// The rows, in order. `time_offset_sigma_s` is shown with `time_offset_s`.
pub(crate) const ROWS: [Row; 30] = [
    Row { key: "log_contents", label: "What the input holds", meaning: "scans and wheel records read, lines skipped (lenient mode) and messages not understood" },
    Row { key: "samples_used", label: "Samples used", meaning: "scan pairs with their wheel rotations that entered the final estimate" },
    Row { key: "samples_synchronized", label: "Samples synchronized", meaning: "scan pairs matched and given the wheel rotations between their two scans, before outliers were trimmed" },
    Row { key: "samples_trimmed", label: "Samples trimmed as outliers", meaning: "samples whose residual was too large for the noise (slip, bad matches); left out of the estimate" },
    Row { key: "scan_pairs", label: "Scan pairs tried", meaning: "pairs of scans handed to the scan matcher" },
    Row { key: "discarded", label: "Pairs discarded, by cause", meaning: "pairs not used: a gap in the wheel data, too long between the scans, a failed match, the robot standing still" },
    Row { key: "match_rejections", label: "Failed matches, by reason", meaning: "why the scan matcher refused the pairs it could not match" },
    Row { key: "chained_matches", label: "Pairs matched through the scans between", meaning: "pairs refused when matched directly and matched as a chain of shorter matches (2 to 4) through the scans between their two; ŝ is the chain's composition" },
    Row { key: "neighbour_matches", label: "Pairs matched with their neighbouring scans", meaning: "pairs of sparse scans refused when matched alone and matched with each scan densified by the scan beyond it (the one before the first, the one after the second; the two beyond it when it has few returns), placed by odometry" },
    Row { key: "free_direction_matches", label: "Pairs matched along a corridor", meaning: "pairs of sparse scans whose match fixes the rotation and the displacement across the walls but not along them (a corridor, one wall): ŝ keeps odometry's first guess there, and the calibration gives that direction no weight" },
    Row { key: "match_self_check", label: "Scan-matching self-check", meaning: "the matcher's own error, from the closure of consecutive scan triples (a lower bound); closures far beyond the typical one are left out, as the solver leaves out samples" },
    Row { key: "stride", label: "Stride", meaning: "scans from the first to the second scan of a pair" },
    Row { key: "interval_s", label: "Pair interval", meaning: "target time (s) between the two scans of a pair" },
    Row { key: "ticks_per_revolution", label: "Encoder ticks per wheel turn", meaning: "wheel counts per revolution (wheel angles of a bag or of odometry are counted in 2²⁰ ticks per turn by convention)" },
    Row { key: "sm_sigma", label: "Scan-matching noise σ", meaning: "standard deviation of one scan match, per component, estimated from the residuals" },
    Row { key: "noise_weights", label: "Sample weights", meaning: "shaped: the typical match's σ (see the shaping), per sample shaped as the scan matcher's covariance of the sample compares with the typical match's (a spin matched through the scans between, a pair sharing few points weigh less); estimated: the scan-matching noise σ for every sample; sample_covariance: each sample's own covariance (--icp-covariance)" },
    Row { key: "noise_shaping", label: "Sample weights' shaping", meaning: "with shaped weights: the typical match's σ the samples were weighted by; per component, the share of the residuals' noise that follows the matcher's covariances (0: none, 1: as the matcher says); the level the σ of the estimate take with that blend" },
    Row { key: "time_offset_s", label: "Clock offset (laser − encoders)", meaning: "what was subtracted from the laser's timestamps to put them on the wheels' clock, with its σ" },
    Row { key: "time_offset_parameter_shift", label: "Parameters' move per σ of the clock offset", meaning: "how far r_L, r_R, b, ℓx, ℓy, ℓθ move when the clock offset moves by its σ (half the difference of the estimates solved at the offset ± σ); the covariance and the σ include it" },
    Row { key: "cost_before", label: "Cost at the closed form", meaning: "sum of the squared residuals, each in units of its σ (χ²), at the closed-form solution" },
    Row { key: "cost_after", label: "Cost after refinement", meaning: "the same sum after the non-linear refinement (it should not be larger)" },
    Row { key: "observability", label: "Observability", meaning: "how well the motion in the log determines each parameter" },
    Row { key: "shared_scan_noise", label: "Scan noise shared by consecutive samples", meaning: "consecutive samples share a scan, so their matching errors are correlated; the σ's account for it" },
    Row { key: "lateral_slip", label: "Sideways slide in turns", meaning: "a skid-steer robot's slide outward of its turns, v_y = −k·v·ω, checked on every log; weighed in with the six parameters by the evidence for it (in full from about 4σ, or when asked with --lateral-slip), whose σ then include not knowing k" },
    Row { key: "consistency", label: "The two halves of the log", meaning: "each half calibrated alone; the difference compared with its σ" },
    Row { key: "covariance", label: "Covariance of the estimate", meaning: "the uncertainty of the six parameters and how they move together; its diagonal is σ²" },
    Row { key: "closed_form", label: "Closed-form solution", meaning: "the linear least-squares estimate the refinement started from" },
    Row { key: "settings", label: "Settings", meaning: "the solver options of this run (outlier trimming, refinement, first guess, held or prior parameters)" },
    Row { key: "timing_s", label: "Time per stage", meaning: "seconds spent reading, synchronizing, matching, estimating the clock offset and solving" },
    Row { key: "time_offset_sigma_s", label: "Clock offset σ", meaning: "shown with the clock offset" },
];

/// Scale and unit of parameter `i` as the summary shows it: mm, or ° for ℓθ.
fn unit(i: usize) -> (f64, &'static str) {
    if i == 5 {
        (DEG, "°")
    } else {
        (1e3, "mm")
    }
}

/// The six parameters as a row of numbers headed by name and unit (mm, °).
fn parameter_vector(v: &Value, pointer: &str) -> Markup {
    html! {
        table.matrix {
            tr { @for i in 0..6 { th { (PARAMETER_LABELS[i]) " (" (unit(i).1) ")" } } }
            tr { @for i in 0..6 { td {
                @match v.get(i).and_then(Value::as_f64) {
                    Some(x) => (num(&format!("{pointer}/{i}"), x, unit(i).0, 4)),
                    None => "—",
                }
            } } }
        }
    }
}

/// A symmetric covariance matrix with labelled rows and columns, in mm and mrad (m and
/// rad × 1000: every entry × 10⁶).
fn covariance(v: &Value, pointer: &str, labels: &[&str]) -> Markup {
    html! {
        table.matrix {
            tr { th { } @for h in labels { th { (h) } } }
            @for (i, row) in v.as_array().into_iter().flatten().enumerate() {
                tr {
                    th { (labels.get(i).copied().unwrap_or("")) }
                    @for (k, x) in row.as_array().into_iter().flatten().enumerate() {
                        td { @match x.as_f64() {
                            Some(x) => (scaled(&format!("{pointer}/{i}/{k}"), x, 1e6)),
                            None => "—",
                        } }
                    }
                }
            }
        }
        p.note { "Entries in mm², mm·mrad or mrad² (the product of the row's and the column's units; lengths in mm, angles in mrad)." }
    }
}

/// The observability values: in words, the condition numbers, the motion and each
/// parameter's σ and verdict.
fn observability(v: &Value) -> Markup {
    let motion = &v["motion"];
    html! {
        @if let Some(s) = v["sentence"].as_str() { p { (s) "." } }
        table.kv {
            @if let Some(x) = v["step1_condition"].as_f64() {
                tr { th { "condition number, step 1 (r_L, r_R, b)" }
                     td { (scaled("/observability/step1_condition", x, 1.0)) " — how well the wheel odometry's least squares separates the wheel parameters (large: the motion does not)" } }
            }
            @if let Some(x) = v["a_condition"].as_f64() {
                tr { th { "condition number, step 2 (laser pose)" }
                     td { (scaled("/observability/a_condition", x, 1.0)) " — the same for the laser pose, in metres and radians" } }
            }
            @if let Some(x) = v["a_condition_scaled"].as_f64() {
                tr { th { "condition number, step 2, scaled" }
                     td { (scaled("/observability/a_condition_scaled", x, 1.0)) " — with each unknown scaled to its typical size: the one to read" } }
            }
            @if motion.is_object() {
                tr { th { "motion (samples)" } td {
                    @for (k, (key, what)) in [("spins", "spins in place"), ("straight", "straight"), ("turning_while_translating", "turning while translating"), ("still", "still")].iter().enumerate() {
                        @if k > 0 { ", " }
                        (json(&motion[*key], &format!("/observability/motion/{key}"))) " " (what)
                    }
                } }
            }
            tr { th { "wheel directions" } td { @match v["wheel_signs"].as_str() {
                Some(w) => (w),
                None => "as expected (both radii positive)",
            } } }
        }
        @if let Some(ps) = v["parameters"].as_array() {
            table {
                tr { th { "parameter" } th { "estimate" } th { "σ" } th { "unit" } th { "verdict" } }
                @for (i, p) in ps.iter().enumerate().take(6) {
                    @let (scale, u) = unit(i);
                    tr {
                        th { (PARAMETER_LABELS[i]) }
                        td { @if let Some(x) = p["value"].as_f64() { (num(&format!("/observability/parameters/{i}/value"), x, scale, 4)) } }
                        td { @if let Some(x) = p["sigma"].as_f64() { "± " (num(&format!("/observability/parameters/{i}/sigma"), x, scale, 4)) } }
                        td { (u) }
                        td { (words(p["verdict"].as_str().unwrap_or(""))) }
                    }
                }
            }
        }
    }
}

/// The two-halves check: not run (and why), or each parameter's difference against its
/// σ and the χ² against its limit, in words.
fn consistency(v: &Value) -> Markup {
    if let Some(reason) = v["not_available"]["reason"].as_str() {
        return html! { p { "Not compared: " (reason) "." } };
    }
    let c = v.get("checked").unwrap_or(v);
    let p = if v.get("checked").is_some() {
        "/consistency/checked"
    } else {
        "/consistency"
    };
    html! {
        @if let Some(s) = c["sentence"].as_str() { p { (s) } }
        table {
            tr { th { "parameter" } th { "first − second half" } th { "σ of the difference" } th { "unit" } th { "in σ" } }
            @for i in 0..6 {
                @let (scale, u) = unit(i);
                tr {
                    th { (PARAMETER_LABELS[i]) }
                    td { @if let Some(x) = c["difference"][i].as_f64() { (num(&format!("{p}/difference/{i}"), x, scale, 4)) } }
                    td { @if let Some(x) = c["sigma"][i].as_f64() { (num(&format!("{p}/sigma/{i}"), x, scale, 4)) } }
                    td { (u) }
                    td { @if let Some(x) = c["z"][i].as_f64() { (num(&format!("{p}/z/{i}"), x, 1.0, 2)) } }
                }
            }
        }
        @if let (Some(chi2), Some(limit)) = (c["chi2"].as_f64(), c["chi2_limit"].as_f64()) {
            p {
                "χ² of the difference: " (num(&format!("{p}/chi2"), chi2, 1.0, 2))
                " with " (json(&c["dof"], &format!("{p}/dof"))) " degrees of freedom, against "
                (num(&format!("{p}/chi2_limit"), limit, 1.0, 2))
                " at the 3σ (99.73 %) level: the halves "
                (if c["agree"].as_bool() == Some(true) { "agree" } else { "disagree" }) "."
            }
        }
    }
}

/// The scan-matching self-check in words.
fn self_check(v: &Value) -> Markup {
    let p = "/match_self_check";
    html! {
        p {
            (json(&v["triples"], &format!("{p}/triples"))) " of " (json(&v["tried"], &format!("{p}/tried")))
            " scan triples closed"
            @if v["left_out"].as_u64().is_some_and(|n| n > 0) {
                " (" (json(&v["left_out"], &format!("{p}/left_out"))) " more left out as outliers)"
            }
            "; one match's error: "
            @if let Some(x) = v["xy_m"].as_f64() { (num(&format!("{p}/xy_m"), x, 1e3, 3)) " mm" }
            @if let Some(x) = v["theta_rad"].as_f64() { ", " (num(&format!("{p}/theta_rad"), x, DEG, 4)) "°" }
            @if let Some(x) = v["range_noise_m"].as_f64() { "; the laser's range noise: " (num(&format!("{p}/range_noise_m"), x, 1e3, 2)) " mm" }
            "."
        }
    }
}

/// The sideways slide in words: k with its σ, the slip angle, whether it was applied.
fn lateral_slip(v: &Value) -> Markup {
    let p = "/lateral_slip";
    let applied = v["applied"].as_bool().unwrap_or(false);
    // Results written before the weighing have no weight: the slide was all or nothing.
    let weight = v["weight"].as_f64().unwrap_or(1.0);
    html! {
        p {
            "k = " (json(&v["k"], &format!("{p}/k"))) " ± " (json(&v["sigma"], &format!("{p}/sigma"))) " s"
            @if let Some(k) = v["k"].as_f64() { " (a " (format!("{:.1}", k.atan().to_degrees())) "° slip angle at 1 rad/s)" }
            "; ℓx with the slide minus ℓx without: "
            @if let Some(d) = v["l_x_shift"].as_f64() { (num(&format!("{p}/l_x_shift"), d, 1e3, 2)) " mm" }
            @if applied && weight < 1.0 {
                "; weighed in at " (format!("{:.0}", 100.0 * weight)) " % by its evidence: the parameters are the two models' mixture, and their σ include both and the difference between them."
            } @else if applied { "; estimated: the parameters and their σ include it." } @else { "; not estimated: the parameters are the differential-drive ones." }
        }
    }
}

/// The value of row `key` in the section's units.
fn value(key: &str, x: &Value, all: &Value) -> Markup {
    let pointer = format!("/{}", escape_pointer(key));
    match key {
        "closed_form" | "time_offset_parameter_shift" => parameter_vector(x, &pointer),
        "covariance" => covariance(x, &pointer, &PARAMETER_LABELS),
        "sm_sigma" => html! {
            @for (i, (name, scale, u)) in [("x", 1e3, "mm"), ("y", 1e3, "mm"), ("θ", DEG, "°")].iter().enumerate() {
                @if i > 0 { ", " }
                (name) " " @match x.get(i).and_then(Value::as_f64) {
                    Some(s) => (num(&format!("{pointer}/{i}"), s, *scale, 4)),
                    None => "—",
                } " " (u)
            }
        },
        "shared_scan_noise" => html! {
            table.kv {
                @if let Some(f) = x["shared_fraction"].as_array() {
                    tr { th { "share of the noise shared (x, y, θ)" } td {
                        @for (i, s) in f.iter().enumerate() {
                            @if i > 0 { ", " }
                            @if let Some(s) = s.as_f64() { (num(&format!("{pointer}/shared_fraction/{i}"), s, 100.0, 0)) " %" }
                        }
                    } }
                }
                tr { th { "shared scans" } td { (json(&x["shared_scans"], &format!("{pointer}/shared_scans"))) } }
                tr { th { "window (samples)" } td { (json(&x["window"], &format!("{pointer}/window"))) } }
                @for (k, label) in [("per_scan", "covariance per scan"), ("per_sample", "covariance per sample")] {
                    @if x[k].is_array() {
                        tr { th { (label) } td { (covariance(&x[k], &format!("{pointer}/{k}"), &["x", "y", "θ"])) } }
                    }
                }
            }
        },
        "lateral_slip" => lateral_slip(x),
        "observability" => observability(x),
        "consistency" => consistency(x),
        "match_self_check" => self_check(x),
        "time_offset_s" => html! {
            @if let Some(t) = x.as_f64() {
                (num("/time_offset_s", t, 1e3, 2))
                @if let Some(s) = all.get("time_offset_sigma_s").and_then(Value::as_f64) {
                    " ± " (num("/time_offset_sigma_s", s, 1e3, 2))
                }
                " ms"
            }
        },
        "interval_s" => html! { (json(x, &pointer)) " s" },
        _ => json(x, &pointer),
    }
}

/// The section's table: every row whose key results.json has.
pub(crate) fn section(v: &Value) -> Markup {
    html! {
        table.kv.data {
            @for row in ROWS.iter().filter(|r| r.key != "time_offset_sigma_s") {
                @if let Some(x) = v.get(row.key) {
                    tr id=(format!("data-{}", row.key)) {
                        th { (row.label) }
                        td { (value(row.key, x, v)) p.meaning { (row.meaning) } }
                    }
                }
            }
        }
    }
}

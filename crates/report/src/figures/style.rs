//! What every figure shares: size, fonts, colours, data ranges, and a legend drawn
//! in its own strip beside or above the plot, where it covers no data.

use super::DrawError;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Figure width (px).
pub const WIDTH: u32 = 860;
/// Font family.
pub const FONT: &str = "sans-serif";
/// Samples used by the estimate.
pub const USED: RGBColor = RGBColor(31, 119, 180);
/// Samples trimmed as outliers.
pub const TRIMMED: RGBColor = RGBColor(214, 39, 40);
/// Shaded time spans (slip episodes).
pub const SPAN: RGBColor = RGBColor(255, 187, 0);

/// How a legend entry is drawn.
pub enum Mark {
    /// A line of this colour and width.
    Line(RGBColor, u32),
    /// A dashed line.
    Dashed(RGBColor, u32),
    /// A filled dot.
    Dot(RGBColor),
    /// A cross.
    Cross(RGBColor),
    /// A filled square.
    Square(RGBColor),
    /// A shaded band.
    Band(RGBColor),
}

/// Draws a marker `m` centred at pixel `(x, y)` of `area`.
fn draw_mark(
    area: &DrawingArea<SVGBackend, Shift>,
    m: &Mark,
    x: i32,
    y: i32,
) -> Result<(), DrawError> {
    match *m {
        Mark::Line(c, w) => area.draw(&PathElement::new(
            vec![(x - 12, y), (x + 12, y)],
            c.stroke_width(w),
        ))?,
        Mark::Dashed(c, w) => {
            for k in 0..3 {
                let a = x - 12 + 9 * k;
                area.draw(&PathElement::new(
                    vec![(a, y), (a + 5, y)],
                    c.stroke_width(w),
                ))?;
            }
        }
        Mark::Dot(c) => area.draw(&Circle::new((x, y), 3, c.filled()))?,
        Mark::Cross(c) => area.draw(&Cross::new((x, y), 4, c.stroke_width(2)))?,
        Mark::Square(c) => area.draw(&Rectangle::new(
            [(x - 4, y - 4), (x + 4, y + 4)],
            c.filled(),
        ))?,
        Mark::Band(c) => area.draw(&Rectangle::new(
            [(x - 12, y - 6), (x + 12, y + 6)],
            c.mix(0.35).filled(),
        ))?,
    }
    Ok(())
}

/// A legend as a column of entries, from the top-left of `area`.
pub fn legend_column(
    area: &DrawingArea<SVGBackend, Shift>,
    entries: &[(Mark, String)],
) -> Result<(), DrawError> {
    for (k, (m, label)) in entries.iter().enumerate() {
        let y = 50 + 22 * k as i32;
        draw_mark(area, m, 18, y)?;
        area.draw(&Text::new(label.clone(), (36, y - 7), (FONT, 14)))?;
    }
    Ok(())
}

/// A legend as one row of entries, left to right across `area`.
pub fn legend_row(
    area: &DrawingArea<SVGBackend, Shift>,
    entries: &[(Mark, String)],
) -> Result<(), DrawError> {
    let mut x = 80;
    for (m, label) in entries {
        draw_mark(area, m, x, 14)?;
        area.draw(&Text::new(label.clone(), (x + 18, 7), (FONT, 14)))?;
        x += 40 + 8 * label.chars().count() as i32;
    }
    Ok(())
}

/// The range of the finite `values` with a 5 % margin; never empty.
pub fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-12 * (1.0 + lo.abs()) {
        return (lo - 0.5, hi + 0.5);
    }
    let m = 0.05 * (hi - lo);
    (lo - m, hi + m)
}

/// A symmetric range ±(1.1 × the largest finite |value|); never empty.
pub fn symmetric_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let m = values
        .filter(|v| v.is_finite())
        .fold(0.0f64, |a, v| a.max(v.abs()));
    let m = if m > 0.0 { 1.1 * m } else { 1.0 };
    (-m, m)
}

/// Width of the legend strip beside a chart (px).
pub const LEGEND_W: u32 = 290;

/// A chart with two `f64` axes.
pub type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A chart over `x × y` filling `plot`, its axes drawn and labelled (the legend goes
/// in a strip [`LEGEND_W`] wide beside it).
pub fn xy_chart<'a, 'b>(
    plot: &'a DrawingArea<SVGBackend<'b>, Shift>,
    x: (f64, f64),
    y: (f64, f64),
    x_desc: &str,
    y_desc: &str,
) -> Result<Chart<'a, 'b>, DrawError> {
    let mut chart = ChartBuilder::on(plot)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FONT, 13))
        .light_line_style(TRANSPARENT)
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .draw()?;
    Ok(chart)
}

/// A new SVG figure of `WIDTH × height` drawn by `draw` on a white background.
pub fn svg(
    height: u32,
    draw: impl FnOnce(&DrawingArea<SVGBackend, Shift>) -> Result<(), DrawError>,
) -> Result<String, DrawError> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(out)
}

/// A tick label: at most four decimals, no trailing zeros, no "-0".
pub fn tick(v: &f64) -> String {
    let s = format!("{:.4}", v + 0.0);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_short() {
        assert_eq!(tick(&10.0), "10");
        assert_eq!(tick(&-0.0), "0");
        assert_eq!(tick(&-0.00001), "0");
        assert_eq!(tick(&0.25), "0.25");
    }

    #[test]
    fn ranges_are_never_empty() {
        assert_eq!(range(std::iter::empty()), (0.0, 1.0));
        assert_eq!(range([2.0, f64::NAN].into_iter()), (1.5, 2.5));
        assert_eq!(symmetric_range([-2.0, 1.0].into_iter()), (-2.2, 2.2));
    }
}

//! The plots of a report: error against time or evaluations on log-log
//! axes, unresolved errors on a dashed floor line, and one colour per rule
//! name that every page (Markdown SVGs and HTML alike) keeps.
//!
//! ```
//! use lightquad::experiment::plot::{rule_css, svg};
//!
//! // A rule has its colour on every page: Gauss–Legendre is always red.
//! assert_eq!(rule_css("gauss-legendre"), "#d62728");
//! // Error against n on log-log axes, one curve per rule.
//! let curve = |f: fn(f64) -> f64| [4.0, 16.0, 64.0].map(|n| (n, f(n))).to_vec();
//! let series = vec![
//!     ("trapezoid".to_string(), curve(|n| 0.1 / (n * n))),
//!     ("monte-carlo".to_string(), curve(|n| 0.3 / n.sqrt())),
//! ];
//! let page = svg("I_E: error against n", "n", &series, 1e-16)?.ok_or("nothing to plot")?;
//! assert!(page.contains("<svg") && page.contains("I_E: error against n"));
//! let lower = page.to_lowercase();
//! assert!(lower.contains(&rule_css("trapezoid")) && lower.contains(&rule_css("monte-carlo")));
//! // No finite point, no plot.
//! assert_eq!(svg("t", "n", &[("sobol".to_string(), vec![(4.0, f64::NAN)])], 1e-16)?, None);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use plotters::prelude::*;

/// The colours of the rules lightquad ships, by name, so a rule looks the same
/// on every page whatever else the page compares.
const KNOWN: [(&str, RGBColor); 10] = [
    ("trapezoid", RGBColor(31, 119, 180)),
    ("simpson", RGBColor(44, 160, 44)),
    ("gauss-legendre", RGBColor(214, 39, 40)),
    ("gauss-kronrod", RGBColor(148, 103, 189)),
    ("monte-carlo", RGBColor(255, 127, 14)),
    ("stratified", RGBColor(140, 86, 75)),
    ("sobol", RGBColor(227, 119, 194)),
    ("delta-tracking", RGBColor(23, 190, 207)),
    ("ratio-tracking", RGBColor(188, 189, 34)),
    ("residual-ratio-tracking", RGBColor(127, 127, 127)),
];

/// Colours for other labels (products, a user family's estimators, a rule
/// named twice), picked by a hash of the label.
const OTHER: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(174, 89, 0),
    RGBColor(0, 110, 90),
    RGBColor(90, 60, 160),
    RGBColor(160, 0, 90),
    RGBColor(70, 110, 0),
    RGBColor(0, 70, 140),
    RGBColor(120, 120, 40),
];

/// The colour of a rule, from its label alone: the same on every page.
pub fn rule_colour(label: &str) -> RGBColor {
    if let Some((_, c)) = KNOWN.iter().find(|(n, _)| *n == label) {
        return *c;
    }
    // FNV-1a: stable across runs and platforms (std's hasher is not).
    let hash = label.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    });
    OTHER[(hash % OTHER.len() as u64) as usize]
}

/// The colour of a rule as CSS `#rrggbb`.
pub fn rule_css(label: &str) -> String {
    let RGBColor(r, g, b) = rule_colour(label);
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// Error against `x` (time or n) as SVG text, one log-log curve per rule
/// (`series`: label and points); None when no point is finite.
pub fn svg(
    title: &str,
    x_label: &str,
    series: &[(String, Vec<(f64, f64)>)],
    floor: f64,
) -> Result<Option<String>, String> {
    // Errors at or below `floor` (exact zeros, the rounding floor, the
    // reference's own accuracy) are not resolved: they are drawn on a dashed
    // floor line as open markers, not as numbers on the axis.
    let series: Vec<(String, Vec<(f64, f64)>)> = series
        .iter()
        .map(|(name, s)| {
            let kept = s.iter().filter(|(x, y)| !y.is_nan() && !x.is_nan());
            (
                name.clone(),
                kept.map(|&(x, y)| (x, y.max(floor))).collect(),
            )
        })
        .collect();
    let series = &series;
    let pts: Vec<(f64, f64)> = series.iter().flat_map(|s| s.1.iter().copied()).collect();
    if pts.is_empty() {
        return Ok(None);
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in &pts {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    // Whole decades, at least two wide on each axis. The axes are linear in
    // the decade exponent, labelled 1eN: plotters' own log axis misbehaves
    // on ranges that are narrow or start off a decade, and looped without
    // end over an error range of 320 decades (a reference of 1.5e-305
    // beside errors of 1e0).
    let decades = |lo: f64, hi: f64| {
        let a = lo.log10().floor().clamp(-330.0, 310.0);
        let b = hi.log10().ceil().clamp(-330.0, 310.0).max(a + 2.0);
        (a, b)
    };
    let (x0, x1) = decades(x0, x1);
    // A decade below the floor line, so it is not drawn on the axis.
    let at_floor = pts.iter().any(|&(_, y)| y <= floor);
    let y0 = if at_floor { y0.min(floor / 10.0) } else { y0 };
    let (y0, y1) = decades(y0, y1);
    // A point's place, an infinite error (or 0 against a floor of 0) on the
    // chart's edge.
    let at = |(x, y): (f64, f64)| (x.log10().clamp(x0, x1), y.log10().clamp(y0, y1));
    // A label per decade up to 12, else per step of whole decades.
    let labels = |a: f64, b: f64| (b - a + 1.0).min(12.0) as usize;
    let decade = |v: &f64| {
        if (v - v.round()).abs() < 1e-9 {
            format!("1e{}", v.round())
        } else {
            String::new()
        }
    };
    // The legend panel is wide enough for a product label of two rule names.
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (1020, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        // The legend gets a panel of its own on the right, so it never hides a curve.
        let (left, right) = root.split_horizontally(700);
        let mut chart = ChartBuilder::on(&left)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(48)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc("error (relative; absolute where the reference is 0)")
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .x_labels(labels(x0, x1))
            .y_labels(labels(y0, y1))
            .x_label_formatter(&decade)
            .y_label_formatter(&decade)
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, (name, s)) in series.iter().enumerate() {
            let colour = rule_colour(name);
            chart
                .draw_series(LineSeries::new(
                    s.iter().map(|&p| at(p)),
                    colour.stroke_width(2),
                ))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(
                    s.iter()
                        .filter(|&&(_, y)| y > floor)
                        .map(|&p| Circle::new(at(p), 3, colour.filled())),
                )
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(
                    s.iter()
                        .filter(|&&(_, y)| y <= floor)
                        .map(|&p| Circle::new(at(p), 5, colour.stroke_width(2))),
                )
                .map_err(|e| e.to_string())?;
            let y = 60 + 24 * i as i32;
            right
                .draw(&PathElement::new(
                    vec![(8, y), (34, y)],
                    colour.stroke_width(3),
                ))
                .map_err(|e| e.to_string())?;
            right
                .draw(&Text::new(name.clone(), (42, y - 8), ("sans-serif", 14)))
                .map_err(|e| e.to_string())?;
        }
        if pts.iter().any(|&(_, y)| y <= floor) {
            let grey = RGBColor(110, 110, 110);
            chart
                .draw_series(DashedLineSeries::new(
                    [(x0, floor.log10()), (x1, floor.log10())],
                    6,
                    4,
                    grey.stroke_width(1),
                ))
                .map_err(|e| e.to_string())?;
            let y = 60 + 24 * series.len() as i32 + 12;
            right
                .draw(&Circle::new((21, y), 5, grey.stroke_width(2)))
                .map_err(|e| e.to_string())?;
            right
                .draw(&Text::new(
                    format!("error at or below {floor:.0e} (not resolved:"),
                    (42, y - 8),
                    ("sans-serif", 14),
                ))
                .map_err(|e| e.to_string())?;
            right
                .draw(&Text::new(
                    "exact, rounding, or the reference's accuracy)",
                    (42, y + 10),
                    ("sans-serif", 14),
                ))
                .map_err(|e| e.to_string())?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(Some(text))
}

#[cfg(test)]
mod tests {
    use super::svg;

    /// Errors across the whole f64 range (a reference of 1.5e-305 beside an
    /// error of 1e305, 5e-324, an infinite error) are plotted, and promptly:
    /// plotters' log axis looped without end over 320 decades. A thread and
    /// a deadline make a hang a failure.
    #[test]
    fn a_plot_over_every_decade_of_f64_finishes_with_its_decades_labelled()
    -> Result<(), Box<dyn std::error::Error>> {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let series = vec![
                (
                    "gauss-legendre".to_string(),
                    vec![(2.0, 1e305), (8.0, 1e-16), (64.0, 5e-324)],
                ),
                (
                    "trapezoid".to_string(),
                    vec![(3.0, f64::INFINITY), (9.0, 1e-300)],
                ),
            ];
            let _ = tx.send(svg("wide", "n", &series, 1e-320));
        });
        let page = rx
            .recv_timeout(std::time::Duration::from_secs(60))
            .map_err(|_| "the plot did not finish within 60 s")??
            .ok_or("no points")?;
        // Whole decades labelled 1eN, the top beyond 1e305.
        let labels: Vec<&str> = page
            .lines()
            .filter(|l| l.starts_with("1e") && l[2..].parse::<i32>().is_ok())
            .collect();
        assert!(labels.len() >= 6, "{labels:?}");
        assert!(
            labels
                .iter()
                .any(|l| l[2..].parse::<i32>().is_ok_and(|e| e >= 250)),
            "{labels:?}"
        );
        assert!(
            labels
                .iter()
                .any(|l| l[2..].parse::<i32>().is_ok_and(|e| e <= -250)),
            "{labels:?}"
        );
        assert!(
            !page.contains("NaN") && !page.contains("inf"),
            "a non-finite coordinate"
        );
        Ok(())
    }
}

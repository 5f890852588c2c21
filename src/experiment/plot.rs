//! The plots of a report: error against time or evaluations on log-log
//! axes, unresolved errors on a dashed floor line, and a colour per rule:
//! no two rules of a page alike, and a shipped rule's the same on every page
//! (Markdown SVGs and HTML alike).
//!
//! ```
//! use lightquad::experiment::plot::{Palette, rule_css, svg};
//!
//! // A rule has its colour on every page: Gauss–Legendre is always red.
//! assert_eq!(rule_css("gauss-legendre"), "#d62728");
//! // Error against n on log-log axes, one curve per rule.
//! let curve = |f: fn(f64) -> f64| [4.0, 16.0, 64.0].map(|n| (n, f(n))).to_vec();
//! let series = vec![
//!     ("trapezoid".to_string(), curve(|n| 0.1 / (n * n))),
//!     ("monte-carlo".to_string(), curve(|n| 0.3 / n.sqrt())),
//! ];
//! let palette = Palette::new(series.iter().map(|s| s.0.as_str()));
//! let page = svg("I_E: error against n", "n", &series, 1e-16, &palette)?.ok_or("nothing to plot")?;
//! assert!(page.contains("<svg") && page.contains("I_E: error against n"));
//! let lower = page.to_lowercase();
//! assert!(lower.contains(&rule_css("trapezoid")) && lower.contains(&rule_css("monte-carlo")));
//! // No finite point, no plot.
//! assert_eq!(svg("t", "n", &[("sobol".to_string(), vec![(4.0, f64::NAN)])], 1e-16, &palette)?, None);
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
/// named twice): a label takes the one its hash picks unless a rule of the
/// same page holds it, else the first free one.
const OTHER: [RGBColor; 12] = [
    RGBColor(0, 0, 0),
    RGBColor(174, 89, 0),
    RGBColor(0, 110, 90),
    RGBColor(90, 60, 160),
    RGBColor(160, 0, 90),
    RGBColor(70, 110, 0),
    RGBColor(0, 70, 140),
    RGBColor(120, 120, 40),
    RGBColor(230, 50, 130),
    RGBColor(0, 160, 110),
    RGBColor(110, 0, 0),
    RGBColor(60, 60, 60),
];

/// The colour a label has wherever it appears alone: a shipped rule's own,
/// else the one its hash picks.
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
    css(rule_colour(label))
}

fn css(RGBColor(r, g, b): RGBColor) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// The colours of one page's rules, no two alike: a shipped rule keeps its
/// own colour on every page, and every other label takes [`rule_colour`]'s
/// choice where no rule of the page holds it, else the first free colour.
///
/// ```
/// use lightquad::experiment::plot::{Palette, rule_css};
///
/// let labels = ["gauss-legendre", "genz-malik", "centre", "corner", "mis-power"];
/// let page = Palette::new(labels);
/// let mut seen: Vec<String> = labels.iter().map(|l| page.css(l)).collect();
/// assert_eq!(seen[0], rule_css("gauss-legendre"));
/// seen.sort();
/// seen.dedup();
/// assert_eq!(seen.len(), labels.len());
/// ```
#[derive(Debug, Clone, Default)]
pub struct Palette(Vec<(String, RGBColor)>);

impl Palette {
    /// The palette of a page showing `labels` (repeats are one rule).
    pub fn new<'a>(labels: impl IntoIterator<Item = &'a str>) -> Self {
        let mut labels: Vec<&str> = labels.into_iter().collect();
        let mut seen = std::collections::HashSet::new();
        labels.retain(|l| seen.insert(*l));
        let shipped = |l: &str| KNOWN.iter().any(|(n, _)| *n == l);
        let mut taken: Vec<(String, RGBColor)> = labels
            .iter()
            .filter(|l| shipped(l))
            .map(|l| (l.to_string(), rule_colour(l)))
            .collect();
        // Beyond the fixed colours, hues a golden angle apart.
        let spare = OTHER
            .into_iter()
            .chain(KNOWN.map(|(_, c)| c))
            .chain((0..4096).map(|i| hue(0.618_034 * f64::from(i))));
        for l in labels.iter().filter(|l| !shipped(l)) {
            let free = |c: &RGBColor| taken.iter().all(|(_, t)| t != c);
            let own = rule_colour(l);
            let colour = if free(&own) {
                own
            } else {
                let mut spare = spare.clone();
                spare.find(free).unwrap_or(own)
            };
            taken.push((l.to_string(), colour));
        }
        Palette(taken)
    }

    /// The colour of `label` on this page ([`rule_colour`] for a label the
    /// page was not told of).
    pub fn colour(&self, label: &str) -> RGBColor {
        self.0
            .iter()
            .find(|(l, _)| l == label)
            .map_or_else(|| rule_colour(label), |(_, c)| *c)
    }

    /// The colour of `label` on this page as CSS `#rrggbb`.
    pub fn css(&self, label: &str) -> String {
        css(self.colour(label))
    }
}

/// A saturated, mid-dark colour at hue `turns` (fraction of a turn).
fn hue(turns: f64) -> RGBColor {
    let h = turns.fract() * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    let c = |v: f64| (40.0 + 150.0 * v).round() as u8;
    RGBColor(c(r), c(g), c(b))
}

/// Error against `x` (time or n) as SVG text, one log-log curve per rule
/// (`series`: label and points); None when no point is finite.
pub fn svg(
    title: &str,
    x_label: &str,
    series: &[(String, Vec<(f64, f64)>)],
    floor: f64,
    palette: &Palette,
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
            let colour = palette.colour(name);
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
            let palette = super::Palette::new(series.iter().map(|s| s.0.as_str()));
            let _ = tx.send(svg("wide", "n", &series, 1e-320, &palette));
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

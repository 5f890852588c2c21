//! One quantity of an experiment page, computed once and shown by both the
//! Markdown and the HTML page: its rows, fitted orders, times to the targets,
//! plots and images, and the cells and lines both pages print.

use std::collections::BTreeMap;

use super::Page;
use super::fitted::{Reach, Slope};
use super::order::{Against, FIT_ROWS, fit_floor, fitted};
use super::pictures::{Picture, pictures};
use super::ranking::Ranked;
use super::rows::{FLOOR, Row, RowFlag, rows, scale_of};
use crate::experiment::plot;
use crate::experiment::reference::rms;
use crate::experiment::run::JobResult;
use crate::family::{Display, Flag};

/// An error for a table cell: "—" where there is none (a failed row).
pub fn cell(x: f64) -> String {
    if x.is_nan() {
        "—".into()
    } else {
        format!("{x:.2e}")
    }
}

/// A mean count for a table cell, or "—" where none was counted (NaN).
pub fn count_cell(x: f64) -> String {
    if x.is_nan() {
        "—".into()
    } else {
        format!("{x:.0}")
    }
}

/// A value for a table cell: the number, or the root mean square of the
/// channels with their count.
pub fn show_value(v: &[f64]) -> String {
    match v {
        [] => "—".into(),
        [x] => format!("{x:.15e}"),
        _ => format!("rms {:.15e} ({} channels)", rms(v.iter().copied()), v.len()),
    }
}

/// One quantity of an experiment page, computed once and shown by both the
/// Markdown and the HTML page.
#[derive(Debug, Clone)]
pub struct Section {
    /// The quantity.
    pub quantity: &'static str,
    /// The reference value as shown, or why there is none (then the rest is empty).
    pub reference: Result<String, String>,
    /// A row per (rule, budget).
    pub rows: Vec<Row>,
    /// The heading of the slope-against-budget column.
    pub slope_heading: String,
    /// A line per rule: fitted slopes and times to the targets.
    pub fits: Vec<Fit>,
    /// The plots: (what they show, file name, SVG text).
    pub plots: Vec<(&'static str, String, String)>,
    /// Each rule's time to the middle target.
    pub ranking: Vec<Ranked>,
    /// For an image-valued quantity: the reference's image and each rule's
    /// at its largest budget, with error heat maps.
    pub pictures: Vec<Picture>,
    /// The random rules' statistical verdicts, budget by budget.
    pub verdicts: Vec<super::verdict::RuleVerdicts>,
}

/// A rule's fitted slopes and times to the targets, as numbers and as shown.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The rule's index in the file.
    pub rule_index: usize,
    /// The rule's label.
    pub label: String,
    /// The slope against the resolution per axis, with its interval.
    pub resolution_slope: Option<Slope>,
    /// The slope against evaluations, with its interval.
    pub evaluations_slope: Option<Slope>,
    /// Per target: reached (with the row's time), not reached (with an
    /// extrapolation where the order allows), or below the reference's accuracy.
    pub reach: Vec<Reach>,
    /// The slope of log error against log budget per axis ("—": too few rows).
    pub slope_budget: String,
    /// The slope of log error against log evaluations.
    pub slope_evaluations: String,
    /// Per target as shown: the time in seconds, "not reached" (with its
    /// extrapolation) or "below reference accuracy".
    pub times: Vec<String>,
}

/// Computes the sections of a page, one per quantity in the file's order.
pub fn sections(page: &Page, results: &[JobResult]) -> Result<Vec<Section>, String> {
    let mut out = Vec::new();
    for (i, &q) in page.quantities.iter().enumerate() {
        let Some(reference) = page.reference.values.get(q) else {
            let why = page
                .reference
                .missing
                .get(q)
                .map_or("no reference value", String::as_str);
            out.push(Section {
                quantity: q,
                reference: Err(why.to_string()),
                rows: Vec::new(),
                slope_heading: String::new(),
                fits: Vec::new(),
                plots: Vec::new(),
                ranking: Vec::new(),
                pictures: Vec::new(),
                verdicts: Vec::new(),
            });
            continue;
        };
        let display = page.displays.get(i).copied().flatten();
        let doubt = display
            .as_ref()
            .map(|d| in_doubt(d, q, reference, page))
            .unwrap_or_default();
        let mut rows = rows(
            &page.rules,
            results,
            q,
            reference,
            display.as_ref().map(|d| (d, doubt.as_slice())),
        );
        let accuracy = page.reference.accuracy_of(q);
        for r in rows.iter_mut() {
            if accuracy > 0.0 && r.rel_error <= accuracy {
                r.flags.push(RowFlag::AtReferenceAccuracy(accuracy));
                // The true error is known only to be below the reference's
                // accuracy: an estimate is contradicted only beyond ten
                // times that.
                if r.rel_estimate <= 10.0 * accuracy.max(100.0 * FLOOR) {
                    r.flags.retain(|f| *f != RowFlag::EstimateOff);
                }
            }
        }
        let pictures = match page.images.get(i).copied().flatten() {
            Some(shape) => pictures(page, q, shape, reference, &rows)?,
            None => Vec::new(),
        };
        let mut section = orders_and_plots(page, q, show_value(reference), rows)?;
        section.pictures = pictures;
        section.verdicts = super::verdict::verdicts(page, results, q);
        out.push(section);
    }
    Ok(out)
}

/// The rules whose minimum budget for some quantity is above the smallest
/// budget, in words: the minimum, and the quantities it holds for where
/// the others start lower.
pub fn skipped(page: &Page) -> Vec<String> {
    let Some(&first) = page.budgets.first() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for r in &page.rules {
        let mut by_least: BTreeMap<usize, Vec<&str>> = BTreeMap::new();
        for &q in &page.quantities {
            by_least.entry(r.min_budget_of(q)).or_default().push(q);
        }
        let one = by_least.len() == 1;
        for (least, qs) in by_least.into_iter().filter(|(least, _)| *least > first) {
            out.push(if one {
                format!("{} needs at least {least}", r.label)
            } else {
                format!("{} needs at least {least} for {}", r.label, qs.join(", "))
            });
        }
    }
    out
}

/// The rules that did not run at all, and why, in words.
pub fn not_run(page: &Page) -> Vec<String> {
    page.rules
        .iter()
        .filter_map(|r| Some(format!("{} ({})", r.label, r.not_run.as_ref()?)))
        .collect()
}

/// Whether a quantity's table has the largest-channel-error column (several
/// channels) and the display column (a display and a row that counted).
pub fn extra_columns<'a>(
    rows: &[Row],
    display: Option<&'a Display>,
) -> (bool, Option<&'a Display>) {
    let multi = rows.iter().any(|r| r.value.len() > 1);
    let display = display.filter(|_| rows.iter().any(|r| r.display_off.is_some()));
    (multi, display)
}

/// A count of displayed values off, as shown ("—" where none was counted).
pub fn off_cell(off: Option<f64>) -> String {
    match off {
        None => "—".into(),
        Some(x) if x.fract() == 0.0 => format!("{x:.0}"),
        Some(x) => format!("{x:.1}"),
    }
}

/// What the display column shows, in words: half a step against the
/// table's scale, per rule the first budget from which every larger budget
/// leaves every displayed value equal to the reference's, and how many of
/// the reference's own displayed values its accuracy leaves in doubt.
pub fn display_line(
    display: &Display,
    q: &str,
    reference: &[f64],
    rows: &[Row],
    page: &Page,
) -> String {
    let scale = scale_of(reference);
    let unsure = in_doubt(display, q, reference, page)
        .iter()
        .filter(|&&d| d)
        .count();
    let unsure =
        if page.reference.accuracy_of(q) > 0.0 || page.reference.channel_accuracy.contains_key(q) {
            let how = if page.reference.channel_accuracy.contains_key(q) {
                "Each channel's accuracy (its last change or own error estimate, the larger, \
             and at least 1e-13 of its value)"
            } else {
                "The reference's accuracy"
            };
            format!(
                " {how} leaves {unsure} of the reference's own displayed values in doubt (within \
             it of a step boundary, such as a constant background of 0.3, 76.5 steps): those \
             channels are not counted, in the column or here."
            )
        } else {
            String::new()
        };
    let mut settled = Vec::new();
    for (i, rule) in page.rules.iter().enumerate() {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.rule_index == i).collect();
        let from = (0..mine.len())
            .find(|&k| mine[k..].iter().all(|r| r.display_off == Some(0.0)))
            .map(|k| mine[k].budget);
        let best = mine
            .iter()
            .filter_map(|r| r.display_off)
            .fold(f64::INFINITY, f64::min);
        settled.push(match from {
            Some(n) => format!("{} from n = {n}", rule.label),
            None if best.is_finite() => format!(
                "{} never (at best {} off)",
                rule.label,
                off_cell(Some(best))
            ),
            None => format!("{} never", rule.label),
        });
    }
    format!(
        "{name}: a channel's displayed value; {total} in all. Half a display step, {h:.3e} absolute, \
         is {rel:.2e} on this table's relative scale: a largest channel error below it moves no \
         displayed value by more than one step. The displayed image equals the reference's \
         (and more work leaves it unchanged, against this reference): {list}.{unsure}",
        name = display.name,
        total = reference.len(),
        h = display.half_step,
        rel = display.half_step / scale,
        list = settled.join("; ")
    )
}

/// Per channel of quantity `q`'s reference, whether its displayed value is
/// in doubt: within its accuracy (the channel's own where the reference knows
/// it, the quantity's otherwise) of a step boundary, where it may display
/// either way.
fn in_doubt(display: &Display, q: &str, reference: &[f64], page: &Page) -> Vec<bool> {
    let overall = page.reference.accuracy_of(q) * scale_of(reference);
    let each = page.reference.channel_accuracy.get(q);
    reference
        .iter()
        .enumerate()
        .map(|(c, &r)| {
            let a = each.and_then(|e| e.get(c)).copied().unwrap_or(overall);
            (display.quantize)(r - a) != (display.quantize)(r + a)
        })
        .collect()
}

/// A line saying why evaluations exceed the budget, where a row's do (its
/// mean evaluations above its n), naming the largest ratio; `None` where no
/// row's do.
pub fn over_budget(page: &Page, rows: &[Row]) -> Option<String> {
    let worst = rows
        .iter()
        .filter(|r| r.budget > 0 && r.evaluations > r.budget as f64)
        .map(|r| r.evaluations / r.budget as f64)
        .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))?;
    Some(format!(
        "Evaluations above n (up to {worst:.1} n in this table): {}.",
        page.over_budget
    ))
}

/// The label of rule `i` of the page.
pub fn label(page: &Page, i: usize) -> String {
    page.rules
        .get(i)
        .map_or_else(|| format!("rule #{i}"), |r| r.label.clone())
}

/// Rule `i`'s fitted slopes (a deterministic rule whose error grows with
/// the budget inside the fitted rows, a kink that moves between nodes, has
/// no order either) and where it stands against each target.
fn fit(page: &Page, i: usize, mine: &[&Row], dimension: usize, accuracy: f64) -> Fit {
    let random = page.rules.get(i).is_some_and(|r| r.is_random);
    let resolution = Against::Resolution {
        dimension,
        by_budget: page.rules.get(i).and_then(|r| r.resolution.get(&dimension)),
    };
    let resolution_slope = Slope::of(mine, resolution, accuracy, random);
    let cost = fitted(mine, Against::Evaluations, accuracy);
    let evaluations_slope = cost.map(|o| Slope::from_order(o, random));
    // Only an order known to within a quarter extrapolates: the error's
    // distance to a target grows as a power of the slope's error.
    let order = cost.filter(|_| evaluations_slope.is_some_and(|s| s.extrapolates()));
    let reach: Vec<Reach> = page
        .targets
        .iter()
        .map(|&t| Reach::of(mine, t, accuracy, order.as_ref()))
        .collect();
    let shown = |s: Option<Slope>| s.map_or_else(|| "—".into(), |s| s.shown(random));
    Fit {
        rule_index: i,
        label: label(page, i),
        resolution_slope,
        evaluations_slope,
        slope_budget: shown(resolution_slope),
        slope_evaluations: shown(evaluations_slope),
        times: reach.iter().map(Reach::shown).collect(),
        reach,
    }
}

/// Fitted orders, times to the targets and the two plots of one quantity,
/// with each rule's time to the middle target.
fn orders_and_plots(
    page: &Page,
    q: &'static str,
    reference: String,
    rows: Vec<Row>,
) -> Result<Section, String> {
    let accuracy = page.reference.accuracy_of(q);
    let dimension = page
        .quantities
        .iter()
        .position(|x| *x == q)
        .and_then(|i| page.dimensions.get(i).copied())
        .unwrap_or(1);
    // Below this an error is not resolved: f64 rounding, or the reference's
    // own accuracy.
    let floor = accuracy.max(1e-16);
    let slope_heading = format!(
        "fitted slope of log error vs log of the resolution per axis that n buys{} (the intervals \
         of the points a composite rule uses, nodes or samples per axis otherwise: order p shows \
         as -p; the largest {FIT_ROWS} budgets whose error is above {:.1e}, ten times the \
         reference's accuracy and the f64 rounding floor)",
        if dimension > 1 {
            format!(", about n^(1/{dimension})")
        } else {
            String::new()
        },
        fit_floor(floor),
    );
    let middle = page.middle_target();
    let (mut ranking, mut fits, mut by_time, mut by_n) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..page.rules.len() {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.rule_index == i).collect();
        if mine.is_empty() {
            continue;
        }
        let label = label(page, i);
        let fit = fit(page, i, &mine, dimension, accuracy);
        // The middle target is one of the targets, already judged.
        let at_middle = match fit.reach.get(page.targets.len() / 2) {
            Some(r) => r.clone(),
            None => Reach::of(&mine, middle, accuracy, None),
        };
        fits.push(fit);
        let first = mine
            .iter()
            .filter(|r| !r.rel_error.is_nan())
            .min_by_key(|r| r.budget);
        ranking.push(Ranked {
            label: label.clone(),
            target: middle,
            seconds: at_middle.seconds(),
            time: at_middle.interval(),
            // At the floor from the first budget, deterministic or random
            // (a random rule whose every sample agrees sees a constant
            // integrand), unless the value underflowed: 0 against 0 is not
            // an easy integrand but one f64 cannot hold.
            exact_from_start: first.is_some_and(|r| {
                r.rel_error <= fit_floor(accuracy)
                    && !r.flags.contains(&RowFlag::Job(Flag::Underflow))
            }),
        });
        // NaN (failed) rows are dropped; the plot puts unresolved errors on
        // its floor line.
        // An underflowed row (0 against a reference that also reads 0) is
        // not an error at the floor: it is dropped like a failed one, and
        // the rows and the log-space quantity (`ln_tau`) say why.
        let err = |r: &&Row| {
            if r.flags.contains(&RowFlag::Job(Flag::Underflow)) {
                f64::NAN
            } else {
                r.rel_error
            }
        };
        by_time.push((
            label.clone(),
            mine.iter().map(|r| (r.seconds.max(1e-9), err(r))).collect(),
        ));
        by_n.push((
            label,
            mine.iter()
                .map(|r| (r.evaluations.max(1.0), err(r)))
                .collect(),
        ));
    }
    let base = format!("{}-{q}", page.name);
    let mut plots = Vec::new();
    let drawn = [
        ("time", "time", "median run time (s)", by_time),
        ("evaluations", "n", "evaluations", by_n),
    ];
    for (what, suffix, x_label, series) in drawn {
        let title = format!("{}: {q} error against {what}", page.name);
        if let Some(text) = plot::svg(&title, x_label, &series, floor, &page.palette())? {
            plots.push((what, format!("{base}-{suffix}.svg"), text));
        }
    }
    // A reference of 0 that the rows' values underflow to is not 0.
    let reference = if rows
        .iter()
        .any(|r| r.flags.contains(&RowFlag::Job(Flag::Underflow)))
        && page
            .reference
            .values
            .get(q)
            .is_some_and(|v| v.iter().all(|&x| x == 0.0))
    {
        format!("{reference}: the true value underflows f64; its logarithm is exact (ln_tau)")
    } else {
        reference
    };
    Ok(Section {
        quantity: q,
        reference: Ok(reference),
        rows,
        slope_heading,
        fits,
        plots,
        ranking,
        pictures: Vec::new(),
        verdicts: Vec::new(),
    })
}

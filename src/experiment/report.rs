//! Reports, the sinks of a run: per experiment a Markdown page (a table per
//! quantity, fitted orders, time to reach target errors, stability flags) with
//! SVG plots of error against time and against n, a CSV of every job, and an
//! index page that links every experiment and ranks the rules by time to error.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use super::fit::fitted_order;
use super::run::{JobResult, write_atomic};
use super::spec::Quantity;
use super::validate::Experiment;

/// One row of a report table: a rule at one budget, aggregated over repeats.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Index of the rule in the file.
    pub rule_index: usize,
    /// Rule name.
    pub rule: String,
    /// Budget.
    pub budget: usize,
    /// Mean value over repeats.
    pub value: f64,
    /// Root-mean-square true error over repeats, relative to the reference.
    pub rel_error: f64,
    /// Mean estimated error, relative to the reference.
    pub rel_estimate: f64,
    /// Mean evaluations.
    pub evaluations: f64,
    /// Median wall time, seconds.
    pub seconds: f64,
    /// Stability flags.
    pub flags: Vec<String>,
}

/// Relative errors below this are at the f64 rounding floor: no order is
/// fitted through them and no estimate is judged against them.
const FLOOR: f64 = 1e-14;

/// The lower median (of two repeats, the faster: the first pays for cold caches).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[(v.len() - 1) / 2]
    }
}

/// Aggregates the jobs of one quantity into rows, with their flags.
pub fn rows(exp: &Experiment, results: &[JobResult], q: Quantity, reference: f64) -> Vec<Row> {
    let mut groups: BTreeMap<(usize, usize), Vec<&JobResult>> = BTreeMap::new();
    for r in results {
        groups.entry((r.rule_index, r.budget)).or_default().push(r);
    }
    let scale = if reference != 0.0 {
        reference.abs()
    } else {
        1.0
    };
    let mut out: Vec<Row> = Vec::new();
    for ((rule_index, budget), jobs) in groups {
        let mut flags = Vec::new();
        let vals: Vec<(f64, f64, f64)> = jobs
            .iter()
            .filter_map(|j| {
                Some((
                    *j.values.get(&q)?,
                    *j.estimated_errors.get(&q)?,
                    *j.evaluations.get(&q)? as f64,
                ))
            })
            .collect();
        let rule_spec = &exp.spec.rules[rule_index.min(exp.spec.rules.len() - 1)];
        if let Some(f) = jobs.iter().find_map(|j| j.failure.clone()) {
            flags.push(format!("failed: {f}"));
        }
        if vals.is_empty() {
            // Every job of this row failed: keep the row, so the failure shows.
            out.push(Row {
                rule_index,
                rule: rule_spec.name().to_string(),
                budget,
                value: f64::NAN,
                rel_error: f64::NAN,
                rel_estimate: f64::NAN,
                evaluations: 0.0,
                seconds: median(jobs.iter().map(|j| j.seconds).collect()),
                flags,
            });
            continue;
        }
        if vals.iter().any(|v| !v.0.is_finite()) {
            flags.push("non-finite value".into());
        }
        // A sum much smaller than the magnitudes of its parts has lost digits
        // to cancellation.
        if jobs
            .iter()
            .any(|j| match (j.values.get(&q), j.magnitudes.get(&q)) {
                (Some(v), Some(m)) => *m > 0.0 && v.abs() < 1e-6 * m,
                _ => false,
            })
        {
            flags.push("cancellation: |sum| < 1e-6 of its parts".into());
        }
        if jobs.iter().any(|j| j.underflow) && q == Quantity::Tau {
            flags.push("tau underflows: log space".into());
        }
        let m = vals.len() as f64;
        let value = vals.iter().map(|v| v.0).sum::<f64>() / m;
        let rel_error =
            (vals.iter().map(|v| (v.0 - reference).powi(2)).sum::<f64>() / m).sqrt() / scale;
        let rel_estimate = vals.iter().map(|v| v.1).sum::<f64>() / m / scale;
        let evaluations = vals.iter().map(|v| v.2).sum::<f64>() / m;
        // The rule's own error estimate against the truth.
        if rule_spec.is_random() {
            if vals
                .iter()
                .any(|v| (v.0 - reference).abs() > 4.0 * v.1 && v.1.is_finite())
            {
                flags.push("outside 4 standard errors".into());
            }
        } else if rel_error > 100.0 * FLOOR
            && rel_estimate.is_finite()
            && (rel_estimate > 10.0 * rel_error || rel_estimate < rel_error / 10.0)
        {
            flags.push("estimate off by more than 10x".into());
        }
        out.push(Row {
            rule_index,
            rule: rule_spec.name().to_string(),
            budget,
            value,
            rel_error,
            rel_estimate,
            evaluations,
            seconds: median(jobs.iter().map(|j| j.seconds).collect()),
            flags,
        });
    }
    // Convergence that stalls or reverses, above the rounding floor.
    for i in 1..out.len() {
        if out[i].rule_index == out[i - 1].rule_index
            && out[i - 1].rel_error > 1e3 * FLOOR
            && out[i].rel_error > 1.5 * out[i - 1].rel_error
        {
            out[i].flags.push("error grew with the budget".into());
        }
    }
    out
}

/// The fitted order (error against evaluations) of one rule's rows.
pub fn order(rows: &[&Row]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.rel_error > 100.0 * FLOOR)
        .map(|r| (r.evaluations, r.rel_error))
        .collect();
    if pts.len() < 3 {
        return None;
    }
    fitted_order(&pts)
}

/// The least median time among rows whose error meets `target`.
pub fn time_to(rows: &[&Row], target: f64) -> Option<f64> {
    rows.iter()
        .filter(|r| r.rel_error <= target && r.flags.iter().all(|f| !f.starts_with("failed")))
        .map(|r| r.seconds)
        .min_by(f64::total_cmp)
}

fn rule_label(exp: &Experiment, i: usize) -> String {
    let name = exp.spec.rules[i].name();
    let same = exp.spec.rules.iter().filter(|r| r.name() == name).count();
    if same > 1 {
        format!("{name}#{i}")
    } else {
        name.to_string()
    }
}

/// Draws error against `x` (time or n), one log-log curve per rule.
fn plot(
    path: &Path,
    title: &str,
    x_label: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<(), String> {
    let pts: Vec<(f64, f64)> = series.iter().flat_map(|s| s.1.iter().copied()).collect();
    if pts.is_empty() {
        return Ok(());
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for (x, y) in &pts {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    // Whole decades, at least one wide on each axis: plotters' log axis
    // misbehaves on ranges that are very narrow or start off a decade.
    let decades = |lo: f64, hi: f64| {
        let a = lo.log10().floor().clamp(-300.0, 300.0);
        let b = hi.log10().ceil().clamp(-300.0, 300.0).max(a + 1.0);
        (10f64.powf(a), 10f64.powf(b))
    };
    let (x0, x1) = decades(x0, x1);
    let (y0, y1) = decades(y0, y1);
    let root = SVGBackend::new(path, (900, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    // The legend gets a panel of its own on the right, so it never hides a curve.
    let (left, right) = root.split_horizontally(700);
    let mut chart = ChartBuilder::on(&left)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc("relative error")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|e| e.to_string())?;
    for (i, (name, s)) in series.iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(s.iter().copied(), colour.stroke_width(2)))
            .map_err(|e| e.to_string())?;
        chart
            .draw_series(
                s.iter()
                    .map(|&(x, y)| Circle::new((x, y), 3, colour.filled())),
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
            .draw(&Text::new(name.clone(), (42, y - 8), ("sans-serif", 15)))
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

/// Per-experiment summary for the index: quantity -> rule -> time to target.
pub type Summary = BTreeMap<Quantity, Vec<(String, Option<f64>)>>;

/// Writes `report.md`, the SVG plots and `results.csv` of one experiment.
pub fn write_experiment(
    dir: &Path,
    exp: &Experiment,
    results: &[JobResult],
    reference: &BTreeMap<Quantity, f64>,
    reference_note: &str,
    reference_accuracy: f64,
    crosscheck: &str,
) -> Result<Summary, String> {
    let spec = &exp.spec;
    let mut md = String::new();
    let _ = writeln!(md, "# {}\n\n{}\n", spec.name, spec.description);
    let _ = writeln!(
        md,
        "Equations: {}. Budgets {:?} per smooth piece, {} repeat(s), seed {}, depth scheme {:?}.\n\n\
         Reference: {reference_note}\n",
        spec.equations.join(", "),
        exp.budgets,
        spec.repeats,
        spec.seed,
        spec.depth_scheme
    );
    if let Some(r) = results.first() {
        let _ = writeln!(
            md,
            "lightquad {} (commit {}), {}, experiment hash {}.\n",
            r.version,
            r.git_commit.as_deref().unwrap_or("unknown"),
            r.machine,
            r.experiment_hash
        );
    }
    let mut summary = Summary::new();
    for q in &spec.quantities {
        let Some(&reference) = reference.get(q) else {
            continue;
        };
        let mut rows = rows(exp, results, *q, reference);
        // Errors the reference cannot resolve.
        for r in rows.iter_mut() {
            if reference_accuracy > 0.0 && r.rel_error <= reference_accuracy {
                r.flags.push(format!(
                    "at the reference's accuracy ({reference_accuracy:.1e})"
                ));
            }
        }
        let _ = writeln!(md, "## {} (reference {reference:.16e})\n", q.name());
        let _ = writeln!(
            md,
            "| rule | n | value | true error (relative; absolute where the reference is 0) | estimated error (same) | evaluations | median time (s) | flags |\n\
             |---|---:|---:|---:|---:|---:|---:|---|"
        );
        for r in &rows {
            let _ = writeln!(
                md,
                "| {} | {} | {:.15e} | {:.2e} | {:.2e} | {:.0} | {:.2e} | {} |",
                rule_label(exp, r.rule_index),
                r.budget,
                r.value,
                r.rel_error,
                r.rel_estimate,
                r.evaluations,
                r.seconds,
                r.flags.join("; ")
            );
        }
        let _ = writeln!(
            md,
            "\n| rule | fitted slope of log error vs log evaluations (order p shows as -p) | {} |",
            spec.targets
                .iter()
                .map(|t| format!("time to {t:.0e} (s)"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        let _ = writeln!(md, "|---|---:|{}", "---:|".repeat(spec.targets.len()));
        let mut ranking = Vec::new();
        let mut by_time = Vec::new();
        let mut by_n = Vec::new();
        for i in 0..spec.rules.len() {
            let mine: Vec<&Row> = rows.iter().filter(|r| r.rule_index == i).collect();
            if mine.is_empty() {
                continue;
            }
            let label = rule_label(exp, i);
            let order = order(&mine).map_or("—".into(), |o| format!("{o:.2}"));
            let times: Vec<String> = spec
                .targets
                .iter()
                .map(|t| {
                    if *t < reference_accuracy {
                        "below reference accuracy".into()
                    } else {
                        time_to(&mine, *t).map_or("not reached".into(), |s| format!("{s:.2e}"))
                    }
                })
                .collect();
            let _ = writeln!(md, "| {label} | {order} | {} |", times.join(" | "));
            let middle = spec
                .targets
                .get(spec.targets.len() / 2)
                .copied()
                .unwrap_or(1e-6);
            ranking.push((
                label.clone(),
                if middle < reference_accuracy {
                    None
                } else {
                    time_to(&mine, middle)
                },
            ));
            // Errors at exactly 0 are drawn at 1e-17; NaN (failed) rows are dropped.
            let floor = |r: &&Row| {
                if r.rel_error.is_nan() {
                    f64::NAN
                } else {
                    r.rel_error.max(1e-17)
                }
            };
            by_time.push((
                label.clone(),
                mine.iter()
                    .map(|r| (r.seconds.max(1e-9), floor(r)))
                    .collect(),
            ));
            by_n.push((
                label,
                mine.iter()
                    .map(|r| (r.evaluations.max(1.0), floor(r)))
                    .collect(),
            ));
        }
        summary.insert(*q, ranking);
        let base = format!("{}-{}", spec.name, q.name());
        plot(
            &dir.join(format!("{base}-time.svg")),
            &format!("{}: {} error against time", spec.name, q.name()),
            "median run time (s)",
            &by_time,
        )?;
        plot(
            &dir.join(format!("{base}-n.svg")),
            &format!("{}: {} error against evaluations", spec.name, q.name()),
            "density evaluations",
            &by_n,
        )?;
        let _ = writeln!(
            md,
            "\n![error against time]({base}-time.svg)\n![error against evaluations]({base}-n.svg)\n"
        );
    }
    if !crosscheck.is_empty() {
        let _ = writeln!(
            md,
            "## lightquad vs Mitsuba 3 vs closed form\n\n{crosscheck}"
        );
    }
    let _ = writeln!(
        md,
        "Flags: `non-finite value`; `outside 4 standard errors` (a random estimate whose standard \
         error misses the true error); `estimate off by more than 10x` (a deterministic error \
         estimate, above the rounding floor); `error grew with the budget`; `cancellation` (V-I \
         is below 1e-6 of the summed magnitudes of its terms); `tau underflows: log space` (the \
         optical depth is exact, tau itself is below the smallest f64)."
    );
    write_atomic(&dir.join("report.md"), md.as_bytes()).map_err(|e| e.to_string())?;
    // CSV of every job.
    let mut csv = String::from(
        "experiment,rule_index,rule,budget,repeat,seed,quantity,value,estimated_error,evaluations,seconds,failure\n",
    );
    for r in results {
        if r.values.is_empty() {
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},,,,,{:e},{}",
                r.experiment,
                r.rule_index,
                r.rule,
                r.budget,
                r.repeat,
                r.seed,
                r.seconds,
                r.failure.as_deref().unwrap_or("no value").replace(',', ";")
            );
        }
        for (q, v) in &r.values {
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{},{},{:e},{:e},{},{:e},{}",
                r.experiment,
                r.rule_index,
                r.rule,
                r.budget,
                r.repeat,
                r.seed,
                q.name(),
                v,
                r.estimated_errors.get(q).copied().unwrap_or(f64::NAN),
                r.evaluations.get(q).copied().unwrap_or(0),
                r.seconds,
                r.failure.as_deref().unwrap_or("").replace(',', ";")
            );
        }
    }
    write_atomic(&dir.join("results.csv"), csv.as_bytes()).map_err(|e| e.to_string())?;
    Ok(summary)
}

/// Writes the index page: every experiment, and the rules ranked by time to
/// the middle target error per quantity.
pub fn write_index(
    out: &Path,
    entries: &[(String, String, Summary)],
    crosscheck: &str,
    no_crosscheck: bool,
) -> Result<(), String> {
    let mut md = String::from(
        "# lightquad report\n\nEvery experiment, and per quantity the rules ranked by the time they need to reach the middle target relative error (1e-6 unless the experiment says otherwise); `not reached` means no budget got there.\n\n",
    );
    for (name, description, summary) in entries {
        let _ = writeln!(md, "## [{name}]({name}/report.md)\n\n{description}\n");
        for (q, ranking) in summary {
            let mut ranked = ranking.clone();
            ranked.sort_by(|a, b| match (a.1, b.1) {
                (Some(x), Some(y)) => x.total_cmp(&y),
                (Some(_), None) => std::cmp::Ordering::Less,
                (None, Some(_)) => std::cmp::Ordering::Greater,
                (None, None) => a.0.cmp(&b.0),
            });
            let list: Vec<String> = ranked
                .iter()
                .map(|(r, t)| match t {
                    Some(t) => format!("{r} ({t:.1e} s)"),
                    None => format!("{r} (not reached)"),
                })
                .collect();
            let _ = writeln!(md, "- {}: {}", q.name(), list.join(", "));
        }
        md.push('\n');
    }
    if !no_crosscheck {
        let _ = writeln!(
            md,
            "## lightquad vs Mitsuba 3 vs closed form\n\nEvery case the Mitsuba harness (reference/) covers: \
             lightquad's converged value, Mitsuba's value with its standard error (float32 renderer: \
             expect ~1e-6 relative at best), the closed form where one exists. Mitsuba media have no \
             volumetric emission, so V-E (and V-I with emission) has no Mitsuba counterpart.\n\n{crosscheck}"
        );
    }
    write_atomic(&out.join("index.md"), md.as_bytes()).map_err(|e| e.to_string())
}

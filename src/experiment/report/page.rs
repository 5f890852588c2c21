//! The Markdown page of one experiment (`report.md`), with its plots,
//! images, `results.csv` and the HTML page beside it.

use std::fmt::Write as _;
use std::path::Path;

use super::Page;
use super::csv::csv;
use super::findings::findings;
use super::ranking::Summary;
use super::rows::{FLAG_LEGEND, Row, RowFlag};
use super::section::{
    cell, count_cell, display_line, extra_columns, label, not_run, off_cell, over_budget, sections,
    show_value, skipped,
};
use super::summary::{ExperimentSummary, ReportSummary, experiment_summary};
use crate::experiment::reference::crosscheck_markdown;
use crate::experiment::run::{JobResult, write_report_file};
use crate::experiment::timing::TimeInterval;
use crate::family::Display;

/// Writes `report.md`, the SVG plots, `results.csv`, `summary.json` and
/// `index.html` of one experiment; gives the index its ranking and summary.
pub fn write_experiment(
    dir: &Path,
    page: &Page,
    results: &[JobResult],
) -> Result<(Summary, ExperimentSummary), String> {
    let sections = sections(page, results)?;
    let mut md = header(page, results);
    if let Some(audit) = &page.scene_audit {
        let _ = writeln!(md, "{audit}");
    }
    let mut summary = Summary::new();
    for (i, s) in sections.iter().enumerate() {
        let q = s.quantity;
        let reference = match &s.reference {
            Ok(r) => r,
            Err(why) => {
                let _ = writeln!(
                    md,
                    "## {q} (no reference)\n\nNo reference, so no true errors, orders or times to target: \
                     {why}. The jobs' values and estimated errors are in results.csv.\n"
                );
                continue;
            }
        };
        let display = page.displays.get(i).copied().flatten();
        let _ = writeln!(md, "## {q} (reference {reference})\n");
        if let Some(f) = findings(page, s) {
            let _ = writeln!(md, "{}\n", crate::experiment::markdown::plain(&f));
        }
        let _ = writeln!(md, "{}", table(page, &s.rows, display.as_ref()));
        if let (Some(d), Some(values)) = (
            extra_columns(&s.rows, display.as_ref()).1,
            page.reference.values.get(q),
        ) {
            let _ = writeln!(md, "{}\n", display_line(d, q, values, &s.rows, page));
        }
        if let Some(line) = over_budget(page, &s.rows) {
            let _ = writeln!(md, "{line}");
        }
        let _ = writeln!(
            md,
            "\n| rule | {} | fitted slope vs log evaluations (the cost) | {} |\n|---|---:|---:|{}",
            s.slope_heading,
            page.targets
                .iter()
                .map(|t| format!("time to {t:e} (s)"))
                .collect::<Vec<_>>()
                .join(" | "),
            "---:|".repeat(page.targets.len())
        );
        for f in &s.fits {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} |",
                f.label,
                f.slope_budget,
                f.slope_evaluations,
                f.times.join(" | ")
            );
        }
        let _ = writeln!(
            md,
            "\nTime to a target: the least median time among the rows from the budget on which \
             the error stays at or below the target at every larger budget (an error that dips \
             below it at one budget and rises again does not count; a row whose value underflows \
             has no error and reaches nothing). {FIT_NOTE}"
        );
        md.push('\n');
        let verdicts = super::verdict::markdown(&s.verdicts);
        if !verdicts.is_empty() {
            let _ = writeln!(md, "{verdicts}");
        }
        for (what, file, text) in &s.plots {
            write_report_file(&dir.join(file), text.as_bytes())?;
            let _ = writeln!(md, "![error against {what}]({file})");
        }
        md.push('\n');
        if !s.pictures.is_empty() {
            md.push_str("### Images\n\n");
        }
        for p in &s.pictures {
            for (file, bytes) in &p.files {
                write_report_file(&dir.join(file), bytes)?;
            }
            let _ = write!(md, "![{}]({})", p.caption, p.png);
            if let Some(e) = &p.error_png {
                let _ = write!(md, " ![error map]({e})");
            }
            let _ = writeln!(md, " {} ([PFM]({}))\n", p.caption, p.pfm);
        }
        summary.push((q, s.ranking.clone()));
    }
    if !page.crosscheck.is_empty() {
        let _ = writeln!(
            md,
            "## lightquad vs Mitsuba 3 vs closed form\n\n{}",
            crosscheck_markdown(page.crosscheck)
        );
    }
    let _ = writeln!(md, "{FLAG_LEGEND}");
    write_report_file(&dir.join("report.md"), md.as_bytes())?;
    write_report_file(&dir.join("results.csv"), csv(page, results).as_bytes())?;
    let numbers = experiment_summary(page, &sections);
    write_summary(dir, std::slice::from_ref(&numbers))?;
    crate::experiment::html::write_experiment(dir, page, results, &sections)?;
    Ok((summary, numbers))
}

/// What the fitted-slope and time-to-target columns' extra figures mean.
pub const FIT_NOTE: &str = "A slope's ± is half its 95% confidence interval (Student's t on the \
fitted rows, from their scatter about the line: 3 rows leave 1 degree of freedom and a wide \
interval). Where a target is not reached and the slope against evaluations is an order known to within \
a quarter of itself (its 95% interval), the extrapolation is where that line reaches the target, its time scaled from the largest budget's \
in proportion to the evaluations: an estimate, not a measurement.";

/// A time's interval as a cell: `1.1e-6 to 1.3e-6 (96%)`; "—" where
/// no time was read (every job of the row failed).
pub fn interval_cell(t: Option<&TimeInterval>) -> String {
    match t {
        Some(t) if t.samples > 1 => format!(
            "{:.1e} to {:.1e} ({:.0}%)",
            t.low,
            t.high,
            100.0 * t.confidence
        ),
        Some(_) => "— (one reading)".into(),
        None => "—".into(),
    }
}

/// Writes `summary.json` into `dir`: the summary of `experiments`.
pub fn write_summary(dir: &Path, experiments: &[ExperimentSummary]) -> Result<(), String> {
    let summary = ReportSummary::of(experiments.to_vec());
    let text = serde_json::to_string_pretty(&summary)
        .map_err(|e| format!("summary.json could not be written: {e}"))?;
    write_report_file(
        &dir.join(crate::experiment::run::SUMMARY_FILE),
        text.as_bytes(),
    )
}

/// The page's title, settings, reference and provenance.
fn header(page: &Page, results: &[JobResult]) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# {}\n\n{}\n",
        page.name,
        crate::experiment::markdown::plain(page.description)
    );
    let settings = if page.settings.is_empty() {
        String::new()
    } else {
        format!(", {}", page.settings)
    };
    let equations = if page.equations.is_empty() {
        String::new()
    } else {
        format!(" Equations: {}.", page.equations.join(", "))
    };
    let shared = if page.quantities.len() > 1 {
        SHARED
    } else {
        ""
    };
    let targets: Vec<String> = page.targets.iter().map(|t| format!("{t:e}")).collect();
    let _ = writeln!(
        md,
        "Family `{}`.{equations} Budgets {:?} ({}), {} repeat(s), seed {}{settings}.{shared}\n\n\
         Target relative errors {}; the index ranks the rules by their time to {:e}, the middle \
         one.\n\nReference: {}\n",
        page.family,
        page.budgets,
        page.budget_unit,
        page.repeats,
        page.seed,
        targets.join(", "),
        page.middle_target(),
        page.reference.note
    );
    let skipped = skipped(page);
    if !skipped.is_empty() {
        let _ = writeln!(
            md,
            "Budgets below a rule's minimum are skipped for it: {}.\n",
            skipped.join("; ")
        );
    }
    for line in external_times(page, results) {
        let _ = writeln!(md, "External estimator {line}.\n");
    }
    let not_run = not_run(page);
    if !not_run.is_empty() {
        let _ = writeln!(md, "Not run, no rows: {}.\n", not_run.join("; "));
    }
    if let Some(short) = short_rows(page, results) {
        let _ = writeln!(md, "**Incomplete**: {short}\n");
    }
    if let Some(p) = provenance(results) {
        let _ = writeln!(md, "{p}\n");
    }
    md
}

/// Said where some (rule, budget) rows hold fewer jobs than the
/// experiment's repeats (a shard left out of a merge): their figures, and
/// any "K of N repeats", rest on the repeats present.
pub fn short_rows(page: &Page, results: &[JobResult]) -> Option<String> {
    let mut per_row: std::collections::BTreeMap<(usize, usize), usize> =
        std::collections::BTreeMap::new();
    for r in results {
        *per_row.entry((r.rule_index, r.budget)).or_default() += 1;
    }
    let short = per_row.values().filter(|&&k| k < page.repeats).count();
    (short > 0).then(|| {
        format!(
            "{short} of {} row(s) hold fewer than the {} repeat(s) (a shard \
             missing from a merge, or a run stopped); their figures rest on the repeats present.",
            per_row.len(),
            page.repeats
        )
    })
}

/// Said of an experiment of several quantities.
pub const SHARED: &str = " Each quantity is evaluated and timed on its own (a job evaluates only \
the terms that quantity needs), so its times are its own cost.";

/// The version, commit, machine and experiment hash of a run, in words;
/// every commit with its count of jobs where the results come from several
/// builds (a merge allowed to mix them, or a `--resume` after a rebuild).
pub fn provenance(results: &[JobResult]) -> Option<String> {
    let mut builds: std::collections::BTreeMap<&str, usize> = std::collections::BTreeMap::new();
    for r in results {
        *builds
            .entry(r.git_commit.as_deref().unwrap_or("unknown"))
            .or_default() += 1;
    }
    let commits = match builds.len() {
        1 => format!(
            "commit {}",
            builds.keys().next().copied().unwrap_or("unknown")
        ),
        _ => format!(
            "results of {} builds: {}",
            builds.len(),
            builds
                .iter()
                .map(|(c, n)| format!("commit {c} ({n} jobs)"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    results.first().map(|r| {
        format!(
            "lightquad {} ({commits}), {}, experiment hash {}.",
            r.version, r.machine, r.experiment_hash
        )
    })
}

/// Per external rule that reported its own times, a sentence on how much
/// of lightquad's time of a request the program's own time is (medians over
/// the requests of each one's ratio and difference, so that budgets of
/// different cost are not pooled into one time).
pub fn external_times(page: &Page, results: &[JobResult]) -> Vec<String> {
    let median = |mut xs: Vec<f64>| {
        xs.sort_by(f64::total_cmp);
        let n = xs.len();
        if n % 2 == 1 {
            xs[n / 2]
        } else {
            (xs[n / 2 - 1] + xs[n / 2]) / 2.0
        }
    };
    let mut out = Vec::new();
    for (i, rule) in page.rules.iter().enumerate() {
        let pairs: Vec<(f64, f64)> = results
            .iter()
            .filter(|r| r.rule_index == i && r.failure.is_none())
            .flat_map(|r| r.quantities.values())
            .filter_map(|m| Some((m.program_seconds?, m.seconds?)))
            .filter(|(_, timed)| *timed > 0.0)
            .collect();
        if pairs.is_empty() {
            continue;
        }
        let share = median(pairs.iter().map(|(own, timed)| own / timed).collect());
        let overhead = median(pairs.iter().map(|(own, timed)| timed - own).collect());
        out.push(format!(
            "{}: its own time for a request is {:.0}% of lightquad's time of it (median over {} \
             requests); the difference, sending, transfer and parsing, is {overhead:.2e} s a \
             request (median). The tables use lightquad's time",
            rule.label,
            100.0 * share,
            pairs.len()
        ));
    }
    out
}

/// The table of one quantity: a row per (rule, budget); with several
/// channels the largest channel error, and with a display the displayed
/// values off the reference's.
fn table(page: &Page, rows: &[Row], display: Option<&Display>) -> String {
    let (multi, display) = extra_columns(rows, display);
    let mut md = String::from(
        "| rule | n | value (mean over repeats) | true error (root mean square over repeats; relative, absolute where the reference is 0) |",
    );
    if multi {
        md.push_str(" largest channel error (same scale) |");
    }
    if let Some(d) = display {
        let _ = write!(
            md,
            " {} values off the reference's (mean over repeats) |",
            d.name
        );
    }
    md.push_str(
        " estimated error (mean over repeats, same scale; a standard error for random rules) | evaluations (mean) | median time (s) | its interval (s, confidence) | flags |\n|---|---:|---:|---:|",
    );
    md.push_str(&"---:|".repeat(usize::from(multi) + usize::from(display.is_some())));
    md.push_str("---:|---:|---:|---:|---|\n");
    for r in rows {
        // A job's failure text may carry a user's strings (a results line
        // edited by hand): escaped, so that it cannot break the table.
        let flags: Vec<String> = r
            .flags
            .iter()
            .map(|f| match f {
                RowFlag::Failed { why, failed, of } => format!(
                    "{}: {}",
                    super::rows::failed_in(*failed, *of),
                    crate::experiment::markdown::plain(why)
                ),
                f => f.to_string(),
            })
            .collect();
        let _ = write!(
            md,
            "| {} | {} | {} | {} |",
            label(page, r.rule_index),
            r.budget,
            show_value(&r.value),
            cell(r.rel_error),
        );
        if multi {
            let _ = write!(md, " {} |", cell(r.max_error));
        }
        if display.is_some() {
            let _ = write!(md, " {} |", off_cell(r.display_off));
        }
        let _ = writeln!(
            md,
            " {} | {} | {} | {} | {} |",
            cell(r.rel_estimate),
            count_cell(r.evaluations),
            cell(r.seconds),
            interval_cell(r.time.as_ref()),
            flags.join("; ")
        );
    }
    md
}

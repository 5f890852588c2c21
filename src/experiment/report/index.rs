//! The index pages of a run (`index.md`, `index.html`).

use std::fmt::Write as _;
use std::path::Path;

use super::ranking::{EXACT_FROM_START, Summary, TIED, ranked, ranks, shares_rank};
use crate::experiment::reference::{CROSSCHECK_INTRO, Crosscheck, crosscheck_markdown};
use crate::experiment::run::write_report_file;

/// Writes the index pages (`index.md`, `index.html`): every experiment, per quantity the rules ranked by
/// time to the middle target error, the Mitsuba comparison, and the
/// families' audits of printed formulas.
pub fn write_index(
    out: &Path,
    entries: &[(String, String, Summary)],
    crosscheck: &[Crosscheck],
    audits: &[String],
    problems: &[String],
    earlier: &[String],
) -> Result<(), String> {
    let mut md = String::from("# lightquad report\n\n");
    if !problems.is_empty() {
        let _ = writeln!(
            md,
            "**This report is incomplete**, and its rankings may be wrong:\n\n{}\n",
            problems
                .iter()
                .map(|p| format!("- {p}"))
                .collect::<Vec<_>>()
                .join("\n")
        );
    }
    md.push_str(
        "Every experiment, and per quantity the rules ranked by the time they need to reach the middle target relative error (the middle of the experiment's targets from the largest down, of two the smaller; each quantity says which); `not reached` means no budget got there and stayed there with every repeat finished (such a rule has no rank).\n\n",
    );
    for (name, description, summary) in entries {
        let _ = writeln!(
            md,
            "## [{name}]({name}/report.md)\n\n{}\n",
            crate::experiment::markdown::plain(description)
        );
        for (q, ranking) in summary {
            let ranking = ranked(ranking);
            let ranks = ranks(&ranking);
            let list: Vec<String> = ranking
                .iter()
                .enumerate()
                .map(|(i, r)| {
                    let mut exact = String::new();
                    if shares_rank(&ranks, i) {
                        exact.push_str(&format!(", {TIED}"));
                    }
                    if r.exact_from_start {
                        exact.push_str(&format!(", {EXACT_FROM_START}"));
                    }
                    match r.seconds {
                        Some(t) => format!("{} ({t:.1e} s{exact})", r.label),
                        None => format!("{} (not reached{exact})", r.label),
                    }
                })
                .collect();
            let at = ranking
                .first()
                .map_or(String::new(), |r| format!(" (to {:e})", r.target));
            let _ = writeln!(md, "- {q}{at}: {}", list.join(", "));
        }
        md.push('\n');
    }
    if !earlier.is_empty() {
        let links: Vec<String> = earlier
            .iter()
            .map(|name| format!("[{name}]({name}/report.md)"))
            .collect();
        let _ = writeln!(
            md,
            "{}: {}.\n",
            crate::experiment::html::EARLIER,
            links.join(", ")
        );
    }
    if !crosscheck.is_empty() {
        let _ = writeln!(
            md,
            "## lightquad vs Mitsuba 3 vs closed form\n\n{CROSSCHECK_INTRO}\n\n{}",
            crosscheck_markdown(crosscheck)
        );
    }
    for audit in audits {
        let _ = writeln!(md, "{audit}");
    }
    write_report_file(&out.join("index.md"), md.as_bytes())?;
    crate::experiment::html::write_index(out, entries, crosscheck, audits, problems, earlier)
}

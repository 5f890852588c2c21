//! One experiment's page, `<out>/<name>/index.html`: its facts, equations,
//! table of contents and cross-check; each quantity's section comes from
//! `section`.

use std::fmt::Write as _;
use std::path::Path;

use crate::experiment::markdown::{escape, inline, to_html};
use crate::experiment::reference::crosscheck_markdown;
use crate::experiment::report::{FLAG_LEGEND, Page, SHARED, Section, not_run, provenance, skipped};
use crate::experiment::run::{JobResult, write_report_file};

use super::document;
use super::section::section;

/// An equation of docs/EQUATIONS.md: its ID, statement (Markdown) and section.
struct Equation {
    id: String,
    statement: String,
    section: String,
}

/// The equations of docs/EQUATIONS.md, read when lightquad was built.
fn equations() -> Vec<Equation> {
    let text = include_str!("../../../docs/EQUATIONS.md");
    let mut out = Vec::new();
    let mut section = String::new();
    for line in text.lines() {
        if let Some(h) = line.strip_prefix("## ") {
            section = h.trim().to_string();
        } else if let Some(row) = line.strip_prefix("| ")
            && let Some((id, rest)) = row.split_once(" | ")
        {
            let statement = rest.trim().trim_end_matches('|').trim();
            if id != "ID" && !id.starts_with('-') {
                out.push(Equation {
                    id: id.trim().to_string(),
                    statement: statement.to_string(),
                    section: section.clone(),
                });
            }
        }
    }
    out
}

/// The anchor of an equation ID on a page.
fn eq_anchor(id: &str) -> String {
    let safe: String = id
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    format!("eq-{safe}")
}

/// The anchor of a quantity's section.
pub(super) fn q_anchor(q: &str) -> String {
    let safe: String = q
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    format!("q-{safe}")
}

/// Writes `<dir>/index.html`, the HTML page of one experiment.
pub fn write_experiment(
    dir: &Path,
    page: &Page,
    results: &[JobResult],
    sections: &[Section],
) -> Result<(), String> {
    let html = experiment_page(dir, page, results, sections);
    write_report_file(&dir.join("index.html"), html.as_bytes())
}

/// The HTML of one experiment's page; links only to files present in `dir`
/// (and the index above it).
fn experiment_page(dir: &Path, page: &Page, results: &[JobResult], sections: &[Section]) -> String {
    let mut b = String::new();
    let _ = writeln!(
        b,
        "<nav class=\"top\"><a href=\"../index.html\">&larr; all experiments</a></nav>\n<h1>{}</h1>\n<p class=\"lead\">{}</p>",
        escape(page.name),
        escape(page.description)
    );
    b.push_str(&facts(dir, page, results));
    b.push_str(&equation_table(page.equations));
    if sections.len() > 1 {
        b.push_str("<ul class=\"toc\">");
        for s in sections {
            let _ = write!(
                b,
                "<li><a href=\"#{}\">{}</a></li>",
                q_anchor(s.quantity),
                escape(s.quantity)
            );
        }
        if !page.crosscheck.is_empty() {
            b.push_str("<li><a href=\"#crosscheck\">lightquad vs Mitsuba 3</a></li>");
        }
        b.push_str("</ul>\n");
    }
    if let Some(audit) = &page.scene_audit {
        b.push_str(&to_html(audit, 0));
    }
    for s in sections {
        b.push_str(&section(page, s));
    }
    if !page.crosscheck.is_empty() {
        let _ = writeln!(
            b,
            "<h2 id=\"crosscheck\">lightquad vs Mitsuba 3 vs closed form</h2>\n{}",
            to_html(&crosscheck_markdown(page.crosscheck), 1)
        );
    }
    let _ = writeln!(b, "<h2>Flags</h2>\n{}", to_html(FLAG_LEGEND, 1));
    document(page.name, &b)
}

/// The experiment's settings, reference, provenance and files.
fn facts(dir: &Path, page: &Page, results: &[JobResult]) -> String {
    let mut rows: Vec<(&str, String)> =
        vec![("Family", format!("<code>{}</code>", escape(page.family)))];
    if !page.equations.is_empty() {
        let links: Vec<String> = page
            .equations
            .iter()
            .map(|e| format!("<a href=\"#{}\">{}</a>", eq_anchor(e), escape(e)))
            .collect();
        rows.push(("Equations", links.join(", ")));
    }
    let budgets: Vec<String> = page.budgets.iter().map(ToString::to_string).collect();
    rows.push((
        "Budgets",
        format!("{} ({})", budgets.join(", "), escape(page.budget_unit)),
    ));
    rows.push((
        "Repeats, seed",
        format!("{} repeat(s), seed {}", page.repeats, page.seed),
    ));
    if !page.settings.is_empty() {
        rows.push(("Settings", escape(&page.settings)));
    }
    let targets: Vec<String> = page.targets.iter().map(|t| format!("{t:e}")).collect();
    rows.push(("Target errors", targets.join(", ")));
    if page.quantities.len() > 1 {
        rows.push(("Timing", escape(SHARED.trim())));
    }
    rows.push(("Reference", inline(&page.reference.note)));
    let skipped = skipped(page);
    if !skipped.is_empty() {
        rows.push((
            "Skipped",
            format!(
                "Budgets below a rule's minimum are skipped for it: {}.",
                escape(&skipped.join("; "))
            ),
        ));
    }
    for line in crate::experiment::report::external_times(page, results) {
        rows.push(("External estimator", format!("{}.", escape(&line))));
    }
    let not_run = not_run(page);
    if !not_run.is_empty() {
        rows.push((
            "Not run",
            format!("No rows: {}.", escape(&not_run.join("; "))),
        ));
    }
    if let Some(short) = crate::experiment::report::short_rows(page, results) {
        rows.push(("Incomplete", escape(&short)));
    }
    if let Some(p) = provenance(results) {
        rows.push(("Run", escape(&p)));
    }
    let files: Vec<String> = [
        ("experiment.json", "the experiment file"),
        ("report.md", "this page as Markdown"),
        ("results.csv", "every job (CSV)"),
        ("results.jsonl", "every job (JSON lines)"),
    ]
    .iter()
    .filter(|(f, _)| dir.join(f).is_file())
    .map(|(f, what)| format!("<a href=\"{f}\"><code>{f}</code></a> ({what})"))
    .collect();
    if !files.is_empty() {
        rows.push(("Files", files.join(", ")));
    }
    let mut html = String::from("<dl class=\"facts\">");
    for (k, v) in rows {
        let _ = write!(html, "<dt>{k}</dt><dd>{v}</dd>");
    }
    html.push_str("</dl>\n");
    html
}

/// The page's equations with their statements from docs/EQUATIONS.md.
fn equation_table(ids: &[String]) -> String {
    if ids.is_empty() {
        return String::new();
    }
    let all = equations();
    let mut html = String::from(
        "<h2>Equations</h2>\n<p class=\"note\">As restated in <code>docs/EQUATIONS.md</code> of the lightquad sources.</p>\n\
         <div class=\"scroll\"><table><thead><tr><th>ID</th><th>equation</th><th>source</th></tr></thead><tbody>",
    );
    for id in ids {
        let (statement, section) = all.iter().find(|e| e.id == *id).map_or_else(
            || ("not in docs/EQUATIONS.md".to_string(), String::new()),
            |e| (inline(&e.statement), inline(&e.section)),
        );
        let _ = write!(
            html,
            "<tr id=\"{}\"><td><strong>{}</strong></td><td>{statement}</td><td>{section}</td></tr>",
            eq_anchor(id),
            escape(id)
        );
    }
    html.push_str("</tbody></table></div>\n");
    html
}

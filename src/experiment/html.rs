//! The report as self-contained HTML, beside the Markdown: per experiment
//! `<out>/<name>/index.html` and the top-level `<out>/index.html`. Styles,
//! plots (inline SVG) and the script that sorts tables are in the page;
//! nothing is loaded from elsewhere. Every string from a user's file is
//! escaped ([`escape`]).
//!
//! The facts are those of the Markdown ([`super::report`] computes them once,
//! as [`Section`]s); a rule has the same colour on every page
//! ([`plot::rule_css`]).
//!
//! ```
//! use lightquad::experiment::html::write_index;
//! use lightquad::experiment::plot::rule_css;
//! use lightquad::experiment::report::Ranked;
//!
//! // The top-level page of a report with one experiment whose description
//! // holds markup: it is shown as text, and the page loads nothing from elsewhere.
//! let out = std::env::temp_dir().join(format!("lightquad-doc-html-{}", std::process::id()));
//! std::fs::create_dir_all(&out)?;
//! let ranked = Ranked { label: "gauss-legendre".into(), seconds: Some(2e-6), exact_from_start: false };
//! let entries = [("exp".to_string(), "e^u <b>& friends</b>".to_string(), vec![("exp", vec![ranked])])];
//! write_index(&out, &entries, &[], &[], &[], &[])?;
//! let page = std::fs::read_to_string(out.join("index.html"))?;
//! assert!(page.contains("e^u &lt;b&gt;&amp; friends&lt;/b&gt;") && !page.contains("<b>&"));
//! assert!(page.contains(&rule_css("gauss-legendre"))); // the rule's colour
//! assert!(!page.contains("src=\"http") && !page.contains("href=\"http"));
//! std::fs::remove_dir_all(&out)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::fmt::Write as _;
use std::path::Path;

use super::markdown::{escape, inline, to_html};
use super::plot;
use super::reference::{CROSSCHECK_INTRO, Crosscheck, crosscheck_markdown};
use super::report::{
    EXACT_FROM_START, FLAG_LEGEND, Page, Row, RowFlag, SHARED, Section, Summary, TIED, cell, label,
    provenance, ranked, ranks, show_value, skipped,
};
use super::run::{JobResult, write_report_file};

/// The page's styles.
const CSS: &str = r#"
:root { --fg: #1d1f21; --muted: #5b6168; --line: #d5d9de; --head: #eef1f4; --warn: #fff1d6; --floor: #f2f4f7; }
* { box-sizing: border-box; }
body { font: 16px/1.5 system-ui, -apple-system, "Segoe UI", "DejaVu Sans", sans-serif; color: var(--fg);
  margin: 0 auto; padding: 1.5rem 2rem 4rem; max-width: 1320px; }
h1 { font-size: 1.9rem; margin: .3rem 0 .6rem; }
h2 { font-size: 1.45rem; margin-top: 2.4rem; border-bottom: 2px solid var(--line); padding-bottom: .2rem; }
h3 { font-size: 1.15rem; margin-top: 1.6rem; }
a { color: #0b5cad; }
nav.top { font-size: .95rem; color: var(--muted); }
p.lead { font-size: 1.08rem; max-width: 70rem; }
dl.facts { display: grid; grid-template-columns: max-content 1fr; gap: .25rem 1.2rem; margin: 1rem 0; }
dl.facts dt { font-weight: 600; color: var(--muted); }
dl.facts dd { margin: 0; }
code { font: .92em/1.3 ui-monospace, "DejaVu Sans Mono", monospace; background: #f3f4f6; padding: 0 .2em; border-radius: 3px; }
.scroll { overflow-x: auto; margin: .8rem 0 1.2rem; }
table { border-collapse: collapse; font-size: .9rem; }
th, td { border: 1px solid var(--line); padding: .28rem .55rem; vertical-align: top; }
th { background: var(--head); text-align: left; font-weight: 600; }
table.sortable th { cursor: pointer; user-select: none; white-space: nowrap; }
table.sortable th::after { content: " \2195"; color: #9aa1a9; font-size: .8em; }
table.sortable th.asc::after { content: " \25B2"; color: var(--fg); }
table.sortable th.desc::after { content: " \25BC"; color: var(--fg); }
td.num, th.num { text-align: right; font-variant-numeric: tabular-nums; }
td.num { white-space: nowrap; }
td.r, th.r { text-align: right; font-variant-numeric: tabular-nums; }
td.r { min-width: 7rem; }
details > summary { cursor: pointer; color: #0b5cad; margin: .3rem 0; }
tr.warn td { background: var(--warn); }
tr.floor td { color: var(--muted); }
.sw { display: inline-block; width: .9em; height: .9em; border-radius: 2px; margin-right: .4em; vertical-align: -.1em; }
td.rule { white-space: nowrap; }
td.flags { min-width: 16rem; }
.images { display: flex; flex-wrap: wrap; gap: 1rem; }
.images figure { margin: 0; max-width: 520px; }
img.px { image-rendering: pixelated; margin-right: .3rem; border: 1px solid var(--line); }
figure { margin: 1rem 0; }
figure svg { width: 100%; max-width: 1020px; height: auto; border: 1px solid var(--line); display: block; }
figcaption { color: var(--muted); font-size: .9rem; }
.plots { display: grid; grid-template-columns: 1fr; gap: .5rem; }
@media (min-width: 2100px) { .plots { grid-template-columns: 1fr 1fr; } }
.note { color: var(--muted); font-size: .9rem; max-width: 75rem; }
.problems { background: var(--warn); border: 1px solid #e0b050; padding: .6rem 1rem; border-radius: 4px; }
ul.toc { columns: 3 18rem; padding-left: 1.2rem; }
.chart svg { max-width: 100%; height: auto; }
"#;

/// Sorts a table by the clicked header: numerically where the column's cells
/// are numbers (a cell's `data-sort` first), cells with no number ("—",
/// "not reached") last either way; a second click reverses.
const JS: &str = r#"
(function () {
  function key(td) {
    var s = td.getAttribute('data-sort');
    if (s === null) s = td.textContent.trim();
    return s;
  }
  function num(s) {
    var m = /^[+-]?(\d+\.?\d*|\.\d+)(e[+-]?\d+)?/i.exec(s.replace(/\u2212/g, '-'));
    return m ? parseFloat(m[0]) : null;
  }
  document.querySelectorAll('table.sortable').forEach(function (table) {
    var heads = table.tHead ? table.tHead.rows[0].cells : [];
    Array.prototype.forEach.call(heads, function (th, col) {
      th.title = (th.title ? th.title + ' \u2014 ' : '') + 'click to sort';
      th.addEventListener('click', function () {
        var body = table.tBodies[0];
        var rows = Array.prototype.slice.call(body.rows);
        var keys = rows.map(function (r) { return r.cells[col] ? key(r.cells[col]) : ''; });
        var nums = keys.map(num);
        var numeric = nums.some(function (x) { return x !== null; }) &&
          keys.every(function (k, i) { return nums[i] !== null || !/\d/.test(k) || /^(not|below|rms)/.test(k); });
        var dir = th.classList.contains('asc') ? -1 : 1;
        Array.prototype.forEach.call(heads, function (h) { h.classList.remove('asc', 'desc'); });
        th.classList.add(dir === 1 ? 'asc' : 'desc');
        var order = rows.map(function (r, i) { return i; });
        order.sort(function (a, b) {
          if (numeric) {
            var x = nums[a], y = nums[b];
            if (x === null && y === null) return keys[a].localeCompare(keys[b]) || a - b;
            if (x === null) return 1;
            if (y === null) return -1;
            return dir * (x - y) || a - b;
          }
          var blankA = keys[a] === '' || keys[a] === '\u2014', blankB = keys[b] === '' || keys[b] === '\u2014';
          if (blankA !== blankB) return blankA ? 1 : -1;
          return dir * keys[a].localeCompare(keys[b], undefined, { numeric: true }) || a - b;
        });
        order.forEach(function (i) { body.appendChild(rows[i]); });
      });
    });
  });
})();
"#;

/// A whole page around `body`.
fn document(title: &str, body: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{CSS}</style>\n</head>\n<body>\n{body}\n<script>{JS}</script>\n</body>\n</html>\n",
        escape(title)
    )
}

/// A rule's name with its colour swatch.
fn rule_cell(label: &str) -> String {
    format!(
        "<td class=\"rule\" data-sort=\"{}\"><span class=\"sw\" style=\"background:{}\"></span>{}</td>",
        escape(label),
        plot::rule_css(label),
        escape(label)
    )
}

/// A numeric cell: `text` shown, `value` sorted by.
fn num_cell(text: &str, value: f64) -> String {
    if value.is_finite() {
        format!(
            "<td class=\"num\" data-sort=\"{value:e}\">{}</td>",
            escape(text)
        )
    } else {
        format!("<td class=\"num\">{}</td>", escape(text))
    }
}

/// A header cell with its long meaning as a tooltip.
fn th(short: &str, long: &str, numeric: bool) -> String {
    format!(
        "<th{} title=\"{}\">{}</th>",
        if numeric { " class=\"num\"" } else { "" },
        escape(long),
        escape(short)
    )
}

/// An equation of docs/EQUATIONS.md: its ID, statement (Markdown) and section.
struct Equation {
    id: String,
    statement: String,
    section: String,
}

/// The equations of docs/EQUATIONS.md, read when lightquad was built.
fn equations() -> Vec<Equation> {
    let text = include_str!("../../docs/EQUATIONS.md");
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
fn q_anchor(q: &str) -> String {
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
    let targets: Vec<String> = page.targets.iter().map(|t| format!("{t:.0e}")).collect();
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
                escape(&skipped.join(", "))
            ),
        ));
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

/// True for flags that say a row is not to be trusted as it stands.
fn alarming(f: &RowFlag) -> bool {
    matches!(
        f,
        RowFlag::Failed(_)
            | RowFlag::NonFinite
            | RowFlag::OutsideStandardErrors
            | RowFlag::EstimateOff
            | RowFlag::ErrorGrew
            | RowFlag::ErrorBeyondRange
    )
}

/// One quantity: plots, fitted slopes and times, and the table of rows.
fn section(page: &Page, s: &Section) -> String {
    let q = s.quantity;
    let mut b = String::new();
    let reference = match &s.reference {
        Ok(r) => r,
        Err(why) => {
            let _ = writeln!(
                b,
                "<h2 id=\"{}\">{} (no reference)</h2>\n<p class=\"problems\">No reference, so no true errors, orders or times to target: {}. \
                 The jobs' values and estimated errors are in <a href=\"results.csv\">results.csv</a>.</p>",
                q_anchor(q),
                escape(q),
                escape(why)
            );
            return b;
        }
    };
    let _ = writeln!(
        b,
        "<h2 id=\"{}\">{}</h2>\n<p>Reference value: <code>{}</code></p>",
        q_anchor(q),
        escape(q),
        escape(reference)
    );
    b.push_str("<div class=\"plots\">");
    for (what, file, svg) in &s.plots {
        let _ = write!(
            b,
            "<figure>{}<figcaption>Error against {what}, log-log; open circles on the dashed line: errors at or below the floor (exact, rounding, or the reference's accuracy). \
             Also as <a href=\"{file}\">{file}</a>.</figcaption></figure>",
            strip_xml_declaration(svg),
            file = escape(file)
        );
    }
    b.push_str("</div>\n");
    // The images of an image-valued quantity, drawn large with square pixels.
    if !s.pictures.is_empty() {
        b.push_str("<h3>Images</h3>\n<div class=\"images\">");
        for p in &s.pictures {
            let shown = (240 / p.width.max(1)).max(1) * p.width;
            let _ = write!(
                b,
                "<figure><img class=\"px\" src=\"{}\" width=\"{shown}\" alt=\"{}\">",
                escape(&p.png),
                escape(&p.caption)
            );
            if let Some(e) = &p.error_png {
                let _ = write!(
                    b,
                    "<img class=\"px\" src=\"{}\" width=\"{shown}\" alt=\"error map\">",
                    escape(e)
                );
            }
            let _ = write!(
                b,
                "<figcaption>{} (<a href=\"{}\">PFM</a>)</figcaption></figure>",
                escape(&p.caption),
                escape(&p.pfm)
            );
        }
        b.push_str("</div>\n");
    }
    // Fitted slopes and times to the targets.
    let _ = write!(
        b,
        "<h3>Fitted orders and time to target</h3>\n<div class=\"scroll\"><table class=\"sortable\"><thead><tr>{}{}{}",
        th("rule", "rule or estimator", false),
        th("slope vs n", &s.slope_heading, true),
        th(
            "slope vs evaluations",
            "fitted slope vs log evaluations (the cost)",
            true
        ),
    );
    for t in page.targets {
        b.push_str(&th(
            &format!("time to {t:.0e} (s)"),
            &format!(
                "least median time among the rows from the budget on which the error stays at \
                 most {t:.0e} at every larger budget (a row whose value underflows has no \
                 error and reaches nothing)"
            ),
            true,
        ));
    }
    b.push_str("</tr></thead><tbody>");
    for f in &s.fits {
        b.push_str("<tr>");
        b.push_str(&rule_cell(&f.label));
        for text in [&f.slope_budget, &f.slope_evaluations]
            .into_iter()
            .chain(&f.times)
        {
            let _ = write!(b, "<td class=\"num\">{}</td>", escape(text));
        }
        b.push_str("</tr>");
    }
    let _ = writeln!(
        b,
        "</tbody></table></div>\n<p class=\"note\">Slope vs n: {}. An order-p rule shows as -p.</p>",
        escape(&s.slope_heading)
    );
    // Every row.
    let display = page
        .quantities
        .iter()
        .position(|&q| q == s.quantity)
        .and_then(|i| page.displays.get(i).copied().flatten());
    let (multi, display) = super::report::extra_columns(&s.rows, display.as_ref());
    let mut extra = String::new();
    if multi {
        extra.push_str(&th(
            "largest channel error",
            "the largest error of any channel in any repeat, same scale (the worst pixel)",
            true,
        ));
    }
    if let Some(d) = display {
        extra.push_str(&th(
            &format!("{} values off", d.name),
            "displayed values that differ from the reference's, mean over repeats",
            true,
        ));
    }
    let _ = write!(
        b,
        "<h3>Every rule and budget</h3>\n<div class=\"scroll\"><table class=\"sortable\"><thead><tr>{}{}{}{}{extra}{}{}{}{}</tr></thead><tbody>",
        th("rule", "rule or estimator", false),
        th("n", "budget", true),
        th("value", "value, mean over repeats", true),
        th(
            "true error",
            "root mean square over repeats; relative, absolute where the reference is 0",
            true
        ),
        th(
            "estimated error",
            "mean over repeats, same scale; a standard error for random rules",
            true
        ),
        th("evaluations", "mean evaluations", true),
        th(
            "median time (s)",
            "lower median wall time over repeats",
            true
        ),
        th("flags", "see Flags below", false),
    );
    for r in &s.rows {
        b.push_str(&row(page, r, multi, display.is_some()));
    }
    let _ = writeln!(
        b,
        "</tbody></table></div>\n<p class=\"note\">True error: root mean square over repeats (and channels), relative to the reference (absolute where it is 0). \
         Estimated error: the rule's own, mean over repeats, same scale (a standard error for random rules). \
         Highlighted rows carry a flag that questions the row; greyed rows are at the reference's accuracy.</p>"
    );
    if let Some(line) = super::report::over_budget(page, &s.rows) {
        let _ = writeln!(b, "<p class=\"note\">{}</p>", escape(&line));
    }
    if let (Some(d), Some(values)) = (display, page.reference.values.get(s.quantity)) {
        let line = super::report::display_line(d, s.quantity, values, &s.rows, page);
        let _ = writeln!(b, "<p class=\"note\">{}</p>", escape(&line));
    }
    b
}

/// One table row of a quantity, with the largest channel error (`multi`)
/// and the displayed values off (`display`) where the table has them.
fn row(page: &Page, r: &Row, multi: bool, display: bool) -> String {
    let class = if r.flags.iter().any(alarming) {
        " class=\"warn\""
    } else if r
        .flags
        .iter()
        .any(|f| matches!(f, RowFlag::AtReferenceAccuracy(_)))
    {
        " class=\"floor\""
    } else {
        ""
    };
    let flags: Vec<String> = r.flags.iter().map(ToString::to_string).collect();
    let value = match r.value.as_slice() {
        [] => f64::NAN,
        [x] => *x,
        v => super::reference::rms(v.iter().copied()),
    };
    let mut extra = String::new();
    if multi {
        extra.push_str(&num_cell(&cell(r.max_error), r.max_error));
    }
    if display {
        let off = r.display_off.unwrap_or(f64::NAN);
        extra.push_str(&num_cell(&super::report::off_cell(r.display_off), off));
    }
    format!(
        "<tr{class}>{}{}{}{}{extra}{}{}{}<td class=\"flags\">{}</td></tr>",
        rule_cell(&label(page, r.rule_index)),
        num_cell(&r.budget.to_string(), r.budget as f64),
        num_cell(&show_value(&r.value), value),
        num_cell(&cell(r.rel_error), r.rel_error),
        num_cell(&cell(r.rel_estimate), r.rel_estimate),
        num_cell(&format!("{:.0}", r.evaluations), r.evaluations),
        num_cell(&format!("{:.2e}", r.seconds), r.seconds),
        escape(&flags.join("; "))
    )
}

/// Said of the experiment folders in the output folder that this run did
/// not write (a run of other files into the same folder listed only its
/// own, leaving the earlier pages unlinked).
pub const EARLIER: &str = "Also in this folder, from earlier runs and not part of this one (their pages are as those runs left them)";

/// SVG text without an XML declaration, to sit inside HTML.
fn strip_xml_declaration(svg: &str) -> &str {
    match svg.trim_start().strip_prefix("<?xml") {
        Some(rest) => rest.split_once("?>").map_or(svg, |(_, body)| body),
        None => svg,
    }
}

/// Writes `<out>/index.html`: every experiment linked, per quantity the rules
/// ranked by time to the middle target (a chart and a sortable table), the
/// Mitsuba comparison and the families' audits.
pub fn write_index(
    out: &Path,
    entries: &[(String, String, Summary)],
    crosscheck: &[Crosscheck],
    audits: &[String],
    problems: &[String],
    earlier: &[String],
) -> Result<(), String> {
    let mut b = String::from("<h1>lightquad report</h1>\n");
    if !problems.is_empty() {
        b.push_str(
            "<div class=\"problems\"><strong>This report is incomplete</strong>, and its rankings may be wrong:<ul>",
        );
        for p in problems {
            let _ = write!(b, "<li>{}</li>", escape(p));
        }
        b.push_str("</ul></div>\n");
    }
    b.push_str(
        "<p class=\"lead\">Every experiment, and per quantity the rules ranked by the time they need to reach the middle target relative error \
         (1e-6 unless the experiment says otherwise); <em>not reached</em> means no budget got there. \
         A rule has the same colour on every page.</p>\n",
    );
    // The overview table.
    b.push_str("<h2>Experiments</h2>\n<div class=\"scroll\"><table class=\"sortable\"><thead><tr><th>experiment</th><th>description</th><th>quantities</th><th>fastest to the middle target</th></tr></thead><tbody>");
    for (name, description, summary) in entries {
        let quantities: Vec<&str> = summary.iter().map(|(q, _)| *q).collect();
        let fastest: Vec<String> = summary
            .iter()
            .map(|(q, ranking)| {
                // The first, and any tied with it within timing noise.
                let ranking = ranked(ranking);
                let best: Vec<String> = ranking
                    .iter()
                    .zip(ranks(&ranking))
                    .filter(|(r, rank)| *rank == 1 && r.seconds.is_some())
                    .map(|(r, _)| {
                        format!(
                            "<span class=\"sw\" style=\"background:{}\"></span>{}",
                            plot::rule_css(&r.label),
                            escape(&r.label)
                        )
                    })
                    .collect();
                match best.len() {
                    0 => format!("{}: none reached", escape(q)),
                    1 => format!("{}: {}", escape(q), best[0]),
                    _ => format!(
                        "{}: {} (tied within timing noise)",
                        escape(q),
                        best.join(" = ")
                    ),
                }
            })
            .collect();
        let _ = write!(
            b,
            "<tr><td><a href=\"{}\">{}</a></td><td>{}</td><td>{}</td><td>{}</td></tr>",
            page_link(out, name),
            escape(name),
            escape(description),
            escape(&quantities.join(", ")),
            fastest.join("<br>")
        );
    }
    b.push_str("</tbody></table></div>\n");
    if !earlier.is_empty() {
        let links: Vec<String> = earlier
            .iter()
            .map(|name| format!("<a href=\"{}\">{}</a>", page_link(out, name), escape(name)))
            .collect();
        let _ = writeln!(b, "<p class=\"note\">{EARLIER}: {}.</p>", links.join(", "));
    }
    // The time scale shared by every chart, so bars compare across experiments.
    let times: Vec<f64> = entries
        .iter()
        .flat_map(|(_, _, s)| {
            s.iter()
                .flat_map(|(_, r)| r.iter().filter_map(|x| x.seconds))
        })
        .filter(|t| *t > 0.0)
        .collect();
    let lo = times.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = times.iter().copied().fold(0.0, f64::max);
    let scale = (lo.is_finite() && hi > 0.0).then(|| {
        (
            10f64.powf(lo.log10().floor()),
            10f64.powf(hi.log10().ceil().max(lo.log10().floor() + 1.0)),
        )
    });
    b.push_str("<h2>Rankings</h2>\n");
    for (name, description, summary) in entries {
        let _ = writeln!(
            b,
            "<h3 id=\"{}\"><a href=\"{}\">{}</a></h3>\n<p>{}</p>",
            escape(&format!("x-{name}")),
            page_link(out, name),
            escape(name),
            escape(description)
        );
        if summary.is_empty() {
            b.push_str("<p class=\"note\">No quantity has a reference: nothing to rank.</p>\n");
            continue;
        }
        if let Some(scale) = scale {
            let _ = write!(
                b,
                "<div class=\"chart\">{}</div>",
                ranking_chart(summary, scale)
            );
        }
        b.push_str("<details><summary>as a table</summary><div class=\"scroll\"><table class=\"sortable\"><thead><tr><th>quantity</th><th class=\"num\">rank</th><th>rule</th><th class=\"num\">time to target (s)</th><th>note</th></tr></thead><tbody>");
        for (q, ranking) in summary {
            let ranking = ranked(ranking);
            let ranks = ranks(&ranking);
            for (i, r) in ranking.iter().enumerate() {
                let time = r
                    .seconds
                    .map_or("not reached".to_string(), |t| format!("{t:.1e}"));
                let tied = i > 0 && ranks[i] == ranks[i - 1];
                let note: Vec<&str> = [(tied, TIED), (r.exact_from_start, EXACT_FROM_START)]
                    .into_iter()
                    .filter_map(|(on, text)| on.then_some(text))
                    .collect();
                let _ = write!(
                    b,
                    "<tr><td>{}</td><td class=\"num\">{}</td>{}{}<td>{}</td></tr>",
                    escape(q),
                    if tied {
                        format!("={}", ranks[i])
                    } else {
                        ranks[i].to_string()
                    },
                    rule_cell(&r.label),
                    num_cell(&time, r.seconds.unwrap_or(f64::NAN)),
                    note.join("; ")
                );
            }
        }
        b.push_str("</tbody></table></div></details>\n");
    }
    if !crosscheck.is_empty() {
        let _ = writeln!(
            b,
            "<h2>lightquad vs Mitsuba 3 vs closed form</h2>\n<p>{}</p>\n{}",
            escape(CROSSCHECK_INTRO),
            to_html(&crosscheck_markdown(crosscheck), 1)
        );
    }
    for audit in audits {
        b.push_str(&to_html(audit, 0));
    }
    let html = document("lightquad report", &b);
    write_report_file(&out.join("index.html"), html.as_bytes())
}

/// The link to an experiment's page: its HTML page where it was written,
/// else its Markdown.
fn page_link(out: &Path, name: &str) -> String {
    let file = if out.join(name).join("index.html").is_file() {
        "index.html"
    } else {
        "report.md"
    };
    format!("{}/{file}", escape(&percent(name)))
}

/// A path segment with the characters a URL cannot hold as they are encoded.
fn percent(s: &str) -> String {
    let mut out = String::new();
    for b in s.bytes() {
        if b.is_ascii_alphanumeric() || b"-_.~".contains(&b) {
            out.push(b as char);
        } else {
            let _ = write!(out, "%{b:02X}");
        }
    }
    out
}

/// Horizontal bars of the time to the middle target, one per (quantity,
/// rule), on a log scale from `scale.0` to `scale.1` seconds shared by the
/// whole index; a rule that did not reach the target has no bar.
fn ranking_chart(summary: &Summary, scale: (f64, f64)) -> String {
    let (lo, hi) = (scale.0.log10(), scale.1.log10());
    let (left, width, row_h, top) = (300.0, 560.0, 20.0, 28.0);
    let rows: Vec<(&str, crate::experiment::report::Ranked)> = summary
        .iter()
        .flat_map(|(q, r)| ranked(r).into_iter().map(move |x| (*q, x)))
        .collect();
    let height = top + row_h * rows.len() as f64 + 8.0;
    let total = left + width + 110.0;
    let x = |t: f64| left + width * ((t.log10() - lo) / (hi - lo)).clamp(0.0, 1.0);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{total}\" height=\"{height}\" viewBox=\"0 0 {total} {height}\" font-family=\"sans-serif\" font-size=\"13\">"
    );
    // Decade grid and labels.
    let mut d = lo;
    while d <= hi + 1e-9 {
        let px = left + width * (d - lo) / (hi - lo);
        let _ = write!(
            svg,
            "<line x1=\"{px}\" y1=\"{}\" x2=\"{px}\" y2=\"{}\" stroke=\"#d5d9de\"/><text x=\"{px}\" y=\"14\" text-anchor=\"middle\" fill=\"#5b6168\">1e{d:.0}</text>",
            top - 6.0,
            height - 4.0
        );
        d += 1.0;
    }
    let _ = write!(
        svg,
        "<text x=\"{}\" y=\"14\" text-anchor=\"end\" fill=\"#5b6168\">seconds to the middle target (log)</text>",
        left - 30.0
    );
    let mut last_q = "";
    for (i, (q, r)) in rows.iter().enumerate() {
        let y = top + row_h * i as f64;
        if *q != last_q && i > 0 {
            let _ = write!(
                svg,
                "<line x1=\"0\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"#9aa1a9\"/>",
                left + width
            );
        }
        let name = if *q == last_q {
            escape(&r.label)
        } else {
            format!("{}: {}", escape(q), escape(&r.label))
        };
        last_q = q;
        let _ = write!(
            svg,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{name}</text>",
            left - 8.0,
            y + 14.0
        );
        match r.seconds {
            Some(t) => {
                let w = (x(t.max(scale.0)) - left).max(2.0);
                let opacity = if r.exact_from_start { "0.45" } else { "1" };
                let _ = write!(
                    svg,
                    "<rect x=\"{left}\" y=\"{}\" width=\"{w}\" height=\"{}\" fill=\"{}\" fill-opacity=\"{opacity}\"><title>{} {}: {t:.2e} s</title></rect><text x=\"{}\" y=\"{}\" fill=\"#1d1f21\">{t:.1e} s{}</text>",
                    y + 3.0,
                    row_h - 6.0,
                    plot::rule_css(&r.label),
                    escape(q),
                    escape(&r.label),
                    left + w + 6.0,
                    y + 14.0,
                    if r.exact_from_start { " (exact)" } else { "" }
                );
            }
            None => {
                let _ = write!(
                    svg,
                    "<text x=\"{}\" y=\"{}\" fill=\"#5b6168\" font-style=\"italic\">not reached</text>",
                    left + 6.0,
                    y + 14.0
                );
            }
        }
    }
    svg.push_str("</svg>");
    svg
}

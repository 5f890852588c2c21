//! One quantity's section of an experiment's page: its plots, images,
//! fitted orders and times, and the table of its rows with their flags.

use std::fmt::Write as _;

use crate::experiment::markdown::escape;
use crate::experiment::report::{Page, Row, RowFlag, Section, cell, count_cell, label, show_value};
use crate::family::Flag;

use super::page::q_anchor;
use super::{num_cell, rule_cell};

/// True for flags that say a row is not to be trusted as it stands.
fn alarming(f: &RowFlag) -> bool {
    matches!(
        f,
        RowFlag::Failed { .. }
            | RowFlag::NonFinite
            | RowFlag::OutsideStandardErrors
            | RowFlag::EstimateOff
            | RowFlag::ErrorGrew
            | RowFlag::ErrorBeyondRange
            | RowFlag::Job(Flag::HeavyWalks { .. })
    )
}

/// One quantity: plots, fitted slopes and times, and the table of rows.
pub(super) fn section(page: &Page, s: &Section) -> String {
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
    if let Some(f) = crate::experiment::report::findings(page, s) {
        let _ = writeln!(b, "<p class=\"findings\">{}</p>", escape(&f));
    }
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
            &format!("time to {t:e} (s)"),
            &format!(
                "least median time among the rows from the budget on which the error stays at \
                 most {t:e} at every larger budget (a row whose value underflows has no \
                 error and reaches nothing)"
            ),
            true,
        ));
    }
    b.push_str("</tr></thead><tbody>");
    for f in &s.fits {
        b.push_str("<tr>");
        b.push_str(&rule_cell(&page.palette(), &f.label));
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
        "</tbody></table></div>\n<p class=\"note\">Slope vs n: {}. An order-p rule shows as -p. {}</p>",
        escape(&s.slope_heading),
        escape(crate::experiment::report::FIT_NOTE)
    );
    let verdicts = crate::experiment::report::verdict::markdown(&s.verdicts);
    if !verdicts.is_empty() {
        b.push_str(&crate::experiment::markdown::to_html(&verdicts, 0));
    }
    // Every row.
    let display = page
        .quantities
        .iter()
        .position(|&q| q == s.quantity)
        .and_then(|i| page.displays.get(i).copied().flatten());
    let (multi, display) = crate::experiment::report::extra_columns(&s.rows, display.as_ref());
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
        "<h3>Every rule and budget</h3>\n<div class=\"scroll\"><table class=\"sortable\"><thead><tr>{}{}{}{}{extra}{}{}{}{}{}</tr></thead><tbody>",
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
            "lower median wall time per call, over the per-call times of every repeat",
            true
        ),
        th(
            "time interval",
            "confidence interval of the median time (order statistics, distribution-free), with its confidence",
            false
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
    if let Some(line) = crate::experiment::report::over_budget(page, &s.rows) {
        let _ = writeln!(b, "<p class=\"note\">{}</p>", escape(&line));
    }
    if let (Some(d), Some(values)) = (display, page.reference.values.get(s.quantity)) {
        let line = crate::experiment::report::display_line(d, s.quantity, values, &s.rows, page);
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
        v => crate::experiment::reference::rms(v.iter().copied()),
    };
    let mut extra = String::new();
    if multi {
        extra.push_str(&num_cell(&cell(r.max_error), r.max_error));
    }
    if display {
        let off = r.display_off.unwrap_or(f64::NAN);
        extra.push_str(&num_cell(
            &crate::experiment::report::off_cell(r.display_off),
            off,
        ));
    }
    format!(
        "<tr{class}>{}{}{}{}{extra}{}{}{}<td>{}</td><td class=\"flags\">{}</td></tr>",
        rule_cell(&page.palette(), &label(page, r.rule_index)),
        num_cell(&r.budget.to_string(), r.budget as f64),
        num_cell(&show_value(&r.value), value),
        num_cell(&cell(r.rel_error), r.rel_error),
        num_cell(&cell(r.rel_estimate), r.rel_estimate),
        num_cell(&count_cell(r.evaluations), r.evaluations),
        num_cell(&cell(r.seconds), r.seconds),
        escape(&crate::experiment::report::interval_cell(r.time.as_ref())),
        escape(&flags.join("; "))
    )
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

/// SVG text without an XML declaration, to sit inside HTML.
fn strip_xml_declaration(svg: &str) -> &str {
    match svg.trim_start().strip_prefix("<?xml") {
        Some(rest) => rest.split_once("?>").map_or(svg, |(_, body)| body),
        None => svg,
    }
}

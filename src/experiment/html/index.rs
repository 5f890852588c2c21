//! The top-level page, `<out>/index.html`: every experiment's link, its
//! ranking chart, the cross-checks and what did not run.

use std::fmt::Write as _;
use std::path::Path;

use crate::experiment::markdown::{escape, to_html};
use crate::experiment::plot;
use crate::experiment::reference::{CROSSCHECK_INTRO, Crosscheck, crosscheck_markdown};
use crate::experiment::report::{EXACT_FROM_START, Summary, TIED, ranked, ranks, shares_rank};
use crate::experiment::run::write_report_file;

use super::{document, num_cell, rule_cell};

/// Said of the experiment folders in the output folder that this run did
/// not write (a run of other files into the same folder listed only its
/// own, leaving the earlier pages unlinked).
pub const EARLIER: &str = "Also in this folder, from earlier runs and not part of this one (their pages are as those runs left them)";

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
    // One palette for the page: no two of its rules alike.
    let palette = plot::Palette::new(entries.iter().flat_map(|(_, _, summary)| {
        summary
            .iter()
            .flat_map(|(_, ranking)| ranking.iter().map(|r| r.label.as_str()))
    }));
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
         (the middle of the experiment's targets from the largest down, of two the smaller; each chart and table says which); <em>not reached</em> means no budget got there and stayed there with every repeat finished (such a rule has no rank). \
         A rule lightquad ships has the same colour on every page; no two rules of one page share one.</p>\n",
    );
    // The overview table.
    b.push_str("<h2>Experiments</h2>\n<div class=\"scroll\"><table class=\"sortable\"><thead><tr><th>experiment</th><th>description</th><th>quantities</th><th>fastest to the middle target</th></tr></thead><tbody>");
    for (name, description, summary) in entries {
        let quantities: Vec<&str> = summary.iter().map(|(q, _)| *q).collect();
        let fastest: Vec<String> = summary
            .iter()
            .map(|(q, ranking)| {
                // The first, and any tied with it (overlapping time intervals).
                let ranking = ranked(ranking);
                let best: Vec<String> = ranking
                    .iter()
                    .zip(ranks(&ranking))
                    .filter(|(_, rank)| *rank == Some(1))
                    .map(|(r, _)| {
                        format!(
                            "<span class=\"sw\" style=\"background:{}\"></span>{}",
                            palette.css(&r.label),
                            escape(&r.label)
                        )
                    })
                    .collect();
                let q = match ranking.first() {
                    Some(r) => format!("{} (to {:e})", escape(q), r.target),
                    None => escape(q),
                };
                match best.len() {
                    0 => format!("{q}: none reached"),
                    1 => format!("{q}: {}", best[0]),
                    _ => format!(
                        "{q}: {} (tied: their time intervals overlap)",
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
                ranking_chart(summary, scale, &palette)
            );
        }
        b.push_str("<details><summary>as a table</summary><div class=\"scroll\"><table class=\"sortable\"><thead><tr><th>quantity</th><th class=\"num\">rank</th><th>rule</th><th class=\"num\">target</th><th class=\"num\">time to it (s)</th><th>note</th></tr></thead><tbody>");
        for (q, ranking) in summary {
            let ranking = ranked(ranking);
            let ranks = ranks(&ranking);
            for (i, r) in ranking.iter().enumerate() {
                let time = r
                    .seconds
                    .map_or("not reached".to_string(), |t| format!("{t:.1e}"));
                let tied = shares_rank(&ranks, i);
                let note: Vec<&str> = [(tied, TIED), (r.exact_from_start, EXACT_FROM_START)]
                    .into_iter()
                    .filter_map(|(on, text)| on.then_some(text))
                    .collect();
                let _ = write!(
                    b,
                    "<tr><td>{}</td><td class=\"num\">{}</td>{}{}{}<td>{}</td></tr>",
                    escape(q),
                    match ranks[i] {
                        None => "—".to_string(),
                        Some(rank) if tied => format!("={rank}"),
                        Some(rank) => rank.to_string(),
                    },
                    rule_cell(&palette, &r.label),
                    num_cell(&format!("{:e}", r.target), r.target),
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
fn ranking_chart(summary: &Summary, scale: (f64, f64), palette: &plot::Palette) -> String {
    let (lo, hi) = (scale.0.log10(), scale.1.log10());
    let (left, width, row_h, top) = (300.0, 560.0, 20.0, 28.0);
    let target = summary
        .iter()
        .find_map(|(_, r)| r.first())
        .map_or(String::new(), |r| format!("{:e}", r.target));
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
        "<text x=\"{}\" y=\"14\" text-anchor=\"end\" fill=\"#5b6168\">seconds to reach {} (log)</text>",
        left - 30.0,
        target
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
                    palette.css(&r.label),
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

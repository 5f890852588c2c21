//! The report as HTML, beside the Markdown: per experiment
//! `<out>/<name>/index.html` and the top-level `<out>/index.html`. Styles,
//! plots (inline SVG) and the script that sorts tables are in the page; the
//! pictures of image quantities (Whitted's `image`) are PNG files beside it
//! in the experiment's folder, as for the Markdown; nothing is loaded from
//! another host. Every string from a user's file is escaped ([`escape`]).
//!
//! The facts are those of the Markdown ([`super::report`] computes them once,
//! as [`Section`]s); a rule has the same colour on every page
//! ([`plot::rule_css`]).
//!
//! `page` writes one experiment's page, `section` a quantity's table and
//! plot on it, and `index` the top-level page; the styles, the script and
//! the cells they share are here.
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
//! let ranked = Ranked { label: "gauss-legendre".into(), target: 1e-6, seconds: Some(2e-6), time: None, exact_from_start: false };
//! let entries = [("exp".to_string(), "e^u <b>& friends</b>".to_string(), vec![("exp", vec![ranked])])];
//! write_index(&out, &entries, &[], &[], &[], &[])?;
//! let page = std::fs::read_to_string(out.join("index.html"))?;
//! assert!(page.contains("e^u &lt;b&gt;&amp; friends&lt;/b&gt;") && !page.contains("<b>&"));
//! assert!(page.contains(&rule_css("gauss-legendre"))); // the rule's colour
//! assert!(!page.contains("src=\"http") && !page.contains("href=\"http"));
//! std::fs::remove_dir_all(&out)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`Section`]: super::report::Section

use super::markdown::escape;
use super::plot;

mod index;
mod page;
mod section;

pub use index::{EARLIER, write_index};
pub use page::write_experiment;

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
p.findings { max-width: 75rem; border-left: 3px solid var(--muted); padding-left: .8rem; }
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

/// A page of Markdown `md` as HTML, in the report's style.
pub fn markdown_page(title: &str, md: &str) -> String {
    document(title, &super::markdown::to_html(md, 0))
}

/// A rule's name with its colour swatch on the page of `palette`.
fn rule_cell(palette: &plot::Palette, label: &str) -> String {
    format!(
        "<td class=\"rule\" data-sort=\"{}\"><span class=\"sw\" style=\"background:{}\"></span>{}</td>",
        escape(label),
        palette.css(label),
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

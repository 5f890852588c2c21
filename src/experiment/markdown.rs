//! HTML escaping and a small Markdown-to-HTML converter for the Markdown
//! lightquad writes itself (the families' audits, the Mitsuba comparison,
//! the flag legend): headings, paragraphs, `-` lists, pipe tables, code
//! spans and bold. Every character of the input is escaped, so text from a
//! user's file cannot inject markup.
//!
//! ```
//! use lightquad::experiment::markdown::{escape, inline, to_html};
//!
//! // Text from a user's file is escaped, markup from lightquad's Markdown is not.
//! assert_eq!(escape("a < b & 'c'"), "a &lt; b &amp; &#39;c&#39;");
//! assert_eq!(inline("**V-tau** at `n < 8`"), "<strong>V-tau</strong> at <code>n &lt; 8</code>");
//! let md = "# Audit\n\n| point | value |\n|---|---|\n| <script> | 0.5 |\n";
//! let html = to_html(md, 1); // `#` becomes <h2>, below the page's <h1>
//! assert!(html.contains("<h2") && html.contains("<table"));
//! assert!(html.contains("&lt;script&gt;") && !html.contains("<script>"));
//! ```

/// `s` with `&`, `<`, `>`, `"` and `'` escaped, for HTML text and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Text from a user's file (an experiment's description) as Markdown that
/// renders as that text: every character Markdown gives a meaning to
/// (emphasis, code, links, raw HTML, headings, tables, lists) is
/// backslash-escaped, and paragraphs (blank lines) are kept.
pub fn plain(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for (i, line) in s.lines().enumerate() {
        if i > 0 {
            out.push('\n');
        }
        let line = line.trim_start();
        // A list marker opens a line: `-`, `+`, or digits then `.` or `)`.
        let digits = line.len() - line.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        let marker = if digits > 0 {
            matches!(line[digits..].chars().next(), Some('.' | ')')).then_some(digits)
        } else {
            matches!(line.chars().next(), Some('-' | '+')).then_some(0)
        };
        for (j, c) in line.char_indices() {
            if Some(j) == marker
                || matches!(
                    c,
                    '\\' | '`' | '*' | '_' | '[' | ']' | '<' | '>' | '#' | '|' | '~'
                )
            {
                out.push('\\');
            }
            out.push(c);
        }
    }
    out
}

/// One line of Markdown text as HTML: code spans, bold and backslash
/// escapes (a backslash before ASCII punctuation stands for that
/// character, as [`plain`] writes it), the rest escaped.
pub fn inline(s: &str) -> String {
    let mut out = String::new();
    let mut bold = false;
    let mut rest = s;
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix('\\')
            && let Some(c) = after.chars().next().filter(char::is_ascii_punctuation)
        {
            out.push_str(&escape(&after[..1]));
            rest = &after[c.len_utf8()..];
            continue;
        }
        if let Some(after) = rest.strip_prefix('`')
            && let Some(end) = after.find('`')
        {
            out.push_str("<code>");
            out.push_str(&escape(&after[..end]));
            out.push_str("</code>");
            rest = &after[end + 1..];
            continue;
        }
        if let Some(after) = rest.strip_prefix("**")
            && (bold || after.contains("**"))
        {
            out.push_str(if bold { "</strong>" } else { "<strong>" });
            bold = !bold;
            rest = after;
            continue;
        }
        let c = rest.chars().next().unwrap_or(' ');
        out.push_str(&escape(&rest[..c.len_utf8()]));
        rest = &rest[c.len_utf8()..];
    }
    if bold {
        out.push_str("</strong>");
    }
    out
}

/// The cells of a pipe-table line (`\|` is a literal bar).
fn cells(line: &str) -> Vec<String> {
    let line = line.trim();
    let line = line.strip_prefix('|').unwrap_or(line);
    let line = line.strip_suffix('|').unwrap_or(line);
    let mut out = vec![String::new()];
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek() == Some(&'|') => {
                chars.next();
                if let Some(last) = out.last_mut() {
                    last.push('|');
                }
            }
            '|' => out.push(String::new()),
            c => {
                if let Some(last) = out.last_mut() {
                    last.push(c);
                }
            }
        }
    }
    out.into_iter().map(|c| c.trim().to_string()).collect()
}

/// A pipe table (header, alignment line, rows) as a sortable HTML table.
fn table(lines: &[&str]) -> String {
    let head = cells(lines[0]);
    let right: Vec<bool> = lines
        .get(1)
        .map(|l| cells(l).iter().map(|c| c.ends_with(':')).collect())
        .unwrap_or_default();
    let align = |i: usize| {
        if right.get(i).copied().unwrap_or(false) {
            " class=\"r\""
        } else {
            ""
        }
    };
    let mut html = String::from("<div class=\"scroll\"><table class=\"sortable\"><thead><tr>");
    for (i, h) in head.iter().enumerate() {
        html.push_str(&format!("<th{}>{}</th>", align(i), inline(h)));
    }
    html.push_str("</tr></thead><tbody>");
    for line in lines.iter().skip(2) {
        html.push_str("<tr>");
        for (i, c) in cells(line).iter().enumerate() {
            html.push_str(&format!("<td{}>{}</td>", align(i), inline(c)));
        }
        html.push_str("</tr>");
    }
    html.push_str("</tbody></table></div>\n");
    html
}

/// Markdown as HTML; headings are shifted down by `shift` levels (so a
/// section's `#` sits below the page's title).
pub fn to_html(md: &str, shift: usize) -> String {
    let lines: Vec<&str> = md.lines().collect();
    let mut html = String::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim_end();
        if line.trim().is_empty() {
            i += 1;
        } else if line.starts_with('#') {
            let level = line.chars().take_while(|&c| c == '#').count();
            let h = (level + shift).min(6);
            let text = line[level..].trim();
            html.push_str(&format!("<h{h}>{}</h{h}>\n", inline(text)));
            i += 1;
        } else if line.trim_start().starts_with('|') {
            let start = i;
            while i < lines.len() && lines[i].trim_start().starts_with('|') {
                i += 1;
            }
            html.push_str(&table(&lines[start..i]));
        } else if line.starts_with("- ") {
            html.push_str("<ul>");
            while i < lines.len() && lines[i].starts_with("- ") {
                html.push_str(&format!("<li>{}</li>", inline(&lines[i][2..])));
                i += 1;
            }
            html.push_str("</ul>\n");
        } else {
            let mut para = Vec::new();
            while i < lines.len() {
                let l = lines[i].trim_end();
                if l.trim().is_empty()
                    || l.starts_with('#')
                    || l.trim_start().starts_with('|')
                    || l.starts_with("- ")
                {
                    break;
                }
                para.push(l.trim());
                i += 1;
            }
            html.push_str(&format!("<p>{}</p>\n", inline(&para.join(" "))));
        }
    }
    html
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markup_in_the_text_is_escaped() {
        let html = to_html("# a <b>\n\n<script>alert(1)</script> `x<y` **bold**\n", 1);
        assert!(html.contains("<h2>a &lt;b&gt;</h2>"), "{html}");
        assert!(html.contains("&lt;script&gt;"), "{html}");
        assert!(html.contains("<code>x&lt;y</code>"), "{html}");
        assert!(html.contains("<strong>bold</strong>"), "{html}");
        assert!(!html.contains("<script>"), "{html}");
    }

    /// What `plain` escapes reads as the text again in HTML.
    #[test]
    fn escaped_text_renders_as_itself() {
        let text = "E_cone *x* [a](b) <i> \\int # | ~";
        let html = to_html(&plain(text), 0);
        assert_eq!(html, format!("<p>{}</p>\n", escape(text)));
    }

    #[test]
    fn plain_text_keeps_its_characters() {
        let md = plain(
            "A *star* | <b>x</b> `c`\n\n# not a heading\n- not a list, 1.5 V-E\n12. nor this",
        );
        assert_eq!(
            md,
            "A \\*star\\* \\| \\<b\\>x\\</b\\> \\`c\\`\n\n\\# not a heading\n\\- not a list, 1.5 V-E\n12\\. nor this"
        );
    }

    #[test]
    fn tables_get_headers_and_alignment() {
        let html = to_html("| a | b |\n|---|---:|\n| x \\| y | 1e-3 |\n", 0);
        assert!(html.contains("<th>a</th><th class=\"r\">b</th>"), "{html}");
        assert!(
            html.contains("<td>x | y</td><td class=\"r\">1e-3</td>"),
            "{html}"
        );
    }
}

//! The HTML report: a run writes `index.html` beside every Markdown page;
//! every page is well nested, self-contained (no external resource), has no
//! broken relative link, image or in-page anchor, inlines a plot wherever the
//! Markdown has one, gives every table a header row, keeps a rule's colour
//! across pages, and shows text from the experiment file as text.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

use lightquad::experiment::plot::rule_css;
use lightquad::experiment::run::RunOptions;
use lightquad::experiment::run_files;

const HOSTILE: &str = r#"{
  "name": "html-hostile",
  "family": "volume",
  "description": "A <script>alert('x')</script> description & <b>markup</b> \"quoted\"",
  "equations": ["V-tau"],
  "scene": {
    "ray": { "origin": [-3.0, 0.4, 0.1], "direction": [1.0, 0.02, 0.0] },
    "medium": { "type": "constant-sphere", "centre": [0.1, -0.05, 0.0], "radius": 1.2, "kappa": 0.8 }
  },
  "quantities": ["tau"],
  "rules": [ {"rule": "trapezoid"}, {"rule": "gauss-legendre"}, {"rule": "monte-carlo"} ],
  "budgets": [4, 16, 64, 256],
  "repeats": 2,
  "seed": 1,
  "reference": {"type": "closed-form"}
}"#;

/// A fresh scratch folder.
fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lightquad-html-{}-{tag}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// A tag of a page: its name (lowercase, `/name` for a closing tag), its
/// attributes, and whether it closes itself.
#[derive(Debug)]
struct Tag {
    name: String,
    attrs: Vec<(String, String)>,
    self_closing: bool,
}

/// The tags of `html`, skipping comments and the bodies of `script` and
/// `style`; panics on a tag that does not end.
fn tags(html: &str) -> Vec<Tag> {
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(at) = rest.find('<') {
        rest = &rest[at + 1..];
        if let Some(after) = rest.strip_prefix("!--") {
            let end = after.find("-->").expect("unterminated comment");
            rest = &after[end + 3..];
            continue;
        }
        if rest.starts_with('!') {
            rest = &rest[rest.find('>').expect("unterminated doctype") + 1..];
            continue;
        }
        // The end of the tag: the first '>' outside a quoted attribute.
        let mut quote = None;
        let mut end = None;
        for (i, c) in rest.char_indices() {
            match (quote, c) {
                (None, '"' | '\'') => quote = Some(c),
                (Some(q), c) if c == q => quote = None,
                (None, '>') => {
                    end = Some(i);
                    break;
                }
                _ => {}
            }
        }
        let end =
            end.unwrap_or_else(|| panic!("unterminated tag at {:?}", &rest[..rest.len().min(80)]));
        let body = &rest[..end];
        rest = &rest[end + 1..];
        let self_closing = body.ends_with('/');
        let body = body.trim_end_matches('/');
        let name_end = body.find(|c: char| c.is_whitespace()).unwrap_or(body.len());
        let name = body[..name_end].to_ascii_lowercase();
        let attrs = attributes(&body[name_end..]);
        if name == "script" || name == "style" {
            let close = format!("</{name}>");
            let stop = rest.find(&close).expect("unclosed script or style");
            rest = &rest[stop..];
        }
        out.push(Tag {
            name,
            attrs,
            self_closing,
        });
    }
    out
}

/// `name="value"` pairs (values unescaped for `&amp;` only, enough for paths).
fn attributes(s: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut rest = s.trim();
    while !rest.is_empty() {
        let name_end = rest
            .find(|c: char| c == '=' || c.is_whitespace())
            .unwrap_or(rest.len());
        let name = rest[..name_end].to_ascii_lowercase();
        rest = rest[name_end..].trim_start();
        let mut value = String::new();
        if let Some(after) = rest.strip_prefix('=') {
            let after = after.trim_start();
            let q = after.chars().next().expect("attribute value");
            assert!(q == '"' || q == '\'', "unquoted attribute {name} in {s}");
            let close = after[1..].find(q).expect("unterminated attribute value");
            value = after[1..1 + close].replace("&amp;", "&");
            rest = after[close + 2..].trim_start();
        }
        out.push((name, value));
    }
    out
}

const VOID: [&str; 6] = ["meta", "br", "img", "link", "hr", "input"];

/// Checks that the non-void elements nest properly.
fn well_nested(page: &Path, tags: &[Tag]) {
    let mut stack: Vec<&str> = Vec::new();
    for t in tags {
        if let Some(closed) = t.name.strip_prefix('/') {
            let open = stack
                .pop()
                .unwrap_or_else(|| panic!("{}: </{closed}> with nothing open", page.display()));
            assert_eq!(
                open,
                closed,
                "{}: <{open}> closed by </{closed}>",
                page.display()
            );
        } else if !t.self_closing && !VOID.contains(&t.name.as_str()) {
            stack.push(&t.name);
        }
    }
    assert!(stack.is_empty(), "{}: left open: {stack:?}", page.display());
}

/// Every `.html` file below `dir`.
fn pages(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in fs::read_dir(dir).expect("read dir").flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(pages(&p));
        } else if p.extension().is_some_and(|x| x == "html") {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// `%XX` sequences decoded.
fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).expect("utf-8");
            out.push(u8::from_str_radix(hex, 16).expect("percent escape"));
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).expect("utf-8 path")
}

#[test]
fn the_html_report_is_self_contained_linked_plotted_and_escaped() {
    let dir = scratch("run");
    let hostile = dir.join("hostile.json");
    fs::write(&hostile, HOSTILE).expect("write");
    let audit =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/v-audit-printed-formulas.json");
    let out = dir.join("out");
    let opts = RunOptions {
        out: out.clone(),
        resume: false,
        shard: None,
        progress: false,
    };
    let registry = lightquad::families::builtin();
    run_files(&registry, &[hostile, audit], &opts).unwrap_or_else(|e| panic!("{e}"));

    let all = pages(&out);
    let expected = [
        out.join("index.html"),
        out.join("html-hostile/index.html"),
        out.join("v-audit-printed-formulas/index.html"),
    ];
    for p in &expected {
        assert!(
            all.contains(p),
            "{} not written (pages: {all:?})",
            p.display()
        );
    }
    for page in &all {
        let html = fs::read_to_string(page).expect("read page");
        let tags = tags(&html);
        well_nested(page, &tags);
        let ids: BTreeSet<&str> = tags
            .iter()
            .flat_map(|t| {
                t.attrs
                    .iter()
                    .filter(|(k, _)| k == "id")
                    .map(|(_, v)| v.as_str())
            })
            .collect();
        let base = page.parent().expect("page folder");
        for t in &tags {
            assert!(
                t.name != "link" && t.name != "iframe",
                "{}: <{}> loads a resource",
                page.display(),
                t.name
            );
            for (k, v) in &t.attrs {
                if k != "href" && k != "src" {
                    continue;
                }
                assert!(
                    !v.contains("://") && !v.starts_with("//"),
                    "{}: external resource {k}={v}",
                    page.display()
                );
                if let Some(anchor) = v.strip_prefix('#') {
                    assert!(
                        ids.contains(anchor),
                        "{}: broken anchor {v}",
                        page.display()
                    );
                    continue;
                }
                let path = v.split(['#', '?']).next().unwrap_or_default();
                let target = base.join(percent_decode(path));
                assert!(target.is_file(), "{}: broken link {k}={v}", page.display());
            }
            if t.name == "script" {
                assert!(
                    t.attrs.iter().all(|(k, _)| k != "src"),
                    "{}: a script from elsewhere",
                    page.display()
                );
            }
        }
        // One script: the table sorter; the description's is text.
        assert_eq!(
            tags.iter().filter(|t| t.name == "script").count(),
            1,
            "{}: scripts",
            page.display()
        );
        // Every table has a header row of <th>.
        let mut in_table = 0usize;
        let (mut tables, mut with_head) = (0, 0);
        let mut seen_th = false;
        for t in &tags {
            match t.name.as_str() {
                "table" => {
                    in_table += 1;
                    tables += 1;
                    seen_th = false;
                }
                "th" if in_table > 0 && !seen_th => {
                    seen_th = true;
                    with_head += 1;
                }
                "/table" => in_table -= 1,
                _ => {}
            }
        }
        assert!(tables > 0, "{}: no table", page.display());
        assert_eq!(
            tables,
            with_head,
            "{}: a table without a header",
            page.display()
        );
        // A plot inline wherever the Markdown has one.
        let md = fs::read_to_string(page.with_file_name(if page == &out.join("index.html") {
            "index.md"
        } else {
            "report.md"
        }))
        .expect("markdown beside the page");
        let images = md.matches("![").count();
        let svgs = tags.iter().filter(|t| t.name == "svg").count();
        assert!(
            svgs >= images,
            "{}: {svgs} inline plots, the Markdown has {images}",
            page.display()
        );
        assert!(
            !tags.iter().any(|t| t.name == "img"),
            "{}: an image file instead of an inline plot",
            page.display()
        );
    }

    // Escaping: the description is text on the index and on its page.
    for page in [&expected[0], &expected[1]] {
        let html = fs::read_to_string(page).expect("read");
        assert!(
            !html.contains("<script>alert"),
            "{}: unescaped description",
            page.display()
        );
        assert!(
            !html.contains("<b>markup"),
            "{}: unescaped description",
            page.display()
        );
        assert!(
            html.contains("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt;"),
            "{}: the description is not shown as text",
            page.display()
        );
    }

    // The experiment pages: plots, equations, the experiment file, the audit.
    let hostile_page = fs::read_to_string(&expected[1]).expect("read");
    assert!(hostile_page.contains("href=\"experiment.json\""));
    assert!(
        hostile_page.contains("id=\"eq-V-tau\""),
        "the equation's statement"
    );
    assert!(
        hostile_page.contains("transmittance"),
        "the equation's statement"
    );
    assert!(
        hostile_page.matches("<svg").count() >= 2,
        "time and evaluations"
    );
    assert!(hostile_page.contains("class=\"sortable\""));
    let audit_page = fs::read_to_string(&expected[2]).expect("read");
    assert!(
        audit_page.contains("printed formulas in this scene"),
        "the scene audit"
    );
    assert!(
        audit_page.matches("<svg").count() >= 4,
        "two plots per quantity"
    );

    // One colour per rule on every page: gauss-legendre's swatch and curve.
    let colour = rule_css("gauss-legendre");
    for page in &expected {
        let html = fs::read_to_string(page).expect("read").to_ascii_lowercase();
        assert!(
            html.contains(&colour),
            "{}: gauss-legendre is not {colour}",
            page.display()
        );
    }
    assert_ne!(rule_css("trapezoid"), rule_css("gauss-legendre"));
    let _ = fs::remove_dir_all(&dir);
}

/// The label and colour of every rule swatch of an HTML page.
fn swatches(html: &str) -> BTreeSet<(String, String)> {
    let mut out = BTreeSet::new();
    let mut rest = html;
    let head = "<td class=\"rule\" data-sort=\"";
    while let Some(at) = rest.find(head) {
        rest = &rest[at + head.len()..];
        let label = rest[..rest.find('"').expect("label")].to_string();
        let bg = "background:";
        let at = rest.find(bg).expect("swatch") + bg.len();
        out.insert((label, rest[at..at + 7].to_ascii_lowercase()));
    }
    out
}

/// No two rules of one page share a colour, where twelve rules' labels
/// (several outside the shipped list, products among them) meet on one page
/// and on the index; each shipped rule keeps its own colour, and the plots
/// draw each rule in its table's colour.
#[test]
fn no_two_rules_of_a_page_share_a_colour() {
    let dir = scratch("colours");
    let base = fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("experiments/w-ss-edge-coverage.json"),
    )
    .expect("bundled file");
    let mut exp: serde_json::Value = serde_json::from_str(&base).expect("json");
    let product = |a: &str, b: &str| serde_json::json!({"rule": "product", "outer": {"rule": a}, "inner": {"rule": b}});
    let mut rules: Vec<serde_json::Value> = [
        "gauss-legendre",
        "genz-malik",
        "trapezoid",
        "grid",
        "centre",
        "corner",
        "stratified",
        "sobol",
        "monte-carlo",
    ]
    .map(|r| serde_json::json!({ "rule": r }))
    .to_vec();
    rules.push(serde_json::json!({"rule": "adaptive", "threshold": 0.01}));
    rules.push(product("gauss-legendre", "trapezoid"));
    rules.push(product("gauss-kronrod", "stratified"));
    exp["rules"] = serde_json::Value::Array(rules);
    exp["budgets"] = serde_json::json!([16, 256]);
    exp["repeats"] = serde_json::json!(1);
    exp["quantities"] = serde_json::json!(["coverage"]);
    let file = dir.join("many.json");
    fs::write(&file, exp.to_string()).expect("write");
    let out = dir.join("out");
    let opts = RunOptions {
        out: out.clone(),
        resume: false,
        shard: None,
        progress: false,
    };
    run_files(&lightquad::families::builtin(), &[file], &opts).unwrap_or_else(|e| panic!("{e}"));
    for page in [
        out.join("index.html"),
        out.join("w-ss-edge-coverage/index.html"),
    ] {
        let html = fs::read_to_string(&page).expect("page");
        let pairs = swatches(&html);
        let labels: BTreeSet<&str> = pairs.iter().map(|(l, _)| l.as_str()).collect();
        let colours: BTreeSet<&str> = pairs.iter().map(|(_, c)| c.as_str()).collect();
        assert_eq!(
            labels.len(),
            pairs.len(),
            "{}: a rule in two colours: {pairs:?}",
            page.display()
        );
        assert_eq!(
            colours.len(),
            pairs.len(),
            "{}: two rules in one colour: {pairs:?}",
            page.display()
        );
        for (label, colour) in &pairs {
            if ["gauss-legendre", "trapezoid", "sobol", "stratified"].contains(&label.as_str()) {
                assert_eq!(colour, &rule_css(label), "{label} changed colour");
            }
        }
        if page.ends_with("w-ss-edge-coverage/index.html") {
            assert_eq!(pairs.len(), 12, "{pairs:?}");
            let svg = html.to_ascii_lowercase();
            for (label, colour) in &pairs {
                assert!(
                    svg.matches(colour.as_str()).count() >= 3,
                    "{label}'s {colour} not in its plots"
                );
            }
        }
    }
    let _ = fs::remove_dir_all(&dir);
}

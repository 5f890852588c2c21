//! The findings of a quantity, in words computed from its section: which
//! rule reaches each target first and by how much, the fitted orders, and
//! which rules carry flags at which budgets. Every figure comes from the
//! results, so no description has to state one (and none can go stale).

use std::borrow::Cow;
use std::collections::BTreeMap;

use super::rows::failed_in;
use super::{Page, RowFlag, Section, label};
use crate::experiment::timing::TimeInterval;
use crate::family::Flag;

/// The findings paragraph of `s` (Markdown, one paragraph), or none where
/// the quantity has no reference.
pub fn findings(page: &Page, s: &Section) -> Option<String> {
    s.reference.as_ref().ok()?;
    let mut out = vec![targets(page, s), orders(s), flags(page, s)];
    out.retain(|p| !p.is_empty());
    Some(format!("Findings (from the results): {}", out.join(" ")))
}

/// A sentence per target: the fastest rule and the next, or who reached it.
fn targets(page: &Page, s: &Section) -> String {
    let mut out = Vec::new();
    let exact: Vec<&str> = s
        .ranking
        .iter()
        .filter(|r| r.exact_from_start)
        .map(|r| r.label.as_str())
        .collect();
    for (k, t) in page.targets.iter().enumerate() {
        let mut reached: Vec<(&str, f64, TimeInterval)> = s
            .fits
            .iter()
            .filter_map(|f| {
                let time = f.reach.get(k)?.interval()?;
                Some((f.label.as_str(), time.median, time))
            })
            .collect();
        reached.sort_by(|a, b| a.1.total_cmp(&b.1));
        let below = s.fits.iter().all(|f| {
            f.times
                .get(k)
                .is_some_and(|x| x == "below reference accuracy")
        });
        let sentence = match reached.as_slice() {
            _ if below => {
                format!("{t:e} is below the reference's accuracy: no rule is judged against it.")
            }
            [] => format!("No rule reaches {t:e}."),
            [(a, x, _)] => format!("Only {a} reaches {t:e}, in {x:.2e} s."),
            [(a, x, i), (b, y, j), ..] if !i.apart(j) => format!(
                "{a} and {b} reach {t:e} in {x:.2e} and {y:.2e} s, not told apart (their \
                 times' confidence intervals overlap, or single readings within 1.5x; {} of {} \
                 rules reach it).",
                reached.len(),
                s.fits.len()
            ),
            [(a, x, _), (b, y, _), ..] => format!(
                "{a} reaches {t:e} first, in {x:.2e} s, {} times as fast as the next, \
                 {b} ({} of {} rules reach it).",
                speedup(y / x),
                reached.len(),
                s.fits.len()
            ),
        };
        out.push(sentence);
    }
    if !exact.is_empty() {
        out.push(format!(
            "At the error floor from its first budget: {}.",
            exact.join(", ")
        ));
    }
    out.join(" ")
}

/// A ratio of times above 1, to three digits below 10 (`1.04`: rules told
/// apart by a few percent do not read as `1.0` times as fast).
fn speedup(r: f64) -> String {
    if r < 10.0 {
        format!("{r:.2}")
    } else {
        format!("{r:.0}")
    }
}

/// The fitted orders against evaluations, erratic ones named as such.
fn orders(s: &Section) -> String {
    let fitted: Vec<String> = s
        .fits
        .iter()
        .filter_map(|f| {
            let (o, erratic) = f.evaluations_slope.map(|s| (s.slope, s.erratic))?;
            Some(if erratic {
                format!("{} erratic (not an order)", f.label)
            } else {
                // -0.001 reads as 0.00, not -0.00.
                let o = if o.abs() < 0.005 { 0.0 } else { o };
                format!("{} {o:.2}", f.label)
            })
        })
        .collect();
    if fitted.is_empty() {
        String::new()
    } else {
        format!(
            "Fitted slopes of log error against log evaluations: {}.",
            fitted.join(", ")
        )
    }
}

/// What a flag says of a rule, in a few words; none for the flags that say
/// nothing against the rule (an error at the reference's accuracy, no
/// estimate). A failure says in how many of the row's repeats.
fn kind(f: &RowFlag) -> Option<Cow<'static, str>> {
    Some(Cow::Borrowed(match f {
        RowFlag::Failed { failed, of, .. } => return Some(failed_in(*failed, *of).into()),
        RowFlag::NonFinite => "gave a value that is not a number",
        RowFlag::OutsideStandardErrors => "is more than 4 standard errors off",
        RowFlag::EstimateOff => "has an error estimate off by more than 10x",
        RowFlag::ErrorGrew => "has an error that grew with the budget",
        RowFlag::ErrorBeyondRange => "has an error beyond the f64 range",
        RowFlag::Job(Flag::AllNodesAlike { .. }) => {
            "saw the same value at every node (what no node saw reads as 0 +- 0)"
        }
        RowFlag::Job(Flag::HeavyWalks { .. }) => {
            "has walks carried by a few (the mean rests on walks not yet seen)"
        }
        RowFlag::Job(Flag::AllWalksAlike { .. }) => "had every walk score alike",
        RowFlag::Job(Flag::UnreliableEstimate) => "doubts its own error estimate",
        RowFlag::Job(Flag::Underflow) => "underflows f64",
        RowFlag::Job(Flag::Cancellation { .. }) => "lost digits to cancellation",
        RowFlag::AtReferenceAccuracy(_) | RowFlag::NoEstimate => return None,
    }))
}

/// A clause per rule and flag: the budgets it shows at.
fn flags(page: &Page, s: &Section) -> String {
    let mut by: BTreeMap<(usize, Cow<'static, str>), Vec<usize>> = BTreeMap::new();
    for r in &s.rows {
        for f in &r.flags {
            if let Some(k) = kind(f) {
                by.entry((r.rule_index, k)).or_default().push(r.budget);
            }
        }
    }
    if by.is_empty() {
        return "No row carries a flag against its rule.".into();
    }
    // A rule's clauses in the order of their first budget ("failed in 10
    // of 12" at n = 8 before "failed in 2 of 12" at n = 16).
    let mut clauses: Vec<(usize, usize, String)> = by
        .into_iter()
        .map(|((i, k), mut budgets)| {
            budgets.sort_unstable();
            budgets.dedup();
            let first = budgets.first().copied().unwrap_or(0);
            let clause = format!("{} {k} at {}", label(page, i), at(page.budgets, &budgets));
            (i, first, clause)
        })
        .collect();
    clauses.sort();
    let clauses: Vec<String> = clauses.into_iter().map(|(_, _, c)| c).collect();
    format!("Flags: {}.", clauses.join("; "))
}

/// The budgets a flag shows at, in words: a run of the page's budgets as
/// its ends, a few others one by one.
fn at(all: &[usize], budgets: &[usize]) -> String {
    let run = |a: usize, b: usize| {
        let between: Vec<usize> = all.iter().copied().filter(|&n| n >= a && n <= b).collect();
        between == budgets
    };
    match budgets {
        [one] => format!("n = {one}"),
        [a, .., b] if budgets.len() > 2 && run(*a, *b) => {
            format!("every budget from n = {a} to {b}")
        }
        _ if budgets.len() <= 6 => {
            let list: Vec<String> = budgets.iter().map(ToString::to_string).collect();
            format!("n = {}", list.join(", "))
        }
        [a, .., b] => format!("{} of the budgets from n = {a} to {b}", budgets.len()),
        [] => String::new(),
    }
}

//! Reports, the sinks of a run: per experiment a Markdown page (a table per
//! quantity, fitted orders, time to reach target errors, stability flags) with
//! SVG plots of error against time and against n, a CSV of every job, and an
//! index page that links every experiment and ranks the rules by time to error.
//!
//! Nothing here knows a family: a page is described by a [`Page`], and values
//! are channel vectors (a scalar, RGB, an image), compared by their root mean
//! square.
//!
//! ```
//! use std::collections::BTreeMap;
//! use lightquad::experiment::report::{Against, RuleInfo, order, rows};
//! use lightquad::quadrature::{Rule, Trapezoid};
//!
//! let text = r#"{"name": "doc-report", "family": "calibration", "scene": {}, "quantities": ["exp"],
//!   "rules": [{"rule": "trapezoid"}], "budgets": [8, 16, 32, 64, 128], "repeats": 1,
//!   "reference": {"type": "closed-form"}}"#;
//! let exp = lightquad::families::builtin().load(serde_json::from_str(text)?, "hash")?;
//! let results: Vec<_> = exp.jobs(None).into_iter().map(|job| exp.run_job(job)).collect();
//! // One row per (rule, budget) against the reference e - 1, and the order fitted
//! // against the resolution a budget buys (n - 1 intervals): -2 for the trapezoid rule.
//! let intervals: BTreeMap<usize, f64> = [8, 16, 32, 64, 128].map(|n| (n, Trapezoid.resolution(n, 1))).into();
//! let rule = RuleInfo { label: "trapezoid".into(), is_random: false, min_budget: 2,
//!     resolution: BTreeMap::from([(1, intervals.clone())]) };
//! let table = rows(&[rule], &results, "exp", &[std::f64::consts::E - 1.0], None);
//! assert_eq!(table.len(), 5);
//! let against = Against::Resolution { dimension: 1, by_budget: Some(&intervals) };
//! let slope = order(&table.iter().collect::<Vec<_>>(), against, 0.0).ok_or("no fit")?;
//! assert!((slope + 2.0).abs() < 0.01, "{slope}");
//! // The page itself: report.md, SVG plots, results.csv and index.html.
//! let dir = std::env::temp_dir().join(format!("lightquad-doc-report-{}", std::process::id()));
//! std::fs::create_dir_all(&dir)?;
//! exp.write_report(&dir, &results)?;
//! assert!(std::fs::read_to_string(dir.join("report.md"))?.contains("trapezoid"));
//! assert!(dir.join("results.csv").exists() && dir.join("index.html").exists());
//! std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::fit::fitted_line;
use super::plot;
use super::reference::{CROSSCHECK_INTRO, Crosscheck, Reference, crosscheck_markdown, rms};
use super::run::{JobResult, write_report_file};
use crate::family::{Display, Flag, Measured};

/// What a report page shows of an experiment, whatever its family.
#[derive(Debug, Clone)]
pub struct Page<'a> {
    /// Experiment name.
    pub name: &'a str,
    /// What it shows.
    pub description: &'a str,
    /// Its family.
    pub family: &'static str,
    /// Its equation IDs.
    pub equations: &'a [String],
    /// Budgets, ascending.
    pub budgets: &'a [usize],
    /// What a budget counts.
    pub budget_unit: &'static str,
    /// Why a row may count more evaluations than its budget
    /// ([`Family::OVER_BUDGET`](crate::family::Family::OVER_BUDGET)).
    pub over_budget: &'static str,
    /// Repeats per (rule, budget).
    pub repeats: usize,
    /// The file's seed.
    pub seed: u64,
    /// How the family evaluates the scene, in words (may be empty).
    pub settings: String,
    /// The quantities, in the file's order.
    pub quantities: Vec<&'static str>,
    /// Each quantity's dimension (a budget of n is n^(1/D) nodes per axis).
    pub dimensions: Vec<usize>,
    /// Each quantity's display ([`Family::display`](crate::family::Family::display)).
    pub displays: Vec<Option<Display>>,
    /// Each quantity's image shape ([`Family::image`](crate::family::Family::image)).
    pub images: Vec<Option<[usize; 2]>>,
    /// The rules and estimators, in the file's order.
    pub rules: Vec<RuleInfo>,
    /// Target relative errors.
    pub targets: &'a [f64],
    /// The reference.
    pub reference: &'a Reference,
    /// The Mitsuba comparison rows (may be empty).
    pub crosscheck: &'a [Crosscheck],
    /// The family's section on this scene (e.g. printed formulas), if any.
    pub scene_audit: Option<String>,
}

/// A rule or estimator as a report sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct RuleInfo {
    /// Its label (its name, with `#index` where the file names it twice).
    pub label: String,
    /// True for randomised rules (their estimate is a standard error).
    pub is_random: bool,
    /// The smallest budget it runs at (smaller budgets are skipped for it).
    pub min_budget: usize,
    /// Per dimension, the resolution per axis each budget buys
    /// ([`crate::quadrature::Rule::resolution`]: intervals of a composite
    /// rule, nodes or samples per axis otherwise); a missing entry is read as
    /// `n^(1/D)`.
    pub resolution: BTreeMap<usize, BTreeMap<usize, f64>>,
}

/// A fact about a row of a report table.
#[derive(Debug, Clone, PartialEq)]
pub enum RowFlag {
    /// A job failed, with its reason.
    Failed(String),
    /// A value is NaN or infinite.
    NonFinite,
    /// A fact the family recorded on the value.
    Job(Flag),
    /// A random estimate whose standard error misses the true error.
    OutsideStandardErrors,
    /// A deterministic error estimate off by more than 10x: too small beside
    /// an error above 1e-13, too large beside one of at least 1e-12.
    EstimateOff,
    /// The error grew with the budget, above the rounding floor.
    ErrorGrew,
    /// The error is at or below the reference's own relative accuracy.
    AtReferenceAccuracy(f64),
    /// The method's error estimate is infinite: it had no information to
    /// estimate the error (stratified sampling on two cells).
    NoEstimate,
    /// The true relative error is beyond the f64 range though value and
    /// reference are finite: the reference is too small to divide by (a
    /// literal reference of 5e-324 showed an error of inf, unflagged).
    ErrorBeyondRange,
}

impl std::fmt::Display for RowFlag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RowFlag::Failed(why) => write!(f, "failed: {why}"),
            RowFlag::NonFinite => write!(f, "non-finite value"),
            RowFlag::Job(flag) => write!(f, "{flag}"),
            RowFlag::OutsideStandardErrors => write!(f, "outside 4 standard errors"),
            RowFlag::EstimateOff => write!(f, "estimate off by more than 10x"),
            RowFlag::ErrorGrew => write!(f, "error grew with the budget"),
            RowFlag::AtReferenceAccuracy(a) => write!(f, "at the reference's accuracy ({a:.1e})"),
            RowFlag::NoEstimate => write!(
                f,
                "no error estimate (infinite: too little to estimate from)"
            ),
            RowFlag::ErrorBeyondRange => write!(
                f,
                "relative error beyond the f64 range (the reference is too small to divide by)"
            ),
        }
    }
}

/// The legend of the flags (Markdown), below every page.
pub const FLAG_LEGEND: &str = "Flags: `failed` (the job's reason follows); `non-finite value`; \
`outside 4 standard errors` (a random estimate whose standard error misses the true error: \
the root mean square over channels of error / standard error above 4); \
`estimate off by more than 10x` (a deterministic error estimate: too small beside an error \
above 1e-13, or too large beside an error, or the reference's accuracy, of at least 1e-12); \
`error estimate unreliable (rule's own check)` (the rule doubts its own estimate: a \
deterministic rule too small to check it (below 16 Gauss–Legendre nodes or 17 composite points \
per axis), whose differences do not shrink the way its order says, or whose sum one node \
carries; or a random one whose \
samples were all alike, a constant integrand included, since nothing was seen to vary, or whose \
sample variance is carried by a few samples); `error grew with the budget` (by more than 1.5x \
from one budget to the next, from an error above 1e-11; smaller rises are not flagged); `cancellation` (a sum below 1e-6 of the summed magnitudes of its \
parts); `relative error beyond the f64 range` (a finite value against a finite reference too small to \
divide by); `underflows` (the value is below the smallest f64 and reads 0; its logarithm is exact: ask for `ln_tau`, \
and `ln I_B = ln B + ln tau`); `no error estimate` (the method had too little to estimate from: \
stratified sampling on two cells); `at the reference's accuracy` (the error is not resolved by the reference); `all N walks \
scored alike` (a tracking estimate with zero sample variance: its error is a Wilson half-width \
/ 1.96, not a sample standard error).";

/// One row of a report table: a rule at one budget, aggregated over repeats.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Index of the rule in the file.
    pub rule_index: usize,
    /// Budget.
    pub budget: usize,
    /// Mean value over repeats, per channel.
    pub value: Vec<f64>,
    /// Root-mean-square true error over repeats and channels, relative to the
    /// reference's root mean square (absolute where that is 0).
    pub rel_error: f64,
    /// Mean over repeats of the root-mean-square estimated error, same scale.
    pub rel_estimate: f64,
    /// The largest true error of any channel in any repeat, same scale (the
    /// worst pixel of an image; `rel_error` itself for one channel).
    pub max_error: f64,
    /// Where the quantity has a display: mean over repeats of the channels
    /// whose displayed value differs from the reference's (0: more work does
    /// not change what a person sees, against this reference).
    pub display_off: Option<f64>,
    /// Mean evaluations.
    pub evaluations: f64,
    /// Lower median wall time, seconds.
    pub seconds: f64,
    /// Stability flags.
    pub flags: Vec<RowFlag>,
}

/// Relative errors below this are at the f64 rounding floor: no order is
/// fitted through them and no estimate is judged against them.
const FLOOR: f64 = 1e-14;

/// The lower median (of two repeats, the faster: the first pays for cold caches).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[(v.len() - 1) / 2]
    }
}

/// Aggregates the jobs of quantity `q` into rows, with their flags; with
/// the quantity's display, each row counts the displayed values that differ
/// from the reference's.
pub fn rows(
    rules: &[RuleInfo],
    results: &[JobResult],
    q: &str,
    reference: &[f64],
    display: Option<(&Display, &[bool])>,
) -> Vec<Row> {
    let mut groups: BTreeMap<(usize, usize), Vec<&JobResult>> = BTreeMap::new();
    for r in results {
        groups.entry((r.rule_index, r.budget)).or_default().push(r);
    }
    let scale = scale_of(reference);
    let mut out: Vec<Row> = groups
        .into_iter()
        .map(|((rule_index, budget), jobs)| {
            let random = rules.get(rule_index).is_some_and(|r| r.is_random);
            let mut row = row(rule_index, budget, &jobs, q, reference, scale, random);
            if let Some((d, doubt)) = display
                && !row.value.is_empty()
            {
                row.display_off = Some(display_off(d, doubt, &jobs, q, reference));
            }
            row
        })
        .collect();
    // Convergence that stalls or reverses, above the rounding floor.
    for i in 1..out.len() {
        if out[i].rule_index == out[i - 1].rule_index
            && out[i - 1].rel_error > 1e3 * FLOOR
            && out[i].rel_error > 1.5 * out[i - 1].rel_error
        {
            out[i].flags.push(RowFlag::ErrorGrew);
        }
    }
    out
}

/// The scale of a quantity's relative errors: the reference's root mean
/// square, or 1 (absolute errors) where that is 0.
fn scale_of(reference: &[f64]) -> f64 {
    match rms(reference.iter().copied()) {
        s if s > 0.0 => s,
        _ => 1.0,
    }
}

/// One row from the repeats of one (rule, budget).
fn row(
    rule_index: usize,
    budget: usize,
    jobs: &[&JobResult],
    q: &str,
    reference: &[f64],
    scale: f64,
    random: bool,
) -> Row {
    let mut flags = Vec::new();
    if let Some(f) = jobs.iter().find_map(|j| j.failure.clone()) {
        flags.push(RowFlag::Failed(f));
    }
    // The quantity's own time where the job timed it alone (older results
    // files: the job's).
    let seconds = median(
        jobs.iter()
            .map(|j| {
                j.quantities
                    .get(q)
                    .and_then(|m| m.seconds)
                    .unwrap_or(j.seconds)
            })
            .collect(),
    );
    let measured: Vec<_> = jobs.iter().filter_map(|j| j.quantities.get(q)).collect();
    if measured.is_empty() {
        // Every job of this row failed: keep the row, so the failure shows.
        return Row {
            rule_index,
            budget,
            value: Vec::new(),
            rel_error: f64::NAN,
            rel_estimate: f64::NAN,
            max_error: f64::NAN,
            display_off: None,
            evaluations: 0.0,
            seconds,
            flags,
        };
    }
    if measured
        .iter()
        .any(|m| m.value.iter().any(|v| !v.is_finite()))
    {
        flags.push(RowFlag::NonFinite);
    }
    if measured
        .iter()
        .any(|m| m.error.iter().any(|e| !e.is_finite()))
    {
        flags.push(RowFlag::NoEstimate);
    }
    // The families' flags, once per kind.
    for f in measured.iter().flat_map(|m| &m.flags) {
        let kind = std::mem::discriminant(f);
        if !flags
            .iter()
            .any(|g| matches!(g, RowFlag::Job(h) if std::mem::discriminant(h) == kind))
        {
            flags.push(RowFlag::Job(*f));
        }
    }
    let count = measured.len() as f64;
    let channels = reference.len();
    // Each value divided before the sum, so values near 1.8e308 average
    // without overflow.
    let value: Vec<f64> = (0..channels)
        .map(|c| {
            measured
                .iter()
                .map(|m| channel(&m.value, c) / count)
                .sum::<f64>()
        })
        .collect();
    if value.iter().any(|v| !v.is_finite()) && !flags.contains(&RowFlag::NonFinite) {
        flags.push(RowFlag::NonFinite);
    }
    // True error: the root mean square over repeats and channels. Near the
    // top of the range the halves are subtracted and the result doubled
    // (exact for normal numbers): 1.7e308 against -1.7e308 overflowed to an
    // error of inf.
    let huge = reference.iter().any(|r| r.abs() > f64::MAX / 2.0)
        || measured
            .iter()
            .flat_map(|m| &m.value)
            .any(|v| v.abs() > f64::MAX / 2.0);
    let (halve, double) = if huge { (0.5, 2.0) } else { (1.0, 1.0) };
    let diffs: Vec<f64> = measured
        .iter()
        .flat_map(|m| {
            (0..channels.max(m.value.len()))
                .map(move |c| channel(&m.value, c) * halve - channel(reference, c) * halve)
        })
        .collect();
    let rel_error = rms(diffs.iter().copied()) / scale * double;
    if rel_error.is_infinite()
        && value.iter().all(|v| v.is_finite())
        && reference.iter().all(|r| r.is_finite())
    {
        flags.push(RowFlag::ErrorBeyondRange);
    }
    let max_error = diffs.iter().map(|d| d.abs()).fold(0.0, |m: f64, d| {
        if d.is_nan() || m.is_nan() {
            f64::NAN
        } else {
            m.max(d)
        }
    }) / scale
        * double;
    let rel_estimate = measured
        .iter()
        .map(|m| rms(m.error.iter().copied()) / count)
        .sum::<f64>()
        / scale;
    let evaluations = measured.iter().map(|m| m.evaluations as f64).sum::<f64>() / count;
    if let Some(flag) = judge_estimate(&measured, reference, rel_error, rel_estimate, random) {
        flags.push(flag);
    }
    // A value that underflowed (0 in f64 against a reference that also reads
    // 0) has no error f64 can show: 0 on paper, 100% against the true value
    // (e^-100000 on the stiff sphere). Shown as none; its logarithm is the
    // quantity that carries it.
    let underflow = flags.contains(&RowFlag::Job(Flag::Underflow));
    let none_if_underflow = |x: f64| if underflow { f64::NAN } else { x };
    let (rel_error, rel_estimate, max_error) = (
        none_if_underflow(rel_error),
        none_if_underflow(rel_estimate),
        none_if_underflow(max_error),
    );
    Row {
        rule_index,
        budget,
        value,
        rel_error,
        rel_estimate,
        max_error,
        display_off: None,
        evaluations,
        seconds,
        flags,
    }
}

/// Mean over the repeats of the channels whose displayed value differs from
/// the reference's (a missing channel counts as differing), among those whose
/// displayed value the reference fixes (`doubt[c]` false or absent): a
/// reference within its accuracy of a step boundary would count a rule off,
/// or not, by its own rounding.
fn display_off(
    d: &Display,
    doubt: &[bool],
    jobs: &[&JobResult],
    q: &str,
    reference: &[f64],
) -> f64 {
    let measured: Vec<&Measured> = jobs.iter().filter_map(|j| j.quantities.get(q)).collect();
    let off = |m: &Measured| {
        (0..reference.len().max(m.value.len()))
            .filter(|&c| !doubt.get(c).copied().unwrap_or(false))
            .filter(|&c| match (m.value.get(c), reference.get(c)) {
                (Some(&v), Some(&r)) => (d.quantize)(v) != (d.quantize)(r),
                _ => true,
            })
            .count() as f64
    };
    measured.iter().map(|m| off(m)).sum::<f64>() / measured.len().max(1) as f64
}

/// The rule's own error estimate against the truth: a random estimate more
/// than 4 standard errors off in any channel; a deterministic estimate off by
/// more than 10x, above the rounding floor.
fn judge_estimate(
    measured: &[&Measured],
    reference: &[f64],
    rel_error: f64,
    rel_estimate: f64,
    random: bool,
) -> Option<RowFlag> {
    if random {
        // Per job, the root mean square over channels of the errors in units
        // of their standard errors: |z| for a scalar, and for an image a test
        // that does not fire merely because some of many pixels sit beyond 4.
        let outside = measured.iter().any(|m| {
            let z = (0..m.value.len())
                .filter(|&c| channel(&m.error, c).is_finite())
                .map(|c| {
                    let d = channel(&m.value, c) - channel(reference, c);
                    // A difference at the rounding floor is no miss, whatever
                    // the standard error (0 when every sample agreed).
                    let rounding = FLOOR * channel(reference, c).abs();
                    match channel(&m.error, c) {
                        _ if d.abs() <= rounding => 0.0,
                        e if e > 0.0 => d / e,
                        _ => f64::INFINITY,
                    }
                });
            rms(z.collect::<Vec<_>>().into_iter()) > 4.0
        });
        outside.then_some(RowFlag::OutsideStandardErrors)
    } else {
        // An estimate more than 10x too small is judged from an error of
        // 1e-13 (ten times the floor): at a cut of 1e-12 an error of 1e-12
        // with an estimate of 2.2e-16 went unflagged or flagged as rounding
        // put it at 0.99997e-12 or 1.0001e-12. One more than 10x too large
        // (the safe side) is judged against an error of at least 1e-12: an
        // estimate of 8.2e-3 beside a true error of 1.8e-16 (the trapezoid
        // at the rounding floor) went unflagged.
        let low = rel_error > 10.0 * FLOOR && rel_estimate < rel_error / 10.0;
        let high = rel_estimate > 10.0 * rel_error.max(100.0 * FLOOR);
        let off = rel_estimate.is_finite() && (low || high);
        off.then_some(RowFlag::EstimateOff)
    }
}

/// Channel `c` of `v`, NaN when it has none (a value of the wrong shape).
fn channel(v: &[f64], c: usize) -> f64 {
    v.get(c).copied().unwrap_or(f64::NAN)
}

/// What a fitted slope is measured against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Against<'a> {
    /// The resolution per axis each budget buys the rule (intervals of a
    /// composite rule, nodes or samples per axis: `n^(1/D)` where the map has
    /// no entry): a rule of order p shows as -p whatever an evaluation costs
    /// and whatever the dimension.
    Resolution {
        /// The quantity's dimension D.
        dimension: usize,
        /// Budget to resolution, for this rule and dimension.
        by_budget: Option<&'a BTreeMap<usize, f64>>,
    },
    /// The evaluations spent: the cost (nested depth makes it ~n^2, so an
    /// order-2 rule shows as -1 there).
    Evaluations,
}

/// Rows an order is fitted through: the largest budgets above the floor (an
/// order is an asymptotic property; the smallest budgets are often not yet
/// in the asymptotic range).
pub const FIT_ROWS: usize = 4;

/// The fitted slope of log error against log `against` of one rule's rows,
/// through the last [`FIT_ROWS`] rows whose error is above both the rounding
/// floor and ten times the reference's own accuracy (`floor`); None below
/// three such rows.
pub fn order(rows: &[&Row], against: Against, floor: f64) -> Option<f64> {
    order_and_scatter(rows, against, floor).map(|(o, _, _)| o)
}

/// The error an order is fitted above: ten times the reference's accuracy
/// `accuracy`, and `100 FLOOR` (f64 rounding), the larger.
pub fn fit_floor(accuracy: f64) -> f64 {
    (100.0 * FLOOR).max(10.0 * accuracy)
}

/// Errors further than this factor from the fitted line: the slope is shown
/// as erratic, not as an order (a deterministic rule's; a random rule's root
/// mean square over a few repeats scatters more and gets twice the room).
pub const ERRATIC: f64 = 2.0;

/// [`order`] with the largest factor by which a fitted point lies off the
/// line ([`super::fit::fitted_line`]), and whether the error grew by more
/// than 1.5x from one fitted point to the next.
pub fn order_and_scatter(rows: &[&Row], against: Against, floor: f64) -> Option<(f64, f64, bool)> {
    let mut pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.rel_error > fit_floor(floor))
        .map(|r| {
            let x = match against {
                Against::Resolution {
                    dimension,
                    by_budget,
                } => by_budget
                    .and_then(|m| m.get(&r.budget).copied())
                    .unwrap_or_else(|| (r.budget as f64).powf(1.0 / dimension.max(1) as f64)),
                Against::Evaluations => r.evaluations,
            };
            (x, r.rel_error)
        })
        .collect();
    if pts.len() < 3 {
        return None;
    }
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let tail = &pts[pts.len().saturating_sub(FIT_ROWS)..];
    let grew = tail.windows(2).any(|w| w[1].1 > 1.5 * w[0].1);
    fitted_line(tail).map(|(slope, off)| (slope, off, grew))
}

/// The time a rule needs to reach `target` and stay there: the least median
/// time among the rows from the smallest budget on whose every larger
/// budget meets the target too; None where the largest budget misses it.
///
/// An error that dips below the target at one budget by a lucky
/// cancellation and rises above it again does not count (Gauss–Legendre on
/// r-sphere-below-horizon: 3.2e-7 at n = 1024, 5.7e-6 at 4096, below 1e-6
/// only from 65536 on; the first row ranked it first). A failed row reaches
/// nothing, nor does one whose value underflowed: 0 against a reference
/// that also reads 0 in f64 is an error of 0 on paper and of 100% against
/// the true value (`e^-100000` on the stiff sphere).
pub fn time_to(rows: &[&Row], target: f64) -> Option<f64> {
    let meets = |r: &Row| {
        r.rel_error <= target
            && !r
                .flags
                .iter()
                .any(|f| matches!(f, RowFlag::Failed(_) | RowFlag::Job(Flag::Underflow)))
    };
    let mut by_budget: Vec<&Row> = rows.to_vec();
    by_budget.sort_by_key(|r| r.budget);
    // The rows past the last budget that misses the target.
    let from = by_budget
        .iter()
        .rposition(|r| !meets(r))
        .map_or(0, |i| i + 1);
    by_budget[from..]
        .iter()
        .map(|r| r.seconds)
        .min_by(f64::total_cmp)
}

/// An error for a table cell: "—" where there is none (a failed row).
pub fn cell(x: f64) -> String {
    if x.is_nan() {
        "—".into()
    } else {
        format!("{x:.2e}")
    }
}

/// A value for a table cell: the number, or the root mean square of the
/// channels with their count.
pub fn show_value(v: &[f64]) -> String {
    match v {
        [] => "—".into(),
        [x] => format!("{x:.15e}"),
        _ => format!("rms {:.15e} ({} channels)", rms(v.iter().copied()), v.len()),
    }
}

/// Per-experiment summary for the index: per quantity, in the file's order,
/// each rule's time to the middle target (None: not reached).
pub type Summary = Vec<(&'static str, Vec<Ranked>)>;

/// One rule in the index's ranking of a quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct Ranked {
    /// The rule's label.
    pub label: String,
    /// Its time to the middle target (None: not reached).
    pub seconds: Option<f64>,
    /// A deterministic rule whose error is unresolved (exact, at rounding, or
    /// at the reference's accuracy) already at its smallest budget: its rank
    /// then says nothing about its speed on integrands in general.
    pub exact_from_start: bool,
}

/// One quantity of an experiment page, computed once and shown by both the
/// Markdown and the HTML page.
#[derive(Debug, Clone)]
pub struct Section {
    /// The quantity.
    pub quantity: &'static str,
    /// The reference value as shown, or why there is none (then the rest is empty).
    pub reference: Result<String, String>,
    /// A row per (rule, budget).
    pub rows: Vec<Row>,
    /// The heading of the slope-against-budget column.
    pub slope_heading: String,
    /// A line per rule: fitted slopes and times to the targets.
    pub fits: Vec<Fit>,
    /// The plots: (what they show, file name, SVG text).
    pub plots: Vec<(&'static str, String, String)>,
    /// Each rule's time to the middle target.
    pub ranking: Vec<Ranked>,
    /// For an image-valued quantity: the reference's image and each rule's
    /// at its largest budget, with error heat maps.
    pub pictures: Vec<Picture>,
}

/// An image the report shows, with its files (PNG, PFM, and the error heat
/// map's PNG where it is a rule's).
#[derive(Debug, Clone)]
pub struct Picture {
    /// What it is, with its errors.
    pub caption: String,
    /// Its width in pixels.
    pub width: usize,
    /// The PNG's file name (W-Grey's 8-bit mapping).
    pub png: String,
    /// The PFM's file name (32-bit floats).
    pub pfm: String,
    /// The error heat map's PNG file name, for a rule's image.
    pub error_png: Option<String>,
    /// The files' names and bytes.
    pub files: Vec<(String, Vec<u8>)>,
}

/// A rule's fitted slopes and times to the targets, as shown.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The rule's label.
    pub label: String,
    /// The slope of log error against log budget per axis ("—": too few rows).
    pub slope_budget: String,
    /// The slope of log error against log evaluations.
    pub slope_evaluations: String,
    /// Per target: the time in seconds, "not reached" or "below reference accuracy".
    pub times: Vec<String>,
}

/// Computes the sections of a page, one per quantity in the file's order.
pub fn sections(page: &Page, results: &[JobResult]) -> Result<Vec<Section>, String> {
    let mut out = Vec::new();
    for (i, &q) in page.quantities.iter().enumerate() {
        let Some(reference) = page.reference.values.get(q) else {
            let why = page
                .reference
                .missing
                .get(q)
                .map_or("no reference value", String::as_str);
            out.push(Section {
                quantity: q,
                reference: Err(why.to_string()),
                rows: Vec::new(),
                slope_heading: String::new(),
                fits: Vec::new(),
                plots: Vec::new(),
                ranking: Vec::new(),
                pictures: Vec::new(),
            });
            continue;
        };
        let display = page.displays.get(i).copied().flatten();
        let doubt = display
            .as_ref()
            .map(|d| in_doubt(d, q, reference, page))
            .unwrap_or_default();
        let mut rows = rows(
            &page.rules,
            results,
            q,
            reference,
            display.as_ref().map(|d| (d, doubt.as_slice())),
        );
        let accuracy = page.reference.accuracy_of(q);
        for r in rows.iter_mut() {
            if accuracy > 0.0 && r.rel_error <= accuracy {
                r.flags.push(RowFlag::AtReferenceAccuracy(accuracy));
                // The true error is known only to be below the reference's
                // accuracy: an estimate is contradicted only beyond ten
                // times that.
                if r.rel_estimate <= 10.0 * accuracy.max(100.0 * FLOOR) {
                    r.flags.retain(|f| *f != RowFlag::EstimateOff);
                }
            }
        }
        let pictures = match page.images.get(i).copied().flatten() {
            Some(shape) => pictures(page, q, shape, reference, &rows)?,
            None => Vec::new(),
        };
        let mut section = orders_and_plots(page, q, show_value(reference), rows)?;
        section.pictures = pictures;
        out.push(section);
    }
    Ok(out)
}

/// The reference's image and each rule's mean image at its largest budget,
/// with heat maps of `|image - reference|` (the largest channel per pixel),
/// each on its own scale (on a common one the better rules' maps were
/// black beside the centre ray's), stated in its caption.
fn pictures(
    page: &Page,
    q: &str,
    [width, height]: [usize; 2],
    reference: &[f64],
    rows: &[Row],
) -> Result<Vec<Picture>, String> {
    use crate::whitted::image::Image;
    let image = |v: &[f64]| -> Result<Image, String> {
        let pixels = v
            .chunks_exact(3)
            .map(|c| crate::value::Rgb::new(c[0], c[1], c[2]))
            .collect();
        Image::new(width, height, pixels).map_err(|e| e.to_string())
    };
    if reference.len() != 3 * width * height {
        return Ok(Vec::new());
    }
    let reference_image = image(reference)?;
    let base = format!("{}-{q}", page.name);
    let png = |i: &Image| i.png().map_err(|e| e.to_string());
    let pfm = |i: &Image| i.pfm().map_err(|e| e.to_string());
    let mut out = vec![Picture {
        caption: "the reference".into(),
        width,
        png: format!("{base}-reference.png"),
        pfm: format!("{base}-reference.pfm"),
        error_png: None,
        files: vec![
            (format!("{base}-reference.png"), png(&reference_image)?),
            (format!("{base}-reference.pfm"), pfm(&reference_image)?),
        ],
    }];
    // Each rule's row at its largest budget whose value is a whole image.
    let last: Vec<&Row> = (0..page.rules.len())
        .filter_map(|i| {
            rows.iter()
                .filter(|r| r.rule_index == i && r.value.len() == reference.len())
                .max_by_key(|r| r.budget)
        })
        .collect();
    let images = last
        .iter()
        .map(|r| image(&r.value))
        .collect::<Result<Vec<_>, _>>()?;
    for (r, img) in last.iter().zip(&images) {
        let worst = img
            .pixels()
            .iter()
            .zip(reference_image.pixels())
            .map(|(a, b)| (a - b).abs().max())
            .filter(|e| e.is_finite())
            .fold(0.0f64, f64::max);
        let scale = if worst > 0.0 { worst } else { 1.0 };
        let name = label(page, r.rule_index)
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect::<String>();
        let stem = format!("{base}-{}-{name}-n{}", r.rule_index, r.budget);
        let errors = img
            .error_map(&reference_image, scale)
            .map_err(|e| e.to_string())?;
        let off = r
            .display_off
            .map(|o| format!(", {} 8-bit values off", off_cell(Some(o))))
            .unwrap_or_default();
        out.push(Picture {
            caption: format!(
                "{}, n = {}: the mean over repeats, its map white at {worst:.2e} absolute; the \
                 row's errors over repeats {} RMS, {} largest channel (relative){off}",
                label(page, r.rule_index),
                r.budget,
                cell(r.rel_error),
                cell(r.max_error),
            ),
            width,
            png: format!("{stem}.png"),
            pfm: format!("{stem}.pfm"),
            error_png: Some(format!("{stem}-error.png")),
            files: vec![
                (format!("{stem}.png"), png(img)?),
                (format!("{stem}.pfm"), pfm(img)?),
                (format!("{stem}-error.png"), png(&errors)?),
            ],
        });
    }
    if let Some(first) = out.first_mut() {
        first.caption = "the reference; beside each rule's image its error map: the largest \
                         channel error per pixel, from black (0) through red and yellow to white \
                         (that image's largest)"
            .into();
    }
    Ok(out)
}

/// The rules whose minimum budget is above the smallest budget, in words.
pub fn skipped(page: &Page) -> Vec<String> {
    page.rules
        .iter()
        .filter(|r| page.budgets.first().is_some_and(|&b| b < r.min_budget))
        .map(|r| format!("{} needs at least {}", r.label, r.min_budget))
        .collect()
}

/// A ranking, fastest first; rules that never reached the target last, by name.
pub fn ranked(ranking: &[Ranked]) -> Vec<Ranked> {
    let mut ranked = ranking.to_vec();
    ranked.sort_by(|a, b| match (a.seconds, b.seconds) {
        (Some(x), Some(y)) => x.total_cmp(&y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => a.label.cmp(&b.label),
    });
    ranked
}

/// Times closer than this factor are ranked as a tie: two runs of the
/// bundled suite on one machine swapped rules whose times differed by 2%
/// (5.6e-7 s and 5.7e-7 s), and timings on a shared machine move by 10-20%.
pub const TIE_FACTOR: f64 = 1.25;

/// The rank of each rule in `ranked` (sorted by [`ranked`]): 1, 2, ...,
/// with a rule whose time is within [`TIE_FACTOR`] of the one before it
/// sharing that one's rank (a tie within timing noise). Rules that did not
/// reach the target rank after all that did.
pub fn ranks(ranked: &[Ranked]) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::with_capacity(ranked.len());
    for (i, r) in ranked.iter().enumerate() {
        let tied = i > 0
            && matches!(
                (ranked[i - 1].seconds, r.seconds),
                (Some(a), Some(b)) if b <= a * TIE_FACTOR
            );
        out.push(if tied { out[i - 1] } else { i + 1 });
    }
    out
}

/// Said of a rule whose rank it shares with the one before.
pub const TIED: &str = "tied: within 25% of the time of the rule before, timing noise";

/// Said of a rule ranked while exact from its first budget.
pub const EXACT_FROM_START: &str = "at the error floor from its first budget: this integrand is \
easy for it, the rank says little in general";

/// Writes `report.md`, the SVG plots, `results.csv` and `index.html` of one
/// experiment.
pub fn write_experiment(dir: &Path, page: &Page, results: &[JobResult]) -> Result<Summary, String> {
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
        let _ = writeln!(
            md,
            "## {q} (reference {reference})\n\n{}",
            table(page, &s.rows, display.as_ref())
        );
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
                .map(|t| format!("time to {t:.0e} (s)"))
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
             has no error and reaches nothing)."
        );
        md.push('\n');
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
    write_report_file(&dir.join("results.csv"), csv(results).as_bytes())?;
    super::html::write_experiment(dir, page, results, &sections)?;
    Ok(summary)
}

/// The page's title, settings, reference and provenance.
fn header(page: &Page, results: &[JobResult]) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# {}\n\n{}\n",
        page.name,
        super::markdown::plain(page.description)
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
    let _ = writeln!(
        md,
        "Family `{}`.{equations} Budgets {:?} ({}), {} repeat(s), seed {}{settings}.{shared}\n\n\
         Reference: {}\n",
        page.family, page.budgets, page.budget_unit, page.repeats, page.seed, page.reference.note
    );
    let skipped = skipped(page);
    if !skipped.is_empty() {
        let _ = writeln!(
            md,
            "Budgets below a rule's minimum are skipped for it: {}.\n",
            skipped.join(", ")
        );
    }
    if let Some(p) = provenance(results) {
        let _ = writeln!(md, "{p}\n");
    }
    md
}

/// Said of an experiment of several quantities.
pub const SHARED: &str = " Each quantity is evaluated and timed on its own (a job evaluates only \
the terms that quantity needs), so its times are its own cost.";

/// The version, commit, machine and experiment hash of a run, in words.
pub fn provenance(results: &[JobResult]) -> Option<String> {
    results.first().map(|r| {
        format!(
            "lightquad {} (commit {}), {}, experiment hash {}.",
            r.version,
            r.git_commit.as_deref().unwrap_or("unknown"),
            r.machine,
            r.experiment_hash
        )
    })
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
        " estimated error (mean over repeats, same scale; a standard error for random rules) | evaluations (mean) | median time (s) | flags |\n|---|---:|---:|---:|",
    );
    md.push_str(&"---:|".repeat(usize::from(multi) + usize::from(display.is_some())));
    md.push_str("---:|---:|---:|---|\n");
    for r in rows {
        // A job's failure text may carry a user's strings (a results line
        // edited by hand): escaped, so that it cannot break the table.
        let flags: Vec<String> = r
            .flags
            .iter()
            .map(|f| match f {
                RowFlag::Failed(why) => format!("failed: {}", super::markdown::plain(why)),
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
            " {} | {:.0} | {:.2e} | {} |",
            cell(r.rel_estimate),
            r.evaluations,
            r.seconds,
            flags.join("; ")
        );
    }
    md
}

/// Whether a quantity's table has the largest-channel-error column (several
/// channels) and the display column (a display and a row that counted).
pub fn extra_columns<'a>(
    rows: &[Row],
    display: Option<&'a Display>,
) -> (bool, Option<&'a Display>) {
    let multi = rows.iter().any(|r| r.value.len() > 1);
    let display = display.filter(|_| rows.iter().any(|r| r.display_off.is_some()));
    (multi, display)
}

/// A count of displayed values off, as shown ("—" where none was counted).
pub fn off_cell(off: Option<f64>) -> String {
    match off {
        None => "—".into(),
        Some(x) if x.fract() == 0.0 => format!("{x:.0}"),
        Some(x) => format!("{x:.1}"),
    }
}

/// What the display column shows, in words: half a step against the
/// table's scale, per rule the first budget from which every larger budget
/// leaves every displayed value equal to the reference's, and how many of
/// the reference's own displayed values its accuracy leaves in doubt.
pub fn display_line(
    display: &Display,
    q: &str,
    reference: &[f64],
    rows: &[Row],
    page: &Page,
) -> String {
    let scale = scale_of(reference);
    let unsure = in_doubt(display, q, reference, page)
        .iter()
        .filter(|&&d| d)
        .count();
    let unsure =
        if page.reference.accuracy_of(q) > 0.0 || page.reference.channel_accuracy.contains_key(q) {
            let how = if page.reference.channel_accuracy.contains_key(q) {
                "Each channel's accuracy (its last change or own error estimate, the larger, \
             and at least 1e-13 of its value)"
            } else {
                "The reference's accuracy"
            };
            format!(
                " {how} leaves {unsure} of the reference's own displayed values in doubt (within \
             it of a step boundary, such as a constant background of 0.3, 76.5 steps): those \
             channels are not counted, in the column or here."
            )
        } else {
            String::new()
        };
    let mut settled = Vec::new();
    for (i, rule) in page.rules.iter().enumerate() {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.rule_index == i).collect();
        let from = (0..mine.len())
            .find(|&k| mine[k..].iter().all(|r| r.display_off == Some(0.0)))
            .map(|k| mine[k].budget);
        let best = mine
            .iter()
            .filter_map(|r| r.display_off)
            .fold(f64::INFINITY, f64::min);
        settled.push(match from {
            Some(n) => format!("{} from n = {n}", rule.label),
            None if best.is_finite() => format!(
                "{} never (at best {} off)",
                rule.label,
                off_cell(Some(best))
            ),
            None => format!("{} never", rule.label),
        });
    }
    format!(
        "{name}: a channel's displayed value; {total} in all. Half a display step, {h:.3e} absolute, \
         is {rel:.2e} on this table's relative scale: a largest channel error below it moves no \
         displayed value by more than one step. The displayed image equals the reference's \
         (and more work leaves it unchanged, against this reference): {list}.{unsure}",
        name = display.name,
        total = reference.len(),
        h = display.half_step,
        rel = display.half_step / scale,
        list = settled.join("; ")
    )
}

/// Per channel of quantity `q`'s reference, whether its displayed value is
/// in doubt: within its accuracy (the channel's own where the reference knows
/// it, the quantity's otherwise) of a step boundary, where it may display
/// either way.
fn in_doubt(display: &Display, q: &str, reference: &[f64], page: &Page) -> Vec<bool> {
    let overall = page.reference.accuracy_of(q) * scale_of(reference);
    let each = page.reference.channel_accuracy.get(q);
    reference
        .iter()
        .enumerate()
        .map(|(c, &r)| {
            let a = each.and_then(|e| e.get(c)).copied().unwrap_or(overall);
            (display.quantize)(r - a) != (display.quantize)(r + a)
        })
        .collect()
}

/// A line saying why evaluations exceed the budget, where a row's do (its
/// mean evaluations above its n), naming the largest ratio; `None` where no
/// row's do.
pub fn over_budget(page: &Page, rows: &[Row]) -> Option<String> {
    let worst = rows
        .iter()
        .filter(|r| r.budget > 0 && r.evaluations > r.budget as f64)
        .map(|r| r.evaluations / r.budget as f64)
        .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))?;
    Some(format!(
        "Evaluations above n (up to {worst:.1} n in this table): {}.",
        page.over_budget
    ))
}

/// The label of rule `i` of the page.
pub fn label(page: &Page, i: usize) -> String {
    page.rules
        .get(i)
        .map_or_else(|| format!("rule #{i}"), |r| r.label.clone())
}

/// Fitted orders, times to the targets and the two plots of one quantity,
/// with each rule's time to the middle target.
fn orders_and_plots(
    page: &Page,
    q: &'static str,
    reference: String,
    rows: Vec<Row>,
) -> Result<Section, String> {
    let accuracy = page.reference.accuracy_of(q);
    let dimension = page
        .quantities
        .iter()
        .position(|x| *x == q)
        .and_then(|i| page.dimensions.get(i).copied())
        .unwrap_or(1);
    // Below this an error is not resolved: f64 rounding, or the reference's
    // own accuracy.
    let floor = accuracy.max(1e-16);
    let slope_heading = format!(
        "fitted slope of log error vs log of the resolution per axis that n buys{} (the intervals \
         of the points a composite rule uses, nodes or samples per axis otherwise: order p shows \
         as -p; the largest {FIT_ROWS} budgets whose error is above {:.1e}, ten times the \
         reference's accuracy and the f64 rounding floor)",
        if dimension > 1 {
            format!(", about n^(1/{dimension})")
        } else {
            String::new()
        },
        fit_floor(floor),
    );
    let middle = page
        .targets
        .get(page.targets.len() / 2)
        .copied()
        .unwrap_or(1e-6);
    let (mut ranking, mut fits, mut by_time, mut by_n) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..page.rules.len() {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.rule_index == i).collect();
        if mine.is_empty() {
            continue;
        }
        let label = label(page, i);
        let reach = |t: f64| (t >= accuracy).then(|| time_to(&mine, t)).flatten();
        let times: Vec<String> = page
            .targets
            .iter()
            .map(|&t| match (t < accuracy, reach(t)) {
                (true, _) => "below reference accuracy".into(),
                (false, None) => "not reached".into(),
                (false, Some(s)) => format!("{s:.2e}"),
            })
            .collect();
        // A deterministic rule whose error grows with the budget inside the
        // fitted rows (a kink that moves between nodes) has no order either.
        let deterministic = !page.rules.get(i).is_some_and(|r| r.is_random);
        let limit = if deterministic {
            ERRATIC
        } else {
            2.0 * ERRATIC
        };
        let slope = |against| match order_and_scatter(&mine, against, accuracy) {
            None => "—".into(),
            Some((o, off, grew)) if off > limit || (deterministic && grew) => format!(
                "{o:.2} (erratic: errors up to {}x off the line{}, not an order)",
                if off < 1e4 {
                    format!("{off:.1}")
                } else {
                    format!("{off:.1e}")
                },
                if deterministic && grew {
                    ", growing with n"
                } else {
                    ""
                }
            ),
            Some((o, _, _)) => format!("{o:.2}"),
        };
        fits.push(Fit {
            label: label.clone(),
            slope_budget: slope(Against::Resolution {
                dimension,
                by_budget: page.rules.get(i).and_then(|r| r.resolution.get(&dimension)),
            }),
            slope_evaluations: slope(Against::Evaluations),
            times,
        });
        let first = mine
            .iter()
            .filter(|r| !r.rel_error.is_nan())
            .min_by_key(|r| r.budget);
        ranking.push(Ranked {
            label: label.clone(),
            seconds: reach(middle),
            // At the floor from the first budget, deterministic or random
            // (a random rule whose every sample agrees sees a constant
            // integrand), unless the value underflowed: 0 against 0 is not
            // an easy integrand but one f64 cannot hold.
            exact_from_start: first.is_some_and(|r| {
                r.rel_error <= floor.max(1e-14) && !r.flags.contains(&RowFlag::Job(Flag::Underflow))
            }),
        });
        // NaN (failed) rows are dropped; the plot puts unresolved errors on
        // its floor line.
        // An underflowed row (0 against a reference that also reads 0) is
        // not an error at the floor: it is dropped like a failed one, and
        // the rows and the log-space quantity (`ln_tau`) say why.
        let err = |r: &&Row| {
            if r.flags.contains(&RowFlag::Job(Flag::Underflow)) {
                f64::NAN
            } else {
                r.rel_error
            }
        };
        by_time.push((
            label.clone(),
            mine.iter().map(|r| (r.seconds.max(1e-9), err(r))).collect(),
        ));
        by_n.push((
            label,
            mine.iter()
                .map(|r| (r.evaluations.max(1.0), err(r)))
                .collect(),
        ));
    }
    let base = format!("{}-{q}", page.name);
    let mut plots = Vec::new();
    let drawn = [
        ("time", "time", "median run time (s)", by_time),
        ("evaluations", "n", "evaluations", by_n),
    ];
    for (what, suffix, x_label, series) in drawn {
        let title = format!("{}: {q} error against {what}", page.name);
        if let Some(text) = plot::svg(&title, x_label, &series, floor)? {
            plots.push((what, format!("{base}-{suffix}.svg"), text));
        }
    }
    // A reference of 0 that the rows' values underflow to is not 0.
    let reference = if rows
        .iter()
        .any(|r| r.flags.contains(&RowFlag::Job(Flag::Underflow)))
        && page
            .reference
            .values
            .get(q)
            .is_some_and(|v| v.iter().all(|&x| x == 0.0))
    {
        format!("{reference}: the true value underflows f64; its logarithm is exact (ln_tau)")
    } else {
        reference
    };
    Ok(Section {
        quantity: q,
        reference: Ok(reference),
        rows,
        slope_heading,
        fits,
        plots,
        ranking,
        pictures: Vec::new(),
    })
}

/// A CSV line per job and quantity (a channel vector as `;`-separated numbers).
fn csv(results: &[JobResult]) -> String {
    let mut csv = String::from(
        "experiment,rule_index,rule,budget,repeat,seed,quantity,value,estimated_error,evaluations,seconds,failure\n",
    );
    let join = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:e}"))
            .collect::<Vec<_>>()
            .join(";")
    };
    for r in results {
        let lead = format!(
            "{},{},{},{},{},{}",
            field(&r.experiment),
            r.rule_index,
            field(&r.rule),
            r.budget,
            r.repeat,
            r.seed
        );
        let failure = field(r.failure.as_deref().unwrap_or(""));
        if r.quantities.is_empty() {
            let why = if failure.is_empty() {
                "no value"
            } else {
                &failure
            };
            let _ = writeln!(csv, "{lead},,,,,{:e},{why}", r.seconds);
        }
        for (q, m) in &r.quantities {
            let _ = writeln!(
                csv,
                "{lead},{},{},{},{},{:e},{failure}",
                field(q),
                join(&m.value),
                join(&m.error),
                m.evaluations,
                r.seconds
            );
        }
    }
    csv
}

/// A CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

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
        "Every experiment, and per quantity the rules ranked by the time they need to reach the middle target relative error (1e-6 unless the experiment says otherwise); `not reached` means no budget got there.\n\n",
    );
    for (name, description, summary) in entries {
        let _ = writeln!(
            md,
            "## [{name}]({name}/report.md)\n\n{}\n",
            super::markdown::plain(description)
        );
        for (q, ranking) in summary {
            let ranking = ranked(ranking);
            let ranks = ranks(&ranking);
            let list: Vec<String> = ranking
                .iter()
                .enumerate()
                .map(|(i, r)| {
                    let mut exact = String::new();
                    if i > 0 && ranks[i] == ranks[i - 1] {
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
            let _ = writeln!(md, "- {q}: {}", list.join(", "));
        }
        md.push('\n');
    }
    if !earlier.is_empty() {
        let links: Vec<String> = earlier
            .iter()
            .map(|name| format!("[{name}]({name}/report.md)"))
            .collect();
        let _ = writeln!(md, "{}: {}.\n", super::html::EARLIER, links.join(", "));
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
    super::html::write_index(out, entries, crosscheck, audits, problems, earlier)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule(label: &str, seconds: Option<f64>) -> Ranked {
        Ranked {
            label: label.into(),
            seconds,
            exact_from_start: false,
        }
    }

    /// Times within 25% of the one before share its rank; a gap of more
    /// starts a new rank at the position; rules that did not reach the
    /// target are never tied.
    #[test]
    fn times_within_timing_noise_share_a_rank() {
        let r = ranked(&[
            rule("d", None),
            rule("c", Some(2.0e-6)),
            rule("b", Some(5.7e-7)),
            rule("a", Some(5.6e-7)),
            rule("e", None),
        ]);
        let labels: Vec<&str> = r.iter().map(|x| x.label.as_str()).collect();
        assert_eq!(labels, ["a", "b", "c", "d", "e"]);
        assert_eq!(ranks(&r), [1, 1, 3, 4, 5]);
    }

    /// An estimate of 8.2e-3 beside a true error of 1.8e-16 (the trapezoid
    /// on v-b-background-blobs at the rounding floor; the second independent
    /// check) was not flagged: too large is judged against an error of at
    /// least 1e-12. Too small stays judged from 1e-13.
    #[test]
    fn an_estimate_far_above_an_error_at_the_floor_is_flagged() {
        let judged = |error: f64, estimate: f64| {
            judge_estimate(&[], &[1.0], error, estimate, false) == Some(RowFlag::EstimateOff)
        };
        assert!(judged(1.8e-16, 8.2e-3));
        assert!(judged(0.0, 1.1e-11));
        assert!(!judged(1.8e-16, 9e-12));
        assert!(!judged(2e-14, 2e-13));
        assert!(judged(1e-12, 1.1e-11) && !judged(1e-12, 9e-12));
        assert!(judged(1e-12, 9e-14) && !judged(5e-14, 1e-16));
    }

    fn row(budget: usize, rel_error: f64, seconds: f64) -> Row {
        Row {
            rule_index: 0,
            budget,
            value: vec![1.0],
            rel_error,
            rel_estimate: rel_error,
            max_error: rel_error,
            display_off: None,
            evaluations: budget as f64,
            seconds,
            flags: Vec::new(),
        }
    }

    /// Gauss–Legendre on r-sphere-below-horizon (the independent check of
    /// session 22): 3.2e-7 at n = 1024 by a lucky cancellation, then 5.7e-6
    /// and 1.65e-6, below 1e-6 only from 65536 on. Its time to 1e-6 is the
    /// time at 65536, not the dip's.
    #[test]
    fn a_lucky_dip_below_the_target_is_not_the_time_to_it() {
        let rows = [
            row(256, 3e-5, 1e-5),
            row(1024, 3.2e-7, 2.5e-4),
            row(4096, 5.7e-6, 1e-3),
            row(16384, 1.65e-6, 5e-3),
            row(65536, 2e-7, 2e-2),
            row(262144, 5e-8, 8e-2),
        ];
        let refs: Vec<&Row> = rows.iter().collect();
        assert_eq!(time_to(&refs, 1e-6), Some(2e-2));
        assert_eq!(time_to(&refs, 1e-4), Some(1e-5));
        assert_eq!(time_to(&refs, 1e-8), None);
        // The largest budget missing the target: not reached, whatever
        // came before.
        let dip = [row(16, 1e-9, 1e-6), row(64, 1e-3, 4e-6)];
        let refs: Vec<&Row> = dip.iter().collect();
        assert_eq!(time_to(&refs, 1e-6), None);
    }
}

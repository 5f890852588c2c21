//! `summary.json`: what a report page shows, for a program to read. One per
//! experiment beside its `results.jsonl`, and one for the whole report
//! beside `index.md` (every experiment's, in the index's order). Its JSON
//! Schema is `lightquad schema --summary`.
//!
//! Per quantity and rule: the reference with its accuracy; per budget the
//! RMS true error, the estimate, the evaluations and the median time with
//! its interval; the fitted slopes with their intervals; per target the
//! time reached (with its interval) or an extrapolation marked as such; the
//! rank at the middle target and whether it is tied; the flags. Numbers
//! that are not finite (a failed row's error, an infinite estimate) are
//! written as `null`.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::fitted::{Reach, Slope};
use super::ranking::{ranked, ranks, shares_rank};
use super::rows::{Row, RowFlag};
use super::section::Section;
use super::{Page, label};
use crate::experiment::timing::TimeInterval;
use crate::family::Flag;

/// The version of the summary's format; a change that a reader written for
/// an older one would misread raises it.
pub const SUMMARY_VERSION: u32 = 1;

/// A `summary.json`: the whole report's (`<out>/summary.json`, every
/// experiment) or one experiment's (`<out>/<name>/summary.json`, that one),
/// in one shape.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ReportSummary {
    /// The format's version: readers check it (this build writes 1).
    pub summary_version: u32,
    /// The lightquad version that wrote it.
    pub lightquad: String,
    /// The experiments it covers, in the index's order.
    pub experiments: Vec<ExperimentSummary>,
}

impl ReportSummary {
    /// A summary of `experiments`, written by this build.
    pub fn of(experiments: Vec<ExperimentSummary>) -> Self {
        ReportSummary {
            summary_version: SUMMARY_VERSION,
            lightquad: env!("CARGO_PKG_VERSION").to_string(),
            experiments,
        }
    }
}

/// The summary of one experiment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExperimentSummary {
    /// The experiment's name.
    pub experiment: String,
    /// Its family.
    pub family: String,
    /// FNV-1a hash of the experiment file's bytes, as in results.jsonl.
    pub experiment_hash: String,
    /// Budgets, ascending.
    pub budgets: Vec<usize>,
    /// What a budget counts.
    pub budget_unit: String,
    /// Repeats per (rule, budget).
    pub repeats: usize,
    /// Target relative errors.
    pub targets: Vec<f64>,
    /// The target the rules are ranked by (the middle one).
    pub ranked_at: f64,
    /// The quantities, in the file's order.
    pub quantities: Vec<QuantitySummary>,
}

/// One quantity of an experiment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct QuantitySummary {
    /// Its name.
    pub quantity: String,
    /// Its dimension (a budget of n is about n^(1/D) nodes per axis).
    pub dimension: usize,
    /// The reference, or null with `no_reference` saying why (then `rules`
    /// is empty: no true error can be computed).
    pub reference: Option<ReferenceSummary>,
    /// Why there is no reference, where there is none.
    pub no_reference: Option<String>,
    /// The rules, in the file's order.
    pub rules: Vec<RuleSummary>,
}

/// A quantity's reference value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSummary {
    /// Per channel.
    pub value: Vec<Option<f64>>,
    /// Its relative accuracy (0: exact to rounding, or unknown; null: not
    /// finite, as a stated uncertainty far above the value makes it).
    pub accuracy: Option<f64>,
    /// Where the reference comes from, in a sentence.
    pub source: String,
}

/// One rule of a quantity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RuleSummary {
    /// Index in the file's `rules`.
    pub rule_index: usize,
    /// Its label as the report shows it.
    pub label: String,
    /// Randomised (its estimate is a standard error).
    pub random: bool,
    /// A row per budget it ran at, ascending.
    pub rows: Vec<RowSummary>,
    /// The fitted slope against the resolution per axis a budget buys
    /// (order p shows as -p); null with fewer than three rows above the
    /// error floor.
    pub resolution_slope: Option<Slope>,
    /// The fitted slope against evaluations.
    pub evaluations_slope: Option<Slope>,
    /// Per target, in `targets`' order.
    pub targets: Vec<TargetSummary>,
    /// Rank by time to `ranked_at` (1 fastest); null where the rule did not
    /// reach it (out of budget, or every job failed) or has no rows.
    pub rank: Option<usize>,
    /// Shares its rank with the rule ranked before it: their times'
    /// confidence intervals overlap.
    pub tied: bool,
    /// Its error is at or below the floor no order is fitted under (1e-12, or
    /// ten times the reference's accuracy) from its smallest budget on: the
    /// rank says little about it in general.
    pub exact_from_start: bool,
}

/// One rule at one budget, over its repeats.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RowSummary {
    /// The budget.
    pub budget: usize,
    /// Mean value over repeats, per channel.
    pub value: Vec<Option<f64>>,
    /// Root-mean-square true error over repeats and channels, relative to the
    /// reference's root mean square (absolute where that is 0).
    pub rel_error: Option<f64>,
    /// Mean of the rule's own error estimate, same scale.
    pub rel_estimate: Option<f64>,
    /// The largest error of any channel in any repeat, same scale.
    pub max_error: Option<f64>,
    /// Mean evaluations (null where every job of the row failed).
    pub evaluations: Option<f64>,
    /// Median time per call with the median's confidence interval.
    pub seconds: Option<TimeInterval>,
    /// What the row's figures can be trusted for.
    pub flags: Vec<FlagSummary>,
    /// For a random rule with two or more repeats and a reference: the
    /// statistical verdict on its bias and error bars.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verdict: Option<VerdictSummary>,
}

fn one() -> f64 {
    1.0
}

/// The tests of a random rule at one budget
/// ([`crate::experiment::report::verdict`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VerdictSummary {
    /// One of: consistent, biased, se-too-small, se-too-large, se-in-doubt,
    /// no-se, too-few-repeats.
    pub verdict: String,
    /// The level each test was made at (α Šidák-corrected over the rule's
    /// budgets and channels).
    pub level: f64,
    /// The bias test's smallest p-value over the channels.
    pub p_bias: f64,
    /// The error-bar test's smallest p-value, where standard errors were given.
    pub p_se: Option<f64>,
    /// The spread of the values over the root mean square standard error
    /// (1 for honest error bars; null where infinite or none given).
    pub se_ratio: Option<f64>,
    /// Repeats within 1.96 standard errors of the reference, and those judged.
    pub covered: [usize; 2],
    /// The coverage's Wilson 95% interval.
    pub coverage: Option<[f64; 2]>,
    /// The coverage's one-sided binomial p-value against 95% error bars,
    /// the smallest over the channels (1 where no standard error is given).
    #[serde(default = "one")]
    pub p_coverage: f64,
    /// Repeats whose standard error the method itself doubted (a variance
    /// carried by a few samples, samples or walks all alike); where any is,
    /// `verdict` weighs the coverage ([`crate::experiment::report::verdict::Judged::in_doubt`]).
    #[serde(default)]
    pub doubted: usize,
}

/// A flag on a row: a code to match on and the sentence the report shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FlagSummary {
    /// One of: failed, non-finite, outside-standard-errors, estimate-off,
    /// error-grew, at-reference-accuracy, no-estimate, error-beyond-range,
    /// underflow, cancellation, unreliable-estimate, all-walks-alike,
    /// heavy-walks, all-nodes-alike.
    pub kind: String,
    /// As the report says it.
    pub text: String,
}

/// A rule against one target.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TargetSummary {
    /// The target relative error.
    pub target: f64,
    /// Reached, not reached (with an extrapolation where the order allows)
    /// or below the reference's accuracy.
    #[serde(flatten)]
    pub reach: Reach,
}

/// A finite number, or none.
fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

impl RowFlag {
    /// The flag's code in `summary.json`.
    pub fn kind(&self) -> &'static str {
        match self {
            RowFlag::Failed { .. } => "failed",
            RowFlag::NonFinite => "non-finite",
            RowFlag::OutsideStandardErrors => "outside-standard-errors",
            RowFlag::EstimateOff => "estimate-off",
            RowFlag::ErrorGrew => "error-grew",
            RowFlag::AtReferenceAccuracy(_) => "at-reference-accuracy",
            RowFlag::NoEstimate => "no-estimate",
            RowFlag::ErrorBeyondRange => "error-beyond-range",
            RowFlag::Job(f) => match f {
                Flag::Underflow => "underflow",
                Flag::Cancellation { .. } => "cancellation",
                Flag::UnreliableEstimate => "unreliable-estimate",
                Flag::AllWalksAlike { .. } => "all-walks-alike",
                Flag::HeavyWalks { .. } => "heavy-walks",
                Flag::AllNodesAlike { .. } => "all-nodes-alike",
            },
        }
    }
}

impl From<&Row> for RowSummary {
    fn from(r: &Row) -> Self {
        RowSummary {
            budget: r.budget,
            value: r.value.iter().map(|&v| finite(v)).collect(),
            rel_error: finite(r.rel_error),
            rel_estimate: finite(r.rel_estimate),
            max_error: finite(r.max_error),
            evaluations: finite(r.evaluations),
            seconds: r.time,
            flags: r
                .flags
                .iter()
                .map(|f| FlagSummary {
                    kind: f.kind().into(),
                    text: f.to_string(),
                })
                .collect(),
            verdict: None,
        }
    }
}

/// The summary of an experiment from its page and sections.
pub fn experiment_summary(page: &Page, sections: &[Section]) -> ExperimentSummary {
    ExperimentSummary {
        experiment: page.name.to_string(),
        family: page.family.to_string(),
        experiment_hash: page.hash.to_string(),
        budgets: page.budgets.to_vec(),
        budget_unit: page.budget_unit.to_string(),
        repeats: page.repeats,
        targets: page.targets.to_vec(),
        ranked_at: page.middle_target(),
        quantities: sections
            .iter()
            .enumerate()
            .map(|(i, s)| quantity(page, i, s))
            .collect(),
    }
}

/// One quantity's summary.
fn quantity(page: &Page, i: usize, s: &Section) -> QuantitySummary {
    let q = s.quantity;
    let reference = match (&s.reference, page.reference.values.get(q)) {
        (Ok(_), Some(v)) => Some(ReferenceSummary {
            value: v.iter().map(|&x| finite(x)).collect(),
            accuracy: finite(page.reference.accuracy_of(q)),
            source: page.reference.note.clone(),
        }),
        _ => None,
    };
    // Ranks by label, as the index ranks them.
    let order = ranked(&s.ranking);
    let all = ranks(&order);
    let rank_of: BTreeMap<&str, (Option<usize>, bool)> = order
        .iter()
        .enumerate()
        .map(|(k, r)| (r.label.as_str(), (all[k], shares_rank(&all, k))))
        .collect();
    let rules = s
        .fits
        .iter()
        .map(|f| {
            let judged = s.verdicts.iter().find(|v| v.rule_index == f.rule_index);
            let rows: Vec<RowSummary> = s
                .rows
                .iter()
                .filter(|r| r.rule_index == f.rule_index)
                .map(|r| {
                    let mut row = RowSummary::from(r);
                    row.verdict = judged.and_then(|v| {
                        let (_, j) = v.budgets.iter().find(|(b, _)| *b == r.budget)?;
                        Some(VerdictSummary {
                            verdict: serde_json::to_value(j.verdict).ok()?.as_str()?.to_string(),
                            level: v.level,
                            p_bias: j.p_bias,
                            p_se: j.p_se,
                            se_ratio: j.se_ratio.and_then(finite),
                            covered: j.covered,
                            coverage: j.coverage,
                            p_coverage: j.p_coverage,
                            doubted: j.doubted,
                        })
                    });
                    row
                })
                .collect();
            let (rank, tied) = rank_of
                .get(f.label.as_str())
                .map_or((None, false), |&(r, t)| (r, t));
            RuleSummary {
                rule_index: f.rule_index,
                label: label(page, f.rule_index),
                random: page.rules.get(f.rule_index).is_some_and(|r| r.is_random),
                rows,
                resolution_slope: f.resolution_slope,
                evaluations_slope: f.evaluations_slope,
                targets: page
                    .targets
                    .iter()
                    .zip(&f.reach)
                    .map(|(&target, reach)| TargetSummary {
                        target,
                        reach: reach.clone(),
                    })
                    .collect(),
                rank,
                tied,
                exact_from_start: s
                    .ranking
                    .iter()
                    .any(|r| r.label == f.label && r.exact_from_start),
            }
        })
        .collect();
    QuantitySummary {
        quantity: q.to_string(),
        dimension: page.dimensions.get(i).copied().unwrap_or(1),
        no_reference: s.reference.as_ref().err().cloned(),
        reference,
        rules,
    }
}

/// The JSON Schema of every `summary.json`.
pub fn schema() -> schemars::Schema {
    schemars::schema_for!(ReportSummary)
}

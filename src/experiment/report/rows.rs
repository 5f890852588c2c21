//! The rows of a report table: per rule and budget, the repeats' values,
//! true and estimated errors, evaluations and time, and the flags that say
//! what a row's figures can be trusted for.

use std::collections::BTreeMap;

use super::RuleInfo;
use crate::experiment::reference::rms;
use crate::experiment::run::JobResult;
use crate::experiment::timing::TimeInterval;
use crate::family::{Display, Flag, Measured};

/// A fact about a row of a report table.
#[derive(Debug, Clone, PartialEq)]
pub enum RowFlag {
    /// Jobs of the row failed: the first one's reason, and how many of the
    /// row's repeats failed.
    Failed {
        /// The first failed job's reason.
        why: String,
        /// The repeats that failed.
        failed: usize,
        /// The row's repeats.
        of: usize,
    },
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
    /// The method's error estimate is infinite: it had none to give (the
    /// estimate switched off, too few nodes or cells for one, an external
    /// estimator that sends none), or the estimate passed the f64 range
    /// (values near 1.8e308).
    NoEstimate,
    /// The true relative error is beyond the f64 range though value and
    /// reference are finite: the reference is too small to divide by (a
    /// literal reference of 5e-324 showed an error of inf, unflagged).
    ErrorBeyondRange,
}

/// "failed", with how many of the row's repeats failed where it had more
/// than one: "failed in 1 of 2 repeats".
pub fn failed_in(failed: usize, of: usize) -> String {
    if of > 1 {
        format!("failed in {failed} of {of} repeats")
    } else {
        "failed".to_string()
    }
}

impl std::fmt::Display for RowFlag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RowFlag::Failed { why, failed, of } => write!(f, "{}: {why}", failed_in(*failed, *of)),
            RowFlag::NonFinite => write!(f, "non-finite value"),
            RowFlag::Job(flag) => write!(f, "{flag}"),
            RowFlag::OutsideStandardErrors => write!(f, "outside 4 standard errors"),
            RowFlag::EstimateOff => write!(f, "estimate off by more than 10x"),
            RowFlag::ErrorGrew => write!(f, "error grew with the budget"),
            RowFlag::AtReferenceAccuracy(a) => write!(f, "at the reference's accuracy ({a:.1e})"),
            RowFlag::NoEstimate => write!(
                f,
                "no error estimate (infinite: the method gave none, as with the estimate \
                 switched off, too few nodes or cells, or an external estimator without one; \
                 or its estimate passed the f64 range)"
            ),
            RowFlag::ErrorBeyondRange => write!(
                f,
                "relative error beyond the f64 range (the reference is too small to divide by)"
            ),
        }
    }
}

/// The legend of the flags (Markdown), below every page.
pub const FLAG_LEGEND: &str = "Flags: `failed` (with more than one repeat, `failed in K of N repeats`; the first failed job's reason follows); `non-finite value`; \
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
and `ln I_B = ln B + ln tau`); `no error estimate` (the method gave none: its estimate switched off, too few nodes or cells \
(Gauss–Legendre at one node, stratified sampling on two cells), an external estimator without \
one; or its estimate passed the f64 range); `at the reference's accuracy` (the error is not resolved by the reference); `all N walks \
scored alike` (a tracking estimate with zero sample variance: its error is a Wilson half-width \
/ 1.96, not a sample standard error); `N walks carried by a few` (a tracking estimate whose \
scores' sample variance is carried by a few walks, as the mean of a product of many factors is: \
the mean rests on walks not yet seen, and the standard error can be orders of magnitude too \
small); `every one of N nodes gave the same value` (a deterministic rule whose error estimate \
is 0 because every node saw the same value, as where no node saw a small light: the 0 says \
nothing of what lies between them; a constant integrand is flagged too, truly).";

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
    /// Mean evaluations (NaN where every job of the row failed: none were
    /// counted).
    pub evaluations: f64,
    /// Lower median wall time per call, seconds: `time`'s median (NaN
    /// where every job of the row failed).
    pub seconds: f64,
    /// The median's confidence interval over the repeats' times (None: no
    /// time was read).
    pub time: Option<TimeInterval>,
    /// Stability flags.
    pub flags: Vec<RowFlag>,
}

/// Relative errors below this are at the f64 rounding floor: no order is
/// fitted through them and no estimate is judged against them.
pub(super) const FLOOR: f64 = 1e-14;

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
    // A job below the rule's minimum for `q` did not compute it, whatever
    // became of the job.
    let computes_q = |r: &JobResult| {
        rules
            .get(r.rule_index)
            .is_none_or(|rule| r.budget >= rule.min_budget_of(q))
    };
    for r in results.iter().filter(|r| computes_q(r)) {
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

/// The factors a difference of `numbers` is taken with, `(halve, double)`:
/// near the top of the range the halves are subtracted and the result
/// doubled (exact for normal numbers): 1.7e308 against -1.7e308 overflowed
/// to an error of inf. `(1, 1)` otherwise.
pub(super) fn halving<'a>(mut numbers: impl Iterator<Item = &'a f64>) -> (f64, f64) {
    if numbers.any(|x| x.abs() > f64::MAX / 2.0) {
        (0.5, 2.0)
    } else {
        (1.0, 1.0)
    }
}

/// The scale of a quantity's relative errors: the reference's root mean
/// square, or 1 (absolute errors) where that is 0.
pub(super) fn scale_of(reference: &[f64]) -> f64 {
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
    if let Some(why) = jobs.iter().find_map(|j| j.failure.clone()) {
        let failed = jobs.iter().filter(|j| j.failure.is_some()).count();
        flags.push(RowFlag::Failed {
            why,
            failed,
            of: jobs.len(),
        });
    }
    // A sample per finished repeat: the quantity's own time where the job
    // timed it alone, the job's otherwise (older results files). The
    // repeats ran at different moments of the run, so their spread holds
    // the machine's changing load; a job's batches, run back to back, do
    // not (GL at n = 16 on calibration-exp: batches within 3% of each other
    // in each repeat, 0.92 and 1.43 us between two repeats). The lower
    // median: of two samples the faster, as the first pays for cold caches.
    // A failed job's time is not a time of this row's work (an external
    // program's failure took none): only finished jobs count.
    let samples: Vec<f64> = jobs
        .iter()
        .filter(|j| j.failure.is_none())
        .map(|j| {
            j.quantities
                .get(q)
                .and_then(|m| m.seconds)
                .unwrap_or(j.seconds)
        })
        .collect();
    let time = TimeInterval::of(&samples);
    let seconds = time.map_or(f64::NAN, |t| t.median);
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
            evaluations: f64::NAN,
            seconds,
            time,
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
    // True error: the root mean square over repeats and channels.
    let (halve, double) = halving(
        reference
            .iter()
            .chain(measured.iter().flat_map(|m| &m.value)),
    );
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
        time,
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

#[cfg(test)]
mod tests {
    use super::*;

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
}

//! The converged reference: the family's most accurate deterministic
//! evaluation at `n` nodes, checked against twice as many, doubling until
//! it settles.

use std::collections::BTreeMap;

use crate::error::SpecError;
use crate::experiment::validate::Experiment;
use crate::experiment::validate::{MAX_JOB_BYTES, MAX_JOB_EVALUATIONS, cost_limit_lifted};
use crate::family::{Family, Measured, Quantity};

use super::{Reference, names, relative_distance, rms};

/// The largest `n` of a converged reference.
pub const MAX_CONVERGED_N: usize = 100_000;

/// Checks a converged reference's `n`: an integer in `2..=MAX_CONVERGED_N`.
pub fn check_converged_n(n: usize) -> Result<(), SpecError> {
    if (2..=MAX_CONVERGED_N).contains(&n) {
        Ok(())
    } else {
        Err(SpecError::at(
            "reference.n",
            format!("{n} is not an integer in 2..={MAX_CONVERGED_N}"),
        ))
    }
}

/// The family's converged values of every quantity of the experiment with
/// `n` nodes per piece.
pub fn converged<F: Family>(
    exp: &Experiment<F>,
    n: usize,
) -> Result<BTreeMap<F::Quantity, Vec<f64>>, String> {
    converged_measured(exp, n).map(|out| out.into_iter().map(|(q, m)| (q, m.value)).collect())
}

/// The family's converged evaluation with its error estimates.
pub(super) fn converged_measured<F: Family>(
    exp: &Experiment<F>,
    n: usize,
) -> Result<BTreeMap<F::Quantity, Measured>, String> {
    F::converged(&exp.scene, n, &exp.spec.quantities).map_err(|e| e.to_string())
}

/// The tightest relative change the converged reference asks for: the
/// evaluation's own rounding (sums of thousands of terms, each with a
/// relative error near 1e-16) leaves changes near 1e-14, so a goal below
/// this would never be met; errors under it are flagged as at the
/// reference's accuracy, and the note says when the floor was used.
pub const CONVERGED_FLOOR: f64 = 1e-13;

/// Doublings of `n` the converged reference may take past the spec's `n`.
const MAX_DOUBLINGS: u32 = 6;

/// The evaluations an evaluation of every quantity made.
fn evaluations<Q>(out: &BTreeMap<Q, Measured>) -> f64 {
    out.values().map(|m| m.evaluations as f64).sum()
}

/// Why the converged reference stops doubling after its evaluation at `m`
/// (`last` evaluations; `spent` in all so far), if it must: the next, at
/// `2m`, priced as `last` times the growth of [`Family::converged_cost`]
/// from `m` to `2m`, would take the reference past [`MAX_JOB_EVALUATIONS`]
/// in all, or hold more than [`MAX_JOB_BYTES`] at once: the limits of a
/// job. `--no-cost-limit` lifts them. (A scene that never settled doubled
/// six times, each evaluation dearer, at costs no check had seen.)
fn too_dear<F: Family>(exp: &Experiment<F>, m: usize, spent: f64, last: f64) -> Option<String> {
    if cost_limit_lifted() {
        return None;
    }
    let next = m.saturating_mul(2);
    let [now, _] = F::converged_cost(&exp.scene, m, &exp.spec.quantities);
    let [then, bytes] = F::converged_cost(&exp.scene, next, &exp.spec.quantities);
    let growth = (then / now).clamp(2.0, 16.0);
    let growth = if growth.is_nan() { 2.0 } else { growth };
    let cost = last * growth;
    let why = if spent + cost > MAX_JOB_EVALUATIONS {
        format!(
            "about {:.1e} integrand evaluations in all, beyond the {MAX_JOB_EVALUATIONS:.0e} \
             a job may make",
            spent + cost
        )
    } else if bytes.is_nan() || bytes > MAX_JOB_BYTES {
        format!(
            "about {:.1} GB at once, beyond the {:.1} GB a job may hold",
            bytes / 1e9,
            MAX_JOB_BYTES / 1e9
        )
    } else {
        return None;
    };
    Some(format!(
        "it stopped doubling at n = {m}: the next evaluation, at n = {next}, would take {why} \
         (pass --no-cost-limit to run it)"
    ))
}

/// Each quantity's relative change from `coarse` to `fine`, or the finer
/// evaluation's own relative error estimate where that is larger (an
/// adaptive rule that met its tolerance twice changes by nothing).
fn changes_between<F: Family>(
    exp: &Experiment<F>,
    coarse: &BTreeMap<F::Quantity, Measured>,
    fine: &BTreeMap<F::Quantity, Measured>,
) -> BTreeMap<String, f64> {
    exp.spec
        .quantities
        .iter()
        .filter_map(|q| {
            let (x, y) = (coarse.get(q)?, fine.get(q)?);
            let change = relative_distance(&x.value, &y.value);
            let size = rms(y.value.iter().copied());
            let own = rms(y.error.iter().copied()) / size;
            let own = if own.is_finite() && size > 0.0 {
                own
            } else {
                0.0
            };
            Some((q.name().to_string(), change.max(own)))
        })
        .collect()
}

/// Each channel's absolute change from `coarse` to `fine` or the finer
/// evaluation's own error estimate, the larger, never below the rounding
/// floor [`CONVERGED_FLOOR`] of its value (as the whole quantity's): a
/// background channel of 0.1 every ray sees alike changed by 0, yet the
/// rules' weights summed it to 0.09999999999999999, a display step below
/// the reference's 25.5.
fn per_channel_changes<F: Family>(
    exp: &Experiment<F>,
    coarse: &BTreeMap<F::Quantity, Measured>,
    fine: &BTreeMap<F::Quantity, Measured>,
) -> BTreeMap<String, Vec<f64>> {
    exp.spec
        .quantities
        .iter()
        .filter_map(|q| {
            let (x, y) = (coarse.get(q)?, fine.get(q)?);
            let each = (0..y.value.len())
                .map(|c| {
                    let change = match x.value.get(c) {
                        Some(&a) => (a - y.value[c]).abs(),
                        None => f64::NAN,
                    };
                    let own = y.error.get(c).copied().filter(|e| e.is_finite());
                    own.map_or(change, |e| change.max(e.abs()))
                        .max(CONVERGED_FLOOR * y.value[c].abs())
                })
                .collect();
            Some((q.name().to_string(), each))
        })
        .collect()
}

/// The converged reference: the family's converged evaluation at `n`, `2n`,
/// `4n`, ... nodes per piece until every quantity's relative change from one
/// to the next is at most `goal` (a hundredth of the tightest target, but not
/// below [`CONVERGED_FLOOR`]) or `n` has doubled [`MAX_DOUBLINGS`] times, or
/// the next doubling would pass a job's limits ([`too_dear`]) or fails (a
/// family's own limit), said in the note. Each quantity
/// keeps the finest value and, as its accuracy, its own last change (at
/// least [`CONVERGED_FLOOR`], the evaluation's own rounding); one that
/// did not get below the goal is named in the note. A quantity the family
/// could not compute, or whose value is not finite, has no reference.
pub(super) fn converged_reference<F: Family>(exp: &Experiment<F>, n: usize) -> Reference {
    let tightest = exp
        .spec
        .targets
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let goal = (tightest / 100.0).max(CONVERGED_FLOOR);
    let failed = |e: String| {
        let why = format!("the converged evaluation failed: {e}");
        Reference {
            values: BTreeMap::new(),
            missing: names::<F>(exp, &why),
            note: format!("none: {why}."),
            accuracy: BTreeMap::new(),
            channel_accuracy: BTreeMap::new(),
            unverified: Vec::new(),
        }
    };
    let (mut coarse, mut fine) = match (converged_measured(exp, n), converged_measured(exp, 2 * n))
    {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => return failed(e),
    };
    let mut m = 2 * n;
    let mut spent = evaluations(&coarse) + evaluations(&fine);
    let mut stopped = None;
    let changes = loop {
        let changes = changes_between::<F>(exp, &coarse, &fine);
        if changes.values().all(|c| *c <= goal) || m >= n << MAX_DOUBLINGS {
            break changes;
        }
        stopped = too_dear::<F>(exp, m, spent, evaluations(&fine));
        if stopped.is_some() {
            break changes;
        }
        // A reference that goes on doubling says so, or a long one looks
        // like a hang.
        let largest = changes.values().copied().fold(0.0, f64::max);
        crate::say!(
            "{}: the converged reference changed by {largest:.1e} from n = {} to {m} (goal \
             {}): doubling to n = {}",
            exp.spec.name,
            m / 2,
            three_digits(goal),
            m * 2
        );
        // An evaluation past the first two that fails (a family's own
        // limit on its cost) ends the doubling; the last two stand.
        match converged_measured(exp, 2 * m) {
            Ok(next) => {
                spent += evaluations(&next);
                coarse = std::mem::replace(&mut fine, next);
                m *= 2;
            }
            Err(e) => {
                stopped = Some(format!(
                    "it stopped doubling at n = {m}: the evaluation at n = {} failed: {e}",
                    2 * m
                ));
                break changes;
            }
        }
    };
    let per_channel = per_channel_changes::<F>(exp, &coarse, &fine);
    let mut values = BTreeMap::new();
    let mut missing = BTreeMap::new();
    let mut accuracy = BTreeMap::new();
    for q in &exp.spec.quantities {
        let name = q.name().to_string();
        match fine.get(q).map(|m| &m.value) {
            Some(y) if y.iter().all(|v| v.is_finite()) => {
                values.insert(name.clone(), y.clone());
                // Never below the floor: a change of 5.4e-14 on the voxel
                // grid's I_L stood for an error of 7.8e-14 (an independent
                // 40-digit evaluation), rounding that the change cannot see.
                let change = changes.get(&name).copied().unwrap_or(f64::NAN);
                let stated = if change.is_nan() {
                    change
                } else {
                    change.max(CONVERGED_FLOOR)
                };
                accuracy.insert(name, stated);
            }
            Some(y) => {
                missing.insert(name, format!("its converged value {y:?} is not finite"));
            }
            None => {
                missing.insert(
                    name,
                    "the family's converged evaluation did not produce it".into(),
                );
            }
        }
    }
    // A converged evaluation that doubts its own error estimate (across a
    // discontinuity it does not split at, a feature one node carries, a
    // history that contradicts it) is not called converged, whatever its
    // change between budgets.
    let doubted: Vec<String> = exp
        .spec
        .quantities
        .iter()
        .filter(|q| {
            fine.get(q)
                .is_some_and(|m| m.flags.contains(&crate::family::Flag::UnreliableEstimate))
        })
        .map(|q| q.name().to_string())
        .collect();
    let mut unconverged: Vec<String> = accuracy
        .iter()
        .filter(|(q, c)| (c.is_nan() || **c > goal) && !doubted.contains(q))
        .map(|(q, c)| format!("{q} ({c:.1e})"))
        .collect();
    unconverged.extend(doubted.iter().map(|q| {
        format!(
            "{q} (unverified: its evaluation doubts its own error estimate, as across a \
             discontinuity it does not split at, where the change between budgets can \
             understate the error)"
        )
    }));
    let floor = if goal == CONVERGED_FLOOR {
        format!(
            " (the goal: a hundredth of the tightest target, {tightest:e}, but not below \
             {CONVERGED_FLOOR:.0e}, the evaluation's own rounding)"
        )
    } else {
        String::new()
    };
    let stopped = stopped.map_or(String::new(), |why| format!("; {why}"));
    let verdict = if unconverged.is_empty() {
        format!(
            "every quantity converged to {} or better{floor}",
            three_digits(goal)
        )
    } else {
        format!(
            "NOT converged to {}{floor}: {}; errors below that are not \
             resolved{stopped}",
            three_digits(goal),
            unconverged.join(", ")
        )
    };
    let changes_text = accuracy
        .iter()
        .map(|(q, c)| format!("{q} {c:.1e}"))
        .collect::<Vec<_>>()
        .join(", ");
    Reference {
        values,
        missing,
        note: format!(
            "the {} family's converged evaluation at n = {m}; relative change from n = {} \
             (or its own error estimate, where larger): {changes_text} ({verdict}).",
            F::NAME,
            m / 2
        ),
        accuracy,
        channel_accuracy: per_channel,
        unverified: doubted,
    }
}

/// `x` to at most three significant digits, as briefly as it reads:
/// `1e-11`, `2.5e-5` (a hundredth of a target of 2.5e-3), not `1.00e-11`
/// or the quotient's `2.5000000000000002e-5`.
fn three_digits(x: f64) -> String {
    let rounded: f64 = format!("{x:.2e}").parse().unwrap_or(x);
    format!("{rounded:e}")
}

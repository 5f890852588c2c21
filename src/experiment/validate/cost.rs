//! The cost guards: a job's and an experiment's estimated evaluations, bytes
//! and jobs against their limits, refused before anything runs.

use crate::error::SpecError;
use crate::experiment::spec::ExperimentSpec;
use crate::family::Family;

use super::{min_budget, quantities_at, quantity_min_budget};

/// The most integrand evaluations one job may cost by its family's estimate
/// ([`Family::cost`]): 1e11, minutes to hours at a nanosecond or more per
/// evaluation. `run --no-cost-limit` lifts it ([`lift_cost_limit`]).
pub const MAX_JOB_EVALUATIONS: f64 = 1e11;

/// The most bytes one job may hold by its family's estimate
/// ([`Family::memory`]): 4 GiB, so that the default of one job per core fits
/// a machine of 8 GiB a core (Gauss–Legendre at 1e8 nodes needs about 5.6
/// GB). `--no-cost-limit` lifts it too.
pub const MAX_JOB_BYTES: f64 = 4.0 * (1u64 << 30) as f64;

/// The most work a whole experiment may cost by its family's estimates
/// (every rule at every budget it runs, every repeat): 1e12 simple
/// evaluations, hours on a few cores. 300 rules at 185 budgets and 1000
/// repeats passed the per-job guard: 55 million jobs, 3e14 evaluations.
pub const MAX_EXPERIMENT_EVALUATIONS: f64 = 1e12;

/// The most jobs one experiment may have (rules x budgets x repeats).
pub const MAX_JOBS: f64 = 1e6;

/// The most bytes of results one experiment may write, estimated at 400
/// bytes a job and 48 a channel (value and error): 2 GB. An image of
/// 1024 x 1024 pixels wrote 106 MB of results.jsonl for a few jobs.
pub const MAX_RESULTS_BYTES: f64 = 2e9;

static COST_LIMIT_LIFTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Lets experiments whose jobs cost more than [`MAX_JOB_EVALUATIONS`] through
/// (the command line's `--no-cost-limit`), for this process.
pub fn lift_cost_limit() {
    COST_LIMIT_LIFTED.store(true, std::sync::atomic::Ordering::Relaxed);
}

/// Whether `--no-cost-limit` was passed ([`lift_cost_limit`]).
pub fn cost_limit_lifted() -> bool {
    COST_LIMIT_LIFTED.load(std::sync::atomic::Ordering::Relaxed)
}

/// Refuses an experiment whose costliest job (the largest budget each rule
/// runs at, every quantity) would pass [`MAX_JOB_EVALUATIONS`], with the
/// estimate: the nested depth scheme at a budget of 1e6 was accepted and ran
/// for about 22 hours.
pub(super) fn check_cost<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
    budgets: &[usize],
) -> Result<(), SpecError> {
    if cost_limit_lifted() {
        return Ok(());
    }
    if let crate::experiment::spec::ReferenceSpec::Converged(c) = &spec.reference {
        // Its range first: an n beyond it is refused whatever the cost limit
        // (the cost was reported first, and lifting the limit then met the
        // range).
        crate::experiment::reference::check_converged_n(c.n)?;
        check_converged_cost::<F>(scene, c.n, &spec.quantities)?;
    }
    let Some(&largest) = budgets.last() else {
        return Ok(());
    };
    for (i, listed) in spec.rules.iter().enumerate() {
        // An external program's cost is its own: lightquad cannot price it.
        let Some(m) = listed.own() else {
            continue;
        };
        let cost: f64 = spec
            .quantities
            .iter()
            .map(|&q| F::cost(scene, m, largest, q))
            .sum();
        if cost.is_nan() || cost > MAX_JOB_EVALUATIONS {
            // Where even the least budget the rule runs at costs too much,
            // the scene makes the rule too dear (ratio tracking through a
            // blob of amplitude 1e307 collides about that often a walk):
            // lowering the budget, the advice given, could not help. (The
            // experiment's own smallest budget said so of any single budget.)
            // Each quantity at its own minimum: the least any budget list
            // that passes the minimums can cost.
            let least = min_budget::<F>(scene, listed, &spec.quantities);
            let at_least: f64 = spec
                .quantities
                .iter()
                .map(|&q| F::cost(scene, m, quantity_min_budget::<F>(scene, listed, q), q))
                .sum();
            let advice = if at_least.is_nan() || at_least > MAX_JOB_EVALUATIONS {
                format!(
                    "even with each quantity at its smallest budget (from {least}) it costs about \
                     {at_least:.1e}, so this scene makes the \
                     rule too dear at any budget: remove rules[{i}] or change the scene (a \
                     tracking walk through a deep or loose majorant makes many look-ups)"
                )
            } else {
                "lower the budget".to_string()
            };
            return Err(SpecError::at(
                "budgets",
                format!(
                    "a job of rules[{i}] ({}) at budget {largest} costs about {cost:.1e} integrand \
                     evaluations: expected at most {MAX_JOB_EVALUATIONS:.0e} per job ({advice}, \
                     or pass --no-cost-limit to check and run to go ahead)",
                    m.label()
                ),
            ));
        }
        let bytes = spec
            .quantities
            .iter()
            .map(|&q| F::memory(scene, m, largest, q))
            .fold(0.0, f64::max);
        if bytes.is_nan() || bytes > MAX_JOB_BYTES {
            return Err(SpecError::at(
                "budgets",
                format!(
                    "a job of rules[{i}] ({}) at budget {largest} needs about {:.1} GB of memory: \
                     expected at most {:.1} GB per job (lower the budget, or pass --no-cost-limit \
                     to check and run to go ahead)",
                    m.label(),
                    bytes / 1e9,
                    MAX_JOB_BYTES / 1e9
                ),
            ));
        }
    }
    let [jobs, total] = jobs_cost(spec, scene, budgets);
    let channels: f64 = spec
        .quantities
        .iter()
        .map(|&q| F::channels(scene, q) as f64)
        .sum();
    let written = jobs * (400.0 + 48.0 * channels);
    let whole = "rules x budgets x repeats";
    let lower =
        "(fewer rules, budgets or repeats, or pass --no-cost-limit to check and run to go ahead)";
    if total.is_nan() || total > MAX_EXPERIMENT_EVALUATIONS {
        return Err(SpecError::at(
            "budgets",
            format!(
                "the experiment's {jobs:.0} jobs ({whole}) cost about {total:.1e} integrand \
                 evaluations in all: expected at most {MAX_EXPERIMENT_EVALUATIONS:.0e} {lower}"
            ),
        ));
    }
    if jobs > MAX_JOBS {
        return Err(SpecError::at(
            "budgets",
            format!(
                "the experiment has {jobs:.0} jobs ({whole}): expected at most {MAX_JOBS:.0e} {lower}"
            ),
        ));
    }
    if written > MAX_RESULTS_BYTES {
        return Err(SpecError::at(
            "budgets",
            format!(
                "the experiment's {jobs:.0} jobs of {channels:.0} channels each would write about \
                 {:.1} GB of results: expected at most {:.1} GB {lower}",
                written / 1e9,
                MAX_RESULTS_BYTES / 1e9
            ),
        ));
    }
    Ok(())
}

/// Refuses a converged reference at `n` whose first two evaluations (at
/// `n` and `2n`, [`Family::converged_cost`]) pass the job limits, at
/// `reference.n`: later doublings stop before passing them
/// ([`crate::experiment::reference`]), but these two are the least the
/// reference is. A furnace reference at n = 1e5 (Genz–Malik at n^2 a
/// hemisphere) passed `check`, ran every job and then failed for 80 GB.
pub(super) fn check_converged_cost<F: Family>(
    scene: &F::Scene,
    n: usize,
    quantities: &[F::Quantity],
) -> Result<(), SpecError> {
    let [c1, b1] = F::converged_cost(scene, n, quantities);
    let [c2, b2] = F::converged_cost(scene, n.saturating_mul(2), quantities);
    let (cost, bytes) = (c1 + c2, b1.max(b2));
    let lift = "lower n, or pass --no-cost-limit to check and run to go ahead";
    if cost.is_nan() || cost > MAX_JOB_EVALUATIONS {
        return Err(SpecError::at(
            "reference.n",
            format!(
                "the converged reference's first evaluations, at n = {n} and {}, cost up to \
                 about {cost:.1e} integrand evaluations: expected at most \
                 {MAX_JOB_EVALUATIONS:.0e} ({lift})",
                n.saturating_mul(2)
            ),
        ));
    }
    if bytes.is_nan() || bytes > MAX_JOB_BYTES {
        return Err(SpecError::at(
            "reference.n",
            format!(
                "the converged reference's evaluation at n = {} needs about {:.1} GB of memory: \
                 expected at most {:.1} GB ({lift})",
                n.saturating_mul(2),
                bytes / 1e9,
                MAX_JOB_BYTES / 1e9
            ),
        ));
    }
    Ok(())
}

/// Refuses an experiment whose Mitsuba comparison would evaluate lightquad's
/// converged value ([`crate::experiment::reference::CROSSCHECK_N`]) past
/// the job limits, at `scene`: the comparison runs where a values file
/// made from this very file is found, whatever the file's own reference.
pub(super) fn check_crosscheck_cost<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
    hash: &str,
    origin: &crate::experiment::source::Origin,
) -> Result<(), SpecError> {
    use crate::experiment::reference::{CROSSCHECK_N, compares};
    use crate::experiment::spec::{MitsubaReference, ReferenceSpec};
    let named = match &spec.reference {
        ReferenceSpec::Mitsuba(MitsubaReference { file }) => Some(file.as_str()),
        _ => None,
    };
    if cost_limit_lifted() || !compares(origin, &spec.name, hash, named) {
        return Ok(());
    }
    let [cost, bytes] = F::converged_cost(scene, CROSSCHECK_N, &spec.quantities);
    if cost.is_nan() || cost > MAX_JOB_EVALUATIONS || bytes.is_nan() || bytes > MAX_JOB_BYTES {
        return Err(SpecError::at(
            "scene",
            format!(
                "the Mitsuba comparison evaluates lightquad's converged value at n = \
                 {CROSSCHECK_N}, which in this scene costs about {cost:.1e} integrand evaluations \
                 and {:.1} GB: expected at most {MAX_JOB_EVALUATIONS:.0e} and {:.1} GB (pass \
                 --no-cost-limit to check and run to go ahead)",
                bytes / 1e9,
                MAX_JOB_BYTES / 1e9
            ),
        ));
    }
    Ok(())
}

/// The experiment's jobs (every rule at each budget it runs, every repeat)
/// and their evaluations in all, by the family's estimates
/// ([`Family::cost`]).
pub fn jobs_cost<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
    budgets: &[usize],
) -> [f64; 2] {
    let repeats = spec.repeats as f64;
    let (mut jobs, mut total) = (0.0, 0.0);
    for m in &spec.rules {
        let need = min_budget::<F>(scene, m, &spec.quantities);
        for &b in budgets.iter().filter(|&&b| b >= need) {
            jobs += repeats;
            // An external program's work is counted as its budget.
            total += repeats
                * quantities_at::<F>(scene, m, &spec.quantities, b)
                    .into_iter()
                    .map(|q| m.own().map_or(b as f64, |m| F::cost(scene, m, b, q)))
                    .sum::<f64>();
        }
    }
    [jobs, total]
}

/// The evaluations of the reference stage by the family's estimates: a
/// converged reference's first two evaluations (at `n` and `2n`; later
/// doublings stop before [`MAX_JOB_EVALUATIONS`] in all), and lightquad's
/// value for the Mitsuba comparison where it is computed.
pub fn reference_cost<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
    compared: bool,
) -> f64 {
    let converged = match &spec.reference {
        crate::experiment::spec::ReferenceSpec::Converged(c) => {
            F::converged_cost(scene, c.n, &spec.quantities)[0]
                + F::converged_cost(scene, c.n.saturating_mul(2), &spec.quantities)[0]
        }
        _ => 0.0,
    };
    let crosscheck = if compared {
        F::converged_cost(
            scene,
            crate::experiment::reference::CROSSCHECK_N,
            &spec.quantities,
        )[0]
    } else {
        0.0
    };
    converged + crosscheck
}

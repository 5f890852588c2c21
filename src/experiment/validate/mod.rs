//! From a parsed [`ExperimentSpec`] to a runnable [`Experiment`]: every number
//! checked once, here, with the JSON path of the fault in the error. The
//! family checks its scene ([`Family::build`]); this module checks the rest,
//! and that every rule and estimator can compute every quantity asked for.
//! The text's own checks (JSON syntax, numbers beyond f64, the family's
//! format) are in `parse`, the guards on cost and memory in `cost`.
//!
//! ```
//! use lightquad::calibration::Calibration;
//! use lightquad::experiment::validate::{deserialize, parse_json, validate};
//!
//! let text = r#"{"name": "e", "family": "calibration", "scene": {}, "quantities": ["exp"],
//!   "rules": [{"rule": "gauss-legendre"}], "budgets": {"from": 2, "to": 32, "factor": 2},
//!   "reference": {"type": "closed-form"}}"#;
//! let exp = validate::<Calibration>(deserialize(parse_json(text)?)?, "hash")?;
//! // The range expands to its budgets; the closed form e - 1 is known before any run.
//! assert_eq!(exp.budgets, [2, 4, 8, 16, 32]);
//! let known = exp.known.as_ref().ok_or("no reference values")?;
//! let exact = known.values[&exp.spec.quantities[0]][0];
//! assert!((exact - (std::f64::consts::E - 1.0)).abs() < 1e-15);
//! // A fault names its JSON path.
//! let bad = text.replace("\"factor\": 2", "\"factor\": 1");
//! let e = validate::<Calibration>(deserialize(parse_json(&bad)?)?, "hash").err().ok_or("accepted")?;
//! assert!(e.to_string().contains("budgets.factor"), "{e}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::collections::BTreeMap;

use super::reference::{Known, known_values};
use super::source::Origin;
use super::spec::{Budgets, ExperimentSpec};

pub use crate::error::SpecError;
use crate::experiment::external::{Found, Servers};
use crate::family::{Estimator, Family, Listed, Method, Quantity};
use crate::quadrature::Rule;

mod cost;
mod parse;

use cost::{check_cost, check_crosscheck_cost};

pub use cost::{
    MAX_EXPERIMENT_EVALUATIONS, MAX_JOB_BYTES, MAX_JOB_EVALUATIONS, MAX_JOBS, MAX_RESULTS_BYTES,
    cost_limit_lifted, jobs_cost, lift_cost_limit, reference_cost,
};

pub use parse::{deserialize, parse_and_load, parse_json};

/// Largest budget accepted (per smooth piece).
pub const MAX_BUDGET: i64 = 100_000_000;

/// The smallest target relative error: below it an error is within the
/// rounding of a value and its reference in f64 (2.2e-16 a step), and no
/// rule is told to reach it or not (the schema's `minimum`).
pub const MIN_TARGET: f64 = 1e-15;

/// Most budgets a list may hold or a range expand to (the schema's
/// `maxItems` on a list).
const MAX_BUDGETS: usize = 200;

/// A validated experiment of family `F`, ready to run.
#[derive(Debug)]
pub struct Experiment<F: Family> {
    /// The file as parsed.
    pub spec: ExperimentSpec<F>,
    /// The scene, built.
    pub scene: F::Scene,
    /// The budgets, ascending.
    pub budgets: Vec<usize>,
    /// FNV-1a hash of the file's bytes.
    pub hash: String,
    /// Reference values known before running (closed forms, literals, Mitsuba
    /// values); a converged reference is computed when the report is written.
    pub known: Option<Known<F::Quantity>>,
    /// Where its file came from: Mitsuba values are looked for relative to it.
    pub origin: Origin,
    /// The program of each external rule, by rule index.
    pub programs: BTreeMap<usize, Found>,
    /// The external rules' running programs.
    pub servers: Servers,
}

/// Validates a parsed experiment whose file hashes to `hash`, as if its file
/// were in the working folder.
pub fn validate<F: Family>(
    spec: ExperimentSpec<F>,
    hash: &str,
) -> Result<Experiment<F>, SpecError> {
    validate_from(spec, hash, Origin::default())
}

/// Validates a parsed experiment whose file hashes to `hash` and came from
/// `origin` (a Mitsuba values file is looked for relative to it).
pub fn validate_from<F: Family>(
    spec: ExperimentSpec<F>,
    hash: &str,
    origin: Origin,
) -> Result<Experiment<F>, SpecError> {
    check_header::<F>(&spec)?;
    // The report's columns run from the largest target error down, and the
    // rules are ranked at the middle one, whatever order the file lists.
    let mut spec = spec;
    spec.targets.sort_by(|a, b| b.total_cmp(a));
    let scene = F::build(&spec.scene)?;
    for (k, q) in spec.quantities.iter().enumerate() {
        if let Some(why) = F::lacks(&scene, *q) {
            let at = format!("quantities[{k}]");
            return Err(SpecError::at(
                at,
                format!("{} cannot be computed in this scene: {why}", q.name()),
            ));
        }
    }
    let programs = check_methods::<F>(&spec, &scene, &origin)?;
    let budgets = budgets(&spec.budgets)?;
    // Budgets below a rule's minimum for a quantity are skipped for that
    // rule and quantity; a pair left with none is an error, so no rule
    // silently disappears from a quantity's table.
    let largest = budgets.last().copied().unwrap_or(0);
    let mut short = Vec::new();
    for (i, m) in spec.rules.iter().enumerate() {
        let unmet: Vec<(&str, usize)> = spec
            .quantities
            .iter()
            .map(|&q| (q.name(), quantity_min_budget::<F>(&scene, m, q)))
            .filter(|&(_, need)| largest < need)
            .collect();
        let Some(&(_, need)) = unmet.first() else {
            continue;
        };
        let one = unmet.len() == spec.quantities.len() && unmet.iter().all(|u| u.1 == need);
        let each: Vec<String> = unmet.iter().map(|(q, n)| format!("{n} for {q}")).collect();
        short.push(if one {
            format!("rules[{i}] ({}) needs at least {need}", m.name())
        } else {
            format!(
                "rules[{i}] ({}) needs at least {}",
                m.name(),
                each.join(", ")
            )
        });
    }
    if !short.is_empty() {
        return Err(SpecError::at(
            "budgets",
            format!(
                "the largest budget, {largest}, is below what some rules need: {}",
                short.join("; ")
            ),
        ));
    }
    check_cost::<F>(&spec, &scene, &budgets)?;
    let known = known_values::<F>(&spec, &scene, hash, &origin)?;
    check_crosscheck_cost::<F>(&spec, &scene, hash, &origin)?;
    Ok(Experiment {
        spec,
        scene,
        budgets,
        hash: hash.to_string(),
        known,
        origin,
        programs,
        servers: Servers::default(),
    })
}

/// The smallest budget at which `method` computes quantity `q` (its
/// minimum in `q`'s dimension).
pub fn quantity_min_budget<F: Family>(
    scene: &F::Scene,
    method: &Listed<F::Estimator>,
    q: F::Quantity,
) -> usize {
    method.min_budget(F::dimension(scene, q))
}

/// The quantities `method` computes at `budget`: those whose minimum the
/// budget reaches (a 4-D rule's minimum does not hold back a 2-D quantity
/// of the same experiment).
pub fn quantities_at<F: Family>(
    scene: &F::Scene,
    method: &Listed<F::Estimator>,
    quantities: &[F::Quantity],
    budget: usize,
) -> Vec<F::Quantity> {
    quantities
        .iter()
        .copied()
        .filter(|&q| budget >= quantity_min_budget::<F>(scene, method, q))
        .collect()
}

/// The smallest budget at which `method` computes any quantity of the
/// experiment: where its jobs start.
pub fn min_budget<F: Family>(
    scene: &F::Scene,
    method: &Listed<F::Estimator>,
    quantities: &[F::Quantity],
) -> usize {
    quantities
        .iter()
        .map(|&q| quantity_min_budget::<F>(scene, method, q))
        .min()
        .unwrap_or(1)
}

/// The longest experiment name: it names a folder, and file systems refuse
/// names past 255 bytes (a 300-character name passed `check` and failed the
/// run with an empty folder left).
pub const MAX_NAME: usize = 100;

/// Name, family tag, equation IDs, quantities, repeats and targets.
fn check_header<F: Family>(spec: &ExperimentSpec<F>) -> Result<(), SpecError> {
    let name_ok = !spec.name.is_empty()
        && spec.name.len() <= MAX_NAME
        && spec
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    if !name_ok {
        return Err(SpecError::at(
            "name",
            format!(
                "{:?} is not a name of 1 to {MAX_NAME} letters, digits, '-' and '_' (it names the report's folder)",
                spec.name
            ),
        ));
    }
    if spec.family != F::NAME {
        return Err(SpecError::at(
            "family",
            format!("{:?} is not the family {:?}", spec.family, F::NAME),
        ));
    }
    for (i, id) in spec.equations.iter().enumerate() {
        if !F::EQUATIONS.contains(&id.as_str()) {
            return Err(SpecError::at(
                format!("equations[{i}]"),
                if F::EQUATIONS.is_empty() {
                    format!(
                        "unknown equation ID {id:?}: the family {} instantiates no equation of \
                         the documents; expected no `equations` (or an empty list)",
                        F::NAME
                    )
                } else {
                    format!(
                        "unknown equation ID {id:?} for family {}: expected one of {}",
                        F::NAME,
                        F::EQUATIONS.join(", ")
                    )
                },
            ));
        }
    }
    if spec.quantities.is_empty() {
        let all: Vec<_> = F::Quantity::all().iter().map(Quantity::name).collect();
        return Err(SpecError::at(
            "quantities",
            format!("an empty list: name at least one of {}", all.join(", ")),
        ));
    }
    for (i, q) in spec.quantities.iter().enumerate() {
        if spec.quantities[..i].contains(q) {
            return Err(SpecError::at(
                format!("quantities[{i}]"),
                format!("{} is named twice: name each quantity once", q.name()),
            ));
        }
    }
    if !(1..=1000).contains(&spec.repeats) {
        return Err(SpecError::at(
            "repeats",
            format!("{} is not an integer in 1..=1000", spec.repeats),
        ));
    }
    if spec.targets.is_empty() {
        return Err(SpecError::at(
            "targets",
            "an empty list: give at least one relative error in (0, 1) (the rules are \
             ranked at the middle one)",
        ));
    }
    for (i, t) in spec.targets.iter().enumerate() {
        if !(t.is_finite() && *t >= MIN_TARGET && *t < 1.0) {
            return Err(SpecError::at(
                format!("targets[{i}]"),
                format!(
                    "{t} is not a relative error in [{MIN_TARGET:e}, 1) (below {MIN_TARGET:e}, an \
                     error is within the f64 rounding of a value and its reference)"
                ),
            ));
        }
    }
    let bits: Vec<u64> = spec.targets.iter().map(|t| t.to_bits()).collect();
    once_each("targets", "target", &bits, |&b| {
        f64::from_bits(b).to_string()
    })?;
    Ok(())
}

/// Every rule's parameters, and that every rule and estimator can compute
/// every quantity asked for (a rule in the quantity's dimension; an
/// estimator only the quantities it estimates); an external rule's program
/// found, by rule index.
fn check_methods<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
    origin: &Origin,
) -> Result<BTreeMap<usize, Found>, SpecError> {
    if spec.rules.is_empty() {
        return Err(SpecError::at(
            "rules",
            format!(
                "an empty list: name at least one of {}, or an external program",
                Method::<F::Estimator>::names().join(", ")
            ),
        ));
    }
    let mut programs = BTreeMap::new();
    for (i, method) in spec.rules.iter().enumerate() {
        let at = format!("rules[{i}]");
        match method {
            Listed::Own(Method::Rule(rule)) => check_rule::<F>(spec, scene, &at, rule)?,
            Listed::Own(Method::Estimator(e)) => check_estimator::<F>(spec, scene, &at, e)?,
            Listed::External(x) => {
                let found = x
                    .check(origin, &Method::<F::Estimator>::names())
                    .map_err(|(field, message)| SpecError::at(format!("{at}.{field}"), message))?;
                programs.insert(i, found);
            }
        }
    }
    Ok(programs)
}

/// A rule's parameters, and that it integrates in every quantity's dimension.
fn check_rule<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
    at: &str,
    rule: &crate::quadrature::AnyRule,
) -> Result<(), SpecError> {
    rule.check().map_err(|e| SpecError::from_quad(at, e))?;
    for (k, q) in spec.quantities.iter().enumerate() {
        let dim = F::dimension(scene, *q);
        if !rule.dimensions().contains(dim) {
            return Err(SpecError::at(
                at,
                format!(
                    "rule `{}` integrates in dimension {}, but quantities[{k}] ({}) is an \
                     integral in dimension {dim} in family {}: use a rule for dimension {dim}",
                    rule.name(),
                    rule.dimensions(),
                    q.name(),
                    F::NAME
                ),
            ));
        }
    }
    Ok(())
}

/// An estimator's parameters, and that it estimates every quantity in this scene.
fn check_estimator<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
    at: &str,
    e: &F::Estimator,
) -> Result<(), SpecError> {
    F::check_estimator(e).map_err(|err| SpecError::from_quad(at, err))?;
    let can = F::estimates(e);
    for (k, q) in spec.quantities.iter().enumerate() {
        if !can.contains(q) {
            let names: Vec<_> = can.iter().map(Quantity::name).collect();
            return Err(SpecError::at(
                at,
                format!(
                    "estimator `{}` estimates only {}, but quantities[{k}] is {}: \
                     give it an experiment of its own, or use a quadrature rule",
                    e.name(),
                    names.join(", "),
                    q.name()
                ),
            ));
        }
        if let Some(why) = F::refuses(scene, e, *q) {
            return Err(SpecError::at(
                at,
                format!(
                    "estimator `{}` cannot estimate quantities[{k}] ({}) in this scene: {why}",
                    e.name(),
                    q.name()
                ),
            ));
        }
    }
    Ok(())
}

/// The budgets, ascending and distinct.
fn budgets(spec: &Budgets) -> Result<Vec<usize>, SpecError> {
    let check = |path: String, n: i64| -> Result<usize, SpecError> {
        if (1..=MAX_BUDGET).contains(&n) {
            Ok(n as usize)
        } else {
            Err(SpecError::at(
                path,
                format!("{n} is not an integer in 1..={MAX_BUDGET}"),
            ))
        }
    };
    let mut out = match spec {
        Budgets::List(list) if list.is_empty() => {
            return Err(SpecError::at(
                "budgets",
                "an empty list: give at least one budget",
            ));
        }
        Budgets::List(list) if list.len() > MAX_BUDGETS => {
            return Err(SpecError::at(
                "budgets",
                format!(
                    "a list of {} budgets: give at most {MAX_BUDGETS}",
                    list.len()
                ),
            ));
        }
        Budgets::List(list) => {
            let out = list
                .iter()
                .enumerate()
                .map(|(i, &n)| check(format!("budgets[{i}]"), n))
                .collect::<Result<Vec<_>, _>>()?;
            once_each("budgets", "budget", &out, usize::to_string)?;
            out
        }
        Budgets::Range(r) => {
            let from = check("budgets.from".into(), r.from)?;
            let to = check("budgets.to".into(), r.to)?;
            if to < from {
                return Err(SpecError::at(
                    "budgets.to",
                    format!("{to} is below from = {from}"),
                ));
            }
            geometric(from, to, r.factor)?
        }
    };
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

/// Every entry of the list `field` given once (`keys`, its entries as
/// compared; `shown`, one as the error writes it): a repeated budget would
/// run once and be reported once, not as often as it was listed, and a
/// repeated target would be a second column of the same times.
fn once_each<K: std::hash::Hash + Eq>(
    field: &str,
    each: &str,
    keys: &[K],
    shown: impl Fn(&K) -> String,
) -> Result<(), SpecError> {
    let mut first = std::collections::HashMap::with_capacity(keys.len());
    for (i, key) in keys.iter().enumerate() {
        if let Some(j) = first.insert(key, i) {
            return Err(SpecError::at(
                format!("{field}[{i}]"),
                format!("{} repeats {field}[{j}]: give each {each} once", shown(key)),
            ));
        }
    }
    Ok(())
}

/// `from, from * factor, ... <= to`, each at least one above the last (so
/// factors near 1 still advance), at most [`MAX_BUDGETS`] of them.
fn geometric(from: usize, to: usize, factor: f64) -> Result<Vec<usize>, SpecError> {
    if !(factor.is_finite() && factor > 1.0) {
        return Err(SpecError::at(
            "budgets.factor",
            format!("{factor} is not a finite number > 1"),
        ));
    }
    let mut v = vec![from];
    loop {
        let last = v[v.len() - 1];
        let next = ((last as f64 * factor).round() as usize).max(last + 1);
        if next > to {
            return Ok(v);
        }
        if v.len() == MAX_BUDGETS {
            return Err(SpecError::at(
                "budgets.factor",
                format!(
                    "{factor} gives more than {MAX_BUDGETS} budgets from {from} to {to}: use a larger factor"
                ),
            ));
        }
        v.push(next);
    }
}

/// Literal reference values, checked: finite, one per quantity.
pub fn literal_values<Q: Quantity>(
    values: &BTreeMap<Q, super::spec::Literal>,
    quantities: &[Q],
    channels: impl Fn(Q) -> usize,
) -> Result<BTreeMap<Q, Vec<f64>>, SpecError> {
    // A value for a quantity the experiment does not ask for is a mistake
    // (a typo, or a quantity dropped from the list): refused, not ignored.
    if let Some(extra) = values.keys().find(|q| !quantities.contains(q)) {
        return Err(SpecError::at(
            format!("reference.values.{}", extra.name()),
            format!(
                "{} is not among the experiment's quantities ({}): remove it or add it to quantities",
                extra.name(),
                quantities
                    .iter()
                    .map(|q| q.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    let mut out = BTreeMap::new();
    for q in quantities {
        let Some(v) = values.get(q) else {
            return Err(SpecError::at(
                "reference.values",
                format!("no value for quantity {}", q.name()),
            ));
        };
        let at = format!("reference.values.{}", q.name());
        let got = v.channels();
        let want = channels(*q);
        if got.iter().any(|x| !x.is_finite()) {
            return Err(SpecError::at(at, format!("{got:?} is not finite")));
        }
        if got.len() != want {
            return Err(SpecError::at(
                at,
                format!(
                    "{} value(s) given, but {} has {want} channel(s): give {}",
                    got.len(),
                    q.name(),
                    if want == 1 {
                        "one number".to_string()
                    } else {
                        format!("a list of {want} numbers")
                    }
                ),
            ));
        }
        let (lo, hi) = q.bounds();
        if let Some((i, x)) = got
            .iter()
            .enumerate()
            .find(|(_, x)| !(lo..=hi).contains(*x))
        {
            let at = if let super::spec::Literal::Channels(_) = v {
                format!("{at}[{i}]")
            } else {
                at
            };
            return Err(SpecError::at(
                at,
                format!(
                    "{x} is not a value {} can take: expected {}",
                    q.name(),
                    crate::family::bounds_in_words((lo, hi))
                ),
            ));
        }
        out.insert(*q, got);
    }
    Ok(out)
}

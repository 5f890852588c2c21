//! The values errors are measured against, and where they come from: the
//! family's closed forms, literal values, the Mitsuba 3 harness's values
//! files, or the family's converged deterministic evaluation checked against
//! twice its nodes. Also the "lightquad vs Mitsuba vs closed form" rows.
//!
//! ```
//! use lightquad::calibration::Calibration;
//! use lightquad::experiment::reference::{reference, relative_distance};
//! use lightquad::experiment::validate::{deserialize, validate};
//!
//! // A converged reference: the family's most accurate deterministic evaluation
//! // at n = 32 nodes, checked against 2n. For int_0^1 e^u du that is e - 1.
//! let json = serde_json::json!({"name": "e", "family": "calibration", "scene": {},
//!     "quantities": ["exp"], "rules": [{"rule": "trapezoid"}], "budgets": [8],
//!     "reference": {"type": "converged", "n": 32}});
//! let exp = validate::<Calibration>(deserialize(json)?, "hash")?;
//! let r = reference(&exp);
//! assert!(r.missing.is_empty());
//! assert!((r.values["exp"][0] - (std::f64::consts::E - 1.0)).abs() < 1e-15);
//! // Its stated accuracy is its last change, never below the rounding floor.
//! assert_eq!(r.accuracy_of("exp"), lightquad::experiment::reference::CONVERGED_FLOOR);
//! // Errors are relative distances of channel vectors: rms(a - b) / rms(b).
//! assert!((relative_distance(&[1.0, 2.0], &[1.0, 1.0]) - 0.5f64.sqrt()).abs() < 1e-15);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::collections::BTreeMap;

use super::source::{Origin, Values, find_values};
use super::spec::{
    ConvergedReference, ExperimentSpec, MitsubaReference, ReferenceSpec, ValueReference,
};
use super::validate::{Experiment, literal_values};
use crate::error::SpecError;
use crate::family::{Family, Measured, Quantity};

/// Reference values known when an experiment is loaded.
#[derive(Debug, Clone, PartialEq)]
pub struct Known<Q> {
    /// Value per quantity, per channel.
    pub values: BTreeMap<Q, Vec<f64>>,
    /// Their absolute uncertainty.
    pub uncertainty: f64,
    /// Where they come from, for the report.
    pub note: String,
}

/// The reference of a run: values per quantity name, where they come from,
/// and their relative accuracy (errors below it are not resolved).
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// Value per quantity name, per channel.
    pub values: BTreeMap<String, Vec<f64>>,
    /// Quantities without a reference value, with the reason.
    pub missing: BTreeMap<String, String>,
    /// Where they come from, in a sentence.
    pub note: String,
    /// Relative accuracy per quantity name (absent: unknown, taken as 0).
    pub accuracy: BTreeMap<String, f64>,
    /// Absolute accuracy per quantity name and channel, where the reference
    /// knows it channel by channel (a converged reference: each channel's
    /// last change or its own error estimate, the larger, and never below
    /// [`CONVERGED_FLOOR`] of its value).
    pub channel_accuracy: BTreeMap<String, Vec<f64>>,
}

impl Reference {
    /// The relative accuracy of quantity `q`'s reference value (0 when the
    /// reference states none).
    pub fn accuracy_of(&self, q: &str) -> f64 {
        self.accuracy.get(q).copied().unwrap_or(0.0)
    }
}

/// The reference values an experiment can know before it runs (none for a
/// converged reference); checks the reference spec. A Mitsuba values file is
/// looked for relative to `origin`, the experiment file's folder.
pub fn known_values<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
    hash: &str,
    origin: &Origin,
) -> Result<Option<Known<F::Quantity>>, SpecError> {
    Ok(Some(match &spec.reference {
        ReferenceSpec::ClosedForm {} => closed_forms(spec, scene)?,
        ReferenceSpec::Value(ValueReference {
            values,
            uncertainty,
        }) => {
            if !(uncertainty.is_finite() && *uncertainty >= 0.0) {
                return Err(SpecError::at(
                    "reference.uncertainty",
                    format!("{uncertainty} is not a finite number >= 0"),
                ));
            }
            Known {
                values: literal_values(values, &spec.quantities, |q| F::channels(scene, q))?,
                uncertainty: *uncertainty,
                note: format!("literal values, uncertainty {uncertainty:e}."),
            }
        }
        ReferenceSpec::Mitsuba(MitsubaReference { file }) => {
            // The harness writes one number per quantity.
            if let Some(q) = spec
                .quantities
                .iter()
                .find(|q| F::channels(scene, **q) != 1)
            {
                return Err(SpecError::at(
                    "reference",
                    format!(
                        "Mitsuba values files hold scalars, and {} has {} channels",
                        q.name(),
                        F::channels(scene, *q)
                    ),
                ));
            }
            let at = "reference.file";
            match find_values(origin, &spec.name, hash, Some(file)) {
                Values::Found { location, json } => {
                    values_from_json(&location, &json, &spec.quantities)?
                }
                Values::Stale {
                    location,
                    made_from,
                    named_missing,
                } => {
                    let stale = stale_values(&location, &made_from, hash);
                    return Err(match named_missing {
                        // The named file is the fault: say so first.
                        Some(missing) => SpecError::at(
                            at,
                            format!("{missing} could not be read; and {}", stale.message),
                        ),
                        None => stale,
                    });
                }
                Values::NotValues { location, why } => {
                    return Err(SpecError::at(at, not_values(&location, &why)));
                }
                Values::Missing { looked } => {
                    return Err(SpecError::at(
                        at,
                        format!(
                            "no Mitsuba values file for this experiment (looked for {}, relative \
                             to the experiment file); run scripts/reference.sh to generate it",
                            looked.join(", ")
                        ),
                    ));
                }
                // find_values expects a file the reference names.
                Values::NotExpected => {
                    return Err(SpecError::at(at, format!("{file}: not found")));
                }
            }
        }
        ReferenceSpec::Converged(ConvergedReference { n }) => {
            check_converged_n(*n)?;
            return Ok(None);
        }
    }))
}

/// The family's closed form of every quantity, each finite and of the
/// quantity's channel count.
fn closed_forms<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
) -> Result<Known<F::Quantity>, SpecError> {
    let mut values = BTreeMap::new();
    for q in &spec.quantities {
        let Some(v) = F::closed_form(scene, *q).filter(|v| v.len() == F::channels(scene, *q))
        else {
            return Err(SpecError::at(
                "reference",
                format!(
                    "quantity {} has no closed form for this scene ({}): use {{\"type\": \"converged\"}}",
                    q.name(),
                    F::closed_forms_available()
                ),
            ));
        };
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(SpecError::at(
                "reference",
                format!(
                    "the closed form of {} is {x} for this scene (it overflows): no error \
                     can be measured against it",
                    q.name()
                ),
            ));
        }
        values.insert(*q, v);
    }
    Ok(Known {
        values,
        uncertainty: 0.0,
        note: format!("closed forms of the {} family.", F::NAME),
    })
}

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

/// Reads a Mitsuba values file for an experiment whose file hashes to `hash`:
/// the value and standard error per quantity.
pub fn mitsuba_values<Q: Quantity>(
    path: &str,
    hash: &str,
    quantities: &[Q],
) -> Result<Known<Q>, SpecError> {
    let at = "reference.file";
    let text = super::source::read_text(std::path::Path::new(path)).map_err(|e| {
        SpecError::at(
            at,
            format!("{path}: {e} (run scripts/reference.sh to generate it)"),
        )
    })?;
    let json =
        super::source::values_json(&text).map_err(|e| SpecError::at(at, format!("{path}: {e}")))?;
    let made_from = json["experiment_hash"].as_str().unwrap_or("");
    if made_from != hash {
        return Err(stale_values(path, made_from, hash));
    }
    values_from_json(path, &json, quantities)
}

/// Why the file a Mitsuba reference names is not a values file, with what
/// a values file is.
fn not_values(location: &str, why: &str) -> String {
    if !why.starts_with("not JSON") {
        // Not a values file, or not a regular file: said with what is expected.
        format!("{location}: {why}")
    } else {
        format!(
            "{location} is not a Mitsuba values file ({why}): expected the JSON file \
             scripts/reference.sh writes, with `experiment_hash`, a string, and `quantities`, an \
             object of values"
        )
    }
}

fn stale_values(path: &str, made_from: &str, hash: &str) -> SpecError {
    SpecError::at(
        "reference.file",
        format!(
            "{path} is stale: it was made from an experiment file with hash {made_from:?}, this one \
             hashes to {hash:?} (the hash is of the file's bytes: any edit counts, reformatting \
             included); regenerate it (scripts/reference.sh)"
        ),
    )
}

/// The value and standard error per quantity of a values file's JSON.
fn values_from_json<Q: Quantity>(
    path: &str,
    json: &serde_json::Value,
    quantities: &[Q],
) -> Result<Known<Q>, SpecError> {
    let at = "reference.file";
    let mut values = BTreeMap::new();
    let mut worst = 0.0f64;
    for q in quantities {
        let entry = &json["quantities"][q.name()];
        let (Some(v), Some(se)) = (entry["value"].as_f64(), entry["std_error"].as_f64()) else {
            return Err(SpecError::at(
                at,
                format!(
                    "{path} has no value for quantity {} (Mitsuba cannot compute it here?)",
                    q.name()
                ),
            ));
        };
        let (lo, hi) = q.bounds();
        if !(lo..=hi).contains(&v) {
            return Err(SpecError::at(
                at,
                format!(
                    "{path} gives {} = {v}, which is not a value it can take: expected {}",
                    q.name(),
                    crate::family::bounds_in_words((lo, hi))
                ),
            ));
        }
        values.insert(*q, vec![v]);
        worst = worst.max(se);
    }
    Ok(Known {
        values,
        uncertainty: worst,
        note: format!(
            "Mitsuba 3 values from `{path}` ({} {}), largest standard error {worst:.1e} (float32 \
             renderer: ~1e-6 relative floor).",
            json["mitsuba_variant"].as_str().unwrap_or("?"),
            json["mitsuba_version"].as_str().unwrap_or("?")
        ),
    })
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
fn converged_measured<F: Family>(
    exp: &Experiment<F>,
    n: usize,
) -> Result<BTreeMap<F::Quantity, Measured>, String> {
    F::converged(&exp.scene, n, &exp.spec.quantities).map_err(|e| e.to_string())
}

/// `sqrt(mean_c (a_c - b_c)^2) / sqrt(mean_c b_c^2)`: the relative distance of
/// two channel vectors (absolute where `b` is 0), without overflow.
pub fn relative_distance(a: &[f64], b: &[f64]) -> f64 {
    let scale = rms(b.iter().copied());
    // x - y overflows for opposite signs near the top of the range (a value
    // of 1.7e308 against a reference of -1.7e308 showed an error of inf):
    // there the halves are subtracted (exact for normal numbers) and the
    // result doubled.
    let huge = a.iter().chain(b).any(|x| x.abs() > f64::MAX / 2.0);
    let (diff, double) = if huge {
        (rms(a.iter().zip(b).map(|(x, y)| x / 2.0 - y / 2.0)), 2.0)
    } else {
        (rms(a.iter().zip(b).map(|(x, y)| x - y)), 1.0)
    };
    if a.len() != b.len() {
        f64::NAN
    } else if scale > 0.0 {
        diff / scale * double
    } else {
        diff * double
    }
}

/// Root mean square, scaled by the largest magnitude so that no square
/// overflows or underflows; NaN when any term is NaN.
pub fn rms(xs: impl Iterator<Item = f64> + Clone) -> f64 {
    if xs.clone().any(f64::is_nan) {
        return f64::NAN;
    }
    let big = xs.clone().fold(0.0f64, |m, x| m.max(x.abs()));
    if big == 0.0 || !big.is_finite() {
        return big;
    }
    let (sum, count) = xs.fold((0.0, 0usize), |(s, c), x| (s + (x / big).powi(2), c + 1));
    big * (sum / count as f64).sqrt()
}

/// The reference of a run.
pub fn reference<F: Family>(exp: &Experiment<F>) -> Reference {
    if let ReferenceSpec::Converged(ConvergedReference { n }) = exp.spec.reference {
        return converged_reference(exp, n);
    }
    let Some(known) = &exp.known else {
        let why = "no reference values were loaded";
        return Reference {
            values: BTreeMap::new(),
            missing: names::<F>(exp, why),
            note: format!("none: {why}."),
            accuracy: BTreeMap::new(),
            channel_accuracy: BTreeMap::new(),
        };
    };
    // Relative accuracy per quantity: the stated uncertainty against the
    // value's magnitude.
    let accuracy = known
        .values
        .iter()
        .map(|(q, v)| {
            let size = rms(v.iter().copied());
            let a = if size > 0.0 {
                known.uncertainty / size
            } else {
                known.uncertainty
            };
            (q.name().to_string(), a)
        })
        .collect();
    Reference {
        values: known
            .values
            .iter()
            .map(|(q, v)| (q.name().to_string(), v.clone()))
            .collect(),
        missing: BTreeMap::new(),
        note: known.note.clone(),
        accuracy,
        channel_accuracy: BTreeMap::new(),
    }
}

/// Every quantity of the experiment, with the same reason.
fn names<F: Family>(exp: &Experiment<F>, why: &str) -> BTreeMap<String, String> {
    exp.spec
        .quantities
        .iter()
        .map(|q| (q.name().to_string(), why.to_string()))
        .collect()
}

/// The tightest relative change the converged reference asks for: the
/// evaluation's own rounding (sums of thousands of terms, each with a
/// relative error near 1e-16) leaves changes near 1e-14, so a goal below
/// this would never be met; errors under it are flagged as at the
/// reference's accuracy, and the note says when the floor was used.
pub const CONVERGED_FLOOR: f64 = 1e-13;

/// Doublings of `n` the converged reference may take past the spec's `n`.
const MAX_DOUBLINGS: u32 = 6;

/// The converged reference: the family's converged evaluation at `n`, `2n`,
/// `4n`, ... nodes per piece until every quantity's relative change from one
/// to the next is at most `goal` (a hundredth of the tightest target, but not
/// below [`CONVERGED_FLOOR`]) or `n` has doubled [`MAX_DOUBLINGS`] times. Each quantity
/// keeps the finest value and, as its accuracy, its own last change (at
/// least [`CONVERGED_FLOOR`], the evaluation's own rounding); one that
/// did not get below the goal is named in the note. A quantity the family
/// could not compute, or whose value is not finite, has no reference.
fn converged_reference<F: Family>(exp: &Experiment<F>, n: usize) -> Reference {
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
        }
    };
    let mut coarse = match converged_measured(exp, n) {
        Ok(a) => a,
        Err(e) => return failed(e),
    };
    let mut m = n;
    let (fine, changes, per_channel) = loop {
        m *= 2;
        let fine = match converged_measured(exp, m) {
            Ok(b) => b,
            Err(e) => return failed(e),
        };
        let changes: BTreeMap<String, f64> = exp
            .spec
            .quantities
            .iter()
            .filter_map(|q| {
                let (x, y) = (coarse.get(q)?, fine.get(q)?);
                // The change from the coarser evaluation, or the finer one's
                // own error estimate where that is larger (an adaptive rule
                // that met its tolerance twice changes by nothing).
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
            .collect();
        let done = changes.values().all(|c| *c <= goal);
        if done || m >= n << MAX_DOUBLINGS {
            // Each channel's change or own error estimate, the larger.
            let per_channel: BTreeMap<String, Vec<f64>> = exp
                .spec
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
                            // Never below the rounding floor (as the whole
                            // quantity's): a background channel of 0.1 every
                            // ray sees alike changed by 0, yet the rules'
                            // weights summed it to 0.09999999999999999, a
                            // display step below the reference's 25.5.
                            own.map_or(change, |e| change.max(e.abs()))
                                .max(CONVERGED_FLOOR * y.value[c].abs())
                        })
                        .collect();
                    Some((q.name().to_string(), each))
                })
                .collect();
            break (fine, changes, per_channel);
        }
        coarse = fine;
    };
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
    // A converged evaluation that doubts its own error estimate (the
    // rendering family's, across outlines it does not split at) is not
    // called converged, whatever its change between budgets.
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
            "{q} (unverified: its evaluation crosses discontinuities it does not split at, where \
             the change between budgets can understate the error)"
        )
    }));
    let floor = if goal == CONVERGED_FLOOR {
        format!(
            " (the goal: a hundredth of the tightest target, {tightest:.0e}, but not below \
             {CONVERGED_FLOOR:.0e}, the evaluation's own rounding)"
        )
    } else {
        String::new()
    };
    let verdict = if unconverged.is_empty() {
        format!("every quantity converged to {goal:.0e} or better{floor}")
    } else {
        format!(
            "NOT converged to {goal:.0e}{floor}: {}; errors below that are not resolved",
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
    }
}

/// One row of the "lightquad vs Mitsuba vs closed form" comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Crosscheck {
    /// Experiment name.
    pub experiment: String,
    /// The quantity's name.
    pub quantity: &'static str,
    /// lightquad's converged value (the family's converged evaluation at n = 400).
    pub lightquad: f64,
    /// False when that evaluation doubts its own error (it crosses outlines
    /// it does not split at): the table marks the value unverified.
    pub verified: bool,
    /// Mitsuba's value and standard error, when it has one.
    pub mitsuba: Option<(f64, f64)>,
    /// The closed form, where the family has one.
    pub closed_form: Option<f64>,
    /// Why Mitsuba has no value, or that its file is stale.
    pub note: String,
}

/// Whether the experiment's name or description speaks of Mitsuba.
fn mentions_mitsuba<F: Family>(exp: &Experiment<F>) -> bool {
    [&exp.spec.name, &exp.spec.description]
        .iter()
        .any(|t| t.to_lowercase().contains("mitsuba"))
}

/// The bundled experiment with Mitsuba values whose scene `exp` has, under
/// another name.
fn copy_of_bundled<F: Family>(exp: &Experiment<F>) -> Option<String> {
    super::source::bundled_experiments()
        .iter()
        .find_map(|(file, text)| {
            let name = file.strip_suffix(".json")?;
            if name == exp.spec.name || super::source::bundled_values(name).is_none() {
                return None;
            }
            let spec =
                super::validate::deserialize::<F>(super::validate::parse_json(text).ok()?).ok()?;
            (spec.family == exp.spec.family && spec.scene == exp.spec.scene)
                .then(|| name.to_string())
        })
}

/// The comparison rows of an experiment with Mitsuba values (found as
/// [`find_values`] says: relative to the experiment file, or built into the
/// binary); none when it has none and none is expected. Values that are
/// expected but missing, or stale, give rows saying so, so the comparison
/// never silently disappears. Scalar quantities only (Mitsuba's files hold
/// scalars).
pub fn crosscheck<F: Family>(exp: &Experiment<F>) -> Vec<Crosscheck> {
    let named = match &exp.spec.reference {
        ReferenceSpec::Mitsuba(MitsubaReference { file }) => Some(file.as_str()),
        _ => None,
    };
    let (json, note) = match find_values(&exp.origin, &exp.spec.name, &exp.hash, named) {
        Values::NotExpected => match copy_of_bundled(exp) {
            // A renamed copy of a bundled Mitsuba experiment lost its values
            // (they are found by name and hash): said, not dropped.
            Some(bundled) => (
                serde_json::Value::Null,
                Some(format!(
                    "no Mitsuba values for `{}`: its scene is that of the bundled `{bundled}`, \
                     whose values belong to that file alone (values are found by the \
                     experiment's name and the hash of its file); make this file's with \
                     `cd reference && .venv/bin/python -m lqref --out DIR FILE`, DIR being \
                     `reference/values` beside the experiment's folder",
                    exp.spec.name
                )),
            ),
            // An experiment that says it is cross-checked against Mitsuba
            // (its name or description) but has no values: said, not
            // dropped (an edited, renamed copy of a bundled one).
            None if mentions_mitsuba(exp) => (
                serde_json::Value::Null,
                Some(format!(
                    "no Mitsuba values for `{}` (it names Mitsuba, but no values file was found \
                     for its name and file hash): make them with `cd reference && \
                     .venv/bin/python -m lqref --out DIR FILE`, DIR being `reference/values` \
                     beside the experiment's folder",
                    exp.spec.name
                )),
            ),
            None => return Vec::new(),
        },
        Values::Found { json, .. } => (json, None),
        Values::Stale {
            location,
            made_from,
            ..
        } => (
            serde_json::Value::Null,
            Some(format!(
                "values file {location} is stale (made from experiment hash {made_from}, this \
                 file hashes to {}; the hash is of the file's bytes: any edit counts, \
                 reformatting included): regenerate with scripts/reference.sh",
                exp.hash
            )),
        ),
        Values::NotValues { location, why } => {
            (serde_json::Value::Null, Some(not_values(&location, &why)))
        }
        Values::Missing { looked } => (
            serde_json::Value::Null,
            Some(format!(
                "MISSING: no Mitsuba values file found (looked for {}): generate it with \
                 scripts/reference.sh",
                looked.join(", ")
            )),
        ),
    };
    let lightquad = converged_measured(exp, 400).unwrap_or_default();
    let scalar = |v: Option<&Vec<f64>>| v.and_then(|v| (v.len() == 1).then(|| v[0]));
    exp.spec
        .quantities
        .iter()
        .map(|q| {
            let entry = &json["quantities"][q.name()];
            let mitsuba = match (entry["value"].as_f64(), entry["std_error"].as_f64()) {
                (Some(v), Some(se)) if note.is_none() => Some((v, se)),
                _ => None,
            };
            let note = note.clone().unwrap_or_else(|| {
                json["unsupported"][q.name()]
                    .as_str()
                    .unwrap_or("")
                    .to_string()
            });
            Crosscheck {
                experiment: exp.spec.name.clone(),
                quantity: q.name(),
                lightquad: scalar(lightquad.get(q).map(|m| &m.value)).unwrap_or(f64::NAN),
                verified: lightquad
                    .get(q)
                    .is_none_or(|m| !m.flags.contains(&crate::family::Flag::UnreliableEstimate)),
                mitsuba,
                closed_form: scalar(F::closed_form(&exp.scene, *q).as_ref()),
                note,
            }
        })
        .collect()
}

/// What the comparison's table shows, said above it in every report.
pub const CROSSCHECK_INTRO: &str = "Every case the Mitsuba harness (reference/) covers: \
     lightquad's converged value (the family's converged evaluation at n = 400, computed apart \
     from the experiment's reference), Mitsuba's value with its standard error (float32 \
     renderer: expect ~1e-6 relative at best), the closed form where one exists; where Mitsuba \
     has no value, the row says why.";

/// The comparison as a Markdown table.
pub fn crosscheck_markdown(rows: &[Crosscheck]) -> String {
    let mut md = String::from(
        "| experiment | quantity | lightquad (converged) | Mitsuba 3 +- std. error | closed form | lightquad - Mitsuba |\n\
         |---|---|---:|---:|---:|---|\n",
    );
    for r in rows {
        let mitsuba = r.mitsuba.map_or(format!("— {}", r.note), |(v, se)| {
            format!("{v:.10e} +- {se:.1e}")
        });
        let closed = r.closed_form.map_or("—".into(), |c| format!("{c:.10e}"));
        let agreement = match r.mitsuba {
            Some((v, se)) if se > 0.0 => format!("{:+.2} SE", (r.lightquad - v) / se),
            // 0 against 0 has no relative difference to show: an underflowed
            // value (tau at depth 1e5) is compared by its logarithm.
            Some((v, _)) if v == 0.0 && r.lightquad == 0.0 => {
                "both 0 in f64: no relative difference (an underflowed value is compared as its \
                 logarithm, ln_tau)"
                    .into()
            }
            Some((v, _)) => format!(
                "{:+.1e} relative (deterministic, float32)",
                relative_distance(&[r.lightquad], &[v]) * if r.lightquad >= v { 1.0 } else { -1.0 }
            ),
            None => "—".into(),
        };
        let unverified = if r.verified {
            ""
        } else {
            " (unverified: across outlines it does not split at)"
        };
        // A colour or an image has no single number to show.
        let lightquad = if r.lightquad.is_finite() {
            format!("{:.10e}{unverified}", r.lightquad)
        } else {
            "— (not one number: a colour or an image)".to_string()
        };
        md.push_str(&format!(
            "| {} | {} | {lightquad} | {mitsuba} | {closed} | {agreement} |\n",
            r.experiment, r.quantity
        ));
    }
    md
}

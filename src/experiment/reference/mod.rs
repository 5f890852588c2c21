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
//!
//! `converged` builds the converged reference, `mitsuba` reads the Mitsuba
//! harness's values files, and `crosscheck` makes the "lightquad vs Mitsuba
//! vs closed form" rows; `Known`, `Reference`, the values known at load
//! and the distances are here.

use std::collections::BTreeMap;

use crate::error::SpecError;
use crate::experiment::source::{Origin, Values, find_values};
use crate::experiment::spec::{
    ConvergedReference, ExperimentSpec, MitsubaReference, ReferenceSpec, ValueReference,
};
use crate::experiment::validate::{Experiment, literal_values};
use crate::family::{Family, Quantity};

mod converged;
mod crosscheck;
mod mitsuba;

use converged::converged_reference;
pub use converged::{CONVERGED_FLOOR, MAX_CONVERGED_N, check_converged_n, converged};
pub use crosscheck::{
    CROSSCHECK_INTRO, CROSSCHECK_N, Crosscheck, compares, crosscheck, crosscheck_markdown,
};
pub use mitsuba::mitsuba_values;
use mitsuba::{not_values, stale_values, values_from_json};

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
    /// Quantities whose converged evaluation doubts its own error estimate
    /// (across a discontinuity it does not split at): their accuracy is
    /// the change between budgets, unverified.
    pub unverified: Vec<String>,
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
            unverified: Vec::new(),
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
        unverified: Vec::new(),
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

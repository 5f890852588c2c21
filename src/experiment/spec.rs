//! The experiment file format (serde), generic over the family: the family
//! tag, the family's scene, its quantities, the rules and estimators to
//! compare, the budgets and the reference. Unknown fields are rejected; every
//! error names the JSON path of the fault.
//!
//! ```
//! use lightquad::calibration::Calibration;
//! use lightquad::experiment::spec::{BudgetRange, Budgets, ConvergedReference, ExperimentSpec, ReferenceSpec};
//! use lightquad::experiment::validate::deserialize;
//!
//! let json = serde_json::json!({
//!     "name": "e", "family": "calibration", "scene": {}, "quantities": ["exp"],
//!     "rules": [{"rule": "gauss-legendre"}, {"rule": "monte-carlo"}],
//!     "budgets": {"from": 4, "to": 64, "factor": 4},
//!     "reference": {"type": "converged", "n": 100}
//! });
//! let spec: ExperimentSpec<Calibration> = deserialize(json.clone())?;
//! assert_eq!(spec.budgets, Budgets::Range(BudgetRange { from: 4, to: 64, factor: 4.0 }));
//! assert_eq!(spec.reference, ReferenceSpec::Converged(ConvergedReference { n: 100 }));
//! // Fields left out take their defaults: 3 repeats, targets 1e-3, 1e-6, 1e-9.
//! assert_eq!((spec.repeats, spec.targets.as_slice()), (3, &[1e-3, 1e-6, 1e-9][..]));
//! // Unknown fields are refused, with their JSON path.
//! let mut typo = json;
//! typo["reference"]["nodes"] = 100.into();
//! let e = deserialize::<Calibration>(typo).err().ok_or("accepted")?;
//! assert!(e.to_string().contains("reference") && e.to_string().contains("nodes"), "{e}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::family::{Family, Listed};

/// One experiment file of family `F`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, bound = "")]
#[schemars(bound = "", rename = "Experiment")]
pub struct ExperimentSpec<F: Family> {
    /// The JSON Schema the file follows, for an editor to validate and
    /// complete it against (`lightquad schema > lightquad.schema.json`);
    /// any string, not read.
    #[serde(rename = "$schema", default, skip_serializing_if = "Option::is_none")]
    pub schema: Option<String>,
    /// Short name (file-name safe: letters, digits, `-`, `_`).
    pub name: String,
    /// The equation family (`volume`, ...): it decides what `scene`,
    /// `quantities` and the family's own estimators in `rules` may be.
    pub family: String,
    /// What the experiment shows.
    #[serde(default)]
    pub description: String,
    /// The equation IDs it instantiates (docs/EQUATIONS.md: `V-tau`, `V-E`, ...;
    /// default none).
    #[serde(default)]
    pub equations: Vec<String>,
    /// The scene, in the family's format: only the parts it has.
    #[serde(deserialize_with = "super::tagged::object")]
    pub scene: F::SceneSpec,
    /// Quantities to compute, at least one, each once.
    #[serde(deserialize_with = "super::tagged::names")]
    #[schemars(length(min = 1), extend("uniqueItems" = true))]
    pub quantities: Vec<F::Quantity>,
    /// Rules and estimators to compare, with their parameters; at least one.
    #[schemars(length(min = 1))]
    pub rules: Vec<Listed<F::Estimator>>,
    /// Budgets: a list, or a geometric range.
    pub budgets: Budgets,
    /// Repeats per (rule, budget): run time is their lower median; randomised
    /// rules get one independent stream each.
    #[serde(default = "default_repeats", deserialize_with = "repeats")]
    #[schemars(range(min = 1, max = 1000))]
    pub repeats: usize,
    /// Seed of every random stream (each job derives its own from it).
    #[serde(default, deserialize_with = "seed")]
    #[schemars(range(max = u64::MAX))]
    pub seed: u64,
    /// The reference the errors are measured against.
    pub reference: ReferenceSpec<F::Quantity>,
    /// Relative errors in [1e-15, 1) whose time-to-reach the report gives, each
    /// once, at least one; validation sorts them from the largest, and the
    /// rules are ranked at the middle one.
    #[serde(default = "default_targets")]
    #[schemars(
        length(min = 1),
        extend("uniqueItems" = true),
        extend("items" = {"type": "number", "minimum": 1e-15, "exclusiveMaximum": 1})
    )]
    pub targets: Vec<f64>,
}

fn default_repeats() -> usize {
    3
}

fn repeats<'de, D: serde::Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
    super::tagged::whole(d, 1, 1000, "")
}

fn seed<'de, D: serde::Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
    super::tagged::whole(d, 0, u64::MAX.into(), "")
}

/// A budget read by [`whole`](super::tagged::whole): its range named where
/// the number does not fit (`18446744073709551615`).
fn budget<'de, D: serde::Deserializer<'de>>(d: D) -> Result<i64, D::Error> {
    super::tagged::whole(d, 1, super::validate::MAX_BUDGET.into(), "")
}

/// One budget of a list (see [`budget`]).
struct ListedBudget(i64);

impl<'de> Deserialize<'de> for ListedBudget {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        budget(d).map(ListedBudget)
    }
}

fn default_targets() -> Vec<f64> {
    vec![1e-3, 1e-6, 1e-9]
}

/// Budgets: a list, or a geometric range `from, from*factor, ... <= to`.
/// Read by a visitor of its own (a list or a map, never buffered), so an error
/// inside names its own path (`budgets.factor`, `budgets[2]`).
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum Budgets {
    /// An explicit list.
    List(
        #[schemars(
            length(min = 1, max = 200),
            extend("uniqueItems" = true),
            inner(range(min = 1, max = 100_000_000))
        )]
        Vec<i64>,
    ),
    /// A geometric range.
    Range(BudgetRange),
}

/// A geometric range of budgets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BudgetRange {
    /// First budget.
    #[serde(deserialize_with = "budget")]
    #[schemars(range(min = 1, max = 100_000_000))]
    pub from: i64,
    /// Last budget (inclusive bound).
    #[serde(deserialize_with = "budget")]
    #[schemars(range(min = 1, max = 100_000_000))]
    pub to: i64,
    /// Ratio between consecutive budgets (> 1).
    #[schemars(extend("exclusiveMinimum" = 1))]
    pub factor: f64,
}

/// A literal reference value: a number, or one number per channel (read by
/// a visitor of its own, so an error names its own path).
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum Literal {
    /// One channel.
    Scalar(f64),
    /// Several channels (RGB, pixels).
    Channels(Vec<f64>),
}

impl Literal {
    /// The channels.
    pub fn channels(&self) -> Vec<f64> {
        match self {
            Literal::Scalar(x) => vec![*x],
            Literal::Channels(v) => v.clone(),
        }
    }
}

/// The reference values errors are measured against: `{"type": <name>,
/// <the variant's fields>}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(
    tag = "type",
    rename_all = "kebab-case",
    bound(serialize = "Q: Serialize + Ord")
)]
pub enum ReferenceSpec<Q> {
    /// The family's closed forms (an error at validation when a quantity has none).
    ClosedForm {},
    /// Literal values per quantity, with their uncertainty.
    Value(ValueReference<Q>),
    /// Values written by the Mitsuba 3 harness (`reference/`), e.g.
    /// `../reference/values/<name>.json` for a file in `experiments/`; stale
    /// files (another experiment hash) are rejected.
    Mitsuba(MitsubaReference),
    /// The family's converged deterministic evaluation at `n` nodes per
    /// piece, checked against `2n`.
    Converged(ConvergedReference),
}

/// Reads the tag, then the variant's fields, so that a fault inside names
/// its own path (`reference.values.tau`; see [`tagged`](super::tagged)).
impl<'de, Q: serde::de::DeserializeOwned + Ord> Deserialize<'de> for ReferenceSpec<Q> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use super::tagged::{NoFields, split_tag, variant};
        const NAMES: [&str; 4] = ["closed-form", "value", "mitsuba", "converged"];
        let (tag, fields) = split_tag(serde_json::Value::deserialize(d)?, "type", &NAMES)?;
        match tag.as_str() {
            "closed-form" => variant::<NoFields, _>(fields).map(|_| ReferenceSpec::ClosedForm {}),
            "value" => variant(fields).map(ReferenceSpec::Value),
            "mitsuba" => variant(fields).map(ReferenceSpec::Mitsuba),
            _ => variant(fields).map(ReferenceSpec::Converged),
        }
    }
}

/// Literal values per quantity, with their uncertainty.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(
    deny_unknown_fields,
    bound(
        serialize = "Q: Serialize + Ord",
        deserialize = "Q: serde::de::DeserializeOwned + Ord"
    )
)]
pub struct ValueReference<Q> {
    /// Value per quantity name.
    #[serde(deserialize_with = "super::tagged::keyed")]
    pub values: BTreeMap<Q, Literal>,
    /// Absolute uncertainty (default 0).
    #[serde(default)]
    pub uncertainty: f64,
}

/// Values written by the Mitsuba 3 harness.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MitsubaReference {
    /// Path of the values file, relative to the experiment file's folder.
    pub file: String,
}

/// The family's converged deterministic evaluation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConvergedReference {
    /// Nodes per smooth piece (default 400).
    #[serde(default = "four_hundred", deserialize_with = "converged_n")]
    #[schemars(range(min = 2, max = 100_000))]
    pub n: usize,
}

fn four_hundred() -> usize {
    400
}

fn converged_n<'de, D: serde::Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
    super::tagged::whole(d, 2, 100_000, "")
}

/// Deserialises the two untagged enums of experiment files by the JSON
/// kind they meet (number, list, map) instead of serde's untagged buffering,
/// which loses the path and the reason of an error inside ("data did not
/// match any variant").
mod untagged {
    use super::{BudgetRange, Budgets, ListedBudget, Literal};
    use serde::de::value::{MapAccessDeserializer, SeqAccessDeserializer};
    use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
    use std::fmt;

    impl<'de> Deserialize<'de> for Budgets {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            struct V;
            impl<'de> Visitor<'de> for V {
                type Value = Budgets;
                fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                    f.write_str(
                        "a list of budgets ([4, 16, 64]) or a range \
                         ({\"from\": 4, \"to\": 4096, \"factor\": 4})",
                    )
                }
                fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Budgets, A::Error> {
                    Vec::<ListedBudget>::deserialize(SeqAccessDeserializer::new(seq))
                        .map(|list| Budgets::List(list.into_iter().map(|b| b.0).collect()))
                }
                fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Budgets, A::Error> {
                    BudgetRange::deserialize(MapAccessDeserializer::new(map)).map(Budgets::Range)
                }
            }
            d.deserialize_any(V)
        }
    }

    impl<'de> Deserialize<'de> for Literal {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            struct V;
            impl<'de> Visitor<'de> for V {
                type Value = Literal;
                fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                    f.write_str("a number, or a list of numbers (one per channel)")
                }
                fn visit_f64<E: serde::de::Error>(self, x: f64) -> Result<Literal, E> {
                    Ok(Literal::Scalar(x))
                }
                fn visit_i64<E: serde::de::Error>(self, x: i64) -> Result<Literal, E> {
                    Ok(Literal::Scalar(x as f64))
                }
                fn visit_u64<E: serde::de::Error>(self, x: u64) -> Result<Literal, E> {
                    Ok(Literal::Scalar(x as f64))
                }
                fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Literal, A::Error> {
                    Vec::<f64>::deserialize(SeqAccessDeserializer::new(seq)).map(Literal::Channels)
                }
            }
            d.deserialize_any(V)
        }
    }
}

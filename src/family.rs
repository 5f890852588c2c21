//! The contract of an equation family: what the experiment layer needs of the
//! volume-rendering equations (`V-*`), the rendering equation (`R-*`) or
//! Whitted's model (`W-*`), and nothing more.
//!
//! A family owns its scene format (serde + JSON Schema), its quantities, the
//! estimators it has beside the quadrature rules (tracking, path tracing,
//! recursive ray tracing), how it evaluates a quantity with a rule or an
//! estimator, and its closed forms. [`crate::experiment`] is generic over this
//! trait and never names a family; [`crate::families`] is the one registry
//! that does.
//!
//! Adding a family: a module that implements [`Family`], and one line in
//! [`crate::families::builtin`] (or [`crate::experiment::Registry::with`] from
//! outside the crate).
//!
//! ```
//! use lightquad::family::{Family, Quantity};
//! use lightquad::volume::experiment::Volume;
//!
//! // What a family declares: its tag, quantities and equation IDs.
//! assert_eq!(Volume::NAME, "volume");
//! let quantities: Vec<&str> = <Volume as Family>::Quantity::all().iter().map(Quantity::name).collect();
//! assert!(quantities.contains(&"I_L"));
//! assert!(Volume::EQUATIONS.contains(&"V-tau"));
//! ```

use std::collections::BTreeMap;
use std::fmt::Debug;

use schemars::JsonSchema;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::{QuadError, SpecError};
use crate::experiment::external::External;
use crate::experiment::tagged::below;
use crate::quadrature::{AnyRule, BaseRule, Product, Rule};

/// A quantity a family computes (`tau`, `I_L`, a pixel image, ...).
pub trait Quantity:
    Copy + Ord + Debug + Serialize + DeserializeOwned + JsonSchema + Send + Sync + 'static
{
    /// The name in experiment files, results and reports.
    fn name(&self) -> &'static str;
    /// Every quantity of the family.
    fn all() -> &'static [Self];
    /// The values the quantity can take, `(lo, hi)` inclusive: a radiance is
    /// never negative, a transmittance is in [0, 1], `ln tau` is never
    /// positive. A literal reference value outside them is refused at
    /// `check` (`-1` for a radiance was accepted, and every error measured
    /// against it). Default: any number.
    fn bounds(&self) -> (f64, f64) {
        (f64::NEG_INFINITY, f64::INFINITY)
    }
}

/// `(lo, hi)` of [`Quantity::bounds`] in words: `a number >= 0`, `a number in
/// [0, 1]`.
pub fn bounds_in_words((lo, hi): (f64, f64)) -> String {
    match (lo.is_finite(), hi.is_finite()) {
        (true, true) => format!("a number in [{lo}, {hi}]"),
        (true, false) => format!("a number >= {lo}"),
        (false, true) => format!("a number <= {hi}"),
        (false, false) => "a finite number".into(),
    }
}

/// A family's estimator that is not a quadrature rule (tracking, path
/// tracing, ...). Its serde form is tagged by `"rule"`, like the rules'.
pub trait Estimator:
    Clone + Debug + PartialEq + Serialize + DeserializeOwned + JsonSchema + Send + Sync + 'static
{
    /// The name in experiment files (`ratio-tracking`, ...).
    fn name(&self) -> &'static str;
    /// One line on what it estimates and how.
    fn about(&self) -> &'static str;
    /// The smallest budget it accepts.
    fn min_budget(&self) -> usize;
    /// True for randomised estimators.
    fn is_random(&self) -> bool;
    /// Every estimator with default parameters (for listings and names).
    fn all() -> Vec<Self>;
    /// The resolution per axis that a budget of `n` buys in `dim`
    /// dimensions, against which the reports fit the order per axis, as
    /// for the rules: the largest `m` with `m^dim <= n` (`n` itself in one
    /// dimension; a sampler in two dimensions was fitted against `n`, and
    /// its slope showed as half of Monte Carlo's beside it), the points per
    /// axis for a grid.
    fn resolution(&self, n: usize, dim: usize) -> f64 {
        crate::quadrature::integer_root(n, dim) as f64
    }
}

/// The estimators of a family that has none beyond the quadrature rules.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub enum NoEstimator {}

impl Estimator for NoEstimator {
    fn name(&self) -> &'static str {
        match *self {}
    }
    fn about(&self) -> &'static str {
        match *self {}
    }
    fn min_budget(&self) -> usize {
        match *self {}
    }
    fn is_random(&self) -> bool {
        match *self {}
    }
    fn all() -> Vec<Self> {
        Vec::new()
    }
}

/// How a quantity is computed: a quadrature rule, or one of the family's own
/// estimators. In experiment files both are `{"rule": "<name>", ...}`.
#[derive(Debug, Clone, PartialEq)]
pub enum Method<E> {
    /// A quadrature rule (products included).
    Rule(AnyRule),
    /// The family's estimator.
    Estimator(E),
}

impl<E: Estimator> Method<E> {
    /// The name in experiment files.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Rule(r) => r.name(),
            Method::Estimator(e) => e.name(),
        }
    }

    /// The name, with a product's factors (`product(gauss-legendre,trapezoid)`).
    pub fn label(&self) -> String {
        match self {
            Method::Rule(r) => r.label(),
            Method::Estimator(e) => e.name().to_string(),
        }
    }

    /// The smallest budget it accepts in `dim` dimensions.
    pub fn min_budget(&self, dim: usize) -> usize {
        match self {
            Method::Rule(r) => r.min_budget(dim),
            Method::Estimator(e) => e.min_budget(),
        }
    }

    /// The resolution per axis a budget buys ([`Rule::resolution`]); an
    /// estimator's budget itself (walks).
    pub fn resolution(&self, n: usize, dim: usize) -> f64 {
        match self {
            Method::Rule(r) => r.resolution(n, dim),
            Method::Estimator(e) => e.resolution(n, dim),
        }
    }

    /// True for randomised rules and estimators.
    pub fn is_random(&self) -> bool {
        match self {
            Method::Rule(r) => r.is_random(),
            Method::Estimator(e) => e.is_random(),
        }
    }

    /// Every name a method of this family may have: the rules, then the estimators.
    pub fn names() -> Vec<&'static str> {
        let mut names: Vec<&'static str> = AnyRule::listing().iter().map(|r| r.0).collect();
        names.extend(E::all().iter().map(Estimator::name));
        names
    }
}

impl<E: Serialize> Serialize for Method<E> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Method::Rule(r) => r.serialize(s),
            Method::Estimator(e) => e.serialize(s),
        }
    }
}

/// Reads the `"rule"` tag first, then the rule or the estimator it names, so
/// an unknown name gets one message listing every accepted name.
impl<'de, E: Estimator> Deserialize<'de> for Method<E> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let value = serde_json::Value::deserialize(d)?;
        let names = Self::names();
        let accepted = || format!("expected one of {}", names.join(", "));
        if !value.is_object() {
            return Err(D::Error::custom(format!(
                "{value} is not a rule: expected {{\"rule\": <name>, <parameters>}}, the name one of {}",
                names.join(", ")
            )));
        }
        let Some(tag) = value.get("rule") else {
            return Err(D::Error::custom(format!(
                "missing field `rule`: {}",
                accepted()
            )));
        };
        let Some(tag) = tag.as_str() else {
            return Err(below(
                "rule",
                &format!(
                    "{}: expected a name in quotes, one of {}",
                    crate::experiment::tagged::kind(tag),
                    names.join(", ")
                ),
            ));
        };
        // A fault inside a rule is reported at its field; serde's tagged enums
        // do not track paths below the tag, so a rule's parameters are read
        // by [`BaseRule::from_json`] and an estimator's at the estimator.
        if E::all().iter().any(|e| e.name() == tag) {
            let estimator: E = serde_json::from_value(value.clone()).map_err(D::Error::custom)?;
            // serde ignores unknown fields beside an internally tagged unit
            // variant (`{"rule": "delta-tracking", "n": 3}` read as plain
            // delta tracking), so every field given must be one the
            // estimator writes back.
            let known = serde_json::to_value(&estimator).map_err(D::Error::custom)?;
            let unknown = value
                .as_object()
                .into_iter()
                .flatten()
                .map(|(k, _)| k)
                .find(|k| known.get(k.as_str()).is_none());
            match unknown {
                None => Ok(Method::Estimator(estimator)),
                Some(k) => {
                    let fields: Vec<String> = known
                        .as_object()
                        .into_iter()
                        .flatten()
                        .map(|(k, _)| format!("`{k}`"))
                        .collect();
                    Err(below(
                        k,
                        &format!(
                            "unknown field `{k}` of the estimator `{tag}`: expected only {}",
                            fields.join(", ")
                        ),
                    ))
                }
            }
        } else if tag == "product" {
            product(&value).map(Method::Rule)
        } else if names.contains(&tag) {
            BaseRule::from_json(&value)
                .map(|r| Method::Rule(AnyRule::Base(r)))
                .map_err(|(path, message)| below(&path, &message))
        } else {
            Err(D::Error::custom(format!(
                "unknown rule `{tag}`: {}",
                accepted()
            )))
        }
    }
}

/// `{"rule": "product", "outer": {..}, "inner": {..}}`, a fault in a factor
/// reported below it (`.outer.rel_tol`).
fn product<Er: serde::de::Error>(value: &serde_json::Value) -> Result<AnyRule, Er> {
    let map = value.as_object().into_iter().flatten();
    if let Some((key, _)) = map
        .clone()
        .find(|(k, _)| !matches!(k.as_str(), "rule" | "outer" | "inner"))
    {
        return Err(Er::custom(format!(
            "unknown field `{key}`, expected `outer` or `inner`"
        )));
    }
    let factor = |field: &str| -> Result<BaseRule, Er> {
        let v = value
            .get(field)
            .ok_or_else(|| Er::custom(format!("missing field `{field}`")))?;
        BaseRule::from_json(v).map_err(|(path, message)| {
            let path = if path.is_empty() {
                field.to_string()
            } else {
                format!("{field}.{path}")
            };
            below(
                &path,
                &format!("{message} (a product's factors are single 1-D rules)"),
            )
        })
    };
    Ok(AnyRule::Product(Box::new(Product {
        outer: factor("outer")?,
        inner: factor("inner")?,
    })))
}

impl<E: JsonSchema> JsonSchema for Method<E> {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Method".into()
    }
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let rule = generator.subschema_for::<AnyRule>();
        let estimator = generator.subschema_for::<E>();
        schemars::json_schema!({ "anyOf": [rule, estimator] })
    }
}

/// A method as an experiment file lists it in `rules`: one of the family's
/// own ([`Method`]), or an external program ([`External`]) that the runner
/// asks for its estimates (a family never sees one).
#[derive(Debug, Clone, PartialEq)]
pub enum Listed<E> {
    /// A quadrature rule or the family's estimator.
    Own(Method<E>),
    /// `{"rule": "external", ...}`.
    External(External),
}

impl<E: Estimator> Listed<E> {
    /// The family's method, if it is one.
    pub fn own(&self) -> Option<&Method<E>> {
        match self {
            Listed::Own(m) => Some(m),
            Listed::External(_) => None,
        }
    }

    /// The name in experiment files (an external program's own name).
    pub fn name(&self) -> &str {
        match self {
            Listed::Own(m) => m.name(),
            Listed::External(x) => &x.name,
        }
    }

    /// The name, with a product's factors ([`Method::label`]).
    pub fn label(&self) -> String {
        match self {
            Listed::Own(m) => m.label(),
            Listed::External(x) => x.name.clone(),
        }
    }

    /// The smallest budget it accepts in `dim` dimensions (1 for a program).
    pub fn min_budget(&self, dim: usize) -> usize {
        match self {
            Listed::Own(m) => m.min_budget(dim),
            Listed::External(_) => 1,
        }
    }

    /// The resolution per axis a budget buys: a program's as a sampler's,
    /// the largest `m` with `m^dim <= n` ([`Estimator::resolution`]).
    pub fn resolution(&self, n: usize, dim: usize) -> f64 {
        match self {
            Listed::Own(m) => m.resolution(n, dim),
            Listed::External(_) => crate::quadrature::integer_root(n, dim) as f64,
        }
    }

    /// True for randomised rules, estimators and programs.
    pub fn is_random(&self) -> bool {
        match self {
            Listed::Own(m) => m.is_random(),
            Listed::External(x) => x.random,
        }
    }
}

impl<E: Serialize> Serialize for Listed<E> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Tagged<'a> {
            rule: &'static str,
            #[serde(flatten)]
            external: &'a External,
        }
        match self {
            Listed::Own(m) => m.serialize(s),
            Listed::External(x) => Tagged {
                rule: "external",
                external: x,
            }
            .serialize(s),
        }
    }
}

/// `{"rule": "external", ...}` is read here, its faults at their field;
/// anything else is the family's [`Method`].
impl<'de, E: Estimator> Deserialize<'de> for Listed<E> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut value = serde_json::Value::deserialize(d)?;
        if value.get("rule").and_then(|t| t.as_str()) != Some("external") {
            return Method::deserialize(value)
                .map(Listed::Own)
                .map_err(D::Error::custom);
        }
        if let Some(map) = value.as_object_mut() {
            map.remove("rule");
        }
        serde_path_to_error::deserialize(value)
            .map(Listed::External)
            .map_err(|e| {
                let path = e.path().to_string();
                let path = if path == "." { String::new() } else { path };
                below(&path, &e.into_inner().to_string())
            })
    }
}

/// The schema of `{"rule": "external", ...}`.
#[derive(JsonSchema)]
#[allow(dead_code)]
#[schemars(rename = "External")]
struct ExternalRule {
    /// `"external"`.
    rule: ExternalTag,
    #[serde(flatten)]
    external: External,
}

/// The tag of an external estimator.
#[derive(JsonSchema)]
#[allow(dead_code)]
enum ExternalTag {
    #[serde(rename = "external")]
    External,
}

impl<E: JsonSchema> JsonSchema for Listed<E> {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "ListedMethod".into()
    }
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let own = generator.subschema_for::<Method<E>>();
        let external = generator.subschema_for::<ExternalRule>();
        schemars::json_schema!({ "anyOf": [own, external] })
    }
}

/// A fact about one evaluated value that a report must show.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "flag", rename_all = "kebab-case")]
pub enum Flag {
    /// The value is below the smallest normal f64: only its logarithm (the
    /// family computes it) is meaningful.
    Underflow,
    /// A sum that lost digits: its magnitude is below 1e-6 of the summed
    /// magnitudes of its parts, `parts`.
    Cancellation {
        /// `sum |part|`.
        #[serde(with = "json_f64::one")]
        parts: f64,
    },
    /// The rule doubted its own error estimate: the differences it is built
    /// from did not behave as the estimate assumes (algebraic instead of
    /// geometric convergence, a jump or a kink in the integrand); for a
    /// random rule, every sample alike (a standard error of 0 that says
    /// nothing about values not seen: a constant integrand is flagged too)
    /// or a sample variance carried by a few samples (an infinite-variance
    /// integrand, an event hit by few samples).
    UnreliableEstimate,
    /// Every walk of a tracking estimator scored alike: the sample variance
    /// is 0, which says nothing about outcomes not yet seen, so the error is
    /// a Wilson-type bound (`W(n) D`, [`crate::volume::tracking::Tracked`])
    /// that still reads as one standard error, not a sample standard error.
    AllWalksAlike {
        /// The number of walks.
        walks: u64,
    },
    /// A tracking estimator's scores are carried by a few walks
    /// ([`crate::volume::tracking::Tracked::heavy`]): the mean rests on
    /// walks not yet seen, and the standard error can understate the true
    /// error by orders of magnitude.
    HeavyWalks {
        /// The number of walks.
        walks: u64,
    },
    /// A deterministic rule's every node gave the same value and its error
    /// estimate is 0 ([`crate::estimate::Estimate::alike`]): the 0 says
    /// nothing of what lies between the nodes.
    AllNodesAlike {
        /// The evaluations.
        evaluations: u64,
    },
}

impl std::fmt::Display for Flag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Flag::Underflow => write!(f, "underflows: 0 in f64, ln_tau holds it in log space"),
            Flag::Cancellation { parts } => {
                write!(f, "cancellation: |sum| < 1e-6 of its parts ({parts:.1e})")
            }
            Flag::UnreliableEstimate => write!(f, "error estimate unreliable (rule's own check)"),
            Flag::AllWalksAlike { walks } => write!(
                f,
                "all {walks} walks scored alike: error is a Wilson-type bound / 1.96, not a sample SE"
            ),
            Flag::AllNodesAlike { evaluations } => write!(
                f,
                "every one of {evaluations} nodes gave the same value: an error of 0 says nothing of what lies between them"
            ),
            Flag::HeavyWalks { walks } => write!(
                f,
                "{walks} walks carried by a few: the mean rests on walks not yet seen, the SE can be far too small"
            ),
        }
    }
}

/// One quantity as evaluated: its channels (a scalar, RGB, or the pixels of
/// an image), the error estimate per channel, and the evaluations it cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    /// The value, per channel.
    #[serde(with = "json_f64::many")]
    pub value: Vec<f64>,
    /// The method's own estimate of the absolute error, per channel
    /// (infinite where the method had no information to estimate it).
    #[serde(with = "json_f64::many")]
    pub error: Vec<f64>,
    /// Evaluations of the integrand's costly part (density lookups, rays).
    pub evaluations: u64,
    /// Facts a report must show.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub flags: Vec<Flag>,
    /// Wall time of this quantity's own evaluation, seconds: the runner
    /// evaluates each quantity alone and times it, so a quantity's time to a
    /// target is its own cost, not that of every quantity of the job.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seconds: Option<f64>,
    /// An external estimator's own wall time for it, seconds, as the
    /// program reported it (start-up excluded); `seconds` is lightquad's
    /// time of the same request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub program_seconds: Option<f64>,
}

impl Measured {
    /// A one-channel value.
    pub fn scalar(value: f64, error: f64, evaluations: u64) -> Self {
        Measured {
            value: vec![value],
            error: vec![error],
            evaluations,
            flags: Vec::new(),
            seconds: None,
            program_seconds: None,
        }
    }

    /// The same, with a flag.
    pub fn flagged(mut self, flag: Flag) -> Self {
        self.flags.push(flag);
        self
    }
}

impl<V: crate::value::Value> From<crate::estimate::Estimate<V>> for Measured {
    /// The estimate's channels, error per channel and cost.
    fn from(e: crate::estimate::Estimate<V>) -> Self {
        Measured {
            value: (0..V::CHANNELS).map(|c| e.value.channel(c)).collect(),
            error: (0..V::CHANNELS).map(|c| e.error.channel(c)).collect(),
            evaluations: e.evaluations,
            flags: [
                (!e.reliable).then_some(Flag::UnreliableEstimate),
                e.alike.then_some(Flag::AllNodesAlike {
                    evaluations: e.evaluations,
                }),
            ]
            .into_iter()
            .flatten()
            .collect(),
            seconds: None,
            program_seconds: None,
        }
    }
}

/// The quantities of one evaluation.
pub type Outcome<Q> = BTreeMap<Q, Measured>;

/// An equation family: see the module documentation.
pub trait Family: Sized + Send + Sync + 'static {
    /// The tag in experiment files (`"family": "volume"`).
    const NAME: &'static str;
    /// One line on what the family covers.
    const ABOUT: &'static str;
    /// The equation IDs of docs/EQUATIONS.md it instantiates.
    const EQUATIONS: &'static [&'static str];
    /// What a budget counts, for reports ("evaluations per smooth piece of
    /// the ray", ...).
    const BUDGET_UNIT: &'static str;
    /// Why a job may evaluate its integrand more often than its budget, for
    /// the reports' rows where it does: "the rule's error estimate" by
    /// default (Gauss–Legendre's three companion rules, about 3.5 n).
    const OVER_BUDGET: &'static str = "the rule's own error estimate evaluates more than n \
        nodes (Gauss–Legendre's three companion rules of about n, n and n/2 nodes: about 3.5 n \
        in all)";

    /// The scene as written in an experiment file.
    type SceneSpec: Clone
        + Debug
        + PartialEq
        + Serialize
        + DeserializeOwned
        + JsonSchema
        + Send
        + Sync;
    /// The scene, built and checked.
    type Scene: Debug + Send + Sync;
    /// Its quantities.
    type Quantity: Quantity;
    /// Its estimators beside the quadrature rules ([`NoEstimator`] for none).
    type Estimator: Estimator;

    /// Checks every number of the scene once and builds it; errors name the
    /// JSON path from the file's root (`scene.medium.kappa`).
    fn build(spec: &Self::SceneSpec) -> Result<Self::Scene, SpecError>;

    /// The dimension of the unit cube over which a rule integrates `quantity`
    /// in `scene`.
    fn dimension(scene: &Self::Scene, quantity: Self::Quantity) -> usize;

    /// The number of channels of `quantity` in `scene` (1 for a scalar, 3 for
    /// RGB, the pixel count of an image): every value, error and reference of
    /// it must have that many.
    fn channels(scene: &Self::Scene, quantity: Self::Quantity) -> usize;

    /// Why `quantity` cannot be computed in this `scene` by any method (a
    /// term it needs is missing: reflected radiance without a BRDF); checked
    /// when an experiment is validated, the error at the quantity. None: it
    /// can.
    fn lacks(_scene: &Self::Scene, _quantity: Self::Quantity) -> Option<String> {
        None
    }

    /// Doubts about a scene that is built and runs, but may not be what was
    /// meant (a material that is not energy conserving), each at its JSON
    /// path; `check` and `run` print them as warnings. None by default.
    fn warnings(_scene: &Self::Scene) -> Vec<SpecError> {
        Vec::new()
    }

    /// The quantities `estimator` estimates.
    fn estimates(estimator: &Self::Estimator) -> &'static [Self::Quantity];

    /// Checks the estimator's own parameters, as a quadrature rule's `check`
    /// does; the error names the parameter, which the validator appends to
    /// the rule's JSON path (`rules[0].threshold`). Ok by default.
    fn check_estimator(_estimator: &Self::Estimator) -> Result<(), QuadError> {
        Ok(())
    }

    /// Why `estimator` cannot estimate `quantity` in this `scene`, though it
    /// estimates it in general ([`Family::estimates`]); checked when an
    /// experiment is validated. None: it can.
    fn refuses(
        _scene: &Self::Scene,
        _estimator: &Self::Estimator,
        _quantity: Self::Quantity,
    ) -> Option<String> {
        None
    }

    /// About how many integrand evaluations one job of `quantity` with
    /// `method` at `budget` costs, in evaluations of a simple integrand (a
    /// lookup that sums 2000 blobs, or a ray tested against 50 000 objects,
    /// counts that many), to refuse before running what would take
    /// hours ([`crate::experiment::validate::MAX_JOB_EVALUATIONS`]). The
    /// evaluations the rule makes at that budget by default
    /// ([`Rule::evaluations`], in the quantity's dimension; the budget for an
    /// estimator); a family whose evaluations nest (an inner integral per
    /// outer node) says so here.
    fn cost(
        scene: &Self::Scene,
        method: &Method<Self::Estimator>,
        budget: usize,
        quantity: Self::Quantity,
    ) -> f64 {
        match method {
            Method::Rule(rule) => rule.evaluations(budget, Self::dimension(scene, quantity)),
            Method::Estimator(_) => budget as f64,
        }
    }

    /// About how many bytes one job of `quantity` with `method` at `budget`
    /// holds at once, to refuse before running what would exhaust the
    /// machine ([`crate::experiment::validate::MAX_JOB_BYTES`]): the rule's
    /// own [`Rule::memory`] in the quantity's dimension by default; a family
    /// that holds several node tables at once (an inner rule per outer
    /// node) says so here.
    fn memory(
        scene: &Self::Scene,
        method: &Method<Self::Estimator>,
        budget: usize,
        quantity: Self::Quantity,
    ) -> f64 {
        match method {
            Method::Rule(r) => r.memory(budget, Self::dimension(scene, quantity)),
            Method::Estimator(_) => 0.0,
        }
    }

    /// About how many simple evaluations (counted as [`Family::cost`] counts
    /// them) and how many bytes at once the converged evaluation
    /// ([`Family::converged`]) of `quantities` at `n` takes: `check` refuses
    /// a converged reference whose first two evaluations (at `n` and `2n`)
    /// pass the job limits, and the reference stops doubling before an
    /// evaluation that would. By default the price of adaptive
    /// Gauss–Kronrod at its cap of `15 + 30 n` evaluations a piece, which a
    /// family whose converged evaluation uses another rule or budget
    /// overrides.
    fn converged_cost(scene: &Self::Scene, n: usize, quantities: &[Self::Quantity]) -> [f64; 2] {
        let Ok(gk) = crate::quadrature::AnyRule::by_name("gauss-kronrod") else {
            return [f64::NAN; 2];
        };
        job_cost::<Self>(
            scene,
            &Method::Rule(gk),
            n.saturating_mul(30).saturating_add(15),
            quantities,
        )
    }

    /// Evaluates `quantities` with `method` at `budget`, drawing randomness from
    /// `rng` only.
    fn evaluate(
        scene: &Self::Scene,
        method: &Method<Self::Estimator>,
        budget: usize,
        rng: &mut rand_pcg::Pcg64,
        quantities: &[Self::Quantity],
    ) -> Result<Outcome<Self::Quantity>, QuadError>;

    /// The closed form of `quantity` for this scene, when one is known.
    fn closed_form(scene: &Self::Scene, quantity: Self::Quantity) -> Option<Vec<f64>>;

    /// Where the family has closed forms (for the error when one is missing).
    fn closed_forms_available() -> &'static str;

    /// `quantities` by the family's most accurate deterministic method with
    /// `n` nodes per smooth piece: the converged reference, and lightquad's
    /// column in the Mitsuba comparison.
    fn converged(
        scene: &Self::Scene,
        n: usize,
        quantities: &[Self::Quantity],
    ) -> Result<Outcome<Self::Quantity>, QuadError>;

    /// How the scene is evaluated, in words, for the report's header
    /// (e.g. the volume family's depth scheme).
    fn settings(_spec: &Self::SceneSpec) -> String {
        String::new()
    }

    /// The display a quantity is looked at through, if any (W-Grey's 8-bit
    /// image for Whitted's pixels): the reports count, per row, the
    /// displayed values that differ from the reference's, so they say from
    /// which budget on more work no longer changes what a person sees.
    fn display(_quantity: Self::Quantity) -> Option<Display> {
        None
    }

    /// `[width, height]` where the quantity's channels are an RGB image, in
    /// rows from the top (R, G, B per pixel): the reports then show the
    /// reference and each rule's image at its largest budget, with error
    /// heat maps, as PNG (and PFM files beside them).
    fn image(_scene: &Self::Scene, _quantity: Self::Quantity) -> Option<[usize; 2]> {
        None
    }

    /// The family's audit of printed formulas, as Markdown, if it has one.
    fn audit() -> Option<String> {
        None
    }

    /// A section of one experiment's report on its own scene (for instance the
    /// document's printed formulas evaluated in it), as Markdown, if any.
    fn scene_audit(_scene: &Self::Scene) -> Option<String> {
        None
    }
}

/// A quantized display of a quantity's channels ([`Family::display`]).
#[derive(Debug, Clone, Copy)]
pub struct Display {
    /// Its name in the reports (`8-bit (W-Grey)`).
    pub name: &'static str,
    /// Half a display step, in the quantity's units: an error below it moves
    /// a displayed value by at most one step (`1/510` for 8 bits over
    /// `[0, 1]`).
    pub half_step: f64,
    /// The displayed value of one channel.
    pub quantize: fn(f64) -> u8,
}

/// Serde for floats in results files that keeps the non-finite ones: JSON has
/// no infinity or NaN (serde_json writes `null`, which reads back as nothing),
/// so they are written as the strings `"inf"`, `"-inf"` and `"NaN"`.
pub mod json_f64 {
    use serde::de::Error;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// A number, or the name of a non-finite one.
    #[derive(Serialize, Deserialize)]
    #[serde(untagged)]
    enum Num {
        Finite(f64),
        Named(String),
    }

    fn write(x: f64) -> Num {
        match x {
            _ if x.is_finite() => Num::Finite(x),
            _ if x.is_nan() => Num::Named("NaN".into()),
            _ if x > 0.0 => Num::Named("inf".into()),
            _ => Num::Named("-inf".into()),
        }
    }

    fn read<E: Error>(n: Num) -> Result<f64, E> {
        match n {
            Num::Finite(x) => Ok(x),
            Num::Named(s) => match s.as_str() {
                "inf" => Ok(f64::INFINITY),
                "-inf" => Ok(f64::NEG_INFINITY),
                "NaN" => Ok(f64::NAN),
                other => Err(E::custom(format!(
                    "{other:?} is not a number, \"inf\", \"-inf\" or \"NaN\""
                ))),
            },
        }
    }

    /// One float.
    pub mod one {
        use super::*;

        /// Writes `x`.
        pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
            write(*x).serialize(s)
        }

        /// Reads a float.
        pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
            read(Num::deserialize(d)?)
        }
    }

    /// A vector of floats.
    pub mod many {
        use super::*;

        /// Writes `v`.
        pub fn serialize<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
            s.collect_seq(v.iter().map(|&x| write(x)))
        }

        /// Reads a vector of floats.
        pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
            Vec::<Num>::deserialize(d)?.into_iter().map(read).collect()
        }
    }
}

/// The evaluations (summed over `quantities`, [`Family::cost`]) and bytes
/// (the largest, [`Family::memory`]) of one job of `method` at `budget`.
pub fn job_cost<F: Family>(
    scene: &F::Scene,
    method: &Method<F::Estimator>,
    budget: usize,
    quantities: &[F::Quantity],
) -> [f64; 2] {
    let evaluations = quantities
        .iter()
        .map(|&q| F::cost(scene, method, budget, q))
        .sum();
    let bytes = quantities
        .iter()
        .map(|&q| F::memory(scene, method, budget, q))
        .fold(0.0, f64::max);
    [evaluations, bytes]
}

//! The experiment file format (serde): a scene with only the parts it has, the
//! quantities to compute, the rules and budgets to compare, and the reference.
//! Unknown fields are rejected; every error names the JSON path of the fault.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// One experiment file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExperimentSpec {
    /// Short name (file-name safe: letters, digits, `-`, `_`).
    pub name: String,
    /// What the experiment shows.
    #[serde(default)]
    pub description: String,
    /// The equation IDs it instantiates (docs/EQUATIONS.md: `V-tau`, `V-E`, ...).
    pub equations: Vec<String>,
    /// The scene: only the parts it has.
    pub scene: SceneSpec,
    /// Quantities to compute.
    pub quantities: Vec<Quantity>,
    /// Rules to compare, with their parameters.
    pub rules: Vec<RuleSpec>,
    /// Budgets: a list, or a geometric range.
    pub budgets: Budgets,
    /// Repeats per (rule, budget): run time is their median; randomised rules
    /// get one independent stream each.
    #[serde(default = "default_repeats")]
    pub repeats: usize,
    /// Seed of every random stream (each job derives its own from it).
    #[serde(default)]
    pub seed: u64,
    /// How `tau(t_n, t)` inside V-E and V-L is computed.
    #[serde(default)]
    pub depth_scheme: DepthSchemeSpec,
    /// How the shadow ray's optical depth in V-Lp is computed.
    #[serde(default)]
    pub shadow: ShadowSpec,
    /// The reference the errors are measured against.
    pub reference: ReferenceSpec,
    /// Relative errors whose time-to-reach the report gives.
    #[serde(default = "default_targets")]
    pub targets: Vec<f64>,
}

fn default_repeats() -> usize {
    3
}

fn default_targets() -> Vec<f64> {
    vec![1e-3, 1e-6, 1e-9]
}

/// The scene along one eye ray.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// The eye ray.
    pub ray: RaySpec,
    /// Start of the looked-at part of the ray (default 0).
    #[serde(default)]
    pub t_min: Option<f64>,
    /// End of the looked-at part (default: infinite).
    #[serde(default)]
    pub t_max: Option<f64>,
    /// The medium, if any.
    #[serde(default)]
    pub medium: Option<MediumSpec>,
    /// `lambda` in `sigma = lambda v_r` (default 1).
    #[serde(default)]
    pub lambda: Option<f64>,
    /// The emission map, if the medium emits.
    #[serde(default)]
    pub emission: Option<EmissionSpec>,
    /// Background radiance `I_b`, if any.
    #[serde(default)]
    pub background: Option<f64>,
    /// The directional light, if any.
    #[serde(default)]
    pub light: Option<LightSpec>,
}

/// A ray `e + t v`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RaySpec {
    /// `e`.
    pub origin: [f64; 3],
    /// `v` (normalised; t is arc length).
    pub direction: [f64; 3],
}

/// A medium.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum MediumSpec {
    /// Constant density `kappa` in a sphere.
    ConstantSphere {
        /// Centre.
        centre: [f64; 3],
        /// Radius.
        radius: f64,
        /// Density.
        kappa: f64,
    },
    /// A sum of Gaussian blobs.
    GaussianBlobs {
        /// The blobs.
        blobs: Vec<BlobSpec>,
    },
    /// `max(0, base + gradient . (x - centre))` inside a sphere.
    LinearGradient {
        /// Centre of the bounding sphere.
        centre: [f64; 3],
        /// Its radius.
        radius: f64,
        /// Density at the centre.
        base: f64,
        /// Gradient.
        gradient: [f64; 3],
    },
    /// A voxel grid (values at voxel centres, trilinear, `[z][y][x]`).
    VoxelGrid {
        /// Lower corner.
        min: [f64; 3],
        /// Upper corner.
        max: [f64; 3],
        /// Voxels per axis.
        resolution: [usize; 3],
        /// Densities, x fastest.
        data: Vec<f64>,
    },
}

/// One Gaussian blob.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlobSpec {
    /// Centre.
    pub centre: [f64; 3],
    /// Peak density.
    pub amplitude: f64,
    /// Width (standard deviation).
    pub width: f64,
}

/// The emission map `c(v)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum EmissionSpec {
    /// `c(v) = c` inside the medium.
    Constant {
        /// The constant.
        c: f64,
    },
    /// `c(v) = k v`.
    Proportional {
        /// The factor.
        k: f64,
    },
}

/// A directional light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    /// Direction from a point toward the light.
    pub toward_light: [f64; 3],
    /// Intensity `I_p`.
    pub intensity: f64,
    /// Single-scattering albedo (omit for the document's reduced V-L).
    #[serde(default)]
    pub albedo: Option<f64>,
}

/// A quantity to compute.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, JsonSchema,
)]
pub enum Quantity {
    /// V-tau over the chord.
    #[serde(rename = "tau")]
    Tau,
    /// V-E.
    #[serde(rename = "I_E")]
    Emission,
    /// V-B.
    #[serde(rename = "I_B")]
    Background,
    /// V-L.
    #[serde(rename = "I_L")]
    Light,
    /// V-I.
    #[serde(rename = "I")]
    Total,
}

impl Quantity {
    /// The name used in files and reports.
    pub fn name(&self) -> &'static str {
        match self {
            Quantity::Tau => "tau",
            Quantity::Emission => "I_E",
            Quantity::Background => "I_B",
            Quantity::Light => "I_L",
            Quantity::Total => "I",
        }
    }
}

/// A rule with its parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "rule", rename_all = "kebab-case", deny_unknown_fields)]
pub enum RuleSpec {
    /// Composite trapezoid.
    Trapezoid {},
    /// Gauss–Legendre.
    GaussLegendre {
        /// Spend `m - 1` more nodes on the error estimate (default true).
        #[serde(default = "yes")]
        error_estimate: bool,
    },
    /// Adaptive G7–K15.
    GaussKronrod {
        /// Absolute tolerance (default 0: use the whole budget).
        #[serde(default)]
        abs_tol: f64,
        /// Relative tolerance (default 0).
        #[serde(default)]
        rel_tol: f64,
    },
    /// Plain Monte Carlo.
    MonteCarlo {},
    /// Stratified Monte Carlo.
    Stratified {},
    /// Owen-scrambled Sobol'.
    Sobol {
        /// Independent scrambles (default 8).
        #[serde(default = "eight")]
        replicates: usize,
    },
    /// Delta tracking (tau only).
    DeltaTracking {},
    /// Ratio tracking (tau only).
    RatioTracking {},
    /// Residual ratio tracking (tau only).
    ResidualRatioTracking {},
}

fn yes() -> bool {
    true
}

fn eight() -> usize {
    8
}

impl RuleSpec {
    /// The registry name.
    pub fn name(&self) -> &'static str {
        match self {
            RuleSpec::Trapezoid {} => "trapezoid",
            RuleSpec::GaussLegendre { .. } => "gauss-legendre",
            RuleSpec::GaussKronrod { .. } => "gauss-kronrod",
            RuleSpec::MonteCarlo {} => "monte-carlo",
            RuleSpec::Stratified {} => "stratified",
            RuleSpec::Sobol { .. } => "sobol",
            RuleSpec::DeltaTracking {} => "delta-tracking",
            RuleSpec::RatioTracking {} => "ratio-tracking",
            RuleSpec::ResidualRatioTracking {} => "residual-ratio-tracking",
        }
    }

    /// The smallest budget the rule accepts (smaller budgets are skipped for it).
    pub fn min_budget(&self) -> usize {
        match self {
            RuleSpec::Trapezoid {} => 3,
            RuleSpec::GaussKronrod { .. } => 15,
            RuleSpec::Sobol { replicates } => *replicates,
            RuleSpec::GaussLegendre { .. } => 1,
            _ => 2,
        }
    }

    /// True for the randomised rules and estimators.
    pub fn is_random(&self) -> bool {
        matches!(
            self,
            RuleSpec::MonteCarlo {}
                | RuleSpec::Stratified {}
                | RuleSpec::Sobol { .. }
                | RuleSpec::DeltaTracking {}
                | RuleSpec::RatioTracking {}
                | RuleSpec::ResidualRatioTracking {}
        )
    }
}

/// Budgets: a list, or a geometric range `from, from*factor, ... <= to`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum Budgets {
    /// An explicit list.
    List(Vec<i64>),
    /// A geometric range.
    Range(BudgetRange),
}

/// A geometric range of budgets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BudgetRange {
    /// First budget.
    pub from: i64,
    /// Last budget (inclusive bound).
    pub to: i64,
    /// Ratio between consecutive budgets (> 1).
    pub factor: f64,
}

/// How the nested optical depth is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum DepthSchemeSpec {
    /// Cumulative (cost ~ n).
    #[default]
    Cumulative,
    /// Nested (cost ~ n^2).
    Nested,
}

/// How the shadow ray is integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ShadowSpec {
    /// Closed form where the medium has one.
    #[default]
    ClosedForm,
    /// Always quadrature.
    Quadrature,
}

/// The reference values errors are measured against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ReferenceSpec {
    /// Closed forms from `exact` (an error at validation when a quantity has none).
    ClosedForm {},
    /// Literal values per quantity, with their uncertainty.
    Value {
        /// Value per quantity name.
        values: BTreeMap<Quantity, f64>,
        /// Absolute uncertainty (default 0).
        #[serde(default)]
        uncertainty: f64,
    },
    /// Values written by the Mitsuba 3 harness (`reference/`), e.g.
    /// `reference/values/<name>.json`; stale files (another experiment hash)
    /// are rejected.
    Mitsuba {
        /// Path of the values file, relative to the working folder.
        file: String,
    },
    /// A high-order Gauss–Legendre run at `n` nodes per piece, checked against `2n`.
    Converged {
        /// Nodes per smooth piece (default 400).
        #[serde(default = "four_hundred")]
        n: usize,
    },
}

fn four_hundred() -> usize {
    400
}

//! The volume-rendering family (V-* in docs/EQUATIONS.md) as the experiment
//! layer sees it: the scene format of an experiment file (`"family":
//! "volume"`), its quantities, the tracking estimators beside the rules, the
//! closed forms and the converged reference.
//!
//! ```
//! use lightquad::family::{Family, Method};
//! use lightquad::volume::experiment::{SceneSpec, Volume, VolumeQuantity};
//! use lightquad::volume::tracking::Tracker;
//! use rand::SeedableRng;
//!
//! // A scene as an experiment file writes it, built and evaluated as a job is.
//! let spec: SceneSpec = serde_json::from_value(serde_json::json!({
//!     "ray": {"origin": [-3.0, 0.6, 0.0], "direction": [1.0, 0.0, 0.0]},
//!     "medium": {"type": "constant-sphere", "centre": [0.0, 0.0, 0.0], "radius": 1.0, "kappa": 2.0}
//! }))?;
//! let built = Volume::build(&spec)?;
//! // tau = exp(-kappa * chord), the chord 2 sqrt(1 - 0.6^2) = 1.6.
//! let want = (-2.0 * 1.6f64).exp();
//! assert!((Volume::closed_form(&built, VolumeQuantity::Tau).ok_or("none")?[0] - want).abs() < 1e-15);
//! // A rule and a tracker, named as in the file's "rules".
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! for rule in [r#"{"rule": "gauss-legendre"}"#, r#"{"rule": "residual-ratio-tracking"}"#] {
//!     let method: Method<Tracker> = serde_json::from_str(rule)?;
//!     let out = Volume::evaluate(&built, &method, 8, &mut rng, &[VolumeQuantity::Tau])?;
//!     assert!((out[&VolumeQuantity::Tau].value[0] - want).abs() < 1e-14, "{rule}");
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::sync::Arc;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::printed::{self, Printed};
use super::tracking::{
    Extinction, Tracked, Tracker, Walks, Wanted, expected_lookups, radiance, transmittance,
};
use super::{
    ConstantSphere, DepthScheme, DirectionalLight, EmissionMap, GaussianBlob, GaussianBlobs,
    Medium, ShadowMethod, TransferTable, VolumeResult, VolumeScene, evaluate,
    linear_gradient::LinearGradient, voxel_grid::VoxelGrid,
};
use crate::domain::Vec3;
use crate::error::{QuadError, SpecError};
use crate::estimate::Estimate;
use crate::exact::volume as exact;
use crate::experiment::tagged;
use crate::family::{self, Family, Flag, Measured, Method, Outcome};
use crate::geometry::Ray;
use crate::quadrature::GaussKronrod;
use crate::volume::gaussian_blobs::{MAX_WIDTH, MIN_WIDTH};

/// The volume family.
#[derive(Debug, Clone, Copy)]
pub struct Volume;

/// The scene along one eye ray.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// How `tau(t_n, t)` inside V-E and V-L is computed.
    #[serde(default, deserialize_with = "tagged::named")]
    pub depth_scheme: DepthSchemeSpec,
    /// How the shadow ray's optical depth in V-Lp is computed.
    #[serde(default, deserialize_with = "tagged::named")]
    pub shadow: ShadowSpec,
    /// The eye ray.
    #[serde(deserialize_with = "tagged::object")]
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
    #[serde(default, deserialize_with = "tagged::optional_object")]
    pub light: Option<LightSpec>,
    /// Audit points of docs/EQUATIONS.md whose printed forms the report
    /// evaluates in this scene beside the corrected ones (constant sphere
    /// only; `s` and `exponent` need a light, `background` a background).
    #[serde(default, deserialize_with = "tagged::non_empty_names")]
    pub printed: Vec<Printed>,
}

/// A ray `e + t v`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RaySpec {
    /// `e`.
    #[serde(deserialize_with = "tagged::array")]
    pub origin: [f64; 3],
    /// `v` (normalised; t is arc length).
    #[serde(deserialize_with = "tagged::array")]
    pub direction: [f64; 3],
}

/// A medium: `{"type": <name>, <the variant's fields>}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum MediumSpec {
    /// Constant density `kappa` in a sphere.
    ConstantSphere(ConstantSphereSpec),
    /// A sum of Gaussian blobs.
    GaussianBlobs(GaussianBlobsSpec),
    /// `max(0, base + gradient . (x - centre))` inside a sphere.
    LinearGradient(LinearGradientSpec),
    /// A voxel grid (values at voxel centres, trilinear, `[z][y][x]`).
    VoxelGrid(VoxelGridSpec),
}

/// Reads the tag, then the variant's fields, so that a fault inside names
/// its own path (`scene.medium.kappa`; see [`tagged`]).
impl<'de> Deserialize<'de> for MediumSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const NAMES: [&str; 4] = [
            "constant-sphere",
            "gaussian-blobs",
            "linear-gradient",
            "voxel-grid",
        ];
        let (tag, fields) = tagged::split_tag(serde_json::Value::deserialize(d)?, "type", &NAMES)?;
        match tag.as_str() {
            "constant-sphere" => tagged::variant(fields).map(MediumSpec::ConstantSphere),
            "gaussian-blobs" => tagged::variant(fields).map(MediumSpec::GaussianBlobs),
            "linear-gradient" => tagged::variant(fields).map(MediumSpec::LinearGradient),
            _ => tagged::variant(fields).map(MediumSpec::VoxelGrid),
        }
    }
}

/// Constant density `kappa` in a sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConstantSphereSpec {
    /// Centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// Radius.
    pub radius: f64,
    /// Density.
    pub kappa: f64,
}

/// A sum of Gaussian blobs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GaussianBlobsSpec {
    /// The blobs.
    pub blobs: Vec<BlobSpec>,
}

/// `max(0, base + gradient . (x - centre))` inside a sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LinearGradientSpec {
    /// Centre of the bounding sphere.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// Its radius.
    pub radius: f64,
    /// Density at the centre.
    pub base: f64,
    /// Gradient.
    #[serde(deserialize_with = "tagged::array")]
    pub gradient: [f64; 3],
}

/// A voxel grid (values at voxel centres, trilinear, `[z][y][x]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VoxelGridSpec {
    /// Lower corner.
    #[serde(deserialize_with = "tagged::array")]
    pub min: [f64; 3],
    /// Upper corner.
    #[serde(deserialize_with = "tagged::array")]
    pub max: [f64; 3],
    /// Voxels per axis.
    #[serde(deserialize_with = "tagged::counts")]
    pub resolution: [usize; 3],
    /// Densities, x fastest.
    pub data: Vec<f64>,
}

/// One Gaussian blob.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlobSpec {
    /// Centre.
    #[serde(deserialize_with = "tagged::array")]
    pub centre: [f64; 3],
    /// Peak density.
    pub amplitude: f64,
    /// Width (standard deviation).
    pub width: f64,
}

/// The emission of V-E: a map `c(v)` of the density, or a field of its own;
/// `{"type": <name>, <the variant's fields>}`.
#[derive(Debug, Clone, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum EmissionSpec {
    /// `c(v) = c` inside the medium (where the density is positive).
    Constant(ConstantEmissionSpec),
    /// `c(v) = k v`.
    Proportional(ProportionalEmissionSpec),
    /// A transfer function `c(v)`, piecewise linear.
    Table(TableEmissionSpec),
    /// An emission field of its own, `Le(p)`, independent of the density.
    Field(FieldEmissionSpec),
}

/// Reads the tag, then the variant's fields (see [`MediumSpec`]'s reader).
impl<'de> Deserialize<'de> for EmissionSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        const NAMES: [&str; 4] = ["constant", "proportional", "table", "field"];
        let (tag, fields) = tagged::split_tag(serde_json::Value::deserialize(d)?, "type", &NAMES)?;
        match tag.as_str() {
            "constant" => tagged::variant(fields).map(EmissionSpec::Constant),
            "proportional" => tagged::variant(fields).map(EmissionSpec::Proportional),
            "table" => tagged::variant(fields).map(EmissionSpec::Table),
            _ => tagged::variant(fields).map(EmissionSpec::Field),
        }
    }
}

/// `c(v) = c` inside the medium (where the density is positive).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConstantEmissionSpec {
    /// The constant.
    pub c: f64,
}

/// `c(v) = k v`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ProportionalEmissionSpec {
    /// The factor.
    pub k: f64,
}

/// A transfer function: `c(v)` piecewise linear through `points`
/// `[[v0, c0], [v1, c1], ..]` (at least 2; `v` at least 0 and strictly
/// increasing; `c` finite, at least 0), held at `c0` below `v0` and at the
/// last `c` above the last `v`, and 0 where the density is 0 (a medium
/// emits where its density is positive).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TableEmissionSpec {
    /// The points `[v, c]`.
    #[serde(deserialize_with = "tagged::arrays")]
    pub points: Vec<[f64; 2]>,
}

/// An emission field of its own, `Le(p)`, independent of the density:
/// `I_E = int tau(t_0, t) Le(r(t)) dt`, also where the density is 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FieldEmissionSpec {
    /// The field's shape and values, written as a medium (`Le` is its
    /// density): `constant-sphere`, `gaussian-blobs`, `linear-gradient`
    /// or `voxel-grid`.
    pub field: MediumSpec,
}

/// A directional light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    /// Direction from a point toward the light.
    #[serde(deserialize_with = "tagged::array")]
    pub toward_light: [f64; 3],
    /// Intensity `I_p`.
    pub intensity: f64,
    /// Single-scattering albedo (omit for the document's reduced V-L).
    #[serde(default)]
    pub albedo: Option<f64>,
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

/// A quantity of the volume family.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, JsonSchema,
)]
pub enum VolumeQuantity {
    /// V-tau over the looked-at part of the ray.
    #[serde(rename = "tau")]
    Tau,
    /// `ln tau = -optical depth`: exact where `tau` underflows (optical
    /// depths past ~745), with the optical depth's error estimate.
    #[serde(rename = "ln_tau")]
    LnTau,
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

impl family::Quantity for VolumeQuantity {
    fn name(&self) -> &'static str {
        match self {
            VolumeQuantity::Tau => "tau",
            VolumeQuantity::LnTau => "ln_tau",
            VolumeQuantity::Emission => "I_E",
            VolumeQuantity::Background => "I_B",
            VolumeQuantity::Light => "I_L",
            VolumeQuantity::Total => "I",
        }
    }

    fn all() -> &'static [Self] {
        use VolumeQuantity::*;
        &[Tau, LnTau, Emission, Background, Light, Total]
    }

    /// A transmittance is in [0, 1] and its logarithm at most 0; the
    /// radiances are at least 0 (emission, background and light are).
    fn bounds(&self) -> (f64, f64) {
        match self {
            VolumeQuantity::Tau => (0.0, 1.0),
            VolumeQuantity::LnTau => (f64::NEG_INFINITY, 0.0),
            _ => (0.0, f64::INFINITY),
        }
    }
}

impl family::Estimator for Tracker {
    fn name(&self) -> &'static str {
        Tracker::name(self)
    }
    fn about(&self) -> &'static str {
        match self {
            Tracker::Delta => {
                "delta (Woodcock) tracking, per-span majorants: tau, I_B, and I_E, I_L, I as a \
                 renderer does (emission and light at tentative collisions, shadow rays by ratio \
                 tracking); standard error (Wilson for tau)"
            }
            Tracker::Ratio => {
                "ratio tracking of tau (and I_B), per-span majorants, tentative collisions at \
                 max(1, min(2D, 256/D)) times them (less variance); standard error"
            }
            Tracker::ResidualRatio => {
                "residual ratio tracking of tau (and I_B) with a per-span control extinction; \
                 standard error"
            }
        }
    }
    /// Two walks: a standard error needs them.
    fn min_budget(&self) -> usize {
        2
    }
    fn is_random(&self) -> bool {
        true
    }
    fn all() -> Vec<Self> {
        vec![Tracker::Delta, Tracker::Ratio, Tracker::ResidualRatio]
    }
}

/// Bytes a depth checkpoint of the cumulative scheme holds (`t` and its
/// compensated depth, 24 bytes, in a B-tree's leaves of 11 slots that nodes
/// visited in order leave about half full): 49 bytes an entry allocated at
/// 2e5 trapezoid nodes (tests/memory_checkpoints.rs).
pub const CHECKPOINT_BYTES: f64 = 48.0;

/// The built scene with how it is evaluated.
#[derive(Debug, Clone)]
pub struct Built {
    /// The scene.
    pub scene: VolumeScene,
    /// The inner optical depth of V-E and V-L.
    pub scheme: DepthScheme,
    /// The shadow rays of V-Lp.
    pub shadow: ShadowMethod,
    /// `kappa` of a constant-sphere medium (its closed forms need it).
    pub sphere_kappa: Option<f64>,
    /// The constant sphere, and the printed forms to evaluate in it.
    pub printed: Option<(printed::Sphere, Vec<Printed>)>,
    /// The value of an emission field that is a constant sphere (its closed
    /// form needs it).
    pub field_sphere_value: Option<f64>,
}

impl Family for Volume {
    const NAME: &'static str = "volume";
    const ABOUT: &'static str =
        "volume rendering along one eye ray with a directional light (V-tau .. V-I)";
    const EQUATIONS: &'static [&'static str] = &["V-tau", "V-E", "V-B", "V-Lp", "V-L", "V-I"];
    const BUDGET_UNIT: &'static str =
        "nodes or samples per smooth piece of the ray (walks for tracking)";
    const OVER_BUDGET: &'static str = "every density lookup counts as an evaluation, and the \
        budget is per piece: n goes to each smooth piece of the ray, and V-E and V-L cut their \
        pieces further at optical depths 1, 2, 4, ... (graded pieces); each outer node of V-E and \
        V-L walks the cumulative optical depth from the nearest visited node with 6-point \
        panels (about 12 lookups a node, 6 (2 + log2 n) for rules that visit nodes out of \
        order), or integrates it again with the rule under the nested scheme (about n^2), and \
        shadow rays by quadrature nest a rule too; Gauss–Legendre's error estimate evaluates \
        three companion rules (about 3.5 n in all); a tracker's walk looks the density up at \
        each tentative collision";

    type SceneSpec = SceneSpec;
    type Scene = Built;
    type Quantity = VolumeQuantity;
    type Estimator = Tracker;

    fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
        let scene = scene(spec)?;
        within_reach(spec)?;
        // Products the terms use, checked here rather than failing every job:
        // the fault is lambda's where the medium alone (lambda = 1) is fine.
        let (sigma, depth) = scene.anchored().0.depth_bound();
        if !(sigma.is_finite() && depth.is_finite()) {
            let mut alone = scene.clone();
            alone.lambda = 1.0;
            let (s1, d1) = alone.anchored().0.depth_bound();
            if !(s1.is_finite() && d1.is_finite())
                && let Some(medium) = &spec.medium
            {
                return Err(depth_fault(spec, medium, sigma, depth));
            }
            return Err(SpecError::at(
                "scene.lambda",
                format!(
                    "{}: the optical depth along the ray overflows f64 (the largest extinction \
                     lambda v is {sigma:e}, and times the chord it bounds the depth by {depth:e}), \
                     while with lambda = 1 it is finite: expected a lambda >= 0 whose optical \
                     depth along the ray stays below 1.8e308",
                    crate::error::shortened(scene.lambda.to_string())
                ),
            ));
        }
        if let Some(light) = &scene.light
            && let Some(albedo) = light.albedo
        {
            // V-L's integrand is at most albedo sigma / (4 pi) I_p.
            let per_unit = albedo * sigma / (4.0 * std::f64::consts::PI);
            if !(light.intensity * per_unit).is_finite() {
                return Err(SpecError::at(
                    "scene.light.intensity",
                    format!(
                        "{:e}: times the largest scattering coefficient with the phase, albedo \
                         lambda v / (4 pi) = {per_unit:.2e}, I_L's integrand reaches {:.2e}, beyond \
                         the f64 range: expected an intensity at most {:.1e} in this medium",
                        light.intensity,
                        light.intensity * per_unit,
                        round_down(f64::MAX / per_unit)
                    ),
                ));
            }
        }
        Ok(Built {
            scene,
            scheme: match spec.depth_scheme {
                DepthSchemeSpec::Cumulative => DepthScheme::Cumulative,
                DepthSchemeSpec::Nested => DepthScheme::Nested,
            },
            shadow: match spec.shadow {
                ShadowSpec::ClosedForm => ShadowMethod::ClosedFormWhereAvailable,
                ShadowSpec::Quadrature => ShadowMethod::Quadrature,
            },
            sphere_kappa: match spec.medium {
                Some(MediumSpec::ConstantSphere(ConstantSphereSpec { kappa, .. })) => Some(kappa),
                _ => None,
            },
            printed: printed_forms(spec)?,
            field_sphere_value: match &spec.emission {
                Some(EmissionSpec::Field(FieldEmissionSpec {
                    field: MediumSpec::ConstantSphere(ConstantSphereSpec { kappa, .. }),
                })) => Some(*kappa),
                _ => None,
            },
        })
    }

    /// I, whose bound from the scene's numbers passes the f64 range: each
    /// term was finite and their sum overflowed at run (I_E of 1e308 before
    /// a background of 1.7e308), every job failing. A bound: an I just
    /// below 1.8e308 may be refused, and its terms asked for alone. (Each
    /// term alone is integrated with the integrand rescaled, and fails its
    /// job, with the reason, only where its value itself overflows.)
    fn lacks(built: &Built, q: VolumeQuantity) -> Option<String> {
        let (e, b, l) = term_bounds(&built.scene);
        let beyond = |x: f64| !x.is_finite();
        match q {
            VolumeQuantity::Total if beyond(e + b + l) => Some(format!(
                "I = I_E + I_B + I_L can reach {:.2e}, beyond the f64 range (I_E up to {e:.2e} \
                 from scene.emission, I_B up to {b:.2e} from scene.background, I_L up to {l:.2e} from \
                 scene.light.intensity): expected terms whose sum stays below 1.8e308 (lower the \
                 largest, or ask for the terms alone)",
                e + b + l
            )),
            _ => None,
        }
    }

    fn scene_audit(built: &Built) -> Option<String> {
        let (sphere, forms) = built.printed.as_ref()?;
        let (scene, _) = built.scene.anchored();
        let chord = scene.medium.as_ref().and_then(|m| {
            let pieces = m.support(&scene.ray, scene.t_min, scene.t_max);
            Some((pieces.first()?.start(), pieces.last()?.end()))
        });
        Some(printed::section(&scene, sphere, forms, chord))
    }

    /// Every volume integral is along a ray segment.
    fn dimension(_: &Built, _: VolumeQuantity) -> usize {
        1
    }

    /// Every volume quantity is a scalar.
    fn channels(_: &Built, _: VolumeQuantity) -> usize {
        1
    }

    /// Per smooth piece of the ray (its support pieces split at their break
    /// points: a voxel grid's cells), `n` nodes; V-E and V-L pieces are
    /// further graded at optical depths 1, 2, 4, ... up to where the
    /// transmittance underflows (about `log2 min(D, 746)` more pieces for a
    /// depth bound `D`), and a transfer table's knots cut them too. Per
    /// outer node of V-E and V-L: in the cumulative scheme the optical depth
    /// walks from the nearest visited node with 6-point panels, about
    /// 12 density lookups (two panels) for rules that visit their nodes in
    /// order (trapezoid, Simpson, Gauss–Legendre, stratified), `6 (2 + log2
    /// n)` for those that do not (Gauss–Kronrod, Monte Carlo, Sobol': they
    /// walk the gaps again at every level); it was counted as 1, and the
    /// bundled scenes cost 12 to 80 times the estimate (Gauss–Legendre's
    /// error estimate's rules, 2.5 n more, were not counted either); `n` more where an integral
    /// nests in each node (the nested scheme, shadow rays by quadrature). A
    /// tracker's walk costs 1 plus its expected look-ups
    /// ([`super::tracking::expected_lookups`]; it was `1 + D` for every
    /// tracker, which refused delta tracking through dense media, where a
    /// walk stops at its first look-up, and undercounted ratio tracking,
    /// which draws at `k = min(2 D, 256 / D)` times the bound, up to 22.6,
    /// and the shadow rays).
    fn cost(
        built: &Built,
        method: &Method<Tracker>,
        budget: usize,
        quantity: VolumeQuantity,
    ) -> f64 {
        use VolumeQuantity::*;
        let (scene, _) = built.scene.anchored();
        let (_, depth) = scene.depth_bound();
        let n = budget as f64;
        // Lookups, each as costly as the costliest field's.
        let work = scene
            .medium
            .iter()
            .map(|m| m.lookup_work())
            .chain(match &scene.emission {
                Some(EmissionMap::Field(f)) => Some(f.lookup_work()),
                _ => None,
            })
            .fold(1.0, f64::max);
        let rule = match method {
            Method::Estimator(tracker) => {
                let wanted = |emission, light| Wanted { emission, light };
                let walks = match quantity {
                    Emission => Walks::Radiance(built.shadow, wanted(true, false)),
                    Light => Walks::Radiance(built.shadow, wanted(false, true)),
                    Total => Walks::Radiance(built.shadow, wanted(true, true)),
                    Tau | LnTau | Background => Walks::Transmittance(*tracker),
                };
                // Walks the spans refuse (too deep a bound) fail when the job
                // runs, with their own message; here the bound's depth.
                let per_walk = expected_lookups(&scene, walks).unwrap_or(depth);
                return n * (1.0 + per_walk) * work;
            }
            Method::Rule(rule) => rule,
        };
        // A rule's evaluations at the budget, its error estimate's included
        // (Gauss–Legendre's are 3.5 n).
        let e = crate::quadrature::Rule::evaluations(rule, budget, 1);
        let support = scene
            .medium
            .as_ref()
            .map(|m| m.support(&scene.ray, scene.t_min, scene.t_max))
            .unwrap_or_default();
        let smooth = (support.iter().map(|p| p.pieces().count()).sum::<usize>() as f64).max(1.0);
        let knots = match &scene.emission {
            Some(super::EmissionMap::Table(t)) => 2.0 * t.knots().count() as f64,
            Some(super::EmissionMap::Field(f)) => f
                .support(&scene.ray, scene.t_min, scene.t_max)
                .iter()
                .map(|p| p.pieces().count() as f64)
                .sum(),
            _ => 0.0,
        };
        // Where the transmittance from t_n has underflowed the pieces are
        // skipped (exp(-745.2) is 0).
        let graded = smooth + support.len() as f64 * depth.clamp(1.0, 746.0).log2();
        let nested = built.scheme == DepthScheme::Nested;
        // Shadow rays by quadrature: asked for, or the medium has no closed
        // form for them.
        let shadow = built.shadow == ShadowMethod::Quadrature
            || scene.medium.as_ref().is_some_and(|m| {
                m.density_integral(&scene.ray, scene.t_min, scene.t_max)
                    .is_none()
            });
        // Rules that visit their nodes out of order walk the gaps again at
        // every level of their refinement; the others about twice.
        let in_order = !matches!(
            crate::quadrature::Rule::name(rule),
            "gauss-kronrod" | "monte-carlo" | "sobol"
        );
        // Each piece's integral costs its evaluations and the call around
        // them (the rule's setup and bookkeeping, about PIECE_OVERHEAD
        // lookups): with thousands of voxels along a ray and a few nodes a
        // piece the calls cost more than the lookups (2000 voxels at n = 4,
        // nested: 93 ns an evaluation against about 20 on one piece).
        let pieces = |e: f64| (e + PIECE_OVERHEAD) * smooth;
        let inner = if nested {
            pieces(e)
        } else if in_order {
            12.0
        } else {
            6.0 * (2.0 + n.max(1.0).log2())
        };
        let shadow = if shadow { pieces(e) } else { 1.0 };
        // V-tau is always evaluated; a term the scene lacks costs nothing.
        let tau = pieces(e);
        let emission = if scene.emission.is_some() {
            (graded + knots) * e * (1.0 + inner)
        } else {
            0.0
        };
        let light = if scene.light.is_some() && scene.medium.is_some() {
            graded * e * (1.0 + inner + shadow)
        } else {
            0.0
        };
        work * match quantity {
            Tau | LnTau | Background => tau,
            Emission => tau + emission,
            Light => tau + light,
            Total => tau + emission + light,
        }
    }

    /// The rule's node table, and a second one of the same size under the
    /// nested scheme (the inner optical depth's rule beside the outer one);
    /// under the cumulative scheme, V-E and V-L also hold the depth
    /// checkpoints of the graded piece being integrated: one entry per node
    /// the outer rule visits (its evaluations, an error estimate's rules
    /// included, and the piece's two ends), [`CHECKPOINT_BYTES`] each.
    fn memory(
        built: &Built,
        method: &Method<Tracker>,
        budget: usize,
        quantity: VolumeQuantity,
    ) -> f64 {
        use VolumeQuantity::*;
        let Method::Rule(rule) = method else {
            return 0.0;
        };
        let nested =
            built.scheme == DepthScheme::Nested || built.shadow == ShadowMethod::Quadrature;
        let scene = &built.scene;
        let emission = scene.emission.is_some();
        let light = scene.light.is_some() && scene.medium.is_some();
        let outer = match quantity {
            Emission => emission,
            Light => light,
            Total => emission || light,
            Tau | LnTau | Background => false,
        };
        let tables = if outer && nested { 2.0 } else { 1.0 };
        let checkpoints = if outer && built.scheme == DepthScheme::Cumulative {
            CHECKPOINT_BYTES * (crate::quadrature::Rule::evaluations(rule, budget, 1) + 2.0)
        } else {
            0.0
        };
        tables * crate::quadrature::Rule::memory(rule, budget, 1) + checkpoints
    }

    /// Delta tracking estimates every term a renderer's walk scores
    /// ([`super::tracking::radiance`]); ratio and residual ratio tracking
    /// estimate transmittance only, so `tau` and `I_B = I_b tau`. None
    /// estimates `ln_tau` (the logarithm of a mean is biased).
    fn estimates(tracker: &Tracker) -> &'static [VolumeQuantity] {
        use VolumeQuantity::*;
        match tracker {
            Tracker::Delta => &[Tau, Background, Emission, Light, Total],
            Tracker::Ratio | Tracker::ResidualRatio => &[Tau, Background],
        }
    }

    /// Delta tracking scores `c(v)` at its collisions: an emission field of
    /// its own (which may emit where the medium does not) is not a map of
    /// the density, so I_E and I are refused for it.
    fn refuses(built: &Built, tracker: &Tracker, q: VolumeQuantity) -> Option<String> {
        let field = matches!(built.scene.emission, Some(EmissionMap::Field(_)));
        let emits = matches!(q, VolumeQuantity::Emission | VolumeQuantity::Total);
        (*tracker == Tracker::Delta && field && emits).then(|| {
            "its collisions score c(v) of the density, and the scene's emission is a field of \
             its own (scene.emission.type = field): integrate it with a quadrature rule"
                .to_string()
        })
    }

    fn evaluate(
        built: &Built,
        method: &Method<Tracker>,
        budget: usize,
        rng: &mut rand_pcg::Pcg64,
        quantities: &[VolumeQuantity],
    ) -> Result<Outcome<VolumeQuantity>, QuadError> {
        match method {
            Method::Rule(rule) => {
                let scene = needed(&built.scene, quantities);
                let res = evaluate(&scene, rule, budget, built.scheme, built.shadow, rng)?;
                Ok(collect(&res, quantities))
            }
            Method::Estimator(tracker) => estimate(built, *tracker, budget, rng, quantities),
        }
    }

    fn closed_form(built: &Built, q: VolumeQuantity) -> Option<Vec<f64>> {
        closed_form(built, q).map(|v| vec![v])
    }

    fn closed_forms_available() -> &'static str {
        "closed forms: tau for the constant sphere, blobs and gradient; I_E for the constant \
         sphere (constant, proportional or table emission), for an emission field that is a \
         constant sphere seen through a constant sphere, and for any emission field with a \
         closed-form line integral where nothing absorbs; I_L for the constant sphere with the light along the ray"
    }

    /// Adaptive Gauss–Kronrod (relative tolerance 1e-13) with up to `n`
    /// bisections per graded piece, cumulative depth, closed-form shadow rays
    /// where the medium has them. Adaptive because the integrands of V-L are
    /// not smooth everywhere a piece boundary could say: a shadow ray that
    /// crosses an edge of a voxel grid's cells, or grazes a sphere, puts a
    /// kink into `I_p(t)` at a `t` no break point knows, and a fixed
    /// Gauss–Legendre rule converges there only algebraically (2.6e-9 between
    /// 512 and 1024 nodes on the bundled voxel grid).
    fn converged(
        built: &Built,
        n: usize,
        quantities: &[VolumeQuantity],
    ) -> Result<Outcome<VolumeQuantity>, QuadError> {
        let rule = GaussKronrod {
            abs_tol: 0.0,
            rel_tol: 1e-13,
        };
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
        // Only the terms asked for: I_B alone computed I_L too.
        let res = evaluate(
            &needed(&built.scene, quantities),
            &rule,
            15 + 30 * n,
            DepthScheme::Cumulative,
            ShadowMethod::ClosedFormWhereAvailable,
            &mut rng,
        )?;
        Ok(collect(&res, quantities))
    }

    fn settings(spec: &SceneSpec) -> String {
        format!(
            "depth scheme {:?}, shadow rays {:?}; every rule gets the budget on each smooth piece of \
             the ray, and V-E and V-L pieces are further cut at optical depths 1, 2, 4, 8, ... from \
             their start (measured with the majorant) where a piece is thicker than 2, so a thick \
             medium's boundary layer is resolved (a piece of depth D costs about 1 + log2 D budgets)",
            spec.depth_scheme, spec.shadow
        )
    }

    fn audit() -> Option<String> {
        Some(super::audit::markdown())
    }
}

/// The scene with only the terms `quantities` need (every term feeds V-I;
/// V-tau is always evaluated): asking for tau alone costs no emission or
/// light integral.
fn needed(scene: &VolumeScene, quantities: &[VolumeQuantity]) -> VolumeScene {
    let wants = |q: VolumeQuantity| {
        quantities
            .iter()
            .any(|&x| x == q || x == VolumeQuantity::Total)
    };
    let mut out = scene.clone();
    if !wants(VolumeQuantity::Emission) {
        out.emission = None;
    }
    if !wants(VolumeQuantity::Background) {
        out.background = None;
    }
    if !wants(VolumeQuantity::Light) {
        out.light = None;
    }
    out
}

/// `quantities` by `tracker` with `budget` walks: `tau` and `I_B` from
/// [`transmittance`] alone, anything else from one set of delta-tracking
/// walks ([`radiance`]); a quantity the tracker does not estimate is an error
/// (validation refuses it first, [`Volume::estimates`]).
fn estimate(
    built: &Built,
    tracker: Tracker,
    budget: usize,
    rng: &mut rand_pcg::Pcg64,
    quantities: &[VolumeQuantity],
) -> Result<Outcome<VolumeQuantity>, QuadError> {
    let can = <Volume as Family>::estimates(&tracker);
    if let Some(q) = quantities.iter().find(|q| !can.contains(q)) {
        let names: Vec<_> = can.iter().map(family::Quantity::name).collect();
        return Err(QuadError::invalid(
            "quantity",
            family::Quantity::name(q),
            format!("one of {} for {}", names.join(", "), tracker.name()),
        ));
    }
    // Measured from the start of the medium's support, as the quadrature terms are
    // (VolumeScene::anchored).
    let (anchored, _) = built.scene.anchored();
    let scene = &anchored;
    let background = scene.background.unwrap_or(0.0);
    let only_tau = quantities
        .iter()
        .all(|q| matches!(q, VolumeQuantity::Tau | VolumeQuantity::Background));
    let out: Vec<(VolumeQuantity, Tracked)> = if only_tau {
        let tau = match scene.medium.as_deref() {
            // No medium: tau = 1 with no work.
            None => Tracked {
                value: 1.0,
                error: 0.0,
                evaluations: 0,
                walks: budget as u64,
                all_alike: false,
            },
            Some(medium) => {
                let sigma = Extinction {
                    medium,
                    lambda: scene.lambda,
                };
                let (t0, t1) = (scene.t_min, scene.t_max);
                transmittance(tracker, sigma, &scene.ray, t0, t1, budget, rng)?
            }
        };
        quantities
            .iter()
            .map(|&q| {
                let s = if q == VolumeQuantity::Background {
                    background
                } else {
                    1.0
                };
                let t = Tracked {
                    value: s * tau.value,
                    error: s * tau.error,
                    ..tau
                };
                (q, t)
            })
            .collect()
    } else {
        let wanted = Wanted {
            emission: quantities
                .iter()
                .any(|q| matches!(q, VolumeQuantity::Emission | VolumeQuantity::Total)),
            light: quantities
                .iter()
                .any(|q| matches!(q, VolumeQuantity::Light | VolumeQuantity::Total)),
        };
        let r = radiance(scene, built.shadow, wanted, budget, rng)?;
        quantities
            .iter()
            .filter_map(|&q| {
                let t = match q {
                    VolumeQuantity::Tau => r.tau,
                    VolumeQuantity::Background => r.background,
                    VolumeQuantity::Emission => r.emission,
                    VolumeQuantity::Light => r.light,
                    VolumeQuantity::Total => r.total,
                    // Refused above.
                    VolumeQuantity::LnTau => return None,
                };
                Some((q, t))
            })
            .collect()
    };
    Ok(out
        .into_iter()
        .map(|(q, t)| {
            let m = Measured::scalar(t.value, t.error, t.evaluations);
            let m = if t.all_alike {
                m.flagged(Flag::AllWalksAlike { walks: t.walks })
            } else {
                m
            };
            (q, m)
        })
        .collect())
}

/// The quantities asked for from one evaluation of the terms. A term the
/// scene does not have is 0 at no cost.
fn collect(res: &VolumeResult, quantities: &[VolumeQuantity]) -> Outcome<VolumeQuantity> {
    let term = |t: Option<super::Term>| t.map_or(Measured::scalar(0.0, 0.0, 0), measured);
    quantities
        .iter()
        .map(|&q| {
            let m = match q {
                VolumeQuantity::Tau => {
                    let tau = measured(super::Term {
                        value: res.transmittance,
                        error: super::terms::transmittance_error(
                            res.transmittance,
                            res.optical_depth.error,
                        ),
                        ..res.optical_depth
                    });
                    if res.underflow {
                        tau.flagged(Flag::Underflow)
                    } else {
                        tau
                    }
                }
                VolumeQuantity::LnTau => measured(super::Term {
                    value: res.log_transmittance,
                    ..res.optical_depth
                }),
                VolumeQuantity::Emission => term(res.emission),
                // I_B = B tau underflows with tau: flagged as tau is
                // (`ln I_B = ln B + ln tau`).
                VolumeQuantity::Background => {
                    let b = term(res.background);
                    if res.underflow && b.value.iter().all(|v| v.abs() < f64::MIN_POSITIVE) {
                        b.flagged(Flag::Underflow)
                    } else {
                        b
                    }
                }
                VolumeQuantity::Light => term(res.light),
                VolumeQuantity::Total => total(res),
            };
            (q, m)
        })
        .collect()
}

/// A term as a measured value, flagged when the rule doubted its estimate.
fn measured(t: super::Term) -> Measured {
    let m = Measured::scalar(t.value, t.error, t.evaluations);
    if t.reliable {
        m
    } else {
        m.flagged(Flag::UnreliableEstimate)
    }
}

/// V-I with the errors and costs of its terms, flagged when the sum lost
/// digits to cancellation. The terms' errors combine as their kinds do
/// ([`Estimate::combine`]): independent standard errors in quadrature.
fn total(res: &VolumeResult) -> Measured {
    let terms = [res.emission, res.background, res.light];
    let sum = terms
        .iter()
        .flatten()
        .map(|t| Estimate {
            value: t.value,
            error: t.error,
            evaluations: t.evaluations,
            kind: t.kind,
            reliable: t.reliable,
        })
        .fold(Estimate::zero(), Estimate::combine);
    // V-B reuses tau's evaluations: count them once.
    let shared = res.background.map_or(0, |b| b.evaluations);
    let evaluations = res.optical_depth.evaluations + sum.evaluations - shared;
    let parts = terms.iter().flatten().map(|t| t.value.abs()).sum::<f64>();
    let m = measured(super::Term {
        id: "V-I",
        value: res.total,
        error: sum.error,
        evaluations,
        kind: sum.kind,
        reliable: sum.reliable,
    });
    if parts > 0.0 && res.total.abs() < 1e-6 * parts {
        m.flagged(Flag::Cancellation { parts })
    } else {
        m
    }
}

/// The closed form of a quantity for this scene, when `exact` has one.
fn closed_form(built: &Built, q: VolumeQuantity) -> Option<f64> {
    // The chord from the start of the medium's support, where its length
    // keeps its digits (VolumeScene::anchored).
    let (scene, _) = built.scene.anchored();
    let scene = &scene;
    let ray = scene.ray;
    // `ln tau = -lambda int v_r dt` (V-tau), kept in log space.
    let ln_tau = match &scene.medium {
        None => 0.0,
        Some(m) => -scene.lambda * m.density_integral(&ray, scene.t_min, scene.t_max)?,
    };
    let tau = ln_tau.exp();
    // The constant sphere's chord inside the looked-at part, and whether that
    // part holds the whole chord (the light closed forms need it).
    let sphere = match built.sphere_kappa {
        Some(kappa) => scene
            .medium
            .as_ref()
            .and_then(|m| {
                m.support(&ray, scene.t_min, scene.t_max)
                    .first()
                    .map(|s| (s.start(), s.end()))
            })
            .map(|(a, b)| {
                (
                    scene.lambda * kappa,
                    b - a,
                    a > scene.t_min && b < scene.t_max,
                )
            }),
        _ => None,
    };
    // A ray that misses the medium: the density-driven terms (emission by a
    // map of the density, single scattering) are 0 along it.
    let missed = scene
        .medium
        .as_ref()
        .is_some_and(|m| m.support(&ray, scene.t_min, scene.t_max).is_empty());
    let emission = || -> Option<f64> {
        let Some(map) = &scene.emission else {
            return Some(0.0);
        };
        if let EmissionMap::Field(field) = map {
            // Nothing absorbs along the ray (ln tau = 0 exactly): I_E is the
            // field's line integral.
            if ln_tau == 0.0 {
                return field.density_integral(&ray, scene.t_min, scene.t_max);
            }
            // A constant-sphere field through a constant-sphere medium: a
            // constant on one interval seen through a constant extinction on
            // another (exact::emission_field_interval).
            let c = built.field_sphere_value?;
            let chord = |m: &dyn Medium| {
                m.support(&ray, scene.t_min, scene.t_max)
                    .first()
                    .map(|s| (s.start(), s.end()))
            };
            let Some(emits) = chord(field.as_ref()) else {
                return Some(0.0);
            };
            let (sigma, _, _) = sphere?;
            let absorbs = chord(scene.medium.as_deref()?)?;
            return Some(exact::emission_field_interval(sigma, absorbs, c, emits));
        }
        if scene.medium.is_none() || missed {
            return Some(0.0);
        }
        let (sigma, chord, _) = sphere?;
        let kappa = built.sphere_kappa?;
        // `c(v)` on the chord, where `v = kappa` (a map of the density emits
        // only where it is positive: nothing from a sphere of kappa 0).
        Some(exact::emission(sigma, chord, map.at(kappa)))
    };
    let light = || -> Option<f64> {
        let Some(light) = scene.light else {
            return Some(0.0);
        };
        if scene.medium.is_none() || missed {
            return Some(0.0);
        }
        let (sigma, chord, whole) = sphere?;
        if !whole {
            return None;
        }
        let cos = light.toward_light.dot(&ray.dir);
        if (cos - 1.0).abs() < 1e-12 {
            Some(exact::light_ahead(
                sigma,
                chord,
                light.intensity,
                light.albedo,
            ))
        } else if (cos + 1.0).abs() < 1e-12 {
            Some(exact::light_behind(
                sigma,
                chord,
                light.intensity,
                light.albedo,
            ))
        } else {
            None
        }
    };
    let background = scene.background.unwrap_or(0.0) * tau;
    match q {
        VolumeQuantity::Tau => Some(tau),
        VolumeQuantity::LnTau => Some(ln_tau),
        VolumeQuantity::Background => Some(background),
        VolumeQuantity::Emission => emission(),
        VolumeQuantity::Light => light(),
        VolumeQuantity::Total => Some(emission()? + background + light()?),
    }
}

/// A field of a medium that scales its optical depth bound: its path below
/// `scene.medium`, its value, and how to set it.
type DepthField = (String, f64, Box<dyn Fn(&mut MediumSpec, f64)>);

/// The fields whose size scales a medium's optical depth along a ray: the
/// densities (kappa, amplitudes, base, gradient, the voxel grid's largest
/// value) and the lengths (radius, widths).
fn depth_fields(m: &MediumSpec) -> Vec<DepthField> {
    let mut out: Vec<DepthField> = Vec::new();
    match m {
        MediumSpec::ConstantSphere(s) => {
            out.push((
                "kappa".into(),
                s.kappa,
                Box::new(|m, x| {
                    if let MediumSpec::ConstantSphere(s) = m {
                        s.kappa = x;
                    }
                }),
            ));
            out.push((
                "radius".into(),
                s.radius,
                Box::new(|m, x| {
                    if let MediumSpec::ConstantSphere(s) = m {
                        s.radius = x;
                    }
                }),
            ));
        }
        MediumSpec::GaussianBlobs(b) => {
            for (i, blob) in b.blobs.iter().enumerate() {
                out.push((
                    format!("blobs[{i}].amplitude"),
                    blob.amplitude,
                    Box::new(move |m, x| {
                        if let MediumSpec::GaussianBlobs(b) = m {
                            b.blobs[i].amplitude = x;
                        }
                    }),
                ));
                out.push((
                    format!("blobs[{i}].width"),
                    blob.width,
                    Box::new(move |m, x| {
                        if let MediumSpec::GaussianBlobs(b) = m {
                            b.blobs[i].width = x;
                        }
                    }),
                ));
            }
        }
        MediumSpec::LinearGradient(g) => {
            out.push((
                "radius".into(),
                g.radius,
                Box::new(|m, x| {
                    if let MediumSpec::LinearGradient(g) = m {
                        g.radius = x;
                    }
                }),
            ));
            out.push((
                "base".into(),
                g.base,
                Box::new(|m, x| {
                    if let MediumSpec::LinearGradient(g) = m {
                        g.base = x;
                    }
                }),
            ));
            for k in 0..3 {
                out.push((
                    format!("gradient[{k}]"),
                    g.gradient[k],
                    Box::new(move |m, x| {
                        if let MediumSpec::LinearGradient(g) = m {
                            g.gradient[k] = x;
                        }
                    }),
                ));
            }
        }
        MediumSpec::VoxelGrid(v) => {
            if let Some((i, &x)) = v
                .data
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
            {
                out.push((
                    format!("data[{i}]"),
                    x,
                    Box::new(move |m, x| {
                        if let MediumSpec::VoxelGrid(v) = m {
                            v.data[i] = x;
                        }
                    }),
                ));
            }
        }
    }
    out
}

/// Whether the scene of `spec` fails to build or its optical depth bound
/// along the ray is not finite.
fn depth_overflows(spec: &SceneSpec) -> bool {
    scene(spec).map_or(true, |s| {
        let (sigma, depth) = s.anchored().0.depth_bound();
        !(sigma.is_finite() && depth.is_finite())
    })
}

/// `x` (> 0) rounded down to two significant digits, in scientific notation.
fn two_digits_down(x: f64) -> String {
    let e = x.log10().floor();
    let mut m = (x / 10f64.powf(e) * 10.0).floor() / 10.0;
    // The division can round a mantissa of 10 down to 9.99...
    if m >= 10.0 {
        m = 9.9;
    }
    format!("{m:.1}e{e}")
}

/// The error for a medium whose optical depth along the ray overflows f64
/// with lambda = 1 (`sigma` and `depth` its bound as given), at the field
/// that causes it: the one field of [`depth_fields`] that brings the bound
/// below 1.8e308 alone when set to 1 (the most extreme of them, if several
/// do), with the largest value it may take, the others as given, found by
/// bisection. A medium no single field can repair is refused at its largest
/// field, saying so.
fn depth_fault(spec: &SceneSpec, medium: &MediumSpec, sigma: f64, depth: f64) -> SpecError {
    let with = |set: &dyn Fn(&mut MediumSpec, f64), x: f64| {
        let mut s = spec.clone();
        if let Some(m) = s.medium.as_mut() {
            set(m, x);
        }
        s
    };
    let fields: Vec<DepthField> = depth_fields(medium)
        .into_iter()
        .filter(|(_, x, _)| x.abs() > 1.0)
        .collect();
    let culprit = fields
        .iter()
        .filter(|(_, x, set)| !depth_overflows(&with(set.as_ref(), x.signum())))
        .reduce(|a, b| if b.1.abs() > a.1.abs() { b } else { a });
    let overflow = format!(
        "the optical depth along the ray overflows f64 (lambda = {}; the largest extinction \
         lambda v is {sigma:e}, and times the chord it bounds the depth by {depth:e})",
        crate::error::shortened(spec.lambda.unwrap_or(1.0).to_string())
    );
    let Some((field, x, set)) = culprit else {
        let Some((field, x, _)) = fields
            .iter()
            .reduce(|a, b| if b.1.abs() > a.1.abs() { b } else { a })
        else {
            return SpecError::at(
                "scene.medium",
                format!(
                    "{overflow}: expected a medium whose optical depth along the ray stays \
                     below 1.8e308"
                ),
            );
        };
        let others: Vec<String> = fields
            .iter()
            .filter(|(f, y, _)| f != field && y.abs() > 1.0)
            .map(|(f, _, _)| format!("scene.medium.{f}"))
            .collect();
        return SpecError::at(
            format!("scene.medium.{field}"),
            format!(
                "{}: {overflow}, and no value of this field alone brings it below 1.8e308: \
                 expected smaller values here and at {}",
                crate::error::shortened(x.to_string()),
                others.join(", ")
            ),
        );
    };
    // The largest magnitude in [1, |x|] whose bound stays finite, bisected
    // on the exponent.
    let (mut lo, mut hi) = (0.0f64, x.abs().log2());
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if depth_overflows(&with(set.as_ref(), x.signum() * mid.exp2())) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let largest = two_digits_down(lo.exp2());
    let range = if *x < 0.0 {
        format!("at least -{largest}")
    } else {
        format!("at most {largest}")
    };
    SpecError::at(
        format!("scene.medium.{field}"),
        format!(
            "{}: {overflow}: expected {field} {range} along this ray, with lambda and the \
             medium's other fields as given (the optical depth must stay below 1.8e308)",
            crate::error::shortened(x.to_string())
        ),
    )
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

fn finite(path: &str, x: f64, accepted: &str) -> Result<f64, SpecError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(SpecError::at(path, format!("{x} is not {accepted}")))
    }
}

/// `x` when finite and `>= 0`, else an error at `path`.
fn non_negative(path: &str, x: f64) -> Result<f64, SpecError> {
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(SpecError::at(
            path,
            format!(
                "{x} is not a finite number >= 0 (emitted radiance; absorption belongs to sigma)"
            ),
        ))
    }
}

/// The medium (or emission field) of `spec`, errors anchored at `at`.
fn medium(spec: &MediumSpec, at: &str) -> Result<Arc<dyn Medium>, SpecError> {
    Ok(match spec {
        MediumSpec::ConstantSphere(ConstantSphereSpec {
            centre,
            radius,
            kappa,
        }) => Arc::new(
            ConstantSphere::new(vec3(*centre), *radius, *kappa)
                .map_err(|e| SpecError::from_quad(at, e))?,
        ),
        MediumSpec::GaussianBlobs(GaussianBlobsSpec { blobs }) => Arc::new(
            GaussianBlobs::new(
                blobs
                    .iter()
                    .map(|b| GaussianBlob {
                        centre: vec3(b.centre),
                        amplitude: b.amplitude,
                        width: b.width,
                    })
                    .collect(),
            )
            .map_err(|e| SpecError::from_quad(at, e))?,
        ),
        MediumSpec::LinearGradient(LinearGradientSpec {
            centre,
            radius,
            base,
            gradient,
        }) => Arc::new(
            LinearGradient::new(vec3(*centre), *radius, *base, vec3(*gradient))
                .map_err(|e| SpecError::from_quad(at, e))?,
        ),
        MediumSpec::VoxelGrid(VoxelGridSpec {
            min,
            max,
            resolution,
            data,
        }) => Arc::new(
            VoxelGrid::new(vec3(*min), vec3(*max), *resolution, data.clone())
                .map_err(|e| SpecError::from_quad(at, e))?,
        ),
    })
}

/// Builds the scene, naming the path of any bad number.
/// The printed forms an experiment asks for, checked against its scene.
fn printed_forms(spec: &SceneSpec) -> Result<Option<(printed::Sphere, Vec<Printed>)>, SpecError> {
    if spec.printed.is_empty() {
        return Ok(None);
    }
    let Some(MediumSpec::ConstantSphere(ConstantSphereSpec {
        centre,
        radius,
        kappa,
    })) = spec.medium
    else {
        return Err(SpecError::at(
            "scene.printed",
            "the printed formulas are written for a constant-density sphere: give a \
             constant-sphere medium, or leave printed out"
                .to_string(),
        ));
    };
    for (i, p) in spec.printed.iter().enumerate() {
        let name = serde_json::to_string(p).unwrap_or_default();
        if spec.printed[..i].contains(p) {
            return Err(SpecError::at(
                format!("scene.printed[{i}]"),
                format!("{name} is named twice: name each audit point once"),
            ));
        }
        let missing = match p {
            Printed::S | Printed::Exponent if spec.light.is_none() => Some("a light"),
            Printed::Background if spec.background.is_none() => Some("a background"),
            _ => None,
        };
        if let Some(what) = missing {
            return Err(SpecError::at(
                format!("scene.printed[{i}]"),
                format!(
                    "{name} is a printed form of a term the scene does not have: give it {what}"
                ),
            ));
        }
    }
    // The printed light formulas square the radius unscaled, as the
    // document writes them: outside [1e-150, 1e150] R^2 leaves the normal
    // numbers (radius 1e308 made their evaluation NaN; 1e-200 made the
    // printed root real where it is not), as for a blob's width.
    let light_forms = spec
        .printed
        .iter()
        .any(|p| matches!(p, Printed::S | Printed::Exponent));
    if light_forms && !(MIN_WIDTH..=MAX_WIDTH).contains(&radius) {
        return Err(SpecError::at(
            "scene.medium.radius",
            format!(
                "{}: expected a radius in [{MIN_WIDTH:e}, {MAX_WIDTH:e}] where the printed light \
                 formulas (scene.printed \"s\" or \"exponent\") are evaluated: they square it, \
                 and its square must be a normal number",
                crate::error::shortened(radius.to_string())
            ),
        ));
    }
    Ok(Some((
        printed::Sphere {
            centre: Vec3::new(centre[0], centre[1], centre[2]),
            radius,
            kappa,
        },
        spec.printed.clone(),
    )))
}

/// `x` with two significant digits, rounded toward 0 (a bound to print).
fn round_down(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let scale = 10f64.powi(x.log10().floor() as i32 - 1);
    (x / scale).floor() * scale
}

/// Upper bounds of I_E, I_B and I_L from the scene's numbers: V-E's largest
/// emitted radiance on each piece of the support times its length (for
/// emission proportional to the density, `k v`, at most `k / lambda` as
/// well: `int tau lambda v = 1 - tau`); I_b; and I_p albedo / (4 pi) times
/// `min(1, the depth bound)` with an albedo (the scattered fraction of the
/// light), I_p times the chord in the document's reduced form.
fn term_bounds(scene: &VolumeScene) -> (f64, f64, f64) {
    let (scene, _) = scene.anchored();
    let pieces = |m: &Arc<dyn Medium>| -> Vec<(f64, f64)> {
        m.support(&scene.ray, scene.t_min, scene.t_max)
            .iter()
            .map(|p| {
                (
                    m.max_density(&scene.ray, p.start(), p.end()),
                    p.end() - p.start(),
                )
            })
            .collect()
    };
    let medium = scene.medium.as_ref().map(pieces).unwrap_or_default();
    let chord: f64 = medium.iter().map(|(_, len)| len).sum();
    let mass: f64 = medium.iter().map(|(v, len)| v * len).sum();
    let emission = match &scene.emission {
        None => 0.0,
        Some(EmissionMap::Constant(c)) => c * chord,
        Some(EmissionMap::Proportional(k)) if scene.lambda > 0.0 => {
            k * mass.min(1.0 / scene.lambda)
        }
        Some(EmissionMap::Proportional(k)) => k * mass,
        Some(EmissionMap::Table(t)) => t.points().iter().map(|p| p.1).fold(0.0, f64::max) * chord,
        Some(EmissionMap::Field(f)) => pieces(f).iter().map(|(v, len)| v * len).sum(),
    };
    let light = scene.light.as_ref().map_or(0.0, |l| match l.albedo {
        Some(a) => l.intensity * a / (4.0 * std::f64::consts::PI) * (scene.lambda * mass).min(1.0),
        None => l.intensity * chord,
    });
    (emission, scene.background.unwrap_or(0.0), light)
}

/// The largest distance from the ray's origin to a sphere's centre that is
/// accepted: the chord is found from `c - o` and its square, which
/// overflows f64 beyond about 1.34e154 (an origin at -1e155 before a sphere
/// at 1e154 was read as a miss, and every term as 0, with no fault).
pub const MAX_REACH: f64 = 1e154;

/// Refuses a sphere (of a constant or linear-gradient medium, or such an
/// emission field) whose centre's distance from the ray's origin, or its
/// square, overflows f64, at the centre's path. (Gaussian blobs and voxel
/// grids meet the ray without that square.)
fn within_reach(spec: &SceneSpec) -> Result<(), SpecError> {
    let origin = vec3(spec.ray.origin);
    let centre = |m: &MediumSpec| match m {
        MediumSpec::ConstantSphere(s) => Some(s.centre),
        MediumSpec::LinearGradient(g) => Some(g.centre),
        _ => None,
    };
    let field = match &spec.emission {
        Some(EmissionSpec::Field(FieldEmissionSpec { field })) => Some(field),
        _ => None,
    };
    let spheres = [
        ("scene.medium", spec.medium.as_ref()),
        ("scene.emission.field", field),
    ];
    for (at, m) in spheres {
        let Some(c) = m.and_then(centre) else {
            continue;
        };
        let d = vec3(c) - origin;
        let scale = d.amax();
        let distance = match scale {
            0.0 => 0.0,
            s if s.is_finite() => s * (d / s).norm(),
            _ => f64::INFINITY,
        };
        if distance.is_nan() || distance > MAX_REACH {
            return Err(SpecError::at(
                format!("{at}.centre"),
                format!(
                    "{c:?} is {distance:.2e} from the ray's origin {:?}: expected a centre within \
                     {MAX_REACH:e} of scene.ray.origin (the chord is found from the square of \
                     that distance, which overflows f64 beyond 1.3e154)",
                    spec.ray.origin
                ),
            ));
        }
    }
    Ok(())
}

fn scene(s: &SceneSpec) -> Result<VolumeScene, SpecError> {
    let ray = Ray::new(vec3(s.ray.origin), vec3(s.ray.direction))
        .map_err(|e| SpecError::from_quad("scene.ray", e))?;
    let mut scene = VolumeScene::new(ray);
    if let Some(t) = s.t_min {
        scene.t_min = finite("scene.t_min", t, "a finite number")?;
    }
    if let Some(t) = s.t_max {
        if t.is_nan() || t < scene.t_min {
            return Err(SpecError::at(
                "scene.t_max",
                format!("{t} must be >= t_min = {} (t_f >= t_n)", scene.t_min),
            ));
        }
        scene.t_max = t;
    }
    if let Some(l) = s.lambda {
        if !(l.is_finite() && l >= 0.0) {
            return Err(SpecError::at(
                "scene.lambda",
                format!("{l} is not a finite number >= 0"),
            ));
        }
        scene.lambda = l;
    }
    scene.medium = s
        .medium
        .as_ref()
        .map(|m| medium(m, "scene.medium"))
        .transpose()?;
    scene.emission = match &s.emission {
        None => None,
        // Emitted radiance is not negative (absorption belongs to sigma), as
        // for a table's values.
        Some(EmissionSpec::Constant(ConstantEmissionSpec { c })) => {
            Some(EmissionMap::Constant(non_negative("scene.emission.c", *c)?))
        }
        Some(EmissionSpec::Proportional(ProportionalEmissionSpec { k })) => Some(
            EmissionMap::Proportional(non_negative("scene.emission.k", *k)?),
        ),
        Some(EmissionSpec::Table(TableEmissionSpec { points })) => Some(EmissionMap::Table(
            TransferTable::new(points.iter().map(|p| (p[0], p[1])).collect())
                .map_err(|e| SpecError::from_quad("scene.emission", e))?,
        )),
        Some(EmissionSpec::Field(FieldEmissionSpec { field })) => {
            Some(EmissionMap::Field(medium(field, "scene.emission.field")?))
        }
    };
    if let Some(b) = s.background {
        if !(b.is_finite() && b >= 0.0) {
            return Err(SpecError::at(
                "scene.background",
                format!("{b} is not a finite radiance >= 0"),
            ));
        }
        scene.background = Some(b);
    }
    if let Some(l) = &s.light {
        scene.light = Some(
            DirectionalLight::new(vec3(l.toward_light), l.intensity, l.albedo)
                .map_err(|e| SpecError::from_quad("scene.light", e))?,
        );
    }
    Ok(scene)
}

/// The cost of one call of a rule on a piece of the ray, beside its
/// evaluations, in density lookups of a simple field: Gauss–Legendre at n =
/// 4 takes about 300 ns a call on a cheap integrand, 9 evaluations of about
/// 10 ns and some 200 ns around them (measured with criterion-like loops on
/// the 2-core machine), about ten lookups of a voxel grid.
const PIECE_OVERHEAD: f64 = 10.0;

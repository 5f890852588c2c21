//! The volume-rendering family (`V-*` in docs/EQUATIONS.md) as the experiment
//! layer sees it: the scene format of an experiment file (`"family":
//! "volume"`), its quantities, the tracking estimators beside the rules, the
//! closed forms and the converged reference.
//! The family and its quantities are here; a job's evaluation is in
//! `estimate`, the closed forms in `closed_form`, the scene's term bounds in
//! `bounds`, and the file's format in `spec`.
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

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::printed::{self, Printed};
use super::tracking::{Tracker, Walks, Wanted, expected_lookups};
use super::{DepthScheme, EmissionMap, ShadowMethod, VolumeScene, evaluate};
use crate::error::{QuadError, SpecError};
use crate::family::{self, Family, Method, Outcome};
use crate::quadrature::GaussKronrod;

mod bounds;
mod closed_form;
mod estimate;
mod spec;

use bounds::{round_down, term_bounds};
use closed_form::closed_form;
use estimate::{collect, estimate, needed};

pub use spec::{
    BlobSpec, ConstantEmissionSpec, ConstantSphereSpec, DepthSchemeSpec, EmissionSpec,
    FieldEmissionSpec, GaussianBlobsSpec, LightSpec, LinearGradientSpec, MAX_REACH, MediumSpec,
    ProportionalEmissionSpec, RaySpec, SceneSpec, ShadowSpec, TableEmissionSpec, VoxelGridSpec,
};
use spec::{depth_fault, printed_forms, scene, within_reach};

/// The volume family.
#[derive(Debug, Clone, Copy)]
pub struct Volume;

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

/// Why `q` is identically 0 in `scene` because a term it integrates is not
/// in the scene (I_L without a light, or without a medium to scatter it;
/// I_E without emission; I_B without a background; I without any of them):
/// every method and the reference would agree on 0, which measures nothing.
/// None where the term is there (its value may still be 0, as with a
/// medium of density 0).
fn missing_term(scene: &VolumeScene, q: VolumeQuantity) -> Option<String> {
    use VolumeQuantity::*;
    let light = match (&scene.light, &scene.medium) {
        (None, _) => Some("the scene has no light (add scene.light)"),
        (Some(_), None) => Some(
            "the scene has a light but no medium to scatter it toward the eye (add scene.medium)",
        ),
        _ => None,
    };
    let emission = scene
        .emission
        .is_none()
        .then_some("the scene has no emission (add scene.emission)");
    let background = scene
        .background
        .is_none()
        .then_some("the scene has no background (add scene.background)");
    let why = match q {
        Light => light,
        Emission => emission,
        Background => background,
        Total if light.is_some() && emission.is_some() && background.is_some() => Some(
            "the scene has no light scattered by a medium, no emission and no background (add \
             scene.light with scene.medium, scene.emission or scene.background)",
        ),
        Total | Tau | LnTau => None,
    }?;
    Some(format!(
        "{why}: it would be 0 for every method and for the reference"
    ))
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
        if let Some(why) = missing_term(&built.scene, q) {
            return Some(why);
        }
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
    /// n)` for those that do not (Gauss–Kronrod, Monte Carlo, Sobol', Halton: they
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
            "gauss-kronrod" | "monte-carlo" | "sobol" | "halton"
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

/// The cost of one call of a rule on a piece of the ray, beside its
/// evaluations, in density lookups of a simple field: Gauss–Legendre at n =
/// 4 takes about 300 ns a call on a cheap integrand, 9 evaluations of about
/// 10 ns and some 200 ns around them (measured with criterion-like loops on
/// the 2-core machine), about ten lookups of a voxel grid.
const PIECE_OVERHEAD: f64 = 10.0;

//! Light between two surfaces (`"family": "exchange"`): R-3P and R-A with a
//! receiving patch instead of a receiving point. The receiver is a
//! one-sided rectangle, disk or triangle; the emitters are Lambertian
//! rectangles, disks and triangles of radiance `L_k`; occluders as in the
//! rendering family. With
//!
//! `G_k = int_(A_r) int_(A_k) cos theta_r cos theta_k / r^2 V(x, y) dA_k dA_r`
//!
//! (R-3P's geometry term over both surfaces, [`forms`]):
//!
//! | value | what | in `G_k` |
//! |---|---|---|
//! | `F` | the form factor from the receiver to the emitters: the fraction of the receiver's Lambertian emission that reaches them (`F_12` of radiosity) | `sum_k G_k / (pi A_r)` |
//! | `Phi` | the flux the receiver gets | `sum_k L_k G_k` |
//! | `E_mean` | its mean irradiance | `sum_k L_k G_k / A_r` |
//!
//! each by three forms, `<value>_area`, `<value>_cone`, `<value>_contour`
//! (`F_area`, ..., `E_mean_contour`): the 4-D area-area form, the 4-D
//! receiver-area x emitter-cone form, and the 2-D receiver-area form whose
//! inner integral is the point's form factor in closed form (Lambert's
//! contour formula over the lit part of a polygon light, Howell's
//! element-to-parallel-disk formula). Every rule of the quantity's dimension
//! integrates it; the budget is the points a rule is given per emitter.
//! The contour form needs a scene where the point formula holds at every
//! receiver point (one polygon light behind polygon blockers whose planes
//! separate it from the receiver, or one disk light parallel to the
//! receiver with nothing in the way); it is refused at the quantity
//! otherwise.
//!
//! **Closed forms**, with one emitter and no occluders: two polygons each
//! wholly in front of the other by the double contour integral
//! ([`crate::exact::exchange::polygon_pair`]: opposed and perpendicular
//! rectangles, shared edges included), and two parallel coaxial disks facing
//! each other (Howell C-41). **Converged reference** otherwise: adaptive
//! Genz–Malik on the contour form where it exists (2-D, relative tolerance
//! 1e-12), else on the area form (4-D).
//!
//! **Terms left out**: visibility is tested only where something can stand
//! between the receiver and an emitter (an occluder or another emitter);
//! a pair of points that do not face each other costs no ray.
//!
//! ```
//! use lightquad::family::{Family, Method};
//! use lightquad::rendering::exchange::{Exchange, ExchangeQuantity};
//! use rand::SeedableRng;
//!
//! // Two unit squares facing each other at distance 1 (Howell C-11).
//! let spec = serde_json::from_value(serde_json::json!({
//!     "receiver": {"type": "rectangle", "origin": [0.0, 0.0, 0.0],
//!                  "edge_u": [1.0, 0.0, 0.0], "edge_v": [0.0, 1.0, 0.0]},
//!     "emitters": [{"type": "rectangle", "origin": [0.0, 0.0, 1.0], "edge_u": [0.0, 1.0, 0.0],
//!                   "edge_v": [1.0, 0.0, 0.0], "radiance": 2.0}]
//! }))?;
//! let built = Exchange::build(&spec)?;
//! let c11 = lightquad::exact::rendering::parallel_rectangles(1.0, 1.0, 1.0)?;
//! let f = Exchange::closed_form(&built, ExchangeQuantity::FArea).ok_or("none")?[0];
//! assert!((f - c11).abs() < 1e-14);
//! // The contour form by Gauss–Legendre, as an experiment's job runs it:
//! // the flux is pi L A_r F.
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let gl: Method<_> = serde_json::from_str(r#"{"rule": "gauss-legendre"}"#)?;
//! let q = ExchangeQuantity::PhiContour;
//! let out = Exchange::evaluate(&built, &gl, 400, &mut rng, &[q])?;
//! let want = std::f64::consts::PI * 2.0 * c11;
//! assert!((out[&q].value[0] / want - 1.0).abs() < 1e-10);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::{QuadError, SpecError};
use crate::estimate::Estimate;
use crate::family::{self, Family, Measured, Method, Outcome};
use crate::quadrature::{AnyRule, BaseRule, GenzMalik, Rule};
use crate::rendering::emitter::Emitter;
use crate::rendering::scene::Scene;

pub mod forms;
mod mis;
mod reference;
mod spec;
pub mod surface;

pub use forms::{ExchangeForm, Transport};
pub use mis::ExchangeMis;
pub use spec::{SceneSpec, SurfaceSpec};
pub use surface::Surface;

/// The exchange family.
#[derive(Debug, Clone, Copy)]
pub struct Exchange;

/// The built scene.
#[derive(Debug, Clone)]
pub struct Built {
    /// Emitters and occluders.
    pub scene: Scene<f64>,
    /// The receiving surface.
    pub receiver: Surface,
    /// Doubts about the scene, each at its JSON path.
    pub warnings: Vec<SpecError>,
}

impl Built {
    /// The transport between the receiver and the emitters.
    pub fn transport(&self) -> Transport<'_> {
        Transport {
            scene: &self.scene,
            receiver: &self.receiver,
        }
    }
}

/// What a quantity measures (module table).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measure {
    /// `F`, the form factor from the receiver to the emitters.
    FormFactor,
    /// `Phi`, the flux.
    Flux,
    /// `E_mean`, the mean irradiance.
    MeanIrradiance,
}

/// A quantity: a value by a form (module table).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, JsonSchema,
)]
pub enum ExchangeQuantity {
    /// `F` by the 4-D area-area form.
    #[serde(rename = "F_area")]
    FArea,
    /// `F` by the 4-D area-cone form.
    #[serde(rename = "F_cone")]
    FCone,
    /// `F` by the 2-D contour form.
    #[serde(rename = "F_contour")]
    FContour,
    /// `Phi` by the area-area form.
    #[serde(rename = "Phi_area")]
    PhiArea,
    /// `Phi` by the area-cone form.
    #[serde(rename = "Phi_cone")]
    PhiCone,
    /// `Phi` by the contour form.
    #[serde(rename = "Phi_contour")]
    PhiContour,
    /// `E_mean` by the area-area form.
    #[serde(rename = "E_mean_area")]
    EMeanArea,
    /// `E_mean` by the area-cone form.
    #[serde(rename = "E_mean_cone")]
    EMeanCone,
    /// `E_mean` by the contour form.
    #[serde(rename = "E_mean_contour")]
    EMeanContour,
}

impl ExchangeQuantity {
    /// The form.
    pub fn form(&self) -> ExchangeForm {
        use ExchangeQuantity::*;
        match self {
            FArea | PhiArea | EMeanArea => ExchangeForm::Area,
            FCone | PhiCone | EMeanCone => ExchangeForm::Cone,
            FContour | PhiContour | EMeanContour => ExchangeForm::Contour,
        }
    }

    /// What it measures.
    pub fn measure(&self) -> Measure {
        use ExchangeQuantity::*;
        match self {
            FArea | FCone | FContour => Measure::FormFactor,
            PhiArea | PhiCone | PhiContour => Measure::Flux,
            EMeanArea | EMeanCone | EMeanContour => Measure::MeanIrradiance,
        }
    }

    /// The weight of `G_k` in the quantity: `1 / (pi A_r)`, `L_k` or
    /// `L_k / A_r`.
    pub fn weight(&self, built: &Built, k: usize) -> f64 {
        let area = built.receiver.area();
        let radiance = built.scene.emitters().get(k).map_or(0.0, |e| e.radiance());
        match self.measure() {
            Measure::FormFactor => 1.0 / (std::f64::consts::PI * area),
            Measure::Flux => radiance,
            Measure::MeanIrradiance => radiance / area,
        }
    }

    /// `sum_k w_k G_k` of this quantity, from per-emitter `G_k`.
    pub fn combine(&self, built: &Built, g: &[Estimate<f64>]) -> Estimate<f64> {
        g.iter().enumerate().fold(Estimate::zero(), |sum, (k, gk)| {
            sum.combine(gk.scaled(self.weight(built, k)))
        })
    }
}

impl family::Quantity for ExchangeQuantity {
    fn name(&self) -> &'static str {
        use ExchangeQuantity::*;
        match self {
            FArea => "F_area",
            FCone => "F_cone",
            FContour => "F_contour",
            PhiArea => "Phi_area",
            PhiCone => "Phi_cone",
            PhiContour => "Phi_contour",
            EMeanArea => "E_mean_area",
            EMeanCone => "E_mean_cone",
            EMeanContour => "E_mean_contour",
        }
    }

    fn all() -> &'static [Self] {
        use ExchangeQuantity::*;
        &[
            FArea,
            FCone,
            FContour,
            PhiArea,
            PhiCone,
            PhiContour,
            EMeanArea,
            EMeanCone,
            EMeanContour,
        ]
    }

    /// A form factor is a fraction, in `[0, 1]`; fluxes and irradiances
    /// are never negative.
    fn bounds(&self) -> (f64, f64) {
        match self.measure() {
            Measure::FormFactor => (0.0, 1.0),
            _ => (0.0, f64::INFINITY),
        }
    }
}

/// Evaluations per emitter of the converged reference for each `n` of
/// `{"type": "converged", "n": n}`.
pub const CONVERGED_PER_N: usize = 100;

/// The converged reference's rule.
fn converged_rule() -> AnyRule {
    AnyRule::Base(BaseRule::GenzMalik(GenzMalik {
        abs_tol: 0.0,
        rel_tol: 1e-12,
    }))
}

/// What a ray may meet besides its emitter: the occluders and the other
/// emitters.
fn blockers(built: &Built) -> f64 {
    (built.scene.occluders().len() + built.scene.emitters().len().saturating_sub(1)) as f64
}

/// `q` by `rule` at `n` points per emitter.
fn by_rule<R: Rule>(
    built: &Built,
    rule: &R,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
    q: ExchangeQuantity,
) -> Result<Estimate<f64>, QuadError> {
    let t = built.transport();
    let g = (0..built.scene.emitters().len())
        .map(|k| t.integrate(q.form(), k, rule, n, rng))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(q.combine(built, &g))
}

impl Family for Exchange {
    const NAME: &'static str = "exchange";
    const ABOUT: &'static str = "light between two surfaces: the form factor, flux and mean \
                                 irradiance a receiving patch gets from rectangle, disk and \
                                 triangle lights, with occluders, by the 4-D area-area and \
                                 area-cone forms and the 2-D contour form";
    const EQUATIONS: &'static [&'static str] = &["R-3P", "R-A"];
    const BUDGET_UNIT: &'static str = "the points a rule is given per emitter (in the \
                                       quantity's dimension: 4 for the area and cone forms, 2 \
                                       for the contour form)";

    type SceneSpec = SceneSpec;
    type Scene = Built;
    type Quantity = ExchangeQuantity;
    type Estimator = ExchangeMis;

    fn build(spec: &SceneSpec) -> Result<Built, SpecError> {
        spec::build(spec)
    }

    fn warnings(built: &Built) -> Vec<SpecError> {
        built.warnings.clone()
    }

    fn dimension(_: &Built, q: ExchangeQuantity) -> usize {
        q.form().dimension()
    }

    fn channels(_: &Built, _: ExchangeQuantity) -> usize {
        1
    }

    fn lacks(built: &Built, q: ExchangeQuantity) -> Option<String> {
        (q.form() == ExchangeForm::Contour)
            .then(|| reference::contour_lacks(built))
            .flatten()
    }

    /// The light-sampled forms: MIS's light strategy is the quantity's form.
    fn estimates(_: &ExchangeMis) -> &'static [ExchangeQuantity] {
        use ExchangeQuantity::*;
        &[FArea, FCone, PhiArea, PhiCone, EMeanArea, EMeanCone]
    }

    /// Per emitter, the rule's evaluations in the form's dimension, each
    /// testing every blocker; the cone form builds a cone per evaluation.
    fn cost(
        built: &Built,
        method: &Method<ExchangeMis>,
        budget: usize,
        q: ExchangeQuantity,
    ) -> f64 {
        let per_emitter = match method {
            Method::Rule(rule) => {
                rule.evaluations(budget, q.form().dimension()) * built.scene.emitters().len() as f64
            }
            Method::Estimator(_) => 2.0 * budget as f64,
        };
        let cone = if q.form() == ExchangeForm::Cone {
            2.0
        } else {
            1.0
        };
        per_emitter * cone * (1.0 + blockers(built))
    }

    fn evaluate(
        built: &Built,
        method: &Method<ExchangeMis>,
        budget: usize,
        rng: &mut rand_pcg::Pcg64,
        quantities: &[ExchangeQuantity],
    ) -> Result<Outcome<ExchangeQuantity>, QuadError> {
        quantities
            .iter()
            .map(|&q| {
                let estimate = match method {
                    Method::Rule(rule) => by_rule(built, rule, budget, rng, q)?,
                    Method::Estimator(m) => mis::by_mis(built, *m, budget, rng, q)?,
                };
                Ok((q, Measured::from(estimate)))
            })
            .collect()
    }

    fn closed_form(built: &Built, q: ExchangeQuantity) -> Option<Vec<f64>> {
        let f = reference::closed_form_factor(built)?;
        Some(vec![
            f * std::f64::consts::PI * built.receiver.area() * q.weight(built, 0),
        ])
    }

    fn closed_forms_available() -> &'static str {
        "closed forms with one emitter and no occluders: two polygons each wholly in front of \
         the other (the double contour integral, where its rounding error is below 1e-12 of F: \
         not for patches far apart beside their size), two parallel coaxial disks facing each \
         other (Howell C-41)"
    }

    fn converged_cost(built: &Built, n: usize, quantities: &[ExchangeQuantity]) -> [f64; 2] {
        let budget = reference::converged_budget(built, n);
        let q = quantities
            .first()
            .copied()
            .unwrap_or(ExchangeQuantity::FArea);
        let form = reference::converged_form(built);
        let rule = Method::Rule(converged_rule());
        let evaluations =
            built.scene.emitters().len() as f64 * budget as f64 * (1.0 + blockers(built));
        [
            evaluations,
            Self::memory(built, &rule, budget, q).max(0.0) * form.dimension() as f64,
        ]
    }

    fn converged(
        built: &Built,
        n: usize,
        quantities: &[ExchangeQuantity],
    ) -> Result<Outcome<ExchangeQuantity>, QuadError> {
        let g = reference::converged_exchange(built, n)?;
        Ok(quantities
            .iter()
            .map(|&q| (q, Measured::from(q.combine(built, &g))))
            .collect())
    }

    fn settings(spec: &SceneSpec) -> String {
        format!(
            "receiver {}; {} emitter(s), {} occluder(s)",
            serde_json::to_string(&spec.receiver).unwrap_or_default(),
            spec.emitters.len(),
            spec.occluders.len()
        )
    }
}

//! The calibration family: integrals whose values are known in closed form,
//! over the domains of rendering, so every rule's accuracy, error estimate,
//! cost and order can be read against the truth before it meets an equation
//! (`"family": "calibration"`). Its scene is empty; its quantities are the
//! integrals themselves:
//!
//! | quantity | integral | value | dimension |
//! |---|---|---|---:|
//! | `exp` | `int_0^1 e^u du` | `e - 1` | 1 |
//! | `exp-rgb` | `int_0^1 (e^u, e^{2u}, e^{3u}) du` | `((e-1), (e^2-1)/2, (e^3-1)/3)` | 1 |
//! | `gaussian-disk` | `int_{unit disk} e^{-(x^2+y^2)} dA` | `pi (1 - 1/e)` | 2 |
//! | `cos3-hemisphere` | `int_{H^2} cos^3(theta) d omega` | `pi / 2` | 2 |
//!
//! ```
//! use lightquad::calibration::Calibration;
//! use lightquad::experiment::validate::{deserialize, validate};
//! use lightquad::family::Family;
//!
//! let json = serde_json::json!({
//!     "name": "c", "family": "calibration", "scene": {},
//!     "quantities": ["exp", "cos3-hemisphere"],
//!     "rules": [{"rule": "gauss-legendre"}], "budgets": [4, 16], "repeats": 1,
//!     "reference": {"type": "closed-form"}
//! });
//! let exp = validate::<Calibration>(deserialize(json)?, "hash")?;
//! // The closed forms of the table above.
//! for (q, want) in exp.spec.quantities.iter().zip([std::f64::consts::E - 1.0, std::f64::consts::PI / 2.0]) {
//!     let v = Calibration::closed_form(&exp.scene, *q).expect("has one");
//!     assert!((v[0] - want).abs() < 1e-15);
//! }
//! # Ok::<(), lightquad::error::SpecError>(())
//! ```

use std::f64::consts::{E, PI};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::domain::{Disk, Hemisphere, Vec3, integrate_over};
use crate::error::{QuadError, SpecError};
use crate::family::{self, Family, Measured, Method, NoEstimator, Outcome};
use crate::quadrature::{GaussLegendre, Rule, RuleVisitor};
use crate::value::Rgb;

/// The calibration family.
#[derive(Debug, Clone, Copy)]
pub struct Calibration;

/// The calibration scene: nothing (the quantities are the integrals).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NoScene {}

/// An integral with a known value.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum Integral {
    /// `int_0^1 e^u du = e - 1`.
    Exp,
    /// `int_0^1 (e^u, e^{2u}, e^{3u}) du`, one channel each.
    ExpRgb,
    /// `int_{unit disk} e^{-(x^2+y^2)} dA = pi (1 - 1/e)`.
    GaussianDisk,
    /// `int_{H^2} cos^3(theta) d omega = pi / 2`.
    Cos3Hemisphere,
}

impl family::Quantity for Integral {
    fn name(&self) -> &'static str {
        match self {
            Integral::Exp => "exp",
            Integral::ExpRgb => "exp-rgb",
            Integral::GaussianDisk => "gaussian-disk",
            Integral::Cos3Hemisphere => "cos3-hemisphere",
        }
    }

    fn all() -> &'static [Self] {
        &[
            Integral::Exp,
            Integral::ExpRgb,
            Integral::GaussianDisk,
            Integral::Cos3Hemisphere,
        ]
    }

    /// Every calibration integral is of a positive integrand.
    fn bounds(&self) -> (f64, f64) {
        (0.0, f64::INFINITY)
    }
}

/// `q` with `rule` at budget `n`; evaluations are integrand evaluations.
fn integrate<R: Rule>(
    q: Integral,
    rule: &R,
    n: usize,
    rng: &mut rand_pcg::Pcg64,
) -> Result<Measured, QuadError> {
    Ok(match q {
        Integral::Exp => rule.integrate(n, rng, |u: [f64; 1]| u[0].exp())?.into(),
        Integral::ExpRgb => rule
            .integrate(n, rng, |u: [f64; 1]| {
                Rgb::new(u[0].exp(), (2.0 * u[0]).exp(), (3.0 * u[0]).exp())
            })?
            .into(),
        Integral::GaussianDisk => {
            let disk = Disk::new(Vec3::zeros(), Vec3::z(), 1.0)?;
            integrate_over(rule, &disk, n, rng, |p| (-(p.x * p.x + p.y * p.y)).exp())?.into()
        }
        Integral::Cos3Hemisphere => {
            integrate_over(rule, &Hemisphere::uniform(), n, rng, |w| w.z * w.z * w.z)?.into()
        }
    })
}

/// One integral, run by [`AnyRule::visit`](crate::quadrature::AnyRule::visit)
/// with the concrete rule: these integrands cost a few nanoseconds, and an
/// indirect call per evaluation would be part of what the report gives as
/// the rule's cost.
struct Run<'a> {
    q: Integral,
    n: usize,
    rng: &'a mut rand_pcg::Pcg64,
}

impl RuleVisitor for Run<'_> {
    type Output = Result<Measured, QuadError>;
    fn visit<R: Rule>(self, rule: &R) -> Self::Output {
        integrate(self.q, rule, self.n, self.rng)
    }
}

impl Family for Calibration {
    const NAME: &'static str = "calibration";
    const ABOUT: &'static str =
        "integrals with closed forms over a segment, a disk and the hemisphere, to calibrate rules";
    const EQUATIONS: &'static [&'static str] = &[];
    const BUDGET_UNIT: &'static str = "the points a rule is given (the evaluations column counts \
                                       what it spent, its error estimate included)";

    type SceneSpec = NoScene;
    type Scene = NoScene;
    type Quantity = Integral;
    type Estimator = NoEstimator;

    fn build(spec: &NoScene) -> Result<NoScene, SpecError> {
        Ok(spec.clone())
    }

    fn dimension(_: &NoScene, q: Integral) -> usize {
        match q {
            Integral::Exp | Integral::ExpRgb => 1,
            Integral::GaussianDisk | Integral::Cos3Hemisphere => 2,
        }
    }

    fn channels(_: &NoScene, q: Integral) -> usize {
        if q == Integral::ExpRgb { 3 } else { 1 }
    }

    fn estimates(e: &NoEstimator) -> &'static [Integral] {
        match *e {}
    }

    fn evaluate(
        _: &NoScene,
        method: &Method<NoEstimator>,
        budget: usize,
        rng: &mut rand_pcg::Pcg64,
        quantities: &[Integral],
    ) -> Result<Outcome<Integral>, QuadError> {
        let Method::Rule(rule) = method else {
            return Err(QuadError::invalid(
                "rule",
                method.name(),
                "a quadrature rule",
            ));
        };
        quantities
            .iter()
            .map(|&q| {
                let run = Run {
                    q,
                    n: budget,
                    rng: &mut *rng,
                };
                Ok((q, rule.visit(run)?))
            })
            .collect()
    }

    fn closed_form(_: &NoScene, q: Integral) -> Option<Vec<f64>> {
        Some(match q {
            Integral::Exp => vec![E - 1.0],
            Integral::ExpRgb => vec![
                E - 1.0,
                (2.0f64.exp() - 1.0) / 2.0,
                (3.0f64.exp() - 1.0) / 3.0,
            ],
            Integral::GaussianDisk => vec![PI * (1.0 - (-1.0f64).exp())],
            Integral::Cos3Hemisphere => vec![PI / 2.0],
        })
    }

    fn closed_forms_available() -> &'static str {
        "every calibration integral has one"
    }

    /// Gauss–Legendre with `n` nodes per axis, at most 10^8 nodes in all
    /// (far past convergence for these integrals: 20 per axis reach 1e-15).
    fn converged(
        scene: &NoScene,
        n: usize,
        quantities: &[Integral],
    ) -> Result<Outcome<Integral>, QuadError> {
        let rule = GaussLegendre {
            error_estimate: false,
        };
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
        quantities
            .iter()
            .map(|&q| {
                let budget = n
                    .saturating_pow(Self::dimension(scene, q) as u32)
                    .min(100_000_000);
                Ok((q, integrate(q, &rule, budget, &mut rng)?))
            })
            .collect()
    }
}

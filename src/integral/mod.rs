//! The `integral` family: the user's own integral, written in the experiment
//! file (`"family": "integral"`): a domain ([`region`]), an integrand
//! expression ([`expr`]) and, if known, the exact value.
//!
//! ```json
//! {"family": "integral",
//!  "scene": {"domain": {"type": "box", "min": [0, 0], "max": [1, 2]},
//!            "integrand": "x*exp(-(x*y))", "exact": "(1 + exp(-2))/2"},
//!  "quantities": ["integral"], ...}
//! ```
//!
//! Its one quantity, `integral`, is `int_Omega f d mu` over the domain in
//! its measure, one channel per expression (a list of three is an RGB
//! integrand). References: `closed-form` takes `exact`; `converged` is
//! adaptive Gauss–Kronrod (`15 + 30 n` evaluations a piece) in one dimension
//! and adaptive Genz–Malik (`n^2` evaluations, relative tolerance 1e-12) in
//! two to six, checked against `2n` as in every family.
//!
//! ```
//! use lightquad::experiment::validate::{deserialize, validate};
//! use lightquad::family::Family;
//! use lightquad::integral::{Integral, Quantity};
//!
//! let json = serde_json::json!({
//!     "name": "i", "family": "integral",
//!     "scene": {"domain": {"type": "box", "min": [0, 0], "max": [1, 2]},
//!               "integrand": "x*exp(-(x*y))", "exact": "(1 + exp(-2))/2"},
//!     "quantities": ["integral"],
//!     "rules": [{"rule": "gauss-legendre"}], "budgets": [64], "repeats": 1,
//!     "reference": {"type": "closed-form"}
//! });
//! let exp = validate::<Integral>(deserialize(json)?, "hash")?;
//! let exact = Integral::closed_form(&exp.scene, Quantity::Integral).expect("given");
//! // int_0^1 int_0^2 x e^{-xy} dy dx = int_0^1 (1 - e^{-2x}) dx = (1 + e^{-2}) / 2.
//! assert!((exact[0] - (1.0 + (-2.0f64).exp()) / 2.0).abs() < 1e-16);
//! # Ok::<(), lightquad::error::SpecError>(())
//! ```

pub mod expr;
pub mod region;
pub mod spec;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::{QuadError, SpecError};
use crate::family::{self, Family, Measured, Method, NoEstimator, Outcome};
use crate::quadrature::{AnyRule, BaseRule, GaussKronrod, GenzMalik, Rule, RuleVisitor};
use crate::value::{Rgb, Value};

use expr::MAX_VARIABLES;
use region::Region;
pub use spec::{Built, IntegralSpec};

/// The `integral` family.
#[derive(Debug, Clone, Copy)]
pub struct Integral;

/// The family's one quantity: the integral.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum Quantity {
    /// `int_Omega f d mu`.
    Integral,
}

impl family::Quantity for Quantity {
    fn name(&self) -> &'static str {
        "integral"
    }
    fn all() -> &'static [Self] {
        &[Quantity::Integral]
    }
}

impl Built {
    /// The integrand times the Jacobian at the unit-cube point `u`; 0 at an
    /// infinite end; a non-finite value is an error naming the point.
    #[inline]
    fn at<V: Value>(&self, u: &[f64]) -> Result<V, QuadError> {
        let mut values = [0.0; MAX_VARIABLES];
        let Some(jacobian) = self.region.point(u, &mut values, self.angles) else {
            return Ok(V::zero());
        };
        if jacobian == f64::INFINITY {
            return Err(QuadError::invalid(
                "integrand",
                format!("evaluated on the rim of the hemisphere (u = {u:?})"),
                "points where the cosine map's Jacobian pi / cos(theta) is finite: rules with \
                 nodes on the domain's edge (trapezoid, Simpson) reach the rim, where it is \
                 infinite; use \"map\": \"projected\" with the integrand divided by \
                 cos(theta), or \"uniform\"",
            ));
        }
        self.weighted(self.integrand_at::<V>(&values)?, jacobian, &values)
    }

    /// The integrand's finite value `f` at `values` times the Jacobian;
    /// where the product is not finite, an error naming the point in the
    /// domain's variables ([`crate::domain::times_jacobian`]).
    #[inline]
    fn weighted<V: Value>(&self, f: V, jacobian: f64, values: &[f64]) -> Result<V, QuadError> {
        crate::domain::times_jacobian(f, jacobian, || self.point(values))
    }

    /// The integrand at the variables' `values`; a non-finite value is an
    /// error naming the point.
    #[inline]
    fn integrand_at<V: Value>(&self, values: &[f64; MAX_VARIABLES]) -> Result<V, QuadError> {
        let f = V::from_fn(|c| self.integrand[c].eval(values));
        if !f.all_finite() {
            return Err(self.not_finite(values, f));
        }
        Ok(f)
    }

    /// The integrand at the ray parameter `t` of a segment (whose own
    /// integration applies its Jacobian).
    #[inline]
    fn at_parameter<V: Value>(&self, t: f64) -> Result<V, QuadError> {
        let mut values = [0.0; MAX_VARIABLES];
        values[0] = t;
        self.integrand_at::<V>(&values)
    }

    /// The error for a non-finite integrand value `f` at `values`.
    #[cold]
    fn not_finite<V: Value>(&self, values: &[f64], f: V) -> QuadError {
        QuadError::invalid(
            "integrand",
            format!("{} at {}", crate::error::channels(f), self.point(values)),
            "a finite value at every point the rules evaluate (closed rules evaluate the \
             domain's ends and edges)",
        )
    }

    /// The point `values` in the domain's variables, as `x = 1, y = 2`.
    fn point(&self, values: &[f64]) -> String {
        let at: Vec<String> = self
            .variables
            .iter()
            .zip(values)
            .take(self.region.coordinates())
            .map(|(name, v)| format!("{name} = {}", crate::error::readable_number(*v)))
            .collect();
        at.join(", ")
    }

    /// `int f d mu` with `rule` at budget `n`.
    fn integrate<R: Rule, V: Value>(
        &self,
        rule: &R,
        n: usize,
        rng: &mut rand_pcg::Pcg64,
    ) -> Result<Measured, QuadError> {
        let est = match (&self.region, self.region.dim()) {
            (Region::Segment(s), _) => {
                s.try_integrate(rule, n, rng, |t| self.at_parameter::<V>(t))?
            }
            (Region::Interval(pieces), _) => self.interval::<R, V>(pieces, rule, n, rng)?,
            (_, 1) => rule.try_integrate(n, rng, |u: [f64; 1]| self.at::<V>(&u))?,
            (_, 2) => rule.try_integrate(n, rng, |u: [f64; 2]| self.at::<V>(&u))?,
            (_, 3) => rule.try_integrate(n, rng, |u: [f64; 3]| self.at::<V>(&u))?,
            (_, 4) => rule.try_integrate(n, rng, |u: [f64; 4]| self.at::<V>(&u))?,
            (_, 5) => rule.try_integrate(n, rng, |u: [f64; 5]| self.at::<V>(&u))?,
            _ => rule.try_integrate(n, rng, |u: [f64; 6]| self.at::<V>(&u))?,
        };
        Ok(est.into())
    }

    /// `int f dx` over an interval's pieces, each with the whole budget.
    fn interval<R: Rule, V: Value>(
        &self,
        pieces: &[region::Interval],
        rule: &R,
        n: usize,
        rng: &mut rand_pcg::Pcg64,
    ) -> Result<crate::estimate::Estimate<V>, QuadError> {
        let mut total = crate::estimate::PieceSum::<V>::new(pieces.len());
        for &piece in pieces {
            let est = rule.try_integrate(n, rng, |u: [f64; 1]| {
                let mut values = [0.0; MAX_VARIABLES];
                match region::interval_point(piece, u[0], &mut values) {
                    Some(jacobian) => {
                        self.weighted(self.integrand_at::<V>(&values)?, jacobian, &values)
                    }
                    None => Ok(V::zero()),
                }
            })?;
            total.add(est);
        }
        total.finish()
    }

    /// The pieces a rule runs on (a segment's between its breaks; else 1).
    fn pieces(&self) -> usize {
        match &self.region {
            Region::Segment(s) => s.pieces().count(),
            Region::Interval(pieces) => pieces.len(),
            _ => 1,
        }
    }
}

/// One integral, run by [`AnyRule::visit`] with the concrete rule, so the
/// expression is called directly, not through a trait object.
struct Run<'a> {
    scene: &'a Built,
    n: usize,
    rng: &'a mut rand_pcg::Pcg64,
}

impl RuleVisitor for Run<'_> {
    type Output = Result<Measured, QuadError>;
    fn visit<R: Rule>(self, rule: &R) -> Self::Output {
        match self.scene.integrand.len() {
            1 => self.scene.integrate::<R, f64>(rule, self.n, self.rng),
            _ => self.scene.integrate::<R, Rgb>(rule, self.n, self.rng),
        }
    }
}

/// The converged evaluation's rule in `dim` dimensions: adaptive
/// Gauss–Kronrod in one, Genz–Malik (relative tolerance 1e-12) above.
fn converged_rule(dim: usize) -> AnyRule {
    AnyRule::Base(if dim == 1 {
        BaseRule::GaussKronrod(GaussKronrod {
            abs_tol: 0.0,
            rel_tol: 0.0,
        })
    } else {
        BaseRule::GenzMalik(GenzMalik {
            abs_tol: 0.0,
            rel_tol: 1e-12,
        })
    })
}

/// The converged evaluation's budget at `n`: `15 + 30 n` a piece in one
/// dimension, `n^2` (at least one Genz–Malik region) above.
fn converged_budget(rule: &AnyRule, dim: usize, n: usize) -> usize {
    if dim == 1 {
        n.saturating_mul(30).saturating_add(15)
    } else {
        n.saturating_mul(n).max(rule.min_budget(dim))
    }
}

impl Family for Integral {
    const NAME: &'static str = "integral";
    const ABOUT: &'static str = "your own integral: an integrand expression over an interval, a box of up to 6 \
         dimensions, a surface, the hemisphere or a pixel";
    const EQUATIONS: &'static [&'static str] = &[];
    const BUDGET_UNIT: &'static str = "the points a rule is given (per piece: a segment's between \
                                       its breaks, an infinite interval's middle and tails; the \
                                       evaluations column counts what it spent, its error \
                                       estimate included)";

    type SceneSpec = IntegralSpec;
    type Scene = Built;
    type Quantity = Quantity;
    type Estimator = NoEstimator;

    fn build(spec: &IntegralSpec) -> Result<Built, SpecError> {
        spec::build(spec)
    }

    fn dimension(scene: &Built, _: Quantity) -> usize {
        scene.region.dim()
    }

    fn channels(scene: &Built, _: Quantity) -> usize {
        scene.integrand.len()
    }

    fn estimates(e: &NoEstimator) -> &'static [Quantity] {
        match *e {}
    }

    /// The rule's evaluations at `budget`, on every piece of a segment.
    fn cost(scene: &Built, method: &Method<NoEstimator>, budget: usize, _: Quantity) -> f64 {
        match method {
            Method::Rule(rule) => {
                rule.evaluations(budget, scene.region.dim()) * scene.pieces() as f64
            }
            Method::Estimator(e) => match *e {},
        }
    }

    fn converged_cost(scene: &Built, n: usize, quantities: &[Quantity]) -> [f64; 2] {
        let dim = scene.region.dim();
        let rule = converged_rule(dim);
        let budget = converged_budget(&rule, dim, n);
        family::job_cost::<Self>(scene, &Method::Rule(rule), budget, quantities)
    }

    fn evaluate(
        scene: &Built,
        method: &Method<NoEstimator>,
        budget: usize,
        rng: &mut rand_pcg::Pcg64,
        quantities: &[Quantity],
    ) -> Result<Outcome<Quantity>, QuadError> {
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
                    scene,
                    n: budget,
                    rng: &mut *rng,
                };
                Ok((q, rule.visit(run)?))
            })
            .collect()
    }

    fn closed_form(scene: &Built, _: Quantity) -> Option<Vec<f64>> {
        scene.exact.clone()
    }

    fn closed_forms_available() -> &'static str {
        "where the scene gives its `exact` value"
    }

    /// Gauss–Kronrod at `15 + 30 n` evaluations a piece in one dimension,
    /// Genz–Malik at `n^2` above ([module documentation](self)).
    fn converged(
        scene: &Built,
        n: usize,
        quantities: &[Quantity],
    ) -> Result<Outcome<Quantity>, QuadError> {
        let dim = scene.region.dim();
        let rule = converged_rule(dim);
        let budget = converged_budget(&rule, dim, n);
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
        Self::evaluate(scene, &Method::Rule(rule), budget, &mut rng, quantities)
    }

    /// The integral as written: its integrand, domain and measure.
    fn settings(spec: &IntegralSpec) -> String {
        let domain = serde_json::to_string(&spec.domain).unwrap_or_default();
        format!(
            "integrand {} over the domain {domain}",
            spec.integrand.0.join(" | ")
        )
    }
}

//! Quadrature rules on the unit cube `[0, 1]^D`.
//!
//! A rule knows how to place weighted nodes in the unit cube for a budget of
//! `n` integrand evaluations; it never knows geometry (that is a
//! [`domain`](crate::domain)'s job) nor which equation it serves. Every rule
//! implements [`Rule`]; [`AnyRule`] selects one by name at run time.
//!
//! **The registry** is the one `registry!` line per rule below: it declares
//! the rule's module and its name in experiment files, and generates
//! [`BaseRule`] (the serde rule spec, tagged by `"rule"`, every parameter a
//! field of the rule's own struct) with dispatch of every [`Rule`] method.
//! Facts about a rule (its minimum budget, whether it is random, the
//! dimensions it integrates, the check of its parameters) are methods of the
//! rule itself. Adding a rule is its file plus one registry line.
//!
//! Beside the rules: `any` ([`AnyRule`], a rule chosen at run time),
//! `guard` (the rescaling of [`Rule::try_integrate`]), `limits` (the
//! budget, memory and tolerance limits, and the nodes per axis a budget
//! buys), [`nodes`] (node sets and the one shared sum) and [`product`].
//!
//! | name | rule | error estimate |
//! |---|---|---|
//! | `trapezoid` | composite trapezoid, product in D > 1 | Richardson, half step; observed order from the quarter step when nested |
//! | `simpson` | composite Simpson, product in D > 1 | Richardson, half step; observed order from the quarter step when nested |
//! | `gauss-legendre` | Gauss–Legendre of any order, product in D > 1 | tail of the differences of `Q_m, Q_{m-1}, Q_{m-2}`, checked against `Q_m - Q_{m/2}` from m = 16 |
//! | `gauss-kronrod` | adaptive Gauss–Kronrod G7–K15 (D = 1) | embedded G7 |
//! | `genz-malik` | adaptive Genz–Malik degree-7 cubature (2 <= D <= 6), bisecting the worst box (as HCubature) | embedded degree-5 rule |
//! | `monte-carlo` | plain Monte Carlo | standard error; doubted when all samples agree or the sample variance is carried by a few samples (kurtosis) |
//! | `stratified` | jittered Monte Carlo, one sample per cell | second differences of every three neighbouring cells; doubted when none varies, or when a few cells carry the variance and one sample inside the cube most of the sum (a peak between samples) |
//! | `sobol` | Owen-scrambled Sobol' points (D <= 21, Joe–Kuo direction numbers), 8 scrambles | standard error over scrambles, times t_{R-1}(0.975)/1.96; doubted when the scrambles agree or the points fail the Monte Carlo tail check |
//! | `halton` | Halton points (D <= 21, prime bases 2 to 73) scrambled by random digit permutations, 8 scrambles | as `sobol` |
//! | `product` | iterated 2-D rule from any two 1-D rules (`AnyRule::by_name("product(A,B)")` in the library) | outer estimate + integrated inner estimates |
//!
//! ```
//! use lightquad::quadrature::{GaussLegendre, Rule, Trapezoid};
//! use rand::SeedableRng;
//!
//! // int_0^1 e^u du = e - 1: Gauss–Legendre converges spectrally, the trapezoid
//! // rule as n^-2.
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let exact = std::f64::consts::E - 1.0;
//! let gl = GaussLegendre::default().integrate(8, &mut rng, |u: [f64; 1]| u[0].exp())?;
//! let tr = Trapezoid.integrate(8, &mut rng, |u: [f64; 1]| u[0].exp())?;
//! assert!((gl.value - exact).abs() < 1e-14);
//! assert!((tr.value - exact).abs() > 1e-4 && (tr.value - exact).abs() < 1e-2);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

mod any;
mod guard;
mod limits;
pub mod nodes;
pub mod product;
mod replay;

pub use any::AnyRule;
pub use limits::{MAX_BUDGET, MAX_RULE_BYTES, integer_root, per_axis};
pub(crate) use limits::{check_budget, check_tolerances};
pub use product::Product;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;

/// The dimensions `min..=max` of the unit cube a rule integrates over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dimensions {
    /// Smallest dimension.
    pub min: usize,
    /// Largest dimension.
    pub max: usize,
}

impl Dimensions {
    /// Every dimension from 1.
    pub const ANY: Dimensions = Dimensions {
        min: 1,
        max: usize::MAX,
    };

    /// True when `dim` is in range.
    pub fn contains(&self, dim: usize) -> bool {
        (self.min..=self.max).contains(&dim)
    }
}

impl std::fmt::Display for Dimensions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.min, self.max) {
            (a, usize::MAX) => write!(f, "{a} and up"),
            (a, b) if a == b => write!(f, "{a} only"),
            (a, b) => write!(f, "{a} to {b}"),
        }
    }
}

/// A quadrature rule on the unit cube `[0, 1]^D`.
pub trait Rule {
    /// The registry name (`gauss-legendre`, ...).
    fn name(&self) -> &'static str;

    /// One line on what the rule is and how it estimates its error.
    fn about(&self) -> &'static str;

    /// The smallest budget the rule accepts in `dim` dimensions (an experiment
    /// skips smaller budgets for it).
    fn min_budget(&self, _dim: usize) -> usize {
        1
    }

    /// True for randomised rules (their error estimate is a standard error).
    fn is_random(&self) -> bool {
        false
    }

    /// Whether a pass in `dim` dimensions needs [`Rule::try_integrate`]'s
    /// guard: true unless all the rule computes from the values is one
    /// weighted sum, with weights that sum to 1, which it finds within the
    /// f64 range or refuses ([`QuadError::SumOutOfRange`]), and it reports
    /// no error estimate (an infinite error). Such a sum does not overflow
    /// where its values do not, and there is no error to underflow: the
    /// guard's log and checks would cost a few-node integral more than its
    /// integrand (Gauss–Legendre without its estimate in one dimension).
    ///
    /// Where the guard would have rescaled, an unguarded rule's answer can
    /// differ from a guarded one's: values beyond `2^500` past the guard's
    /// log give the sum, where the guard ran out of budget
    /// ([`QuadError::RescaleOverBudget`]); a rescaling that makes small
    /// terms subnormal rounds them, which the unguarded sum does not; and a
    /// sum that leaves the range is [`QuadError::SumOutOfRange`], not
    /// [`QuadError::Overflow`].
    fn guarded(&self, _dim: usize) -> bool {
        true
    }

    /// The dimensions the rule integrates over.
    fn dimensions(&self) -> Dimensions {
        Dimensions::ANY
    }

    /// Checks the rule's parameters; the error names the parameter.
    fn check(&self) -> Result<(), QuadError> {
        Ok(())
    }

    /// The resolution per axis that a budget of `n` evaluations in `dim`
    /// dimensions buys: the `x` an error of order `O(x^-p)` falls with, so a
    /// fit of the error against it shows an order-p rule as `-p`. Nodes or
    /// samples per axis, `floor(n^(1/dim))`, by default; the intervals
    /// `m - 1` of the points a composite rule really uses.
    fn resolution(&self, n: usize, dim: usize) -> f64 {
        integer_root(n, dim) as f64
    }

    /// The bytes of working memory a run at a budget of `n` in `dim`
    /// dimensions holds at once, where they grow with `n` (node tables, piece
    /// lists); 0 for rules whose memory does not grow (Monte Carlo draws a
    /// sample at a time). An estimate from measured peak resident memory,
    /// so that a budget that would exhaust the machine is refused before it
    /// runs (Gauss–Legendre at 1e8 nodes held 5.5 GB). Not counted: the
    /// replay logs of [`Rule::try_integrate`], at most 2 MiB per integral
    /// under way.
    fn memory(&self, _n: usize, _dim: usize) -> f64 {
        0.0
    }

    /// The integrand evaluations a run at a budget of `n` in `dim`
    /// dimensions makes, its error estimate's included: `n` by default;
    /// Gauss–Legendre evaluates three more rules of about `m`, `m` and `m/2`
    /// nodes for its estimate (3.5 n in one dimension, 12 n in a nested
    /// integral, which cost estimates counted as n and n^2).
    fn evaluations(&self, n: usize, _dim: usize) -> f64 {
        n as f64
    }

    /// The rule itself, which [`Rule::try_integrate`] guards against
    /// overflow where it is [`Rule::guarded`]: estimates `int_{[0,1]^D} f(u) du` with a budget of about `n`
    /// evaluations, for an integrand that may fail: its first error stops the
    /// rule and is returned as is. `n` above [`MAX_BUDGET`] is an error here
    /// too.
    ///
    /// `rng` drives the randomised rules and is ignored by deterministic ones;
    /// with the same `rng` state the result is bit-for-bit reproducible.
    fn integrate_unguarded<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError>;

    /// Estimates `int_{[0,1]^D} f(u) du` with a budget of about `n` evaluations,
    /// for an integrand that may fail: its first error stops the rule and is
    /// returned as is. `n` above [`MAX_BUDGET`] is an error.
    ///
    /// A rule's sums, differences and squares of values beyond `2^500` can
    /// overflow into an infinite or NaN estimate, and squares of values below
    /// `2^-500` underflow into a standard error of 0. So a pass stops at the
    /// first finite value beyond `2^500` (while its log holds it) and the
    /// integral is taken again of `f 2^-e` in that channel, `2^e` the largest
    /// `|f|` seen; a pass past its log that overflowed is taken again so; and
    /// a channel whose values all lie below `2^-500` and whose error came out
    /// 0 is taken again of `f 2^-e` too: exact scalings, undone on the
    /// estimate. An estimate that is still not finite is an error
    /// ([`QuadError::Overflow`]), never a silent NaN; an error estimate
    /// that is finite at its scale and beyond the f64 range once scaled
    /// back is infinite and doubted.
    ///
    /// Passes after the first keep the budget: they replay the draws and
    /// values logged so far (module `replay`, at most 1 MiB each) and
    /// evaluate `f` only where the log ends or an adaptive rule, deciding on
    /// scaled values, takes another path; every evaluation is counted, and
    /// never more than the rule's own promise ([`Rule::evaluations`]) in all.
    /// A pass that would go past it is abandoned: an estimate with an
    /// underflowed error is then returned doubted (so beyond the log, 65536
    /// one-dimensional evaluations, stratified sampling of an integrand near
    /// 1e-300 gives an error of 0, doubted, where evaluating twice gave a
    /// real one), and a pass that met values beyond `2^500` is an error
    /// ([`QuadError::RescaleOverBudget`]).
    ///
    /// A rule that is not [`Rule::guarded`] runs as it is, its limits
    /// checked, none of the above applied. A rule may answer a call that no
    /// limit can refuse before it checks them (Gauss–Legendre without its
    /// estimate on one axis of at most 100 nodes).
    #[inline]
    fn try_integrate<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        guard::checked(self, n, rng, f)
    }

    /// [`Rule::try_integrate`] for an integrand that cannot fail. The
    /// integrand moves into the rule: through a reference, each node
    /// reloaded its captures' addresses (1.3% of the time of `cos(50 x)`
    /// at n = 1e6 without the estimate, `examples/gl_race.rs`).
    fn integrate<const D: usize, V: Value, R: rand::Rng + ?Sized, F: FnMut([f64; D]) -> V>(
        &self,
        n: usize,
        rng: &mut R,
        mut f: F,
    ) -> Result<Estimate<V>, QuadError> {
        self.try_integrate(n, rng, move |u| Ok(f(u)))
    }
}

/// A computation generic over the rule, which [`BaseRule::visit`] and
/// [`AnyRule::visit`] run with the concrete rule, so that its integrand is
/// compiled into each rule. [`Rule::integrate`] on a [`BaseRule`] passes the
/// integrand as a trait object instead: one indirect call per evaluation,
/// measured at 7 to 16% of the time of `e^u` at a million evaluations (the
/// calibration family, which therefore uses this) and 2.7% of a rendering
/// experiment's run (`r-h-vs-a-tilted-rectangle`, whole process).
pub trait RuleVisitor {
    /// What the computation returns.
    type Output;
    /// Runs the computation with `rule`.
    fn visit<R: Rule>(self, rule: &R) -> Self::Output;
}

/// Declares the rule modules and generates [`BaseRule`], its dispatch and the
/// serde form of [`AnyRule`] from one line per rule:
/// `module::Type = "name in experiment files"`.
macro_rules! registry {
    ($($module:ident :: $rule:ident = $name:literal),+ $(,)?) => {
        $(
            pub mod $module;
            pub use $module::$rule;
        )+

        /// A single rule selected at run time (every rule but the product); its
        /// serde form is the rule spec of experiment files,
        /// `{"rule": "<name>", <the rule's parameters>}`.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
        #[serde(tag = "rule")]
        pub enum BaseRule {
            $(
                #[doc = concat!("`", $name, "`: [`", stringify!($rule), "`].")]
                #[serde(rename = $name)]
                $rule($rule),
            )+
        }

        /// The serde form of [`AnyRule`]: every single rule, and `product`.
        #[derive(Serialize, Deserialize, JsonSchema)]
        #[serde(tag = "rule")]
        #[schemars(rename = "Rule")]
        enum AnyRuleSpec {
            $(
                #[doc = concat!("`", $name, "`: [`", stringify!($rule), "`].")]
                #[serde(rename = $name)]
                $rule($rule),
            )+
            /// `product`: the iterated 2-D rule of two single rules.
            #[serde(rename = "product")]
            Product(Product<BaseRule, BaseRule>),
        }

        impl From<AnyRuleSpec> for AnyRule {
            fn from(spec: AnyRuleSpec) -> Self {
                match spec {
                    $(AnyRuleSpec::$rule(r) => AnyRule::Base(BaseRule::$rule(r)),)+
                    AnyRuleSpec::Product(p) => AnyRule::Product(Box::new(p)),
                }
            }
        }

        impl From<AnyRule> for AnyRuleSpec {
            fn from(rule: AnyRule) -> Self {
                match rule {
                    $(AnyRule::Base(BaseRule::$rule(r)) => AnyRuleSpec::$rule(r),)+
                    AnyRule::Product(p) => AnyRuleSpec::Product(*p),
                }
            }
        }

        impl BaseRule {
            /// Every single rule with its default parameters, in registry order.
            pub fn defaults() -> Vec<BaseRule> {
                vec![$(BaseRule::$rule(<$rule>::default())),+]
            }

            /// Runs `visitor` with the concrete rule (see [`RuleVisitor`]).
            pub fn visit<V: RuleVisitor>(&self, visitor: V) -> V::Output {
                match self { $(BaseRule::$rule(r) => visitor.visit(r),)+ }
            }

            /// Reads `{"rule": "<name>", <parameters>}`; a fault is returned with
            /// the path of its field below the rule (`rel_tol`) and what is wrong.
            pub fn from_json(value: &serde_json::Value) -> Result<BaseRule, (String, String)> {
                let Some(object) = value.as_object() else {
                    return Err((
                        String::new(),
                        format!(
                            "{value} is not a rule: expected {{\"rule\": <name>, <parameters>}}, the name one of {}",
                            [$($name),+].join(", ")
                        ),
                    ));
                };
                let mut params = object.clone();
                let tag = params.remove("rule");
                match tag.as_ref().and_then(|t| t.as_str()) {
                    $(Some($name) => parameters::<$rule>(params).map(BaseRule::$rule),)+
                    _ => Err((
                        "rule".into(),
                        format!(
                            "{} is not a single rule: expected one of {}",
                            tag.unwrap_or(serde_json::Value::Null),
                            [$($name),+].join(", ")
                        ),
                    )),
                }
            }
        }

        impl Rule for BaseRule {
            fn name(&self) -> &'static str {
                match self { $(BaseRule::$rule(r) => r.name(),)+ }
            }
            fn about(&self) -> &'static str {
                match self { $(BaseRule::$rule(r) => r.about(),)+ }
            }
            fn min_budget(&self, dim: usize) -> usize {
                match self { $(BaseRule::$rule(r) => r.min_budget(dim),)+ }
            }
            fn is_random(&self) -> bool {
                match self { $(BaseRule::$rule(r) => r.is_random(),)+ }
            }
            fn guarded(&self, dim: usize) -> bool {
                match self { $(BaseRule::$rule(r) => r.guarded(dim),)+ }
            }
            fn dimensions(&self) -> Dimensions {
                match self { $(BaseRule::$rule(r) => r.dimensions(),)+ }
            }
            fn check(&self) -> Result<(), QuadError> {
                match self { $(BaseRule::$rule(r) => r.check(),)+ }
            }
            fn resolution(&self, n: usize, dim: usize) -> f64 {
                match self { $(BaseRule::$rule(r) => r.resolution(n, dim),)+ }
            }
            fn memory(&self, n: usize, dim: usize) -> f64 {
                match self { $(BaseRule::$rule(r) => r.memory(n, dim),)+ }
            }
            fn evaluations(&self, n: usize, dim: usize) -> f64 {
                match self { $(BaseRule::$rule(r) => r.evaluations(n, dim),)+ }
            }
            fn integrate_unguarded<
                const D: usize,
                V: Value,
                R: rand::Rng + ?Sized,
                F: FnMut([f64; D]) -> Result<V, QuadError>,
            >(
                &self,
                n: usize,
                rng: &mut R,
                f: F,
            ) -> Result<Estimate<V>, QuadError> {
                // The integrand as a trait object: a rule chosen at run time
                // is compiled once per dimension and value type, where a
                // generic `F` compiled every rule of the registry again for
                // each integrand. A rule named by its own type, or reached
                // through `visit`, keeps its integrand inlined.
                let mut f = f;
                let f: &mut dyn FnMut([f64; D]) -> Result<V, QuadError> = &mut f;
                match self { $(BaseRule::$rule(r) => r.integrate_unguarded(n, rng, f),)+ }
            }
        }
    };
}

registry! {
    trapezoid::Trapezoid = "trapezoid",
    simpson::Simpson = "simpson",
    gauss_legendre::GaussLegendre = "gauss-legendre",
    gauss_kronrod::GaussKronrod = "gauss-kronrod",
    genz_malik::GenzMalik = "genz-malik",
    monte_carlo::MonteCarlo = "monte-carlo",
    stratified::Stratified = "stratified",
    sobol::Sobol = "sobol",
    halton::Halton = "halton",
}

/// A rule's parameters (the object without its `"rule"`), with the path of a
/// fault below the rule; a rule without parameters says so of any field.
fn parameters<T: serde::de::DeserializeOwned>(
    params: serde_json::Map<String, serde_json::Value>,
) -> Result<T, (String, String)> {
    let takes_none = serde_json::from_value::<T>(serde_json::Value::Null);
    if let Ok(rule) = takes_none {
        return match params.keys().next() {
            None => Ok(rule),
            Some(key) => Err((
                key.clone(),
                format!("unknown field `{key}`: this rule takes no parameters"),
            )),
        };
    }
    serde_path_to_error::deserialize(serde_json::Value::Object(params)).map_err(|e| {
        let path = e.path().to_string();
        (
            if path == "." { String::new() } else { path },
            e.inner().to_string(),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The registry's name for a rule (its serde tag) is the rule's own name.
    #[test]
    fn registry_names_match_rule_names() -> Result<(), serde_json::Error> {
        for rule in BaseRule::defaults() {
            let json = serde_json::to_value(&rule)?;
            assert_eq!(json["rule"], rule.name());
            assert_eq!(BaseRule::by_name(rule.name()), Ok(rule));
        }
        Ok(())
    }
}

//! Quadrature rules on the unit cube `[0, 1]^D`.
//!
//! A rule knows how to place weighted nodes in the unit cube for a budget of
//! `n` integrand evaluations; it never knows geometry (that is a
//! [`domain`](crate::domain)'s job) nor which equation it serves. Every rule
//! implements [`Rule`]; [`AnyRule`] selects one by name at run time.
//!
//! | name | rule | error estimate |
//! |---|---|---|
//! | `trapezoid` | composite trapezoid, product in D > 1 | Richardson, half step |
//! | `gauss-legendre` | Gauss–Legendre of any order, product in D > 1 | geometric tail of `Q_{m-2}, Q_{m-1}, Q_m` |
//! | `gauss-kronrod` | adaptive Gauss–Kronrod G7–K15 (D = 1) | embedded G7 |
//! | `monte-carlo` | plain Monte Carlo | standard error |
//! | `stratified` | jittered Monte Carlo, one sample per cell | second differences of neighbouring cells |
//! | `sobol` | Owen-scrambled Sobol' points (D <= 2), 8 scrambles | standard error over scrambles |
//! | `product(A,B)` | iterated 2-D rule from any two 1-D rules | outer estimate + integrated inner estimates |

pub mod gauss_kronrod;
pub mod gauss_legendre;
pub mod monte_carlo;
pub mod nodes;
pub mod product;
pub mod sobol;
pub mod stratified;
pub mod trapezoid;

pub use gauss_kronrod::GaussKronrod;
pub use gauss_legendre::GaussLegendre;
pub use monte_carlo::MonteCarlo;
pub use product::Product;
pub use sobol::Sobol;
pub use stratified::Stratified;
pub use trapezoid::Trapezoid;

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;

/// A quadrature rule on the unit cube `[0, 1]^D`.
pub trait Rule {
    /// The registry name (`gauss-legendre`, ...).
    fn name(&self) -> &'static str;

    /// Estimates `int_{[0,1]^D} f(u) du` with a budget of about `n` evaluations.
    ///
    /// `rng` drives the randomised rules and is ignored by deterministic ones;
    /// with the same `rng` state the result is bit-for-bit reproducible.
    fn integrate<const D: usize, V: Value, R: rand::Rng + ?Sized, F: FnMut([f64; D]) -> V>(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError>;
}

/// Nodes per axis for a product rule with a budget of `n` evaluations in `D`
/// dimensions: the largest `m` with `m^D <= n`; at least `min` (else an error
/// naming `name`).
pub fn per_axis<const D: usize>(n: usize, min: usize, name: &str) -> Result<usize, QuadError> {
    let need = min.checked_pow(D as u32).unwrap_or(usize::MAX);
    if n < need {
        return Err(QuadError::invalid(
            name,
            n,
            format!("a budget of at least {need} evaluations in {D} dimension(s)"),
        ));
    }
    let mut m = (n as f64).powf(1.0 / D as f64).round() as usize;
    // Correct the floating-point root to the exact integer root.
    while m > 1 && m.checked_pow(D as u32).is_none_or(|p| p > n) {
        m -= 1;
    }
    while (m + 1).checked_pow(D as u32).is_some_and(|p| p <= n) {
        m += 1;
    }
    Ok(m.max(min))
}

/// One line of `lightquad rules` per single rule: name and description.
pub const RULES: &[(&str, &str)] = &[
    (
        "trapezoid",
        "composite trapezoid (product rule in 2-D); Richardson error estimate from the half-step rule",
    ),
    (
        "gauss-legendre",
        "Gauss–Legendre of any order 1..=1e8 (product rule in 2-D); error estimate from Q_m, Q_(m-1), Q_(m-2)",
    ),
    (
        "gauss-kronrod",
        "adaptive Gauss–Kronrod G7-K15 on [0,1] (1-D); embedded error estimate",
    ),
    ("monte-carlo", "plain Monte Carlo, seeded; standard error"),
    (
        "stratified",
        "stratified (jittered) Monte Carlo, one sample per cell; second-difference standard error",
    ),
    (
        "sobol",
        "Owen-scrambled Sobol' points (1-D and 2-D), 8 independent scrambles; standard error",
    ),
];

/// The `lightquad rules` line for products, which take two rule names.
pub const PRODUCT_RULE: (&str, &str) = (
    "product(A,B)",
    "2-D iterated rule from any two rules above: A over the first coordinate, B over the second",
);

/// A single rule selected at run time (every rule but the product).
#[derive(Debug, Clone, PartialEq)]
pub enum BaseRule {
    /// [`Trapezoid`].
    Trapezoid(Trapezoid),
    /// [`GaussLegendre`].
    GaussLegendre(GaussLegendre),
    /// [`GaussKronrod`].
    GaussKronrod(GaussKronrod),
    /// [`MonteCarlo`].
    MonteCarlo(MonteCarlo),
    /// [`Stratified`].
    Stratified(Stratified),
    /// [`Sobol`].
    Sobol(Sobol),
}

/// Any rule selected at run time, products included.
#[derive(Debug, Clone, PartialEq)]
pub enum AnyRule {
    /// One rule.
    Base(BaseRule),
    /// The [`Product`] of two rules (kept apart from [`BaseRule`] so a product
    /// of products, which the type system could not bound, cannot be named).
    Product(Box<Product<BaseRule, BaseRule>>),
}

impl BaseRule {
    /// The rule named `name` with its default parameters.
    pub fn by_name(name: &str) -> Result<BaseRule, QuadError> {
        Ok(match name.trim() {
            "trapezoid" => BaseRule::Trapezoid(Trapezoid),
            "gauss-legendre" => BaseRule::GaussLegendre(GaussLegendre::default()),
            "gauss-kronrod" => BaseRule::GaussKronrod(GaussKronrod::default()),
            "monte-carlo" => BaseRule::MonteCarlo(MonteCarlo),
            "stratified" => BaseRule::Stratified(Stratified),
            "sobol" => BaseRule::Sobol(Sobol::default()),
            other => {
                return Err(QuadError::UnknownRule {
                    name: other.to_string(),
                    known: RULES.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "),
                });
            }
        })
    }
}

impl AnyRule {
    /// The rule named `name` with its default parameters; `product(A,B)` names
    /// the iterated product of two named rules.
    pub fn by_name(name: &str) -> Result<AnyRule, QuadError> {
        let name = name.trim();
        if let Some(args) = name
            .strip_prefix("product(")
            .and_then(|rest| rest.strip_suffix(')'))
        {
            let Some((outer, inner)) = split_top_level_comma(args) else {
                return Err(QuadError::invalid(
                    "rule",
                    name,
                    "product(A,B) with two rule names, e.g. product(gauss-legendre,trapezoid)",
                ));
            };
            return Ok(AnyRule::Product(Box::new(Product {
                outer: BaseRule::by_name(outer)?,
                inner: BaseRule::by_name(inner)?,
            })));
        }
        BaseRule::by_name(name).map(AnyRule::Base)
    }
}

impl From<BaseRule> for AnyRule {
    fn from(rule: BaseRule) -> Self {
        AnyRule::Base(rule)
    }
}

impl Rule for BaseRule {
    fn name(&self) -> &'static str {
        match self {
            BaseRule::Trapezoid(r) => r.name(),
            BaseRule::GaussLegendre(r) => r.name(),
            BaseRule::GaussKronrod(r) => r.name(),
            BaseRule::MonteCarlo(r) => r.name(),
            BaseRule::Stratified(r) => r.name(),
            BaseRule::Sobol(r) => r.name(),
        }
    }

    fn integrate<const D: usize, V: Value, R: rand::Rng + ?Sized, F: FnMut([f64; D]) -> V>(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        match self {
            BaseRule::Trapezoid(r) => r.integrate(n, rng, f),
            BaseRule::GaussLegendre(r) => r.integrate(n, rng, f),
            BaseRule::GaussKronrod(r) => r.integrate(n, rng, f),
            BaseRule::MonteCarlo(r) => r.integrate(n, rng, f),
            BaseRule::Stratified(r) => r.integrate(n, rng, f),
            BaseRule::Sobol(r) => r.integrate(n, rng, f),
        }
    }
}

impl Rule for AnyRule {
    fn name(&self) -> &'static str {
        match self {
            AnyRule::Base(r) => r.name(),
            AnyRule::Product(r) => r.name(),
        }
    }

    fn integrate<const D: usize, V: Value, R: rand::Rng + ?Sized, F: FnMut([f64; D]) -> V>(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        match self {
            AnyRule::Base(r) => r.integrate(n, rng, f),
            AnyRule::Product(r) => r.integrate(n, rng, f),
        }
    }
}

/// Splits `A,B` at the comma that is not inside parentheses.
fn split_top_level_comma(s: &str) -> Option<(&str, &str)> {
    let mut depth = 0i32;
    for (i, ch) in s.char_indices() {
        match ch {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' if depth == 0 => return Some((s[..i].trim(), s[i + 1..].trim())),
            _ => {}
        }
    }
    None
}

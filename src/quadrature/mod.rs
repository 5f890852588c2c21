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
//! | `gauss-legendre` | Gauss–Legendre of any order, product in D > 1 | `|Q_m - Q_{m-1}|` |
//! | `gauss-kronrod` | adaptive Gauss–Kronrod G7–K15 (D = 1) | embedded G7 |
//! | `monte-carlo` | plain Monte Carlo | standard error |
//! | `stratified` | jittered Monte Carlo, one sample per cell | second differences of neighbouring cells |
//! | `sobol` | Owen-scrambled Sobol' points (D <= 2), 8 scrambles | standard error over scrambles |

pub mod gauss_kronrod;
pub mod gauss_legendre;
pub mod monte_carlo;
pub mod nodes;
pub mod sobol;
pub mod stratified;
pub mod trapezoid;

pub use gauss_kronrod::GaussKronrod;
pub use gauss_legendre::GaussLegendre;
pub use monte_carlo::MonteCarlo;
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

/// One line of `lightquad rules`: name and description.
pub const RULES: &[(&str, &str)] = &[
    (
        "trapezoid",
        "composite trapezoid (product rule in 2-D); Richardson error estimate from the half-step rule",
    ),
    (
        "gauss-legendre",
        "Gauss–Legendre of any order 1..=1e8 (product rule in 2-D); error estimate |Q_m - Q_(m-1)|",
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

/// A rule selected at run time.
#[derive(Debug, Clone, PartialEq)]
pub enum AnyRule {
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

impl AnyRule {
    /// The rule named `name` with its default parameters.
    pub fn by_name(name: &str) -> Result<AnyRule, QuadError> {
        Ok(match name {
            "trapezoid" => AnyRule::Trapezoid(Trapezoid),
            "gauss-legendre" => AnyRule::GaussLegendre(GaussLegendre::default()),
            "gauss-kronrod" => AnyRule::GaussKronrod(GaussKronrod::default()),
            "monte-carlo" => AnyRule::MonteCarlo(MonteCarlo),
            "stratified" => AnyRule::Stratified(Stratified),
            "sobol" => AnyRule::Sobol(Sobol::default()),
            _ => {
                return Err(QuadError::UnknownRule {
                    name: name.to_string(),
                    known: RULES.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "),
                });
            }
        })
    }
}

impl Rule for AnyRule {
    fn name(&self) -> &'static str {
        match self {
            AnyRule::Trapezoid(r) => r.name(),
            AnyRule::GaussLegendre(r) => r.name(),
            AnyRule::GaussKronrod(r) => r.name(),
            AnyRule::MonteCarlo(r) => r.name(),
            AnyRule::Stratified(r) => r.name(),
            AnyRule::Sobol(r) => r.name(),
        }
    }

    fn integrate<const D: usize, V: Value, R: rand::Rng + ?Sized, F: FnMut([f64; D]) -> V>(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        match self {
            AnyRule::Trapezoid(r) => r.integrate(n, rng, f),
            AnyRule::GaussLegendre(r) => r.integrate(n, rng, f),
            AnyRule::GaussKronrod(r) => r.integrate(n, rng, f),
            AnyRule::MonteCarlo(r) => r.integrate(n, rng, f),
            AnyRule::Stratified(r) => r.integrate(n, rng, f),
            AnyRule::Sobol(r) => r.integrate(n, rng, f),
        }
    }
}

//! The result of every integration: a value, an error estimate and a cost.

use crate::value::Value;

/// An integral estimate with the rule's own error estimate and its cost.
///
/// `error` is the rule's estimate of `|value - exact|` per channel: a standard
/// error for Monte Carlo rules, a Richardson or embedded-rule difference for
/// deterministic ones; `f64::INFINITY` when the rule has no information to
/// estimate it (a one-node rule). Reports put it beside the true error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate<V: Value> {
    /// The integral estimate.
    pub value: V,
    /// The rule's estimate of the absolute error, per channel.
    pub error: V,
    /// Integrand evaluations spent, including those spent on the error estimate.
    pub evaluations: u64,
}

impl<V: Value> Estimate<V> {
    /// Largest per-channel error estimate.
    pub fn max_error(&self) -> f64 {
        self.error.max_abs()
    }

    /// Scales value and error by `s` (a Jacobian or an interval length).
    pub fn scaled(self, s: f64) -> Self {
        Estimate {
            value: self.value.map(|v| v * s),
            error: self.error.map(|e| e * s.abs()),
            evaluations: self.evaluations,
        }
    }

    /// Adds an independent estimate over a disjoint region: values add, errors
    /// add (a bound for deterministic rules, conservative for Monte Carlo).
    pub fn combine(self, other: Self) -> Self {
        Estimate {
            value: self.value.zip(other.value, |a, b| a + b),
            error: self.error.zip(other.error, |a, b| a + b),
            evaluations: self.evaluations + other.evaluations,
        }
    }
}

//! The result of every integration: a value, an error estimate and a cost.

use crate::value::Value;

/// What an [`Estimate`]'s `error` is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// A deterministic rule's estimate of `|value - exact|` (Richardson,
    /// embedded rule, geometric tail). Estimates over disjoint regions add.
    Deterministic,
    /// One standard error of a random estimate. Standard errors of
    /// independent estimates over disjoint regions add in quadrature
    /// (`sqrt(a^2 + b^2)`); adding them linearly would overstate the
    /// uncertainty by up to the square root of the number of regions.
    StandardError,
}

/// An integral estimate with the rule's own error estimate and its cost.
///
/// `error` is the rule's estimate of `|value - exact|` per channel: a standard
/// error for Monte Carlo rules, a Richardson or embedded-rule difference for
/// deterministic ones (`kind` says which); `f64::INFINITY` when the rule has no
/// information to estimate it (a one-node rule). `reliable` is false when the
/// rule saw that the assumption behind its estimate does not hold (differences
/// that do not shrink the way the estimate assumes): reports flag such an
/// estimate instead of presenting it as trustworthy. Reports put the error
/// beside the true error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate<V: Value> {
    /// The integral estimate.
    pub value: V,
    /// The rule's estimate of the absolute error, per channel.
    pub error: V,
    /// Integrand evaluations spent, including those spent on the error estimate.
    pub evaluations: u64,
    /// What `error` is.
    pub kind: ErrorKind,
    /// False when the rule itself doubts its error estimate.
    pub reliable: bool,
}

impl<V: Value> Estimate<V> {
    /// A deterministic rule's estimate, trusted.
    pub fn deterministic(value: V, error: V, evaluations: u64) -> Self {
        Estimate {
            value,
            error,
            evaluations,
            kind: ErrorKind::Deterministic,
            reliable: true,
        }
    }

    /// A random estimate with its standard error.
    pub fn random(value: V, standard_error: V, evaluations: u64) -> Self {
        Estimate {
            value,
            error: standard_error,
            evaluations,
            kind: ErrorKind::StandardError,
            reliable: true,
        }
    }

    /// Zero with no cost: the neutral element of [`Estimate::combine`] (a
    /// zero deterministic error leaves either kind of error unchanged and
    /// takes the other's kind).
    pub fn zero() -> Self {
        Estimate {
            value: V::zero(),
            error: V::zero(),
            evaluations: 0,
            kind: ErrorKind::Deterministic,
            reliable: true,
        }
    }

    /// The same estimate, marked as one the rule doubts.
    pub fn doubted(self) -> Self {
        Estimate {
            reliable: false,
            ..self
        }
    }

    /// Largest per-channel error estimate.
    pub fn max_error(&self) -> f64 {
        self.error.max_abs()
    }

    /// Scales value and error by `s` (a Jacobian or an interval length).
    pub fn scaled(self, s: f64) -> Self {
        Estimate {
            value: self.value.map(|v| v * s),
            error: self.error.map(|e| e * s.abs()),
            ..self
        }
    }

    /// Adds an independent estimate over a disjoint region: values add;
    /// deterministic errors add, standard errors add in quadrature. A sum with
    /// a random part is random, and its error is the linear sum of the parts
    /// (a deterministic bound plus a standard error: conservative).
    pub fn combine(self, other: Self) -> Self {
        use ErrorKind::{Deterministic, StandardError};
        let (kind, error) = match (self.kind, other.kind) {
            (StandardError, StandardError) => (
                StandardError,
                self.error.zip(other.error, |a, b| a.hypot(b)),
            ),
            (Deterministic, Deterministic) => {
                (Deterministic, self.error.zip(other.error, |a, b| a + b))
            }
            _ => (StandardError, self.error.zip(other.error, |a, b| a + b)),
        };
        Estimate {
            value: self.value.zip(other.value, |a, b| a + b),
            error,
            evaluations: self.evaluations + other.evaluations,
            kind,
            reliable: self.reliable && other.reliable,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_errors_of_disjoint_regions_add_in_quadrature_and_bounds_linearly() {
        let se = Estimate::random(1.0, 3.0, 10).combine(Estimate::random(2.0, 4.0, 10));
        assert_eq!((se.value, se.error, se.evaluations), (3.0, 5.0, 20));
        assert_eq!(se.kind, ErrorKind::StandardError);
        let det =
            Estimate::deterministic(1.0, 3.0, 10).combine(Estimate::deterministic(2.0, 4.0, 10));
        assert_eq!((det.error, det.kind), (7.0, ErrorKind::Deterministic));
        let mixed = Estimate::deterministic(1.0, 3.0, 1).combine(Estimate::random(2.0, 4.0, 1));
        assert_eq!((mixed.error, mixed.kind), (7.0, ErrorKind::StandardError));
        let zero = Estimate::zero().combine(Estimate::random(2.0, 4.0, 1));
        assert_eq!((zero.error, zero.kind), (4.0, ErrorKind::StandardError));
        let doubted = Estimate::deterministic(1.0, 1.0, 1)
            .doubted()
            .combine(Estimate::deterministic(1.0, 1.0, 1));
        assert!(!doubted.reliable);
    }
}

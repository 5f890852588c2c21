//! Product rules on `[0, 1]^2` built from any two 1-D rules, by iterated
//! integration:
//!
//! `Q = A_u[ g ]`, `g(u) = B_v[ f(u, .) ]`,
//!
//! with `m = floor(sqrt(n))` budget for each axis. Any pairing works: Gauss–
//! Legendre in the polar angle with the trapezoid rule in a periodic azimuth
//! (spectrally accurate there), adaptive Gauss–Kronrod outside Monte Carlo, ...
//!
//! The error estimate adds the outer rule's estimate for `g` to the outer
//! rule's integral of the inner estimates: both are carried through the outer
//! rule as one value ([`WithError`]), so no rule needs to expose its nodes.

use rand::SeedableRng;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Dimensions, Rule, integer_root, per_axis};
use crate::error::QuadError;
use crate::estimate::{ErrorKind, Estimate};
use crate::value::Value;

/// The iterated product of an `outer` rule (first coordinate) and an `inner`
/// rule (second coordinate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Product<A, B> {
    /// Rule over the first coordinate.
    pub outer: A,
    /// Rule over the second coordinate, applied at every outer node.
    pub inner: B,
}

/// A value and the inner rule's error estimate, integrated together by the
/// outer rule (channels: the value's, then the error's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WithError<V: Value> {
    /// The inner integral.
    pub value: V,
    /// Its error estimate.
    pub error: V,
}

impl<V: Value> Value for WithError<V> {
    const CHANNELS: usize = 2 * V::CHANNELS;
    fn zero() -> Self {
        WithError {
            value: V::zero(),
            error: V::zero(),
        }
    }
    fn channel(&self, i: usize) -> f64 {
        if i < V::CHANNELS {
            self.value.channel(i)
        } else {
            self.error.channel(i - V::CHANNELS)
        }
    }
    fn from_fn(mut f: impl FnMut(usize) -> f64) -> Self {
        let value = V::from_fn(&mut f);
        let error = V::from_fn(|i| f(i + V::CHANNELS));
        WithError { value, error }
    }
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        WithError {
            value: self.value.map(&f),
            error: self.error.map(&f),
        }
    }
    fn zip(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        WithError {
            value: self.value.zip(other.value, &f),
            error: self.error.zip(other.error, &f),
        }
    }
    /// Only the value must be finite: an inner rule may report an infinite
    /// error (it had no information), which makes the total error infinite.
    fn all_finite(&self) -> bool {
        self.value.all_finite()
    }
}

impl<A: Rule, B: Rule> Rule for Product<A, B> {
    fn name(&self) -> &'static str {
        "product"
    }

    fn about(&self) -> &'static str {
        "2-D iterated rule: outer over the first coordinate, inner over the second"
    }

    /// Both factors get `floor(sqrt(n))` nodes: each needs its own minimum.
    fn min_budget(&self, _dim: usize) -> usize {
        let m = self.outer.min_budget(1).max(self.inner.min_budget(1));
        m.saturating_mul(m)
    }

    fn is_random(&self) -> bool {
        self.outer.is_random() || self.inner.is_random()
    }

    fn dimensions(&self) -> Dimensions {
        Dimensions { min: 2, max: 2 }
    }

    /// The outer factor's evaluations at `floor(sqrt(n))` nodes, each one an
    /// inner integral of the inner factor's.
    fn evaluations(&self, n: usize, _dim: usize) -> f64 {
        let m = integer_root(n, 2);
        self.outer.evaluations(m, 1) * self.inner.evaluations(m, 1)
    }

    /// Both factors' memory at their `floor(sqrt(n))` nodes each.
    fn memory(&self, n: usize, _dim: usize) -> f64 {
        let m = integer_root(n, 2);
        self.outer.memory(m, 1) + self.inner.memory(m, 1)
    }

    fn check(&self) -> Result<(), QuadError> {
        let factors = [
            (
                "outer",
                self.outer.name(),
                self.outer.dimensions(),
                self.outer.check(),
            ),
            (
                "inner",
                self.inner.name(),
                self.inner.dimensions(),
                self.inner.check(),
            ),
        ];
        for (field, name, dimensions, checked) in factors {
            if !dimensions.contains(1) {
                return Err(QuadError::invalid(
                    field,
                    name,
                    "a rule that integrates in one dimension",
                ));
            }
            // A factor's parameter is named below the factor (`inner.replicates`).
            checked.map_err(|e| match e {
                QuadError::InvalidParameter {
                    name,
                    value,
                    accepted,
                } => QuadError::InvalidParameter {
                    name: format!("{field}.{name}"),
                    value,
                    accepted,
                },
                other => other,
            })?;
        }
        Ok(())
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
        mut f: F,
    ) -> Result<Estimate<V>, QuadError> {
        crate::quadrature::check_budget(n)?;
        if D != 2 {
            return Err(QuadError::UnsupportedDimension {
                rule: "product",
                dim: D,
                supported: "2",
            });
        }
        let m = per_axis::<2>(n, 1, "n")?;
        // The inner rule gets its own stream, derived from the caller's, so the
        // result is reproducible from the caller's rng state.
        let mut inner_rng = rand_pcg::Pcg64::seed_from_u64(rng.next_u64());
        let mut inner_evaluations = 0u64;
        let mut inner_random = false;
        let mut inner_reliable = true;
        let outer = self.outer.try_integrate(m, rng, |u: [f64; 1]| {
            let inner = self.inner.try_integrate(m, &mut inner_rng, |v: [f64; 1]| {
                let mut p = [0.0; D];
                p[0] = u[0];
                p[1] = v[0];
                // A value that is not finite is named at its point in the
                // square, not at the inner rule's point on its line.
                let y = f(p)?;
                if y.all_finite() {
                    Ok(y)
                } else {
                    Err(super::nodes::non_finite(&p, &y))
                }
            })?;
            inner_evaluations += inner.evaluations;
            inner_random |= inner.kind == ErrorKind::StandardError;
            inner_reliable &= inner.reliable;
            Ok(WithError {
                value: inner.value,
                error: inner.error,
            })
        })?;
        // Total error. A random outer rule over random inner estimates: the
        // spread of the inner values about their mean is part of the outer
        // sample variance, so the outer standard error is the whole standard
        // error. Otherwise the outer rule's estimate for g plus the integrated
        // inner estimates (for a deterministic outer rule over random inner
        // ones this adds standard errors linearly: conservative).
        // An inner rule without an error estimate (one node, or
        // `error_estimate: false`) reports an infinite error, and the
        // outer rule's sum of them is infinite; an outer rule whose
        // weights had both signs would sum them to `inf - inf`, NaN, which
        // the guard would report as an overflow of the value: the total
        // error is infinite then too.
        let random_outer = outer.kind == ErrorKind::StandardError;
        let error = V::from_fn(|c| {
            let inner = outer.value.error.channel(c).abs();
            let inner = if inner.is_nan() { f64::INFINITY } else { inner };
            if random_outer && inner_random {
                outer.error.value.channel(c)
            } else {
                outer.error.value.channel(c) + inner
            }
        });
        let kind = if random_outer || inner_random {
            ErrorKind::StandardError
        } else {
            ErrorKind::Deterministic
        };
        Ok(Estimate {
            value: outer.value.value,
            error,
            evaluations: inner_evaluations,
            kind,
            reliable: outer.reliable && inner_reliable,
            alike: false,
        })
    }
}

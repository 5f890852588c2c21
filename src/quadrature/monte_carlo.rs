//! Plain Monte Carlo: `Q = (1/N) sum f(U_i)` with `U_i` independent and uniform
//! on `[0, 1)^D`; standard error `s / sqrt(N)` with the sample standard deviation
//! `s` accumulated by Welford's update (no cancellation when the mean is large),
//! widened to the Student-t interval of `N - 1` degrees of freedom
//! ([`t95_factor`]).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Rule;
use crate::error::QuadError;
use crate::estimate::{Estimate, t95_factor};
use crate::quadrature::nodes::non_finite;
use crate::value::Value;
use rand::RngExt;

/// Plain Monte Carlo with independent uniform samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MonteCarlo;

/// Welford's running mean and sum of squared deviations, per channel.
#[derive(Debug, Clone, Copy)]
pub struct Welford<V: Value> {
    count: u64,
    mean: V,
    m2: V,
}

impl<V: Value> Default for Welford<V> {
    fn default() -> Self {
        Welford {
            count: 0,
            mean: V::zero(),
            m2: V::zero(),
        }
    }
}

impl<V: Value> Welford<V> {
    /// Adds one sample: `mean += (x - mean)/k`, `m2 += (x - mean_old)(x - mean_new)`.
    #[inline]
    pub fn add(&mut self, x: V) {
        self.count += 1;
        let k = self.count as f64;
        let old = self.mean;
        self.mean = old.zip(x, |m, x| m + (x - m) / k);
        let new = self.mean;
        self.m2 = V::from_fn(|i| {
            self.m2.channel(i) + (x.channel(i) - old.channel(i)) * (x.channel(i) - new.channel(i))
        });
    }

    /// Number of samples.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The sample mean.
    pub fn mean(&self) -> V {
        self.mean
    }

    /// Standard error of the mean, `sqrt(m2 / ((k - 1) k))`; infinite below two samples.
    pub fn standard_error(&self) -> V {
        let k = self.count as f64;
        if self.count < 2 {
            return V::zero().map(|_| f64::INFINITY);
        }
        self.m2.map(|m2| (m2 / ((k - 1.0) * k)).sqrt())
    }

    /// [`standard_error`](Self::standard_error) times
    /// [`t95_factor`]`(k - 1)`: `mean +- 1.96` of it is the 95% Student-t
    /// interval of `k` samples.
    pub fn interval_error(&self) -> V {
        let t = t95_factor(self.count as f64 - 1.0);
        self.standard_error().map(|e| e * t)
    }
}

impl Rule for MonteCarlo {
    fn name(&self) -> &'static str {
        "monte-carlo"
    }

    fn about(&self) -> &'static str {
        "plain Monte Carlo, seeded; standard error"
    }

    /// Two samples: a standard error needs them.
    fn min_budget(&self, _dim: usize) -> usize {
        2
    }

    fn is_random(&self) -> bool {
        true
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
        if n < 2 {
            return Err(QuadError::invalid(
                "n",
                n,
                "at least 2 samples (a standard error needs two)",
            ));
        }
        let mut acc = Welford::<V>::default();
        for _ in 0..n {
            let mut p = [0.0; D];
            for c in p.iter_mut() {
                *c = rng.random::<f64>();
            }
            let y = f(p)?;
            if !y.all_finite() {
                return Err(non_finite(&p, &y));
            }
            acc.add(y);
        }
        Ok(Estimate::random(
            acc.mean(),
            acc.interval_error(),
            n as u64,
        ))
    }
}

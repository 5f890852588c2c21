//! Stratified (jittered) Monte Carlo: `[0, 1]^D` is cut into `m^D` equal cells
//! and each cell gets one uniform sample, `Q = (1/N) sum f(U_i)`, `N = m^D`.
//!
//! For smooth f the error falls as `N^(-1/2 - 1/D)` (N^-1 in 2-D), against
//! `N^(-1/2)` for plain Monte Carlo.
//!
//! With one sample per cell the within-cell variances `sigma_i^2` cannot be
//! estimated cell by cell. Neighbouring cells along a row are taken in
//! triples: `(f_a - 2 f_b + f_c)^2 / 6` estimates their mean `sigma^2`, and the
//! second difference cancels the linear trend of the cell means that makes the
//! common paired estimate `(f_a - f_b)^2 / 2` several times too large for smooth
//! integrands (a gradient `g` across cells of width `h` adds `(g h)^2`, while
//! `sigma^2` itself is only `(g h)^2 / 12`). Then
//! `Var(Q) = (1/N^2) sum_i sigma_i^2 ~ (1/N^2) (N / T) sum_triples (...)^2 / 6`
//! over the `T` triples. The standard error has `T` degrees of freedom and is
//! widened by [`t95_factor`]`(T)` to the Student-t interval.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Rule, per_axis};
use crate::error::QuadError;
use crate::estimate::{Estimate, t95_factor};
use crate::quadrature::nodes::non_finite;
use crate::sum::Compensated;
use crate::value::Value;
use rand::RngExt;

/// Jittered sampling, one sample per cell of an `m^D` grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Stratified;

impl Rule for Stratified {
    fn name(&self) -> &'static str {
        "stratified"
    }

    fn about(&self) -> &'static str {
        "stratified (jittered) Monte Carlo, one sample per cell; second-difference standard error"
    }

    /// Two cells per axis: the standard error compares neighbouring cells.
    fn min_budget(&self, dim: usize) -> usize {
        if dim <= 1 {
            2
        } else {
            2usize.saturating_pow(dim as u32)
        }
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
        let m = per_axis::<D>(n, 1, "n")?;
        let cells = m.pow(D as u32);
        if cells < 2 {
            return Err(QuadError::invalid(
                "n",
                n,
                format!("at least 2^{D} evaluations (two cells per axis)"),
            ));
        }
        // With rows shorter than three cells there are no triples and the
        // error is reported as infinite.
        let inv_m = 1.0 / m as f64;
        let mut sum = Compensated::<V>::new();
        let mut triple_sq = Compensated::<V>::new();
        let mut triples = 0usize;
        let mut row: [V; 2] = [V::zero(); 2];
        let mut in_triple = 0usize;
        let mut idx = [0usize; D];
        for _ in 0..cells {
            let mut p = [0.0; D];
            for d in 0..D {
                p[d] = (idx[d] as f64 + rng.random::<f64>()) * inv_m;
            }
            let y = f(p)?;
            if !y.all_finite() {
                return Err(non_finite(&p, &y));
            }
            sum.add(y);
            // Triples of consecutive cells within one row (last axis).
            if in_triple < 2 {
                row[in_triple] = y;
                in_triple += 1;
            } else {
                let (a, b) = (row[0], row[1]);
                triple_sq.add(V::from_fn(|c| {
                    let d2 = a.channel(c) - 2.0 * b.channel(c) + y.channel(c);
                    d2 * d2 / 6.0
                }));
                triples += 1;
                in_triple = 0;
            }
            // Next cell, last axis fastest; a new row starts a new triple.
            for d in (0..D).rev() {
                idx[d] += 1;
                if idx[d] < m {
                    break;
                }
                idx[d] = 0;
            }
            if idx[D - 1] == 0 {
                in_triple = 0;
            }
        }
        let nf = cells as f64;
        // Each triple estimates the mean sigma^2 of its cells; cells outside a
        // triple (rows shorter than 3, row ends) get the average.
        let variance_sum = if triples > 0 {
            triple_sq.total().map(|s| s * nf / triples as f64)
        } else {
            V::zero().map(|_| f64::INFINITY)
        };
        // Each triple's squared second difference is one degree of freedom
        // of the variance estimate.
        let t = t95_factor(triples as f64);
        Ok(Estimate::random(
            sum.total().map(|s| s / nf),
            variance_sum.map(|v| v.sqrt() / nf * t),
            cells as u64,
        ))
    }
}

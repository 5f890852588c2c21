//! Stratified (jittered) Monte Carlo: `[0, 1]^D` is cut into `m^D` equal cells
//! and each cell gets one uniform sample, `Q = (1/N) sum f(U_i)`, `N = m^D`.
//!
//! For smooth f the error falls as `N^(-1/2 - 1/D)` (N^-1 in 2-D), against
//! `N^(-1/2)` for plain Monte Carlo.
//!
//! With one sample per cell the within-cell variances `sigma_i^2` cannot be
//! estimated cell by cell. Neighbouring cells along a row are taken in
//! triples: `E (f_a - 2 f_b + f_c)^2 = sigma_a^2 + 4 sigma_b^2 + sigma_c^2`,
//! and the second difference cancels the linear trend of the cell means that
//! makes the common paired estimate `(f_a - f_b)^2 / 2` several times too
//! large for smooth integrands (a gradient `g` across cells of width `h` adds
//! `(g h)^2`, while `sigma^2` itself is only `(g h)^2 / 12`). Every cell is in
//! a triple: a row is cut into triples from its start, and its last three
//! cells form one more where the row's length is not a multiple of 3. A
//! triple inside the row contributes `d^2 / 2` to `sum_i sigma_i^2` (exact
//! for equal variances), the row's first and last `d^2`, which bounds the sum
//! of their three variances whichever cell carries it (an endpoint
//! singularity: with `d^2 / 2` the interval covered 60% of the time for
//! `x^-1/4`). `Var(Q) = (1/N^2) sum_i sigma_i^2`, and the interval is
//! Student-t's at the Welch-Satterthwaite degrees of freedom of the triples'
//! terms. Measured coverage of `+- 1.96` errors over 2000 repeats, n = 8 ..
//! 1024: smooth integrands 95-99.8%, `e^{10x}` 97-99.8% (26-94% before every
//! cell was in a triple), `x^-1/4` 90-91%, `x^-0.45` 88-89%. A jump inside
//! one cell is seen only when that cell's sample lands on its smaller side
//! (a step at 0.97: 25-100% depending on n).

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
        "stratified (jittered) Monte Carlo, one sample per cell; second-difference standard error, Student-t interval"
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
        let mut variance = Compensated::<V>::new();
        // Squares of the triples' terms, for the effective degrees of freedom.
        let mut squares = Compensated::<V>::new();
        let mut triples = 0usize;
        // The row's last three values, by position modulo 3.
        let mut last: [V; 3] = [V::zero(); 3];
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
            // Triples of consecutive cells within one row (last axis): the
            // row's first and last triple count `d^2`, those between `d^2 / 2`.
            let pos = idx[D - 1];
            last[pos % 3] = y;
            let first = pos == 2;
            let closing = pos == m - 1 && m > 3;
            let between = pos % 3 == 2 && pos > 2 && pos < m - 1;
            if first || closing || between {
                let (a, b, c) = (last[(pos + 1) % 3], last[(pos + 2) % 3], y);
                let weight = if between { 0.5 } else { 1.0 };
                let term = V::from_fn(|k| {
                    let d = a.channel(k) - 2.0 * b.channel(k) + c.channel(k);
                    weight * d * d
                });
                variance.add(term);
                squares.add(term.map(|x| x * x));
                triples += 1;
            }
            // Next cell, last axis fastest.
            for d in (0..D).rev() {
                idx[d] += 1;
                if idx[d] < m {
                    break;
                }
                idx[d] = 0;
            }
        }
        let nf = cells as f64;
        let variance_sum = if triples > 0 {
            variance.total()
        } else {
            V::zero().map(|_| f64::INFINITY)
        };
        // Each triple's term is one degree of freedom of the variance
        // estimate when the terms are alike; where a few cells carry the
        // variance (an endpoint singularity, a jump inside a cell) the
        // Welch-Satterthwaite count `(sum s)^2 / sum s^2` is near 1, and so
        // the interval is Student-t's at that count.
        let squares = squares.total();
        let t = V::from_fn(|k| {
            let (v, q) = (variance_sum.channel(k), squares.channel(k));
            let dof = if q > 0.0 { v * v / q } else { triples as f64 };
            t95_factor(dof.min(triples as f64))
        });
        Ok(Estimate::random(
            sum.total().map(|s| s / nf),
            variance_sum.zip(t, |v, t| v.sqrt() / nf * t),
            cells as u64,
        ))
    }
}

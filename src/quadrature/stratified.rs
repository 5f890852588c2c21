//! Stratified (jittered) Monte Carlo: `[0, 1]^D` is cut into `m^D` equal cells
//! and each cell gets one uniform sample, `Q = (1/N) sum f(U_i)`, `N = m^D`.
//!
//! For smooth f the error falls as `N^(-1/2 - 1/D)` (N^-1 in 2-D), against
//! `N^(-1/2)` for plain Monte Carlo. With one sample per cell the within-cell
//! variance is estimated from pairs of neighbouring cells: `(f_a - f_b)^2`
//! estimates `sigma_a^2 + sigma_b^2` (slightly high when the cell means differ),
//! so `Var(Q) ~ (1/N^2) sum_pairs (f_a - f_b)^2`.

use super::{Rule, per_axis};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::nodes::non_finite;
use crate::sum::Compensated;
use crate::value::Value;
use rand::RngExt;

/// Jittered sampling, one sample per cell of an `m^D` grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stratified;

impl Rule for Stratified {
    fn name(&self) -> &'static str {
        "stratified"
    }

    fn integrate<const D: usize, V: Value, R: rand::Rng + ?Sized, F: FnMut([f64; D]) -> V>(
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
        let inv_m = 1.0 / m as f64;
        let mut sum = Compensated::<V>::new();
        let mut pair_sq = Compensated::<V>::new();
        let mut pending: Option<V> = None;
        let mut idx = [0usize; D];
        for _ in 0..cells {
            let mut p = [0.0; D];
            for d in 0..D {
                p[d] = (idx[d] as f64 + rng.random::<f64>()) * inv_m;
            }
            let y = f(p);
            if !y.all_finite() {
                return Err(non_finite(&p, &y));
            }
            sum.add(y);
            match pending.take() {
                None => pending = Some(y),
                Some(a) => pair_sq.add(a.zip(y, |a, b| (a - b) * (a - b))),
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
        let pairs = (cells / 2) as f64;
        // An unpaired last cell gets the average per-cell variance of the others.
        let variance_sum = pair_sq.total().map(|s| s * nf / (2.0 * pairs));
        Ok(Estimate {
            value: sum.total().map(|s| s / nf),
            error: variance_sum.map(|v| v.sqrt() / nf),
            evaluations: cells as u64,
        })
    }
}

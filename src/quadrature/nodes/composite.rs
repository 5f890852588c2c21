//! Composite Newton–Cotes rules (trapezoid, Simpson) as data: their
//! nested weights and their tensor product.

use std::cell::RefCell;
use std::sync::Arc;

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;

use super::{UnitNodes, product_sum, richardson};

/// Fewest points per axis at which a composite rule's estimate is trusted.
/// Below it the rule has at most 8 intervals; a narrow peak between its
/// points showed estimates down to 4e-6 of the true error at 3 to 9
/// points (Lorentzians of width 1e-2 to 1e-4), where one node's share of
/// the sum cannot tell a peak from a smooth integrand on so few nodes
/// ([`dominated`]). The same bound as Gauss–Legendre's 16 nodes.
///
/// [`dominated`]: super::dominated
pub const CHECKED_POINTS: usize = 17;

/// Largest number of points per axis of a composite rule (the node table
/// takes 40 bytes a point).
pub const MAX_POINTS: usize = 100_000_000;

/// Weights on the `m` points `i h`, `h = 1/(m - 1)`, of a composite rule
/// built from `block` (a panel group's weights in units of its panel width:
/// `[1/2, 1/2]` for the trapezoid, `[1/3, 4/3, 1/3]` for a Simpson pair) on
/// panels of width `stride h` as far as whole blocks fit from 0, then the
/// rest with the stride halved, and so on to `h`.
///
/// Where `stride` blocks tile `[0, 1]` this is the plain composite rule on
/// every `stride`-th point (the `2h`, `4h`, `8h` rules Richardson's estimate
/// compares). Where they do not (a trapezoid at `m = 2^k - 1` points, whose
/// `2^k - 2` intervals halve only once) the rule keeps its order on the
/// finer tail, and its error is the coarse rule's to within the tail's share
/// of the interval: a third and fourth level for the estimate's check, where
/// before only one difference was there to trust. A block never straddles
/// a point it cannot use, so the weights stay on the points and sum to 1.
pub fn coarse_weights(m: usize, stride: usize, block: &[f64]) -> Vec<f64> {
    let h = 1.0 / (m - 1) as f64;
    let span = block.len() - 1;
    let mut w = vec![0.0; m];
    let (mut start, mut s) = (0, stride);
    while start < m - 1 && s > 0 {
        let blocks = (m - 1 - start) / (span * s);
        for b in 0..blocks {
            let first = start + b * span * s;
            for (j, &wj) in block.iter().enumerate() {
                w[first + j * s] += wj * s as f64 * h;
            }
        }
        start += blocks * span * s;
        s /= 2;
    }
    w
}

/// A composite Newton–Cotes rule (trapezoid, Simpson) as data: how many
/// points per axis a budget gives, its node table, and its order.
pub struct Composite {
    /// Rule name, for errors and the node cache.
    pub name: &'static str,
    /// Fewest points per axis (the half-step companion needs them).
    pub min_points: usize,
    /// The largest usable point count `<= m` (odd, `4k + 1`, ...).
    pub usable: fn(usize) -> usize,
    /// The m-point rule on `[0, 1]` with its `2h` companion.
    pub nodes: fn(usize) -> UnitNodes,
    /// Order `p` of the error, `O(h^p)`, for Richardson's estimate.
    pub order: i32,
}

impl Composite {
    /// The intervals per axis, `m - 1`, of the points a budget of `n` in
    /// `dim` dimensions uses ([`crate::quadrature::Rule::resolution`]).
    pub fn resolution(&self, n: usize, dim: usize) -> f64 {
        let m = crate::quadrature::integer_root(n, dim).max(self.min_points);
        ((self.usable)(m) - 1) as f64
    }

    /// The rule's tensor product on `[0, 1]^D` with a budget of `n`
    /// evaluations, and Richardson's error estimate.
    pub fn integrate<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
        &self,
        n: usize,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        let m = crate::quadrature::per_axis::<D>(n, self.min_points, "n")?;
        if m > MAX_POINTS {
            return Err(QuadError::invalid(
                "n",
                n,
                format!("at most {MAX_POINTS} {} points per axis", self.name),
            ));
        }
        let nodes = self.cached((self.usable)(m));
        let max_weight = nodes.w.iter().copied().fold(0.0, f64::max).powi(D as i32);
        let estimate = richardson(
            product_sum([nodes.as_ref(); D], f)?,
            self.order,
            max_weight,
            nodes.len(),
        );
        // Below CHECKED_POINTS per axis nothing checks the estimate.
        if nodes.len() < CHECKED_POINTS {
            Ok(estimate.doubted())
        } else {
            Ok(estimate)
        }
    }

    /// The m-point node table, kept per thread for the last few `m`: inner
    /// loops (nested optical depths, every graded piece) ask for the same
    /// table again and again.
    fn cached(&self, m: usize) -> Arc<UnitNodes> {
        type Recent = Vec<(&'static str, usize, Arc<UnitNodes>)>;
        thread_local! {
            static RECENT: RefCell<Recent> = const { RefCell::new(Vec::new()) };
        }
        /// Rules kept per thread, and the largest kept (big tables are rare).
        const KEPT: usize = 8;
        const KEPT_MAX_POINTS: usize = 1 << 16;
        let hit = RECENT.with(|r| {
            r.borrow()
                .iter()
                .find(|(name, k, _)| *name == self.name && *k == m)
                .map(|(_, _, nodes)| nodes.clone())
        });
        if let Some(nodes) = hit {
            return nodes;
        }
        let nodes = Arc::new((self.nodes)(m));
        if m <= KEPT_MAX_POINTS {
            RECENT.with(|r| {
                let mut r = r.borrow_mut();
                if r.len() == KEPT {
                    r.remove(0);
                }
                r.push((self.name, m, nodes.clone()));
            });
        }
        nodes
    }
}

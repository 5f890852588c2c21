//! Composite trapezoid rule with its Richardson (first Romberg step) error
//! estimate.
//!
//! With `m` equally spaced points `u_i = i h`, `h = 1/(m-1)`:
//! `T_h = h (f_0/2 + f_1 + ... + f_{m-2} + f_{m-1}/2)`, error `O(h^2)` for smooth f.
//! The points with even index form the rule `T_{2h}`, so Richardson's estimate
//! `|T_h - T_{2h}| / 3` of the error of `T_h` costs no extra evaluation. To keep
//! that nesting, `m` is odd: a budget `n` gives the largest odd `m <= n^(1/D)`.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Rule, integer_root};
use super::nodes::{Composite, UnitNodes};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;

pub use super::nodes::MAX_POINTS;

/// The trapezoid rule as a composite rule: odd point counts, order 2.
const COMPOSITE: Composite = Composite {
    name: "trapezoid",
    min_points: 3,
    usable: |m| if m % 2 == 0 { m - 1 } else { m },
    nodes: table,
    order: 2,
};

/// Composite trapezoid rule (tensor product in D > 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Trapezoid;

/// The m-point trapezoid rule on `[0, 1]` (m odd, >= 3) with the `2h`
/// companion, the `4h` rule when `m = 4k + 1` and the `8h` rule when
/// `m = 8k + 1`.
/// Checked: `m` outside the rule's point counts (or above [`MAX_POINTS`],
/// whose table would not fit in memory) is an error, not a panic.
pub fn unit_nodes(m: usize) -> Result<UnitNodes, QuadError> {
    if !(m % 2 == 1 && (3..=MAX_POINTS).contains(&m)) {
        return Err(QuadError::invalid("m", m, format!("an odd number of points in 3..={MAX_POINTS}")));
    }
    Ok(table(m))
}

/// The table itself, for counts the rule has checked.
fn table(m: usize) -> UnitNodes {
    let intervals = (m - 1) as f64;
    let h = 1.0 / intervals;
    let u = (0..m).map(|i| i as f64 / intervals).collect();
    let w = (0..m)
        .map(|i| if i == 0 || i == m - 1 { 0.5 * h } else { h })
        .collect();
    let companion = (0..m)
        .map(|i| match i {
            _ if i % 2 == 1 => 0.0,
            _ if i == 0 || i == m - 1 => h,
            _ => 2.0 * h,
        })
        .collect();
    // The 4h rule on every fourth point, when the points nest it.
    let companion4 = (m % 4 == 1).then(|| {
        (0..m)
            .map(|i| match i {
                _ if i % 4 != 0 => 0.0,
                _ if i == 0 || i == m - 1 => 2.0 * h,
                _ => 4.0 * h,
            })
            .collect()
    });
    // The 8h rule on every eighth point (entry j for point 8j).
    let companion8 = (m % 8 == 1).then(|| {
        let k = (m - 1) / 8;
        (0..=k)
            .map(|j| if j == 0 || j == k { 4.0 * h } else { 8.0 * h })
            .collect()
    });
    UnitNodes {
        u,
        w,
        companion: Some(companion),
        companion4,
        companion8,
    }
}

impl Rule for Trapezoid {
    fn name(&self) -> &'static str {
        "trapezoid"
    }

    fn about(&self) -> &'static str {
        "composite trapezoid (product rule in D > 1); Richardson error estimate from the half-step rule"
    }

    /// Three nodes per axis: the half-step rule of the estimate needs them.
    fn min_budget(&self, dim: usize) -> usize {
        3usize.saturating_pow(dim as u32)
    }

    fn resolution(&self, n: usize, dim: usize) -> f64 {
        COMPOSITE.resolution(n, dim)
    }

    /// The node table per axis: 24 bytes a point (node, weight, companion
    /// weight); 240 MB measured at 1e7 points.
    fn memory(&self, n: usize, dim: usize) -> f64 {
        24.0 * integer_root(n, dim) as f64
    }

    fn integrate_unguarded<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        _rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        COMPOSITE.integrate(n, f)
    }
}

//! Composite Simpson rule with its Richardson error estimate.
//!
//! With `m` equally spaced points `u_i = i h`, `h = 1/(m-1)`, `m` odd:
//! `S_h = (h/3) (f_0 + 4 f_1 + 2 f_2 + 4 f_3 + ... + 4 f_{m-2} + f_{m-1})`,
//! exact for cubics, error `O(h^4)` for smooth f. When `m = 4k + 1` the points
//! with even index form the rule `S_{2h}`, so Richardson's estimate
//! `|S_h - S_{2h}| / 15` of the error of `S_h` costs no extra evaluation: a
//! budget `n` gives the largest `m = 4k + 1 <= n^(1/D)`, tensor products in
//! `D > 1`.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Rule, integer_root};
use super::nodes::{Composite, MAX_POINTS, UnitNodes};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;

/// Simpson's rule as a composite rule: `4k + 1` points (so the even points
/// form the `2h` rule), order 4.
const COMPOSITE: Composite = Composite {
    name: "simpson",
    min_points: 5,
    usable: |m| m - (m - 1) % 4,
    nodes: table,
    order: 4,
};

/// Composite Simpson rule (tensor product in D > 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Simpson;

/// Simpson weights `(H/3) (1, 4, 2, ..., 4, 1)` on the points `i` divisible by
/// `stride`, spaced `H = stride h`; zero on the others (stride 2: the odd
/// points the companion rule skips).
fn weights(m: usize, h: f64, stride: usize) -> Vec<f64> {
    (0..m)
        .map(|i| {
            if i % stride != 0 {
                return 0.0;
            }
            let j = i / stride;
            let w = if i == 0 || i == m - 1 {
                1.0
            } else if j % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * h * stride as f64 / 3.0
        })
        .collect()
}

/// The m-point Simpson rule on `[0, 1]` (m odd, >= 3), with the `2h` companion
/// (a Simpson rule itself when `m = 4k + 1`, which the rule uses), and the
/// `4h` Simpson rule when `m = 8k + 1` and the `8h` one when `m = 16k + 1`.
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
    UnitNodes {
        u: (0..m).map(|i| i as f64 / intervals).collect(),
        w: weights(m, h, 1),
        companion: Some(weights(m, h, 2)),
        // The 4h Simpson rule on every fourth point, when the points nest it.
        companion4: (m % 8 == 1).then(|| weights(m, h, 4)),
        // The 8h Simpson rule, kept only at its own points (entry j for 8j).
        companion8: (m % 16 == 1).then(|| weights(m, h, 8).into_iter().step_by(8).collect()),
    }
}

impl Rule for Simpson {
    fn name(&self) -> &'static str {
        "simpson"
    }

    fn about(&self) -> &'static str {
        "composite Simpson (product rule in D > 1); Richardson error estimate from the half-step rule"
    }

    /// Five nodes per axis: the half-step rule of the estimate needs them.
    fn min_budget(&self, dim: usize) -> usize {
        5usize.saturating_pow(dim as u32)
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

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
use super::nodes::{CHECKED_POINTS, Composite, MAX_POINTS, UnitNodes, coarse_weights};
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
    UnitNodes {
        u: (0..m).map(|i| i as f64 / intervals).collect(),
        w: coarse_weights(m, 1, &PAIR),
        companion: Some(coarse_weights(m, 2, &PAIR)),
        companion4: coarser_level(m, 4).then(|| coarse_weights(m, 4, &PAIR)),
        companion8: coarser_level(m, 8).then(|| coarse_weights(m, 8, &PAIR)),
    }
}

/// Simpson's weights on one pair of panels, in units of a panel's width.
const PAIR: [f64; 3] = [1.0 / 3.0, 4.0 / 3.0, 1.0 / 3.0];

/// Whether the Simpson level of panel width `stride h` is built: where the
/// points nest it exactly (`m = 2 stride k + 1`) and, with a finer tail,
/// from [`CHECKED_POINTS`] on (the `8h` pairs then cover at least 16 of the
/// intervals).
fn coarser_level(m: usize, stride: usize) -> bool {
    m >= CHECKED_POINTS || m % (2 * stride) == 1
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

    /// The node table per axis: 40 bytes a point (node, weight, and the
    /// `2h`, `4h` and `8h` weights of the estimate).
    fn memory(&self, n: usize, dim: usize) -> f64 {
        40.0 * integer_root(n, dim) as f64
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
        crate::quadrature::check_budget(n)?;
        COMPOSITE.integrate(n, f)
    }
}

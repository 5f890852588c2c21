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
use super::nodes::{CHECKED_POINTS, Composite, UnitNodes, coarse_weights};
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
    UnitNodes {
        u: (0..m).map(|i| i as f64 / intervals).collect(),
        w: coarse_weights(m, 1, &PANEL),
        companion: Some(coarse_weights(m, 2, &PANEL)),
        companion4: coarser_level(m, 4).then(|| coarse_weights(m, 4, &PANEL)),
        companion8: coarser_level(m, 8).then(|| coarse_weights(m, 8, &PANEL)),
    }
}

/// One trapezoid panel's weights in units of its width.
const PANEL: [f64; 2] = [0.5, 0.5];

/// Whether the level of panel width `stride h` is built: where the points
/// nest it exactly (`m = stride k + 1`) and, with a finer tail, from
/// [`CHECKED_POINTS`] on, where its panels cover at least 16 of the
/// intervals (fewer, and the tail's share would blur the ratio of
/// differences that checks the order).
fn coarser_level(m: usize, stride: usize) -> bool {
    m >= CHECKED_POINTS || m % stride == 1
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

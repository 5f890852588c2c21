//! [`GaussLegendre`], the rule: its budget, limits and paths to a sum.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::estimate::{HYBRID_FROM, estimated};
use super::{TABLE_MAX_ORDER, unit_rule, unit_table};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::nodes::product_value;
use crate::quadrature::{Rule, integer_root, per_axis};
use crate::value::Value;

/// Gauss–Legendre product rule on `[0, 1]^D`.
///
/// A budget of n evaluations gives `m = floor(n^(1/D))` nodes per axis. The
/// error estimate compares `Q_m` with `Q_{m-1}` and `Q_{m-2}` per axis and,
/// for `m >= 16`, with `Q_{ceil(m/2)}` ([`hybrid_estimate`](super::hybrid_estimate): the tail of the
/// consecutive differences, checked against the halving difference, which
/// sees algebraic convergence where the consecutive differences drown in
/// rounding); below 16 the consecutive orders alone (`tail_estimate`). It
/// costs `(m-1)^D + (m-2)^D + ceil(m/2)^D` extra evaluations (about `2.5 m`
/// in one dimension; without the half order below 16) and can be switched
/// off with `error_estimate: false`, in which case the error is reported as
/// infinite. The estimate is doubted below 16 nodes per axis (nothing checks
/// it there) and where one node dominates the sum ([`dominated`](crate::quadrature::nodes::dominated): a feature
/// narrower than the node spacing, which no difference of rules bounds).
///
/// Its sums are compensated but one: without the estimate, one axis of a
/// tabulated order (at most [`TABLE_MAX_ORDER`] nodes) is one running sum,
/// as the peers sum it, within `gamma_(m-1) sum |w f|` of the terms' exact
/// sum ([`unit_table`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GaussLegendre {
    /// Whether to spend `(m-1)^D + (m-2)^D + ceil(m/2)^D` more evaluations
    /// on the error estimate (default true).
    #[serde(default = "yes")]
    pub error_estimate: bool,
}

fn yes() -> bool {
    true
}

impl Default for GaussLegendre {
    fn default() -> Self {
        GaussLegendre {
            error_estimate: true,
        }
    }
}

impl GaussLegendre {
    /// Whether a budget of `n` is one axis of a tabulated order without
    /// the estimate, which [`tabulated_line`] sums.
    #[inline(always)]
    fn is_tabulated_line<const D: usize>(&self, n: usize) -> bool {
        D == 1 && !self.error_estimate && (1..=TABLE_MAX_ORDER).contains(&n)
    }
}

/// [`GaussLegendre`] without its estimate on one axis of a tabulated
/// order `m` ([`unit_table::tabulated_value`]).
#[inline(always)]
fn tabulated_line<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
    m: usize,
    mut f: F,
) -> Result<Estimate<V>, QuadError> {
    let mut evaluations = 0;
    let value = unit_table::tabulated_value(
        m,
        #[inline(always)]
        move |u| {
            let mut p = [0.0; D];
            p[0] = u;
            f(p)
        },
        &mut evaluations,
    )?;
    Ok(without_estimate(value, evaluations))
}

/// The rule's value without its estimate: its error unknown, infinite.
#[inline(always)]
fn without_estimate<V: Value>(value: V, evaluations: u64) -> Estimate<V> {
    Estimate::deterministic(value, V::zero().map(|_| f64::INFINITY), evaluations)
}

impl Rule for GaussLegendre {
    fn name(&self) -> &'static str {
        "gauss-legendre"
    }

    fn about(&self) -> &'static str {
        "Gauss–Legendre of any order 1..=1e8 (product rule in D > 1); error estimate from the tail of Q_m - Q_(m-1), Q_(m-1) - Q_(m-2), checked against Q_m - Q_(m/2) from m = 16"
    }

    /// The m-node table per axis (a node and a weight, 16 bytes a node),
    /// and with the estimate the companion rules' beside it: 56 bytes a
    /// node, from 552 MB of peak resident memory measured at m = 1e7.
    #[inline]
    fn memory(&self, n: usize, dim: usize) -> f64 {
        let per_node = if self.error_estimate { 56.0 } else { 16.0 };
        per_node * integer_root(n, dim) as f64
    }

    /// `m^D` nodes, and for the estimate `(m-1)^D + (m-2)^D` more, and
    /// `ceil(m/2)^D` from 16 nodes per axis.
    fn evaluations(&self, n: usize, dim: usize) -> f64 {
        let m = integer_root(n, dim).max(1) as f64;
        let d = dim.max(1) as i32;
        if !self.error_estimate || m < 2.0 {
            return m.powi(d);
        }
        let half = if m >= HYBRID_FROM as f64 {
            (m / 2.0).ceil().powi(d)
        } else {
            0.0
        };
        m.powi(d) + (m - 1.0).powi(d) + (m - 2.0).max(0.0).powi(d) + half
    }

    /// Unguarded where the estimate is off in one dimension: one sum on
    /// one axis, which [`product_value`] finds within the f64 range (the
    /// tabulated line hands it a sum that is not finite; the odometer's
    /// running sum in two and more dimensions can pass the range).
    fn guarded(&self, dim: usize) -> bool {
        self.error_estimate || dim > 1
    }

    /// [`Rule::try_integrate`], which a tabulated order without the
    /// estimate on one axis reaches first: no limit can be met at its
    /// 100 nodes at most, and it is not guarded.
    #[inline]
    fn try_integrate<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        if self.is_tabulated_line::<D>(n) {
            return tabulated_line(n, f);
        }
        beyond_the_table(self, n, rng, f)
    }

    /// One axis of a tabulated order without the estimate is summed here
    /// as the calls return ([`unit_table`]: one running sum, not
    /// compensated), inlined where it is called; every other budget out of
    /// line, so that its buffers stay out of the caller's frame.
    #[inline]
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
        if self.is_tabulated_line::<D>(n) {
            return tabulated_line(n, f);
        }
        unguarded_beyond_the_table(self.error_estimate, n, f)
    }
}

/// [`GaussLegendre::try_integrate`] past one tabulated axis without the
/// estimate: the limits, the guard, the rule. Out of line, so that the
/// tabulated line's caller keeps a frame of its own size: inlined, this
/// path's buffers gave it a frame of some 5 KB, probed and aligned at
/// every call.
#[inline(never)]
fn beyond_the_table<
    const D: usize,
    V: Value,
    R: rand::Rng + ?Sized,
    F: FnMut([f64; D]) -> Result<V, QuadError>,
>(
    rule: &GaussLegendre,
    n: usize,
    rng: &mut R,
    f: F,
) -> Result<Estimate<V>, QuadError> {
    crate::quadrature::guard::checked(rule, n, rng, f)
}

/// [`GaussLegendre::integrate_unguarded`] past one tabulated axis without
/// the estimate, out of line as [`beyond_the_table`] is.
#[inline(never)]
fn unguarded_beyond_the_table<
    const D: usize,
    V: Value,
    F: FnMut([f64; D]) -> Result<V, QuadError>,
>(
    error_estimate: bool,
    n: usize,
    f: F,
) -> Result<Estimate<V>, QuadError> {
    crate::quadrature::check_budget(n)?;
    let m = per_axis::<D>(n, 1, "n")?;
    if !error_estimate {
        let value = product_value([&*unit_rule(m)?; D], f)?;
        return Ok(without_estimate(value, (m as u64).pow(D as u32)));
    }
    estimated(m, f)
}

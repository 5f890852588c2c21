//! [`FixedOrder`]: Gauss–Legendre of one order on an interval `[a, b]`,
//! prepared once and called many times, as the peers' rules are (bilby's
//! `GaussLegendre::new(n).rule()`, gauss-quad's `GaussLegendre::new(n)`).
//!
//! A renderer integrates a few nodes per ray segment, per pixel, per light,
//! millions of times with one order. [`GaussLegendre`](super::GaussLegendre)
//! through [`Rule::integrate`](crate::quadrature::Rule::integrate) looks
//! its order up at every call, since the budget is an argument; this type
//! looks it up once, so that a call is the sum alone and its one check.
//! It has no error estimate (the rule with `error_estimate: true` has).
//!
//! ```
//! use lightquad::quadrature::gauss_legendre::FixedOrder;
//!
//! // Five nodes are exact for polynomials up to degree 9.
//! let rule = FixedOrder::new(5)?;
//! let integral = rule.integrate(0.0, 2.0, |x: f64| x.powi(9))?;
//! assert!((integral - 2f64.powi(10) / 10.0).abs() < 1e-12);
//!
//! // A value that is not finite is named with its node, never returned.
//! let err = rule.integrate(-1.0, 1.0, |x: f64| 1.0 / x).unwrap_err();
//! assert!(err.to_string().contains("at x = 0"), "{err}");
//! # Ok::<(), lightquad::QuadError>(())
//! ```

use std::sync::Arc;

use super::unit_table::{running_sum, unit_table};
use super::{TABLE_MAX_ORDER, check_order, unit_nodes};
use crate::error::{QuadError, channels, readable_number};
use crate::quadrature::nodes::{UnitNodes, product_value};
use crate::value::Value;

/// The `n`-node Gauss–Legendre rule on an interval, its nodes found once.
///
/// `int_a^b f(x) dx ~ (b - a) sum_i w_i f(a + (b - a) u_i)` with `u_i`,
/// `w_i` the rule on `[0, 1]` (weights summing to 1); exact for
/// polynomials of degree `2n - 1`. Up to [`TABLE_MAX_ORDER`] nodes the
/// terms are one running sum, as the peers sum them (within
/// `gamma_(n-1) sum |w f|` of their exact sum, [`unit_table`](super::unit_table));
/// above, a compensated one ([`product_value`]).
///
/// A result that is not finite is never returned: the error names the
/// first node whose value is not finite, an end that is not finite, or the
/// integral beyond the f64 range (in the table, after taking the integrand
/// again at every node by the compensated sum).
#[derive(Debug, Clone)]
pub struct FixedOrder {
    /// The compiled-in rule, `[u, w]` pairs on `[0, 1]`, for `n <=`
    /// [`TABLE_MAX_ORDER`]; empty above. Not an enum with `computed`:
    /// the loop's own test of an empty slice is then the only one a call
    /// makes (an enum's test cost some 1% of a five-node call).
    table: &'static [[f64; 2]],
    /// The computed rule from the shared cache ([`unit_nodes`]) above
    /// [`TABLE_MAX_ORDER`] nodes.
    computed: Option<Arc<UnitNodes>>,
}

impl FixedOrder {
    /// The rule of `n` nodes, `n` in `1..=MAX_ORDER`; above
    /// [`TABLE_MAX_ORDER`] its nodes are computed here (some 4 ms at
    /// 1e6 nodes) or taken from the shared cache.
    pub fn new(n: usize) -> Result<Self, QuadError> {
        check_order(n)?;
        if n <= TABLE_MAX_ORDER {
            return Ok(FixedOrder {
                table: unit_table(n),
                computed: None,
            });
        }
        Ok(FixedOrder {
            table: &[],
            computed: Some(unit_nodes(n)?),
        })
    }

    /// The number of nodes, n.
    pub fn order(&self) -> usize {
        match &self.computed {
            Some(nodes) => nodes.len(),
            None => self.table.len(),
        }
    }

    /// `int_a^b f(x) dx` (negated where `b < a`), `f` called once at each
    /// node; see [`FixedOrder::try_integrate`] for the errors.
    #[inline]
    pub fn integrate<V: Value>(
        &self,
        a: f64,
        b: f64,
        mut f: impl FnMut(f64) -> V,
    ) -> Result<V, QuadError> {
        self.try_integrate(a, b, move |x| Ok(f(x)))
    }

    /// [`FixedOrder::integrate`] for an integrand that may fail: its first
    /// error is returned as it is.
    ///
    /// Errors where `a` or `b` or `b - a` is not finite, where `f` returns a
    /// value that is not finite (naming the node `x` and the value), and
    /// where the integral passes the f64 range; in the table, to find
    /// which, `f` is called at every node a second time.
    #[inline]
    pub fn try_integrate<V: Value>(
        &self,
        a: f64,
        b: f64,
        mut f: impl FnMut(f64) -> Result<V, QuadError>,
    ) -> Result<V, QuadError> {
        let table = self.table;
        if table.is_empty() {
            return self.on_cached_nodes(a, b, f);
        }
        // Every node is at least 1.4e-4 of the length from either end
        // (n <= 100), so `a + (b - a) u` stays inside [a, b] through its
        // roundings; an end or a length that is not finite makes the
        // product with `b - a` not finite.
        let h = b - a;
        let value = running_sum(table, |u| f(a + h * u))?.map(|s| s * h);
        if value.all_finite() {
            return Ok(value);
        }
        retabulated(table.len(), &[a, b], f)
    }

    /// [`compensated`] on the computed rule, every call above
    /// [`TABLE_MAX_ORDER`] nodes. Out of line, as [`retabulated`] is.
    #[inline(never)]
    fn on_cached_nodes<V: Value>(
        &self,
        a: f64,
        b: f64,
        f: impl FnMut(f64) -> Result<V, QuadError>,
    ) -> Result<V, QuadError> {
        match &self.computed {
            Some(nodes) => compensated(nodes, a, b, f),
            None => retabulated(self.table.len(), &[a, b], f),
        }
    }
}

/// [`compensated`] on the tabulated rule of order `n`, whose running sum
/// came out not finite. Out of line, so that the tabulated call keeps a
/// frame of its own size and nothing but the order and the ends live past
/// its loop. The ends come by reference: the loop then reads the lower end
/// from memory rather than reloading it and the length into registers
/// after every call (at 50 nodes 1.0008 against 1.0000 of bilby's time).
#[cold]
#[inline(never)]
fn retabulated<V: Value>(
    n: usize,
    [a, b]: &[f64; 2],
    f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    compensated(&*unit_nodes(n)?, *a, *b, f)
}

/// The integral on `nodes` by a compensated sum ([`product_value`]), on
/// `[lo, hi]` with `lo <= hi` (a reversed interval's integral negated):
/// `x = lo + s u`, the scale `s` the length `h = hi - lo` or, where the
/// last node would round past `hi` (computed nodes come within 1e-16 of
/// 1), the largest below it that keeps it at `hi` at most; rounding is
/// monotone, so every node is then inside. The integral is `h` times the
/// mean. One test a call: a select at every node or a map from each end
/// (`hi - h (1 - u)` above the middle) cost some 2% and 5% of a call at
/// 1e6 nodes of `cos(50 x)` (`benches/README.md`, the fifth session).
fn compensated<V: Value>(
    nodes: &UnitNodes,
    a: f64,
    b: f64,
    mut f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    finite_length(a, b)?;
    let (lo, hi, sign) = if a <= b { (a, b, 1.0) } else { (b, a, -1.0) };
    let h = hi - lo;
    let last = nodes.u.last().copied().unwrap_or(0.0);
    let mut s = h;
    while lo + s * last > hi {
        s = s.next_down();
    }
    let x_at = move |u: f64| lo + s * u;
    let mean = product_value([nodes], move |u: [f64; 1]| f(x_at(u[0])))
        .map_err(|e| named_at_x(e, x_at, lo, hi))?;
    let value = mean.map(|m| sign * (m * h));
    if value.all_finite() {
        return Ok(value);
    }
    Err(QuadError::invalid(
        "integrand",
        format!(
            "its mean {} over [{}, {}], times the length {}, is beyond the f64 range",
            channels(mean),
            readable_number(a),
            readable_number(b),
            readable_number(b - a)
        ),
        "an integral at most 1.8e308 in magnitude: scale the integrand down",
    ))
}

/// [`product_value`]'s error for a value that is not finite, at a node
/// `u` of `[0, 1]`, told at its `x_at(u)` in `[lo, hi]`; other errors as
/// they are.
#[cold]
#[inline(never)]
fn named_at_x(error: QuadError, x_at: impl Fn(f64) -> f64, lo: f64, hi: f64) -> QuadError {
    let QuadError::NonFiniteIntegrand { point, value } = &error else {
        return error;
    };
    let Some(&u) = point.first() else {
        return error;
    };
    QuadError::invalid(
        "integrand",
        format!("{value} at x = {}", readable_number(x_at(u))),
        format!(
            "a finite value at every node in [{}, {}]",
            readable_number(lo),
            readable_number(hi)
        ),
    )
}

/// `b - a`, where `a`, `b` and it are finite.
fn finite_length(a: f64, b: f64) -> Result<f64, QuadError> {
    crate::error::require_finite("a", a)?;
    crate::error::require_finite("b", b)?;
    let h = b - a;
    if h.is_finite() {
        return Ok(h);
    }
    Err(QuadError::invalid(
        "b",
        readable_number(b),
        format!(
            "an end whose distance from a = {} is finite in f64 (at most 1.8e308)",
            readable_number(a)
        ),
    ))
}

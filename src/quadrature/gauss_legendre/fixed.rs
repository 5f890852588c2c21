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

use std::sync::Arc;

use super::unit_table::{FIXED_STRAIGHT_UP_TO, running_sum, unit_table};
use super::{TABLE_MAX_ORDER, check_order, unit_nodes, unit_rule};
use crate::error::{QuadError, channels, readable_number};
use crate::quadrature::nodes::{UnitNodes, line_value_par, product_value};
use crate::quadrature::guard::stopped_by;
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
/// integral beyond the f64 range, after taking the integrand again by the
/// compensated sum: in the table at every node, above it up to where the
/// sum stopped ([`product_value`]).
///
/// ```
/// use lightquad::quadrature::gauss_legendre::FixedOrder;
///
/// // Five nodes are exact for polynomials up to degree 9.
/// let rule = FixedOrder::new(5)?;
/// let integral = rule.integrate(0.0, 2.0, |x: f64| x.powi(9))?;
/// assert!((integral - 2f64.powi(10) / 10.0).abs() < 1e-12);
///
/// // A value that is not finite is named with its node, never returned.
/// let err = rule.integrate(-1.0, 1.0, |x: f64| 1.0 / x).unwrap_err();
/// assert!(err.to_string().contains("at x = 0"), "{err}");
/// # Ok::<(), lightquad::QuadError>(())
/// ```
#[derive(Clone)]
pub struct FixedOrder {
    /// The compiled-in rule, `[u, w]` pairs on `[0, 1]`, for `n <=`
    /// [`TABLE_MAX_ORDER`]; empty above, so that a test of its length is
    /// the only test of the kind of rule a call makes.
    table: &'static [[f64; 2]],
    /// The computed rule from the shared cache ([`unit_nodes`]) above
    /// [`TABLE_MAX_ORDER`] nodes.
    computed: Option<Arc<UnitNodes>>,
}

/// The order alone: the nodes are 2e6 numbers at 1e6 nodes.
impl std::fmt::Debug for FixedOrder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FixedOrder")
            .field("order", &self.order())
            .finish()
    }
}

impl FixedOrder {
    /// The rule of `n` nodes, `n` in `1..=MAX_ORDER`; above
    /// [`TABLE_MAX_ORDER`] its nodes are computed here (some 4 ms at
    /// 1e6 nodes: `benches/README.md`, `gl_nodes`) or taken from the shared
    /// cache.
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
    /// node but where a value is not finite or a sum leaves the f64 range;
    /// see [`FixedOrder::try_integrate`].
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
    /// where the integral passes the f64 range; to find which, `f` is
    /// called a second time, in the table at every node, above it up to
    /// where the sum stopped ([`product_value`]).
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
        // roundings. An end that is not finite makes `b - a` not finite
        // too: then no node is taken, and the compensated path names it.
        let h = b - a;
        if !h.is_finite() {
            return retabulated(table.len(), &[a, b], f);
        }
        let value = running_sum::<FIXED_STRAIGHT_UP_TO, V>(table, |u| f(a + h * u))?.map(|s| s * h);
        if value.all_finite() {
            return Ok(value);
        }
        retabulated(table.len(), &[a, b], f)
    }

    /// [`FixedOrder::integrate`] with the nodes shared among rayon's
    /// threads above [`PAR_SPAN`] nodes ([`line_value_par`]), for an
    /// integrand that may be called from several threads at once, as
    /// gauss-quad's `par_integrate`; at most [`TABLE_MAX_ORDER`] nodes,
    /// [`FixedOrder::integrate`] itself. The value is `integrate`'s bit for
    /// bit up to [`PAR_SPAN`] nodes, and above differs from it in rounding
    /// only (both compensated sums: the lanes restart at every span), the
    /// same whatever the number of threads. The same errors, but for a sum
    /// within rounding of the f64 range, which can leave it in one and not
    /// in the other ([`line_sum_par`](crate::quadrature::nodes::line_sum_par)).
    /// Where a value is not finite, or a sum leaves the range, `f` is
    /// called a second time at every node the whole sum reaches to name it
    /// ([`line_value_par`]).
    ///
    /// ```
    /// use lightquad::quadrature::gauss_legendre::FixedOrder;
    ///
    /// let rule = FixedOrder::new(1_000_000)?;
    /// let integral = rule.par_integrate(-1.0, 1.0, |x: f64| (50.0 * x).cos())?;
    /// assert!((integral - 50f64.sin() / 25.0).abs() < 1e-16);
    /// # Ok::<(), lightquad::QuadError>(())
    /// ```
    ///
    /// [`PAR_SPAN`]: crate::quadrature::nodes::PAR_SPAN
    pub fn par_integrate<V: Value>(
        &self,
        a: f64,
        b: f64,
        f: impl Fn(f64) -> V + Sync,
    ) -> Result<V, QuadError> {
        match &self.computed {
            Some(nodes) => compensated_par(nodes, a, b, f),
            None => self.integrate(a, b, f),
        }
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
/// its sum. The ends come by reference, which keeps them in memory, where
/// the sum reads the lower end (`benches/README.md`, `gl_small`, fifth
/// session).
#[cold]
#[inline(never)]
fn retabulated<V: Value>(
    n: usize,
    [a, b]: &[f64; 2],
    f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    compensated(&*unit_rule(n)?, *a, *b, f)
}

/// The integral on `nodes` by a compensated sum ([`product_value`]):
/// `x = a + s u`, the scale `s` the signed length `h = b - a` or, where
/// the last node would round past `b` (only near [`MAX_ORDER`](super::MAX_ORDER)
/// do nodes come within an ulp of 1), the nearest to it that keeps that
/// node at `b`; rounding is monotone, so every node is then inside. The
/// integral is `h` times the mean. On a tabulated order `s = h`: the nodes
/// of the running sum it takes again. The integrand's own error comes back
/// as it is: on one axis [`product_value`] stops at the first error `f`
/// returns, which is kept aside and returned in place of the one that
/// stopped the sum.
fn compensated<V: Value>(
    nodes: &UnitNodes,
    a: f64,
    b: f64,
    mut f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    // The integrand's own error goes back as it is; only the sum's own
    // (a value not finite at a node of [0, 1]) is told at its x.
    let mut own = None;
    let value = times_length(nodes, a, b, |at| {
        product_value([nodes], |u: [f64; 1]| {
            f(at.x(u[0])).map_err(|e| stopped_by(&mut own, e))
        })
    });
    match own {
        Some(error) => Err(error),
        None => value,
    }
}

/// [`compensated`] with the nodes shared among rayon's threads
/// ([`line_value_par`]), for an integrand that does not fail.
fn compensated_par<V: Value>(
    nodes: &UnitNodes,
    a: f64,
    b: f64,
    f: impl Fn(f64) -> V + Sync,
) -> Result<V, QuadError> {
    times_length(nodes, a, b, |at| line_value_par(nodes, |u| Ok(f(at.x(u)))))
}

/// Where a node `u` of `[0, 1]` lies on `[a, b]`: `a + s u`.
#[derive(Clone, Copy)]
struct NodeAt {
    a: f64,
    s: f64,
}

impl NodeAt {
    #[inline(always)]
    fn x(self, u: f64) -> f64 {
        self.a + self.s * u
    }
}

/// `h = b - a` times the `mean` taken with the nodes placed on `[a, b]`
/// ([`compensated`]'s scale), a value not finite told at its `x`, and an
/// integral beyond the f64 range refused.
fn times_length<V: Value>(
    nodes: &UnitNodes,
    a: f64,
    b: f64,
    mean: impl FnOnce(NodeAt) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    let h = finite_length(a, b)?;
    let at = NodeAt {
        a,
        s: scale_within(a, b, nodes.u.last().copied().unwrap_or(0.0)),
    };
    let mean = mean(at).map_err(|e| named_at_x(e, |u| at.x(u), a.min(b), a.max(b)))?;
    let value = mean.map(|m| m * h);
    if value.all_finite() {
        return Ok(value);
    }
    Err(QuadError::invalid(
        "integrand",
        format!(
            "its mean {} over [{}, {}], times b - a = {}, is beyond the f64 range",
            channels(mean),
            readable_number(a),
            readable_number(b),
            readable_number(h)
        ),
        "an integral at most 1.8e308 in magnitude: scale the integrand down",
    ))
}

/// The scale `s` nearest `b - a` (finite) with `a + s last` not past `b`
/// for the largest node `last` of `[0, 1]`: `b - a` itself unless that
/// node rounds past `b`; at `s = 0` the node is `a`, so the search ends.
fn scale_within(a: f64, b: f64, last: f64) -> f64 {
    let mut s = b - a;
    if s >= 0.0 {
        while a + s * last > b {
            s = s.next_down();
        }
    } else {
        while a + s * last < b {
            s = s.next_up();
        }
    }
    s
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

#[cfg(test)]
mod tests {
    use super::scale_within;

    /// `b - a` rounds up where the ends differ in sign and magnitude:
    /// `0.75 + (2^53 - 1)` is `2^53`, so a node at 1 would land at 1,
    /// past `b = 0.75`; the scale then steps down to `2^53 - 1`, the node
    /// to 0. Reversed, the same from above; and `b - a` itself elsewhere.
    #[test]
    fn the_scale_keeps_the_last_node_inside() {
        let a = -(2f64.powi(53) - 1.0);
        let s = scale_within(a, 0.75, 1.0);
        assert_eq!(s, 2f64.powi(53) - 1.0);
        assert!(a + s <= 0.75);
        let s = scale_within(-a, -0.75, 1.0);
        assert_eq!(s, -(2f64.powi(53) - 1.0));
        assert!(-a + s >= -0.75);
        assert_eq!(scale_within(0.1, 0.3, 1.0 - f64::EPSILON / 2.0), 0.3 - 0.1);
        assert_eq!(scale_within(2.0, -1.0, 0.9), -3.0);
    }
}

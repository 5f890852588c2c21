//! The sum over a short axis, fewer than [`SHORT_BELOW`] nodes: every
//! value first, into a buffer on the stack, then one pass over them.
//!
//! A few nodes a call is the common case in a renderer (a few nodes per
//! ray segment, per pixel, per light), and there the set-up of
//! [`line_sum`]'s groups and blocks (a block of 256 values and three
//! companions' lanes zeroed) is as much work as the terms. Sums carried
//! across the integrand's calls are also stored and reloaded at each node,
//! where a pass after all the calls keeps them in registers. So a short
//! axis is summed after its values: term by term below [`LANES_FROM`]
//! nodes, in lanes from there.
//!
//! Two sums of the values: [`short_sum`], the whole of [`ProductSum`]
//! (what an error estimate reads), and [`short_value`], the rule's own sum
//! alone, which is all a rule without an estimate needs.
//!
//! [`line_sum`]: super::line::line_sum

use crate::error::QuadError;
use crate::sum::{Compensated, LaneValues, Lanes};
use crate::value::Value;

use super::{ProductSum, UnitNodes, in_range, non_finite, value_in_range};

/// Nodes from which an axis is summed in lanes; below, term by term.
pub(super) const LANES_FROM: usize = 16;

/// Nodes below which an axis is short: its values are taken into one
/// buffer (1 KB for a scalar) before they are summed.
pub(super) const SHORT_BELOW: usize = 128;

/// The whole [`ProductSum`] of a short axis: below [`LANES_FROM`] nodes
/// term by term ([`few_sum`]), from there in the lanes ([`lanes_sum`]).
/// A value that is not finite is named after all the values.
pub(super) fn short_sum<V: Value>(
    a: &UnitNodes,
    f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<ProductSum<V>, QuadError> {
    buffered(
        a,
        f,
        #[inline(always)]
        |ys| {
            let sum = if ys.len() < LANES_FROM {
                few_sum(a, ys)?
            } else {
                lanes_sum(a, ys)?
            };
            in_range(sum)
        },
    )
}

/// [`short_sum`]'s `value` alone, bit for bit, and its errors but for a
/// companion's: the same compensated sum of the same terms in the same
/// order, without `sum |w y|`, the largest term or the companions. A
/// total that is not finite (a value that is not, or a running sum that
/// passed `f64::MAX`) is taken to the whole sum of the same values, which
/// names the point, finds the total within range, or names the sum out of
/// range.
#[inline]
pub(super) fn short_value<V: Value>(
    a: &UnitNodes,
    f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    buffered(
        a,
        f,
        #[inline(always)]
        |ys: &[V]| {
            if ys.len() < LANES_FROM {
                let mut value = Compensated::<V>::new();
                for (y, &w) in ys.iter().zip(&a.w) {
                    value.add(y.map(|v| v * w));
                }
                return finite_or(value.total(), || few_sum(a, ys));
            }
            let mut value = Lanes::new();
            value.add_products(ys, &a.w[..ys.len()]);
            finite_or(value.total(), || lanes_sum(a, ys))
        },
    )
}

/// `then` of the values of `f` at the nodes of `a`, fewer than
/// [`SHORT_BELOW`], held in a buffer on the stack of at most twice as
/// many values (from 16): zeroing the whole 128 values (1 KB for a
/// scalar) was a sixth of what a call spent beside `cos(50 x)` at 20
/// nodes (callgrind).
#[inline(always)]
fn buffered<V: Value, R>(
    a: &UnitNodes,
    f: impl FnMut(f64) -> Result<V, QuadError>,
    then: impl FnOnce(&[V]) -> Result<R, QuadError>,
) -> Result<R, QuadError> {
    const _: () = assert!(SHORT_BELOW == 128 && LANES_FROM == 16);
    match a.len() {
        ..16 => then(values(a, f, &mut [V::zero(); 16])?),
        16..32 => then(values(a, f, &mut [V::zero(); 32])?),
        32..64 => then(values(a, f, &mut [V::zero(); 64])?),
        _ => then(values(a, f, &mut [V::zero(); 128])?),
    }
}

/// `f` at every node of `a`, in the first `a.len()` places of `buffer`.
#[inline(always)]
fn values<'b, V: Value>(
    a: &UnitNodes,
    mut f: impl FnMut(f64) -> Result<V, QuadError>,
    buffer: &'b mut [V],
) -> Result<&'b [V], QuadError> {
    let ys = &mut buffer[..a.len()];
    for (y, &u) in ys.iter_mut().zip(&a.u) {
        *y = f(u)?;
    }
    Ok(ys)
}

/// `total` where it is finite, else the `value` of the `whole` sum
/// ([`value_in_range`]).
#[inline(always)]
fn finite_or<V: Value>(
    total: V,
    whole: impl FnOnce() -> Result<ProductSum<V>, QuadError>,
) -> Result<V, QuadError> {
    if total.all_finite() {
        return Ok(total);
    }
    whole_value(whole)
}

/// [`finite_or`]'s way out, off the line of the sum.
#[cold]
#[inline(never)]
fn whole_value<V: Value>(
    whole: impl FnOnce() -> Result<ProductSum<V>, QuadError>,
) -> Result<V, QuadError> {
    value_in_range(whole()?)
}

/// The first value that is not finite, named at its node.
fn first_non_finite<V: Value>(a: &UnitNodes, ys: &[V]) -> Result<(), QuadError> {
    match a.u.iter().zip(ys).find(|(_, y)| !y.all_finite()) {
        Some((u, y)) => Err(non_finite(&[*u], y)),
        None => Ok(()),
    }
}

/// [`short_sum`] of fewer than [`LANES_FROM`] values `ys`, before its
/// range is checked: one pass, a compensated running sum per weight set,
/// `sum |w y|` and the largest term.
///
/// The rule's own sum is found as the lanes find it where finite terms'
/// running sum passes `f64::MAX` on the way to a total within range (14
/// nodes of `f64::MAX`): summed again at a quarter of their size, the
/// total scaled back ([`crate::sum::Lanes::total`]).
#[inline(always)]
fn few_sum<V: Value>(a: &UnitNodes, ys: &[V]) -> Result<ProductSum<V>, QuadError> {
    let mut value = Compensated::<V>::new();
    let (mut magnitude, mut largest) = (V::zero(), V::zero());
    for (y, (&w, &u)) in ys.iter().zip(a.w.iter().zip(&a.u)) {
        if !y.all_finite() {
            return Err(non_finite(&[u], y));
        }
        let wy = y.map(|v| v * w);
        value.add(wy);
        magnitude = magnitude.zip(wy, |m, v| m + v.abs());
        // A comparison, cheaper than `f64::max`, and like it a NaN term
        // (of a channel `all_finite` does not check) leaves `m` as it is.
        largest = largest.zip(wy, |m, v| if v.abs() > m { v.abs() } else { m });
    }
    // `sum scale w_i y_i`, compensated.
    let weighted = |weights: &[f64], scale: f64| {
        let mut sum = Compensated::<V>::new();
        for (y, &w) in ys.iter().zip(weights) {
            sum.add(y.map(|v| v * (scale * w)));
        }
        sum.total()
    };
    let mut total = value.total();
    if !total.all_finite() {
        // Only the channels that passed the range: a quarter of a
        // subnormal term loses bits.
        let quarter = weighted(&a.w, 0.25);
        total = total.zip(quarter, |t, q| if t.is_finite() { t } else { 4.0 * q });
    }
    let companion = |weights: &Option<Vec<f64>>| weights.as_deref().map(|c| weighted(c, 1.0));
    Ok(ProductSum {
        value: total,
        companion: companion(&a.companion),
        companion4: companion(&a.companion4),
        companion8: companion(&a.companion8),
        magnitude,
        largest,
        evaluations: a.len() as u64,
    })
}

/// [`short_sum`] of [`LANES_FROM`] to [`SHORT_BELOW`] values `ys`, in
/// the lanes, before its range is checked. The same terms in the same lanes in the same order as
/// `LineSum::add_span` (its groups are whole multiples of the lanes, and
/// so is its block), so the same bits, the finite check included.
fn lanes_sum<V: Value>(a: &UnitNodes, ys: &[V]) -> Result<ProductSum<V>, QuadError> {
    let mut value = Lanes::new();
    let (mut magnitude, mut largest) = (LaneValues::zero(), LaneValues::zero());
    value.add_products_scaled(ys, &a.w[..ys.len()], &mut magnitude, &mut largest);
    // `magnitude` carries a term that is not finite.
    if !magnitude.all_finite() {
        first_non_finite(a, ys)?;
    }
    let companion = |weights: &Option<Vec<f64>>| {
        weights.as_deref().map(|c| {
            let mut lanes = Lanes::new();
            lanes.add_products(ys, &c[..ys.len()]);
            lanes.total()
        })
    };
    Ok(ProductSum {
        value: value.total(),
        companion: companion(&a.companion),
        companion4: companion(&a.companion4),
        companion8: companion(&a.companion8),
        magnitude: magnitude.sum(),
        largest: largest.max(),
        evaluations: a.len() as u64,
    })
}

//! Weighted node sets on the unit interval and the one shared summation that
//! turns (tensor products of) them into an integral.
//!
//! `line` sums one axis (in groups between the integrand's calls, in lanes,
//! and across threads in [`line_sum_par`]); `composite` holds the
//! trapezoid and Simpson rules as data ([`Composite`]); `estimate` turns
//! nested sums into Richardson's error estimate ([`richardson`]) and checks
//! that no single node carries the sum ([`dominated`]).

use crate::error::QuadError;
use crate::sum::Compensated;
use crate::value::Value;

mod composite;
mod estimate;
mod line;
mod short;

pub use composite::{CHECKED_POINTS, Composite, MAX_POINTS, coarse_weights};
pub(crate) use estimate::ROUNDING_ULPS;
pub use estimate::{DOMINANT_SHARE, dominated, richardson};
pub use line::{PAR_SPAN, line_sum_par, line_value_par, par_span};
use line::{line_sum, line_value};

/// A 1-D rule on `[0, 1]`: nodes `u_i` and weights `w_i` with `sum w_i = 1`
/// (so the rule estimates `int_0^1 f(u) du` by `sum w_i f(u_i)`), and optional
/// companion weights on the same nodes for an embedded error estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct UnitNodes {
    /// Nodes in `[0, 1]`, ascending.
    pub u: Vec<f64>,
    /// Weights, summing to 1.
    pub w: Vec<f64>,
    /// Weights of a lower-order companion rule on the same nodes (zero where
    /// the companion has no node), when the rule has one.
    pub companion: Option<Vec<f64>>,
    /// Weights of the companion's own companion (a composite rule's `4h`
    /// rule), when the node set nests it.
    pub companion4: Option<Vec<f64>>,
    /// Weights of the `8h` rule (zero off its nodes), when the node set
    /// has it: a third difference lets [`richardson`] check that the order
    /// it sees holds over two ratios.
    pub companion8: Option<Vec<f64>>,
}

impl UnitNodes {
    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.u.len()
    }

    /// True when the rule has no nodes.
    pub fn is_empty(&self) -> bool {
        self.u.is_empty()
    }

    /// Checks that `w` and each companion hold one weight per node: the
    /// fields are public, and a sum reads weight `i` beside node `i`.
    ///
    /// ```
    /// use lightquad::quadrature::nodes::UnitNodes;
    ///
    /// let mut nodes = UnitNodes {
    ///     u: vec![0.25, 0.75],
    ///     w: vec![0.5, 0.5],
    ///     companion: None,
    ///     companion4: None,
    ///     companion8: None,
    /// };
    /// assert!(nodes.check().is_ok());
    /// nodes.w.pop();
    /// let e = nodes.check().unwrap_err().to_string();
    /// assert_eq!(e, "invalid w = 1: expected 2 weights, one per node");
    /// ```
    #[inline]
    pub fn check(&self) -> Result<(), QuadError> {
        let n = self.u.len();
        let other = |set: &Option<Vec<f64>>| set.as_ref().is_some_and(|w| w.len() != n);
        if self.w.len() != n
            || other(&self.companion)
            || other(&self.companion4)
            || other(&self.companion8)
        {
            return Err(self.weights_per_node());
        }
        Ok(())
    }

    /// [`UnitNodes::check`]'s error, naming the first weight set of another
    /// length than the nodes.
    #[cold]
    fn weights_per_node(&self) -> QuadError {
        let sets = [
            ("w", Some(&self.w)),
            ("companion", self.companion.as_ref()),
            ("companion4", self.companion4.as_ref()),
            ("companion8", self.companion8.as_ref()),
        ];
        let n = self.u.len();
        let (name, len) = sets
            .into_iter()
            .find_map(|(name, w)| w.filter(|w| w.len() != n).map(|w| (name, w.len())))
            .unwrap_or(("w", self.w.len()));
        QuadError::invalid(name, len, format!("{n} weights, one per node"))
    }
}

/// The result of one pass over a tensor-product node set.
#[derive(Debug, Clone, Copy)]
pub struct ProductSum<V: Value> {
    /// `sum_i prod_d w_{i_d} f(u_i)`.
    pub value: V,
    /// The same sum with the companion weights, when every axis has them.
    pub companion: Option<V>,
    /// The same sum with the `companion4` weights, when every axis has them.
    pub companion4: Option<V>,
    /// The same sum with the `companion8` weights, when every axis has them.
    pub companion8: Option<V>,
    /// `max_i |prod_d w_{i_d} f(u_i)|`: the largest single term. When it is a
    /// large share of `magnitude` the sum rests on one node
    /// ([`dominated`]).
    pub largest: V,
    /// `sum_i |prod_d w_{i_d} f(u_i)|`, the scale of the sum's rounding error:
    /// a difference of two rules below a small multiple of `eps` times it is
    /// rounding, not truncation. A plain sum: its own `n eps` relative error
    /// does not matter for a scale.
    pub magnitude: V,
    /// Integrand evaluations.
    pub evaluations: u64,
}

/// Sums `f` over the tensor product of `axes` with compensated summation.
///
/// With [`line_sum_par`], the only place where a deterministic rule meets
/// the integrand.
/// A non-finite integrand value is an error naming the point, found on one
/// axis of 128 nodes or more at the end of the block of 256 nodes it is in
/// (the sum stops there), below 128 once every value is in, and in two and
/// more dimensions at once. Weight sets of another length than the nodes
/// are an error ([`UnitNodes::check`]). Finite values within rounding of `f64::MAX`,
/// whose sum passes it on the way, are summed on one axis (see
/// [`crate::sum::Lanes::total`]), the rule's own sum always: its terms are
/// spread over four lanes, each some quarter of the sum (below 16 nodes,
/// summed again at a quarter of their size). A companion whose weights are zero at three nodes of four
/// (a composite rule's `4h` and `8h` rules) puts all its terms in one lane,
/// whose running sum can pass `f64::MAX` where the total would not; such
/// a sum, and in two and more dimensions any, is
/// [`QuadError::SumOutOfRange`] naming it, never a sum that is not finite.
pub fn product_sum<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
    axes: [&UnitNodes; D],
    mut f: F,
) -> Result<ProductSum<V>, QuadError> {
    for a in axes {
        a.check()?;
    }
    if D == 1 && !axes[0].is_empty() {
        return line_sum(
            axes[0],
            #[inline(always)]
            move |u| {
                let mut p = [0.0; D];
                p[0] = u;
                f(p)
            },
        );
    }
    in_range(odometer_sum(axes, f)?)
}

/// [`product_sum`] of any axes, term by term in the order of an index
/// odometer (last axis fastest), before its range is checked; `Ok` of
/// zero sums where an axis is empty.
fn odometer_sum<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
    axes: [&UnitNodes; D],
    mut f: F,
) -> Result<ProductSum<V>, QuadError> {
    let with_companion = axes.iter().all(|a| a.companion.is_some());
    let with_companion4 = axes.iter().all(|a| a.companion4.is_some());
    let with_companion8 = axes.iter().all(|a| a.companion8.is_some());
    let mut acc = Compensated::<V>::new();
    let mut acc_c = Compensated::<V>::new();
    let mut acc_c4 = Compensated::<V>::new();
    let mut acc_c8 = Compensated::<V>::new();
    let mut magnitude = V::zero();
    let mut largest = V::zero();
    let mut evaluations = 0u64;
    if axes.iter().any(|a| a.is_empty()) {
        return Ok(ProductSum {
            value: V::zero(),
            companion: with_companion.then(V::zero),
            companion4: with_companion4.then(V::zero),
            companion8: with_companion8.then(V::zero),
            magnitude,
            largest,
            evaluations,
        });
    }

    let mut idx = [0usize; D];
    loop {
        let mut p = [0.0; D];
        let mut w = 1.0;
        let mut wc = 1.0;
        let mut wc4 = 1.0;
        let mut wc8 = if with_companion8 { 1.0 } else { 0.0 };
        for d in 0..D {
            p[d] = axes[d].u[idx[d]];
            w *= axes[d].w[idx[d]];
            if with_companion {
                wc *= axes[d].companion.as_ref().map_or(0.0, |c| c[idx[d]]);
            }
            if with_companion4 {
                wc4 *= axes[d].companion4.as_ref().map_or(0.0, |c| c[idx[d]]);
            }
            if with_companion8 && wc8 != 0.0 {
                wc8 *= axes[d].companion8.as_ref().map_or(0.0, |c| c[idx[d]]);
            }
        }
        let y = f(p)?;
        evaluations += 1;
        if !y.all_finite() {
            return Err(non_finite(&p, &y));
        }
        let wy = y.map(|v| v * w);
        acc.add(wy);
        magnitude = magnitude.zip(wy, |m, v| m + v.abs());
        largest = largest.zip(wy, |m, v| m.max(v.abs()));
        if with_companion8 && wc8 != 0.0 {
            acc_c8.add(y.map(|v| v * wc8));
        }
        if with_companion {
            acc_c.add(y.map(|v| v * wc));
        }
        if with_companion4 && wc4 != 0.0 {
            acc_c4.add(y.map(|v| v * wc4));
        }
        // Advance the odometer, last axis fastest.
        let mut d = D;
        loop {
            if d == 0 {
                return Ok(ProductSum {
                    value: acc.total(),
                    companion: with_companion.then(|| acc_c.total()),
                    companion4: with_companion4.then(|| acc_c4.total()),
                    companion8: with_companion8.then(|| acc_c8.total()),
                    magnitude,
                    largest,
                    evaluations,
                });
            }
            d -= 1;
            idx[d] += 1;
            if idx[d] < axes[d].u.len() {
                break;
            }
            idx[d] = 0;
        }
    }
}

/// [`product_sum`]'s `value` alone, bit for bit, with the same errors but
/// for a companion's (a composite rule's `4h` rule can leave the range
/// where its own sum does not): all a rule without an error estimate
/// reads. On one axis it skips the sums only an estimate reads (`sum |w
/// y|`, the largest term, the companions): at a few nodes a large share of
/// the call (`benches/README.md`, `gl_small`), at 1e6 nodes of `cos(50 x)`
/// one percent. Where a value is not finite, or the sum leaves the f64
/// range, the whole sum is taken again to name it: from 128 nodes on one
/// axis `f` is then called a second time at every node that sum reaches,
/// to the end of the block of 256 holding the first value that is not
/// finite, or every node where the sum left the range (below 128 the
/// values are kept and summed again).
///
/// ```
/// use lightquad::quadrature::gauss_legendre::unit_nodes;
/// use lightquad::quadrature::nodes::{product_sum, product_value};
///
/// let nodes = unit_nodes(5)?;
/// let f = |u: [f64; 1]| Ok((3.0 * u[0]).exp());
/// let value = product_value([&*nodes], f)?;
/// assert_eq!(value, product_sum([&*nodes], f)?.value);
/// assert!((value - (3f64.exp() - 1.0) / 3.0).abs() < 1e-6);
/// # Ok::<(), lightquad::error::QuadError>(())
/// ```
#[inline]
pub fn product_value<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
    axes: [&UnitNodes; D],
    mut f: F,
) -> Result<V, QuadError> {
    for a in axes {
        a.check()?;
    }
    if D == 1 && !axes[0].is_empty() {
        return line_value(
            axes[0],
            #[inline(always)]
            move |u| {
                let mut p = [0.0; D];
                p[0] = u;
                f(p)
            },
        );
    }
    value_in_range(odometer_sum(axes, f)?)
}

/// `sum` with `magnitude` at most `f64::MAX`, or
/// [`QuadError::SumOutOfRange`] where a weighted sum of its finite terms is
/// not finite. Weights that sum to 1 keep an integral within the range of
/// the values, but not every running sum: the sum of `f64::MAX` on 1e5
/// Gauss nodes came out NaN, where the integral is `f64::MAX`
/// ([`crate::sum::Lanes::total`] now finds it; the odometer's single
/// running sum of [`product_sum`] in two and more dimensions can still
/// pass the range). `sum |w f|` passes `f64::MAX` only by rounding (it is
/// at most `max |f|` times the weights' sum, 1), so it is kept at
/// `f64::MAX`: a scale of rounding, not a value.
#[inline]
fn in_range<V: Value>(sum: ProductSum<V>) -> Result<ProductSum<V>, QuadError> {
    let finite = |s: Option<V>| s.is_none_or(|s| s.all_finite());
    if sum.value.all_finite()
        && finite(sum.companion)
        && finite(sum.companion4)
        && finite(sum.companion8)
    {
        return Ok(ProductSum {
            magnitude: sum.magnitude.map(|m| m.min(f64::MAX)),
            ..sum
        });
    }
    out_of_range(sum)
}

/// The `value` of `sum` where it is finite ([`in_range`] of the value
/// alone): a companion that left the range is no error of a sum that
/// does not read it.
#[inline]
fn value_in_range<V: Value>(sum: ProductSum<V>) -> Result<V, QuadError> {
    let value = ProductSum {
        companion: None,
        companion4: None,
        companion8: None,
        ..sum
    };
    in_range(value).map(|sum| sum.value)
}

/// [`in_range`]'s error, naming the first sum that is not finite.
#[cold]
fn out_of_range<V: Value>(sum: ProductSum<V>) -> Result<ProductSum<V>, QuadError> {
    let sums = [
        ("value", Some(sum.value)),
        ("companion", sum.companion),
        ("companion4", sum.companion4),
        ("companion8", sum.companion8),
    ];
    let (name, out) = sums
        .into_iter()
        .find_map(|(name, s)| s.filter(|s| !s.all_finite()).map(|s| (name, s)))
        .unwrap_or(("value", sum.value));
    Err(QuadError::SumOutOfRange {
        sum: name,
        value: crate::error::channels(out),
        largest: crate::error::channels(sum.largest),
    })
}

/// The error for a non-finite integrand value at unit-cube point `p`.
pub fn non_finite<V: Value>(p: &[f64], y: &V) -> QuadError {
    QuadError::NonFiniteIntegrand {
        point: p.to_vec(),
        value: crate::error::channels(*y),
    }
}

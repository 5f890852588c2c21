//! Weighted node sets on the unit interval and the one shared summation that
//! turns (tensor products of) them into an integral.

use std::cell::RefCell;
use std::sync::Arc;

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::sum::{Compensated, Kernel, KernelTask, LaneValues, Lanes, with_kernel};
use crate::value::Value;

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
/// A non-finite integrand value stops the sum with an error naming the point
/// (on one axis, at the end of the block of 256 nodes it is in). Finite
/// values within rounding of `f64::MAX`, whose sum passes it on the way,
/// are summed on one axis (see [`crate::sum::Lanes::total`]); in two and
/// more dimensions such a sum is [`QuadError::SumOutOfRange`], never a sum
/// that is not finite.
pub fn product_sum<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
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

    if D == 1 {
        return line_sum(axes[0], move |u| {
            let mut p = [0.0; D];
            p[0] = u;
            f(p)
        });
    }
    // D dimensions: walk the index odometer.
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
                return in_range(ProductSum {
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

/// [`product_sum`] on one axis: [`LineSum::add_span`] over all its nodes.
fn line_sum<V: Value>(
    a: &UnitNodes,
    f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<ProductSum<V>, QuadError> {
    let mut sum = LineSum::new();
    sum.add_span(a, 0..a.len(), f)?;
    in_range(sum.finish(a))
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
fn in_range<V: Value>(sum: ProductSum<V>) -> Result<ProductSum<V>, QuadError> {
    let sums = [
        Some(sum.value),
        sum.companion,
        sum.companion4,
        sum.companion8,
    ];
    if sums.iter().flatten().all(Value::all_finite) {
        Ok(ProductSum {
            magnitude: sum.magnitude.map(|m| m.min(f64::MAX)),
            ..sum
        })
    } else {
        Err(QuadError::SumOutOfRange {
            value: format!("{:?}", sum.value),
            largest: format!("{:?}", sum.largest),
        })
    }
}

/// Nodes per span of [`line_sum_par`]: a multiple of `BLOCK`, fixed, so
/// the spans, and with them the result, do not depend on the number of
/// threads. Some 0.2 ms of `cos(50 x)`, long against rayon's hand-over of
/// a span (microseconds) and short enough that 1e6 nodes make 62 spans for
/// two to eight threads to share evenly.
pub const PAR_SPAN: usize = 1 << 14;

/// [`product_sum`] on one axis, its nodes shared among rayon's threads:
/// the axis is cut into spans of [`PAR_SPAN`] nodes, each summed as
/// [`product_sum`] sums a whole axis (the same blocks, the same lanes, the
/// same compensated sum), and the spans' sums are merged in node order
/// ([`Lanes::merge`]). So the value is the same, bit for bit, whatever the
/// number of threads, and the same as [`product_sum`]'s up to `n <=
/// PAR_SPAN`; above, it differs from it in rounding only (the lanes restart
/// at every span; both are compensated sums).
///
/// `f` is called from several threads at once, at nodes in no particular
/// order. An error (a non-finite value, a sum out of range, or the
/// integrand's own) is the one [`product_sum`] would give: that of the
/// first span, in node order, that fails, and in it of the first failing
/// block. Spans after a failed span that have not started yet are skipped;
/// spans before it all run, and spans already started run to their end. A
/// panic of `f` is an outcome of its span like an error: it reaches the
/// caller only where no span before it failed, as with [`product_sum`]
/// (the panic hook may still print the message of one that is then
/// dropped).
///
/// ```
/// use lightquad::quadrature::gauss_legendre::unit_nodes;
/// use lightquad::quadrature::nodes::line_sum_par;
///
/// // int_0^1 cos(50 u) du = sin(50)/50 with a million Gauss nodes.
/// let nodes = unit_nodes(1_000_000)?;
/// let sum = line_sum_par(&nodes, |u| Ok((50.0 * u).cos()))?;
/// assert!((sum.value - 50f64.sin() / 50.0).abs() < 1e-17);
/// assert_eq!(sum.evaluations, 1_000_000);
/// # Ok::<(), lightquad::error::QuadError>(())
/// ```
pub fn line_sum_par<V: Value, F: Fn(f64) -> Result<V, QuadError> + Sync>(
    a: &UnitNodes,
    f: F,
) -> Result<ProductSum<V>, QuadError> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    // The lowest span that has failed (or panicked) so far: later spans
    // need not run.
    let failed = AtomicUsize::new(usize::MAX);
    let spans: Vec<Option<SpanOutcome<V>>> = (0..a.len().div_ceil(PAR_SPAN))
        .into_par_iter()
        .map(|k| {
            if k > failed.load(Ordering::Relaxed) {
                return None;
            }
            let range = k * PAR_SPAN..((k + 1) * PAR_SPAN).min(a.len());
            // `f` is only borrowed, and a span that panicked is never
            // read: nothing broken by the panic is seen again.
            let span = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                LineSum::of_span(a, range, &f)
            }));
            if !matches!(span, Ok(Ok(_))) {
                failed.fetch_min(k, Ordering::Relaxed);
            }
            Some(span)
        })
        .collect();
    let mut total = LineSum::new();
    // In node order: the first failed span is reached before any skipped
    // one (a span is skipped only after one before it failed), and a panic
    // resumes only when no span before it failed.
    for span in spans.into_iter().flatten() {
        match span {
            Ok(span) => total.merge(&span?),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    }
    in_range(total.finish(a))
}

/// What one span of [`line_sum_par`] came to: its sums, the integrand's
/// error, or the payload of its panic.
type SpanOutcome<V> = std::thread::Result<Result<LineSum<V>, QuadError>>;

/// Nodes per block of [`LineSum::add_span`]: the values of a block are
/// checked finite at once, and the companions summed. 256 rather than 64:
/// each block's check and hand-over cost some 1.3% of the evaluations of
/// `cos(50 x)` at 64 (paired rounds of `examples/gl_race.rs`, lightquad over
/// bilby 1.047, 1.058, 1.047 at 64 against 1.034, 1.046, 1.032 at 256, when
/// the block was summed after it was evaluated). The buffer is 2 KiB for a
/// scalar, 12 KiB for the largest value.
const BLOCK: usize = 256;

/// Nodes per group of [`LineSum::add_span`]: the integrand is evaluated
/// at a group, then the group before it is summed. A multiple of
/// [`crate::sum::LANES`], so a block's lanes take the same terms as when
/// the block is summed at once (the same bits).
const GROUP: usize = 16;

const _: () = assert!(BLOCK.is_multiple_of(GROUP) && GROUP.is_multiple_of(crate::sum::LANES));

// A span of `line_sum_par` is whole blocks, so its blocks are `product_sum`'s.
const _: () = assert!(PAR_SPAN.is_multiple_of(BLOCK));

/// The running sums of [`product_sum`] on one axis (and of each span of
/// [`line_sum_par`]): the weighted sum and its companions in lanes, `sum |w
/// y|` and the largest term.
#[derive(Clone, Copy)]
struct LineSum<V: Value> {
    value: Lanes<V>,
    companions: [Lanes<V>; 3],
    magnitude: LaneValues<V>,
    largest: LaneValues<V>,
}

impl<V: Value> LineSum<V> {
    fn new() -> Self {
        Self {
            value: Lanes::new(),
            companions: [Lanes::new(); 3],
            magnitude: LaneValues::zero(),
            largest: LaneValues::zero(),
        }
    }

    /// Adds the nodes `range` of `a`. The integrand is evaluated at a
    /// group of [`GROUP`] nodes, then the group before it is summed, in
    /// [`crate::sum::LANES`] independent lanes (the compensated sum, `sum |w
    /// y|` and the largest term in one pass), all in one function compiled
    /// for the lanes' kernel ([`with_kernel`]): AVX where the CPU has it.
    ///
    /// Why this shape, measured on `cos(50 x)` at n = 1e6 against bilby's
    /// plain loop (`examples/gl_race.rs`):
    /// - An integrand that calls a function (`cos`) clobbers every
    ///   floating-point register, so sums carried across each call are
    ///   stored and reloaded at every node: 1.13 to 1.18 times the bare
    ///   evaluations, term by term.
    /// - A whole block of 256 values summed after it is evaluated kept the
    ///   sums in registers, but the pass (a chain of dependent additions)
    ///   then ran alone, not in the shadow of the calls: 1.02 to 1.03 times
    ///   bilby, with the pass in AVX called once a block.
    /// - Groups of 16, summed between the calls in the same function, hide
    ///   the pass behind the calls: 1.00 to 1.01 times bilby (groups of 8
    ///   and of 32 came out at 1.03).
    /// - The integrand is taken by value: through a reference, each node
    ///   reloaded the captures' addresses before their values (2.5%).
    /// - In [`line_sum_par`]'s spans the compiler had left the pass a call
    ///   once a group (a `#[inline]` function compiled for AVX; it may not
    ///   be `inline(always)`): 1.01 to 1.05 times gauss-quad's parallel sum.
    ///   The pass is now an `inline(always)` closure: 0.98 to 1.00.
    ///
    /// The values are checked finite once a block of [`BLOCK`] nodes,
    /// through the block's `sum |w y|` (a NaN or infinite value makes it
    /// non-finite, and then the block is searched for the first such node):
    /// a check at every node cost about 5% of the evaluations of `cos(50
    /// x)`. So `f` may be called at up to 255 nodes after a non-finite value,
    /// and an error `f` returns at one of them is reported instead of that
    /// value (reporting the value first, with the loop that took, cost
    /// another 8% at n = 1e6). `magnitude` is summed a block at a time, so it
    /// can differ from a term-by-term sum in its last few bits. The
    /// companions' lanes take a block at a time.
    #[inline(always)]
    fn add_span(
        &mut self,
        a: &UnitNodes,
        range: std::ops::Range<usize>,
        f: impl FnMut(f64) -> Result<V, QuadError>,
    ) -> Result<(), QuadError> {
        with_kernel(Span {
            sums: self,
            a,
            range,
            f,
        })
    }

    /// The sums over the nodes `range` of `a`. Not inlined: in rayon's
    /// deeply inlined worker the integrand was left a call of its own at
    /// every node.
    #[inline(never)]
    fn of_span(
        a: &UnitNodes,
        range: std::ops::Range<usize>,
        f: &impl Fn(f64) -> Result<V, QuadError>,
    ) -> Result<Self, QuadError> {
        let mut sum = Self::new();
        sum.add_span(a, range, f)?;
        Ok(sum)
    }

    /// Adds the sums of a span that follows the spans already added.
    fn merge(&mut self, other: &Self) {
        self.value.merge(&other.value);
        for (lanes, more) in self.companions.iter_mut().zip(&other.companions) {
            lanes.merge(more);
        }
        self.magnitude.add(&other.magnitude);
        self.largest.max_with(&other.largest);
    }

    /// The sums over every node of `a`, once all are added.
    fn finish(&self, a: &UnitNodes) -> ProductSum<V> {
        let [c, c4, c8] = &self.companions;
        ProductSum {
            value: self.value.total(),
            companion: a.companion.as_ref().map(|_| c.total()),
            companion4: a.companion4.as_ref().map(|_| c4.total()),
            companion8: a.companion8.as_ref().map(|_| c8.total()),
            magnitude: self.magnitude.sum(),
            largest: self.largest.max(),
            evaluations: a.u.len() as u64,
        }
    }
}

/// [`LineSum::add_span`] as a [`KernelTask`]: the nodes `range` of `a`
/// added to `sums`.
struct Span<'a, V: Value, F> {
    sums: &'a mut LineSum<V>,
    a: &'a UnitNodes,
    range: std::ops::Range<usize>,
    f: F,
}

impl<V: Value, F: FnMut(f64) -> Result<V, QuadError>> KernelTask<V> for Span<'_, V, F> {
    type Output = Result<(), QuadError>;

    /// The integrand at a group of [`GROUP`] nodes, then the group's
    /// products into the lanes, group after group; the finite check and
    /// the companions a block of [`BLOCK`] nodes at a time.
    #[inline(always)]
    fn run(self, kernel: impl Kernel<V>) -> Self::Output {
        let Self {
            sums,
            a,
            range,
            mut f,
        } = self;
        let companions = [
            a.companion.as_deref(),
            a.companion4.as_deref(),
            a.companion8.as_deref(),
        ];
        let (u, w) = (&a.u[range.clone()], &a.w[range.clone()]);
        // Local copies of the sums, which the compiler keeps apart from `sums`.
        let LineSum {
            mut value,
            companions: mut others,
            mut magnitude,
            mut largest,
        } = *sums;
        let mut ys = [V::zero(); BLOCK];
        for (block, (us, ws)) in u.chunks(BLOCK).zip(w.chunks(BLOCK)).enumerate() {
            let ys = &mut ys[..us.len()];
            let mut block_magnitude = LaneValues::zero();
            // The integrand a group of `GROUP` nodes at a time (a loop of
            // known length, unrolled), and the group before it summed after
            // it: by then the values' stores have left the store buffer, and
            // a load of four of them as one vector does not wait on them.
            let (groups, tail) = us.as_chunks::<GROUP>();
            let mut pending = 0..0;
            for (g, ug) in groups.iter().enumerate() {
                let start = g * GROUP;
                for (y, &u) in ys[start..start + GROUP].iter_mut().zip(ug) {
                    *y = f(u)?;
                }
                value.add_products_scaled_in(
                    kernel,
                    &ys[pending.clone()],
                    &ws[pending],
                    &mut block_magnitude,
                    &mut largest,
                );
                pending = start..start + GROUP;
            }
            let start = groups.len() * GROUP;
            for (y, &u) in ys[start..].iter_mut().zip(tail) {
                *y = f(u)?;
            }
            for group in [pending, start..us.len()] {
                value.add_products_scaled_in(
                    kernel,
                    &ys[group.clone()],
                    &ws[group],
                    &mut block_magnitude,
                    &mut largest,
                );
            }
            if !block_magnitude.all_finite()
                && let Some((u, y)) = us.iter().zip(ys.iter()).find(|(_, y)| !y.all_finite())
            {
                return Err(non_finite(&[*u], y));
            }
            magnitude.add(&block_magnitude);
            let start = range.start + block * BLOCK;
            for (lanes, c) in others.iter_mut().zip(companions) {
                if let Some(c) = c {
                    lanes.add_products_in(kernel, ys, &c[start..start + us.len()]);
                }
            }
        }
        *sums = LineSum {
            value,
            companions: others,
            magnitude,
            largest,
        };
        Ok(())
    }
}

/// Fewest points per axis at which a composite rule's estimate is trusted.
/// Below it the rule has at most 8 intervals; a narrow peak between its
/// points showed estimates down to 4e-6 of the true error at 3 to 9
/// points (Lorentzians of width 1e-2 to 1e-4), where one node's share of
/// the sum cannot tell a peak from a smooth integrand on so few nodes
/// ([`dominated`]). The same bound as Gauss–Legendre's 16 nodes.
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
    /// `dim` dimensions uses ([`super::Rule::resolution`]).
    pub fn resolution(&self, n: usize, dim: usize) -> f64 {
        let m = super::integer_root(n, dim).max(self.min_points);
        ((self.usable)(m) - 1) as f64
    }

    /// The rule's tensor product on `[0, 1]^D` with a budget of `n`
    /// evaluations, and Richardson's error estimate.
    pub fn integrate<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
        &self,
        n: usize,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        let m = super::per_axis::<D>(n, self.min_points, "n")?;
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

/// A difference of two rules at most this many `eps` times `sum |w f|` is
/// rounding: the rule has converged.
pub(crate) const ROUNDING_ULPS: f64 = 128.0;

/// Share of `sum |w f|` above which one term makes a sum dominated
/// ([`dominated`]).
pub const DOMINANT_SHARE: f64 = 0.3;

/// Whether the sum rests on a single node, per channel: `largest > max(0.3,
/// 3 w_max) * magnitude`, with `w_max` the largest (product) weight of the
/// rule (weights sum to 1).
///
/// When one term carries that much of `sum |w f|` the integrand has a
/// feature narrower than the node spacing there (a narrow peak, a
/// near-singularity between nodes): its shape below the spacing is unseen,
/// and its true integral can be any multiple of what the node shows (a
/// Lorentzian `1/(w^2 + (x - c)^2)` of width `w = 1e-4` integrates to
/// `pi/w`, while a node `h/2` away shows `h / (h/2)^2`). No difference of
/// rules on these nodes bounds that error, so the estimate is doubted. The
/// `3 w_max` keeps a rule of a handful of nodes, where every node carries a
/// third, from being doubted for that alone. Resolved integrands stay well
/// below 0.3: `exp(3x)`, the largest share among the smooth battery
/// integrands, is 0.22 at 17 Simpson nodes and shrinks as `1/m`.
pub fn dominated<V: Value>(largest: V, magnitude: V, max_weight: f64) -> bool {
    let share = DOMINANT_SHARE.max(3.0 * max_weight);
    (0..V::CHANNELS).any(|c| largest.channel(c) > share * magnitude.channel(c))
}

/// A composite rule's sum as an estimate with Richardson's error estimate for
/// a rule of order `p`, checked against the order the differences show.
///
/// With the nested sums `Q_h, Q_2h, Q_4h, Q_8h` (the companions: no extra
/// evaluation; as many as the node set nests), the differences
/// `d_1 = Q_h - Q_2h`, `d_2 = Q_2h - Q_4h`, `d_3 = Q_4h - Q_8h` and their
/// ratios `rho_k = d_{k+1} / d_k` (`2^p` for order `p`) decide. Richardson's
/// estimate `|d_1| / (2^p - 1)` is right when the error is `C h^p`; a jump,
/// kink or cusp lowers the order (`O(h)` for a jump, `O(h^1.5)` for
/// `|x - c|^0.5`), and where the cusp or jump lies between nodes its error
/// oscillates with `h`, so one ratio can look like order `p` by chance
/// (`Q_h` and `Q_2h` agreeing while both are off).
///
/// - Every `rho_k` within 20% of `2^p`: the order is confirmed, and the
///   error is Richardson's `|d_1| / (min(rho_1, 2^p) - 1)`.
/// - Every `rho_k > 3/2`, some not near `2^p`: the differences shrink
///   geometrically at a rate `s = min(min_k rho_k, 4)` (order 2 at most
///   assumed: a lower order, or a ratio near `2^p` by chance), and the error
///   of `Q_h` is the largest of the differences carried down to `h` at that
///   rate, `max_k |d_k| / ((s - 1) s^(k-1))`: honest when `d_1` is small by
///   chance, as the coarser differences still show the error's size.
/// - Otherwise (a sign change, or differences that do not shrink):
///   `max(|d_1|, |d_2|)` undivided, and the coarser differences carried down
///   at order 2, whichever is larger.
///
/// The coarser sums are those of [`coarse_weights`]: where the points do
/// not nest the `4h` (`8h`) rule, its panels with a finer tail. Only rules
/// below [`CHECKED_POINTS`], whose estimate is doubted anyway, lack the `4h`
/// level; there nothing shows the order, and the estimate assumes no more
/// than order 2 (what a kink still gives): `|d_1| / (min(2^p, 4) - 1)`.
/// (A band of 25% let a Simpson estimate at a cusp through at 0.034 of the
/// true error: ratios 12.17 and 12.07 at m = 109; 20% holds it.)
///
/// On `|x - c|^0.5` (200 random `c`, 19 point counts from 17 to 16385)
/// the single-ratio check let estimates fall to 1.4e-3 (trapezoid) and
/// 1.6e-4 (Simpson) of the true error; with this rule the smallest is 0.2.
///
/// Where `Q_h`, `Q_2h` and `Q_4h` agree to rounding (`|d_1|, |d_2| <= 128
/// eps sum |w f|`) the rule has converged, and the coarsest difference,
/// which may still be large, is capped as Gauss–Legendre caps its drowned
/// differences ([`super::gauss_legendre::hybrid_estimate`]): `max(eps M,
/// min(E, m 128 eps M))`, `m` the `points` per axis. The trapezoid on a
/// periodic integrand converges faster than any power, and an `8h` rule
/// with a finer tail is not exact for it. Two rules agreeing are not
/// enough: by the symmetry of `sin`, `Q_h` and `Q_2h` of the trapezoid on
/// `1/(1 + 0.99 sin 2 pi x)` at 47 points agree to 1e-11 while both are off
/// by 2e-2 (with the cap on `d_1` alone the estimate was 9.4e-12). Where
/// the `4h` rule ends in a finer tail the periodic estimate stays honest but
/// pessimistic (`exp(u) (1 + cos^2(2 pi v))` at 31 points in `v`: 8.3e-3
/// for an error of 1e-15; at 33 points, where the rules nest, 1e-15).
///
/// The estimate is doubted when one node dominates the sum ([`dominated`]).
pub fn richardson<V: Value>(
    sum: ProductSum<V>,
    order: i32,
    max_weight: f64,
    points: usize,
) -> Estimate<V> {
    let coarse = sum.companion.unwrap_or(sum.value);
    let full = 2f64.powi(order);
    let unchecked = full.min(4.0);
    let error = match sum.companion4 {
        // No estimate below the rounding of the sum itself, `eps sum |w f|`
        // (two rules that agree exactly, on a constant, differ by 0).
        None => V::from_fn(|c| {
            ((sum.value.channel(c) - coarse.channel(c)).abs() / (unchecked - 1.0))
                .max(f64::EPSILON * sum.magnitude.channel(c))
        }),
        Some(coarser) => V::from_fn(|c| {
            let mut q = [
                sum.value.channel(c),
                coarse.channel(c),
                coarser.channel(c),
                0.0,
            ];
            let levels = match sum.companion8 {
                Some(q8) => {
                    q[3] = q8.channel(c);
                    4
                }
                None => 3,
            };
            let nested = nested_estimate(&q[..levels], full);
            // Q_h, Q_2h and Q_4h agree to rounding: the rule has converged
            // (a periodic integrand under the trapezoid), whatever the 8h
            // level shows (its finer tail is not exact for it).
            let rounding = f64::EPSILON * sum.magnitude.channel(c);
            let noise = ROUNDING_ULPS * rounding;
            if (q[0] - q[1]).abs() <= noise && (q[1] - q[2]).abs() <= noise {
                rounding.max(nested.min(points as f64 * noise))
            } else {
                nested
            }
        }),
    };
    let estimate = Estimate::deterministic(sum.value, error, sum.evaluations);
    if dominated(sum.largest, sum.magnitude, max_weight) {
        estimate.doubted()
    } else {
        estimate
    }
}

/// The error of `q[0]` from nested sums `q = [Q_h, Q_2h, Q_4h (, Q_8h)]` of
/// a rule of nominal rate `full = 2^p` ([`richardson`]).
fn nested_estimate(q: &[f64], full: f64) -> f64 {
    let d: Vec<f64> = q.windows(2).map(|w| w[0] - w[1]).collect();
    let rho: Vec<f64> = d.windows(2).map(|w| w[1] / w[0]).collect();
    // `|d_k| / ((s - 1) s^(k-1))`, the largest over k.
    let carried = |s: f64| {
        d.iter()
            .enumerate()
            .map(|(k, dk)| dk.abs() / ((s - 1.0) * s.powi(k as i32)))
            .fold(0.0, f64::max)
    };
    if rho.iter().all(|&r| r > 1.5) {
        let slowest = rho.iter().copied().fold(f64::INFINITY, f64::min);
        let confirmed = rho.iter().all(|&r| (0.8 * full..=1.2 * full).contains(&r));
        if confirmed {
            // Order p over every level: Richardson's estimate at the
            // finest ratio.
            d[0].abs() / (rho[0].min(full) - 1.0)
        } else {
            carried(slowest.min(full).min(4.0))
        }
    } else {
        carried(full.min(4.0)).max(d[0].abs().max(d[1].abs()))
    }
}

/// The error for a non-finite integrand value at unit-cube point `p`.
pub fn non_finite<V: Value>(p: &[f64], y: &V) -> QuadError {
    QuadError::NonFiniteIntegrand {
        point: p.to_vec(),
        value: format!("{y:?}"),
    }
}

//! The sum over one axis of nodes, [`product_sum`]'s in one dimension and
//! [`line_sum_par`]'s across threads: groups of values summed between the
//! integrand's calls, in lanes.
//!
//! [`product_sum`]: super::product_sum

use wide::f64x4;

use crate::error::QuadError;
use crate::sum::{Kernel, KernelTask, LaneValues, Lanes, with_kernel, with_kernel_sharing};
use crate::value::Value;

use super::short::{LANES_FROM, SHORT_BELOW, short_sum, short_value};
use super::{ProductSum, UnitNodes, in_range, non_finite, value_in_range};

/// The smallest span size of [`line_sum_par`] ([`par_span`]; the last
/// span of an axis, and the one span of a shorter axis, can hold fewer
/// nodes): some 36 µs of `cos(50 x)`, long against the claim of a span
/// (an atomic addition and an uncontended lock).
pub const PAR_SPAN: usize = 1 << 12;

/// Nodes per span of [`line_sum_par`] on an axis of `n` nodes: the power
/// of two nearest `8 sqrt(n)` in ratio (between 5.7 and 11.3 times
/// `sqrt(n)`), at least [`PAR_SPAN`]: 4096 below `n = 2^19`, 8192 from
/// `2^19` (so at n = 1e6), 16384 from `2^21`, doubling at every fourfold
/// `n`. It depends on `n` alone, so the spans, and with them the result,
/// do not depend on the number of threads.
///
/// Why `sqrt(n)`: each span costs a fixed amount (some 0.27 µs a span,
/// measured on one thread when each span was a rayon task of its own),
/// and a thread that runs out of spans waits at most for the one its peer
/// is in, on average about half a span. With `n / s` spans of `s` nodes on
/// `P` threads the time lost is about `c n / (s P) + t s / 2`, least at
/// `s = sqrt(2 c n / (t P))`: proportional to `sqrt(n)` for every `P`, with
/// a factor that falls as `1 / sqrt(P)`. The factor 8 is tuned on two
/// threads (the formula gives some 5.7 there), and only the growth with
/// `n` holds for every `P`. Measured on two threads against gauss-quad's
/// parallel sum (`cos(50 x)`, benches/README.md, session 44): at n = 1e6
/// spans of 8192 gave 1.0001 where 4096 gave 1.0026 (`gl_race`, medians of
/// 10 processes); below, a scratch race (medians of 5) was mixed: at n =
/// 3e5, 4096 gave 1.0094 where 8192 (37 spans, one thread doing 19) gave
/// 1.0197, and at n = 1e5, 8192 gave 1.0135 where 4096 gave 1.0160. The
/// cut at `2^19` is the rule's, not the data's.
///
/// ```
/// use lightquad::quadrature::nodes::{PAR_SPAN, par_span};
///
/// assert_eq!(par_span(100_000), PAR_SPAN);
/// assert_eq!(par_span(1_000_000), 8192);
/// assert_eq!(par_span(10_000_000), 32768);
/// ```
pub fn par_span(n: usize) -> usize {
    let log = n.checked_ilog2().unwrap_or(0);
    PAR_SPAN.max(1 << ((log + 7) / 2))
}

/// [`product_sum`] on one axis, its nodes shared among rayon's threads:
/// the axis is cut into spans of [`par_span`]`(n)` nodes, each summed as
/// [`product_sum`] sums a whole axis (the same blocks, the same lanes, the
/// same compensated sum), and the spans' sums are merged in node order
/// ([`Lanes::merge`]). So the value is the same, bit for bit, whatever the
/// number of threads, and the same as [`product_sum`]'s up to `n <=
/// PAR_SPAN`; above, it differs from it in rounding only (the lanes restart
/// at every span; both are compensated sums).
///
/// The spans are shared among one worker a thread of rayon's pool: the
/// axis is cut into one run of consecutive spans a worker, and each worker
/// claims the spans of its own run in order (an atomic addition each),
/// then helps in the other runs in turn (those after its own, then those
/// before), so a thread reads the nodes in order, as the serial sum does,
/// and waits at the end at most for the span its peer is in. Measured
/// (benches/README.md, session 44) against what it replaced, rayon's tree
/// of one task a span, alternating: on two threads at n = 1e6 0.9989 times
/// gauss-quad's parallel sum (median of 10 processes) where the tree gave
/// 1.0024, and 1.0010 (8) where it gave 1.0020: level with gauss-quad's,
/// some 0.1 to 0.35% ahead of the tree; on one thread 0.981 to 0.993 times
/// gauss-quad's where the tree gave 1.001 to 1.004, and 1.001 to 1.006
/// times the serial sum where the tree gave 1.022 to 1.028. Spans claimed
/// from one counter for all threads, so interleaved between them, were 3%
/// slower on two threads in one process (8 to 12% before the counter had
/// a cache line of its own); presumably each thread's reads, jumping at
/// every span, lost the caches' prefetching (not measured).
///
/// `f` is called from several threads at once, at nodes in no particular
/// order, each span through a shared reference. The reference reaches the
/// span's loop as an argument of its own (`sum::with_kernel_sharing`), so
/// the compiler knows the integrand's calls do not write to the closure
/// and loads its captures once a group of nodes, not at every node:
/// reloaded at every node through a reference inside the span's task,
/// they cost 0.6 to 0.9% of `cos(50 x)` at n = 1e6. (A clone of `f` per
/// span, an `F: Clone` bound, did the same and was not kept: a closure
/// that owns what it reads, a table, a lazily filled cache, a `Mutex`,
/// would have been cloned, or filled, once per span, or not accepted at
/// all; benches/README.md, session 42.)
///
/// An error (a non-finite value, or the integrand's own) is the one
/// [`product_sum`] would give: that of the first span, in node order, that
/// fails, and in it of the first failing block. A sum out of range
/// ([`QuadError::SumOutOfRange`]) is the exception, as its rounding
/// differs: a sum within rounding of `f64::MAX` can leave the range in one
/// and not in the other (a trapezoid rule's `4h` companion on `f64::MAX`:
/// at 100001 nodes serially, not here), or leave it in another of the
/// companions. Spans after a failed span that have not started yet are skipped;
/// spans before it all run, and spans already started run to their end. A
/// panic of `f` is an outcome of its span like an error: it reaches the
/// caller only where no span before it failed, as with [`product_sum`]
/// (the panic hook may still print the message of one that is then
/// dropped; a payload whose own `Drop` panics is dropped without that
/// panic escaping).
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
///
/// [`product_sum`]: super::product_sum
pub fn line_sum_par<V: Value, F: Fn(f64) -> Result<V, QuadError> + Sync>(
    a: &UnitNodes,
    f: F,
) -> Result<ProductSum<V>, QuadError> {
    // A value of no channels has nothing to store ([`LineSum::STORED`] is
    // 0): its nodes are evaluated, and their errors found, serially; and a
    // few nodes are summed term by term, as `line_sum` sums them.
    a.check()?;
    if V::CHANNELS == 0 || a.len() < LANES_FROM {
        return line_sum(a, f);
    }
    in_range(whole_par(a, &f)?.finish(a))
}

/// [`line_sum_par`]'s `value` alone, bit for bit, with its errors but for a
/// companion's, as [`product_value`] is [`product_sum`]'s: the spans sum
/// the value's lanes alone (no `sum |w y|`, largest term or companions),
/// and where a span's sums stop being finite (a value not finite, a sum
/// past the range), or their total is not, the whole of [`line_sum_par`]
/// is taken again, which names it: `f` is called a second time at every
/// node that sum reaches.
///
/// ```
/// use lightquad::quadrature::gauss_legendre::unit_nodes;
/// use lightquad::quadrature::nodes::{line_sum_par, line_value_par};
///
/// let nodes = unit_nodes(100_000)?;
/// let f = |u: f64| Ok((50.0 * u).cos());
/// let value = line_value_par(&nodes, f)?;
/// assert_eq!(value, line_sum_par(&nodes, f)?.value);
/// assert!((value - 50f64.sin() / 50.0).abs() < 1e-17);
/// # Ok::<(), lightquad::error::QuadError>(())
/// ```
///
/// [`product_value`]: super::product_value
/// [`product_sum`]: super::product_sum
pub fn line_value_par<V: Value, F: Fn(f64) -> Result<V, QuadError> + Sync>(
    a: &UnitNodes,
    f: F,
) -> Result<V, QuadError> {
    a.check()?;
    if V::CHANNELS == 0 || a.len() < LANES_FROM {
        return line_value(a, f);
    }
    if let Some(sums) = par_sum::<V, F, true>(a, &f)? {
        let value = sums.value.total();
        if value.all_finite() {
            return Ok(value);
        }
    }
    value_in_range(whole_par(a, &f)?.finish(a))
}

/// [`par_sum`]'s whole sums, which never stop without an error: a span
/// of them names the value that is not finite. An error that says so
/// rather than a panic, should one ever come back stopped.
fn whole_par<V: Value, F: Fn(f64) -> Result<V, QuadError> + Sync>(
    a: &UnitNodes,
    f: &F,
) -> Result<LineSum<V>, QuadError> {
    par_sum::<V, F, false>(a, f)?.ok_or_else(|| {
        QuadError::invalid(
            "line_sum_par",
            "a span stopped without an error",
            "a whole span that runs to its end or names its error",
        )
    })
}

/// The sums of [`line_sum_par`] (with `VALUE_ONLY`, of
/// [`line_value_par`]) over the spans of `a`, merged in node order; `None`
/// where a value-only span stopped at sums that are not finite before any
/// span failed.
fn par_sum<V: Value, F: Fn(f64) -> Result<V, QuadError> + Sync, const VALUE_ONLY: bool>(
    a: &UnitNodes,
    f: &F,
) -> Result<Option<LineSum<V>>, QuadError> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::{Mutex, PoisonError};
    // An atomic on a cache line of its own: a claim (a write) is not
    // seen by the other threads' reads of what lay beside it.
    #[repr(align(128))]
    struct Padded(AtomicUsize);
    // The lowest span that has failed (or panicked) so far: later spans
    // need not run.
    let failed = Padded(AtomicUsize::new(usize::MAX));
    // Nodes per span, and spans.
    let per_span = par_span(a.len());
    let count = a.len().div_ceil(per_span);
    // Each span's sums, the channels of `V` only ([`LineSum::store`]):
    // `LineSum` is sized for the most channels a value may have, and
    // moving it out of every span cost some 0.5 to 1% at n = 1e6.
    let mut sums = vec![f64x4::ZERO; count * LineSum::<V>::STORED];
    // Each span's slot and outcome, behind a lock that only the worker
    // that claimed the span takes.
    let slots: Vec<Mutex<(&mut [f64x4], Option<SpanOutcome>)>> = sums
        .chunks_mut(LineSum::<V>::STORED)
        .map(|slot| Mutex::new((slot, None)))
        .collect();
    // The runs: `first(w)..first(w + 1)`, and the next span of each to
    // claim.
    let workers = rayon::current_num_threads().clamp(1, count.max(1));
    let first = |w: usize| w * count / workers;
    let next: Vec<Padded> = (0..workers)
        .map(|w| Padded(AtomicUsize::new(first(w))))
        .collect();
    // Worker `w` claims the spans of run `w` until none is left, or until
    // a span before the one it claimed has failed; then those of the other
    // runs in turn.
    (0..workers).into_par_iter().with_max_len(1).for_each(|w| {
        for run in (w..workers).chain(0..w) {
            loop {
                let k = next[run].0.fetch_add(1, Ordering::Relaxed);
                if k >= first(run + 1) || k > failed.0.load(Ordering::Relaxed) {
                    break;
                }
                let range = k * per_span..((k + 1) * per_span).min(a.len());
                let mut slot = slots[k].lock().unwrap_or_else(PoisonError::into_inner);
                let (sums, outcome) = &mut *slot;
                // `f` is only borrowed, and a span that panicked is never
                // read: nothing broken by the panic is seen again.
                let span = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    LineSum::of_span::<VALUE_ONLY>(a, range, f, sums)
                }));
                if !matches!(span, Ok(Ok(true))) {
                    failed.0.fetch_min(k, Ordering::Relaxed);
                }
                *outcome = Some(span);
            }
        }
    });
    let spans: Vec<Option<SpanOutcome>> = slots
        .into_iter()
        .map(|slot| slot.into_inner().unwrap_or_else(PoisonError::into_inner).1)
        .collect();
    let mut total = LineSum::new();
    // In node order: the first failed span is reached before any skipped
    // one (a span is skipped only after one before it failed), and a panic
    // resumes only when no span before it failed. The panics of the spans
    // after the first failure are dropped, not resumed.
    let mut spans = spans
        .into_iter()
        .zip(sums.chunks_exact(LineSum::<V>::STORED));
    let failure = spans.find_map(|(span, slot)| match span? {
        Ok(Ok(true)) => {
            total.merge(&LineSum::load(slot));
            None
        }
        Ok(Ok(false)) => Some(Ok(None)),
        Ok(Err(error)) => Some(Ok(Some(error))),
        Err(panic) => Some(Err(panic)),
    });
    let Some(failure) = failure else {
        return Ok(Some(total));
    };
    for (span, _) in spans {
        if let Some(Err(panic)) = span {
            drop_panic(panic);
        }
    }
    match failure {
        Ok(None) => Ok(None),
        Ok(Some(error)) => Err(error),
        Err(panic) => std::panic::resume_unwind(panic),
    }
}

/// Drops the payload of a panic that is not resumed. Its own `Drop` may
/// panic too (a payload is any type): that panic is caught, and its
/// payload, which could do the same, forgotten rather than dropped, so
/// that no panic escapes from a call that returns an error.
fn drop_panic(panic: Box<dyn std::any::Any + Send>) {
    if let Err(again) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| drop(panic))) {
        std::mem::forget(again);
    }
}

/// What one span of [`line_sum_par`] came to: its sums stored, the
/// integrand's error, or the payload of its panic.
/// `Ok(Ok(false))`: a value-only span stopped at sums that are not finite.
type SpanOutcome = std::thread::Result<Result<bool, QuadError>>;

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

// A span of `line_sum_par` (a power of two, at least `PAR_SPAN`) is whole
// blocks, so its blocks are `product_sum`'s.
const _: () = assert!(PAR_SPAN.is_power_of_two() && PAR_SPAN.is_multiple_of(BLOCK));

/// [`product_sum`] on one axis: [`LineSum::add_span`] over all its nodes,
/// or below [`SHORT_BELOW`] nodes [`short_sum`].
///
/// [`product_sum`]: super::product_sum
pub(super) fn line_sum<V: Value>(
    a: &UnitNodes,
    f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<ProductSum<V>, QuadError> {
    if a.len() < SHORT_BELOW {
        return short_sum(a, f);
    }
    let mut sum = LineSum::new();
    sum.add_span(a, 0..a.len(), f)?;
    in_range(sum.finish(a))
}

/// [`line_sum`]'s `value` alone, bit for bit, and its errors but for a
/// companion's, without the sums only an error estimate reads (`sum |w
/// y|`, the largest term, the companions): below [`SHORT_BELOW`] nodes
/// [`short_value`], from there the lanes of the value alone
/// ([`LineSum::add_value_span`]). Where those lanes meet a value that is
/// not finite, or leave the f64 range, or their total does, the whole sum
/// is taken again from the first node and names the node or the sum as
/// [`line_sum`] does: `f` is called a second time at every node that sum
/// reaches (to the end of the block holding the first value that is not
/// finite, or every node).
///
/// Why: at n = 1e6 on `cos(50 x)` the largest term's `maxpd` alone, one
/// instruction a group of four nodes, cost 0.7% (`examples/gl_race.rs`,
/// `lightquad / bilby` 1.0132 with it and 1.0059 without); without `sum |w
/// y|` too, the rule through
/// [`Rule::integrate`](crate::quadrature::Rule::integrate) went from
/// 1.0134 to 1.0055 times bilby (benches/README.md, tenth session).
#[inline]
pub(super) fn line_value<V: Value>(
    a: &UnitNodes,
    mut f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    if a.len() < SHORT_BELOW {
        return short_value(a, f);
    }
    let mut sum = LineSum::new();
    if sum.add_value_span(a, 0..a.len(), &mut f)? {
        let value = sum.value.total();
        if value.all_finite() {
            return Ok(value);
        }
    }
    let mut sum = LineSum::new();
    sum.add_span(a, 0..a.len(), f)?;
    value_in_range(sum.finish(a))
}

/// The running sums of [`product_sum`] on one axis (and of each span of
/// [`line_sum_par`]): the weighted sum and its companions in lanes, `sum |w
/// y|` and the largest term.
///
/// [`product_sum`]: super::product_sum
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
    /// - The pass over a group as arrays of known length
    ///   ([`group_before`]), unrolled, the lanes held as one 256-bit value
    ///   from group to group (`sum::avx::to_avx`): 0.9963 to 1.0020 times
    ///   bilby (median 0.9988) in 10 processes, where the pass as a loop
    ///   over a range had 1.0035 to 1.0066 (median 1.0050) in 10 processes
    ///   alternating with them.
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
        with_kernel(Span::<V, _, false> {
            sums: self,
            a,
            range,
            f,
        })
        .map(|_| ())
    }

    /// [`LineSum::add_span`] into the value's lanes alone, the same bits
    /// in them: no `sum |w y|`, no largest term, no companions. The check
    /// at the end of a block reads the lanes' sums instead (a value not
    /// finite makes them so): `Ok(false)` where they are not finite in a
    /// channel that [`Value::all_finite`] reads, a value there not finite
    /// or a sum past the range, and the sums are then left unfinished.
    #[inline(always)]
    fn add_value_span(
        &mut self,
        a: &UnitNodes,
        range: std::ops::Range<usize>,
        f: impl FnMut(f64) -> Result<V, QuadError>,
    ) -> Result<bool, QuadError> {
        with_kernel(Span::<V, _, true> {
            sums: self,
            a,
            range,
            f,
        })
    }

    /// The sums over the nodes `range` of `a`, stored in `slot`
    /// ([`LineSum::store`]). Not inlined: in rayon's deeply inlined worker
    /// the integrand was left a call of its own at every node.
    /// With `VALUE_ONLY`, the value's lanes alone, and `Ok(false)` (nothing
    /// stored) where they stop ([`LineSum::add_value_span`]).
    #[inline(never)]
    fn of_span<const VALUE_ONLY: bool>(
        a: &UnitNodes,
        range: std::ops::Range<usize>,
        f: &impl Fn(f64) -> Result<V, QuadError>,
        slot: &mut [f64x4],
    ) -> Result<bool, QuadError> {
        let mut sums = Self::new();
        let whole = with_kernel_sharing(
            SharedSpan::<V, VALUE_ONLY> {
                sums: &mut sums,
                a,
                range,
            },
            f,
        )?;
        if whole {
            sums.store(slot);
        }
        Ok(whole)
    }

    /// Vectors [`LineSum::store`] fills: ten [`LaneValues`] (the sums and
    /// carries of the value and its three companions, the magnitude and
    /// the largest term), each of the channels of `V`.
    const STORED: usize = 10 * V::CHANNELS;

    /// The ten [`LaneValues`] of the sums, in [`LineSum::STORED`]'s order.
    fn parts(&self) -> [&LaneValues<V>; 10] {
        let [v, vc] = self.value.parts();
        let [c, cc] = self.companions[0].parts();
        let [d, dc] = self.companions[1].parts();
        let [e, ec] = self.companions[2].parts();
        [v, vc, c, cc, d, dc, e, ec, &self.magnitude, &self.largest]
    }

    /// The sums in `slot`, [`LineSum::STORED`] vectors, the channels of
    /// `V` only.
    fn store(&self, slot: &mut [f64x4]) {
        for (lanes, to) in self
            .parts()
            .into_iter()
            .zip(slot.chunks_exact_mut(V::CHANNELS))
        {
            to.copy_from_slice(lanes.used());
        }
    }

    /// The sums [`LineSum::store`] stored in `slot`.
    fn load(slot: &[f64x4]) -> Self {
        let mut sums = Self::new();
        let [c, d, e] = &mut sums.companions;
        let parts = [&mut sums.value, c, d, e]
            .map(Lanes::parts_mut)
            .into_iter()
            .flatten()
            .chain([&mut sums.magnitude, &mut sums.largest]);
        for (lanes, from) in parts.zip(slot.chunks_exact(V::CHANNELS)) {
            lanes.used_mut().copy_from_slice(from);
        }
        sums
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
/// added to `sums`; with `VALUE_ONLY`, [`LineSum::add_value_span`].
struct Span<'a, V: Value, F, const VALUE_ONLY: bool> {
    sums: &'a mut LineSum<V>,
    a: &'a UnitNodes,
    range: std::ops::Range<usize>,
    f: F,
}

/// [`Span`] with the integrand shared: [`LineSum::of_span`]'s, which
/// reads it through a shared reference ([`KernelTask`]).
struct SharedSpan<'a, V: Value, const VALUE_ONLY: bool> {
    sums: &'a mut LineSum<V>,
    a: &'a UnitNodes,
    range: std::ops::Range<usize>,
}

impl<V: Value, F: Fn(f64) -> Result<V, QuadError>, const VALUE_ONLY: bool> KernelTask<V, F>
    for SharedSpan<'_, V, VALUE_ONLY>
{
    type Output = Result<bool, QuadError>;

    #[inline(always)]
    fn run(self, kernel: impl Kernel<V>, f: &F) -> Self::Output {
        let Self { sums, a, range } = self;
        Span::<V, _, VALUE_ONLY> { sums, a, range, f }.run(kernel, &())
    }
}

impl<V: Value, F: FnMut(f64) -> Result<V, QuadError>, const VALUE_ONLY: bool> KernelTask<V>
    for Span<'_, V, F, VALUE_ONLY>
{
    /// `Ok(false)` where a value-only span stopped at a block whose sums
    /// are not finite; `Ok(true)` otherwise.
    type Output = Result<bool, QuadError>;

    /// The integrand at a group of [`GROUP`] nodes, then the products of
    /// the group before it into the lanes, group after group; the finite
    /// check and the companions a block of [`BLOCK`] nodes at a time.
    #[inline(always)]
    fn run(self, kernel: impl Kernel<V>, _: &()) -> Self::Output {
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
            for (g, ug) in groups.iter().enumerate() {
                let start = g * GROUP;
                for (y, &u) in ys[start..start + GROUP].iter_mut().zip(ug) {
                    *y = f(u)?;
                }
                if let Some((yg, wg)) = group_before(ys, ws, start) {
                    add::<V, VALUE_ONLY>(
                        kernel,
                        &mut value,
                        yg,
                        wg,
                        &mut block_magnitude,
                        &mut largest,
                    );
                }
            }
            let start = groups.len() * GROUP;
            for (y, &u) in ys[start..].iter_mut().zip(tail) {
                *y = f(u)?;
            }
            if let Some((yg, wg)) = group_before(ys, ws, start) {
                add::<V, VALUE_ONLY>(
                    kernel,
                    &mut value,
                    yg,
                    wg,
                    &mut block_magnitude,
                    &mut largest,
                );
            }
            add::<V, VALUE_ONLY>(
                kernel,
                &mut value,
                &ys[start..],
                &ws[start..],
                &mut block_magnitude,
                &mut largest,
            );
            if VALUE_ONLY {
                if !value.parts()[0].finite_as_value() {
                    return Ok(false);
                }
                continue;
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
        Ok(true)
    }
}

/// The products `w_i y_i` into `value` and, but for `VALUE_ONLY`, `|w_i
/// y_i|` into `magnitude` and the largest into `largest`.
#[inline(always)]
fn add<V: Value, const VALUE_ONLY: bool>(
    kernel: impl Kernel<V>,
    value: &mut Lanes<V>,
    ys: &[V],
    ws: &[f64],
    magnitude: &mut LaneValues<V>,
    largest: &mut LaneValues<V>,
) {
    if VALUE_ONLY {
        value.add_products_in(kernel, ys, ws);
    } else {
        value.add_products_scaled_in(kernel, ys, ws, magnitude, largest);
    }
}

/// The whole group of [`GROUP`] values and weights that ends at `end`,
/// none at the start of a block: arrays of known length, over which the
/// pass is unrolled. (A range that could be empty left the pass a loop.)
#[inline(always)]
fn group_before<'a, V>(
    ys: &'a [V],
    ws: &'a [f64],
    end: usize,
) -> Option<(&'a [V; GROUP], &'a [f64; GROUP])> {
    let start = end.checked_sub(GROUP)?;
    Some((ys[start..].first_chunk()?, ws[start..].first_chunk()?))
}

//! Every tabulated Gauss–Legendre rule mapped to `[0, 1]`, built at compile
//! time, and the rule's value on one such axis without its estimate.
//!
//! There the rule without its estimate reads its nodes and weights with
//! no cache to look up and no set to check, and adds each term to one
//! running sum as the integrand's call returns, as bilby and gauss-quad
//! do: what a compensated sum would cost at a few nodes is in
//! `benches/README.md` (`gl_small`, the tabulated line).
//!
//! Each term `w f` is rounded once, within `u = 2^-53` of itself, and the
//! running sum of the m terms is within `gamma_(m-1) sum |w f|` of their
//! exact sum, `gamma_k = k u / (1 - k u)` (Higham, *Accuracy and Stability
//! of Numerical Algorithms*, 2nd ed., section 4.2): at most about `99 u` of
//! the terms' magnitude at the largest order here, where a compensated sum
//! is within about `u |sum|`. Larger orders, and every sum the error
//! estimate reads, are compensated.

use crate::error::QuadError;
use crate::quadrature::nodes::product_value;
use crate::value::Value;

use super::{TABLE_MAX_ORDER, mirrored_row, unit_rule};

/// Nodes of all tabulated rules one after another, `sum_{n <= 100} n`.
const UNIT_LEN: usize = TABLE_MAX_ORDER * (TABLE_MAX_ORDER + 1) / 2;

/// Every tabulated rule on `[0, 1]` as `[node, weight]` pairs, nodes
/// ascending, order n from `n (n - 1) / 2`.
static UNIT: [[f64; 2]; UNIT_LEN] = unit_mirrored();

/// The pairs of order n at index n (none at 0).
static RULES: [&[[f64; 2]]; TABLE_MAX_ORDER + 1] = rules();

/// The tabulated half rules mirrored into full rules on `[0, 1]`
/// (`mirrored_row`), as `computed_unit_nodes` maps them: a lower-half
/// entry at `u = (1 - x_k)/2`, from the tabulated `1 - x_k` (full relative
/// precision near 0), an upper one at `u = (1 + x_k)/2`; each weight is
/// `w_k / 2`.
const fn unit_mirrored() -> [[f64; 2]; UNIT_LEN] {
    let mut out = [[0.0; 2]; UNIT_LEN];
    let mut n = 1;
    while n <= TABLE_MAX_ORDER {
        let start = n * (n - 1) / 2;
        let mut i = 0;
        while i < n {
            let ([x, one_minus_x, w], lower) = mirrored_row(n, i);
            let u = if lower {
                0.5 * one_minus_x
            } else {
                0.5 * (1.0 + x)
            };
            out[start + i] = [u, 0.5 * w];
            i += 1;
        }
        n += 1;
    }
    out
}

/// [`UNIT`] cut into its orders.
const fn rules() -> [&'static [[f64; 2]]; TABLE_MAX_ORDER + 1] {
    let mut out: [&[[f64; 2]]; TABLE_MAX_ORDER + 1] = [&[]; TABLE_MAX_ORDER + 1];
    let mut rest: &'static [[f64; 2]] = &UNIT;
    let mut n = 1;
    while n <= TABLE_MAX_ORDER {
        let (rule, tail) = rest.split_at(n);
        out[n] = rule;
        rest = tail;
        n += 1;
    }
    out
}

/// The tabulated rule of order `n` on `[0, 1]` as `[node, weight]` pairs,
/// nodes ascending; empty outside `1..=TABLE_MAX_ORDER`.
pub fn unit_table(n: usize) -> &'static [[f64; 2]] {
    RULES.get(n).copied().unwrap_or(&[])
}

/// `sum_i w_i f(u_i)` over the tabulated rule of order `m` in
/// `1..=TABLE_MAX_ORDER` (the caller checks it) on `[0, 1]`, one running
/// sum in the order of the nodes; `evaluations` counts the calls of `f`. A
/// sum that is not finite is taken again by [`product_value`], which calls
/// `f` at every node a second time and names the point whose value is not
/// finite, finds a total within range, or names the sum out of range.
#[inline(always)]
pub(super) fn tabulated_value<V: Value>(
    m: usize,
    mut f: impl FnMut(f64) -> Result<V, QuadError>,
    evaluations: &mut u64,
) -> Result<V, QuadError> {
    let sum = running_sum::<RULE_STRAIGHT_UP_TO, V>(RULES[m], &mut f)?;
    *evaluations = m as u64;
    if sum.all_finite() {
        return Ok(sum);
    }
    *evaluations += m as u64;
    again(m, f)
}

/// `sum_i w_i f(u_i)` over `pairs` (`[u_i, w_i]`), one running sum in
/// their order, unchecked: within `gamma_(k-1) sum |w f|` of the terms'
/// exact sum where it is finite, `k = pairs.len()` (module doc). Up to
/// `UPTO` pairs (at most [`STRAIGHT_UP_TO`]), one arm an order
/// ([`straight_sum`]); above, a loop over chunks of [`CHUNK`] pairs
/// ([`chunked_sum`]; `benches/README.md`, `gl_small`, fifth, sixth and
/// eleventh sessions). Both add the same terms in the same order, so the
/// arms change no bit of a value.
#[inline(always)]
pub(super) fn running_sum<const UPTO: usize, V: Value>(
    pairs: &[[f64; 2]],
    f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    // A jump on the length, then that order's calls one after another,
    // with no loop counter between them. Each arm's conversion holds by
    // the arm's own length (its `Err` is never taken).
    macro_rules! by_order {
        ($($k:literal)*) => {{
            const _: () = assert!(
                [$($k),*].len() == STRAIGHT_UP_TO && [$($k),*][STRAIGHT_UP_TO - 1] == STRAIGHT_UP_TO,
                "one arm for each order 1..=STRAIGHT_UP_TO"
            );
            const { assert!(UPTO <= STRAIGHT_UP_TO) };
            match pairs.len() {
                $($k if $k <= UPTO => match <&[[f64; 2]; $k]>::try_from(pairs) {
                    Ok(order) => straight_sum(order, f),
                    Err(_) => chunked_sum(pairs, f),
                },)*
                _ => chunked_sum(pairs, f),
            }
        }};
    }
    by_order!(1 2 3 4 5 6 7 8 9 10)
}

/// Most orders [`running_sum`] sums by [`straight_sum`]. Each order's arm
/// is compiled with the integrand inlined at each of its calls where the
/// compiler inlines it (a large integrand may be called instead):
/// `k (k + 1) / 2` copies per integrand and call site for arms up to `k`
/// (and [`chunked_sum`]'s own beside them), and nested integrals multiply
/// them. Only the order in use runs.
const STRAIGHT_UP_TO: usize = FIXED_STRAIGHT_UP_TO;

/// [`running_sum`]'s arms on `FixedOrder`: 55 copies of the integrand,
/// where 8 arms left n = 10 about 1% slower than bilby (`benches/README.md`,
/// eleventh session).
pub(super) const FIXED_STRAIGHT_UP_TO: usize = 10;

/// [`running_sum`]'s arms on the rule's tabulated line: 36 copies (the
/// command-line binary grew by 1.8%, `benches/README.md`, sixth session).
/// Arms to 10 there made the rule 5 to 10% slower at n = 5, 10 and 20
/// (eleventh session): the compiler inlined less of its caller.
const RULE_STRAIGHT_UP_TO: usize = 8;

/// [`running_sum`] over an order known when compiled: a loop of `K`
/// steps, which an optimized build unrolls into `K` calls in a row.
#[inline(always)]
fn straight_sum<const K: usize, V: Value>(
    pairs: &[[f64; 2]; K],
    mut f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    let mut sum = V::zero();
    for &[u, w] in pairs {
        sum = sum.zip(f(u)?, |s, y| s + y * w);
    }
    Ok(sum)
}

/// Pairs [`chunked_sum`] takes at a time. Against a loop by index over the
/// pairs, the rule at n = 20 and 50 went from 1.0094 and 0.9836 times
/// bilby to 0.9828 and 0.9739, `FixedOrder` at n = 20 from 1.0033 to
/// 0.9963 (`benches/README.md`, eleventh session).
const CHUNK: usize = 4;

/// [`running_sum`] above its straight arms, [`CHUNK`] terms at a time,
/// each chunk's calls one after another (as in [`straight_sum`]), then the
/// remaining terms in their order.
#[inline(always)]
fn chunked_sum<V: Value>(
    pairs: &[[f64; 2]],
    mut f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    let mut sum = V::zero();
    let (chunks, rest) = pairs.as_chunks::<CHUNK>();
    for chunk in chunks {
        for &[u, w] in chunk {
            sum = sum.zip(f(u)?, |s, y| s + y * w);
        }
    }
    for &[u, w] in rest {
        sum = sum.zip(f(u)?, |s, y| s + y * w);
    }
    Ok(sum)
}

/// [`tabulated_value`]'s way out, off the line of the sum.
#[cold]
#[inline(never)]
fn again<V: Value>(
    m: usize,
    mut f: impl FnMut(f64) -> Result<V, QuadError>,
) -> Result<V, QuadError> {
    product_value([&*unit_rule(m)?], |u: [f64; 1]| f(u[0]))
}

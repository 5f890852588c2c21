//! Iteration-free Gauss–Legendre nodes and weights for large `n`, after
//! I. Bogaert, "Iteration-free computation of Gauss–Legendre quadrature nodes and
//! weights", SIAM J. Sci. Comput. 36(3), A1008–A1026 (2014).
//!
//! With `v = 1/(n + 1/2)`, `alpha = v j_{0,k}` (the k-th zero of `J_0` scaled),
//! `u = cot(alpha)`, the k-th node `x_k = cos(theta_k)` (counted from `x = +1`) is
//!
//! `theta_k = alpha + v^2 F1(alpha) + v^4 F2(alpha) + v^6 F3(alpha) + O(v^8)` with
//!
//! - `F1 = (u - 1/alpha) / 8`
//! - `F2 = (6 (1 + u^2)/alpha + 25/alpha^3 - u (31 u^2 + 33)) / 384`
//! - `F3 = u (2595 + 6350 u^2 + 3779 u^4)/15360 - 1073/(5120 alpha^5)
//!        + (1 + u^2) (-(31 u^2 + 11)/(1024 alpha) + u/(512 alpha^2) - 25/(3072 alpha^3))`,
//!
//! and the weight is `w_k = 2 / (J_1(j_{0,k})^2 (alpha / sin alpha) (1/v^2 + W1 + W2 v^2 + W3 v^4))`,
//! evaluated as `(pi v) sin(alpha) / (p_k (1 + v^2 (W1 + W2 v^2 + W3 v^4)))` with
//! `p_k = (pi/2) j_{0,k} J_1(j_{0,k})^2`
//! with
//!
//! - `W1 = (u alpha + alpha^2 - 1) / (8 alpha^2)`
//! - `W2 = (81 - 31 u alpha - 3 (1 - 2 u^2) alpha^2 + 6 u alpha^3 - (27 + 84 u^2 + 56 u^4) alpha^4) / (384 alpha^4)`
//! - `W3 = (187/96 u^4 + 295/256 u^2 + 151/160 u^6 + 153/1024) + (-119/768 u^2 - 35/384 u^4 - 65/1024) u/alpha
//!        + (5/512 + 7/384 u^4 + 15/512 u^2)/alpha^2 + (u^2/512 - 13/1536) u/alpha^3
//!        + (-7/384 u^2 + 53/3072)/alpha^4 + 3749/15360 u/alpha^5 - 1125/1024/alpha^6`.
//!
//! The expansion is uniform in k, so one formula serves interior and boundary
//! nodes. Terms are dropped where they fall below a tenth of an ulp for every k
//! (the thresholds are stated at the constants). The truncation error
//! `O(v^8)` is below double precision for n > 100; smaller n are tabulated
//! (`small_table`).
//!
//! Only one `sin_cos` is evaluated per node (an inline polynomial, module `trig`):
//! `cos theta` and `1 - cos theta` follow from `sin alpha`, `cos alpha` and the
//! small `delta = theta - alpha` by the angle-addition formula, without
//! cancellation.

use crate::error::QuadError;
use super::bessel::alpha_and_weight_factor;
use super::lanes::Lanes;

/// From this n on, only the `v^2` terms (F1, W1) are kept: the `v^4` terms are
/// below `1e-20 |F2|, 1e-20 |W2|` (|F2|, |W2| < 0.05 for every node).
pub const FIRST_ORDER_FROM: usize = 100_000;
/// From this n on, the `v^6` terms (F3, W3) are dropped: below `1.4e-21 |F3|`.
pub const SECOND_ORDER_FROM: usize = 3_000;

/// How many terms of the expansion an order n needs (1, 2 or 3).
pub fn terms_for(n: usize) -> usize {
    if n >= FIRST_ORDER_FROM {
        1
    } else if n >= SECOND_ORDER_FROM {
        2
    } else {
        3
    }
}

/// One node of the upper half: `x = cos theta`, `y = 1 - x` (accurate even when
/// `x` rounds to 1), and the weight.
/// `T` is `f64` for one node or [`Lanes`] for several.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfNode<T = f64> {
    /// The node `x_k = cos(theta_k)`.
    pub x: T,
    /// `1 - x_k`, computed without cancellation.
    pub one_minus_x: T,
    /// The weight `w_k`.
    pub weight: T,
}

/// The k-th node counted from `x = +1` (k in 1..=ceil(n/2)) of the n-point
/// rule; any other `n` or `k` is an error (`node(0, 0)` gave x = -3.4e62).
pub fn node(n: usize, k: usize) -> Result<HalfNode, QuadError> {
    check_node(n, k)?;
    Ok(node_unchecked(n, k))
}

/// `n >= 1`, at most [`crate::quadrature::MAX_BUDGET`], and `1 <= k <=
/// ceil(n/2)`.
pub(crate) fn check_node(n: usize, k: usize) -> Result<(), QuadError> {
    if n == 0 || n > crate::quadrature::MAX_BUDGET {
        return Err(QuadError::invalid("n", n, "an order in 1..=2^40"));
    }
    if k == 0 || k > n.div_ceil(2) {
        return Err(QuadError::invalid(
            "k",
            k,
            format!("a node index in 1..={} (from x = +1, half of the rule)", n.div_ceil(2)),
        ));
    }
    Ok(())
}

/// [`node`] for `n`, `k` already checked.
pub(crate) fn node_unchecked(n: usize, k: usize) -> HalfNode {
    let (a, a_lo, p) = alpha_and_weight_factor(k, n);
    let (a, a_lo, p) = (Lanes([a]), Lanes([a_lo]), Lanes([p]));
    let node = match terms_for(n) {
        1 => node_from::<1, 1>(n, a, a_lo, p),
        2 => node_from::<1, 2>(n, a, a_lo, p),
        _ => node_from::<1, 3>(n, a, a_lo, p),
    };
    HalfNode {
        x: node.x.0[0],
        one_minus_x: node.one_minus_x.0[0],
        weight: node.weight.0[0],
    }
}

/// The node and weight for `alpha = j_{0,k} / (n + 1/2)` (as `alpha + alpha_lo`)
/// and `p - 1` for the weight factor `p = (pi/2) j_{0,k} J_1(j_{0,k})^2`
/// ([`super::bessel`]),
/// keeping
/// `TERMS` terms of each expansion, for `L` nodes in lock step. Straight-line
/// code without branches.
#[inline(always)]
pub fn node_from<const L: usize, const TERMS: usize>(
    n: usize,
    alpha: Lanes<L>,
    alpha_lo: Lanes<L>,
    weight_factor_minus_one: Lanes<L>,
) -> HalfNode<Lanes<L>> {
    let v = 1.0 / (n as f64 + 0.5);
    let v2 = v * v;
    let (s, c) = super::trig::sin_cos(alpha, alpha_lo);
    // One division for both 1/alpha and cot(alpha) = c / s.
    let r = Lanes::splat(1.0) / (alpha * s);
    let ia = s * r;
    let u = c * (alpha * r);
    let u2 = u * u;

    // Node angle: theta = alpha + delta.
    let f1 = (u - ia) * 0.125;
    const INV_384: f64 = 1.0 / 384.0;
    let mut delta_over_v2 = f1;
    if TERMS >= 2 {
        let ia3 = ia * ia * ia;
        let f2 = (6.0 * (1.0 + u2) * ia + 25.0 * ia3 - u * (31.0 * u2 + 33.0)) * INV_384;
        let mut tail = f2;
        if TERMS >= 3 {
            let ia2 = ia * ia;
            let ia5 = ia3 * ia2;
            let f3 = u * (2595.0 + u2 * (6350.0 + 3779.0 * u2)) / 15360.0 - 1073.0 / 5120.0 * ia5
                + (1.0 + u2)
                    * (-(31.0 * u2 + 11.0) / 1024.0 * ia + u / 512.0 * ia2 - 25.0 / 3072.0 * ia3);
            tail = tail + v2 * f3;
        }
        delta_over_v2 = delta_over_v2 + v2 * tail;
    }
    let delta = v2 * delta_over_v2;

    // cos(alpha + delta) and 1 - cos(alpha + delta) without cancellation:
    // 1 - cos(alpha) = s^2/(1 + c); cos(alpha) - cos(theta) = c (1 - cos delta) + s sin delta.
    let d2 = delta * delta;
    let one_minus_cos_delta = 0.5 * d2 * (1.0 - d2 / 12.0);
    let sin_delta = delta * (1.0 - d2 / 6.0);
    let drop = c * one_minus_cos_delta + s * sin_delta;
    let x = c - drop;
    let one_minus_x = s * s / (1.0 + c) + drop;

    // Weight.
    let ua = u * alpha;
    let a2 = alpha * alpha;
    let w1 = (ua + a2 - 1.0) * (0.125 * ia * ia);
    let mut correction = w1;
    if TERMS >= 2 {
        let a4 = a2 * a2;
        let w2 = (81.0 - 31.0 * ua - 3.0 * (1.0 - 2.0 * u2) * a2 + 6.0 * ua * a2
            - (27.0 + u2 * (84.0 + 56.0 * u2)) * a4)
            * (INV_384 * (ia * ia) * (ia * ia));
        let mut tail = w2;
        if TERMS >= 3 {
            let u4 = u2 * u2;
            let w3 =
                (187.0 / 96.0 * u4 + 295.0 / 256.0 * u2 + 151.0 / 160.0 * u4 * u2 + 153.0 / 1024.0)
                    + (-119.0 / 768.0 * u2 - 35.0 / 384.0 * u4 - 65.0 / 1024.0) * u * ia
                    + (5.0 / 512.0 + 7.0 / 384.0 * u4 + 15.0 / 512.0 * u2) * ia * ia
                    + (u2 / 512.0 - 13.0 / 1536.0) * u * ia * ia * ia
                    + (-7.0 / 384.0 * u2 + 53.0 / 3072.0) * (ia * ia) * (ia * ia)
                    + 3749.0 / 15360.0 * u * (ia * ia) * (ia * ia) * ia
                    - 1125.0 / 1024.0 * (ia * ia * ia) * (ia * ia * ia);
            tail = tail + v2 * w3;
        }
        correction = correction + v2 * tail;
    }
    // w = 2 v^2 sin(alpha) / (J1^2 alpha (1 + v^2 (W1 + ...)))
    //   = (pi v) sin(alpha) / (p (1 + v^2 (W1 + ...)))   with alpha = v j, p = (pi/2) j J1^2,
    // which spends fewer roundings than the first form.
    // The denominator p (1 + v^2 W) = 1 + [(p - 1) + v^2 W (1 + (p - 1))] is
    // rounded once, after the small parts are summed.
    let pi_v = std::f64::consts::PI / (n as f64 + 0.5);
    let pm1 = weight_factor_minus_one;
    let vw = v2 * correction;
    let weight = s * pi_v / ((pm1 + vw + pm1 * vw) + 1.0);
    HalfNode {
        x,
        one_minus_x,
        weight,
    }
}

//! Gauss–Legendre nodes for small `n` by Newton's method on the three-term
//! recurrence, finished in double-double arithmetic.
//!
//! `P_0 = 1`, `P_1 = x`, `(j + 1) P_{j+1} = (2j + 1) x P_j - j P_{j-1}`, and the
//! scaled derivative `S = (1 - x^2) P_n' = n (P_{n-1} - x P_n)`. The weight is
//! `w = 2 / ((1 - x^2) P_n'^2) = 2 (1 - x^2) / S^2`.
//!
//! In f64 the recurrence loses up to ~n ulps of `P_{n-1}(x_k)`, which go
//! straight into the weight (10 ulps at n = 100), and near `x = +-1` the
//! rounding of `x` itself moves `1 - x^2`. So Newton runs in f64 from the
//! asymptotic start and one more step runs in double-double (~32 digits), where
//! the node, `1 - x` and the weight are formed before rounding once to f64.
//! Each evaluation costs O(n); the rule O(n^2): well under a millisecond for the
//! n <= 100 this serves.

use super::bogaert::HalfNode;
use super::double_double::DD;

/// `(P_n(x), S(x))` by the three-term recurrence in f64.
#[inline]
fn eval_f64(n: usize, x: f64) -> (f64, f64) {
    let (mut p_prev, mut p) = (1.0, x);
    for j in 1..n {
        let jf = j as f64;
        let next = ((2.0 * jf + 1.0) * x * p - jf * p_prev) / (jf + 1.0);
        p_prev = p;
        p = next;
    }
    (p, n as f64 * (p_prev - x * p))
}

/// `(P_n(x), S(x))` by the three-term recurrence in double-double.
fn eval_dd(n: usize, x: DD) -> (DD, DD) {
    let (mut p_prev, mut p) = (DD::from(1.0), x);
    for j in 1..n {
        let jf = j as f64;
        let next = x
            .mul(p)
            .mul_f(2.0 * jf + 1.0)
            .sub(p_prev.mul_f(jf))
            .div_f(jf + 1.0);
        p_prev = p;
        p = next;
    }
    (p, p_prev.sub(x.mul(p)).mul_f(n as f64))
}

/// The k-th node from `x = +1` of the n-point rule, polished by Newton's
/// method from `start`; `n` and `k` out of range are an error.
pub fn node(n: usize, k: usize, start: HalfNode) -> Result<HalfNode, crate::error::QuadError> {
    super::bogaert::check_node(n, k)?;
    Ok(node_unchecked(n, k, start))
}

/// [`node`] for `n`, `k` already checked.
pub(crate) fn node_unchecked(n: usize, k: usize, start: HalfNode) -> HalfNode {
    let one = DD::from(1.0);
    // The middle node of an odd rule is exactly zero.
    let x = if 2 * k == n + 1 {
        DD::from(0.0)
    } else {
        // Newton in f64: x <- x - P (1 - x^2) / S, to the rounding level.
        let mut x = start.x;
        for _ in 0..10 {
            let (p, s) = eval_f64(n, x);
            let dx = p * (1.0 - x) * (1.0 + x) / s;
            x -= dx;
            if dx.abs() <= 1e-16 * x.abs() {
                break;
            }
        }
        // One step in double-double squares the f64 error (~1e-16 relative
        // to 1 - x at worst 1e-13) to below 1e-26.
        let x = DD::from(x);
        let (p, s) = eval_dd(n, x);
        let one_minus_x2 = one.sub(x.mul(x));
        x.sub(p.mul(one_minus_x2).div(s))
    };
    let (_, s) = eval_dd(n, x);
    let one_minus_x = one.sub(x);
    let one_minus_x2 = one.sub(x.mul(x));
    let weight = one_minus_x2.mul_f(2.0).div(s.mul(s));
    HalfNode {
        x: x.round(),
        one_minus_x: one_minus_x.round(),
        weight: weight.round(),
    }
}

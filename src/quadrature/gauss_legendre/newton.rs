//! Gauss–Legendre nodes for small `n` by Newton's method on the three-term
//! recurrence, started from the asymptotic nodes.
//!
//! `P_0 = 1`, `P_1 = x`, `(j + 1) P_{j+1} = (2j + 1) x P_j - j P_{j-1}`, and the
//! scaled derivative `S = (1 - x^2) P_n' = n (P_{n-1} - x P_n)`, which is
//! stationary at a zero of `P_n` (`S' = -n (n+1) P_n`), so rounding of the node
//! does not reach the weight `w = 2 (1 - x^2) / S^2`. Each evaluation costs O(n),
//! the rule O(n^2): cheap for the n <= 100 this serves.
//!
//! Nodes with `x >= 1/2` are found in the variable `y = 1 - x` with Reinsch's
//! form of the recurrence for the differences `D_j = P_j - P_{j-1}`:
//! `D_{j+1} = (j D_j - (2j + 1) y P_j) / (j + 1)`, `P_{j+1} = P_j + D_{j+1}`.
//! Near `x = 1` every term is small, so `P_n` keeps its accuracy relative to the
//! tiny `1 - x`, and the weight, which is sensitive to `1 - x^2`, comes out to a
//! few ulps.

use super::bogaert::HalfNode;

/// `(P_n(x), S(x))` by the three-term recurrence in `x`.
#[inline]
fn eval_in_x(n: usize, x: f64) -> (f64, f64) {
    let (mut p_prev, mut p) = (1.0, x);
    for j in 1..n {
        let jf = j as f64;
        let next = ((2.0 * jf + 1.0) * x * p - jf * p_prev) / (jf + 1.0);
        p_prev = p;
        p = next;
    }
    (p, n as f64 * (p_prev - x * p))
}

/// `(P_n(1 - y), S(1 - y))` by Reinsch's difference recurrence in `y`.
#[inline]
fn eval_in_y(n: usize, y: f64) -> (f64, f64) {
    // P_1 = 1 - y, D_1 = P_1 - P_0 = -y.
    let (mut p, mut d) = (1.0 - y, -y);
    for j in 1..n {
        let jf = j as f64;
        d = (jf * d - (2.0 * jf + 1.0) * y * p) / (jf + 1.0);
        p += d;
    }
    // S = n (P_{n-1} - x P_n) = n (y P_n - D_n).
    (p, n as f64 * (y * p - d))
}

/// The k-th node from `x = +1` of the n-point rule, polished by Newton's method.
pub fn node(n: usize, k: usize, start: HalfNode) -> HalfNode {
    // The middle node of an odd rule is exactly zero.
    if 2 * k == n + 1 {
        let (_, s) = eval_in_x(n, 0.0);
        return HalfNode {
            x: 0.0,
            one_minus_x: 1.0,
            weight: 2.0 / (s * s),
        };
    }
    if start.x >= 0.5 {
        // Newton in y: dP/dy = -P', so y <- y + P (1 - x^2) / S.
        let mut y = start.one_minus_x;
        for _ in 0..10 {
            let (p, s) = eval_in_y(n, y);
            let dy = p * y * (2.0 - y) / s;
            y += dy;
            if dy.abs() <= 1e-17 * y {
                break;
            }
        }
        let (p, s) = eval_in_y(n, y);
        y += p * y * (2.0 - y) / s;
        return HalfNode {
            x: 1.0 - y,
            one_minus_x: y,
            weight: 2.0 * y * (2.0 - y) / (s * s),
        };
    }
    // Newton in x: x <- x - P (1 - x^2) / S.
    let mut x = start.x;
    for _ in 0..10 {
        let (p, s) = eval_in_x(n, x);
        let dx = p * (1.0 - x) * (1.0 + x) / s;
        x -= dx;
        if dx.abs() <= 1e-17 * x.abs() {
            break;
        }
    }
    let (_, s) = eval_in_x(n, x);
    let one_minus_x2 = (1.0 - x) * (1.0 + x);
    HalfNode {
        x,
        one_minus_x: 1.0 - x,
        weight: 2.0 * one_minus_x2 / (s * s),
    }
}

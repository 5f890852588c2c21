//! Gauss–Legendre quadrature of any order, n = 1 to 10^8.
//!
//! `int_{-1}^{1} f(x) dx ~ sum_k w_k f(x_k)` with `x_k` the zeros of the Legendre
//! polynomial `P_n` and `w_k = 2 / ((1 - x_k^2) P_n'(x_k)^2)`; exact for
//! polynomials of degree `2n - 1`.
//!
//! - n <= 100: Newton's method on the three-term recurrence ([`newton`]), O(n^2).
//! - n > 100: Bogaert's iteration-free asymptotic expansion ([`bogaert`]), O(n),
//!   in parallel over both cores for large n.
//!
//! Both are accurate to a few ulps (tested against 40-digit tables). Nodes are
//! computed from their angle `theta_k`, so `1 - |x_k|` is available to full
//! relative precision even where `x_k` rounds to `+-1`; the unit-interval rule
//! uses it to keep nodes near 0 accurate (near-singular integrands need that).
//! Unit-interval rules are cached per n.

mod bessel;
pub mod bogaert;
pub mod newton;

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use rayon::prelude::*;

use super::nodes::{UnitNodes, product_sum};
use super::{Rule, per_axis};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;
use bogaert::HalfNode;

/// Largest order accepted (the tables take 24 bytes a node).
pub const MAX_ORDER: usize = 100_000_000;
/// Orders up to this use Newton's method; above it, Bogaert's expansion.
pub const NEWTON_MAX_ORDER: usize = 100;
/// Below this order the table is built on one thread.
const PARALLEL_FROM: usize = 1 << 15;

/// The n-point Gauss–Legendre rule on `[-1, 1]`, nodes ascending.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Nodes `x_i`, ascending.
    pub x: Vec<f64>,
    /// Weights `w_i`, summing to 2.
    pub w: Vec<f64>,
    /// `1 - |x_i|`, to full relative precision.
    pub one_minus_abs_x: Vec<f64>,
}

/// Checks an order n.
pub fn check_order(n: usize) -> Result<usize, QuadError> {
    if (1..=MAX_ORDER).contains(&n) {
        Ok(n)
    } else {
        Err(QuadError::invalid(
            "n",
            n,
            format!("a Gauss–Legendre order in 1..={MAX_ORDER}"),
        ))
    }
}

/// The k-th node from `x = +1` (k in 1..=ceil(n/2)).
fn half_node(n: usize, k: usize) -> HalfNode {
    let mut node = bogaert::node(n, k);
    if n <= NEWTON_MAX_ORDER {
        node = newton::node(n, k, node);
    } else if 2 * k == n + 1 {
        // The middle node of an odd rule is exactly zero.
        node.x = 0.0;
        node.one_minus_x = 1.0;
    }
    node
}

/// Computes the n-point rule on `[-1, 1]` (not cached: see [`unit_nodes`]).
pub fn table(n: usize) -> Result<Table, QuadError> {
    check_order(n)?;
    let lower = n / 2; // nodes with x < 0; the same number with x > 0
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let mut y = vec![0.0; n];

    // Fill the negative half (ascending: k = 1 is the most negative) and its
    // mirror image in the positive half in one pass, chunk by chunk.
    {
        let (x_lo, x_hi) = x.split_at_mut(n - lower);
        let (w_lo, w_hi) = w.split_at_mut(n - lower);
        let (y_lo, y_hi) = y.split_at_mut(n - lower);
        let fill = |chunk: usize,
                    (xl, wl, yl): (&mut [f64], &mut [f64], &mut [f64]),
                    (xh, wh, yh): (&mut [f64], &mut [f64], &mut [f64])| {
            let len = xl.len();
            for i in 0..len {
                let node = half_node(n, chunk + i + 1);
                xl[i] = -node.x;
                wl[i] = node.weight;
                yl[i] = node.one_minus_x;
                xh[len - 1 - i] = node.x;
                wh[len - 1 - i] = node.weight;
                yh[len - 1 - i] = node.one_minus_x;
            }
        };
        let (x_lo, x_mid) = x_lo.split_at_mut(lower);
        let (w_lo, w_mid) = w_lo.split_at_mut(lower);
        let (y_lo, y_mid) = y_lo.split_at_mut(lower);
        const CHUNK: usize = 4096;
        if n >= PARALLEL_FROM {
            x_lo.par_chunks_mut(CHUNK)
                .zip(w_lo.par_chunks_mut(CHUNK))
                .zip(y_lo.par_chunks_mut(CHUNK))
                .zip(
                    x_hi.par_rchunks_mut(CHUNK)
                        .zip(w_hi.par_rchunks_mut(CHUNK))
                        .zip(y_hi.par_rchunks_mut(CHUNK)),
                )
                .enumerate()
                .for_each(|(c, (((xl, wl), yl), ((xh, wh), yh)))| {
                    fill(c * CHUNK, (xl, wl, yl), (xh, wh, yh))
                });
        } else {
            fill(0, (x_lo, w_lo, y_lo), (x_hi, w_hi, y_hi));
        }
        // The middle node of an odd rule.
        if let (Some(xm), Some(wm), Some(ym)) =
            (x_mid.first_mut(), w_mid.first_mut(), y_mid.first_mut())
        {
            let node = half_node(n, lower + 1);
            *xm = 0.0;
            *wm = node.weight;
            *ym = 1.0;
        }
    }
    Ok(Table {
        x,
        w,
        one_minus_abs_x: y,
    })
}

/// The n-point rule mapped to `[0, 1]` (`u = (1 + x)/2`, `w/2`), cached per n.
///
/// Nodes in the lower half are `(1 - |x|)/2`, exact to full relative precision
/// however close they come to 0.
pub fn unit_nodes(n: usize) -> Result<Arc<UnitNodes>, QuadError> {
    check_order(n)?;
    static CACHE: OnceLock<Mutex<HashMap<usize, Arc<UnitNodes>>>> = OnceLock::new();
    /// Total nodes kept in the cache before it is emptied (~0.5 GB).
    const CACHE_NODES: usize = 1 << 25;
    let cache = CACHE.get_or_init(Default::default);
    if let Some(hit) = cache.lock().ok().and_then(|c| c.get(&n).cloned()) {
        return Ok(hit);
    }
    let t = table(n)?;
    let lower = n / 2;
    let u = (0..n)
        .map(|i| {
            if i < lower {
                0.5 * t.one_minus_abs_x[i]
            } else {
                0.5 * (1.0 + t.x[i])
            }
        })
        .collect();
    let w = t.w.iter().map(|w| 0.5 * w).collect();
    let nodes = Arc::new(UnitNodes {
        u,
        w,
        companion: None,
    });
    if let Ok(mut c) = cache.lock() {
        let cached: usize = c.values().map(|v| v.len()).sum();
        if cached + n > CACHE_NODES {
            c.clear();
        }
        c.insert(n, nodes.clone());
    }
    Ok(nodes)
}

/// Gauss–Legendre product rule on `[0, 1]^D`.
///
/// A budget of n evaluations gives `m = floor(n^(1/D))` nodes per axis. The
/// error estimate is `|Q_m - Q_{m-1}|` (one order lower, which converges more
/// slowly, so the estimate is conservative); it costs `(m-1)^D` extra
/// evaluations and can be switched off with `error_estimate: false`, in which
/// case the error is reported as infinite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GaussLegendre {
    /// Whether to spend `(m-1)^D` evaluations on the error estimate.
    pub error_estimate: bool,
}

impl Default for GaussLegendre {
    fn default() -> Self {
        GaussLegendre {
            error_estimate: true,
        }
    }
}

impl Rule for GaussLegendre {
    fn name(&self) -> &'static str {
        "gauss-legendre"
    }

    fn integrate<const D: usize, V: Value, R: rand::Rng + ?Sized, F: FnMut([f64; D]) -> V>(
        &self,
        n: usize,
        _rng: &mut R,
        mut f: F,
    ) -> Result<Estimate<V>, QuadError> {
        let m = per_axis::<D>(n, 1, "n")?;
        let nodes = unit_nodes(m)?;
        let main = product_sum([nodes.as_ref(); D], &mut f)?;
        let (error, extra) = if self.error_estimate && m >= 2 {
            let lower = unit_nodes(m - 1)?;
            let low = product_sum([lower.as_ref(); D], &mut f)?;
            (
                main.value.zip(low.value, |a, b| (a - b).abs()),
                low.evaluations,
            )
        } else {
            (V::zero().map(|_| f64::INFINITY), 0)
        };
        Ok(Estimate {
            value: main.value,
            error,
            evaluations: main.evaluations + extra,
        })
    }
}

//! Gauss–Legendre quadrature of any order, n = 1 to 10^8.
//!
//! `int_{-1}^{1} f(x) dx ~ sum_k w_k f(x_k)` with `x_k` the zeros of the Legendre
//! polynomial `P_n` and `w_k = 2 / ((1 - x_k^2) P_n'(x_k)^2)`; exact for
//! polynomials of degree `2n - 1`.
//!
//! - n <= 100: compiled-in tables ([`small_table`], generated once by
//!   `scripts/gen_gauss_legendre_table.py` at 60 digits), every value correctly
//!   rounded; tested against Newton's method on the three-term recurrence in
//!   double-double ([`newton`]) and against 40-digit tables.
//! - n > 100: Bogaert's iteration-free asymptotic expansion ([`bogaert`]), O(n),
//!   in parallel over both cores for large n, accurate to a few ulps (tested
//!   against 40-digit values).
//!
//! Nodes are computed from their angle `theta_k`, so `1 - |x_k|` is available to full
//! relative precision even where `x_k` rounds to `+-1`; the unit-interval rule
//! uses it to keep nodes near 0 accurate (near-singular integrands need that).
//! Unit-interval rules are cached per n.

pub mod bessel;
pub mod bogaert;
mod double_double;
pub mod lanes;
pub mod newton;
pub mod small_table;
mod trig;
pub mod unit_table;

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use rayon::prelude::*;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::nodes::{ROUNDING_ULPS, UnitNodes, dominated, product_sum, product_value};
use super::{Rule, integer_root, per_axis};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;
use bogaert::HalfNode;
use lanes::Lanes;

/// Largest order accepted (a table takes 16 bytes a node).
pub const MAX_ORDER: usize = 100_000_000;
/// Orders up to this are read from the compiled-in table; above it,
/// Bogaert's expansion.
pub const TABLE_MAX_ORDER: usize = small_table::MAX_TABULATED;
/// Below this order the table is built on one thread.
const PARALLEL_FROM: usize = 1 << 15;

/// The n-point Gauss–Legendre rule on `[-1, 1]`, nodes ascending.
///
/// One buffer of `2n` values, the nodes and then the weights. For
/// `n <= TABLE_MAX_ORDER` it is borrowed from the compiled-in tables (no
/// allocation, nothing computed); above, it is owned. One allocation, not
/// two: at n = 1e6 glibc gives two 8 MB buffers back to the kernel at every
/// free and faults their pages in again at the next rule (about 4 ms of the
/// 10), while one 16 MB buffer stays below its trim threshold and is reused
/// (up to n of about 2e6: past 32 MB glibc maps and unmaps every rule).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    nodes_then_weights: Cow<'static, [f64]>,
}

impl Table {
    /// The order n.
    pub fn len(&self) -> usize {
        self.nodes_then_weights.len() / 2
    }

    /// Always false: a rule has at least one node.
    pub fn is_empty(&self) -> bool {
        self.nodes_then_weights.is_empty()
    }

    /// Nodes `x_i`, ascending.
    pub fn x(&self) -> &[f64] {
        &self.nodes_then_weights[..self.len()]
    }

    /// Weights `w_i`, summing to 2.
    pub fn w(&self) -> &[f64] {
        &self.nodes_then_weights[self.len()..]
    }

    /// The same rule in a buffer of its own (a copy of a compiled-in rule).
    pub fn into_owned(self) -> Self {
        Self {
            nodes_then_weights: Cow::Owned(self.nodes_then_weights.into_owned()),
        }
    }
}

/// Length of all tabulated rules one after another, nodes then weights,
/// `sum_{n <= 100} 2n`.
const FULL_LEN: usize = TABLE_MAX_ORDER * (TABLE_MAX_ORDER + 1);
/// Every tabulated rule in full, order n at `n (n - 1)` ([`full_rule`]):
/// its n nodes ascending, then its n weights; built at compile time from
/// the half table.
static FULL: [f64; FULL_LEN] = mirrored();

/// The tabulated half rules mirrored into full rules ascending in x
/// ([`mirrored_row`]; the middle row of an odd rule at `i = n/2`); the
/// weights follow the nodes in the same order.
const fn mirrored() -> [f64; FULL_LEN] {
    let mut out = [0.0; FULL_LEN];
    let mut n = 1;
    while n <= TABLE_MAX_ORDER {
        let start = n * (n - 1);
        let mut i = 0;
        while i < n {
            let ([x, _, w], lower) = mirrored_row(n, i);
            out[start + i] = if lower { -x } else { x };
            out[start + n + i] = w;
            i += 1;
        }
        n += 1;
    }
    out
}

/// Entry `i` of the tabulated rule of order `n` ascending in x: its half
/// table row `[x_k, 1 - x_k, w_k]` and whether it is in the lower half
/// (`i < n/2`, row `k = i + 1`, at `-x_k`; else row `k = n - i`).
const fn mirrored_row(n: usize, i: usize) -> ([f64; 3], bool) {
    let lower = i < n / 2;
    let k = if lower { i + 1 } else { n - i };
    (small_table::HALF_NODES[n * n / 4 + k - 1], lower)
}

/// The tabulated rule of order `n <= TABLE_MAX_ORDER` in full (nodes
/// ascending, then weights), starting at `sum_{m<n} 2m = n (n - 1)`.
fn full_rule(n: usize) -> &'static [f64] {
    let start = n * (n - 1);
    &FULL[start..start + 2 * n]
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

/// The k-th node from `x = +1` of the n-node rule; `n` outside
/// `1..=MAX_ORDER` or `k` outside `1..=ceil(n/2)` is an error (`half_node(0,
/// 0)` was NaN, and `k` past the middle gave a node outside `[-1, 1]`).
pub fn half_node(n: usize, k: usize) -> Result<HalfNode, QuadError> {
    let n = check_order(n)?;
    if !(1..=n.div_ceil(2)).contains(&k) {
        return Err(QuadError::invalid(
            "k",
            k,
            format!("a node index in 1..={} for n = {n}", n.div_ceil(2)),
        ));
    }
    Ok(node_unchecked(n, k))
}

/// The tabulated half rule of order `n <= TABLE_MAX_ORDER`: rows
/// `[x_k, 1 - x_k, w_k]`, k = 1..=ceil(n/2) from `x = +1`. The rule of order
/// n starts at row `sum_{m<n} ceil(m/2) = floor(n^2/4)`.
fn tabulated(n: usize) -> &'static [[f64; 3]] {
    let start = n * n / 4;
    &small_table::HALF_NODES[start..start + n.div_ceil(2)]
}

/// [`half_node`] for an `n` and `k` the caller has checked.
fn node_unchecked(n: usize, k: usize) -> HalfNode {
    if n <= TABLE_MAX_ORDER {
        let [x, one_minus_x, weight] = tabulated(n)[k - 1];
        return HalfNode {
            x,
            one_minus_x,
            weight,
        };
    }
    let mut node = bogaert::node_unchecked(n, k);
    if 2 * k == n + 1 {
        // The middle node of an odd rule is exactly zero.
        node.x = 0.0;
        node.one_minus_x = 1.0;
    }
    node
}

/// Fills `nodes` and `weights` (length n) by symmetry from the half nodes:
/// `place(node)` gives the (lower, upper) node values of a mirrored pair, the
/// lower one at index k - 1 and the upper one at n - k. Chunks run in
/// parallel for large n.
fn fill_symmetric(
    n: usize,
    nodes: &mut [f64],
    weights: &mut [f64],
    scale: f64,
    place: impl Fn(&HalfNode) -> (f64, f64) + Sync,
) {
    const CHUNK: usize = 4096;
    let lower = n / 2;
    let (x_lo, x_rest) = nodes.split_at_mut(lower);
    let (w_lo, w_rest) = weights.split_at_mut(lower);
    let (x_mid, x_hi) = x_rest.split_at_mut(n - 2 * lower);
    let (w_mid, w_hi) = w_rest.split_at_mut(n - 2 * lower);
    // Lower chunk c covers k = c*CHUNK + 1 ..; its mirror is the c-th chunk
    // of the upper half counted from the end, filled back to front.
    let fill = |first_k: usize, xl: &mut [f64], wl: &mut [f64], xh: &mut [f64], wh: &mut [f64]| {
        let len = xl.len();
        let mut store = |i: usize, node: HalfNode| {
            let (lo, hi) = place(&node);
            xl[i] = lo;
            xh[len - 1 - i] = hi;
            wl[i] = scale * node.weight;
            wh[len - 1 - i] = scale * node.weight;
        };
        // A small n from the table; a larger one in blocks: McMahon's
        // expansion for the Bessel zeros of the whole block (the tabulated
        // first zeros, k <= 20, put in after), then the expansion per node,
        // each a loop of straight-line per-node code that the compiler
        // vectorises across nodes (packed SIMD); then the block is stored
        // to its mirrored places.
        if n <= TABLE_MAX_ORDER {
            for i in 0..len {
                store(i, node_unchecked(n, first_k + i));
            }
            return;
        }
        macro_rules! bulk {
            ($terms:literal) => {{
                const BLOCK: usize = 64;
                let mut ba = [0.0; BLOCK];
                let mut ba_lo = [0.0; BLOCK];
                let mut bp = [0.0; BLOCK];
                let mut bx = [0.0; BLOCK];
                let mut by = [0.0; BLOCK];
                let mut bw = [0.0; BLOCK];
                let mut i = 0;
                while i < len {
                    let m = (len - i).min(BLOCK);
                    let k0 = first_k + i;
                    for (j, ((a, a_lo), p)) in ba[..m]
                        .iter_mut()
                        .zip(&mut ba_lo[..m])
                        .zip(&mut bp[..m])
                        .enumerate()
                    {
                        let (ka, ka_lo, kp) = bessel::mcmahon(Lanes([(k0 + j) as f64]), n);
                        (*a, *a_lo, *p) = (ka.0[0], ka_lo.0[0], kp.0[0]);
                    }
                    for k in k0..(k0 + m).min(bessel::TABULATED + 1) {
                        let j = k - k0;
                        (ba[j], ba_lo[j], bp[j]) = bessel::alpha_and_weight_factor(k, n);
                    }
                    for j in 0..m {
                        let node = bogaert::node_from::<1, $terms>(
                            n,
                            Lanes([ba[j]]),
                            Lanes([ba_lo[j]]),
                            Lanes([bp[j]]),
                        );
                        bx[j] = node.x.0[0];
                        by[j] = node.one_minus_x.0[0];
                        bw[j] = node.weight.0[0];
                    }
                    for j in 0..m {
                        store(
                            i + j,
                            HalfNode {
                                x: bx[j],
                                one_minus_x: by[j],
                                weight: bw[j],
                            },
                        );
                    }
                    i += m;
                }
            }};
        }
        match bogaert::terms_for(n) {
            1 => bulk!(1),
            2 => bulk!(2),
            _ => bulk!(3),
        }
    };
    if n >= PARALLEL_FROM {
        x_lo.par_chunks_mut(CHUNK)
            .zip(w_lo.par_chunks_mut(CHUNK))
            .zip(x_hi.par_rchunks_mut(CHUNK).zip(w_hi.par_rchunks_mut(CHUNK)))
            .enumerate()
            .for_each(|(c, ((xl, wl), (xh, wh)))| fill(c * CHUNK + 1, xl, wl, xh, wh));
    } else {
        fill(1, x_lo, w_lo, x_hi, w_hi);
    }
    // The middle node of an odd rule.
    if let (Some(xm), Some(wm)) = (x_mid.first_mut(), w_mid.first_mut()) {
        let node = node_unchecked(n, lower + 1);
        *xm = place(&node).1;
        *wm = scale * node.weight;
    }
}

/// Computes the n-point rule on `[-1, 1]` (not cached: see [`unit_nodes`]).
pub fn table(n: usize) -> Result<Table, QuadError> {
    check_order(n)?;
    if n <= TABLE_MAX_ORDER {
        return Ok(Table {
            nodes_then_weights: Cow::Borrowed(full_rule(n)),
        });
    }
    let mut buffer = vec![0.0; 2 * n];
    let (x, w) = buffer.split_at_mut(n);
    fill_symmetric(n, x, w, 1.0, |node| (-node.x, node.x));
    Ok(Table {
        nodes_then_weights: Cow::Owned(buffer),
    })
}

/// The n-point rule mapped to `[0, 1]` (`u = (1 + x)/2`, weights `w/2`),
/// cached per n.
///
/// Nodes in the lower half are `(1 - |x|)/2` from the accurately computed
/// `1 - |x|`, so they keep full relative precision however close to 0 they
/// come (at n = 1e6 the first is 1.4e-12, where `(1 + x)/2` would keep only
/// four digits); near-singular integrands at a segment's start need that.
pub fn unit_nodes(n: usize) -> Result<Arc<UnitNodes>, QuadError> {
    check_order(n)?;
    // A few recent rules per thread in front of the shared cache, so inner
    // loops (nested optical depths, error estimates) do not contend for its lock.
    thread_local! {
        static RECENT: std::cell::RefCell<Vec<(usize, Arc<UnitNodes>)>> =
            const { std::cell::RefCell::new(Vec::new()) };
    }
    const RECENT_RULES: usize = 8;
    /// Only small rules are kept per thread (large ones stay in the shared
    /// cache alone, whose size is bounded).
    const RECENT_MAX_ORDER: usize = 4096;
    if n > RECENT_MAX_ORDER {
        return shared_unit_nodes(n);
    }
    if let Some(hit) = RECENT.with(|r| {
        r.borrow()
            .iter()
            .find(|(m, _)| *m == n)
            .map(|(_, nodes)| nodes.clone())
    }) {
        return Ok(hit);
    }
    let nodes = shared_unit_nodes(n)?;
    RECENT.with(|r| {
        let mut r = r.borrow_mut();
        if r.len() == RECENT_RULES {
            r.remove(0);
        }
        r.push((n, nodes.clone()));
    });
    Ok(nodes)
}

/// The process-wide cache behind [`unit_nodes`].
fn shared_unit_nodes(n: usize) -> Result<Arc<UnitNodes>, QuadError> {
    static CACHE: OnceLock<Mutex<HashMap<usize, Arc<UnitNodes>>>> = OnceLock::new();
    /// Total nodes kept in the cache before it is emptied (~0.5 GB).
    const CACHE_NODES: usize = 1 << 25;
    let cache = CACHE.get_or_init(Default::default);
    if let Some(hit) = cache.lock().ok().and_then(|c| c.get(&n).cloned()) {
        return Ok(hit);
    }
    let nodes = Arc::new(computed_unit_nodes(n));
    if let Ok(mut c) = cache.lock() {
        let cached: usize = c.values().map(|v| v.len()).sum();
        if cached + n > CACHE_NODES {
            c.clear();
        }
        c.insert(n, nodes.clone());
    }
    Ok(nodes)
}

/// The n-point rule mapped to `[0, 1]`, computed ([`unit_nodes`] caches it).
fn computed_unit_nodes(n: usize) -> UnitNodes {
    let mut u = vec![0.0; n];
    let mut w = vec![0.0; n];
    fill_symmetric(n, &mut u, &mut w, 0.5, |node| {
        (0.5 * node.one_minus_x, 0.5 * (1.0 + node.x))
    });
    UnitNodes {
        u,
        w,
        companion: None,
        companion4: None,
        companion8: None,
    }
}

/// A rule of [`unit_nodes`], held as cheaply as its order allows.
pub enum UnitRule {
    /// A tabulated order's (n <= [`TABLE_MAX_ORDER`]): all of them built
    /// once, then borrowed without a lock or a reference count, which cost
    /// a few-node integral about a tenth of its time.
    Tabulated(&'static UnitNodes),
    /// A larger order's, from the cache.
    Cached(Arc<UnitNodes>),
}

impl std::ops::Deref for UnitRule {
    type Target = UnitNodes;

    fn deref(&self) -> &UnitNodes {
        match self {
            UnitRule::Tabulated(nodes) => nodes,
            UnitRule::Cached(nodes) => nodes,
        }
    }
}

/// [`unit_nodes`] as a [`UnitRule`].
#[inline]
pub fn unit_rule(n: usize) -> Result<UnitRule, QuadError> {
    static TABULATED: OnceLock<Vec<UnitNodes>> = OnceLock::new();
    if (1..=TABLE_MAX_ORDER).contains(&n) {
        let rules =
            TABULATED.get_or_init(|| (1..=TABLE_MAX_ORDER).map(computed_unit_nodes).collect());
        return Ok(UnitRule::Tabulated(&rules[n - 1]));
    }
    unit_nodes(n).map(UnitRule::Cached)
}

/// The error of `Q_m` from the last two differences `d2 = Q_m - Q_{m-1}`,
/// `d1 = Q_{m-1} - Q_{m-2}`: with `r = d2/d1` in (0, 1) the remaining
/// differences are taken as a geometric tail, `|Q_inf - Q_m| ~ |d2| r/(1 - r)`,
/// doubled for safety. That is exact for geometric (analytic-integrand)
/// convergence and within a factor `2p/(p+1)` of the truth for algebraic
/// convergence `C m^-p` (where `r = ((m-1)/m)^(p+1)` and a plain `|d2|` would
/// miss by `m/p`). When the differences do not shrink monotonically,
/// `max(|d1|, |d2|)`.
fn tail_estimate(q: f64, q1: f64, q2: f64) -> f64 {
    let (d2, d1) = (q - q1, q1 - q2);
    let r = d2 / d1;
    if r > 0.0 && r < 1.0 {
        2.0 * d2.abs() * r / (1.0 - r)
    } else {
        d1.abs().max(d2.abs())
    }
}

/// Orders from which the error estimate adds the half-order rule to the
/// consecutive ones ([`hybrid_estimate`]); below it, `Q_{m-1}` and `Q_{m-2}`
/// alone (`tail_estimate`), and the estimate is doubted: below 16 the
/// half-order rule has at most 8 nodes and resolves little, and nothing
/// checks the consecutive differences, which agree by chance where a kink
/// or jump lies between nodes (`|x - c|` at 200 random `c`, m = 2..15: 301
/// of 2800 estimates below a tenth of the true error, some exactly 0; with
/// the half order from m = 4 and the tail's consistency check still 48
/// of 6600, so no check at these orders was found that holds). From 16 to 31 the hybrid is pessimistic on
/// smooth integrands its half order does not resolve (cos(20x): estimate
/// 2e4 to 6e4 times the truth, Runge's function 8e1 to 4e3 times), but it is
/// honest at jumps and kinks where the consecutive differences alone were
/// not (unflagged estimates below a tenth of the truth at random jump and
/// kink positions, m = 31 .. 8193: 14 of 8400 with the hybrid from 32, 2
/// with it from 16, 0 once an inconsistent tail also takes `|d1|`).
pub const HYBRID_FROM: usize = 16;


/// The error of `Q_m` (`m >= 16`) from the consecutive orders `m-1, m-2` and
/// the half order `h = ceil(m/2)`: `q = [Q_m, Q_{m-1}, Q_{m-2}, Q_h]`,
/// `magnitude = M = sum |w f|` of `Q_m`. Never doubted.
///
/// With `noise = 128 eps M`, `d2 = Q_m - Q_{m-1}`, `d1 = Q_{m-1} - Q_{m-2}`,
/// `D = |Q_m - Q_h|`:
///
/// - Drowned, `|d1| <= noise` and `|d2| <= noise`: the consecutive differences
///   say nothing. A rule converging algebraically, `Q_k - I ~ C k^-p`, has an
///   error `m/p` times its consecutive difference, so at most about `m` times
///   it: `max(eps M, min(D, m noise))`. A converged rule whose half order is
///   not (a narrow blob on a long segment) gets `m noise`, not `D`; an
///   algebraic error lost in rounding (`ln x` at `m = 65536`) gets `D`,
///   about `(2^p - 1)` times the error.
/// - Clean tail, `r = d2/d1` in (0, 1): the remaining differences are a
///   geometric tail at the rate `rho = max(r, (|d2|/D)^(1/(m-h)))` (the
///   second term, the mean rate per order from `h` to `m`, used only when
///   `D > |d2|`: a rate that is faster now than on average, as where an
///   oscillating error passes through zero, is not trusted), and
///   `E = 2 |d2| rho/(1 - rho)`. For geometric convergence that is exact (up
///   to the factor 2); for algebraic convergence `r = ((m-1)/m)^(p+1)` is the
///   larger rate and `E` is within `2p/(p+1)` of the error. The tail is kept
///   when `r` is consistent with the halving difference, i.e. the decay from
///   `Q_h` to `Q_m` is at least what `r` compounded over a quarter of the
///   orders between them predicts:
///   `((m-h)/4) ln(1/r) <= ln(2D/E)`. Algebraic convergence
///   (`ln(1/r) ~ (p+1)/m`, `D/E ~ (2^p - 1)(p+1)/(2p)`) and geometric
///   convergence (`D/E ~ r^-(m-h)`) pass; a tail faked by an oscillating
///   error (a kink or jump between nodes: small `r`, `D` of the size of the
///   error) does not, and gets `max(E, D, |d1|)`: the half order can agree
///   with `Q_m` by chance where the error oscillates (a kink at 0.2907,
///   `m = 31`: `D = 1.8e-8` against an error of `1.1e-4`, `|d1| = 3.7e-4`).
/// - No pattern (`r` outside (0, 1)): `max(|d1|, |d2|, min(D, m max(|d1|,
///   |d2|, noise)))`, the half-order difference capped as in the drowned
///   case (a symmetric integrand's odd and even orders alternate before they
///   converge; `D` there is the error of an unresolved `Q_h`).
///
/// On a Kahaner-style battery (smooth, endpoint-singular, kinked and
/// discontinuous integrands, 44 random kink and jump positions, 32 to 65537
/// nodes) no estimate above rounding falls below a tenth of the true error.
/// The consecutive orders alone (`tail_estimate`) see algebraic convergence
/// but drown in rounding at large `m` (estimate/true `3e-5` for
/// `int_0^1 sqrt(x)` at `m = 65536`); the halving orders alone are
/// pessimistic by up to `10^14` where `Q_m` has converged and `Q_{m/2}` has
/// not. This costs `(m-1) + (m-2) + h ~ 2.5 m` extra evaluations in one
/// dimension (per axis in `D`: `(m-1)^D + (m-2)^D + h^D`).
pub fn hybrid_estimate(m: usize, q: [f64; 4], magnitude: f64) -> f64 {
    let [q0, q1, q2, qh] = q;
    let (d2, d1, halving) = (q0 - q1, q1 - q2, (q0 - qh).abs());
    let rounding = f64::EPSILON * magnitude;
    let noise = ROUNDING_ULPS * rounding;
    let mf = m as f64;
    if d1.abs() <= noise && d2.abs() <= noise {
        return rounding.max(halving.min(mf * noise));
    }
    let r = d2 / d1;
    if r > 0.0 && r < 1.0 {
        let span = (m - m.div_ceil(2)) as f64;
        let mean = if halving > d2.abs() {
            ((d2.abs() / halving).ln() / span).exp()
        } else {
            0.0
        };
        let rho = r.max(mean);
        let tail = (2.0 * d2.abs() * rho / (1.0 - rho)).max(algebraic(mf, d2, halving));
        let consistent = halving > 0.0 && span / 4.0 * (1.0 / r).ln() <= (2.0 * halving / tail).ln();
        return if consistent {
            tail
        } else {
            tail.max(halving).max(d1.abs())
        };
    }
    let largest = d1.abs().max(d2.abs());
    largest.max(halving.min(mf * largest.max(noise)))
}

/// The error of `Q_m` under algebraic convergence `Q_k - I = C k^-p`, from
/// the halving difference `D = |Q_m - Q_h| = (2^p - 1) |E|` and the
/// consecutive one `|d2| = p |E| / m`: `p` solves `(2^p - 1) / p = D / (m
/// |d2|)` (the left side grows with `p`), and `E = D / (2^p - 1)`; 0 where
/// that order is not algebraic (`p + 1 >= 20`). Geometric convergence at
/// the rate `r`, `m (1 - r) = c`, solves to `p ~ 0.72 c`, and `E` is then
/// within a factor 2 of its geometric tail.
///
/// The order is judged from `D` and `d2`, not from the consecutive ratio
/// `r = d2/d1` (which gated it before: `m (1 - r) >= 20`): rounding in the
/// integrand moves `r` by more than `1/m`. For `(1 - x)^-0.5` at `m = 32769`
/// `r` came out 0.99932 against 0.99994 for `x^-0.5`, `m (1 - r) = 22`, and
/// the geometric tail alone gave 0.096 of the error.
///
/// The tail `2 |d2| r / (1 - r)` rests on `1 - r ~ (p + 1)/m`, so a
/// relative error of `1/m` in `d2` or `d1` moves it by its own size; the
/// integrand's rounding can be that large where a singularity sits at the
/// right end (`(1 - x)^-0.9`: the node nearest 1 holds `1 - x ~ 1e-9` to 8
/// digits, and its term is of order 1): the tail fell to 0.093 of the error
/// at `m = 32768`, where `x^-0.9` at the left end gets 0.333 (`2p/(p+1)`).
/// Here `d2` enters only as a ratio to `D`, and the estimate is the error
/// itself on both ends (0.93 to 1.7 for `(1 - x)^-0.5` and `x^-0.5`).
fn algebraic(m: f64, d2: f64, halving: f64) -> f64 {
    if d2 == 0.0 || halving == 0.0 {
        return 0.0;
    }
    let target = halving / (m * d2.abs());
    let ratio = |p: f64| (p.exp2() - 1.0) / p;
    // (2^p - 1)/p > ln 2 for every p > 0: a smaller target contradicts the
    // algebraic model (a kink or jump, where D and d2 are both of the size of
    // the error, gives about 1/m), and taking it at a tiny p overestimated
    // such errors 1e4-fold.
    let (mut lo, mut hi) = (1e-3f64, 60.0f64);
    if ratio(lo) >= target {
        return 0.0;
    } else if ratio(hi) <= target {
        lo = hi;
    }
    while hi - lo > 1e-9 * hi {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    if hi + 1.0 >= 20.0 {
        return 0.0;
    }
    halving / (hi.exp2() - 1.0)
}

/// Gauss–Legendre product rule on `[0, 1]^D`.
///
/// A budget of n evaluations gives `m = floor(n^(1/D))` nodes per axis. The
/// error estimate compares `Q_m` with `Q_{m-1}` and `Q_{m-2}` per axis and,
/// for `m >= 16`, with `Q_{ceil(m/2)}` ([`hybrid_estimate`]: the tail of the
/// consecutive differences, checked against the halving difference, which
/// sees algebraic convergence where the consecutive differences drown in
/// rounding); below 16 the consecutive orders alone (`tail_estimate`). It
/// costs `(m-1)^D + (m-2)^D + ceil(m/2)^D` extra evaluations (about `2.5 m`
/// in one dimension; without the half order below 16) and can be switched
/// off with `error_estimate: false`, in which case the error is reported as
/// infinite. The estimate is doubted below 16 nodes per axis (nothing checks
/// it there) and where one node dominates the sum ([`dominated`]: a feature
/// narrower than the node spacing, which no difference of rules bounds).
///
/// Its sums are compensated but one: without the estimate, one axis of a
/// tabulated order (at most [`TABLE_MAX_ORDER`] nodes) is one running sum,
/// as the peers sum it, within `gamma_(m-1) sum |w f|` of the terms' exact
/// sum ([`unit_table`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GaussLegendre {
    /// Whether to spend `(m-1)^D + (m-2)^D + ceil(m/2)^D` more evaluations
    /// on the error estimate (default true).
    #[serde(default = "yes")]
    pub error_estimate: bool,
}

fn yes() -> bool {
    true
}

impl Default for GaussLegendre {
    fn default() -> Self {
        GaussLegendre {
            error_estimate: true,
        }
    }
}

impl GaussLegendre {
    /// Whether a budget of `n` is one axis of a tabulated order without
    /// the estimate, which [`tabulated_line`] sums.
    #[inline(always)]
    fn is_tabulated_line<const D: usize>(&self, n: usize) -> bool {
        D == 1 && !self.error_estimate && (1..=TABLE_MAX_ORDER).contains(&n)
    }
}

/// [`GaussLegendre`] without its estimate on one axis of a tabulated
/// order `m` ([`unit_table::tabulated_value`]).
#[inline(always)]
fn tabulated_line<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
    m: usize,
    mut f: F,
) -> Result<Estimate<V>, QuadError> {
    let mut evaluations = 0;
    let value = unit_table::tabulated_value(
        m,
        #[inline(always)]
        move |u| {
            let mut p = [0.0; D];
            p[0] = u;
            f(p)
        },
        &mut evaluations,
    )?;
    Ok(without_estimate(value, evaluations))
}

/// The rule's value without its estimate: its error unknown, infinite.
#[inline(always)]
fn without_estimate<V: Value>(value: V, evaluations: u64) -> Estimate<V> {
    Estimate::deterministic(value, V::zero().map(|_| f64::INFINITY), evaluations)
}

impl Rule for GaussLegendre {
    fn name(&self) -> &'static str {
        "gauss-legendre"
    }

    fn about(&self) -> &'static str {
        "Gauss–Legendre of any order 1..=1e8 (product rule in D > 1); error estimate from the tail of Q_m - Q_(m-1), Q_(m-1) - Q_(m-2), checked against Q_m - Q_(m/2) from m = 16"
    }

    /// The m-node table per axis (a node and a weight, 16 bytes a node),
    /// and with the estimate the companion rules' beside it: 56 bytes a
    /// node, from 552 MB of peak resident memory measured at m = 1e7.
    #[inline]
    fn memory(&self, n: usize, dim: usize) -> f64 {
        let per_node = if self.error_estimate { 56.0 } else { 16.0 };
        per_node * integer_root(n, dim) as f64
    }

    /// `m^D` nodes, and for the estimate `(m-1)^D + (m-2)^D` more, and
    /// `ceil(m/2)^D` from 16 nodes per axis.
    fn evaluations(&self, n: usize, dim: usize) -> f64 {
        let m = integer_root(n, dim).max(1) as f64;
        let d = dim.max(1) as i32;
        if !self.error_estimate || m < 2.0 {
            return m.powi(d);
        }
        let half = if m >= HYBRID_FROM as f64 {
            (m / 2.0).ceil().powi(d)
        } else {
            0.0
        };
        m.powi(d) + (m - 1.0).powi(d) + (m - 2.0).max(0.0).powi(d) + half
    }

    /// Unguarded where the estimate is off in one dimension: one sum on
    /// one axis, which [`product_sum`] finds within the f64 range (the
    /// odometer's running sum in two and more dimensions can pass it).
    fn guarded(&self, dim: usize) -> bool {
        self.error_estimate || dim > 1
    }

    /// [`Rule::try_integrate`], which a tabulated order without the
    /// estimate on one axis reaches first: no limit can be met at its
    /// 100 nodes at most, and it is not guarded.
    #[inline]
    fn try_integrate<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        if self.is_tabulated_line::<D>(n) {
            return tabulated_line(n, f);
        }
        beyond_the_table(self, n, rng, f)
    }

    /// Without the estimate, the sum alone: small enough to inline where
    /// it is called. One axis of a tabulated order is summed as the calls
    /// return ([`unit_table`]: one running sum, not compensated), every
    /// other in [`product_value`].
    #[inline]
    fn integrate_unguarded<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        _rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError> {
        if self.is_tabulated_line::<D>(n) {
            return tabulated_line(n, f);
        }
        unguarded_beyond_the_table(self.error_estimate, n, f)
    }
}

/// [`GaussLegendre::try_integrate`] past one tabulated axis without the
/// estimate: the limits, the guard, the rule. Out of line, so that the
/// tabulated line's caller keeps a frame of its own size: inlined, this
/// path's buffers gave it a frame of some 5 KB, probed and aligned at
/// every call.
#[inline(never)]
fn beyond_the_table<
    const D: usize,
    V: Value,
    R: rand::Rng + ?Sized,
    F: FnMut([f64; D]) -> Result<V, QuadError>,
>(
    rule: &GaussLegendre,
    n: usize,
    rng: &mut R,
    f: F,
) -> Result<Estimate<V>, QuadError> {
    super::guard::checked(rule, n, rng, f)
}

/// [`GaussLegendre::integrate_unguarded`] past one tabulated axis without
/// the estimate, out of line as [`beyond_the_table`] is.
#[inline(never)]
fn unguarded_beyond_the_table<
    const D: usize,
    V: Value,
    F: FnMut([f64; D]) -> Result<V, QuadError>,
>(
    error_estimate: bool,
    n: usize,
    f: F,
) -> Result<Estimate<V>, QuadError> {
    crate::quadrature::check_budget(n)?;
    let m = per_axis::<D>(n, 1, "n")?;
    if !error_estimate {
        let value = product_value([&*unit_rule(m)?; D], f)?;
        return Ok(without_estimate(value, (m as u64).pow(D as u32)));
    }
    estimated(m, f)
}

/// [`GaussLegendre`] with its error estimate, `m` nodes per axis.
fn estimated<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
    m: usize,
    mut f: F,
) -> Result<Estimate<V>, QuadError> {
    // The integrand reaches each sum in a closure of its own, which
    // the sum inlines: through `&mut f` it was a call at every node
    // (`<&mut F as FnMut>::call_mut`), and the guard's closure behind
    // it cost the estimate 7 to 10% more instructions (callgrind).
    #[allow(clippy::redundant_closure)]
    let mut sum = |order: usize| {
        product_sum([&*unit_rule(order)?; D], #[inline(always)] |u| f(u))
    };
    let main = sum(m)?;
    let (error, extra) = if m < 2 {
        (V::zero().map(|_| f64::INFINITY), 0)
    } else if m >= HYBRID_FROM {
        // Q at orders m-1, m-2 and ceil(m/2) per axis.
        let mut others = [main; 3];
        for (q, order) in others.iter_mut().zip([m - 1, m - 2, m.div_ceil(2)]) {
            *q = sum(order)?;
        }
        let error = V::from_fn(|c| {
            let [q1, q2, qh] = others.map(|q| q.value.channel(c));
            hybrid_estimate(
                m,
                [main.value.channel(c), q1, q2, qh],
                main.magnitude.channel(c),
            )
        });
        (error, others.iter().map(|q| q.evaluations).sum())
    } else {
        let q1 = sum(m - 1)?;
        if m >= 3 {
            let q2 = sum(m - 2)?;
            let error = V::from_fn(|c| {
                tail_estimate(
                    main.value.channel(c),
                    q1.value.channel(c),
                    q2.value.channel(c),
                )
                .max(f64::EPSILON * main.magnitude.channel(c))
            });
            (error, q1.evaluations + q2.evaluations)
        } else {
            // No estimate below the rounding of the sum itself: where
            // the rules agree exactly (a constant integrand) their
            // difference is 0, while the sum is off by its rounding.
            let error = V::from_fn(|c| {
                (main.value.channel(c) - q1.value.channel(c))
                    .abs()
                    .max(f64::EPSILON * main.magnitude.channel(c))
            });
            (error, q1.evaluations)
        }
    };
    let estimate = Estimate::deterministic(main.value, error, main.evaluations + extra);
    // Below HYBRID_FROM nodes per axis nothing checks the consecutive
    // differences; one node carrying the sum means an unresolved
    // feature ([`dominated`]).
    let doubted = m < HYBRID_FROM || {
        let max_weight = unit_rule(m)?.w.iter().copied().fold(0.0, f64::max);
        dominated(main.largest, main.magnitude, max_weight.powi(D as i32))
    };
    if doubted {
        Ok(estimate.doubted())
    } else {
        Ok(estimate)
    }
}

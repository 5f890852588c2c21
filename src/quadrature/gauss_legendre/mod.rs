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
mod estimate;
mod fixed;
pub mod lanes;
pub mod newton;
pub mod small_table;
mod rule;
mod trig;
pub mod unit_table;

pub use estimate::{HYBRID_FROM, hybrid_estimate};
pub use fixed::FixedOrder;
pub use rule::GaussLegendre;

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use rayon::prelude::*;

use super::nodes::UnitNodes;
use crate::error::QuadError;
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

//! Adaptive cubature on `[0, 1]^D` (`D >= 2`) with the Genz–Malik degree-7
//! rule and its embedded degree-5 rule, h-adaptive as HCubature.jl and
//! Steven G. Johnson's `cubature` do.
//!
//! A. C. Genz and A. A. Malik, "An adaptive algorithm for numerical
//! integration over an n-dimensional rectangular region", J. Comput. Appl.
//! Math. 6 (1980) 295-302. On a box with centre `c` and half-widths `h`,
//! the rule evaluates `f` at
//!
//! | points | where | degree-7 weight | degree-5 weight |
//! |---|---|---|---|
//! | 1 | `c` | `(12824 - 9120 D + 400 D^2) / 19683` | `(729 - 950 D + 50 D^2) / 729` |
//! | `2D` | `c +- l2 h_i e_i` | `980 / 6561` | `245 / 486` |
//! | `2D` | `c +- l3 h_i e_i` | `(1820 - 400 D) / 19683` | `(265 - 100 D) / 1458` |
//! | `2D(D-1)` | `c +- l4 h_i e_i +- l4 h_j e_j` | `200 / 19683` | `25 / 729` |
//! | `2^D` | `c + l5 (+-h_1, ..., +-h_D)` | `6859 / 19683 / 2^D` | 0 |
//!
//! with `l2 = sqrt(9/70)`, `l3 = l4 = sqrt(9/10)`, `l5 = sqrt(9/19)`; the
//! weights sum to 1 and the integral is the box's volume times the weighted
//! sum: `1 + 4D + 2D(D-1) + 2^D` evaluations (17 in two dimensions). The
//! box's error estimate is `vol |G7 - G5|`, the degree-5 rule's own error
//! (pessimistic where the degree-7 rule is much better, honest where both
//! are off), and for a box made by a bisection at least half of what the
//! bisection changed, `|G7(parent) - G7(a) - G7(b)| / 2`: across a kink the
//! two rules of a box can agree by chance, and do so systematically where
//! a straight kink crosses a row of equal boxes at the same place in each
//! (`|x + y - 0.731|` at 32000 evaluations: `|G7 - G5|` summed to 1.1e-7
//! against an error of 2.3e-6); the change from the parent is the parent's
//! error, several times the halves'. On a smooth integrand it is of the
//! degree-7 rule's order, far below `|G7 - G5|`. The box with the largest error is bisected along the axis
//! whose fourth difference `|f(c + l2 h e_i) + f(c - l2 h e_i) - 2 f(c) -
//! (l2/l3)^2 (f(c + l3 h e_i) + f(c - l3 h e_i) - 2 f(c))|` is largest (the
//! widest among equals), until the total error meets the tolerance or the
//! next bisection (two boxes) would pass the budget of `n` evaluations.
//! With both tolerances 0 (the default) the whole budget is used; among
//! equal errors the largest box is bisected first, so the refinement stays
//! even where every estimate so far is zero.
//!
//! A feature no node comes near reads as zero and is not seen (as for every
//! rule); one that a single node carries (most of a box's `sum |w f|`) makes
//! the estimate doubted ([`dominated`]), and so does a final estimate that
//! the run's own history contradicts, or a run of one box (`contradicted`).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::nodes::{dominated, non_finite};
use super::{Dimensions, Rule};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::sum::Compensated;
use crate::value::Value;

/// Adaptive Genz–Malik cubature on `[0, 1]^D`, `2 <= D <= 6`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GenzMalik {
    /// Stop when the estimated error is below this absolute tolerance
    /// (default 0: use the whole budget).
    #[serde(default)]
    pub abs_tol: f64,
    /// Stop when the estimated error is below this fraction of `|Q|` (default 0).
    #[serde(default)]
    pub rel_tol: f64,
}

/// The largest dimension: `2^D` corner points a box, 149 evaluations at 6.
pub const MAX_DIM: usize = 6;

/// `l2 = sqrt(9/70)`.
const L2: f64 = 0.358_568_582_800_318_06;
/// `l3 = l4 = sqrt(9/10)`.
const L3: f64 = 0.948_683_298_050_513_8;
/// `l5 = sqrt(9/19)`.
const L5: f64 = 0.688_247_201_611_685_3;

/// Evaluations of one box in `d` dimensions: `1 + 4d + 2d(d-1) + 2^d`.
pub fn points_per_box(d: usize) -> usize {
    1 + 4 * d + 2 * d * (d - 1) + (1 << d)
}

/// The degree-7 and degree-5 weights of the five point classes in `d`
/// dimensions (the corners' per point), as fractions of the box's volume.
fn weights(d: usize) -> ([f64; 5], [f64; 4]) {
    let n = d as f64;
    (
        [
            (12824.0 - 9120.0 * n + 400.0 * n * n) / 19683.0,
            980.0 / 6561.0,
            (1820.0 - 400.0 * n) / 19683.0,
            200.0 / 19683.0,
            6859.0 / 19683.0 / (1u64 << d) as f64,
        ],
        [
            (729.0 - 950.0 * n + 50.0 * n * n) / 729.0,
            245.0 / 486.0,
            (265.0 - 100.0 * n) / 1458.0,
            25.0 / 729.0,
        ],
    )
}

/// One box of the adaptive partition with its estimates.
#[derive(Debug, Clone, Copy)]
struct Region<const D: usize, V: Value> {
    centre: [f64; D],
    half: [f64; D],
    value: V,
    error: V,
    /// `max_c error_c`: the heap's order.
    priority: f64,
    /// The axis to bisect (largest fourth difference).
    axis: usize,
    /// Whether one node carries the box's sum ([`dominated`]).
    dominated: bool,
}

impl<const D: usize, V: Value> Region<D, V> {
    fn volume(&self) -> f64 {
        self.half.iter().map(|h| 2.0 * h).product()
    }
}

impl<const D: usize, V: Value> PartialEq for Region<D, V> {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl<const D: usize, V: Value> Eq for Region<D, V> {}
impl<const D: usize, V: Value> PartialOrd for Region<D, V> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl<const D: usize, V: Value> Ord for Region<D, V> {
    fn cmp(&self, other: &Self) -> Ordering {
        // Largest error first; among equal errors the largest box, so the
        // partition refines evenly where nothing has been seen yet.
        self.priority
            .total_cmp(&other.priority)
            .then(self.volume().total_cmp(&other.volume()))
    }
}

/// Applies the degree-7/5 pair to the box `centre +- half`.
fn genz_malik_box<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
    centre: [f64; D],
    half: [f64; D],
    f: &mut F,
) -> Result<Region<D, V>, QuadError> {
    let (w7, w5) = weights(D);
    let mut eval = |p: [f64; D]| -> Result<V, QuadError> {
        let y = f(p)?;
        if y.all_finite() { Ok(y) } else { Err(non_finite(&p, &y)) }
    };
    let at = |offsets: &[(usize, f64)]| {
        let mut p = centre;
        for &(i, s) in offsets {
            p[i] += s * half[i];
        }
        p
    };
    // Per class, the sum of f over its points; per axis the two pairs of
    // the fourth difference.
    let mut class = [V::zero(); 5];
    let mut largest = V::zero();
    let mut magnitude = V::zero();
    let mut seen = |y: V, w: f64, sum: &mut V| {
        *sum = sum.zip(y, |s, v| s + v);
        magnitude = magnitude.zip(y, |m, v| m + (w * v).abs());
        largest = largest.zip(y, |m, v| m.max((w * v).abs()));
    };
    let f0 = eval(centre)?;
    seen(f0, w7[0], &mut class[0]);
    let mut fourth = [0.0; D];
    for (i, slot) in fourth.iter_mut().enumerate() {
        let (a, b) = (eval(at(&[(i, L2)]))?, eval(at(&[(i, -L2)]))?);
        let (c, d) = (eval(at(&[(i, L3)]))?, eval(at(&[(i, -L3)]))?);
        for (y, k) in [(a, 1), (b, 1), (c, 2), (d, 2)] {
            seen(y, w7[k], &mut class[k]);
        }
        let ratio = (L2 / L3) * (L2 / L3);
        *slot = (0..V::CHANNELS)
            .map(|ch| {
                let centre = 2.0 * f0.channel(ch);
                let inner = a.channel(ch) + b.channel(ch) - centre;
                let outer = c.channel(ch) + d.channel(ch) - centre;
                (inner - ratio * outer).abs()
            })
            .fold(0.0, f64::max);
    }
    for i in 0..D {
        for j in i + 1..D {
            for (si, sj) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                let y = eval(at(&[(i, si * L3), (j, sj * L3)]))?;
                seen(y, w7[3], &mut class[3]);
            }
        }
    }
    for corner in 0..1usize << D {
        let offsets: [(usize, f64); D] =
            std::array::from_fn(|i| (i, if corner >> i & 1 == 1 { L5 } else { -L5 }));
        let y = eval(at(&offsets))?;
        seen(y, w7[4], &mut class[4]);
    }
    let volume: f64 = half.iter().map(|h| 2.0 * h).product();
    let g7 = V::from_fn(|c| volume * (0..5).map(|k| w7[k] * class[k].channel(c)).sum::<f64>());
    let g5 = V::from_fn(|c| volume * (0..4).map(|k| w5[k] * class[k].channel(c)).sum::<f64>());
    let error = g7.zip(g5, |a, b| (a - b).abs());
    // Bisect along the largest fourth difference; the widest axis among
    // equals (within rounding), so a box that sees nothing is split evenly.
    let top = fourth.iter().copied().fold(0.0, f64::max);
    let axis = (0..D)
        .filter(|&i| fourth[i] >= top * (1.0 - 1e-12))
        .max_by(|&i, &j| half[i].total_cmp(&half[j]))
        .unwrap_or(0);
    let max_weight = w7.iter().map(|w| w.abs()).fold(0.0, f64::max);
    Ok(Region {
        centre,
        half,
        value: g7,
        error,
        priority: error.max_abs(),
        axis,
        dominated: dominated(largest, magnitude, max_weight),
    })
}

/// Whether the run's own history contradicts its final estimate: the
/// totals `(Q_half, E_half)` at the last doubling of the evaluations at or
/// below half the final count against the final `(Q, E)`.
///
/// Were both estimates honest, `|Q - Q_half| <= E + E_half` (plus rounding, `4 sqrt(evaluations)` ulps); a change of
/// more than twice that shows the estimates miss part of the error (a
/// narrow ridge or peak that the boxes found only late and may still not
/// resolve: the product Lorentzian `1/(((x - 0.3)^2 + w^2)((y - 0.3)^2 +
/// w^2))` with `w = 1e-3` gave estimates of 0.024 to 0.057 of the true
/// error at 2047 to 8191 evaluations). A run of one box has no history,
/// and its `|G7 - G5|` is checked by nothing: doubted (one box estimated 0.017 of
/// the error of a peak it missed).
pub(crate) fn contradicted<V: Value>(
    history: &[(u64, V, V)],
    last: &Estimate<V>,
) -> bool {
    let Some(&(_, half_value, half_error)) = history
        .iter()
        .rev()
        .find(|h| 2 * h.0 <= last.evaluations)
    else {
        return true;
    };
    // A change within rounding of the sums (4 sqrt(evaluations) ulps of
    // the values, the boxes' rounding added up) is no contradiction: a
    // constant integrand's estimates differ by that much.
    let ulps = 4.0 * (last.evaluations as f64).sqrt();
    (0..V::CHANNELS).any(|c| {
        let (q, h) = (last.value.channel(c), half_value.channel(c));
        let rounding = ulps * f64::EPSILON * (q.abs() + h.abs());
        (q - h).abs() > last.error.channel(c) + half_error.channel(c) + rounding
    })
}

impl Rule for GenzMalik {
    fn name(&self) -> &'static str {
        "genz-malik"
    }

    fn about(&self) -> &'static str {
        "adaptive Genz-Malik degree-7/5 cubature (D = 2..6), h-adaptive bisection as HCubature; embedded degree-5 estimate"
    }

    /// One box: 17 evaluations in two dimensions.
    fn min_budget(&self, dim: usize) -> usize {
        points_per_box(dim.clamp(2, MAX_DIM))
    }

    fn dimensions(&self) -> Dimensions {
        Dimensions {
            min: 2,
            max: MAX_DIM,
        }
    }

    /// Boxes per axis for a budget: `(n / P)^(1/D)`, `P` evaluations a box.
    fn resolution(&self, n: usize, dim: usize) -> f64 {
        let p = points_per_box(dim.clamp(2, MAX_DIM)) as f64;
        (n as f64 / p).max(1.0).powf(1.0 / dim.max(1) as f64)
    }

    /// The boxes, one per `P` evaluations, `8 (2D + 2 + 2 channels)` bytes
    /// each at most: 8 bytes an evaluation bounds it.
    fn memory(&self, n: usize, _dim: usize) -> f64 {
        8.0 * n as f64
    }

    fn check(&self) -> Result<(), QuadError> {
        super::check_tolerances(self.abs_tol, self.rel_tol)
    }

    fn integrate_unguarded<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        _rng: &mut R,
        mut f: F,
    ) -> Result<Estimate<V>, QuadError> {
        crate::quadrature::check_budget(n)?;
        if !(2..=MAX_DIM).contains(&D) {
            return Err(QuadError::UnsupportedDimension {
                rule: "genz-malik",
                dim: D,
                supported: "2 to 6",
            });
        }
        self.check()?;
        let per_box = points_per_box(D) as u64;
        if (n as u64) < per_box {
            return Err(QuadError::invalid(
                "n",
                n,
                format!("at least {per_box} evaluations (one Genz-Malik box in {D} dimensions)"),
            ));
        }
        let mut heap = BinaryHeap::new();
        heap.push(genz_malik_box([0.5; D], [0.5; D], &mut f)?);
        let mut evaluations = per_box;
        let mut value = heap.peek().map_or(V::zero(), |b| b.value);
        let mut error = heap.peek().map_or(V::zero(), |b| b.error);
        // The running totals each time the evaluations have doubled, for
        // the check of the final estimate against its own history.
        let mut history = vec![(evaluations, value, error)];
        // Bisect the worst box while the budget lasts and the tolerance is
        // unmet; running totals decide when to stop, the reported ones are
        // re-summed (compensated) at the end.
        while evaluations + 2 * per_box <= n as u64 {
            let target = self.abs_tol.max(self.rel_tol * value.max_abs());
            if target > 0.0 && error.max_abs() <= target {
                break;
            }
            let Some(worst) = heap.pop() else { break };
            let (i, h) = (worst.axis, 0.5 * worst.half[worst.axis]);
            let (mut lo, mut hi) = (worst.centre, worst.centre);
            lo[i] -= h;
            hi[i] += h;
            if !(lo[i] < worst.centre[i] && worst.centre[i] < hi[i]) || h <= 0.0 {
                // The box cannot be split further in f64.
                heap.push(worst);
                break;
            }
            let mut half = worst.half;
            half[i] = h;
            let mut a = genz_malik_box(lo, half, &mut f)?;
            let mut b = genz_malik_box(hi, half, &mut f)?;
            // What the bisection changed bounds what the halves may still
            // be off: half of it to each.
            let gap = V::from_fn(|c| {
                0.5 * (worst.value.channel(c) - a.value.channel(c) - b.value.channel(c)).abs()
            });
            for half in [&mut a, &mut b] {
                half.error = half.error.zip(gap, f64::max);
                half.priority = half.error.max_abs();
            }
            value = V::from_fn(|c| {
                value.channel(c) - worst.value.channel(c) + a.value.channel(c) + b.value.channel(c)
            });
            error = V::from_fn(|c| {
                (error.channel(c) - worst.error.channel(c) + a.error.channel(c) + b.error.channel(c))
                    .max(0.0)
            });
            heap.push(a);
            heap.push(b);
            evaluations += 2 * per_box;
            if history.last().is_some_and(|h| evaluations >= 2 * h.0) {
                history.push((evaluations, value, error));
            }
        }
        let (mut value, mut error) = (Compensated::<V>::new(), Compensated::<V>::new());
        for b in heap.iter() {
            value.add(b.value);
            error.add(b.error);
        }
        let estimate = Estimate::deterministic(value.total(), error.total(), evaluations);
        if heap.iter().any(|b| b.dominated) || contradicted(&history, &estimate) {
            Ok(estimate.doubted())
        } else {
            Ok(estimate)
        }
    }
}

//! Adaptive Gauss–Kronrod quadrature, the G7–K15 pair (as QUADPACK's QAG).
//!
//! On each interval the 15-point Kronrod rule `K` (exact to degree 22) reuses
//! the 7 Gauss nodes of `G` (exact to degree 13). The interval's error estimate
//! is QUADPACK's `r min(1, (200 |K - G| / r)^(3/2))`, `r` the Kronrod estimate
//! of `int |f - K/h|`, never below `50 eps` times `int |f|`. The interval with
//! the largest error is bisected until the total error meets the tolerance or
//! the next bisection (two new panels, 30 evaluations) would pass the budget
//! of `n` evaluations: `15 + 30 k <= n`. With both
//! tolerances 0 (the default) the whole budget is used, which is what an
//! error-against-cost sweep wants: pieces are bisected largest error first
//! and, among equal errors (zero where every node reads zero), widest first,
//! so a budget of `n` refines the whole interval to panels of about `15/n`
//! even where every estimate so far is zero.
//!
//! What is and is not detectable: a feature is seen once a node falls on it.
//! A narrow Gaussian `exp(-((x - c)/w)^2)` that no node of the budget's
//! partition comes within a few `w` of reads exactly zero at every node; no
//! rule can tell it from zero, and the error estimate is then 0 against a
//! true error of `w sqrt(pi)` (at `w = 1e-3`, `c = 0.37` the 15-evaluation
//! rule misses it; from about 255 evaluations the even refinement puts nodes
//! on it and bisection follows). A feature that nodes see but do not resolve
//! (one node carrying most of a panel's `int |f|`, [`dominated`]) makes the
//! estimate doubted. The reported error adds, where two
//! panels meet, what a jump hidden in their end gaps could cost (`end_gaps`).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{Dimensions, Rule};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::nodes::{dominated, non_finite};
use crate::sum::Compensated;
use crate::value::Value;

/// Adaptive G7–K15 on `[0, 1]` (1-D only).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GaussKronrod {
    /// Stop when the estimated error is below this absolute tolerance
    /// (default 0: use the whole budget).
    #[serde(default)]
    pub abs_tol: f64,
    /// Stop when the estimated error is below this fraction of `|Q|` (default 0).
    #[serde(default)]
    pub rel_tol: f64,
}

/// Kronrod abscissae on [-1, 1], from the outside in; odd indices are the
/// Gauss nodes; the last is 0 (QUADPACK's `xgk`, verified against a 40-digit
/// table in tests/data/gauss_kronrod_15.json).
#[allow(clippy::excessive_precision)] // QUADPACK's digits, correctly rounded by the compiler
pub const XGK: [f64; 8] = [
    0.991_455_371_120_812_639_206_854_697_526_329,
    0.949_107_912_342_758_524_526_189_684_047_851,
    0.864_864_423_359_769_072_789_712_788_640_926,
    0.741_531_185_599_394_439_863_864_773_280_788,
    0.586_087_235_467_691_130_294_144_845_693_013,
    0.405_845_151_377_397_166_906_606_412_076_961,
    0.207_784_955_007_898_467_600_689_403_773_245,
    0.0,
];
/// Kronrod weights for [`XGK`].
#[allow(clippy::excessive_precision)] // QUADPACK's digits, correctly rounded by the compiler
pub const WGK: [f64; 8] = [
    0.022_935_322_010_529_224_963_732_008_058_970,
    0.063_092_092_629_978_553_290_700_663_189_204,
    0.104_790_010_322_250_183_839_876_322_541_518,
    0.140_653_259_715_525_918_745_189_590_510_238,
    0.169_004_726_639_267_902_826_583_426_598_550,
    0.190_350_578_064_785_409_913_256_402_421_014,
    0.204_432_940_075_298_892_414_161_999_234_649,
    0.209_482_141_084_727_828_012_999_174_891_714,
];
/// Gauss weights for the nodes `XGK[1], XGK[3], XGK[5], XGK[7]`.
#[allow(clippy::excessive_precision)] // QUADPACK's digits, correctly rounded by the compiler
pub const WG: [f64; 4] = [
    0.129_484_966_168_869_693_270_611_432_679_082,
    0.279_705_391_489_276_667_901_467_771_423_780,
    0.381_830_050_505_118_944_950_369_775_488_975,
    0.417_959_183_673_469_387_755_102_040_816_327,
];

/// One interval of the adaptive partition with its estimate.
#[derive(Debug, Clone, Copy)]
struct Piece<V: Value> {
    a: f64,
    b: f64,
    value: V,
    error: V,
    priority: f64,
    /// Whether one node carries the panel's sum ([`dominated`]).
    dominated: bool,
    /// The values at the four nodes nearest `a`, outermost first.
    near_a: [V; 4],
    /// The values at the four nodes nearest `b`, outermost first.
    near_b: [V; 4],
    /// Per channel, whether the node nearest `a` (`b`) holds more than
    /// half of `sum_i |f_i|` over the panel's 15 nodes ([`peak_at_seam`]).
    heavy_a: bool,
    heavy_b: bool,
}

/// Share of a panel's `sum_i |f_i|` (unweighted) above which its outermost
/// node marks a peak at the panel's end ([`peak_at_seam`]).
const SEAM_SHARE: f64 = 0.5;

/// Whether an unresolved peak sits at a seam of the partition: where two
/// panels meet, the outermost node on one side holds more than half of its
/// panel's unweighted `sum |f_i|` and reads more than the other side's
/// outermost node (a local maximum by the seam, not a tail running on into
/// the neighbour). The outermost Kronrod weight is small (0.023 of the
/// panel), so [`dominated`]'s weighted share misses such a peak: a
/// Lorentzian of width 1e-4 at 0.4934, between the two outermost nodes of
/// `[0, 0.5]`, read 3% of its mass at 45 evaluations with an estimate of
/// 1757 against an error of 30500. A smooth integrand never puts half of
/// `sum |f_i|` on one node unless it grows by a factor of 2 or more between
/// the two outermost nodes, 2.1% of the panel apart (`exp(33 x)` on a unit
/// panel), and then only where it falls again across the seam.
fn peak_at_seam<V: Value>(pieces: &mut [&Piece<V>]) -> bool {
    pieces.sort_by(|x, y| x.a.total_cmp(&y.a));
    // At the ends of [0, 1] there is no neighbour: a heavy outermost node
    // there is a peak or a near-singularity the nodes do not resolve (a
    // Lorentzian of width 1e-4 at 0.0105 on one panel: estimate 0.02 of the
    // error; `x^-0.9` holds 0.67 of the sum on its first panel at every
    // budget, an error no panel estimate bounds).
    let first = pieces.first().is_some_and(|p| p.heavy_a);
    let last = pieces.last().is_some_and(|p| p.heavy_b);
    first || last || pieces.windows(2).any(|pair| {
        let (l, r) = (pair[0], pair[1]);
        l.b == r.a
            && (0..V::CHANNELS).any(|c| {
                let (left, right) = (l.near_b[0].channel(c).abs(), r.near_a[0].channel(c).abs());
                (l.heavy_b && left > right) || (r.heavy_a && right > left)
            })
    })
}

/// Weights that extrapolate the polynomial through the `k` outermost nodes
/// of a panel to the panel's end: with the nodes at distances
/// `delta_i = (1 - XGK[i]) / 2` (in panel lengths) from the end, Lagrange's
/// `L_i(0) = prod_{j != i, j < k} delta_j / (delta_j - delta_i)`; unused
/// weights are 0.
fn end_weights(k: usize) -> [f64; 4] {
    let d = [0usize, 1, 2, 3].map(|i| 0.5 * (1.0 - XGK[i]));
    [0usize, 1, 2, 3].map(|i| {
        if i >= k {
            return 0.0;
        }
        (0..k)
            .filter(|&j| j != i)
            .map(|j| d[j] / (d[j] - d[i]))
            .product()
    })
}

/// What the G7–K15 pair cannot see: a jump (or kink) between the outermost
/// node of a panel and its end, a gap of `(1 - XGK[0]) / 2 = 0.43%` of the
/// panel at each end, leaves every node on one side of it, and the panel's
/// estimate says nothing. Where two panels meet at `m`, each side's cubic
/// through its four outermost nodes predicts `f(m)`. For an integrand smooth
/// across `m` they agree to within the extrapolations' own uncertainty (the
/// difference between the cubic and the quadratic prediction, per side); a
/// jump `J` in a gap makes them differ by about `J` (a kink by its slope
/// change times its distance from `m`), and the panels' error by at most
/// that difference times the gap. So where `|p_left(m) - p_right(m)|` is more
/// than ten times the extrapolations' uncertainty, it times the two gaps is
/// added to the error. (The ends of `[0, 1]` have no neighbour to compare
/// with: a jump there stays invisible.)
fn end_gaps<V: Value>(pieces: &mut [&Piece<V>]) -> V {
    pieces.sort_by(|x, y| x.a.total_cmp(&y.a));
    let (cubic, quadratic) = (end_weights(4), end_weights(3));
    let gap = 0.5 * (1.0 - XGK[0]);
    let mut total = Compensated::<V>::new();
    for pair in pieces.windows(2) {
        let (l, r) = (pair[0], pair[1]);
        if l.b != r.a {
            continue;
        }
        let width = gap * ((l.b - l.a) + (r.b - r.a));
        total.add(V::from_fn(|c| {
            let at = |w: &[f64; 4], v: &[V; 4]| (0..4).map(|i| w[i] * v[i].channel(c)).sum::<f64>();
            let (left, right) = (at(&cubic, &l.near_b), at(&cubic, &r.near_a));
            let uncertainty = (left - at(&quadratic, &l.near_b)).abs()
                + (right - at(&quadratic, &r.near_a)).abs();
            let mismatch = (left - right).abs();
            if mismatch > 10.0 * uncertainty {
                mismatch * width
            } else {
                0.0
            }
        }));
    }
    total.total()
}

impl<V: Value> PartialEq for Piece<V> {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl<V: Value> Eq for Piece<V> {}
impl<V: Value> PartialOrd for Piece<V> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl<V: Value> Ord for Piece<V> {
    fn cmp(&self, other: &Self) -> Ordering {
        // Largest error first; among equal errors (zero, where every node
        // reads the same) the widest piece, so the partition refines evenly.
        self.priority
            .total_cmp(&other.priority)
            .then((self.b - self.a).total_cmp(&(other.b - other.a)))
    }
}

/// Applies the G7–K15 pair on `[a, b]`.
fn kronrod_piece<V: Value, F: FnMut([f64; 1]) -> Result<V, QuadError>>(
    a: f64,
    b: f64,
    f: &mut F,
) -> Result<Piece<V>, QuadError> {
    let centre = 0.5 * (a + b);
    let half = 0.5 * (b - a);
    let mut eval = |u: f64| -> Result<V, QuadError> {
        let y = f([u])?;
        if y.all_finite() {
            Ok(y)
        } else {
            Err(non_finite(&[u], &y))
        }
    };
    let mut values = [V::zero(); 15];
    values[7] = eval(centre)?;
    for j in 0..7 {
        let dx = half * XGK[j];
        values[j] = eval(centre - dx)?;
        values[14 - j] = eval(centre + dx)?;
    }
    let weight_k = |i: usize| WGK[i.min(14 - i)];
    let weight_g = |i: usize| {
        let j = i.min(14 - i);
        if j % 2 == 1 { WG[j / 2] } else { 0.0 }
    };
    let kronrod = V::from_fn(|c| (0..15).map(|i| weight_k(i) * values[i].channel(c)).sum());
    let gauss = V::from_fn(|c| (0..15).map(|i| weight_g(i) * values[i].channel(c)).sum());
    let abs = V::from_fn(|c| {
        (0..15)
            .map(|i| weight_k(i) * values[i].channel(c).abs())
            .sum()
    });
    let mean = kronrod.map(|k| 0.5 * k);
    let asc = V::from_fn(|c| {
        (0..15)
            .map(|i| weight_k(i) * (values[i].channel(c) - mean.channel(c)).abs())
            .sum()
    });
    // Whether node i holds more than SEAM_SHARE of sum |f_i|, in a channel.
    let heavy = |i: usize| {
        (0..V::CHANNELS).any(|c| {
            let all: f64 = values.iter().map(|v| v.channel(c).abs()).sum();
            values[i].channel(c).abs() > SEAM_SHARE * all
        })
    };
    // QUADPACK's error estimate, per channel, scaled to [a, b].
    let error = V::from_fn(|c| {
        let diff = ((kronrod.channel(c) - gauss.channel(c)) * half).abs();
        let asc = asc.channel(c) * half.abs();
        let abs = abs.channel(c) * half.abs();
        let mut e = diff;
        if asc != 0.0 && diff != 0.0 {
            e = asc * (200.0 * diff / asc).powf(1.5).min(1.0);
        }
        if abs > f64::MIN_POSITIVE / (50.0 * f64::EPSILON) {
            e = e.max(50.0 * f64::EPSILON * abs);
        }
        e
    });
    Ok(Piece {
        a,
        b,
        value: kronrod.map(|k| k * half),
        error,
        priority: error.max_abs(),
        // An interior node, the panel's largest |f|, that carries its sum:
        // a peak between the nodes. (Largest at an outermost node is a
        // steep tail falling away from a neighbouring panel, which
        // bisection resolves.)
        dominated: (0..V::CHANNELS).any(|c| {
            // The node with the largest |f| and its weighted term.
            let top = (0..15).fold(0, |j, i| {
                if values[i].channel(c).abs() > values[j].channel(c).abs() { i } else { j }
            });
            let largest = (weight_k(top) * values[top].channel(c)).abs();
            let alone = V::from_fn(|k| if k == c { largest } else { 0.0 });
            let total = V::from_fn(|k| if k == c { abs.channel(c) } else { 0.0 });
            top != 0 && top != 14 && dominated(alone, total, 0.5 * WGK[7])
        }),
        near_a: [values[0], values[1], values[2], values[3]],
        near_b: [values[14], values[13], values[12], values[11]],
        heavy_a: heavy(0),
        heavy_b: heavy(14),
    })
}

impl Rule for GaussKronrod {
    fn name(&self) -> &'static str {
        "gauss-kronrod"
    }

    fn about(&self) -> &'static str {
        "adaptive Gauss–Kronrod G7-K15 on [0,1] (1-D); embedded error estimate"
    }

    /// One G7-K15 panel.
    fn min_budget(&self, _dim: usize) -> usize {
        15
    }

    fn dimensions(&self) -> Dimensions {
        Dimensions { min: 1, max: 1 }
    }

    /// The list of pieces, one per 30 evaluations: 8 bytes an evaluation
    /// bounds it (4.5 measured at 1e7 evaluations, 45 MB).
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
        if D != 1 {
            return Err(QuadError::UnsupportedDimension {
                rule: "gauss-kronrod",
                dim: D,
                supported: "1",
            });
        }
        self.check()?;
        if n < 15 {
            return Err(QuadError::invalid(
                "n",
                n,
                "at least 15 evaluations (one G7-K15 panel)",
            ));
        }
        let mut g = |u: [f64; 1]| {
            let mut p = [0.0; D];
            p[0] = u[0];
            f(p)
        };
        let mut heap = BinaryHeap::new();
        heap.push(kronrod_piece(0.0, 1.0, &mut g)?);
        let mut evaluations = 15u64;
        let totals = |heap: &BinaryHeap<Piece<V>>| {
            let mut value = Compensated::<V>::new();
            let mut error = Compensated::<V>::new();
            for p in heap.iter() {
                value.add(p.value);
                error.add(p.error);
            }
            (value.total(), error.total())
        };
        // Bisect the worst piece while the budget lasts and the tolerance is
        // unmet. Running totals decide when to stop; the reported totals are
        // re-summed (compensated) at the end, free of the running drift.
        let mut value = heap.peek().map_or(V::zero(), |p| p.value);
        let mut error = heap.peek().map_or(V::zero(), |p| p.error);
        // A bisection costs two new panels, 30 evaluations: never past `n`.
        while evaluations + 30 <= n as u64 {
            // A tolerance met ends the work early; with none (both 0, the
            // default) the whole budget is spent, even where the error
            // estimate is 0: every node reading 0 on a narrow peak between
            // them says nothing about the peak.
            let target = self.abs_tol.max(self.rel_tol * value.max_abs());
            if target > 0.0 && error.max_abs() <= target {
                break;
            }
            let Some(worst) = heap.pop() else { break };
            let mid = 0.5 * (worst.a + worst.b);
            if mid <= worst.a || mid >= worst.b {
                // The interval cannot be split further in f64.
                heap.push(worst);
                break;
            }
            let left = kronrod_piece(worst.a, mid, &mut g)?;
            let right = kronrod_piece(mid, worst.b, &mut g)?;
            value = V::from_fn(|c| {
                value.channel(c) - worst.value.channel(c)
                    + left.value.channel(c)
                    + right.value.channel(c)
            });
            error = V::from_fn(|c| {
                (error.channel(c) - worst.error.channel(c)
                    + left.error.channel(c)
                    + right.error.channel(c))
                .max(0.0)
            });
            heap.push(left);
            heap.push(right);
            evaluations += 30;
        }
        let (value, error) = totals(&heap);
        let mut pieces: Vec<&Piece<V>> = heap.iter().collect();
        let hidden = end_gaps(&mut pieces);
        let error = error.zip(hidden, |e, h| e + h);
        let estimate = Estimate::deterministic(value, error, evaluations);
        if heap.iter().any(|p| p.dominated) || peak_at_seam(&mut pieces) {
            Ok(estimate.doubted())
        } else {
            Ok(estimate)
        }
    }
}

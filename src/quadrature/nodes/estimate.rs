//! From sums to an error estimate: Richardson's on nested sums, checked
//! against the order the differences show, and the one-node check.

use crate::estimate::Estimate;
use crate::value::Value;

use super::ProductSum;

/// A difference of two rules at most this many `eps` times `sum |w f|` is
/// rounding: the rule has converged.
pub(crate) const ROUNDING_ULPS: f64 = 128.0;

/// Share of `sum |w f|` above which one term makes a sum dominated
/// ([`dominated`]).
pub const DOMINANT_SHARE: f64 = 0.3;

/// Whether the sum rests on a single node, per channel: `largest > max(0.3,
/// 3 w_max) * magnitude`, with `w_max` the largest (product) weight of the
/// rule (weights sum to 1).
///
/// When one term carries that much of `sum |w f|` the integrand has a
/// feature narrower than the node spacing there (a narrow peak, a
/// near-singularity between nodes): its shape below the spacing is unseen,
/// and its true integral can be any multiple of what the node shows (a
/// Lorentzian `1/(w^2 + (x - c)^2)` of width `w = 1e-4` integrates to
/// `pi/w`, while a node `h/2` away shows `h / (h/2)^2`). No difference of
/// rules on these nodes bounds that error, so the estimate is doubted. The
/// `3 w_max` keeps a rule of a handful of nodes, where every node carries a
/// third, from being doubted for that alone. Resolved integrands stay well
/// below 0.3: `exp(3x)`, the largest share among the smooth battery
/// integrands, is 0.22 at 17 Simpson nodes and shrinks as `1/m`.
pub fn dominated<V: Value>(largest: V, magnitude: V, max_weight: f64) -> bool {
    let share = DOMINANT_SHARE.max(3.0 * max_weight);
    (0..V::CHANNELS).any(|c| largest.channel(c) > share * magnitude.channel(c))
}

/// A composite rule's sum as an estimate with Richardson's error estimate for
/// a rule of order `p`, checked against the order the differences show.
///
/// With the nested sums `Q_h, Q_2h, Q_4h, Q_8h` (the companions: no extra
/// evaluation; as many as the node set nests), the differences
/// `d_1 = Q_h - Q_2h`, `d_2 = Q_2h - Q_4h`, `d_3 = Q_4h - Q_8h` and their
/// ratios `rho_k = d_{k+1} / d_k` (`2^p` for order `p`) decide. Richardson's
/// estimate `|d_1| / (2^p - 1)` is right when the error is `C h^p`; a jump,
/// kink or cusp lowers the order (`O(h)` for a jump, `O(h^1.5)` for
/// `|x - c|^0.5`), and where the cusp or jump lies between nodes its error
/// oscillates with `h`, so one ratio can look like order `p` by chance
/// (`Q_h` and `Q_2h` agreeing while both are off).
///
/// - Every `rho_k` within 20% of `2^p`: the order is confirmed, and the
///   error is Richardson's `|d_1| / (min(rho_1, 2^p) - 1)`.
/// - Every `rho_k > 3/2`, some not near `2^p`: the differences shrink
///   geometrically at a rate `s = min(min_k rho_k, 4)` (order 2 at most
///   assumed: a lower order, or a ratio near `2^p` by chance), and the error
///   of `Q_h` is the largest of the differences carried down to `h` at that
///   rate, `max_k |d_k| / ((s - 1) s^(k-1))`: honest when `d_1` is small by
///   chance, as the coarser differences still show the error's size.
/// - Otherwise (a sign change, or differences that do not shrink):
///   `max(|d_1|, |d_2|)` undivided, and the coarser differences carried down
///   at order 2, whichever is larger.
///
/// The coarser sums are those of [`coarse_weights`]: where the points do
/// not nest the `4h` (`8h`) rule, its panels with a finer tail. Only rules
/// below [`CHECKED_POINTS`], whose estimate is doubted anyway, lack the `4h`
/// level; there nothing shows the order, and the estimate assumes no more
/// than order 2 (what a kink still gives): `|d_1| / (min(2^p, 4) - 1)`.
/// (A band of 25% let a Simpson estimate at a cusp through at 0.034 of the
/// true error: ratios 12.17 and 12.07 at m = 109; 20% holds it.)
///
/// On `|x - c|^0.5` (200 random `c`, 19 point counts from 17 to 16385)
/// the single-ratio check let estimates fall to 1.4e-3 (trapezoid) and
/// 1.6e-4 (Simpson) of the true error; with this rule the smallest is 0.2.
///
/// Where `Q_h`, `Q_2h` and `Q_4h` agree to rounding (`|d_1|, |d_2| <= 128
/// eps sum |w f|`) the rule has converged, and the coarsest difference,
/// which may still be large, is capped as Gauss–Legendre caps its drowned
/// differences
/// ([`crate::quadrature::gauss_legendre::hybrid_estimate`]):
/// `max(eps M, min(E, m 128 eps M))`, `m` the `points` per axis. The
/// trapezoid on a periodic integrand converges faster than any power, and
/// an `8h` rule with a finer tail is not exact for it. Two rules agreeing are not
/// enough: by the symmetry of `sin`, `Q_h` and `Q_2h` of the trapezoid on
/// `1/(1 + 0.99 sin 2 pi x)` at 47 points agree to 1e-11 while both are off
/// by 2e-2 (with the cap on `d_1` alone the estimate was 9.4e-12). Where
/// the `4h` rule ends in a finer tail the periodic estimate stays honest but
/// pessimistic (`exp(u) (1 + cos^2(2 pi v))` at 31 points in `v`: 8.3e-3
/// for an error of 1e-15; at 33 points, where the rules nest, 1e-15).
///
/// The estimate is doubted when one node dominates the sum ([`dominated`]).
///
/// [`CHECKED_POINTS`]: super::CHECKED_POINTS
/// [`coarse_weights`]: super::coarse_weights
pub fn richardson<V: Value>(
    sum: ProductSum<V>,
    order: i32,
    max_weight: f64,
    points: usize,
) -> Estimate<V> {
    let coarse = sum.companion.unwrap_or(sum.value);
    let full = 2f64.powi(order);
    let unchecked = full.min(4.0);
    let error = match sum.companion4 {
        // No estimate below the rounding of the sum itself, `eps sum |w f|`
        // (two rules that agree exactly, on a constant, differ by 0).
        None => V::from_fn(|c| {
            ((sum.value.channel(c) - coarse.channel(c)).abs() / (unchecked - 1.0))
                .max(f64::EPSILON * sum.magnitude.channel(c))
        }),
        Some(coarser) => V::from_fn(|c| {
            let mut q = [
                sum.value.channel(c),
                coarse.channel(c),
                coarser.channel(c),
                0.0,
            ];
            let levels = match sum.companion8 {
                Some(q8) => {
                    q[3] = q8.channel(c);
                    4
                }
                None => 3,
            };
            let nested = nested_estimate(&q[..levels], full);
            // Q_h, Q_2h and Q_4h agree to rounding: the rule has converged
            // (a periodic integrand under the trapezoid), whatever the 8h
            // level shows (its finer tail is not exact for it).
            let rounding = f64::EPSILON * sum.magnitude.channel(c);
            let noise = ROUNDING_ULPS * rounding;
            if (q[0] - q[1]).abs() <= noise && (q[1] - q[2]).abs() <= noise {
                rounding.max(nested.min(points as f64 * noise))
            } else {
                nested
            }
        }),
    };
    let estimate = Estimate::deterministic(sum.value, error, sum.evaluations);
    if dominated(sum.largest, sum.magnitude, max_weight) {
        estimate.doubted()
    } else {
        estimate
    }
}

/// The error of `q[0]` from nested sums `q = [Q_h, Q_2h, Q_4h (, Q_8h)]` of
/// a rule of nominal rate `full = 2^p` ([`richardson`]).
fn nested_estimate(q: &[f64], full: f64) -> f64 {
    let d: Vec<f64> = q.windows(2).map(|w| w[0] - w[1]).collect();
    let rho: Vec<f64> = d.windows(2).map(|w| w[1] / w[0]).collect();
    // `|d_k| / ((s - 1) s^(k-1))`, the largest over k.
    let carried = |s: f64| {
        d.iter()
            .enumerate()
            .map(|(k, dk)| dk.abs() / ((s - 1.0) * s.powi(k as i32)))
            .fold(0.0, f64::max)
    };
    if rho.iter().all(|&r| r > 1.5) {
        let slowest = rho.iter().copied().fold(f64::INFINITY, f64::min);
        let confirmed = rho.iter().all(|&r| (0.8 * full..=1.2 * full).contains(&r));
        if confirmed {
            // Order p over every level: Richardson's estimate at the
            // finest ratio.
            d[0].abs() / (rho[0].min(full) - 1.0)
        } else {
            carried(slowest.min(full).min(4.0))
        }
    } else {
        carried(full.min(4.0)).max(d[0].abs().max(d[1].abs()))
    }
}

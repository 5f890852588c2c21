//! The error estimate of a Gauss–Legendre rule: `Q_m` against the
//! consecutive orders `Q_{m-1}`, `Q_{m-2}` and, from [`HYBRID_FROM`] nodes
//! per axis, the half order `Q_{ceil(m/2)}`.

use super::unit_rule;
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::nodes::{ROUNDING_ULPS, dominated, product_sum};
use crate::value::Value;

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

/// [`GaussLegendre`](super::GaussLegendre) with its error estimate, `m` nodes per axis.
pub(super) fn estimated<const D: usize, V: Value, F: FnMut([f64; D]) -> Result<V, QuadError>>(
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

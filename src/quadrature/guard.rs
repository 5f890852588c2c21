//! The guard of [`Rule::try_integrate`]: a rule's passes taken again of an
//! exactly rescaled integrand where its values' sums or squares would leave
//! the f64 range, the draws and values of earlier passes replayed.

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;

use super::{MAX_RULE_BYTES, Rule, check_budget, replay};

/// Refuses a budget above [`super::MAX_BUDGET`] and one whose working
/// memory ([`Rule::memory`]) would pass [`MAX_RULE_BYTES`]: G7-K15 at n =
/// 2^40 grew to gigabytes until the machine ran out.
#[inline]
pub(super) fn check_limits<Q: Rule + ?Sized>(
    rule: &Q,
    n: usize,
    dim: usize,
) -> Result<(), QuadError> {
    check_budget(n)?;
    let bytes = rule.memory(n, dim);
    if bytes > MAX_RULE_BYTES {
        return Err(too_much_memory(rule.name(), n, bytes));
    }
    Ok(())
}

/// [`check_limits`]'s error for a rule that would need `bytes` at `n`.
#[cold]
fn too_much_memory(rule: &str, n: usize, bytes: f64) -> QuadError {
    QuadError::invalid(
        "n",
        n,
        format!(
            "a budget whose working memory fits: {rule} needs about {:.0} GB at this n, at \
             most {:.0} GB is accepted",
            bytes / 1e9,
            MAX_RULE_BYTES / 1e9
        ),
    )
}

/// [`Rule::try_integrate`] as every rule has it: its limits checked
/// ([`check_limits`]), then guarded where [`Rule::guarded`].
#[inline]
pub(crate) fn checked<
    Q: Rule + ?Sized,
    const D: usize,
    V: Value,
    R: rand::Rng + ?Sized,
    F: FnMut([f64; D]) -> Result<V, QuadError>,
>(
    rule: &Q,
    n: usize,
    rng: &mut R,
    f: F,
) -> Result<Estimate<V>, QuadError> {
    check_limits(rule, n, D)?;
    if rule.guarded(D) {
        try_integrate(rule, n, rng, f)
    } else {
        rule.integrate_unguarded(n, rng, f)
    }
}

/// [`Rule::try_integrate`] of a rule that is [`Rule::guarded`], its
/// limits checked ([`check_limits`]); its documentation says what is
/// guarded and how.
pub(super) fn try_integrate<
    Q: Rule + ?Sized,
    const D: usize,
    V: Value,
    R: rand::Rng + ?Sized,
    F: FnMut([f64; D]) -> Result<V, QuadError>,
>(
    rule: &Q,
    n: usize,
    rng: &mut R,
    mut f: F,
) -> Result<Estimate<V>, QuadError> {
    let promise = (n as u64).max(rule.evaluations(n, D) as u64);
    let mut points = replay::Log::<([f64; D], V)>::new();
    let mut draws = replay::Log::<replay::Draw>::new();
    points.reserve(promise);
    if rule.is_random() {
        // About a draw per coordinate (a hint: the log grows past it).
        draws.reserve(promise.saturating_mul(D as u64));
    }
    // Evaluations of `f` so far, the largest finite |f| seen per
    // channel, and the scaling exponent per channel.
    let mut fresh = 0u64;
    let mut largest = V::zero();
    let mut e = V::zero();
    // The exponent that brings a channel's largest |f| to at most 1.
    let exponent_of = |l: f64| l.log2().ceil().clamp(-1074.0, 1023.0);
    // The last complete estimate whose error underflowed, kept in case
    // its rescaled pass cannot keep the budget; whether a complete
    // pass's overflow has been rescaled.
    let mut underflowed: Option<Estimate<V>> = None;
    let mut rescaled_overflow = false;
    let mut passes = 0;
    // The first pass's first value, and whether every value since matched
    // it bit for bit (for Estimate::alike). Measured on e^u at 65536 (one
    // thread, medians of 9): Gauss–Legendre 1.146x the time without it
    // (about 0.6 ns of its 229373 evaluations), the other rules 0.98 to
    // 1.05x; a branch-free running min and max cost every rule 4 to 10%.
    let (mut first, mut same) = (None::<V>, true);
    // The integrand's own error, which stops a pass and is returned as it
    // is; the first value (unscaled) of a scaled pass that scaled to a
    // value not finite, with its point.
    let mut own = None::<QuadError>;
    let mut not_finite = None::<([f64; D], V)>;
    loop {
        passes += 1;
        points.rewind();
        draws.rewind();
        let scaled = (0..V::CHANNELS).any(|c| e.channel(c) != 0.0);
        let (mut huge, mut over_budget) = (false, false);
        // The first pass has nothing to replay and nothing scaled: its
        // closure only evaluates, logs and watches for values beyond
        // 2^500 (the general closure below cost about 5 ns an
        // evaluation more).
        let pass = if passes == 1 {
            rule.integrate_unguarded(
                n,
                &mut replay::LoggedRng {
                    inner: rng,
                    log: &mut draws,
                    replaying: false,
                },
                #[inline(always)]
                |u| {
                    let y = f(u).map_err(|error| stopped_by(&mut own, error))?;
                    fresh += 1;
                    // One predictable branch once a value differed.
                    if same {
                        match first {
                            None => first = Some(y),
                            Some(f0) => same = bitwise_equal(&f0, &y),
                        }
                    }
                    // The log keeps the largest |f| of what it holds
                    // (folded only when needed); past it, it is kept here.
                    if points.push((u, y)) {
                        if y.max_abs() > HUGE && beyond(&y) {
                            huge = true;
                            return Err(pass_stopped());
                        }
                    } else {
                        largest = largest.zip(y, finite_max);
                    }
                    Ok(y)
                },
            )
        } else {
            rule.integrate_unguarded(
                n,
                &mut replay::LoggedRng {
                    inner: rng,
                    log: &mut draws,
                    replaying: true,
                },
                |u| {
                    let (y, logged) =
                        match points.replay(|(p, _)| replay::bits(*p) == replay::bits(u)) {
                            Some((_, y)) => (y, true),
                            None if fresh < promise => {
                                fresh += 1;
                                let y = f(u).map_err(|error| stopped_by(&mut own, error))?;
                                (y, points.append((u, y)))
                            }
                            None => {
                                over_budget = true;
                                return Err(pass_stopped());
                            }
                        };
                    largest = largest.zip(y, finite_max);
                    let y = if scaled {
                        let scaled_y = y.zip(e, |y, e| times_pow2(y, -e));
                        if !scaled_y.all_finite() && not_finite.is_none() {
                            not_finite = Some((u, y));
                        }
                        scaled_y
                    } else {
                        y
                    };
                    // A finite value beyond 2^500 at the current scale, while
                    // the log holds the pass: stop, and start again scaled
                    // (past the log the pass runs on, and is rescaled only if
                    // its estimate overflowed).
                    if y.max_abs() > HUGE && logged && beyond(&y) {
                        huge = true;
                        return Err(pass_stopped());
                    }
                    Ok(y)
                },
            )
        };
        // The integrand's own error, as it is; a value that is not finite
        // told as the integrand returned it, not as scaled.
        if let Some(error) = own.take() {
            return Err(error);
        }
        let returned = not_finite.take();
        let pass = pass.map_err(|error| as_returned(error, returned));
        // A raw sum that left the f64 range (values within rounding of
        // f64::MAX, past the log): a pass whose estimate overflowed.
        let pass = match pass {
            Err(QuadError::SumOutOfRange { .. }) => {
                let nan = V::from_fn(|_| f64::NAN);
                Ok(Estimate::deterministic(nan, nan, fresh))
            }
            pass => pass,
        };
        // The channels whose largest |f| is beyond 2^500 at their scale.
        let rescale = |e: V, largest: V| {
            e.zip(largest, |e, l| {
                if times_pow2(l, -e) > HUGE {
                    exponent_of(l)
                } else {
                    e
                }
            })
        };
        // After the first pass, `largest` covers what went past the log;
        // the log's own values are folded in when a decision needs them
        // (a value beyond 2^500, an estimate or error that is not finite
        // or an error of 0), so a plain pass does no bookkeeping for it.
        if passes == 1
            && (huge
                || pass.as_ref().is_ok_and(|p| {
                    !sound(p)
                        || (0..V::CHANNELS).any(|c| {
                            let err = p.error.channel(c);
                            err == 0.0 || err.is_infinite()
                        })
                }))
        {
            largest = points.fold(largest, |l, (_, y)| l.zip(*y, finite_max));
        }
        if huge {
            e = rescale(e, largest);
            continue;
        }
        if over_budget {
            return match underflowed {
                Some(estimate) => Ok(Estimate {
                    evaluations: fresh,
                    ..estimate.doubted()
                }),
                None => Err(QuadError::RescaleOverBudget {
                    rule: rule.name(),
                    budget: n,
                    exponent: e.max_abs() as i32,
                }),
            };
        }
        let pass = pass?;
        let estimate = Estimate {
            value: pass.value.zip(e, times_pow2),
            error: pass.error.zip(e, times_pow2),
            // One pass counts as the rule counts; several as `f` was called.
            evaluations: if passes == 1 { pass.evaluations } else { fresh },
            ..pass
        };
        // A pass that ran past its log with values beyond 2^500 and
        // overflowed (a value that is not finite, or an infinite error
        // where the values' squares overflowed): once more, scaled.
        let overflowed = !sound(&pass)
            || (0..V::CHANNELS).any(|c| {
                times_pow2(largest.channel(c), -e.channel(c)) > HUGE
                    && pass.error.channel(c).is_infinite()
            });
        let wider = rescale(e, largest);
        let changed = (0..V::CHANNELS).any(|c| wider.channel(c) != e.channel(c));
        if overflowed && !rescaled_overflow && changed {
            rescaled_overflow = true;
            e = wider;
            continue;
        }
        // A channel below 2^-500 with an error of exactly 0, not yet
        // scaled: its squares underflowed (a random rule's standard error
        // of an integrand near 1e-300 came out 0). Tiny values with a
        // sound error (a deterministic rule's differences, deep in a
        // stiff medium) are left as they are.
        let tiny = V::from_fn(|c| {
            let l = largest.channel(c);
            let untouched = e.channel(c) == 0.0;
            if untouched && l > 0.0 && l < TINY && estimate.error.channel(c) == 0.0 {
                exponent_of(l)
            } else {
                0.0
            }
        });
        if underflowed.is_none() && (0..V::CHANNELS).any(|c| tiny.channel(c) != 0.0) {
            e = e.zip(tiny, |e, t| e + t);
            underflowed = Some(estimate);
            continue;
        }
        // An error finite at the pass's scale and beyond the f64 range
        // once scaled back (values near +-f64::MAX spread wider than
        // f64): infinite, no bound a report can show, so doubted.
        let beyond_range = (0..V::CHANNELS)
            .any(|c| estimate.error.channel(c).is_infinite() && pass.error.channel(c).is_finite());
        let zero = (0..V::CHANNELS).any(|c| estimate.error.channel(c) == 0.0);
        let alike = if passes == 1 {
            same && fresh >= 2
        } else {
            all_alike(&points, fresh)
        };
        let estimate = Estimate {
            alike: !rule.is_random() && zero && alike,
            ..estimate
        };
        return if sound(&estimate) {
            Ok(if beyond_range {
                estimate.doubted()
            } else {
                estimate
            })
        } else {
            Err(QuadError::Overflow {
                rule: rule.name(),
                value: format!("{:?}", pass.value),
                exponent: e.max_abs() as i32,
            })
        };
    }
}

/// True when every one of the `fresh` evaluations, all held by `points`,
/// gave the same value (bit for bit); false when the log holds fewer.
fn all_alike<const D: usize, V: Value>(points: &replay::Log<([f64; D], V)>, fresh: u64) -> bool {
    if fresh < 2 || points.len() as u64 != fresh {
        return false;
    }
    let mut first: Option<V> = None;
    points.fold(true, |same, (_, y)| {
        let f = *first.get_or_insert(*y);
        same && bitwise_equal(&f, y)
    })
}

/// `a` and `b` are the same in every channel, bit for bit.
#[inline(always)]
fn bitwise_equal<V: Value>(a: &V, b: &V) -> bool {
    (0..V::CHANNELS).all(|c| a.channel(c).to_bits() == b.channel(c).to_bits())
}

/// `x 2^e` exactly (while representable), in two steps so that each power
/// of two is a normal number for every `e` in `-1074..=1023`.
fn times_pow2(x: f64, e: f64) -> f64 {
    let half = (e / 2.0).trunc() as i32;
    x * 2f64.powi(half) * 2f64.powi(e as i32 - half)
}

/// Magnitudes whose squares overflow ([`Rule::try_integrate`] rescales).
const HUGE: f64 = 3.273390607896142e150; // 2^500

/// Magnitudes whose squares underflow ([`Rule::try_integrate`] rescales).
const TINY: f64 = 3.054936363499605e-151; // 2^-500

/// A finite value and an error that is a number (an infinite error is a
/// rule's way of saying it has no estimate, not an overflow).
fn sound<V: Value>(e: &Estimate<V>) -> bool {
    e.value.all_finite() && (0..V::CHANNELS).all(|c| !e.error.channel(c).is_nan())
}

/// `max(l, |y|)` over finite `y` (the largest finite magnitude seen).
#[inline(always)]
fn finite_max(l: f64, y: f64) -> f64 {
    if y.is_finite() { l.max(y.abs()) } else { l }
}

/// Whether a channel of `y` is finite and beyond `2^500`.
#[cold]
fn beyond<V: Value>(y: &V) -> bool {
    (0..V::CHANNELS).any(|c| {
        let v = y.channel(c);
        v.is_finite() && v.abs() > HUGE
    })
}

/// Keeps the integrand's own `error` in `own` and stops the sum it was
/// called in: the caller returns `own` as it is, whatever the sum makes of
/// the stop (the guard; [`FixedOrder`](super::gauss_legendre::FixedOrder)'s
/// compensated sum).
#[cold]
pub(crate) fn stopped_by(own: &mut Option<QuadError>, error: QuadError) -> QuadError {
    *own = Some(error);
    pass_stopped()
}

/// `error` of a scaled pass: a value not finite at the point where the
/// scaled value was found not finite is told as the integrand returned
/// it; every other error as it is.
#[cold]
fn as_returned<const D: usize, V: Value>(
    error: QuadError,
    returned: Option<([f64; D], V)>,
) -> QuadError {
    match (error, returned) {
        (QuadError::NonFiniteIntegrand { point, .. }, Some((p, y))) if point[..] == p[..] => {
            crate::quadrature::nodes::non_finite(&p, &y)
        }
        (error, _) => error,
    }
}

/// The error that stops a pass of [`Rule::try_integrate`] to be taken again
/// (never returned to the caller).
#[cold]
fn pass_stopped() -> QuadError {
    QuadError::invalid("pass", "stopped", "(taken again scaled)")
}

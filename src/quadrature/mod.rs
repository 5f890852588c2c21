//! Quadrature rules on the unit cube `[0, 1]^D`.
//!
//! A rule knows how to place weighted nodes in the unit cube for a budget of
//! `n` integrand evaluations; it never knows geometry (that is a
//! [`domain`](crate::domain)'s job) nor which equation it serves. Every rule
//! implements [`Rule`]; [`AnyRule`] selects one by name at run time.
//!
//! **The registry** is the one `registry!` line per rule below: it declares
//! the rule's module and its name in experiment files, and generates
//! [`BaseRule`] (the serde rule spec, tagged by `"rule"`, every parameter a
//! field of the rule's own struct) with dispatch of every [`Rule`] method.
//! Facts about a rule (its minimum budget, whether it is random, the
//! dimensions it integrates, the check of its parameters) are methods of the
//! rule itself. Adding a rule is its file plus one registry line.
//!
//! | name | rule | error estimate |
//! |---|---|---|
//! | `trapezoid` | composite trapezoid, product in D > 1 | Richardson, half step; observed order from the quarter step when nested |
//! | `simpson` | composite Simpson, product in D > 1 | Richardson, half step; observed order from the quarter step when nested |
//! | `gauss-legendre` | Gauss–Legendre of any order, product in D > 1 | tail of the differences of `Q_m, Q_{m-1}, Q_{m-2}`, checked against `Q_m - Q_{m/2}` from m = 16 |
//! | `gauss-kronrod` | adaptive Gauss–Kronrod G7–K15 (D = 1) | embedded G7 |
//! | `genz-malik` | adaptive Genz–Malik degree-7 cubature (2 <= D <= 6), bisecting the worst box (as HCubature) | embedded degree-5 rule |
//! | `monte-carlo` | plain Monte Carlo | standard error; doubted when all samples agree or the sample variance is carried by a few samples (kurtosis) |
//! | `stratified` | jittered Monte Carlo, one sample per cell | second differences of every three neighbouring cells; doubted when none varies, or when a few cells carry the variance and one sample inside the cube most of the sum (a peak between samples) |
//! | `sobol` | Owen-scrambled Sobol' points (D <= 2), 8 scrambles | standard error over scrambles, times t_{R-1}(0.975)/1.96; doubted when the scrambles agree or the points fail the Monte Carlo tail check |
//! | `product` | iterated 2-D rule from any two 1-D rules (`AnyRule::by_name("product(A,B)")` in the library) | outer estimate + integrated inner estimates |
//!
//! ```
//! use lightquad::quadrature::{GaussLegendre, Rule, Trapezoid};
//! use rand::SeedableRng;
//!
//! // int_0^1 e^u du = e - 1: Gauss–Legendre converges spectrally, the trapezoid
//! // rule as n^-2.
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
//! let exact = std::f64::consts::E - 1.0;
//! let gl = GaussLegendre::default().integrate(8, &mut rng, |u: [f64; 1]| u[0].exp())?;
//! let tr = Trapezoid.integrate(8, &mut rng, |u: [f64; 1]| u[0].exp())?;
//! assert!((gl.value - exact).abs() < 1e-14);
//! assert!((tr.value - exact).abs() > 1e-4 && (tr.value - exact).abs() < 1e-2);
//! # Ok::<(), lightquad::QuadError>(())
//! ```

pub mod nodes;
pub mod product;
mod replay;

pub use product::Product;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::value::Value;

/// The dimensions `min..=max` of the unit cube a rule integrates over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dimensions {
    /// Smallest dimension.
    pub min: usize,
    /// Largest dimension.
    pub max: usize,
}

impl Dimensions {
    /// Every dimension from 1.
    pub const ANY: Dimensions = Dimensions {
        min: 1,
        max: usize::MAX,
    };

    /// True when `dim` is in range.
    pub fn contains(&self, dim: usize) -> bool {
        (self.min..=self.max).contains(&dim)
    }
}

impl std::fmt::Display for Dimensions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.min, self.max) {
            (a, usize::MAX) => write!(f, "{a} and up"),
            (a, b) if a == b => write!(f, "{a} only"),
            (a, b) => write!(f, "{a} to {b}"),
        }
    }
}

/// A quadrature rule on the unit cube `[0, 1]^D`.
pub trait Rule {
    /// The registry name (`gauss-legendre`, ...).
    fn name(&self) -> &'static str;

    /// One line on what the rule is and how it estimates its error.
    fn about(&self) -> &'static str;

    /// The smallest budget the rule accepts in `dim` dimensions (an experiment
    /// skips smaller budgets for it).
    fn min_budget(&self, _dim: usize) -> usize {
        1
    }

    /// True for randomised rules (their error estimate is a standard error).
    fn is_random(&self) -> bool {
        false
    }

    /// The dimensions the rule integrates over.
    fn dimensions(&self) -> Dimensions {
        Dimensions::ANY
    }

    /// Checks the rule's parameters; the error names the parameter.
    fn check(&self) -> Result<(), QuadError> {
        Ok(())
    }

    /// The resolution per axis that a budget of `n` evaluations in `dim`
    /// dimensions buys: the `x` an error of order `O(x^-p)` falls with, so a
    /// fit of the error against it shows an order-p rule as `-p`. Nodes or
    /// samples per axis, `floor(n^(1/dim))`, by default; the intervals
    /// `m - 1` of the points a composite rule really uses.
    fn resolution(&self, n: usize, dim: usize) -> f64 {
        integer_root(n, dim) as f64
    }

    /// The bytes of working memory a run at a budget of `n` in `dim`
    /// dimensions holds at once, where they grow with `n` (node tables, piece
    /// lists); 0 for rules whose memory does not grow (Monte Carlo draws a
    /// sample at a time). An estimate from measured peak resident memory,
    /// so that a budget that would exhaust the machine is refused before it
    /// runs (Gauss–Legendre at 1e8 nodes held 5.5 GB). Not counted: the
    /// replay logs of [`Rule::try_integrate`], at most 2 MiB per integral
    /// under way.
    fn memory(&self, _n: usize, _dim: usize) -> f64 {
        0.0
    }

    /// The integrand evaluations a run at a budget of `n` in `dim`
    /// dimensions makes, its error estimate's included: `n` by default;
    /// Gauss–Legendre evaluates three more rules of about `m`, `m` and `m/2`
    /// nodes for its estimate (3.5 n in one dimension, 12 n in a nested
    /// integral, which cost estimates counted as n and n^2).
    fn evaluations(&self, n: usize, _dim: usize) -> f64 {
        n as f64
    }

    /// The rule itself, which [`Rule::try_integrate`] guards against
    /// overflow: estimates `int_{[0,1]^D} f(u) du` with a budget of about `n`
    /// evaluations, for an integrand that may fail: its first error stops the
    /// rule and is returned as is. `n` above [`MAX_BUDGET`] is an error here
    /// too.
    ///
    /// `rng` drives the randomised rules and is ignored by deterministic ones;
    /// with the same `rng` state the result is bit-for-bit reproducible.
    fn integrate_unguarded<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        rng: &mut R,
        f: F,
    ) -> Result<Estimate<V>, QuadError>;

    /// Estimates `int_{[0,1]^D} f(u) du` with a budget of about `n` evaluations,
    /// for an integrand that may fail: its first error stops the rule and is
    /// returned as is. `n` above [`MAX_BUDGET`] is an error.
    ///
    /// A rule's sums, differences and squares of values beyond `2^500` can
    /// overflow into an infinite or NaN estimate, and squares of values below
    /// `2^-500` underflow into a standard error of 0. So a pass stops at the
    /// first finite value beyond `2^500` (while its log holds it) and the
    /// integral is taken again of `f 2^-e` in that channel, `2^e` the largest
    /// `|f|` seen; a pass past its log that overflowed is taken again so; and
    /// a channel whose values all lie below `2^-500` and whose error came out
    /// 0 is taken again of `f 2^-e` too: exact scalings, undone on the
    /// estimate. An estimate that is still not finite is an error
    /// ([`QuadError::Overflow`]), never a silent NaN; an error estimate
    /// that is finite at its scale and beyond the f64 range once scaled
    /// back is infinite and doubted.
    ///
    /// Passes after the first keep the budget: they replay the draws and
    /// values logged so far (module `replay`, at most 1 MiB each) and
    /// evaluate `f` only where the log ends or an adaptive rule, deciding on
    /// scaled values, takes another path; every evaluation is counted, and
    /// never more than the rule's own promise ([`Rule::evaluations`]) in all.
    /// A pass that would go past it is abandoned: an estimate with an
    /// underflowed error is then returned doubted (so beyond the log, 65536
    /// one-dimensional evaluations, stratified sampling of an integrand near
    /// 1e-300 gives an error of 0, doubted, where evaluating twice gave a
    /// real one), and a pass that met values beyond `2^500` is an error
    /// ([`QuadError::RescaleOverBudget`]).
    fn try_integrate<
        const D: usize,
        V: Value,
        R: rand::Rng + ?Sized,
        F: FnMut([f64; D]) -> Result<V, QuadError>,
    >(
        &self,
        n: usize,
        rng: &mut R,
        mut f: F,
    ) -> Result<Estimate<V>, QuadError> {
        check_budget(n)?;
        // Working memory that grows with n (an adaptive rule's intervals, a
        // node table): G7-K15 at n = 2^40 grew to gigabytes until the machine
        // ran out.
        let bytes = self.memory(n, D);
        if bytes > MAX_RULE_BYTES {
            return Err(QuadError::invalid(
                "n",
                n,
                format!(
                    "a budget whose working memory fits: {} needs about {:.0} GB at this n, at \
                     most {:.0} GB is accepted",
                    self.name(),
                    bytes / 1e9,
                    MAX_RULE_BYTES / 1e9
                ),
            ));
        }
        let promise = (n as u64).max(self.evaluations(n, D) as u64);
        let mut points = replay::Log::<([f64; D], V)>::new();
        let mut draws = replay::Log::<replay::Draw>::new();
        points.reserve(promise);
        if self.is_random() {
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
                self.integrate_unguarded(
                    n,
                    &mut replay::LoggedRng {
                        inner: rng,
                        log: &mut draws,
                        replaying: false,
                    },
                    #[inline(always)]
                    |u| {
                        let y = f(u)?;
                        fresh += 1;
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
                self.integrate_unguarded(
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
                                    let y = f(u)?;
                                    (y, points.append((u, y)))
                                }
                                None => {
                                    over_budget = true;
                                    return Err(pass_stopped());
                                }
                            };
                        largest = largest.zip(y, finite_max);
                        let y = if scaled {
                            y.zip(e, |y, e| times_pow2(y, -e))
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
                        rule: self.name(),
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
            let beyond_range = (0..V::CHANNELS).any(|c| {
                estimate.error.channel(c).is_infinite() && pass.error.channel(c).is_finite()
            });
            return if sound(&estimate) {
                Ok(if beyond_range {
                    estimate.doubted()
                } else {
                    estimate
                })
            } else {
                Err(QuadError::Overflow {
                    rule: self.name(),
                    value: format!("{:?}", pass.value),
                    exponent: e.max_abs() as i32,
                })
            };
        }
    }

    /// [`Rule::try_integrate`] for an integrand that cannot fail.
    fn integrate<const D: usize, V: Value, R: rand::Rng + ?Sized, F: FnMut([f64; D]) -> V>(
        &self,
        n: usize,
        rng: &mut R,
        mut f: F,
    ) -> Result<Estimate<V>, QuadError> {
        self.try_integrate(n, rng, |u| Ok(f(u)))
    }
}

/// Checks an adaptive rule's stopping tolerances (Gauss–Kronrod,
/// Genz–Malik): each finite and `>= 0`; the error names the parameter.
pub(crate) fn check_tolerances(abs_tol: f64, rel_tol: f64) -> Result<(), QuadError> {
    for (name, tol) in [("abs_tol", abs_tol), ("rel_tol", rel_tol)] {
        if !(tol.is_finite() && tol >= 0.0) {
            return Err(QuadError::invalid(name, tol, "a finite number >= 0"));
        }
    }
    Ok(())
}

/// The largest budget any rule accepts, `2^40` (about 1.1e12) evaluations:
/// hours of work at a nanosecond per evaluation. A larger `n` (`usize::MAX`
/// from an unchecked computation) is refused at once instead of looping for
/// centuries.
pub const MAX_BUDGET: usize = 1 << 40;

/// Refuses a budget above [`MAX_BUDGET`]: every rule's entry points, the
/// unguarded ones included (a trapezoid in three dimensions at `usize::MAX`
/// ran on for 1.8e19 evaluations).
pub(crate) fn check_budget(n: usize) -> Result<(), QuadError> {
    if n > MAX_BUDGET {
        return Err(QuadError::invalid(
            "n",
            n,
            format!("a budget of at most 2^40 = {MAX_BUDGET} evaluations"),
        ));
    }
    Ok(())
}

/// The most working memory one integral may need by its rule's own
/// estimate ([`Rule::memory`]): 32 GiB, more than the machines this runs on
/// hold; a larger `n` is refused at once instead of growing until the
/// machine runs out.
pub const MAX_RULE_BYTES: f64 = 32.0 * (1u64 << 30) as f64;

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

/// The error that stops a pass of [`Rule::try_integrate`] to be taken again
/// (never returned to the caller).
#[cold]
fn pass_stopped() -> QuadError {
    QuadError::invalid("pass", "stopped", "(taken again scaled)")
}

/// The largest `m` with `m^dim <= n` (`n` itself for `dim <= 1`).
pub fn integer_root(n: usize, dim: usize) -> usize {
    if dim <= 1 {
        return n;
    }
    let mut m = (n as f64).powf(1.0 / dim as f64).round() as usize;
    while m > 0 && m.checked_pow(dim as u32).is_none_or(|p| p > n) {
        m -= 1;
    }
    while (m + 1).checked_pow(dim as u32).is_some_and(|p| p <= n) {
        m += 1;
    }
    m
}

/// Nodes per axis for a product rule with a budget of `n` evaluations in `D`
/// dimensions: the largest `m` with `m^D <= n`; at least `min` (else an error
/// naming `name`).
pub fn per_axis<const D: usize>(n: usize, min: usize, name: &str) -> Result<usize, QuadError> {
    let need = min.checked_pow(D as u32).unwrap_or(usize::MAX);
    if n < need {
        return Err(QuadError::invalid(
            name,
            n,
            format!("a budget of at least {need} evaluations in {D} dimension(s)"),
        ));
    }
    Ok(integer_root(n, D).max(min))
}

/// Declares the rule modules and generates [`BaseRule`], its dispatch and the
/// serde form of [`AnyRule`] from one line per rule:
/// `module::Type = "name in experiment files"`.
macro_rules! registry {
    ($($module:ident :: $rule:ident = $name:literal),+ $(,)?) => {
        $(
            pub mod $module;
            pub use $module::$rule;
        )+

        /// A single rule selected at run time (every rule but the product); its
        /// serde form is the rule spec of experiment files,
        /// `{"rule": "<name>", <the rule's parameters>}`.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
        #[serde(tag = "rule")]
        pub enum BaseRule {
            $(
                #[doc = concat!("`", $name, "`: [`", stringify!($rule), "`].")]
                #[serde(rename = $name)]
                $rule($rule),
            )+
        }

        /// The serde form of [`AnyRule`]: every single rule, and `product`.
        #[derive(Serialize, Deserialize, JsonSchema)]
        #[serde(tag = "rule")]
        #[schemars(rename = "Rule")]
        enum AnyRuleSpec {
            $(
                #[doc = concat!("`", $name, "`: [`", stringify!($rule), "`].")]
                #[serde(rename = $name)]
                $rule($rule),
            )+
            /// `product`: the iterated 2-D rule of two single rules.
            #[serde(rename = "product")]
            Product(Product<BaseRule, BaseRule>),
        }

        impl From<AnyRuleSpec> for AnyRule {
            fn from(spec: AnyRuleSpec) -> Self {
                match spec {
                    $(AnyRuleSpec::$rule(r) => AnyRule::Base(BaseRule::$rule(r)),)+
                    AnyRuleSpec::Product(p) => AnyRule::Product(Box::new(p)),
                }
            }
        }

        impl From<AnyRule> for AnyRuleSpec {
            fn from(rule: AnyRule) -> Self {
                match rule {
                    $(AnyRule::Base(BaseRule::$rule(r)) => AnyRuleSpec::$rule(r),)+
                    AnyRule::Product(p) => AnyRuleSpec::Product(*p),
                }
            }
        }

        impl BaseRule {
            /// Every single rule with its default parameters, in registry order.
            pub fn defaults() -> Vec<BaseRule> {
                vec![$(BaseRule::$rule(<$rule>::default())),+]
            }

            /// Reads `{"rule": "<name>", <parameters>}`; a fault is returned with
            /// the path of its field below the rule (`rel_tol`) and what is wrong.
            pub fn from_json(value: &serde_json::Value) -> Result<BaseRule, (String, String)> {
                let Some(object) = value.as_object() else {
                    return Err((
                        String::new(),
                        format!(
                            "{value} is not a rule: expected {{\"rule\": <name>, <parameters>}}, the name one of {}",
                            [$($name),+].join(", ")
                        ),
                    ));
                };
                let mut params = object.clone();
                let tag = params.remove("rule");
                match tag.as_ref().and_then(|t| t.as_str()) {
                    $(Some($name) => parameters::<$rule>(params).map(BaseRule::$rule),)+
                    _ => Err((
                        "rule".into(),
                        format!(
                            "{} is not a single rule: expected one of {}",
                            tag.unwrap_or(serde_json::Value::Null),
                            [$($name),+].join(", ")
                        ),
                    )),
                }
            }
        }

        impl Rule for BaseRule {
            fn name(&self) -> &'static str {
                match self { $(BaseRule::$rule(r) => r.name(),)+ }
            }
            fn about(&self) -> &'static str {
                match self { $(BaseRule::$rule(r) => r.about(),)+ }
            }
            fn min_budget(&self, dim: usize) -> usize {
                match self { $(BaseRule::$rule(r) => r.min_budget(dim),)+ }
            }
            fn is_random(&self) -> bool {
                match self { $(BaseRule::$rule(r) => r.is_random(),)+ }
            }
            fn dimensions(&self) -> Dimensions {
                match self { $(BaseRule::$rule(r) => r.dimensions(),)+ }
            }
            fn check(&self) -> Result<(), QuadError> {
                match self { $(BaseRule::$rule(r) => r.check(),)+ }
            }
            fn resolution(&self, n: usize, dim: usize) -> f64 {
                match self { $(BaseRule::$rule(r) => r.resolution(n, dim),)+ }
            }
            fn memory(&self, n: usize, dim: usize) -> f64 {
                match self { $(BaseRule::$rule(r) => r.memory(n, dim),)+ }
            }
            fn evaluations(&self, n: usize, dim: usize) -> f64 {
                match self { $(BaseRule::$rule(r) => r.evaluations(n, dim),)+ }
            }
            fn integrate_unguarded<
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
                match self { $(BaseRule::$rule(r) => r.integrate_unguarded(n, rng, f),)+ }
            }
        }
    };
}

registry! {
    trapezoid::Trapezoid = "trapezoid",
    simpson::Simpson = "simpson",
    gauss_legendre::GaussLegendre = "gauss-legendre",
    gauss_kronrod::GaussKronrod = "gauss-kronrod",
    genz_malik::GenzMalik = "genz-malik",
    monte_carlo::MonteCarlo = "monte-carlo",
    stratified::Stratified = "stratified",
    sobol::Sobol = "sobol",
}

/// Any rule selected at run time, products included. Its serde form is a
/// single rule's, or `{"rule": "product", "outer": {..}, "inner": {..}}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "AnyRuleSpec", into = "AnyRuleSpec")]
pub enum AnyRule {
    /// One rule.
    Base(BaseRule),
    /// The [`Product`] of two rules (kept apart from [`BaseRule`] so a product
    /// of products, which the type system could not bound, cannot be named).
    Product(Box<Product<BaseRule, BaseRule>>),
}

impl JsonSchema for AnyRule {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        AnyRuleSpec::schema_name()
    }
    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        AnyRuleSpec::json_schema(generator)
    }
}

impl BaseRule {
    /// The rule named `name` with its default parameters.
    pub fn by_name(name: &str) -> Result<BaseRule, QuadError> {
        serde_json::from_value(serde_json::json!({ "rule": name.trim() })).map_err(|_| {
            QuadError::UnknownRule {
                name: name.trim().to_string(),
                known: BaseRule::defaults()
                    .iter()
                    .map(Rule::name)
                    .collect::<Vec<_>>()
                    .join(", "),
            }
        })
    }
}

impl AnyRule {
    /// The rule named `name` with its default parameters; `product(A,B)` names
    /// the iterated product of two named rules.
    pub fn by_name(name: &str) -> Result<AnyRule, QuadError> {
        let name = name.trim();
        if let Some(args) = name
            .strip_prefix("product(")
            .and_then(|rest| rest.strip_suffix(')'))
        {
            let Some((outer, inner)) = split_top_level_comma(args) else {
                return Err(QuadError::invalid(
                    "rule",
                    name,
                    "product(A,B) with two rule names, e.g. product(gauss-legendre,trapezoid)",
                ));
            };
            return Ok(AnyRule::Product(Box::new(Product {
                outer: BaseRule::by_name(outer)?,
                inner: BaseRule::by_name(inner)?,
            })));
        }
        BaseRule::by_name(name).map(AnyRule::Base)
    }

    /// The rule's name, with its factors for a product:
    /// `product(gauss-legendre,trapezoid)`.
    pub fn label(&self) -> String {
        match self {
            AnyRule::Base(r) => r.name().to_string(),
            AnyRule::Product(p) => format!("product({},{})", p.outer.name(), p.inner.name()),
        }
    }

    /// Every rule's name and one line about it, products last (for `lightquad rules`).
    pub fn listing() -> Vec<(&'static str, &'static str)> {
        let mut lines: Vec<(&'static str, &'static str)> = BaseRule::defaults()
            .iter()
            .map(|r| (r.name(), r.about()))
            .collect();
        lines.push((
            "product",
            "2-D iterated rule of two 1-D rules: {\"rule\": \"product\", \"outer\": {..}, \"inner\": {..}}",
        ));
        lines
    }
}

impl From<BaseRule> for AnyRule {
    fn from(rule: BaseRule) -> Self {
        AnyRule::Base(rule)
    }
}

impl Rule for AnyRule {
    fn name(&self) -> &'static str {
        match self {
            AnyRule::Base(r) => r.name(),
            AnyRule::Product(r) => r.name(),
        }
    }
    fn about(&self) -> &'static str {
        match self {
            AnyRule::Base(r) => r.about(),
            AnyRule::Product(r) => r.about(),
        }
    }
    fn min_budget(&self, dim: usize) -> usize {
        match self {
            AnyRule::Base(r) => r.min_budget(dim),
            AnyRule::Product(r) => r.min_budget(dim),
        }
    }
    fn is_random(&self) -> bool {
        match self {
            AnyRule::Base(r) => r.is_random(),
            AnyRule::Product(r) => r.is_random(),
        }
    }
    fn dimensions(&self) -> Dimensions {
        match self {
            AnyRule::Base(r) => r.dimensions(),
            AnyRule::Product(r) => r.dimensions(),
        }
    }
    fn check(&self) -> Result<(), QuadError> {
        match self {
            AnyRule::Base(r) => r.check(),
            AnyRule::Product(r) => r.check(),
        }
    }
    fn resolution(&self, n: usize, dim: usize) -> f64 {
        match self {
            AnyRule::Base(r) => r.resolution(n, dim),
            AnyRule::Product(r) => r.resolution(n, dim),
        }
    }
    fn memory(&self, n: usize, dim: usize) -> f64 {
        match self {
            AnyRule::Base(r) => r.memory(n, dim),
            AnyRule::Product(r) => r.memory(n, dim),
        }
    }
    fn evaluations(&self, n: usize, dim: usize) -> f64 {
        match self {
            AnyRule::Base(r) => r.evaluations(n, dim),
            AnyRule::Product(r) => r.evaluations(n, dim),
        }
    }
    fn integrate_unguarded<
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
        match self {
            AnyRule::Base(r) => r.integrate_unguarded(n, rng, f),
            AnyRule::Product(r) => r.integrate_unguarded(n, rng, f),
        }
    }
}

/// A rule's parameters (the object without its `"rule"`), with the path of a
/// fault below the rule; a rule without parameters says so of any field.
fn parameters<T: serde::de::DeserializeOwned>(
    params: serde_json::Map<String, serde_json::Value>,
) -> Result<T, (String, String)> {
    let takes_none = serde_json::from_value::<T>(serde_json::Value::Null);
    if let Ok(rule) = takes_none {
        return match params.keys().next() {
            None => Ok(rule),
            Some(key) => Err((
                key.clone(),
                format!("unknown field `{key}`: this rule takes no parameters"),
            )),
        };
    }
    serde_path_to_error::deserialize(serde_json::Value::Object(params)).map_err(|e| {
        let path = e.path().to_string();
        (
            if path == "." { String::new() } else { path },
            e.inner().to_string(),
        )
    })
}

/// Splits `A,B` at the comma that is not inside parentheses.
fn split_top_level_comma(s: &str) -> Option<(&str, &str)> {
    let mut depth = 0i32;
    for (i, ch) in s.char_indices() {
        match ch {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' if depth == 0 => return Some((s[..i].trim(), s[i + 1..].trim())),
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The registry's name for a rule (its serde tag) is the rule's own name.
    #[test]
    fn registry_names_match_rule_names() -> Result<(), serde_json::Error> {
        for rule in BaseRule::defaults() {
            let json = serde_json::to_value(&rule)?;
            assert_eq!(json["rule"], rule.name());
            assert_eq!(BaseRule::by_name(rule.name()), Ok(rule));
        }
        Ok(())
    }
}

//! Error estimates that lie: a Kahaner-style battery of
//! one-dimensional integrands on `[0, 1]` with closed-form values, run through
//! every deterministic rule at several budgets.
//!
//! A report may never present a lying error estimate without a flag: wherever
//! the true error is above rounding (1e-13 relative to `max(1, |I|)`), the
//! estimate is at least a tenth of the true error or the rule doubts it
//! (`reliable == false`, which reports show as `Flag::UnreliableEstimate`).
//! Smooth integrands are never doubted and their estimates stay sharp.
//!
//! The battery follows D. K. Kahaner, "Comparison of numerical quadrature
//! formulas", in Mathematical Software (J. R. Rice, ed.), Academic Press 1971:
//! smooth, endpoint-singular, kinked and discontinuous integrands. Every exact
//! value below is an elementary antiderivative evaluated at the ends, stated
//! beside the integrand; none comes from the code under test.
//!
//! What is and is not detectable. A rule sees an integrand only at its
//! nodes. A feature no node comes near (a Gaussian of width 1e-4 between
//! the nodes of a 256-evaluation rule) reads as zero everywhere and no rule
//! can report it: those cases are not asserted. A feature the nodes see but
//! do not resolve (one node carrying most of the sum, as at a narrow
//! Lorentzian) is flagged; where the nodes resolve it, the estimate must be
//! honest. Composite rules whose points do not nest the `4h` and `8h` rules
//! (a trapezoid at `n = 2^k - 1`) compare coarser rules with a finer tail,
//! so every point count has the differences that show a chance agreement.

use crate::common;
use common::rng;
use lightquad::quadrature::gauss_kronrod::XGK;
use lightquad::quadrature::{GaussKronrod, GaussLegendre, Rule, Simpson, Trapezoid};

/// How an integrand fails to be smooth (which decides what the rules owe it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Family {
    /// Analytic on `[0, 1]`: never doubted, estimates sharp.
    Smooth,
    /// An algebraic or logarithmic singularity at an end.
    Endpoint,
    /// A jump in the first derivative inside.
    Kink,
    /// A jump in the value inside.
    Jump,
}

/// One integrand of the battery with its closed-form integral over `[0, 1]`.
struct Integrand {
    /// What the messages call it.
    name: &'static str,
    /// The integrand.
    f: fn(f64) -> f64,
    /// `int_0^1 f(x) dx` in closed form.
    exact: f64,
    /// How it fails to be smooth.
    family: Family,
    /// Infinite at an end: only for rules that never evaluate the ends
    /// (Gauss–Legendre, Gauss–Kronrod).
    open_only: bool,
}

/// A jump of height 1 at `c`: `f = 0` below `c`, 1 from `c` on, so
/// `int_0^1 f = 1 - c`.
fn step(x: f64, c: f64) -> f64 {
    if x < c { 0.0 } else { 1.0 }
}

/// A point strictly between two Kronrod nodes of the first G7-K15 panel on
/// `[0, 1]`: halfway between its centre node 1/2 and the next node
/// `(1 + XGK[6])/2`, i.e. `1/2 + XGK[6]/4`; no dyadic bisection reaches it.
fn between_kronrod_nodes() -> f64 {
    0.5 + 0.25 * XGK[6]
}

/// A kink at `c`: `int_0^1 |x - c| = (c^2 + (1 - c)^2)/2`.
fn kink_integral(c: f64) -> f64 {
    0.5 * (c * c + (1.0 - c) * (1.0 - c))
}

/// The battery.
fn battery() -> Vec<Integrand> {
    use Family::*;
    let c = between_kronrod_nodes();
    vec![
        // int exp = e^x: e - 1.
        Integrand {
            name: "exp(x)",
            f: f64::exp,
            exact: std::f64::consts::E - 1.0,
            family: Smooth,
            open_only: false,
        },
        // Runge: int 1/(1 + 25x^2) = atan(5x)/5: atan(5)/5.
        Integrand {
            name: "1/(1+25x^2)",
            f: |x| 1.0 / (1.0 + 25.0 * x * x),
            exact: 5f64.atan() / 5.0,
            family: Smooth,
            open_only: false,
        },
        // int cos(20x) = sin(20x)/20: sin(20)/20.
        Integrand {
            name: "cos(20x)",
            f: |x| (20.0 * x).cos(),
            exact: 20f64.sin() / 20.0,
            family: Smooth,
            open_only: false,
        },
        // int x^a = x^(a+1)/(a+1): 2/3 for a = 1/2.
        Integrand {
            name: "sqrt(x)",
            f: f64::sqrt,
            exact: 2.0 / 3.0,
            family: Endpoint,
            open_only: false,
        },
        // int (1-x)^(1/2) = -(2/3)(1-x)^(3/2): 2/3.
        Integrand {
            name: "sqrt(1-x)",
            f: |x| (1.0 - x).sqrt(),
            exact: 2.0 / 3.0,
            family: Endpoint,
            open_only: false,
        },
        // int x^(3/2) = (2/5) x^(5/2): 2/5.
        Integrand {
            name: "x^1.5",
            f: |x| x * x.sqrt(),
            exact: 0.4,
            family: Endpoint,
            open_only: false,
        },
        // int ln x = x ln x - x: -1 (x ln x -> 0 at 0).
        Integrand {
            name: "ln(x)",
            f: f64::ln,
            exact: -1.0,
            family: Endpoint,
            open_only: true,
        },
        // int x^(-1/2) = 2 x^(1/2): 2.
        Integrand {
            name: "x^-0.5",
            f: |x| 1.0 / x.sqrt(),
            exact: 2.0,
            family: Endpoint,
            open_only: true,
        },
        // int |x - a| = (a^2 + (1-a)^2)/2: 5/18 for a = 1/3.
        Integrand {
            name: "|x-1/3|",
            f: |x| (x - 1.0 / 3.0).abs(),
            exact: 5.0 / 18.0,
            family: Kink,
            open_only: false,
        },
        // The same with a = 1/2: 1/4.
        Integrand {
            name: "|x-0.5|",
            f: |x| (x - 0.5).abs(),
            exact: 0.25,
            family: Kink,
            open_only: false,
        },
        Integrand {
            name: "|x-0.7311|",
            f: |x| (x - 0.7311).abs(),
            exact: kink_integral(0.7311),
            family: Kink,
            open_only: false,
        },
        // Steps: int_0^1 step(x, c) = 1 - c.
        Integrand {
            name: "step at 1/3",
            f: |x| step(x, 1.0 / 3.0),
            exact: 1.0 - 1.0 / 3.0,
            family: Jump,
            open_only: false,
        },
        Integrand {
            name: "step at 0.5",
            f: |x| step(x, 0.5),
            exact: 0.5,
            family: Jump,
            open_only: false,
        },
        Integrand {
            name: "step at 0.7311",
            f: |x| step(x, 0.7311),
            exact: 1.0 - 0.7311,
            family: Jump,
            open_only: false,
        },
        Integrand {
            name: "step between Kronrod nodes",
            f: |x| step(x, between_kronrod_nodes()),
            exact: 1.0 - c,
            family: Jump,
            open_only: false,
        },
    ]
}

/// The budgets every rule is run at (`2^k + 1`: whole composite rules).
const BUDGETS: [usize; 6] = [17, 65, 257, 1025, 4097, 65537];

/// One rule's result on one integrand at one budget.
#[derive(Debug, Clone)]
struct Outcome {
    /// Integrand name.
    integrand: &'static str,
    /// How the integrand fails to be smooth.
    family: Family,
    /// Rule name.
    rule: &'static str,
    /// Budget.
    n: usize,
    /// The rule's error estimate.
    estimate: f64,
    /// `|value - exact|`.
    truth: f64,
    /// True error relative to `max(1, |exact|)`.
    relative: f64,
    /// Whether the rule trusts its estimate.
    reliable: bool,
}

impl Outcome {
    /// Estimate over true error.
    fn ratio(&self) -> f64 {
        self.estimate / self.truth
    }

    /// The line a failure message shows.
    fn describe(&self) -> String {
        format!(
            "{} ({:?}) by {} at n = {}: estimate {:.3e}, true error {:.3e} (ratio {:.2e}), reliable {}",
            self.integrand,
            self.family,
            self.rule,
            self.n,
            self.estimate,
            self.truth,
            self.ratio(),
            self.reliable
        )
    }
}

/// Runs `rule` over every integrand of `family` (or all when `None`) it can
/// take, at every budget.
fn run_rule(rule: &impl Rule, open: bool, family: Option<Family>) -> Vec<Outcome> {
    let mut out = Vec::new();
    for g in battery() {
        if (g.open_only && !open) || family.is_some_and(|f| f != g.family) {
            continue;
        }
        for n in BUDGETS {
            let f = g.f;
            let est = rule
                .integrate(n, &mut rng(0), |p: [f64; 1]| f(p[0]))
                .unwrap_or_else(|e| panic!("{} by {} at n = {n}: {e}", g.name, rule.name()));
            let truth = (est.value - g.exact).abs();
            out.push(Outcome {
                integrand: g.name,
                family: g.family,
                rule: rule.name(),
                n,
                estimate: est.error,
                truth,
                relative: truth / g.exact.abs().max(1.0),
                reliable: est.reliable,
            });
        }
    }
    out
}

/// True errors at or below this (relative to `max(1, |I|)`) are rounding:
/// no estimate is owed there.
const ROUNDING: f64 = 1e-13;
/// An honest estimate is at least this fraction of the true error.
const HONEST: f64 = 0.1;

/// Every outcome above rounding has an estimate of at least a tenth of the
/// true error, or a doubted one.
fn assert_honest(outcomes: &[Outcome]) {
    let lies: Vec<String> = outcomes
        .iter()
        .filter(|o| {
            o.relative > ROUNDING && o.reliable && (o.ratio().is_nan() || o.ratio() < HONEST)
        })
        .map(Outcome::describe)
        .collect();
    assert!(
        lies.is_empty(),
        "unflagged estimates below {HONEST} of the true error:\n{}",
        lies.join("\n")
    );
}

/// Every rule on every non-smooth family with the ends it may evaluate.
fn non_smooth(rule: &impl Rule, open: bool) -> Vec<Outcome> {
    [Family::Endpoint, Family::Kink, Family::Jump]
        .into_iter()
        .flat_map(|family| run_rule(rule, open, Some(family)))
        .collect()
}

#[test]
fn gauss_legendre_estimate_is_honest_under_algebraic_convergence() {
    assert_honest(&non_smooth(&GaussLegendre::default(), true));
}

#[test]
fn gauss_kronrod_estimate_is_honest_on_jumps_kinks_and_singularities() {
    assert_honest(&non_smooth(&GaussKronrod::default(), true));
}

#[test]
fn trapezoid_richardson_estimate_is_honest_when_the_order_drops() {
    assert_honest(&non_smooth(&Trapezoid, false));
}

#[test]
fn simpson_richardson_estimate_is_honest_when_the_order_drops() {
    assert_honest(&non_smooth(&Simpson, false));
}

/// Smooth integrands: never doubted, and the estimate at most `bound` times
/// the true error (above rounding). Measured worst cases on the battery:
/// Gauss–Legendre 4.8 (Runge at n = 17), trapezoid 160 (Runge at n = 17, where
/// the differences do not yet shrink by 4 and the undivided difference is
/// reported), Simpson 340 (cos(20x) at n = 17, likewise); 1e6 leaves room for
/// any pre-asymptotic budget without letting a rounding-level or
/// order-of-magnitude-wrong estimate through. Gauss–Kronrod keeps QUADPACK's
/// estimate on smooth pieces, which on one unresolved panel is pessimistic by
/// design (cos(20x) at n = 17: 0.61 against 1.3e-9, 4.7e8): 1e9 there.
fn assert_smooth_sharp(outcomes: &[Outcome], bound: f64) {
    let bad: Vec<String> = outcomes
        .iter()
        .filter(|o| {
            !o.reliable || (o.relative > ROUNDING && (o.ratio().is_nan() || o.ratio() > bound))
        })
        .map(Outcome::describe)
        .collect();
    assert!(
        bad.is_empty(),
        "smooth integrands doubted or estimated above {bound:e} times the true error:\n{}",
        bad.join("\n")
    );
}

#[test]
fn smooth_integrands_are_not_doubted_and_their_estimates_stay_sharp() {
    let smooth = Some(Family::Smooth);
    assert_smooth_sharp(&run_rule(&GaussLegendre::default(), true, smooth), 1e6);
    assert_smooth_sharp(&run_rule(&Trapezoid, false, smooth), 1e6);
    assert_smooth_sharp(&run_rule(&Simpson, false, smooth), 1e6);
    assert_smooth_sharp(&run_rule(&GaussKronrod::default(), true, smooth), 1e9);
}

#[test]
fn gauss_legendre_hybrid_estimate_costs_two_and_a_half_rules_and_can_be_switched_off() {
    // m = 1024: the rules of order 1023, 1022 and 512 cost 2557 more
    // evaluations.
    let f = |p: [f64; 1]| p[0].sqrt();
    let est = GaussLegendre::default()
        .integrate(1024, &mut rng(0), f)
        .expect("finite");
    assert_eq!(est.evaluations, 1024 + 1023 + 1022 + 512);
    let off = GaussLegendre {
        error_estimate: false,
    }
    .integrate(1024, &mut rng(0), f)
    .expect("finite");
    assert_eq!(off.evaluations, 1024);
    assert!(off.error.is_infinite() && off.reliable);
    // In two dimensions per axis: 32^2 + 31^2 + 30^2 + 16^2.
    let est2 = GaussLegendre::default()
        .integrate(1024, &mut rng(0), |p: [f64; 2]| (p[0] * p[1]).sqrt())
        .expect("finite");
    assert_eq!(est2.evaluations, 1024 + 961 + 900 + 256);
    // int_[0,1]^2 sqrt(xy) = (2/3)^2: algebraic in both axes, still honest.
    let truth = (est2.value - 4.0 / 9.0).abs();
    assert!(
        est2.error >= 0.1 * truth,
        "sqrt(xy) by gauss-legendre at n = 1024: estimate {:.3e}, true error {truth:.3e}",
        est2.error
    );
}

/// Estimates at random jump and kink positions (300 positions by the golden
/// ratio, 14 budgets from 31 to 8193, a step `[x > s]` with integral `1 - s`
/// and a kink `|x - s|` with integral `(s^2 + (1-s)^2)/2`): the share whose
/// estimate is below a tenth of the true error (above 1e-13) without the
/// rule doubting it. Measured: trapezoid 0 and Simpson 0 of 8400 (Simpson
/// was 578 with the unchecked `|d|/15`), Gauss–Legendre 0 of 8400 (14
/// while m = 31 still used the consecutive orders alone, 2 while an
/// inconsistent tail trusted a half order that agreed by chance: a kink at
/// s = 0.2907, m = 31, estimate 1.8e-7 against 1.1e-4), Gauss–Kronrod 0 of 6151 (was 293:
/// a jump between a panel's outermost node and its end was invisible to the
/// panel; the panels' extrapolations to their meeting points now see it).
/// The bounds hold those figures, so a regression fails.
#[test]
fn estimates_at_random_jump_and_kink_positions_rarely_lie() {
    use lightquad::quadrature::AnyRule;
    for (name, allowed) in [
        ("trapezoid", 0.0),
        ("simpson", 0.0),
        ("gauss-legendre", 0.0),
        ("gauss-kronrod", 0.0),
    ] {
        let rule = AnyRule::by_name(name).expect("a rule");
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(1);
        let (mut lies, mut total) = (0usize, 0usize);
        for k in 0..300 {
            let s = 0.05 + 0.9 * ((k as f64 * 0.618_033_988_749_895) % 1.0);
            for n in [
                31usize, 33, 63, 65, 127, 129, 255, 257, 511, 513, 1025, 2049, 4097, 8193,
            ] {
                for kink in [false, true] {
                    let f = |x: f64| {
                        if kink {
                            (x - s).abs()
                        } else if x > s {
                            1.0
                        } else {
                            0.0
                        }
                    };
                    let exact = if kink {
                        0.5 * (s * s + (1.0 - s) * (1.0 - s))
                    } else {
                        1.0 - s
                    };
                    let e = rule
                        .integrate::<1, f64, _, _>(n, &mut rng, |p: [f64; 1]| f(p[0]))
                        .expect("finite");
                    let truth = (e.value - exact).abs();
                    if truth > 1e-13 {
                        total += 1;
                        if e.error < 0.1 * truth && e.reliable {
                            lies += 1;
                        }
                    }
                }
            }
        }
        let share = lies as f64 / total as f64;
        assert!(
            share <= allowed,
            "{name}: {lies} of {total} estimates below a tenth of the true error, unflagged"
        );
    }
}

/// Counts `(lies, total)` over `cases`: a lie is an estimate below a tenth
/// of the true error (above 1e-13 relative to `max(1, |I|)`) that the rule
/// does not doubt.
fn tally(cases: impl Iterator<Item = (lightquad::Estimate<f64>, f64)>) -> (usize, usize) {
    let (mut lies, mut total) = (0, 0);
    for (e, exact) in cases {
        let truth = (e.value - exact).abs();
        if truth > ROUNDING * exact.abs().max(1.0) {
            total += 1;
            if e.reliable && (e.error.is_nan() || e.error < HONEST * truth) {
                lies += 1;
            }
        }
    }
    (lies, total)
}

/// An interior square-root cusp `|x - c|^0.5` at 200 random `c`, at every
/// budget `2^k + 1` from 17 to 16385 (node sets that nest the 4h and 8h
/// rules): `int_0^1 |x - c|^0.5 dx = (2/3) (c^1.5 + (1 - c)^1.5)` (the
/// antiderivative `-(2/3)(c - x)^1.5` below `c`, `(2/3)(x - c)^1.5` above).
/// Its error oscillates with `h`, so `Q_h` and `Q_2h` can agree by chance:
/// the single-ratio check let trapezoid estimates fall to 1.4e-3 of the
/// truth and Simpson's to 1.6e-4 (c = 0.5663, n = 2049); measured now:
/// no lie, smallest estimate/true 0.2, for the composite rules;
/// Gauss–Legendre one (below); Gauss–Kronrod one, its QUADPACK panel
/// estimate (c = 0.7788, n = 513: the cusp 4% into a panel of width 4.9e-4,
/// between its second and third nodes, where G7 and K15 agree by chance;
/// estimate 2.9e-10 against 1.0e-8). The bounds hold those figures, so a
/// regression fails. Budgets whose node sets do not nest the
/// coarser rules: the next test.
#[test]
fn estimates_at_random_square_root_cusps_do_not_lie() {
    use lightquad::quadrature::AnyRule;
    use rand::{RngExt, SeedableRng};
    let mut pick = rand_pcg::Pcg64::seed_from_u64(7);
    let cusps: Vec<f64> = (0..200).map(|_| pick.random_range(0.01..0.99)).collect();
    // Gauss–Legendre: one lie, at n = 17, c = 0.0105 (a cusp that close
    // to an end is half an endpoint singularity; estimate/true 0.025).
    for (name, allowed) in [
        ("trapezoid", 0),
        ("simpson", 0),
        ("gauss-legendre", 1),
        ("gauss-kronrod", 1),
    ] {
        let rule = AnyRule::by_name(name).expect("a rule");
        let cases = cusps.iter().flat_map(|&c| {
            let rule = &rule;
            (4..=14).map(move |k| {
                let n = (1usize << k) + 1;
                let exact = 2.0 / 3.0 * (c.powf(1.5) + (1.0 - c).powf(1.5));
                let e = rule
                    .integrate::<1, f64, _, _>(n, &mut rng(0), |p: [f64; 1]| {
                        (p[0] - c).abs().sqrt()
                    })
                    .expect("finite");
                (e, exact)
            })
        });
        let (lies, total) = tally(cases);
        assert!(
            lies <= allowed,
            "{name}: {lies} of {total} cusp estimates lie unflagged"
        );
    }
}

/// Narrow interior peaks, Lorentzians `1/(w^2 + (x - c)^2)` of width `w` =
/// 1e-2, 1e-3, 1e-4 at 50 random `c` (never on a node), budgets 17 to 60
/// and `2^k +- 1` up to 16385:
/// `int_0^1 = (atan((1 - c)/w) + atan(c/w)) / w` (antiderivative
/// `atan((x - c)/w)/w`). Where the nodes do not resolve the peak the true
/// error is up to its whole mass `~pi/w`, which no difference of rules on
/// those nodes bounds: the rules doubt the estimate (one node carries the
/// sum). Gauss–Legendre on `1/(1e-8 + (x - 0.3)^2)` at n = 18..50 and
/// Simpson lied unflagged by up to 1e-9 and 1e-7 before (GL 64, 341 and
/// 1583 lies at the three widths, Simpson 376, 1447, 2699, over 50 centres
/// and n = 2..60 and 17..16385). Measured now, of about 3200 each: no lie
/// for Gauss–Legendre, trapezoid and Simpson (trapezoid 1 and Simpson 5
/// while node sets that nest one difference only had no coarser level);
/// Gauss–Kronrod none from n = 15 (before: 18 of 1194 at w = 1e-4 from n =
/// 45, a peak between the two outermost nodes of a panel at a seam, and 51
/// more below 45, a peak by an end of [0, 1]; now doubted where the
/// outermost node holds half of its panel's sum, `peak_at_seam`). The
/// bounds hold these figures, so a regression fails.
#[test]
fn estimates_on_narrow_interior_peaks_are_honest_or_doubted() {
    use lightquad::quadrature::AnyRule;
    use rand::{RngExt, SeedableRng};
    let mut pick = rand_pcg::Pcg64::seed_from_u64(7);
    let centres: Vec<f64> = (0..50).map(|_| pick.random_range(0.01..0.99)).collect();
    let budgets: Vec<usize> = (17..=60)
        .chain((5..=14).flat_map(|k| [(1usize << k) - 1, (1 << k) + 1]))
        .collect();
    for name in ["trapezoid", "simpson", "gauss-legendre", "gauss-kronrod"] {
        let rule = AnyRule::by_name(name).expect("a rule");
        let from = if name == "gauss-kronrod" { 15 } else { 17 };
        for w in [1e-2, 1e-3, 1e-4] {
            let cases = centres.iter().flat_map(|&c| {
                let (rule, budgets) = (&rule, &budgets);
                budgets.iter().filter(move |&&n| n >= from).map(move |&n| {
                    let exact = (((1.0 - c) / w).atan() + (c / w).atan()) / w;
                    let e = rule
                        .integrate::<1, f64, _, _>(n, &mut rng(0), |p: [f64; 1]| {
                            1.0 / (w * w + (p[0] - c) * (p[0] - c))
                        })
                        .expect("finite");
                    (e, exact)
                })
            });
            let (lies, total) = tally(cases);
            // The measured counts (module doc above) are the bounds.
            assert!(
                lies == 0,
                "{name}, w = {w}: {lies} of {total} peak estimates lie unflagged"
            );
        }
    }
    // The probe's case: GL on 1/(1e-8 + (x - 0.3)^2), n = 18..50.
    let exact = (0.7e4f64.atan() + 0.3e4f64.atan()) * 1e4;
    let cases = (18..=50).map(|n| {
        let e = GaussLegendre::default()
            .integrate(n, &mut rng(0), |p: [f64; 1]| {
                1.0 / (1e-8 + (p[0] - 0.3).powi(2))
            })
            .expect("finite");
        (e, exact)
    });
    assert_eq!(tally(cases).0, 0);
}

/// Gauss–Legendre below 16 nodes on kinks `|x - c|` and jumps (200 random
/// `c`, m = 2..15): `int |x - c| = (c^2 + (1 - c)^2)/2`, `int [x >= c] =
/// 1 - c`. The consecutive orders agree by chance (estimates of exactly 0
/// against errors of 1e-4 and 1e-2, 301 and 205 of 2800 lies before): no
/// check holds at these orders, and the estimate is doubted.
#[test]
fn gauss_legendre_below_sixteen_nodes_is_doubted_on_kinks_and_jumps() {
    use rand::{RngExt, SeedableRng};
    let mut pick = rand_pcg::Pcg64::seed_from_u64(7);
    let mut total = 0;
    for _ in 0..200 {
        let c: f64 = pick.random_range(0.01..0.99);
        for m in 2..16 {
            let kink = GaussLegendre::default()
                .integrate(m, &mut rng(0), |p: [f64; 1]| (p[0] - c).abs())
                .expect("finite");
            let jump = GaussLegendre::default()
                .integrate(m, &mut rng(0), |p: [f64; 1]| step(p[0], c))
                .expect("finite");
            let (l, t) = tally([(kink, kink_integral(c)), (jump, 1.0 - c)].into_iter());
            assert_eq!(l, 0, "c = {c}, m = {m}");
            total += t;
        }
    }
    assert!(total > 5000, "{total} cases above rounding");
}

/// Product rules in two dimensions on a diagonal jump `[x + y < s]` and a
/// diagonal kink `|x + y - s|`, s in {0.37, 0.731, 0.9, 1.234, 1.5}, 5 to
/// 70 nodes per axis. With `t = x + y` (density `t` on [0, 1], `2 - t` on
/// [1, 2]): the area below the line is `s^2/2` for `s <= 1` and
/// `1 - (2 - s)^2/2` above (0.405 at s = 0.9); `int int |x + y - s| =
/// (1 - s) + 2 int_{t<s} (s - t) t dt = 1 - s + s^3/3` for `s <= 1`
/// (0.343 at 0.9), and `s - 1 + (2 - s)^3/3` above by the symmetry
/// `t -> 2 - t`. Measured: no lie on the jump for trapezoid, Simpson and
/// Gauss–Legendre (smallest estimate/true 0.11, 0.20, 0.25); on the kink
/// trapezoid and Simpson none (Simpson 4 of 355 while node sets that nest
/// one ratio only had no coarser level, m = 37..40) and Gauss–Legendre 1
/// of 330 (m = 21, 0.066): the bound allows that, so a regression fails.
#[test]
fn product_rules_on_diagonal_jumps_and_kinks_rarely_lie() {
    use lightquad::quadrature::AnyRule;
    for (name, allowed_jump, allowed_kink) in [
        ("trapezoid", 0, 0),
        ("simpson", 0, 0),
        ("gauss-legendre", 0, 1),
    ] {
        let rule = AnyRule::by_name(name).expect("a rule");
        let (mut jump, mut kink) = (Vec::new(), Vec::new());
        for s in [0.9f64, 0.37, 0.731, 1.234, 1.5] {
            let area = if s <= 1.0 {
                s * s / 2.0
            } else {
                1.0 - (2.0 - s) * (2.0 - s) / 2.0
            };
            let mean = if s <= 1.0 {
                1.0 - s + s.powi(3) / 3.0
            } else {
                s - 1.0 + (2.0 - s).powi(3) / 3.0
            };
            for m in 5..=70usize {
                let n = m * m;
                let e = rule
                    .integrate::<2, f64, _, _>(n, &mut rng(0), |p: [f64; 2]| {
                        if p[0] + p[1] < s { 1.0 } else { 0.0 }
                    })
                    .expect("finite");
                jump.push((e, area));
                let e = rule
                    .integrate::<2, f64, _, _>(n, &mut rng(0), |p: [f64; 2]| {
                        (p[0] + p[1] - s).abs()
                    })
                    .expect("finite");
                kink.push((e, mean));
            }
        }
        let (lj, tj) = tally(jump.into_iter());
        let (lk, tk) = tally(kink.into_iter());
        assert!(lj <= allowed_jump, "{name} diagonal jump: {lj} of {tj} lie");
        assert!(lk <= allowed_kink, "{name} diagonal kink: {lk} of {tk} lie");
    }
}

/// Gauss–Kronrod spends its budget (with no tolerance) even where every
/// node reads zero, so a narrow Gaussian `exp(-((x - c)/w)^2)` is found once
/// the budget's even refinement puts a node on it:
/// `int_0^1 = w sqrt(pi)/2 (erf((1 - c)/w) + erf(c/w)) = w sqrt(pi)` to
/// f64 precision for `w <= 1e-3` and `c` in [0.1, 0.9] (`erfc(100) < 1e-4000`).
/// A Gaussian narrower than every node spacing of the budget reads zero at
/// every node and is undetectable by any rule: not asserted.
#[test]
fn gauss_kronrod_spends_the_budget_and_finds_a_narrow_gaussian() {
    use rand::{RngExt, SeedableRng};
    let w = 1e-3;
    let exact = w * std::f64::consts::PI.sqrt();
    let mut pick = rand_pcg::Pcg64::seed_from_u64(7);
    for _ in 0..50 {
        let c: f64 = 0.1 + 0.8 * pick.random_range(0.0..1.0);
        for n in [256usize, 1000, 4096] {
            let e = GaussKronrod::default()
                .integrate(n, &mut rng(0), |p: [f64; 1]| {
                    (-((p[0] - c) / w).powi(2)).exp()
                })
                .expect("finite");
            // Two panels a bisection: the budget is spent to within 29.
            assert!(
                e.evaluations as usize + 30 > n && e.evaluations as usize <= n,
                "{n}: {}",
                e.evaluations
            );
            let truth = (e.value - exact).abs();
            assert!(
                truth <= 0.1 * exact && (e.error >= HONEST * truth || !e.reliable),
                "c = {c}, n = {n}: value {} (exact {exact}), estimate {:.2e}",
                e.value,
                e.error
            );
        }
    }
}

/// The cusp sweep of [`estimates_at_random_square_root_cusps_do_not_lie`]
/// at budgets whose node sets do not nest the `4h` and `8h` rules: every
/// odd count from 17 to 129 and `2^k - 1`, `3 2^k - 1` up to 12287 (a
/// budget of 1024 gives the trapezoid 1023 points, `1022 = 2 * 511`
/// intervals). There the coarser levels are composite rules on the coarse
/// points with a finer tail ([`lightquad::quadrature::nodes::coarse_weights`]).
/// Measured: 726 trapezoid lies of 15000 before (one difference, small by
/// chance), none now; Simpson none (2, c = 0.3208 at m = 109, while the
/// order check accepted ratios within 25% of 16: 12.17 and 12.07 there, 20%
/// now).
#[test]
fn composite_estimates_at_square_root_cusps_do_not_lie_at_any_point_count() {
    use lightquad::quadrature::AnyRule;
    use rand::{RngExt, SeedableRng};
    let mut pick = rand_pcg::Pcg64::seed_from_u64(11);
    let cusps: Vec<f64> = (0..200).map(|_| pick.random_range(0.01..0.99)).collect();
    let budgets: Vec<usize> = (17..=129)
        .step_by(2)
        .chain((5..=13).flat_map(|k| [(1usize << k) - 1, 3 * (1 << (k - 1)) - 1]))
        .collect();
    for name in ["trapezoid", "simpson"] {
        let rule = AnyRule::by_name(name).expect("a rule");
        let cases = cusps.iter().flat_map(|&c| {
            let (rule, budgets) = (&rule, &budgets);
            budgets.iter().map(move |&n| {
                let exact = 2.0 / 3.0 * (c.powf(1.5) + (1.0 - c).powf(1.5));
                let e = rule
                    .integrate::<1, f64, _, _>(n, &mut rng(0), |p: [f64; 1]| {
                        (p[0] - c).abs().sqrt()
                    })
                    .expect("finite");
                (e, exact)
            })
        });
        let (lies, total) = tally(cases);
        assert!(
            lies == 0,
            "{name}: {lies} of {total} cusp estimates lie unflagged"
        );
    }
}

/// The periodic `1/(1 + a sin(2 pi m x))` (integral `1/sqrt(1 - a^2)` for
/// every whole `m`), `a` 0.5 and 0.99, `m` 1 and 3, at every odd point count
/// from 17 to 129 and at `2^k +- 1`, `3 2^(k-1) - 1` up to 16385: no
/// trapezoid or Simpson estimate lies unflagged. The trapezoid converges
/// faster than any power here, and where the two finest rules agreed to
/// rounding the coarser differences were capped; by the symmetry of `sin`
/// they can agree while both are off (47 points, `a = 0.99`, `m = 1`: the
/// 24-point rule matched to 1e-11, both 2e-2 off; the estimate was 9.4e-12).
/// Now three rules must agree. Left out, as nothing in the samples shows it:
/// aliasing, where the nodes see the function's period as a slow one or as
/// a constant (`m = 40` at 17 points reads 1 at every node), and the peak of
/// `a = 0.99` (width 0.023 of a period) under fewer than 16 nodes a period
/// (`m = 3` at 19 and 31 points: estimates 0.09 and 0.02 of the error).
#[test]
fn composite_estimates_on_periodic_integrands_do_not_lie() {
    use lightquad::quadrature::AnyRule;
    use std::f64::consts::PI;
    let budgets: Vec<usize> = (17..=129)
        .step_by(2)
        .chain((5..=14).flat_map(|k| [(1usize << k) - 1, (1 << k) + 1, 3 * (1 << (k - 1)) - 1]))
        .collect();
    for name in ["trapezoid", "simpson"] {
        let rule = AnyRule::by_name(name).expect("a rule");
        let mut cases = vec![];
        for a in [0.5f64, 0.99] {
            for m in [1.0, 3.0] {
                for &n in &budgets {
                    if a > 0.9 && ((n - 1) as f64) < 16.0 * m {
                        // A missed peak: fewer than 16 nodes a period.
                        continue;
                    }
                    let e = rule
                        .integrate::<1, f64, _, _>(n, &mut rng(0), |p: [f64; 1]| {
                            1.0 / (1.0 + a * (2.0 * PI * m * p[0]).sin())
                        })
                        .expect("finite");
                    cases.push((e, 1.0 / (1.0 - a * a).sqrt()));
                }
            }
        }
        let (lies, total) = tally(cases.into_iter());
        assert!(
            lies == 0,
            "{name}: {lies} of {total} periodic estimates lie unflagged"
        );
    }
}

/// Gauss–Legendre at an endpoint singularity `x^-a` and `(1 - x)^-a`,
/// a = 0.9 and 0.5 (integrals `1/(1 - a)`, 10 and 2; the error falls as
/// `m^-(2 - 2a)`), 4097 to 131073 evaluations: the estimate is at least a
/// tenth of the error at either end. The consecutive-order tail rests on
/// `1 - r ~ (p + 1)/m`, which the rounding of the node nearest 1 upsets at
/// the right end (0.093 at 32769 before the algebraic-order estimate from
/// the halving difference); at the left end the estimate was 0.333 of the
/// error, now 1.00. `(1 - x)^-0.5` at 32769 evaluations stayed at 0.096
/// while the ratio `r` gated the algebraic estimate (rounding gave
/// `m (1 - r) = 22`, "geometric"); the order from `D` and `d2` is 1.00, the
/// estimate 1.00 of the error.
#[test]
fn gauss_legendre_estimate_is_honest_at_either_endpoint_singularity() {
    for a in [0.9f64, 0.5] {
        for n in [4097usize, 16385, 32769, 65537, 131073] {
            for right in [false, true] {
                let e = GaussLegendre::default()
                    .integrate(n, &mut rng(0), |p: [f64; 1]| {
                        if right { 1.0 - p[0] } else { p[0] }.powf(-a)
                    })
                    .expect("finite");
                let truth = (e.value - 1.0 / (1.0 - a)).abs();
                assert!(
                    e.error >= 0.1 * truth,
                    "a = {a}, n = {n}, right end {right}: estimate {:e} against {truth:e}",
                    e.error
                );
            }
        }
    }
}

/// Stratified sampling of a peak narrower than a cell that no sample hit:
/// the samples saw its flanks only (a Gaussian of width 1e-3 read as 1e-300
/// +- 1e-299) and the estimate lied unflagged (an independent check found
/// 697 of 13936 battery cases, 588 of them peaks and Gaussians).
/// Over 40 interior centres, widths 1e-3 and 1e-4 and 16 budgets from 5 to
/// 1025 cells, counted against the closed forms `int exp(-((x - c) /
/// w)^2) = w sqrt(pi) / 2 (erf((1 - c) / w) + erf(c / w))` and the
/// Lorentzian's arctangents.
#[test]
fn stratified_estimates_of_peaks_between_samples_are_doubted() {
    use lightquad::quadrature::AnyRule;
    use rand::{RngExt, SeedableRng};
    let rule = AnyRule::by_name("stratified").expect("a rule");
    let mut pick = rand_pcg::Pcg64::seed_from_u64(11);
    let centres: Vec<f64> = (0..40).map(|_| pick.random_range(0.05..0.95)).collect();
    let budgets = [
        5usize, 7, 9, 13, 16, 24, 33, 48, 64, 100, 128, 200, 256, 513, 777, 1025,
    ];
    let (mut lies, mut total) = (0usize, 0usize);
    for &w in &[1e-3f64, 1e-4] {
        for (i, &c) in centres.iter().enumerate() {
            let gauss = w * std::f64::consts::PI.sqrt() / 2.0
                * (statrs::function::erf::erf((1.0 - c) / w) + statrs::function::erf::erf(c / w));
            let lorentz = (((1.0 - c) / w).atan() + (c / w).atan()) / w;
            for &n in &budgets {
                let seed = (i * 100 + n) as u64;
                let g = rule
                    .integrate::<1, f64, _, _>(n, &mut rng(seed), |p: [f64; 1]| {
                        (-((p[0] - c) / w).powi(2)).exp()
                    })
                    .expect("finite");
                let l = rule
                    .integrate::<1, f64, _, _>(n, &mut rng(seed), |p: [f64; 1]| {
                        1.0 / (w * w + (p[0] - c).powi(2))
                    })
                    .expect("finite");
                let (a, b) = tally([(g, gauss), (l, lorentz)].into_iter());
                lies += a;
                total += b;
            }
        }
    }
    eprintln!("stratified interior peaks: {lies} of {total} lie unflagged");
    // Measured: 961 of 2560 before the check, 77 now (Lorentzian flanks,
    // which look like a resolved 1/x^2, and budgets of a few cells).
    assert!(
        lies * 25 <= total,
        "{lies} of {total} peak estimates lie unflagged"
    );
}

//! The adaptive Genz–Malik cubature against closed forms: exactness of the
//! degree-7 and degree-5 rules, a smooth product, the `1/r^2` peak of the
//! irradiance at a rectangle's corner at heights down to 1e-6 of its size
//! (Howell's B-3), and honest or doubted estimates across a jump and a kink.

use crate::common;
use common::rng;
use lightquad::exact::rendering::rectangle_corner;
use lightquad::quadrature::genz_malik::points_per_box;
use lightquad::quadrature::{AnyRule, GaussLegendre, GenzMalik, Rule};
use std::f64::consts::{E, PI};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// One box integrates every monomial `x^a y^b` of degree <= 7 exactly:
/// `int_0^1 int_0^1 x^a y^b = 1 / ((a + 1)(b + 1))`; in three dimensions
/// `x^a y^b z^c` likewise. The embedded degree-5 rule agrees with it up to
/// degree 5 (error estimate at rounding) and not at degree 6 and 7.
#[test]
fn one_box_is_exact_to_degree_seven_and_its_estimate_to_degree_five() {
    for a in 0..=7i32 {
        for b in 0..=(7 - a) {
            let e = GenzMalik::default()
                .integrate(17, &mut rng(0), |p: [f64; 2]| p[0].powi(a) * p[1].powi(b))
                .expect("finite");
            let exact = 1.0 / f64::from((a + 1) * (b + 1));
            assert!(rel(e.value, exact) < 1e-14, "x^{a} y^{b}: {}", e.value);
            assert_eq!(e.evaluations, 17);
            if a + b <= 5 {
                assert!(e.error < 1e-15, "x^{a} y^{b}: estimate {}", e.error);
            } else if a + b == 6 && (a == 0 || b == 0) {
                // The degree-5 rule misses x^6 (its error is what is shown).
                assert!(e.error > 1e-6, "x^{a} y^{b}: estimate {}", e.error);
            }
        }
    }
    for (a, b, c) in [(7, 0, 0), (3, 2, 2), (1, 1, 5), (2, 2, 3)] {
        let e = GenzMalik::default()
            .integrate(points_per_box(3), &mut rng(0), |p: [f64; 3]| {
                p[0].powi(a) * p[1].powi(b) * p[2].powi(c)
            })
            .expect("finite");
        let exact = 1.0 / f64::from((a + 1) * (b + 1) * (c + 1));
        assert!(rel(e.value, exact) < 1e-14, "{a} {b} {c}: {}", e.value);
    }
    assert_eq!(points_per_box(2), 17);
    assert_eq!(points_per_box(3), 33);
}

/// `int int e^(x + y) = (e - 1)^2`: the error falls with the budget, the
/// estimate stays above it, and the budget is spent to within one bisection.
/// Every run past one box passes the check against its own history.
#[test]
fn a_smooth_integrand_converges_with_an_honest_estimate_and_the_budget_kept() {
    let exact = (E - 1.0) * (E - 1.0);
    let mut last = f64::INFINITY;
    for n in [17usize, 100, 1000, 10_000] {
        let e = GenzMalik::default()
            .integrate(n, &mut rng(0), |p: [f64; 2]| (p[0] + p[1]).exp())
            .expect("finite");
        let truth = (e.value - exact).abs();
        eprintln!(
            "e^(x+y) n = {n}: error {truth:.2e}, estimate {:.2e}",
            e.error
        );
        assert!(e.evaluations as usize <= n && e.evaluations as usize + 34 > n);
        assert!(truth <= last || truth < 1e-15);
        // One box (17 evaluations) is doubted: nothing checks its estimate.
        assert!(e.error >= truth && e.reliable == (n > 17), "n = {n}");
        last = truth;
    }
    assert!(last < 1e-14 * exact, "{last}");
}

/// The irradiance at a rectangle's corner from height `c` is Howell's B-3
/// form factor: `int_0^a int_0^b c^2 / (pi (x^2 + y^2 + c^2)^2) dx dy`. At
/// `c` = 1e-3 and 1e-6 of a unit square the integrand is a peak of height
/// `1/(pi c^2)` and width `c` at a corner: Gauss–Legendre products keep a
/// large error at 4096 nodes, the adaptive rule reaches 1e-10 relative, and
/// its estimate is above its error.
#[test]
fn the_irradiance_peak_at_a_corner_reaches_1e_minus_10_at_heights_down_to_1e_minus_6() {
    for (c, budget) in [(1e-3, 100_000usize), (1e-6, 300_000)] {
        let exact = rectangle_corner(1.0, 1.0, c).expect("valid");
        let f = |p: [f64; 2]| {
            let r2 = p[0] * p[0] + p[1] * p[1] + c * c;
            c * c / (PI * r2 * r2)
        };
        let gl = GaussLegendre::default()
            .integrate(4096, &mut rng(0), f)
            .expect("finite");
        let e = GenzMalik::default()
            .integrate(budget, &mut rng(0), f)
            .expect("finite");
        let truth = rel(e.value, exact);
        eprintln!(
            "c = {c:e}: F = {exact}, Gauss-Legendre 64^2 {:.2e}, genz-malik {budget}: {truth:.2e} (estimate {:.2e})",
            rel(gl.value, exact),
            e.error / exact
        );
        assert!(rel(gl.value, exact) > 1e-3);
        assert!(truth < 1e-10, "c = {c}: {truth:e}");
        assert!(e.error >= (e.value - exact).abs() || !e.reliable);
    }
}

/// A diagonal jump `[x + y < s]` (area `s^2/2` for `s <= 1`, `1 - (2 -
/// s)^2/2` above) and a diagonal kink `|x + y - s|` (`1 - s + s^3/3` for `s
/// <= 1`, `s - 1 + (2 - s)^3/3` above), 5 positions, 12 budgets: every
/// estimate is at least a tenth of the true error or doubted.
#[test]
fn estimates_across_a_jump_and_a_kink_are_honest_or_doubted() {
    let mut total = 0;
    for s in [0.37f64, 0.731, 0.9, 1.234, 1.5] {
        let area = if s <= 1.0 {
            s * s / 2.0
        } else {
            1.0 - (2.0 - s).powi(2) / 2.0
        };
        let mean = if s <= 1.0 {
            1.0 - s + s.powi(3) / 3.0
        } else {
            s - 1.0 + (2.0 - s).powi(3) / 3.0
        };
        for n in [
            17usize, 51, 85, 153, 289, 561, 1000, 2000, 4000, 8000, 16000, 32000,
        ] {
            let jump = GenzMalik::default()
                .integrate(n, &mut rng(0), |p: [f64; 2]| f64::from(p[0] + p[1] < s))
                .expect("finite");
            let kink = GenzMalik::default()
                .integrate(n, &mut rng(0), |p: [f64; 2]| (p[0] + p[1] - s).abs())
                .expect("finite");
            for (e, exact, what) in [(jump, area, "jump"), (kink, mean, "kink")] {
                let truth = (e.value - exact).abs();
                if truth > 1e-13 {
                    total += 1;
                    assert!(
                        e.error >= 0.1 * truth || !e.reliable,
                        "{what} s = {s}, n = {n}: estimate {:e} against {truth:e}",
                        e.error
                    );
                }
            }
        }
    }
    assert!(total > 100, "{total}");
}

/// A disk's shadow boundary, `[x^2 + y^2 < r^2]` (area `pi r^2 / 4` for
/// `r <= 1`), at 40 random radii and 8 budgets from 51 to 300000: every
/// estimate is at least a tenth of the true error or doubted.
#[test]
fn estimates_across_a_circular_shadow_boundary_are_honest_or_doubted() {
    use rand::{RngExt, SeedableRng};
    let mut pick = rand_pcg::Pcg64::seed_from_u64(3);
    let mut total = 0;
    for _ in 0..40 {
        let r: f64 = pick.random_range(0.05..0.95);
        let area = PI * r * r / 4.0;
        for n in [51usize, 289, 1000, 3000, 10_000, 30_000, 100_000, 300_000] {
            let e = GenzMalik::default()
                .integrate(n, &mut rng(0), |p: [f64; 2]| {
                    f64::from(p[0] * p[0] + p[1] * p[1] < r * r)
                })
                .expect("finite");
            let truth = (e.value - area).abs();
            if truth > 1e-13 {
                total += 1;
                assert!(
                    e.error >= 0.1 * truth || !e.reliable,
                    "disk r = {r}, n = {n}: estimate {:e} against {truth:e}",
                    e.error
                );
            }
        }
    }
    assert!(total > 200, "{total}");
}

/// A product of Lorentzian peaks `1/(((x - a)^2 + w^2)((y - b)^2 + w^2))`
/// (integral the product of `(atan((1 - a)/w) + atan(a/w)) / w` and its `b`
/// twin), a cross of two ridges of width `w` with `1/r^2` tails: at 6
/// centres, `w` from 0.1 to 1e-3 and budgets from 1023 to 16383, every
/// estimate is at least a tenth of the true error or doubted. The boxes
/// find the ridges late; before the check against the run's history
/// (`|Q - Q_half| <= E + E_half`) estimates fell to 0.024 of the error at
/// `w = 1e-3` and 2047 evaluations. One box alone is always doubted. Below
/// about 700 evaluations at `w = 1e-3` the peak stays unseen at every
/// doubling (the value holds at 1% of the integral), and nothing in the
/// samples shows it: those budgets are left out, as a missed feature.
#[test]
fn estimates_on_product_peaks_are_honest_or_doubted() {
    let line = |c: f64, w: f64| (((1.0 - c) / w).atan() + (c / w).atan()) / w;
    let mut total = 0;
    for (a, b) in [
        (0.3, 0.3),
        (0.3, 0.7),
        (0.123, 0.456),
        (0.5, 0.5),
        (0.25, 0.75),
        (0.618_033_988_7, 0.1),
    ] {
        for w in [1e-1, 1e-2, 1e-3] {
            let exact = line(a, w) * line(b, w);
            for n in [1023usize, 2047, 3071, 4095, 6143, 8191, 16383] {
                let e = GenzMalik::default()
                    .integrate(n, &mut rng(0), |p: [f64; 2]| {
                        1.0 / (((p[0] - a).powi(2) + w * w) * ((p[1] - b).powi(2) + w * w))
                    })
                    .expect("finite");
                let truth = (e.value - exact).abs();
                if truth > 1e-13 * exact {
                    total += 1;
                    assert!(
                        e.error >= 0.1 * truth || !e.reliable,
                        "peak ({a}, {b}) w = {w}, n = {n}: estimate {:e} against {truth:e}",
                        e.error
                    );
                }
            }
        }
        // One box: its |G7 - G5| is checked by nothing.
        let one = GenzMalik::default()
            .integrate(17, &mut rng(0), |p: [f64; 2]| {
                1.0 / (((p[0] - a).powi(2) + 1e-6) * ((p[1] - b).powi(2) + 1e-6))
            })
            .expect("finite");
        assert!(!one.reliable, "one box at ({a}, {b})");
    }
    assert!(total > 100, "{total}");
}

/// Wrong input is an error, not a panic: one dimension, a budget below one
/// box, a negative tolerance; the registry knows the rule by name.
#[test]
fn bad_input_is_an_error() {
    let e = GenzMalik::default()
        .integrate(100, &mut rng(0), |p: [f64; 1]| p[0])
        .expect_err("1-D");
    assert!(e.to_string().contains("dimension 1"), "{e}");
    let e = GenzMalik::default()
        .integrate(16, &mut rng(0), |p: [f64; 2]| p[0])
        .expect_err("small");
    assert!(e.to_string().contains("at least 17"), "{e}");
    let e = GenzMalik {
        abs_tol: -1.0,
        rel_tol: 0.0,
    }
    .integrate(100, &mut rng(0), |p: [f64; 2]| p[0])
    .expect_err("tol");
    assert!(e.to_string().contains("abs_tol"), "{e}");
    let rule = AnyRule::by_name("genz-malik").expect("registered");
    let e = rule
        .integrate(17, &mut rng(0), |p: [f64; 2]| p[0] * p[1])
        .expect("finite");
    assert!(rel(e.value, 0.25) < 1e-15);
    // A tolerance stops early.
    let e = GenzMalik {
        abs_tol: 0.0,
        rel_tol: 1e-8,
    }
    .integrate(1_000_000, &mut rng(0), |p: [f64; 2]| (p[0] + p[1]).exp())
    .expect("finite");
    assert!(
        e.evaluations < 10_000 && e.error <= 1e-8 * e.value,
        "{}",
        e.evaluations
    );
}

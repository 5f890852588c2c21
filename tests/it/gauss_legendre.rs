//! Gauss–Legendre against independent references: 40-digit tables (mpmath,
//! scripts/gen_quadrature_reference.py), polynomial exactness with the closed-form
//! error of the first inexact degree, and integrals with closed forms at
//! n = 1e3, 1e5, 1e6.
//!
//! Tolerances: n <= 100 (compiled-in tables, correctly rounded from 60-digit
//! values) within one ulp of the 40-digit tables and of Newton's method in
//! double-double, an independent computation at every n <= 100; n > 100 (Bogaert's expansion, evaluated with a
//! double-double angle) within 1 eps absolute for nodes and 2 eps relative for
//! `1 - |x|` and the weights (measured worst: 0.5 and 1.2).

use crate::common;
use common::*;
use lightquad::QuadError;
use lightquad::quadrature::gauss_legendre::{
    TABLE_MAX_ORDER, bogaert, half_node, newton, table, unit_nodes,
};
use lightquad::quadrature::{GaussLegendre, Rule};

#[test]
fn nodes_and_weights_match_40_digit_tables_for_n_up_to_100() {
    let small = data("gauss_legendre_small.json");
    let rules = small["rules"].as_array().expect("rules");
    assert_eq!(rules.len(), 29);
    for r in rules {
        let n = r["n"].as_u64().expect("n") as usize;
        let (x, w) = (nums(&r["nodes"]), nums(&r["weights"]));
        let t = table(n).expect("valid n");
        for i in 0..n {
            assert!(
                (t.x()[i] - x[i]).abs() <= EPS * x[i].abs().max(0.5),
                "n={n} i={i}: x {} vs {}",
                t.x()[i],
                x[i]
            );
            assert!(
                rel(t.w()[i], w[i]) <= EPS,
                "n={n} i={i}: w {} vs {} ({:.1} ulps)",
                t.w()[i],
                w[i],
                rel(t.w()[i], w[i]) / EPS
            );
            // The table only has x rounded to f64, so 1 - |x| is known to
            // an absolute ulp here (the large-n test checks it relatively).
            let k = if x[i] < 0.0 { i + 1 } else { n - i };
            assert!(
                (half_node(n, k).expect("valid node").one_minus_x - (1.0 - x[i].abs())).abs()
                    <= EPS
            );
        }
    }
}

/// Distance in ulps between two finite f64 of the same sign (0 to 0 is 0).
fn ulps(a: f64, b: f64) -> u64 {
    if a == b {
        return 0;
    }
    (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
}

#[test]
fn compiled_table_matches_newton_in_double_double_for_every_n_up_to_100() {
    // The table was rounded from 60-digit values by a script; Newton's method
    // on the three-term recurrence, finished in double-double in the crate,
    // computes the same rules independently (from Bogaert's start). Every
    // node, 1 - x and weight agrees to one ulp.
    assert_eq!(TABLE_MAX_ORDER, 100);
    let mut worst = [0u64; 3];
    for n in 1..=TABLE_MAX_ORDER {
        for k in 1..=n.div_ceil(2) {
            let t = half_node(n, k).expect("valid node");
            let r = newton::node(n, k, bogaert::node(n, k).expect("valid")).expect("valid");
            let d = [
                ulps(t.x, r.x),
                ulps(t.one_minus_x, r.one_minus_x),
                ulps(t.weight, r.weight),
            ];
            for (w, d) in worst.iter_mut().zip(d) {
                *w = (*w).max(d);
            }
            assert!(
                d.iter().all(|&d| d <= 1),
                "n={n} k={k}: table {t:?} vs Newton {r:?} ({d:?} ulps)"
            );
        }
    }
    eprintln!("table vs Newton-DD, worst ulps (x, 1 - x, w): {worst:?}");
}

#[test]
fn tabulated_rules_are_symmetric_sum_to_one_and_exact_for_degree_2n_minus_1() {
    for n in 1..=TABLE_MAX_ORDER {
        // table() mirrors the half rule: ascending, x[i] = -x[n-1-i].
        let t = table(n).expect("valid n");
        assert_eq!((t.x().len(), t.w().len()), (n, n));
        for i in 0..n {
            assert_eq!(t.x()[i], -t.x()[n - 1 - i], "n={n} i={i}");
            assert_eq!(t.w()[i], t.w()[n - 1 - i], "n={n} i={i}");
            if i > 0 {
                assert!(t.x()[i - 1] < t.x()[i], "n={n} i={i}: not ascending");
            }
        }
        // On [0, 1]: sum w = 1 (each weight is rounded once, so to half an
        // ulp of the sum) and int_0^1 u^(2n-1) du = 1/(2n).
        let unit = unit_nodes(n).expect("valid n");
        let sum_w = lightquad::sum::sum_f64(unit.w.iter().copied());
        assert!((sum_w - 1.0).abs() <= EPS, "n={n}: sum w = {sum_w}");
        let d = 2 * n as i32 - 1;
        let got = 0.5 * shifted_monomial(&t, d);
        let exact = 1.0 / (2.0 * n as f64);
        assert!(rel(got, exact) <= 1e-14, "n={n}: {got} vs {exact}");
    }
}

#[test]
fn sampled_nodes_match_40_digit_values_for_large_n() {
    let large = data("gauss_legendre_large.json");
    for r in large["rules"].as_array().expect("rules") {
        let n = r["n"].as_u64().expect("n") as usize;
        let t = table(n).expect("valid n");
        for node in r["nodes"].as_array().expect("nodes") {
            // k = 1 is the largest node: index n - k ascending; the mirror is k - 1.
            let k = node["k"].as_u64().expect("k") as usize;
            let (x, y, w) = (
                num(&node["x"]),
                num(&node["one_minus_x"]),
                num(&node["weight"]),
            );
            for (i, sign) in [(n - k, 1.0), (k - 1, -1.0)] {
                assert!(
                    (t.x()[i] - sign * x).abs() <= EPS,
                    "n={n} k={k}: x {} vs {}",
                    t.x()[i],
                    sign * x
                );
                let got = half_node(n, k).expect("valid node").one_minus_x;
                assert!(
                    rel(got, y) <= 2.0 * EPS,
                    "n={n} k={k}: 1-|x| {got} vs {y} ({:.1} ulps)",
                    rel(got, y) / EPS
                );
                assert!(
                    rel(t.w()[i], w) <= 2.0 * EPS,
                    "n={n} k={k}: w {} vs {w} ({:.1} ulps)",
                    t.w()[i],
                    rel(t.w()[i], w) / EPS
                );
            }
        }
    }
}

/// `int_{-1}^{1} ((1 + x)/2)^d dx = 2/(d + 1)`, by the n-point rule.
///
/// `(1 + x)/2` is `1 - y/2` (`y = 1 - |x|`) for positive nodes; raising a
/// rounded base to the power 2n - 1 would amplify its rounding n-fold, so the
/// power is taken as `exp(d ln(1 - y/2))`, which the accurate `y` makes exact
/// to a few ulps.
fn shifted_monomial(t: &lightquad::quadrature::gauss_legendre::Table, d: i32) -> f64 {
    let n = t.x().len();
    lightquad::sum::sum_f64(
        t.x()
            .iter()
            .zip(t.w().iter())
            .enumerate()
            .map(|(i, (x, w))| {
                let k = if *x < 0.0 { i + 1 } else { n - i };
                let y = half_node(n, k).expect("valid node").one_minus_x;
                let power = if *x < 0.0 {
                    (0.5 * y).powi(d)
                } else {
                    (d as f64 * (-0.5 * y).ln_1p()).exp()
                };
                w * power
            }),
    )
}

#[test]
fn exact_for_degree_2n_minus_1() {
    for n in (1..=40).chain([50, 64, 99, 100, 101, 150, 500, 1000, 4096]) {
        let t = table(n).expect("valid n");
        let d = 2 * n as i32 - 1;
        let got = shifted_monomial(&t, d);
        let exact = 2.0 / (d as f64 + 1.0);
        assert!(rel(got, exact) <= 1e-14, "n={n}: {got} vs {exact}");
        // The even monomial of degree 2n - 2 as well (no odd-symmetry help).
        if n >= 2 {
            let got = shifted_monomial(&t, d - 1);
            assert!(rel(got, 2.0 / d as f64) <= 1e-14, "n={n}");
        }
    }
}

#[test]
fn not_exact_for_degree_2n_and_the_error_is_the_closed_form() {
    // E_n[x^(2n)] = int x^(2n) - Q_n = 2^(2n+1) (n!)^4 / ((2n+1) ((2n)!)^2) * ... which
    // for f = x^(2n) (f^(2n) = (2n)!) is 2^(2n+1) (n!)^4 / ((2n+1) ((2n)!)^2).
    // (Abramowitz & Stegun 25.4.30.)
    for n in 1..=12usize {
        let t = table(n).expect("valid n");
        let q = lightquad::sum::sum_f64(
            t.x()
                .iter()
                .zip(t.w().iter())
                .map(|(x, w)| w * x.powi(2 * n as i32)),
        );
        let exact = 2.0 / (2.0 * n as f64 + 1.0);
        let lgamma = |k: usize| (1..=k).map(|j| (j as f64).ln()).sum::<f64>();
        let predicted = ((2 * n + 1) as f64 * 2f64.ln() + 4.0 * lgamma(n)
            - ((2 * n + 1) as f64).ln()
            - 2.0 * lgamma(2 * n))
        .exp();
        let err = exact - q;
        assert!(
            err > 1e3 * EPS * exact,
            "n={n}: degree 2n should not be exact"
        );
        assert!(
            rel(err, predicted) < 1e-6,
            "n={n}: error {err} vs {predicted}"
        );
    }
}

#[test]
fn large_n_weights_sum_to_two_and_cos_50x_is_exact() {
    // int_{-1}^{1} cos(50 x) dx = 2 sin(50) / 50.
    let exact = 2.0 * 50f64.sin() / 50.0;
    for n in [1_000usize, 100_000, 1_000_000] {
        let t = table(n).expect("valid n");
        let sum_w = lightquad::sum::sum_f64(t.w().iter().copied());
        assert!((sum_w - 2.0).abs() <= 1e-13, "n={n}: sum w = {sum_w}");
        let q = lightquad::sum::sum_f64(
            t.x()
                .iter()
                .zip(t.w().iter())
                .map(|(x, w)| w * (50.0 * x).cos()),
        );
        assert!((q - exact).abs() <= 1e-13, "n={n}: {q} vs {exact}");
    }
}

#[test]
fn unit_rule_keeps_nodes_near_zero_to_full_relative_precision() {
    // The smallest node of the n-point rule on [0, 1] is (1 - x_1)/2; its
    // 40-digit value for n = 1e6 is in the large table.
    let large = data("gauss_legendre_large.json");
    let r = &large["rules"][3];
    assert_eq!(r["n"].as_u64(), Some(1_000_000));
    let y1 = num(&r["nodes"][0]["one_minus_x"]);
    let nodes = unit_nodes(1_000_000).expect("valid n");
    assert!(
        rel(nodes.u[0], 0.5 * y1) <= 4.0 * EPS,
        "{} vs {}",
        nodes.u[0],
        0.5 * y1
    );
    // A near-singular integrand: int_0^1 u^(-1/2) du = 2 converges only if
    // the nodes near 0 are right; at n = 1e5 the GL error is ~ 1/n.
    let est = GaussLegendre::default()
        .integrate(100_000, &mut rng(0), |u: [f64; 1]| u[0].powf(-0.5))
        .expect("finite");
    assert!((est.value - 2.0).abs() < 1e-4, "{}", est.value);
}

#[test]
fn exponential_convergence_error_below_1e_14_by_n_20() {
    // int_0^1 exp(u) du = e - 1.
    let exact = std::f64::consts::E - 1.0;
    let rule = GaussLegendre::default();
    let mut last = f64::INFINITY;
    for n in 1..=20 {
        let est = rule
            .integrate(n, &mut rng(0), |u: [f64; 1]| u[0].exp())
            .expect("finite");
        let err = (est.value - exact).abs();
        if n <= 6 {
            assert!(err < last, "n={n}: error must fall ({err} >= {last})");
            // The estimate |Q_n - Q_{n-1}| bounds the true error here.
            assert!(est.error >= err, "n={n}");
        }
        last = err;
        if n == 20 {
            assert!(err < 1e-14, "n=20: error {err}");
        }
    }
}

#[test]
fn bad_orders_are_clear_errors() {
    for n in [0usize, 100_000_001] {
        let e = table(n).expect_err("out of range");
        let msg = e.to_string();
        assert!(
            msg.contains("n = ") && msg.contains("1..=100000000"),
            "{msg}"
        );
        assert!(matches!(e, QuadError::InvalidParameter { .. }));
    }
    let e = GaussLegendre::default()
        .integrate(0, &mut rng(0), |u: [f64; 1]| u[0])
        .expect_err("n = 0");
    assert!(e.to_string().contains("invalid n = 0"), "{e}");
}

#[test]
fn the_error_estimate_tracks_the_truth_for_algebraic_and_geometric_convergence() {
    // int_0^1 sqrt(u) = 2/3 (error ~ m^-3), int_0^1 u^-1/2 = 2 (error ~ m^-1),
    // int_0^1 exp(u) = e - 1 (geometric): the estimate must stay within a
    // factor 10 of the true error either way (a plain |Q_m - Q_(m-1)| is 30 to
    // 1000 times too small for the first two).
    type Case = (fn([f64; 1]) -> f64, f64, &'static [usize]);
    let cases: [Case; 3] = [
        (|u| u[0].sqrt(), 2.0 / 3.0, &[20, 100, 1000]),
        (|u| u[0].powf(-0.5), 2.0, &[20, 100, 1000]),
        (|u| u[0].exp(), std::f64::consts::E - 1.0, &[3, 4, 5, 6]),
    ];
    for (f, exact, orders) in cases {
        for &m in orders {
            let est = GaussLegendre::default()
                .integrate(m, &mut rng(0), f)
                .expect("finite");
            let truth = (est.value - exact).abs();
            let ratio = est.error / truth;
            assert!(
                (0.5..=10.0).contains(&ratio),
                "m = {m}: estimate {:.2e} vs true {truth:.2e}",
                est.error
            );
        }
    }
}

/// `half_node` refuses what has no node (it returned NaN for n = 0 and a
/// node outside [-1, 1] for k past the middle), and its last valid k is the
/// middle node, 0 for odd n.
#[test]
fn half_node_refuses_orders_and_indices_that_have_no_node() {
    for (n, k, field) in [(0, 0, "n"), (5, 0, "k"), (5, 4, "k"), (4, 3, "k")] {
        let e = half_node(n, k).expect_err("refused").to_string();
        assert!(e.contains(&format!("invalid {field} =")), "{n} {k}: {e}");
    }
    let middle = half_node(5, 3).expect("the middle node");
    assert_eq!(middle.one_minus_x, 1.0);
}

/// The public building blocks refuse what is out of range:
/// `bogaert::node(0, 0)` gave x = -3.4e62 and a weight of
/// -3.7e17, and the unguarded entry point of a rule at `usize::MAX` in three
/// dimensions ran on (1.8e19 evaluations).
#[test]
fn node_building_blocks_and_unguarded_rules_refuse_out_of_range_input() {
    use lightquad::quadrature::Trapezoid;
    for (n, k) in [(0, 0), (5, 0), (5, 4), (usize::MAX, usize::MAX)] {
        let e = bogaert::node(n, k).expect_err("out of range");
        assert!(e.to_string().contains("1..="), "{e}");
        let start = bogaert::node(5, 1).expect("valid");
        assert!(newton::node(n, k, start).is_err());
    }
    let ok = bogaert::node(201, 101).expect("the middle node");
    assert!(ok.x.abs() < 1e-15 && ok.weight > 0.0);
    let e = Trapezoid
        .integrate_unguarded::<3, f64, _, _>(usize::MAX, &mut rand::rng(), |_| Ok(1.0))
        .expect_err("beyond the budget limit");
    assert!(e.to_string().contains("2^40"), "{e}");
}

/// Without its estimate in one dimension the rule runs unguarded
/// (`Rule::guarded`): values beyond 2^500, near `f64::MAX`, and not finite
/// give what the guarded rule gives. The closed form `int_0^1 s cos(50 u)
/// du = s sin(50)/50`; the guarded rule's own sum at the same nodes (with
/// its estimate on it rescales by a power of two, exactly): bit for bit
/// past the tabulated orders, whose one running sum is within `m u sum
/// |w f|` of that compensated sum, `u = 2^-53`: its own `gamma_(m-1) sum
/// |w f|` from the terms' exact sum and the compensated sum's `u |sum|`
/// to first order (`sum |w f| <= s` here).
#[test]
fn without_its_estimate_the_unguarded_rule_gives_the_guarded_sums() {
    let bare = GaussLegendre {
        error_estimate: false,
    };
    assert!(!bare.guarded(1) && bare.guarded(2) && GaussLegendre::default().guarded(1));
    let mut rng = rng(1);
    let scale = 1e300;
    let exact = scale * 50f64.sin() / 50.0;
    for n in [5, 15, 16, 20, 100, 127, 128, 1000] {
        let f = |u: [f64; 1]| Ok(scale * (50.0 * u[0]).cos());
        let lean = bare.try_integrate(n, &mut rng, f).expect("sum");
        let guarded = GaussLegendre::default()
            .try_integrate(n, &mut rng, f)
            .expect("sum");
        if n <= TABLE_MAX_ORDER {
            let bound = n as f64 * f64::EPSILON / 2.0 * scale;
            let off = (lean.value - guarded.value).abs();
            assert!(off <= bound, "n = {n}: {off:e} > {bound:e}");
        } else {
            assert_eq!(lean.value.to_bits(), guarded.value.to_bits(), "n = {n}");
        }
        assert!(lean.error.is_infinite() && lean.evaluations == n as u64);
        if n >= 100 {
            assert!(((lean.value - exact) / exact).abs() < 1e-13, "n = {n}");
        }
        let max = bare
            .try_integrate(n, &mut rng, |_: [f64; 1]| Ok(f64::MAX))
            .expect("a sum within range");
        assert!(
            max.value >= f64::MAX * (1.0 - 1e-12),
            "n = {n}: {:e}",
            max.value
        );
        let nan = bare.try_integrate(n, &mut rng, |u: [f64; 1]| {
            Ok(if u[0] > 0.5 { f64::NAN } else { 1.0 })
        });
        match nan {
            Err(QuadError::NonFiniteIntegrand { point, .. }) => {
                assert!(point[0] > 0.5, "n = {n}: {point:?}")
            }
            other => panic!("n = {n}: {other:?}"),
        }
    }
    // Values beyond 2^500 only past the guard's log of 65536 values (the
    // guarded rule had no budget left to rescale them): the sum, `int_0^1`
    // of 1 below 0.995 and 1e300 above, 0.005e300 to the rule's resolution
    // of the jump.
    let step = bare
        .try_integrate(70_000, &mut rng, |u: [f64; 1]| {
            Ok(if u[0] > 0.995 { 1e300 } else { 1.0 })
        })
        .expect("the sum");
    assert!((step.value / 5e297 - 1.0).abs() < 1e-3, "{:e}", step.value);
}

//! The tabulated rules on `[0, 1]` built at compile time, and the rule
//! without its estimate on one axis of a tabulated order, which sums them
//! in one running sum as the calls return.

use crate::common::*;
use lightquad::QuadError;
use lightquad::quadrature::gauss_legendre::unit_table::unit_table;
use lightquad::quadrature::gauss_legendre::{TABLE_MAX_ORDER, unit_nodes};
use lightquad::quadrature::{BaseRule, GaussLegendre, Rule};

const BARE: GaussLegendre = GaussLegendre {
    error_estimate: false,
};

/// The compile-time table against the cached rules computed at run time
/// from the same half table: every node and weight bit for bit, nodes
/// ascending in `(0, 1)`; no rule outside the tabulated orders.
#[test]
fn the_compiled_unit_table_is_the_cached_rule_bit_for_bit() {
    for n in 1..=TABLE_MAX_ORDER {
        let cached = unit_nodes(n).expect("a tabulated order");
        let table = unit_table(n);
        assert_eq!(table.len(), n);
        for (i, &[u, w]) in table.iter().enumerate() {
            assert_eq!(u.to_bits(), cached.u[i].to_bits(), "n = {n}, node {i}");
            assert_eq!(w.to_bits(), cached.w[i].to_bits(), "n = {n}, weight {i}");
            assert!(u > 0.0 && u < 1.0 && w > 0.0, "n = {n}, node {i}");
        }
        assert!(table.windows(2).all(|p| p[0][0] < p[1][0]), "n = {n}");
    }
    assert!(unit_table(0).is_empty() && unit_table(TABLE_MAX_ORDER + 1).is_empty());
}

/// Exact for degree `2m - 1`: `int_0^1 u^k du = 1/(k + 1)`, to the one
/// running sum's rounding, `(m - 1) u` of `sum |w u^k|` (which is the
/// integral), and the nodes' own rounding (`k u` of it at most: `u^k`
/// moves by `k` times a node's relative rounding).
#[test]
fn the_bare_rule_on_tabulated_orders_is_exact_to_its_rounding_bound() {
    let mut worst: f64 = 0.0;
    for m in 1..=TABLE_MAX_ORDER {
        for k in [0, m, 2 * m - 1] {
            let got = BARE
                .integrate(m, &mut rng(1), |u: [f64; 1]| u[0].powi(k as i32))
                .expect("a sum");
            let exact = 1.0 / (k + 1) as f64;
            let off = (got.value - exact).abs() / exact / f64::EPSILON;
            let bound = (m + k + 2) as f64;
            assert!(off <= bound, "m = {m}, k = {k}: {off} eps > {bound}");
            assert_eq!(got.evaluations, m as u64);
            assert!(got.error.is_infinite());
            worst = worst.max(off / bound);
        }
    }
    eprintln!("worst rounding against its bound: {worst:.3}");
}

/// `cos(50 x)` on `[-1, 1]`, the race's integrand: from 80 nodes within
/// the running sum's rounding bound of the closed form `sin(50)/25`,
/// `gamma_(m-1) sum |w f|` with `sum |w f| ~ 4/pi` (the truncation error
/// is below it there), and each call of the integrand counted once.
#[test]
fn the_bare_rule_on_tabulated_orders_converges_and_calls_each_node_once() {
    let exact = 50f64.sin() / 25.0;
    for m in [80, 90, 100] {
        let mut calls = 0;
        let got = BARE
            .integrate(m, &mut rng(1), |u: [f64; 1]| {
                calls += 1;
                2.0 * (50.0 * (2.0 * u[0] - 1.0)).cos()
            })
            .expect("a sum");
        assert_eq!(calls, m);
        let bound = m as f64 * f64::EPSILON / 2.0 * 4.0 / std::f64::consts::PI;
        let off = (got.value - exact).abs();
        assert!(off <= bound, "m = {m}: {off:e} > {bound:e}");
    }
}

/// The rule named at run time (`BaseRule`, as experiment files name it)
/// gives the rule's own bits: in one dimension at the tabulated orders and
/// past them, and in two.
#[test]
fn the_rule_named_at_run_time_gives_the_same_bits() {
    let named = BaseRule::GaussLegendre(BARE);
    let f1 = |u: [f64; 1]| (7.0 * u[0]).sin() + 0.1;
    let f2 = |u: [f64; 2]| (7.0 * u[0]).sin() * u[1].exp();
    for n in [1, 2, 5, 64, 100, 101, 300] {
        let own = BARE.integrate(n, &mut rng(1), f1).expect("a sum");
        let run_time = named.integrate(n, &mut rng(1), f1).expect("a sum");
        assert_eq!(own.value.to_bits(), run_time.value.to_bits(), "n = {n}");
        assert_eq!(own.evaluations, run_time.evaluations);
        let own = BARE.integrate(n * n, &mut rng(1), f2).expect("a sum");
        let run_time = named.integrate(n * n, &mut rng(1), f2).expect("a sum");
        assert_eq!(own.value.to_bits(), run_time.value.to_bits(), "n = {n}^2");
    }
}

/// The integrand's own error comes back at once, from the node it failed
/// at, with no call after it; a value that is not finite is named at its
/// point; an integral of `f64::MAX` is `f64::MAX` to its rounding, not
/// infinite.
#[test]
fn the_bare_rule_on_tabulated_orders_names_what_fails() {
    for m in [1, 2, 5, 16, 37, 100] {
        let mut calls = 0;
        let failed = BARE.try_integrate(m, &mut rng(1), |u: [f64; 1]| {
            calls += 1;
            if u[0] >= 0.5 {
                Err(QuadError::invalid("x", u[0], "below 0.5"))
            } else {
                Ok(1.0)
            }
        });
        assert!(
            matches!(failed, Err(QuadError::InvalidParameter { .. })),
            "m = {m}: {failed:?}"
        );
        assert_eq!(calls, m / 2 + 1, "m = {m}");
        // A sum that is not finite is taken again, the integrand called
        // at every node a second time.
        let mut calls = 0;
        let inf = BARE.try_integrate(m, &mut rng(1), |u: [f64; 1]| {
            calls += 1;
            Ok(if u[0] < 0.5 { 1.0 } else { f64::INFINITY })
        });
        match inf {
            Err(QuadError::NonFiniteIntegrand { point, .. }) => assert!(point[0] >= 0.5),
            other => panic!("m = {m}: {other:?}"),
        }
        assert_eq!(calls, 2 * m, "m = {m}");
        let mut calls = 0;
        let max = BARE
            .integrate(m, &mut rng(1), |_: [f64; 1]| {
                calls += 1;
                f64::MAX
            })
            .expect("within range");
        assert!(
            max.value.is_finite() && max.value >= f64::MAX * (1.0 - 1e-13),
            "m = {m}"
        );
        assert_eq!(max.evaluations, calls as u64, "m = {m}");
    }
    let zero = BARE.try_integrate(0, &mut rng(1), |_: [f64; 1]| Ok(1.0));
    let message = zero.expect_err("no nodes").to_string();
    assert!(message.contains("at least 1"), "{message}");
}

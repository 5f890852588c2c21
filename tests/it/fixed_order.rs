//! [`FixedOrder`], Gauss–Legendre of one order prepared once: its values
//! against closed forms on both sides of the compiled-in table, its nodes
//! inside the interval, and every way a call fails.

use lightquad::QuadError;
use lightquad::quadrature::gauss_legendre::{FixedOrder, MAX_ORDER, TABLE_MAX_ORDER};
use lightquad::value::Rgb;
use proptest::prelude::*;

fn rule(n: usize) -> FixedOrder {
    FixedOrder::new(n).expect("an order in range")
}

/// `int_a^b (x - c)^k dx = ((b - c)^(k+1) - (a - c)^(k+1)) / (k + 1)`:
/// exact for every degree `k <= 2n - 1`, to rounding, on tabulated and
/// computed orders, forward and reversed: every order summed in a row
/// (1 to 10) and the first two summed in chunks of four calls.
#[test]
fn polynomials_up_to_degree_2n_minus_1_are_exact() {
    let (a, b, c): (f64, f64, f64) = (-0.5, 2.0, 0.75);
    let straight_and_chunked = 1..=12;
    let larger = [37, 64, 99, 100, 101, 128, 300];
    for n in straight_and_chunked.chain(larger) {
        let fixed = rule(n);
        assert_eq!(fixed.order(), n);
        for k in [0, n, 2 * n - 1] {
            let exact =
                ((b - c).powi(k as i32 + 1) - (a - c).powi(k as i32 + 1)) / (k as f64 + 1.0);
            // The terms' magnitude bounds the rounding: `int |x - c|^k`.
            let scale = ((b - c).abs().powi(k as i32 + 1) + (a - c).abs().powi(k as i32 + 1))
                / (k as f64 + 1.0);
            let f = |x: f64| (x - c).powi(k as i32);
            let forward = fixed.integrate(a, b, f).expect("finite");
            let backward = fixed.integrate(b, a, f).expect("finite");
            let tolerance = 1e-13 * scale;
            assert!(
                (forward - exact).abs() <= tolerance,
                "n = {n}, k = {k}: {forward} against {exact}"
            );
            assert!(
                (backward + exact).abs() <= tolerance,
                "n = {n}, k = {k}: {backward} against {}",
                -exact
            );
        }
    }
}

/// Up to 100 nodes the sum is one running sum in the order of the nodes,
/// as documented: on `[0, 1]` (`x = u`, `b - a = 1` exactly) `FixedOrder`
/// and the rule without its estimate give the bits of a plain loop over
/// the public table, `s += f(u) w`, at every order, those summed in a row
/// (1 to 10 on `FixedOrder`, 1 to 8 on the rule) and those summed in
/// chunks of four calls. The integrand's terms differ in
/// magnitude by some 1e16, so another order of the sum, or a compensated
/// one, would change the last bits.
#[test]
fn the_running_sum_is_the_plain_loops_bits_at_every_tabulated_order() {
    use lightquad::quadrature::gauss_legendre::unit_table::unit_table;
    use lightquad::quadrature::{GaussLegendre, Rule};
    use rand::SeedableRng;
    let f = |x: f64| 1e16 * (1e3 * x).sin() + 1.0 / (x + 1e-3);
    let without_estimate = GaussLegendre {
        error_estimate: false,
    };
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    for n in 1..=TABLE_MAX_ORDER {
        let mut plain = 0.0;
        for &[u, w] in unit_table(n) {
            plain += f(u) * w;
        }
        let fixed = rule(n).integrate(0.0, 1.0, f).expect("finite");
        let by_rule = without_estimate
            .integrate(n, &mut rng, |u: [f64; 1]| f(u[0]))
            .expect("finite")
            .value;
        assert_eq!(fixed.to_bits(), plain.to_bits(), "n = {n}: FixedOrder");
        assert_eq!(by_rule.to_bits(), plain.to_bits(), "n = {n}: the rule");
    }
}

/// `int_{-1}^{1} cos(50 x) dx = sin(50)/25`, the benchmarks' integral: not
/// resolved at 5 nodes; from 100 on, within rounding of the nodes and the
/// sum. Each `x` is within `delta` of its exact node (the table's are
/// correctly rounded, half an ulp; the computed ones within a few ulps:
/// 4 assumed), and `a + h u` adds two roundings, so the values move by at
/// most `max |f'| (delta + 2u) (b - a)`, `f' <= 50`; the running sum adds
/// `99 u sum |w f| (b - a)` (about 1.4e-14), the compensated sum a few `u`.
#[test]
fn the_benchmark_integral_converges_on_both_sides_of_the_table() {
    let exact = 50f64.sin() / 25.0;
    let f = |x: f64| (50.0 * x).cos();
    let at = |n: usize| rule(n).integrate(-1.0, 1.0, f).expect("finite");
    assert!((at(5) - exact).abs() > 0.1);
    let u = f64::EPSILON / 2.0;
    let nodes = |delta: f64| 50.0 * (delta + 2.0 * u) * 2.0;
    let error = (at(100) - exact).abs();
    assert!(
        error < nodes(u) + 99.0 * u * 1.3,
        "n = 100: error {error:e}"
    );
    for n in [101, 1000, 100_000] {
        let error = (at(n) - exact).abs();
        assert!(
            error < nodes(4.0 * u) + 4.0 * u * 1.3,
            "n = {n}: error {error:e}"
        );
    }
}

/// Each channel of an RGB integrand is its own integral.
#[test]
fn rgb_channels_integrate_apart() {
    for n in [8, 12, 300] {
        let value = rule(n)
            .integrate(0.0, 1.0, |x: f64| Rgb::new(1.0, 4.0 * x, (3.0 * x).exp()))
            .expect("finite");
        assert!((value.x - 1.0).abs() < 1e-15, "n = {n}: {value:?}");
        assert!((value.y - 2.0).abs() < 1e-15, "n = {n}: {value:?}");
        assert!(
            (value.z - (3f64.exp() - 1.0) / 3.0).abs() < 1e-12,
            "n = {n}: {value:?}"
        );
    }
}

/// Orders outside `1..=MAX_ORDER` are refused, naming `n`.
#[test]
fn orders_out_of_range_are_refused() {
    for n in [0, MAX_ORDER + 1] {
        let message = FixedOrder::new(n).expect_err("out of range").to_string();
        assert!(message.contains(&format!("n = {n}")), "{message}");
        assert!(message.contains("1..="), "{message}");
    }
}

/// A value that is not finite is named with its node, whatever the order;
/// in the table the integrand is then called a second time at every node.
#[test]
fn a_value_that_is_not_finite_is_named_at_its_node() {
    for n in [5, 101] {
        let mut calls = 0;
        let err = rule(n)
            .integrate(-1.0, 1.0, |x: f64| {
                calls += 1;
                1.0 / x
            })
            .expect_err("1/0 at the middle node");
        let message = err.to_string();
        assert!(message.contains("inf at x = 0"), "n = {n}: {message}");
        assert!(message.contains("[-1, 1]"), "n = {n}: {message}");
        // The running sum, then the compensated sum that names the node.
        let expected_calls = if n <= TABLE_MAX_ORDER { 2 * n } else { n };
        assert_eq!(calls, expected_calls, "n = {n}");
    }
    let message = rule(4)
        .integrate(0.0, 1.0, |x: f64| if x > 0.5 { f64::NAN } else { x })
        .expect_err("NaN above 1/2")
        .to_string();
    assert!(message.contains("NaN at x = 0.6"), "{message}");
}

/// On a reversed interval too, a value that is not finite is named at the
/// node where the running sum met it: the compensated sum that names it
/// takes the same nodes.
#[test]
fn a_reversed_interval_names_its_node() {
    use lightquad::quadrature::gauss_legendre::unit_table::unit_table;
    for n in [5, 7, 20, 64, 100] {
        let (a, b) = (0.3, -0.7);
        let c = a + (b - a) * unit_table(n)[1][0];
        let message = rule(n)
            .integrate(a, b, |x: f64| 1.0 / (x - c))
            .expect_err("1/0 at the second node")
            .to_string();
        assert!(
            message.contains(&format!("inf at x = {c}")),
            "n = {n}, c = {c}: {message}"
        );
    }
}

/// Ends and lengths that are not finite are named; an integrand's own
/// error is returned as it is, at its first call.
#[test]
fn ends_that_are_not_finite_and_integrand_errors_are_named() {
    for n in [3, 200] {
        let fixed = rule(n);
        for (a, b, field) in [
            (f64::NAN, 1.0, "a = NaN"),
            (0.0, f64::INFINITY, "b = inf"),
            (-1e308, 1e308, "distance from a = -1e308"),
        ] {
            let mut calls = 0;
            let message = fixed
                .integrate(a, b, |_: f64| {
                    calls += 1;
                    1.0
                })
                .expect_err("not a finite interval")
                .to_string();
            assert!(message.contains(field), "n = {n}, [{a}, {b}]: {message}");
            assert_eq!(calls, 0, "n = {n}, [{a}, {b}]: no node is taken");
        }
        let mut calls = 0;
        let err = fixed.try_integrate(0.0, 1.0, |x: f64| {
            calls += 1;
            if x >= 0.5 {
                Err(QuadError::invalid("x", x, "below 0.5"))
            } else {
                Ok(x)
            }
        });
        assert!(
            matches!(err, Err(QuadError::InvalidParameter { ref name, .. }) if name == "x"),
            "n = {n}: {err:?}"
        );
        assert_eq!(calls, n / 2 + 1, "n = {n}");
    }
}

/// An integrand's own error is its own even where it is the kind the sum
/// raises for a value that is not finite: returned as it is, not told
/// again at a node, in the table (the running sum returns it at once; the
/// compensated sum, where the running sum came out not finite and takes
/// the nodes again, the last case) and above (the compensated sum).
#[test]
fn an_integrands_own_error_is_not_renamed() {
    let own = || QuadError::NonFiniteIntegrand {
        point: vec![7.0],
        value: "the integrand's own".into(),
    };
    let is_own = |e: &QuadError| {
        matches!(e, QuadError::NonFiniteIntegrand { point, value }
            if point == &[7.0] && value == "the integrand's own")
    };
    for n in [3, 200] {
        let err = rule(n)
            .try_integrate(0.0, 1.0, |x: f64| if x >= 0.5 { Err(own()) } else { Ok(x) })
            .expect_err("its error");
        assert!(is_own(&err), "n = {n}: {err:?}");
    }
    // Infinite at the first pass's last node, its own error at the second.
    let mut calls = 0;
    let err = rule(3)
        .try_integrate(0.0, 1.0, |_: f64| {
            calls += 1;
            match calls {
                3 => Ok(f64::INFINITY),
                4.. => Err(own()),
                _ => Ok(1.0),
            }
        })
        .expect_err("its error on the second pass");
    assert!(is_own(&err), "{err:?}");
}

/// An integral of `f64::MAX` over a unit length is `f64::MAX`, found
/// where a running sum passes the range; over a length of 4 it is beyond
/// the range, and said so.
#[test]
fn integrals_at_the_edge_of_the_range() {
    for n in [5, 64, 100, 150] {
        let fixed = rule(n);
        let max = fixed
            .integrate(0.0, 1.0, |_: f64| f64::MAX)
            .expect("within range");
        assert!(
            max.is_finite() && max >= f64::MAX * (1.0 - 1e-13),
            "n = {n}: {max}"
        );
        let message = fixed
            .integrate(0.0, 4.0, |_: f64| 1e308)
            .expect_err("4e308")
            .to_string();
        assert!(
            message.contains("beyond the f64 range") && message.contains("times b - a = 4"),
            "n = {n}: {message}"
        );
    }
}

proptest! {
    /// Every node the integrand sees lies in `[min(a, b), max(a, b)]`,
    /// also where the interval spans a few ulps of its ends or nearly the
    /// whole f64 range.
    #[test]
    fn every_node_lies_inside_the_interval(
        a in prop_oneof![-1e300f64..1e300, -10f64..10.0],
        relative_width in -17f64..0.5,
        reversed in any::<bool>(),
        n in prop::sample::select(vec![1usize, 2, 5, 17, 64, 100, 101, 257]),
    ) {
        // From a few ulps of `a` to three times its magnitude.
        let b = a + a.abs().max(1e-300) * 10f64.powf(relative_width);
        let (a, b) = if reversed { (b, a) } else { (a, b) };
        let (lo, hi) = (a.min(b), a.max(b));
        let mut outside = None;
        let _ = rule(n).integrate(a, b, |x: f64| {
            if !(lo <= x && x <= hi) {
                outside = Some(x);
            }
            0.0
        });
        prop_assert!(outside.is_none(), "n = {}, [{}, {}]: node {:?}", n, a, b, outside);
    }
}

/// `par_integrate`, the nodes shared among threads: `integrate`'s bits up
/// to one span (4096 nodes), the same bits on one and on two threads,
/// within the closed form's rounding bound above a span (the bound of
/// `the_benchmark_integral_converges_on_both_sides_of_the_table`), and a
/// value not finite named at its `x` as `integrate` names it.
#[test]
fn the_parallel_sum_is_the_serial_one_to_a_span_and_as_exact_beyond() {
    let exact = 50f64.sin() / 25.0;
    let f = |x: f64| (50.0 * x).cos();
    let u = f64::EPSILON / 2.0;
    let bound = 50.0 * (4.0 * u + 2.0 * u) * 2.0 + 4.0 * u * 1.3;
    let pool = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
    };
    for n in [5, 100, 101, 4096, 4097, 100_001, 1_000_000] {
        let fixed = rule(n);
        let serial = fixed.integrate(-1.0, 1.0, f).expect("finite");
        let one = pool(1).install(|| fixed.par_integrate(-1.0, 1.0, f).expect("finite"));
        let two = pool(2).install(|| fixed.par_integrate(-1.0, 1.0, f).expect("finite"));
        assert_eq!(one.to_bits(), two.to_bits(), "n = {n}");
        if n <= 4096 {
            assert_eq!(one.to_bits(), serial.to_bits(), "n = {n}");
        }
        // Two compensated sums of the same terms: each within an ulp or so
        // of the terms' exact sum.
        let apart = (one - serial).abs();
        assert!(
            apart <= 4.0 * f64::EPSILON * serial.abs(),
            "n = {n}: {apart:e} apart"
        );
        if n > 100 {
            let error = (one - exact).abs();
            assert!(error < bound, "n = {n}: error {error:e}");
        }
    }
    let odd = rule(100_001);
    let serial = odd.integrate(-1.0, 1.0, |x: f64| 1.0 / x).expect_err("1/0");
    let par = pool(2)
        .install(|| odd.par_integrate(-1.0, 1.0, |x: f64| 1.0 / x))
        .expect_err("1/0");
    assert_eq!(par, serial);
    assert!(par.to_string().contains("inf at x = 0"), "{par}");
}

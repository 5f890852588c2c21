//! `product_value`, the rule's sum alone (what Gauss–Legendre without its
//! estimate reads): Gauss's exactness to degree `2n - 1` as the closed
//! form, and on every path `product_sum`'s value bit for bit with the same
//! errors, the whole sum being itself checked against closed forms in
//! `line_sum_par.rs` and `gauss_legendre.rs`.

use lightquad::error::QuadError;
use lightquad::quadrature::gauss_legendre::unit_nodes;
use lightquad::quadrature::nodes::{UnitNodes, line_sum_par, product_sum, product_value};
use lightquad::quadrature::product::WithError;
use lightquad::quadrature::{simpson, trapezoid};
use lightquad::value::{Rgb, Value};
use rand::RngExt;

use crate::common::rng;

/// Node counts on either side of every cut of the one-axis sum: the few
/// nodes summed term by term (below 16), the short axis in the lanes
/// (below 128), and the blocks.
fn counts() -> impl Iterator<Item = usize> {
    (1..=40).chain([
        63, 64, 65, 100, 126, 127, 128, 129, 200, 255, 256, 257, 1000,
    ])
}

/// `int_0^1 2n u^(2n-1) du = 1`, which `n` Gauss nodes integrate exactly:
/// within the rounding of a sum of `n` terms.
#[test]
fn n_gauss_nodes_integrate_a_polynomial_of_degree_2n_minus_1() {
    for n in counts() {
        let nodes = unit_nodes(n).expect("nodes");
        let k = 2 * n as i32;
        let value = product_value([&*nodes], |[u]: [f64; 1]| Ok(f64::from(k) * u.powi(k - 1)))
            .expect("a finite sum");
        assert!((value - 1.0).abs() < 1e-12, "n = {n}: {value:e}");
    }
}

/// A value of `scale` times a random sign and a random magnitude over
/// `spread` decades.
fn random_value(rng: &mut rand_pcg::Pcg64, scale: f64, spread: f64) -> f64 {
    let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
    sign * scale * 10f64.powf(-spread * rng.random::<f64>())
}

/// `product_value` and `product_sum` of the same values: the same bits,
/// or the same error. Where a companion's sum left the range (a composite
/// rule's `4h` rule, all its terms in one lane), which the value alone
/// does not form, the value is the whole sum's of the values at a quarter
/// of their size, times 4: the same bits, a power of two being exact.
///
/// Returns whether a companion's sum left the range.
fn same<V: Value>(nodes: &UnitNodes, values: &[V], what: &str) -> bool {
    let at = |u: f64| values[nodes.u.iter().position(|&x| x == u).expect("a node")];
    let value = product_value([nodes], |[u]: [f64; 1]| Ok(at(u)));
    let mut companion_out = false;
    let whole = match product_sum([nodes], |[u]: [f64; 1]| Ok(at(u))) {
        Err(QuadError::SumOutOfRange { sum, .. }) if sum.starts_with("companion") => {
            companion_out = true;
            product_sum([nodes], |[u]: [f64; 1]| Ok(at(u).map(|v| v / 4.0)))
                .map(|s| s.value.map(|v| 4.0 * v))
        }
        whole => whole.map(|s| s.value),
    };
    match (value, whole) {
        (Ok(v), Ok(w)) => {
            for c in 0..V::CHANNELS {
                let (v, w) = (v.channel(c), w.channel(c));
                assert!(
                    v.to_bits() == w.to_bits() || (v.is_nan() && w.is_nan()),
                    "{what}, channel {c}: {v:e} against {w:e}"
                );
            }
        }
        (Err(v), Err(w)) => assert_eq!(v, w, "{what}"),
        (v, w) => panic!("{what}: {v:?} against {w:?}"),
    }
    companion_out
}

/// Random values of every size and sign, and values near `f64::MAX`
/// (whose running sums pass it on the way to a total within range), on
/// Gauss and trapezoid nodes, as scalars, RGB and values with an error:
/// `product_value` is `product_sum`'s value, bit for bit.
#[test]
fn the_value_alone_is_the_whole_sums_value_bit_for_bit() {
    let mut rng = rng(55);
    let mut companions_out = 0;
    for n in counts() {
        let gauss = unit_nodes(n).expect("nodes");
        let trapezoid = trapezoid::unit_nodes((n | 1).max(3)).expect("nodes");
        let simpson = simpson::unit_nodes((n | 1).max(3)).expect("nodes");
        let rules = [
            (&*gauss, "gauss"),
            (&trapezoid, "trapezoid"),
            (&simpson, "simpson"),
        ];
        for (nodes, rule) in rules {
            let len = nodes.len();
            for (scale, spread) in [(1.0, 0.0), (1.0, 30.0), (1e300, 2.0), (f64::MAX, 1e-14)] {
                let what = format!("{rule}, {len} nodes, scale {scale:e}");
                let scalars: Vec<f64> = (0..len)
                    .map(|_| random_value(&mut rng, scale, spread))
                    .collect();
                same(nodes, &scalars, &what);
                let constant = same(nodes, &vec![scale; len], &format!("{what}, constant"));
                companions_out += usize::from(constant);
                let rgb: Vec<Rgb> = (0..len)
                    .map(|_| <Rgb as Value>::from_fn(|_| random_value(&mut rng, scale, spread)))
                    .collect();
                same(nodes, &rgb, &format!("{what}, rgb"));
            }
        }
    }
    // The composite rules' `4h` companions of `f64::MAX` did leave the
    // range: the value alone was found where the whole sum was refused.
    assert!(companions_out > 0);
}

/// Two and three axes of random values, and an empty axis: the odometer's
/// value, bit for bit.
#[test]
fn on_several_axes_the_value_is_the_odometers() {
    let mut rng = rng(57);
    for m in [1, 2, 5, 17] {
        let nodes = unit_nodes(m).expect("nodes");
        let values: Vec<f64> = (0..m * m * m)
            .map(|_| random_value(&mut rng, 1.0, 20.0))
            .collect();
        let index = |u: f64| nodes.u.iter().position(|&x| x == u).expect("a node");
        let f2 = |[u, v]: [f64; 2]| Ok(values[index(u) * m + index(v)]);
        let value = product_value([&*nodes, &*nodes], f2).expect("finite");
        let whole = product_sum([&*nodes, &*nodes], f2).expect("finite").value;
        assert_eq!(value.to_bits(), whole.to_bits(), "{m} x {m}");
        let f3 = |[u, v, w]: [f64; 3]| Ok(values[(index(u) * m + index(v)) * m + index(w)]);
        let value = product_value([&*nodes, &*nodes, &*nodes], f3).expect("finite");
        let whole = product_sum([&*nodes, &*nodes, &*nodes], f3)
            .expect("finite")
            .value;
        assert_eq!(value.to_bits(), whole.to_bits(), "{m} x {m} x {m}");
    }
    let empty = UnitNodes {
        u: vec![],
        w: vec![],
        companion: None,
        companion4: None,
        companion8: None,
    };
    assert_eq!(product_value([&empty], |_: [f64; 1]| Ok(1.0)), Ok(0.0));
    let nodes = unit_nodes(3).expect("nodes");
    assert_eq!(
        product_value([&*nodes, &empty], |_: [f64; 2]| Ok(1.0)),
        Ok(0.0)
    );
}

/// Weights of 1 at every node (a sum, not a rule: they add to `n`) of
/// `f64::MAX`: the value itself leaves the range, the same
/// `SumOutOfRange` from both sums, on every path of one axis.
#[test]
fn a_value_beyond_the_range_is_the_same_error() {
    for n in [5, 20, 100, 200] {
        let nodes = UnitNodes {
            u: (0..n).map(|i| (i as f64 + 0.5) / n as f64).collect(),
            w: vec![1.0; n],
            companion: None,
            companion4: None,
            companion8: None,
        };
        let f = |_: [f64; 1]| Ok(f64::MAX);
        let value = product_value([&nodes], f);
        assert!(
            matches!(value, Err(QuadError::SumOutOfRange { sum: "value", .. })),
            "{n} nodes: {value:?}"
        );
        assert_eq!(
            value,
            product_sum([&nodes], f).map(|s| s.value),
            "{n} nodes"
        );
    }
}

/// Weight sets of another length than the nodes (the fields are public):
/// an error naming the set and its length, from both sums and the parallel
/// one, never a panic or a sum of some of the terms.
#[test]
fn weights_that_do_not_match_the_nodes_are_an_error() {
    for n in [4, 20, 200] {
        let good = trapezoid::unit_nodes(n + 1).expect("nodes");
        let mut short_w = good.clone();
        short_w.w.pop();
        let mut long_companion = good.clone();
        long_companion
            .companion4
            .as_mut()
            .expect("a 4h rule")
            .push(0.0);
        for (nodes, name, len) in [(&short_w, "w", n), (&long_companion, "companion4", n + 2)] {
            let what = format!("{} nodes, {name}", n + 1);
            let f = |_: [f64; 1]| Ok(1.0);
            let expected = Err(QuadError::invalid(
                name,
                len,
                format!("{} weights, one per node", n + 1),
            ));
            assert_eq!(product_value([nodes], f), expected, "{what}");
            assert_eq!(product_sum([nodes], f).map(|s| s.value), expected, "{what}");
            let par = line_sum_par(nodes, |_| Ok(1.0)).map(|s| s.value);
            assert_eq!(par, expected, "{what}, parallel");
        }
    }
}

/// A value that is not finite at one node is named there by both sums;
/// an infinite error beside finite values (an inner rule without an
/// estimate) is summed, not refused; a sum that leaves the range (the
/// odometer's one running sum of 1000 x 1000 nodes of `f64::MAX`) is the
/// same `SumOutOfRange`.
#[test]
fn values_that_are_not_finite_give_the_same_errors() {
    let mut rng = rng(56);
    for n in counts() {
        let nodes = unit_nodes(n).expect("nodes");
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let at = rng.random_range(0..n);
            let mut values = vec![1.0; n];
            values[at] = bad;
            same(&nodes, &values, &format!("{n} nodes, {bad} at {at}"));
            let rgb: Vec<Rgb> = values.iter().map(|&v| Rgb::new(1.0, v, 2.0)).collect();
            same(&nodes, &rgb, &format!("{n} nodes, rgb, {bad} at {at}"));
            let with_error: Vec<WithError<f64>> = values
                .iter()
                .map(|&e| WithError {
                    value: 1.0,
                    error: e,
                })
                .collect();
            same(
                &nodes,
                &with_error,
                &format!("{n} nodes, an error {bad} at {at}"),
            );
            // Errors of both signs, or beside a value near `f64::MAX`.
            let mut both = with_error.clone();
            both[rng.random_range(0..n)].error = -bad;
            same(
                &nodes,
                &both,
                &format!("{n} nodes, errors {bad} and {}", -bad),
            );
            let near_max: Vec<_> = with_error
                .iter()
                .map(|e| WithError {
                    value: f64::MAX,
                    error: e.error,
                })
                .collect();
            same(
                &nodes,
                &near_max,
                &format!("{n} nodes, f64::MAX, an error {bad}"),
            );
            // The integrand's own error after a value that is not finite:
            // the first of them in the order of the nodes.
            let failing = |[u]: [f64; 1]| {
                let i = nodes.u.iter().position(|&x| x == u).expect("a node");
                if i > at {
                    Err(QuadError::invalid("f", i, "no failure"))
                } else {
                    Ok(values[i])
                }
            };
            assert_eq!(
                product_value([&*nodes], failing),
                product_sum([&*nodes], failing).map(|s| s.value),
                "{n} nodes, {bad} at {at}, then an error"
            );
        }
        let first_bad = product_value([&*nodes], |[u]: [f64; 1]| {
            Ok(if u > 0.5 { f64::NAN } else { u })
        });
        match first_bad {
            Err(QuadError::NonFiniteIntegrand { point, .. }) => {
                let first = nodes.u.iter().find(|&&u| u > 0.5).expect("a node past 0.5");
                assert_eq!(point, vec![*first], "{n} nodes");
            }
            other if n == 1 => assert!(other.is_ok(), "{other:?}"),
            other => panic!("{n} nodes: {other:?}"),
        }
    }
    let nodes = unit_nodes(1000).expect("nodes");
    let f = |_: [f64; 2]| Ok(f64::MAX);
    let value = product_value([&*nodes, &*nodes], f);
    let whole = product_sum([&*nodes, &*nodes], f).map(|s| s.value);
    assert!(
        matches!(value, Err(QuadError::SumOutOfRange { sum: "value", .. })),
        "{value:?}"
    );
    assert_eq!(value, whole);
}

/// From 128 nodes on one axis the value's lanes are summed alone, and a
/// block (256 nodes) whose sums are not finite sends the sum back to the
/// first node: `f` is called once at each node where every value is
/// finite, and twice up to the end of the failing block where one is not
/// (the count the documentation of `product_value` gives). With an
/// infinite error beside finite values (`WithError`, whose `all_finite`
/// reads the value) nothing is taken again.
#[test]
fn the_sum_is_taken_again_only_past_a_value_that_is_not_finite() {
    for n in [128, 255, 256, 257, 1000, 5000] {
        let nodes = unit_nodes(n).expect("nodes");
        let calls = std::cell::Cell::new(0usize);
        let counted = |[u]: [f64; 1]| {
            calls.set(calls.get() + 1);
            Ok((3.0 * u).exp())
        };
        let value = product_value([&*nodes], counted).expect("finite");
        assert!(
            (value - (3f64.exp() - 1.0) / 3.0).abs() < 1e-13,
            "{n}: {value}"
        );
        assert_eq!(calls.get(), n, "{n} nodes, finite");

        let with_error = |[u]: [f64; 1]| {
            calls.set(calls.get() + 1);
            Ok(WithError {
                value: u,
                error: f64::INFINITY,
            })
        };
        calls.set(0);
        let value = product_value([&*nodes], with_error).expect("finite value");
        assert!((value.value - 0.5).abs() < 1e-14, "{n}: {value:?}");
        assert_eq!(calls.get(), n, "{n} nodes, infinite errors");

        // `f64::MAX` at every trapezoid node: the lanes' sums stay within
        // the range and their total, `int_0^1 f64::MAX`, is found with no
        // second pass (the whole sum's `4h` companion, in one lane, leaves
        // the range at some counts: not this sum's error).
        let m = 2 * n + 1;
        let composite = trapezoid::unit_nodes(m).expect("nodes");
        calls.set(0);
        let at_max = product_value([&composite], |_: [f64; 1]| {
            calls.set(calls.get() + 1);
            Ok(f64::MAX)
        });
        let near_max = |v: &f64| *v >= f64::MAX * (1.0 - 1e-12);
        assert!(at_max.as_ref().is_ok_and(near_max), "{m} nodes: {at_max:?}");
        assert_eq!(calls.get(), m, "{m} trapezoid nodes, f64::MAX");

        for bad in [0, n / 2, n - 1] {
            calls.set(0);
            let nan_at = |[u]: [f64; 1]| {
                calls.set(calls.get() + 1);
                Ok(if u == nodes.u[bad] { f64::NAN } else { u })
            };
            let err = product_value([&*nodes], nan_at).expect_err("a NaN");
            assert!(
                matches!(&err, QuadError::NonFiniteIntegrand { point, .. } if point == &[nodes.u[bad]]),
                "{n} nodes, NaN at {bad}: {err}"
            );
            let block_end = ((bad / 256 + 1) * 256).min(n);
            assert_eq!(calls.get(), 2 * block_end, "{n} nodes, NaN at {bad}");
        }
    }
}

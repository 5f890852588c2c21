//! `product_value`, the rule's sum alone (what Gauss–Legendre without its
//! estimate reads): Gauss's exactness to degree `2n - 1` as the closed
//! form, and on every path `product_sum`'s value bit for bit with the same
//! errors, the whole sum being itself checked against closed forms in
//! `line_sum_par.rs` and `gauss_legendre.rs`.

use lightquad::error::QuadError;
use lightquad::quadrature::gauss_legendre::unit_nodes;
use lightquad::quadrature::nodes::{UnitNodes, product_sum, product_value};
use lightquad::quadrature::product::WithError;
use lightquad::quadrature::trapezoid;
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
fn same<V: Value>(nodes: &UnitNodes, values: &[V], what: &str) {
    let at = |u: f64| values[nodes.u.iter().position(|&x| x == u).expect("a node")];
    let value = product_value([nodes], |[u]: [f64; 1]| Ok(at(u)));
    let whole = match product_sum([nodes], |[u]: [f64; 1]| Ok(at(u))) {
        Err(QuadError::SumOutOfRange { sum, .. }) if sum.starts_with("companion") => {
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
}

/// Random values of every size and sign, and values near `f64::MAX`
/// (whose running sums pass it on the way to a total within range), on
/// Gauss and trapezoid nodes, as scalars, RGB and values with an error:
/// `product_value` is `product_sum`'s value, bit for bit.
#[test]
fn the_value_alone_is_the_whole_sums_value_bit_for_bit() {
    let mut rng = rng(55);
    for n in counts() {
        let gauss = unit_nodes(n).expect("nodes");
        let trapezoid = trapezoid::unit_nodes((n | 1).max(3)).expect("nodes");
        for (nodes, rule) in [(&*gauss, "gauss"), (&trapezoid, "trapezoid")] {
            let len = nodes.len();
            for (scale, spread) in [(1.0, 0.0), (1.0, 30.0), (1e300, 2.0), (f64::MAX, 1e-14)] {
                let what = format!("{rule}, {len} nodes, scale {scale:e}");
                let scalars: Vec<f64> = (0..len)
                    .map(|_| random_value(&mut rng, scale, spread))
                    .collect();
                same(nodes, &scalars, &what);
                same(nodes, &vec![scale; len], &format!("{what}, constant"));
                let rgb: Vec<Rgb> = (0..len)
                    .map(|_| <Rgb as Value>::from_fn(|_| random_value(&mut rng, scale, spread)))
                    .collect();
                same(nodes, &rgb, &format!("{what}, rgb"));
            }
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
                    error: e.abs(),
                })
                .collect();
            same(
                &nodes,
                &with_error,
                &format!("{n} nodes, an error {bad} at {at}"),
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

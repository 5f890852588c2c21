//! Gauss–Legendre against two independent implementations of Bogaert's method
//! (the crates `bilby` and `gauss-quad`) over every node of n = 1e3, 1e5, 1e6,
//! and all three against the 40-digit values, so "at the same accuracy" is a
//! measured statement. Run with `--nocapture` to see the figures.

use crate::common;
use common::*;
use lightquad::quadrature::gauss_legendre::table;

/// Largest (|dx| / eps, relative dw / eps) between two rules with ascending nodes.
fn max_diff(x: &[f64], w: &[f64], xr: &[f64], wr: &[f64]) -> (f64, f64) {
    x.iter()
        .zip(w)
        .zip(xr.iter().zip(wr))
        .fold((0.0, 0.0), |(mx, mw), ((a, b), (c, d))| {
            (mx.max((a - c).abs() / EPS), mw.max(rel(*b, *d) / EPS))
        })
}

/// bilby's n-point rule, ascending.
fn bilby_rule(n: usize) -> (Vec<f64>, Vec<f64>) {
    let bil = bilby::GaussLegendre::new(n).expect("n > 0");
    let rule = bil.rule();
    ascending(
        rule.nodes
            .iter()
            .copied()
            .zip(rule.weights.iter().copied())
            .collect(),
    )
}

/// A peer's rule sorted ascending (gauss-quad lists nodes descending).
fn ascending(mut pairs: Vec<(f64, f64)>) -> (Vec<f64>, Vec<f64>) {
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    pairs.into_iter().unzip()
}

#[test]
fn the_two_term_regime_agrees_with_bilby() {
    // 3000 <= n < 1e5 keeps F1, F2, W1, W2 only: no 40-digit sample there,
    // so every node of n = 5000 and 20000 is held against bilby's.
    for n in [5000usize, 20_000] {
        let ours = table(n).expect("valid n");
        let (bx, bw) = bilby_rule(n);
        let (dx, dw) = max_diff(ours.x(), ours.w(), &bx, &bw);
        assert!(dx <= 4.0 && dw <= 6.0, "n={n}: {dx} eps, {dw} eps");
    }
}

#[test]
fn agrees_with_bilby_and_gauss_quad_and_is_at_least_as_accurate() {
    let large = data("gauss_legendre_large.json");
    let mut results = Vec::new();
    for r in large["rules"].as_array().expect("rules") {
        let n = r["n"].as_u64().expect("n") as usize;
        if n < 1000 {
            continue;
        }
        let ours = table(n).expect("valid n");
        let (bx, bw) = bilby_rule(n);
        let gq = gauss_quad::GaussLegendre::new(std::num::NonZeroUsize::new(n).expect("n > 0"));
        let (gx, gw) = ascending(gq.iter().map(|(x, w)| (*x, *w)).collect());

        // Whole-rule agreement between independent implementations.
        let (dx_b, dw_b) = max_diff(ours.x(), ours.w(), &bx, &bw);
        let (dx_g, dw_g) = max_diff(ours.x(), ours.w(), &gx, &gw);
        eprintln!(
            "n={n}: max |dx| vs bilby {dx_b:.2} eps, vs gauss-quad {dx_g:.2} eps; \
             max rel dw vs bilby {dw_b:.2} eps, vs gauss-quad {dw_g:.2} eps"
        );
        // Each implementation is a few ulps from the truth, so two of them
        // may differ by the sum.
        assert!(dx_b <= 6.0 && dw_b <= 6.0, "n={n} vs bilby");
        assert!(dx_g <= 6.0 && dw_g <= 6.0, "n={n} vs gauss-quad");

        // Accuracy against the 40-digit values at the sampled nodes.
        let mut worst = [(0.0f64, 0.0f64); 3];
        for node in r["nodes"].as_array().expect("nodes") {
            let k = node["k"].as_u64().expect("k") as usize;
            let (x, w) = (num(&node["x"]), num(&node["weight"]));
            let i = n - k;
            for (slot, (xs, ws)) in
                worst
                    .iter_mut()
                    .zip([(ours.x(), ours.w()), (&bx[..], &bw[..]), (&gx[..], &gw[..])])
            {
                slot.0 = slot.0.max((xs[i] - x).abs() / EPS);
                slot.1 = slot.1.max(rel(ws[i], w) / EPS);
            }
        }
        eprintln!(
            "n={n}: error vs 40 digits (x abs, w rel, in eps): lightquad {:.2}/{:.2}, \
             bilby {:.2}/{:.2}, gauss-quad {:.2}/{:.2}",
            worst[0].0, worst[0].1, worst[1].0, worst[1].1, worst[2].0, worst[2].1
        );
        results.push((n, worst));
    }
    for (n, worst) in results {
        assert!(worst[0].0 <= worst[1].0.max(worst[2].0) + 0.5, "n={n}");
        assert!(worst[0].1 <= worst[1].1.max(worst[2].1) + 0.5, "n={n}");
    }
}

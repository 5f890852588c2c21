//! Many calls of a Gauss–Legendre integral of `cos(50 x)` over a run-time
//! `[-1, 1]` at a few nodes, for counting instructions per call under
//! callgrind (a measure the shared machine's noise does not move; the
//! criterion group `gl_small` times the same calls):
//!
//! `cargo run --release --example gl_call -- N MODE CALLS`, MODE one of
//! `bare` (`Rule::integrate` without the error estimate), `estimate` (with
//! it), `raw` (`product_sum` alone, no guard), `fixed` (a `FixedOrder`
//! prepared once), `bilby` (its cached rule), `gauss-quad` (its rule).
//! Instructions per call: the difference of the counts at CALLS and at 0,
//! over CALLS (`benches/README.md`, `gl_small`).
use std::hint::black_box;

use lightquad::quadrature::gauss_legendre::FixedOrder;
use lightquad::quadrature::{GaussLegendre, Rule};
use rand::SeedableRng;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(5);
    let which = args.get(2).map_or("bare", String::as_str);
    let calls: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let rule = GaussLegendre {
        error_estimate: which == "estimate",
    };
    let bil = bilby::GaussLegendre::new(n).expect("bilby");
    let fixed = FixedOrder::new(n).expect("an order in range");
    let gq = gauss_quad::GaussLegendre::new(std::num::NonZeroUsize::new(n).expect("n >= 1"));
    // The mode is chosen once, outside the loop: a string compared at
    // every call would count as the call's own.
    let s = match which {
        "bilby" => calls_of(calls, |a, b| {
            bil.rule().integrate(a, b, |x: f64| (50.0 * x).cos())
        }),
        "gauss-quad" => calls_of(calls, |a, b| gq.integrate(a, b, |x: f64| (50.0 * x).cos())),
        "fixed" => calls_of(calls, |a, b| {
            fixed
                .integrate(a, b, |x: f64| (50.0 * x).cos())
                .unwrap_or(f64::NAN)
        }),
        "raw" => calls_of(calls, |a, b| {
            let h = b - a;
            let nodes = lightquad::quadrature::gauss_legendre::unit_rule(n).expect("nodes");
            lightquad::quadrature::nodes::product_sum([&*nodes], |u: [f64; 1]| {
                Ok((50.0 * (a + h * u[0])).cos())
            })
            .map(|s| s.value * h)
            .unwrap_or(0.0)
        }),
        _ => calls_of(calls, |a, b| {
            let h = b - a;
            rule.integrate(n, &mut rng, |u: [f64; 1]| (50.0 * (a + h * u[0])).cos())
                .map(|e| e.value * h)
                .unwrap_or(0.0)
        }),
    };
    println!("{s}");
}

/// The sum of `calls` calls of `integral` on `[-1, 1]`, the ends unknown
/// to the compiler.
fn calls_of(calls: usize, mut integral: impl FnMut(f64, f64) -> f64) -> f64 {
    let mut s = 0.0;
    for _ in 0..calls {
        s += integral(black_box(-1.0), black_box(1.0));
    }
    s
}

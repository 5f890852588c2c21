//! Many calls of a Gauss–Legendre integral of `cos(50 x)` over a run-time
//! `[-1, 1]` at a few nodes, for counting instructions per call under
//! callgrind (a measure the shared machine's noise does not move; the
//! criterion group `gl_small` times the same calls):
//!
//! `cargo run --release --example gl_call -- N MODE CALLS`, MODE one of
//! `bare` (`Rule::integrate` without the error estimate), `estimate` (with
//! it), `raw` (`product_sum` alone, no guard), `fixed` (a `FixedOrder`
//! prepared once), `bilby` (its cached rule).
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
    let mut s = 0.0;
    let bil = bilby::GaussLegendre::new(n).expect("bilby");
    let fixed = FixedOrder::new(n).expect("an order in range");
    for _ in 0..calls {
        let (a, b) = (black_box(-1.0f64), black_box(1.0f64));
        let h = b - a;
        s += match which {
            "bilby" => bil.rule().integrate(a, b, |x: f64| (50.0 * x).cos()),
            "fixed" => fixed
                .integrate(a, b, |x: f64| (50.0 * x).cos())
                .unwrap_or(f64::NAN),
            "raw" => {
                let nodes = lightquad::quadrature::gauss_legendre::unit_rule(n).expect("nodes");
                lightquad::quadrature::nodes::product_sum([&*nodes], |u: [f64; 1]| {
                    Ok((50.0 * (a + h * u[0])).cos())
                })
                .map(|s| s.value * h)
                .unwrap_or(0.0)
            }
            _ => rule
                .integrate(n, &mut rng, |u: [f64; 1]| (50.0 * (a + h * u[0])).cos())
                .map(|e| e.value * h)
                .unwrap_or(0.0),
        };
    }
    println!("{s}");
}

//! The `integral` family's expression evaluator against the same integrand
//! written as a Rust closure.
//!
//! - `expression/point/*`: one evaluation at each of 4096 fixed points of
//!   the 6-D unit cube, per point: a 10-term expression with elementary
//!   functions (`functions`) and a 10-term polynomial (`arithmetic`), each
//!   as `Expr::eval` and as a closure.
//! - `expression/integrate/*`: the whole job, Gauss–Legendre with 4096
//!   nodes over the 2-D unit square through `Integral::evaluate`, against
//!   the rule called directly with the closure.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use lightquad::experiment::validate::{deserialize, validate};
use lightquad::family::{Family, Method};
use lightquad::integral::expr::{Expr, MAX_VARIABLES};
use lightquad::integral::{Integral, Quantity};
use lightquad::quadrature::{AnyRule, GaussLegendre, Rule};
use rand::SeedableRng;

/// Ten terms with elementary functions, in `x1..x6`.
const FUNCTIONS: &str = "x1*exp(-x2) + sin(x3)*x4 + x5*x5 + sqrt(x6) + cos(x1*x2) \
                         + x3/(1 + x4) + abs(x5 - x6) + exp(-(x1*x1)) + log(1 + x2) + x3*x4*x5";

fn functions(x: &[f64]) -> f64 {
    x[0] * (-x[1]).exp()
        + x[2].sin() * x[3]
        + x[4] * x[4]
        + x[5].sqrt()
        + (x[0] * x[1]).cos()
        + x[2] / (1.0 + x[3])
        + (x[4] - x[5]).abs()
        + (-(x[0] * x[0])).exp()
        + (1.0 + x[1]).ln()
        + x[2] * x[3] * x[4]
}

/// Ten terms of arithmetic only.
const ARITHMETIC: &str =
    "1 + x1 + x2*x3 + x4*x5 + x6*x1 + x2*x2 + x3*x4*x5 + 0.5*x6 + x1*x2*x3 + x4";

fn arithmetic(x: &[f64]) -> f64 {
    1.0 + x[0]
        + x[1] * x[2]
        + x[3] * x[4]
        + x[5] * x[0]
        + x[1] * x[1]
        + x[2] * x[3] * x[4]
        + 0.5 * x[5]
        + x[0] * x[1] * x[2]
        + x[3]
}

const NAMES: [&str; 6] = ["x1", "x2", "x3", "x4", "x5", "x6"];

/// 4096 points of the unit cube, padded to the evaluator's variable count.
fn points() -> Vec<[f64; MAX_VARIABLES]> {
    (0..4096u32)
        .map(|i| {
            let mut p = [0.0; MAX_VARIABLES];
            for (k, v) in p.iter_mut().take(6).enumerate() {
                *v = ((i as f64 + 0.5) * (0.618_033_988_7 + 0.1 * k as f64)).fract();
            }
            p
        })
        .collect()
}

fn point(c: &mut Criterion) {
    let pts = points();
    let mut g = c.benchmark_group("expression/point");
    g.throughput(Throughput::Elements(pts.len() as u64));
    type Closure = fn(&[f64]) -> f64;
    let cases: [(&str, &str, Closure); 2] = [
        ("functions", FUNCTIONS, functions),
        ("arithmetic", ARITHMETIC, arithmetic),
    ];
    for (name, text, closure) in cases {
        let Ok(expr) = Expr::compile(text, &NAMES) else {
            panic!("{text} compiles")
        };
        // The two agree before either is timed.
        for p in &pts {
            assert!((expr.eval(p) - closure(p)).abs() <= 1e-13 * closure(p).abs());
        }
        g.bench_function(BenchmarkId::new("expression", name), |b| {
            b.iter(|| pts.iter().map(|p| expr.eval(black_box(p))).sum::<f64>())
        });
        g.bench_function(BenchmarkId::new("closure", name), |b| {
            b.iter(|| pts.iter().map(|p| closure(black_box(p))).sum::<f64>())
        });
    }
    g.finish();
}

fn integrate(c: &mut Criterion) {
    let json = serde_json::json!({
        "name": "b", "family": "integral",
        "scene": {"domain": {"type": "cube", "dimension": 2},
                  "integrand": "x*exp(-y) + sin(x)*y + x*x + sqrt(y) + cos(x*y) + x/(1 + y) + abs(x - y) + exp(-(x*x)) + log(1 + y) + x*y*x"},
        "quantities": ["integral"], "rules": [{"rule": "gauss-legendre"}],
        "budgets": [4096], "repeats": 1, "reference": {"type": "converged"}
    });
    let Ok(exp) = deserialize(json).and_then(|s| validate::<Integral>(s, "b")) else {
        panic!("the bench's experiment is valid")
    };
    let Ok(rule) = AnyRule::by_name("gauss-legendre") else {
        panic!("a rule")
    };
    let method = Method::Rule(rule);
    let closure = |u: [f64; 2]| {
        let (x, y) = (u[0], u[1]);
        x * (-y).exp()
            + x.sin() * y
            + x * x
            + y.sqrt()
            + (x * y).cos()
            + x / (1.0 + y)
            + (x - y).abs()
            + (-(x * x)).exp()
            + (1.0 + y).ln()
            + x * y * x
    };
    let mut g = c.benchmark_group("expression/integrate");
    g.bench_function("family", |b| {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
        b.iter(|| {
            Integral::evaluate(
                &exp.scene,
                &method,
                black_box(4096),
                &mut rng,
                &[Quantity::Integral],
            )
        })
    });
    g.bench_function("closure", |b| {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
        b.iter(|| GaussLegendre::default().integrate(black_box(4096), &mut rng, closure))
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = point, integrate
}
criterion_main!(benches);

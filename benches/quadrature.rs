//! Quadrature benchmarks.
//!
//! - `gl_nodes/*`: Gauss–Legendre node and weight generation (the whole rule,
//!   uncached) for n = 1, 2, 5, 10, 20, 50, 100, 1e3, 1e4, 1e5, 1e6: lightquad
//!   against the crates `gauss-quad` and `bilby` (both implement Bogaert's
//!   method), serial and parallel, in the same run. For n <= 100 `table`
//!   borrows the compiled-in rule; `lightquad-owned` adds copying it into a
//!   buffer of its own, as the peers' constructors return owned rules.
//! - `gl_integrate/*`: integrating `cos(50 x)` over [-1, 1] at n = 1e6 with
//!   cached nodes, against the same peers: the interval through `black_box`
//!   (as a run-time interval), `*/const` with constant bounds, and `*/par`
//!   on every core (lightquad's `line_sum_par`, gauss-quad's `par_integrate`).
//! - `gl_small/*`: the same integral with n = 5 .. 100 nodes, one call per
//!   iteration: the fixed cost of a call, against the peers' cached rules;
//!   `lightquad` is `Rule::integrate` (its order looked up at every call),
//!   `lightquad/fixed` a `FixedOrder` prepared once, as the peers' rules are,
//!   `lightquad/estimate` the rule with its error estimate.
//! - `sum_overhead/*`: the shared compensated summation against a bare loop
//!   that only evaluates the integrand at the same nodes, n = 1e3 .. 1e6.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use lightquad::quadrature::gauss_legendre::{TABLE_MAX_ORDER, table, unit_nodes};
use lightquad::quadrature::nodes::{line_sum_par, product_sum};

fn gl_nodes(c: &mut Criterion) {
    let mut g = c.benchmark_group("gl_nodes");
    g.warm_up_time(Duration::from_millis(500));
    for n in [
        1usize, 2, 5, 10, 20, 50, 100, 1_000, 10_000, 100_000, 1_000_000,
    ] {
        g.sample_size(if n >= 100_000 { 20 } else { 50 });
        g.measurement_time(Duration::from_millis(match n {
            0..=100 => 1000,
            101..=99_999 => 2000,
            _ => 4000,
        }));
        g.bench_with_input(BenchmarkId::new("lightquad", n), &n, |b, &n| {
            b.iter(|| table(black_box(n)))
        });
        if n <= TABLE_MAX_ORDER {
            // table(n) borrows the compiled-in rule; what owned copies cost.
            g.bench_with_input(BenchmarkId::new("lightquad-owned", n), &n, |b, &n| {
                b.iter(|| table(black_box(n)).map(|t| t.into_owned()))
            });
        }
        g.bench_with_input(BenchmarkId::new("bilby", n), &n, |b, &n| {
            b.iter(|| bilby::GaussLegendre::new(black_box(n)))
        });
        g.bench_with_input(BenchmarkId::new("bilby-par", n), &n, |b, &n| {
            b.iter(|| bilby::GaussLegendre::new_par(black_box(n)))
        });
        let nz = std::num::NonZeroUsize::new(n).unwrap_or(std::num::NonZeroUsize::MIN);
        g.bench_with_input(BenchmarkId::new("gauss-quad", n), &nz, |b, &nz| {
            b.iter(|| gauss_quad::GaussLegendre::new(black_box(nz)))
        });
        g.bench_with_input(BenchmarkId::new("gauss-quad-par", n), &nz, |b, &nz| {
            b.iter(|| gauss_quad::GaussLegendre::par_new(black_box(nz)))
        });
    }
    g.finish();
}

fn integrand(x: f64) -> f64 {
    (50.0 * x).cos()
}

fn gl_integrate(c: &mut Criterion) {
    let n = 1_000_000;
    let mut g = c.benchmark_group("gl_integrate");
    g.sample_size(20).measurement_time(Duration::from_secs(4));
    let Ok(nodes) = unit_nodes(n) else { return };
    // The interval [a, b] = [-1, 1] reaches every integrator through
    // `black_box`, as a caller's run-time interval would: with constant
    // bounds bilby's inlined affine map `x = (b - a)/2 t + (a + b)/2` folds
    // to `t + 0`, one dependent operation fewer before each `cos` than any
    // interval known only at run time (1 to 4% of bilby's time at n = 1e6
    // in `examples/gl_race.rs`, paired rounds; gauss-quad's map folds only
    // partly, and showed no effect), which is no property of a quadrature
    // library. Both settings are timed: `*/const` keeps the constants.
    let (a, b) = (-1.0f64, 1.0f64);
    g.bench_function(BenchmarkId::new("lightquad", n), |bench| {
        // [a, b] from the unit interval: x = a + (b - a) u, dx = (b - a) du.
        bench.iter(|| {
            let (a, b) = (black_box(a), black_box(b));
            let h = b - a;
            product_sum([nodes.as_ref()], |u: [f64; 1]| Ok(integrand(a + h * u[0])))
                .map(|s| s.value * h)
        })
    });
    g.bench_function(BenchmarkId::new("lightquad/const", n), |bench| {
        bench.iter(|| {
            product_sum([nodes.as_ref()], |u: [f64; 1]| {
                Ok(integrand(2.0 * u[0] - 1.0))
            })
            .map(|s| s.value * 2.0)
        })
    });
    let Ok(bil) = bilby::GaussLegendre::new(n) else {
        return;
    };
    g.bench_function(BenchmarkId::new("bilby", n), |bench| {
        bench.iter(|| bil.rule().integrate(black_box(a), black_box(b), integrand))
    });
    g.bench_function(BenchmarkId::new("bilby/const", n), |bench| {
        bench.iter(|| bil.rule().integrate(-1.0, 1.0, integrand))
    });
    let gq = gauss_quad::GaussLegendre::new(std::num::NonZeroUsize::MIN.saturating_add(n - 1));
    g.bench_function(BenchmarkId::new("gauss-quad", n), |bench| {
        bench.iter(|| gq.integrate(black_box(a), black_box(b), integrand))
    });
    g.bench_function(BenchmarkId::new("gauss-quad/const", n), |bench| {
        bench.iter(|| gq.integrate(-1.0, 1.0, integrand))
    });
    // On every core: lightquad's spans on rayon's threads, gauss-quad's
    // `par_integrate` (bilby has no parallel Gauss–Legendre integral).
    g.bench_function(BenchmarkId::new("lightquad/par", n), |bench| {
        bench.iter(|| {
            let (a, b) = (black_box(a), black_box(b));
            let h = b - a;
            line_sum_par(&nodes, |u| Ok(integrand(a + h * u))).map(|s| s.value * h)
        })
    });
    g.bench_function(BenchmarkId::new("gauss-quad/par", n), |bench| {
        bench.iter(|| gq.par_integrate(black_box(a), black_box(b), integrand))
    });
    g.finish();
}

fn sum_overhead(c: &mut Criterion) {
    let mut g = c.benchmark_group("sum_overhead");
    g.sample_size(30).measurement_time(Duration::from_secs(3));
    for n in [1_000usize, 10_000, 100_000, 1_000_000] {
        let Ok(nodes) = unit_nodes(n) else { return };
        g.bench_with_input(BenchmarkId::new("product_sum", n), &n, |b, _| {
            b.iter(|| product_sum([nodes.as_ref()], |u: [f64; 1]| Ok(integrand(u[0]))))
        });
        g.bench_with_input(BenchmarkId::new("bare_evaluations", n), &n, |b, _| {
            b.iter(|| {
                // Only the evaluations, kept alive by a plain running sum.
                let mut s = 0.0;
                for &u in &nodes.u {
                    s += integrand(black_box(u));
                }
                s
            })
        });
    }
    g.finish();
}

/// Integrating `cos(50 x)` over a run-time `[a, b] = [-1, 1]` with a few
/// nodes, one call per iteration, rules built outside the loop (the peers'
/// cached rules; lightquad's tables for n <= 100 are compiled in):
/// `lightquad` is `Rule::integrate` with the error estimate off (the peers
/// have none), `lightquad/estimate` with it on (its companion rules'
/// evaluations included). Each closure hands criterion the f64, as a
/// caller takes it, a lightquad `Result` by `unwrap_or` (as `gl_race` and
/// `gl_call` do): the peers return an f64, and a whole `Result` kept for
/// criterion would be stored where no caller stores it.
fn gl_small(c: &mut Criterion) {
    use lightquad::quadrature::{GaussLegendre, Rule};
    use rand::SeedableRng;
    let mut g = c.benchmark_group("gl_small");
    g.sample_size(50)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(1));
    let (a, b) = (-1.0f64, 1.0f64);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    for n in [5usize, 10, 20, 50, 100] {
        for (label, rule) in [
            (
                "lightquad",
                GaussLegendre {
                    error_estimate: false,
                },
            ),
            ("lightquad/estimate", GaussLegendre::default()),
        ] {
            g.bench_with_input(BenchmarkId::new(label, n), &n, |bench, &n| {
                bench.iter(|| {
                    let (a, b) = (black_box(a), black_box(b));
                    let h = b - a;
                    rule.integrate(n, &mut rng, |u: [f64; 1]| integrand(a + h * u[0]))
                        .map_or(f64::NAN, |e| e.value * h)
                })
            });
        }
        let Ok(fixed) = lightquad::quadrature::gauss_legendre::FixedOrder::new(n) else {
            return;
        };
        g.bench_with_input(BenchmarkId::new("lightquad/fixed", n), &n, |bench, _| {
            bench.iter(|| {
                fixed
                    .integrate(black_box(a), black_box(b), integrand)
                    .unwrap_or(f64::NAN)
            })
        });
        let Ok(bil) = bilby::GaussLegendre::new(n) else {
            return;
        };
        g.bench_with_input(BenchmarkId::new("bilby", n), &n, |bench, _| {
            bench.iter(|| bil.rule().integrate(black_box(a), black_box(b), integrand))
        });
        let gq = gauss_quad::GaussLegendre::new(std::num::NonZeroUsize::MIN.saturating_add(n - 1));
        g.bench_with_input(BenchmarkId::new("gauss-quad", n), &n, |bench, _| {
            bench.iter(|| gq.integrate(black_box(a), black_box(b), integrand))
        });
    }
    g.finish();
}

criterion_group!(benches, gl_nodes, gl_integrate, gl_small, sum_overhead);
criterion_main!(benches);

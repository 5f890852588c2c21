//! Time to 1e-6 and to 1e-12 relative error in the irradiance of a
//! rectangle light, per form and rule of the rendering family.
//!
//! The scene is the bundled `r-h-vs-a-tilted-rectangle` (a tilted
//! parallelogram light over a tilted receiver), whose irradiance has a
//! closed form (Lambert's contour formula, `E = 0.2702188636144481`). For
//! each form (`E_area`: R-A over the light's surface; `E_cone`: R-H over the
//! light's bounding cone; `E_cosine`, `E_hemisphere`: R-H over the whole
//! hemisphere by the cosine and the uniform map) and each rule, the setup
//! sweeps the budget (doubling from 16 evaluations) and prints, for each
//! target, the smallest budget from which every larger budget of the sweep
//! stays within it (an error that dips below the target and rises again is
//! not counted). A deterministic rule is within when its error is; a
//! stochastic one when its error and its own standard error both are. Criterion then times one evaluation at
//! that budget. Budgets go up to 2^22 under `cargo bench`, and to 2^12 when
//! `cargo test --benches` runs the bench once.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use lightquad::experiment::validate::{Experiment, deserialize, parse_json, validate};
use lightquad::family::{Family, Method};
use lightquad::rendering::experiment::{Mis, Rendering, RenderingQuantity};
use rand::SeedableRng;

/// The bundled experiment, validated.
fn experiment() -> Experiment<Rendering> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/experiments/r-h-vs-a-tilted-rectangle.json"
    );
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    parse_json(&text)
        .and_then(deserialize::<Rendering>)
        .and_then(|spec| validate::<Rendering>(spec, "bench"))
        .unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// `q` by `method` at `budget`: (value, the method's own error estimate);
/// None for a budget the rule refuses (Genz–Malik needs 17 a box).
fn irradiance(
    exp: &Experiment<Rendering>,
    method: &Method<Mis>,
    budget: usize,
    q: RenderingQuantity,
) -> Option<(f64, f64)> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    let out = Rendering::evaluate(&exp.scene, method, budget, &mut rng, &[q]).ok()?;
    Some((out[&q].value[0], out[&q].error[0]))
}

const RULES: [(&str, bool); 7] = [
    ("gauss-legendre", false),
    ("genz-malik", false),
    ("simpson", false),
    ("trapezoid", false),
    ("sobol", true),
    ("stratified", true),
    ("monte-carlo", true),
];

const FORMS: [(&str, RenderingQuantity); 4] = [
    ("E_area", RenderingQuantity::EArea),
    ("E_cone", RenderingQuantity::ECone),
    ("E_cosine", RenderingQuantity::ECosine),
    ("E_hemisphere", RenderingQuantity::EHemisphere),
];

const TARGETS: [f64; 2] = [1e-6, 1e-12];

fn rendering(c: &mut Criterion) {
    let exp = experiment();
    let exact = Rendering::closed_form(&exp.scene, RenderingQuantity::EArea)
        .unwrap_or_else(|| panic!("the rectangle's closed form"))[0];
    // `cargo bench` passes --bench; `cargo test --benches` runs each once.
    let benching = std::env::args().any(|a| a == "--bench");
    let largest: usize = if benching { 1 << 22 } else { 1 << 12 };
    eprintln!("closed form E = {exact:.16e}; budgets 16 to {largest}");

    let mut g = c.benchmark_group("rectangle_irradiance");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(200));
    for (form, q) in FORMS {
        for (rule, stochastic) in RULES {
            let method: Method<Mis> = serde_json::from_value(serde_json::json!({ "rule": rule }))
                .unwrap_or_else(|e| panic!("{rule}: {e}"));
            // One sweep of every budget; the bound at each (None where the
            // rule refuses the budget).
            let mut sweep = Vec::new();
            let mut budget = 16;
            while budget <= largest {
                let bound = irradiance(&exp, &method, budget, q).map(|(value, estimate)| {
                    let error = ((value - exact) / exact).abs();
                    let bound = if stochastic {
                        error.max(estimate / exact)
                    } else {
                        error
                    };
                    (error, bound)
                });
                sweep.push((budget, bound));
                budget *= 2;
            }
            let last = sweep
                .iter()
                .rev()
                .find_map(|(_, b)| b.map(|(e, _)| e))
                .unwrap_or(f64::NAN);
            // Each target's smallest budget from which every larger budget
            // of the sweep stays within it (a lucky crossing does not count).
            let reached = TARGETS.map(|target| {
                let mut first = None;
                for &(n, b) in sweep.iter().rev() {
                    match b {
                        Some((error, bound)) if bound <= target => first = Some((n, error)),
                        Some(_) => break,
                        None => {}
                    }
                }
                first
            });
            for (slot, target) in reached.iter().zip(TARGETS) {
                let Some((n, error)) = *slot else {
                    eprintln!(
                        "{form} {rule}: {target:e} not held from any budget up to {largest} \
                         evaluations (error there {last:.1e})"
                    );
                    continue;
                };
                eprintln!(
                    "{form} {rule}: {target:e} held from {n} evaluations (error there \
                     {error:.1e}, at {largest} {last:.1e})"
                );
                let id = BenchmarkId::new(format!("{form}/{rule}/{target:e}"), n);
                g.bench_function(id, |b| {
                    b.iter(|| irradiance(black_box(&exp), &method, n, q))
                });
            }
        }
    }
    g.finish();
}

criterion_group!(benches, rendering);
criterion_main!(benches);

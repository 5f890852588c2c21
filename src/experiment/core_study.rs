//! The built-in study of the quadrature core: every rule on integrals whose
//! values are known in closed form, over a geometric budget sweep, with the
//! true error beside the rule's own estimate, the cost, and the fitted order.

use std::f64::consts::PI;
use std::time::Instant;

use rand::SeedableRng;

use super::fit::fitted_order;
use crate::domain::{Disk, Hemisphere, integrate_over};
use crate::error::QuadError;
use crate::estimate::Estimate;
use crate::quadrature::{AnyRule, RULES, Rule};

/// One row of the study: a rule at one budget on one integral.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Integral name.
    pub integral: &'static str,
    /// Rule name.
    pub rule: &'static str,
    /// Budget asked for.
    pub budget: usize,
    /// The estimate.
    pub estimate: Estimate<f64>,
    /// `|value - exact|`.
    pub true_error: f64,
    /// Wall time in seconds (nodes cached: integration only).
    pub seconds: f64,
}

/// A test integral with its exact value.
struct Case {
    name: &'static str,
    exact: f64,
}

const CASES: [Case; 3] = [
    Case {
        name: "int_0^1 exp(u) du = e - 1",
        exact: std::f64::consts::E - 1.0,
    },
    Case {
        name: "unit disk: int exp(-(x^2+y^2)) dA = pi (1 - 1/e)",
        exact: PI * (1.0 - 1.0 / std::f64::consts::E),
    },
    Case {
        name: "hemisphere: int cos^3(theta) d omega = pi/2",
        exact: PI / 2.0,
    },
];

fn evaluate(case: usize, rule: &AnyRule, n: usize, seed: u64) -> Result<Estimate<f64>, QuadError> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    match case {
        0 => rule.integrate(n, &mut rng, |u: [f64; 1]| u[0].exp()),
        1 => {
            let disk = Disk::new(crate::domain::Vec3::zeros(), crate::domain::Vec3::z(), 1.0)?;
            integrate_over(rule, &disk, n, &mut rng, |p| {
                (-(p.x * p.x + p.y * p.y)).exp()
            })
        }
        _ => integrate_over(rule, &Hemisphere::uniform(), n, &mut rng, |w| {
            w.z * w.z * w.z
        }),
    }
}

/// Runs every rule on every case over budgets `4^1 .. 4^max_power`.
pub fn run(max_power: u32, seed: u64) -> Vec<Row> {
    let mut rows = Vec::new();
    for (ci, case) in CASES.iter().enumerate() {
        for (name, _) in RULES {
            let Ok(rule) = AnyRule::by_name(name) else {
                continue;
            };
            for p in 1..=max_power {
                let n = 4usize.pow(p);
                let start = Instant::now();
                let result = evaluate(ci, &rule, n, seed);
                let seconds = start.elapsed().as_secs_f64();
                // Rules that cannot take this dimension or budget are skipped.
                if let Ok(estimate) = result {
                    rows.push(Row {
                        integral: case.name,
                        rule: rule.name(),
                        budget: n,
                        true_error: (estimate.value - case.exact).abs(),
                        estimate,
                        seconds,
                    });
                }
            }
        }
    }
    rows
}

/// The study as Markdown: one table per integral, then fitted orders.
pub fn markdown(rows: &[Row]) -> String {
    let mut out = String::from("# lightquad core study\n\n");
    out.push_str(
        "True error against the rule's own error estimate, cost in integrand \
         evaluations and wall time. Fitted order: least-squares slope of \
         log(true error) against log(evaluations) over the rows with a non-zero error \
         above 1e-15 relative (rounding floor).\n",
    );
    for case in CASES.iter() {
        out.push_str(&format!("\n## {}\n\n", case.name));
        out.push_str(
            "| rule | n | evaluations | value | true error | estimated error | time (s) |\n",
        );
        out.push_str("|---|---:|---:|---:|---:|---:|---:|\n");
        for r in rows.iter().filter(|r| r.integral == case.name) {
            out.push_str(&format!(
                "| {} | {} | {} | {:.15e} | {:.2e} | {:.2e} | {:.2e} |\n",
                r.rule,
                r.budget,
                r.estimate.evaluations,
                r.estimate.value,
                r.true_error,
                r.estimate.error,
                r.seconds
            ));
        }
        out.push_str("\n| rule | fitted slope of log error vs log evaluations (order p shows as -p) |\n|---|---:|\n");
        for (name, _) in RULES {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.integral == case.name && r.rule == *name)
                .filter(|r| r.true_error > 1e-15 * case.exact.abs())
                .map(|r| (r.estimate.evaluations as f64, r.true_error))
                .collect();
            if let Some(order) = fitted_order(&pts) {
                out.push_str(&format!("| {name} | {order:.2} |\n"));
            }
        }
    }
    out
}

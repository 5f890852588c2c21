//! An experiment run from code: an experiment file written here (the
//! calibration family's `int_0^1 e^u du`, three rules, three budgets), run
//! into a report in a temporary folder, and its results read back: the
//! Gauss–Legendre value at the largest budget against `e - 1`.
//!
//! `cargo run --release --example experiment_from_code`

use std::error::Error;

use lightquad::experiment::run::{JobResult, RunOptions};
use lightquad::experiment::{Source, run_sources};
use lightquad::families;

const EXPERIMENT: &str = r#"{
  "name": "exp-from-code",
  "family": "calibration",
  "description": "int_0^1 e^u du = e - 1 with three rules.",
  "scene": {},
  "quantities": ["exp"],
  "rules": [{"rule": "trapezoid"}, {"rule": "gauss-legendre"}, {"rule": "monte-carlo"}],
  "budgets": [4, 16, 64],
  "repeats": 2,
  "seed": 1,
  "reference": {"type": "closed-form"}
}"#;

fn main() -> Result<(), Box<dyn Error>> {
    let dir = std::env::temp_dir().join(format!("lightquad-example-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let file = dir.join("exp-from-code.json");
    std::fs::write(&file, EXPERIMENT)?;

    // The registry of the crate's families; a family of your own would be
    // added with `.with::<MyFamily>()`.
    let registry = families::builtin();
    let opts = RunOptions {
        out: dir.join("report"),
        resume: false,
        shard: None,
        progress: false,
    };
    let index = run_sources(&registry, &[Source::File(file)], &opts)?;
    println!("report: {} (and index.html beside it)", index.display());

    // One JSON line per job (rule x budget x repeat).
    let text = std::fs::read_to_string(dir.join("report/exp-from-code/results.jsonl"))?;
    let results: Vec<JobResult> = text
        .lines()
        .map(serde_json::from_str)
        .collect::<Result<_, _>>()?;
    assert_eq!(results.len(), 3 * 3 * 2);
    let exact = std::f64::consts::E - 1.0;
    for r in &results {
        let v = r.quantities["exp"].value[0];
        println!(
            "{:<16} n = {:>3} repeat {}: {v:.16} (error {:.1e})",
            r.rule,
            r.budget,
            r.repeat,
            (v - exact).abs()
        );
    }
    let gl = results
        .iter()
        .find(|r| r.rule == "gauss-legendre" && r.budget == 64)
        .ok_or("no Gauss–Legendre job at n = 64")?;
    let error = (gl.quantities["exp"].value[0] - exact).abs();
    assert!(error < 1e-14, "Gauss–Legendre error {error:e}");
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}

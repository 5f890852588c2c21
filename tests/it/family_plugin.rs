//! A family defined outside the crate plugs into the experiment layer with one
//! `Registry::with` and nothing in src/experiment/ touched: its scene format,
//! its quantities (a scalar, a 3-channel vector, a 2-D integral), its own
//! estimator beside the rules, and products named in the experiment file.
//! The values it reports are checked against the moments `1/(j+1)`, computed
//! here, independently of the family's own closed forms.

use std::fs;
use std::path::PathBuf;

use lightquad::error::{QuadError, SpecError};
use lightquad::experiment::run::{JobResult, RunOptions, read_results};
use lightquad::experiment::{Registry, RunError, run_files};
use lightquad::family::{Estimator, Family, Measured, Method, Outcome, Quantity};
use lightquad::quadrature::Rule;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Monomials on the unit interval and square.
struct Poly;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct PolyScene {
    /// The degree `k` of `u^k`.
    degree: u32,
}

#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize, JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
enum PolyQuantity {
    /// `int_0^1 u^k du`.
    Moment,
    /// `(int u^k, int u^{k+1}, int u^{k+2})`.
    Moments,
    /// `int_0^1 int_0^1 (u v)^k du dv`.
    Square,
}

impl Quantity for PolyQuantity {
    fn name(&self) -> &'static str {
        match self {
            PolyQuantity::Moment => "moment",
            PolyQuantity::Moments => "moments",
            PolyQuantity::Square => "square",
        }
    }
    fn all() -> &'static [Self] {
        &[
            PolyQuantity::Moment,
            PolyQuantity::Moments,
            PolyQuantity::Square,
        ]
    }
}

/// The left Riemann sum: the family's own estimator, for 1-D quantities only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "rule")]
enum Riemann {
    #[serde(rename = "left-riemann")]
    Left,
}

impl Estimator for Riemann {
    fn name(&self) -> &'static str {
        "left-riemann"
    }
    fn about(&self) -> &'static str {
        "left Riemann sum"
    }
    fn min_budget(&self) -> usize {
        1
    }
    fn is_random(&self) -> bool {
        false
    }
    fn all() -> Vec<Self> {
        vec![Riemann::Left]
    }
}

fn moments(k: f64, u: f64) -> lightquad::Rgb {
    lightquad::Rgb::new(u.powf(k), u.powf(k + 1.0), u.powf(k + 2.0))
}

impl Family for Poly {
    const NAME: &'static str = "poly";
    const ABOUT: &'static str = "monomials";
    const EQUATIONS: &'static [&'static str] = &["P-1"];
    const BUDGET_UNIT: &'static str = "evaluations";
    type SceneSpec = PolyScene;
    type Scene = f64;
    type Quantity = PolyQuantity;
    type Estimator = Riemann;

    fn build(spec: &PolyScene) -> Result<f64, SpecError> {
        if spec.degree > 50 {
            return Err(SpecError::at(
                "scene.degree",
                format!("{} is not an integer in 0..=50", spec.degree),
            ));
        }
        Ok(f64::from(spec.degree))
    }

    fn dimension(_: &f64, q: PolyQuantity) -> usize {
        if q == PolyQuantity::Square { 2 } else { 1 }
    }

    fn channels(_: &f64, q: PolyQuantity) -> usize {
        if q == PolyQuantity::Moments { 3 } else { 1 }
    }

    fn estimates(_: &Riemann) -> &'static [PolyQuantity] {
        &[PolyQuantity::Moment, PolyQuantity::Moments]
    }

    fn evaluate(
        &k: &f64,
        method: &Method<Riemann>,
        n: usize,
        rng: &mut rand_pcg::Pcg64,
        quantities: &[PolyQuantity],
    ) -> Result<Outcome<PolyQuantity>, QuadError> {
        let mut out = Outcome::new();
        for &q in quantities {
            let m = match (method, q) {
                (Method::Estimator(Riemann::Left), _) => {
                    let sum = (0..n).fold(lightquad::Rgb::zeros(), |s, i| {
                        s + moments(k, i as f64 / n as f64)
                    }) / n as f64;
                    // A bug planted at budget 7: the runner must turn its
                    // NaN into a failed job.
                    let sum = if n == 7 { sum.map(|_| f64::NAN) } else { sum };
                    let e = lightquad::Estimate::deterministic(
                        sum,
                        lightquad::Rgb::repeat(1.0 / n as f64),
                        n as u64,
                    );
                    let mut m = Measured::from(e);
                    if q == PolyQuantity::Moment {
                        m.value.truncate(1);
                        m.error.truncate(1);
                    }
                    m
                }
                (Method::Rule(r), PolyQuantity::Moment) => {
                    let e = r.integrate(n, rng, |u: [f64; 1]| u[0].powf(k))?;
                    Measured::scalar(e.value, e.error, e.evaluations)
                }
                (Method::Rule(r), PolyQuantity::Moments) => {
                    r.integrate(n, rng, |u: [f64; 1]| moments(k, u[0]))?.into()
                }
                (Method::Rule(r), PolyQuantity::Square) => {
                    let e = r.integrate(n, rng, |u: [f64; 2]| (u[0] * u[1]).powf(k))?;
                    Measured::scalar(e.value, e.error, e.evaluations)
                }
            };
            out.insert(q, m);
        }
        Ok(out)
    }

    fn closed_form(&k: &f64, q: PolyQuantity) -> Option<Vec<f64>> {
        Some(match q {
            PolyQuantity::Moment => vec![1.0 / (k + 1.0)],
            PolyQuantity::Moments => vec![1.0 / (k + 1.0), 1.0 / (k + 2.0), 1.0 / (k + 3.0)],
            PolyQuantity::Square => vec![1.0 / ((k + 1.0) * (k + 1.0))],
        })
    }

    fn closed_forms_available() -> &'static str {
        "all"
    }

    fn converged(
        k: &f64,
        n: usize,
        quantities: &[PolyQuantity],
    ) -> Result<Outcome<PolyQuantity>, QuadError> {
        // A bug planted at degree 49: the reference cannot be computed.
        if *k == 49.0 {
            return Err(QuadError::invalid(
                "degree",
                49,
                "a degree the planted bug spares",
            ));
        }
        let gl = Method::Rule(lightquad::quadrature::AnyRule::by_name("gauss-legendre")?);
        let mut rng = <rand_pcg::Pcg64 as rand::SeedableRng>::seed_from_u64(0);
        Self::evaluate(k, &gl, n * n, &mut rng, quantities)
    }
}

const FILE: &str = r#"{
  "name": "poly-moments",
  "family": "poly",
  "equations": ["P-1"],
  "scene": { "degree": 5 },
  "quantities": ["moment", "moments", "square"],
  "rules": [
    { "rule": "gauss-legendre" },
    { "rule": "product", "outer": { "rule": "gauss-legendre" }, "inner": { "rule": "trapezoid" } },
    { "rule": "stratified" }
  ],
  "budgets": [16, 64, 256],
  "repeats": 2,
  "reference": { "type": "closed-form" }
}"#;

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lightquad-plugin-{}-{tag}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

fn run(registry: &Registry, text: &str, tag: &str) -> (Result<PathBuf, RunError>, PathBuf) {
    let dir = scratch(tag);
    let file = dir.join("e.json");
    fs::write(&file, text).expect("write");
    let opts = RunOptions {
        out: dir.join("out"),
        resume: false,
        shard: None,
        progress: false,
    };
    (run_files(registry, &[file], &opts), dir)
}

fn registry() -> Registry {
    lightquad::families::builtin().with::<Poly>()
}

fn value(r: &JobResult, q: &str) -> Vec<f64> {
    r.quantities[q].value.clone()
}

#[test]
fn a_family_from_outside_the_crate_runs_and_reports() {
    // The product only integrates in 2-D: it must run alone on `square`.
    let text = FILE.replace(
        "{ \"rule\": \"product\", \"outer\": { \"rule\": \"gauss-legendre\" }, \"inner\": { \"rule\": \"trapezoid\" } },\n",
        "",
    );
    let (index, dir) = run(&registry(), &text, "run");
    let index = index.unwrap_or_else(|e| panic!("{e}"));
    let out = dir.join("out").join("poly-moments");
    let results = read_results(&out.join("results.jsonl"), None);
    assert_eq!(results.len(), 2 * 3 * 2, "rules x budgets x repeats");
    for r in &results {
        assert_eq!(r.family, "poly");
        let m = value(r, "moments");
        assert_eq!(m.len(), 3, "three channels");
        if r.rule == "gauss-legendre" {
            // 4 nodes are exact for degree 7 in 1-D; u^5 .. u^7.
            for (j, v) in m.iter().enumerate() {
                let want = 1.0 / (6.0 + j as f64);
                assert!((v - want).abs() < 1e-15, "moment {j}: {v} vs {want}");
            }
            let sq = value(r, "square")[0];
            assert!((sq - 1.0 / 36.0).abs() < 1e-15, "square {sq}");
        } else {
            // Stratified: within 5 of its standard errors.
            let se = r.quantities["moment"].error[0];
            assert!((value(r, "moment")[0] - 1.0 / 6.0).abs() < 5.0 * se);
        }
    }
    let report = fs::read_to_string(out.join("report.md")).expect("report");
    for q in [
        "## moment (",
        "## moments (",
        "## square (",
        "Family `poly`",
    ] {
        assert!(report.contains(q), "report lacks {q}");
    }
    assert!(report.contains("3 channels"), "vector values shown as such");
    assert!(
        fs::read_to_string(index)
            .expect("index")
            .contains("poly-moments")
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn products_and_the_familys_own_estimator_are_named_in_the_file() {
    let text = FILE
        .replace("[\"moment\", \"moments\", \"square\"]", "[\"square\"]")
        .replace("{ \"rule\": \"gauss-legendre\" },\n", "");
    let (index, dir) = run(&registry(), &text, "product");
    index.unwrap_or_else(|e| panic!("{e}"));
    let results = read_results(&dir.join("out/poly-moments/results.jsonl"), None);
    let product: Vec<_> = results
        .iter()
        .filter(|r| r.rule == "product(gauss-legendre,trapezoid)")
        .collect();
    assert_eq!(product.len(), 3 * 2);
    // The trapezoid factor's error for int v^5 at m nodes is about
    // (f'(1) - f'(0)) h^2 / 12 = 5 / (12 (m - 1)^2), times int u^5 = 1/6; the
    // trapezoid takes an odd number of nodes (its estimate halves the step).
    for r in product {
        let root = (r.budget as f64).sqrt().floor();
        let m = if root % 2.0 == 0.0 { root - 1.0 } else { root };
        let err = (value(r, "square")[0] - 1.0 / 36.0).abs();
        let want = 5.0 / (12.0 * (m - 1.0) * (m - 1.0)) / 6.0;
        assert!(
            err < 1.5 * want && err > 0.5 * want,
            "n = {}: {err} vs {want}",
            r.budget
        );
    }
    let _ = fs::remove_dir_all(&dir);

    let text = FILE
        .replace("[\"moment\", \"moments\", \"square\"]", "[\"moment\", \"moments\"]")
        .replace(
            "{ \"rule\": \"product\", \"outer\": { \"rule\": \"gauss-legendre\" }, \"inner\": { \"rule\": \"trapezoid\" } },\n",
            "{ \"rule\": \"left-riemann\" },\n",
        );
    let (index, dir) = run(&registry(), &text, "riemann");
    index.unwrap_or_else(|e| panic!("{e}"));
    let results = read_results(&dir.join("out/poly-moments/results.jsonl"), None);
    for r in results.iter().filter(|r| r.rule == "left-riemann") {
        // Left sum of u^5: 1/6 - 1/(2n) + O(1/n^2).
        let n = r.budget as f64;
        let err = 1.0 / 6.0 - value(r, "moment")[0];
        assert!((err * 2.0 * n - 1.0).abs() < 5.0 / n, "n = {n}: {err}");
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn the_family_and_its_limits_are_checked_before_any_job_runs() {
    // Not registered in the crate's own registry.
    let (result, dir) = run(&lightquad::families::builtin(), FILE, "unknown");
    let e = result.expect_err("unknown family").to_string();
    assert!(
        e.contains("at `family`: unknown family \"poly\": expected one of"),
        "{e}"
    );
    assert!(!dir.join("out").exists(), "a rejected run left output");
    let _ = fs::remove_dir_all(&dir);
    // The estimator does not do 2-D; the product does only 2-D.
    let bad = FILE
        .replace("{ \"rule\": \"stratified\" }", "{ \"rule\": \"left-riemann\" }")
        .replace(
            "{ \"rule\": \"product\", \"outer\": { \"rule\": \"gauss-legendre\" }, \"inner\": { \"rule\": \"trapezoid\" } },\n",
            "",
        );
    let e = run(&registry(), &bad, "estimator")
        .0
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("at `rules[1]`: estimator `left-riemann` estimates only moment, moments, but quantities[2] is square"),
        "{e}"
    );
    let e = run(&registry(), FILE, "dims")
        .0
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("at `rules[1]`: rule `product` integrates in dimension 2 only, but quantities[0] (moment)"),
        "{e}"
    );
    let bad = FILE.replace("\"degree\": 5", "\"degree\": 99");
    let e = run(&registry(), &bad, "scene")
        .0
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("at `scene.degree`: 99 is not an integer in 0..=50"),
        "{e}"
    );
    let bad = FILE.replace("\"P-1\"", "\"V-tau\"");
    let e = run(&registry(), &bad, "eq")
        .0
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("at `equations[0]`: unknown equation ID \"V-tau\" for family poly"),
        "{e}"
    );
    for tag in ["estimator", "dims", "scene", "eq"] {
        let _ = fs::remove_dir_all(scratch(tag));
    }
}

#[test]
fn a_non_finite_value_is_a_failed_job_that_resume_and_merge_keep() {
    // NaN/inf used to be written as JSON null with exit 0; `--resume` then
    // re-ran those jobs forever and `merge` called the folder incomplete.
    let text = FILE
        .replace("[\"moment\", \"moments\", \"square\"]", "[\"moment\"]")
        .replace("[16, 64, 256]", "[7, 16]")
        .replace(
            "{ \"rule\": \"product\", \"outer\": { \"rule\": \"gauss-legendre\" }, \"inner\": { \"rule\": \"trapezoid\" } },\n",
            "{ \"rule\": \"left-riemann\" },\n",
        );
    let (result, dir) = run(&registry(), &text, "nan");
    let e = result.expect_err("a failed job").to_string();
    assert!(e.contains("2 of 12 jobs failed"), "{e}");
    let file = dir.join("out/poly-moments/results.jsonl");
    let before = fs::read_to_string(&file).expect("results");
    let results = read_results(&file, None);
    assert_eq!(results.len(), 12, "every line parses");
    let failed: Vec<_> = results.iter().filter(|r| r.failure.is_some()).collect();
    assert_eq!(failed.len(), 2);
    for r in &failed {
        assert_eq!((r.rule.as_str(), r.budget), ("left-riemann", 7));
        let why = r.failure.as_deref().unwrap_or_default();
        assert!(why.contains("non-finite moment (NaN)"), "{why}");
    }
    let report = fs::read_to_string(dir.join("out/poly-moments/report.md")).expect("report");
    assert!(report.contains("non-finite moment"), "{report}");
    // --resume runs the failed jobs again (an external program may answer
    // now), and keeps every finished one as it was.
    let opts = RunOptions {
        out: dir.join("out"),
        resume: true,
        shard: None,
        progress: false,
    };
    let again = run_files(&registry(), &[dir.join("e.json")], &opts);
    assert!(again.is_err(), "still failed");
    let after = fs::read_to_string(&file).expect("results");
    // The finished jobs' lines byte-identical (a re-run job would carry a
    // new wall time); the failed ones run again, and fail again the same way.
    let lines = |t: &str, failed: bool| {
        let mut v: Vec<String> = t
            .lines()
            .filter(|l| l.contains("\"failure\":null") != failed)
            .map(str::to_string)
            .collect();
        v.sort();
        v
    };
    assert_eq!(lines(&before, false), lines(&after, false));
    let failures = |t: &str| {
        let mut v: Vec<(u64, String)> = lines(t, true)
            .iter()
            .map(|l| {
                let j: serde_json::Value = serde_json::from_str(l).expect("a result line");
                (
                    j["seed"].as_u64().expect("seed"),
                    j["failure"].as_str().expect("failure").to_string(),
                )
            })
            .collect();
        v.sort();
        v
    };
    assert_eq!(failures(&before).len(), 2);
    assert_eq!(failures(&before), failures(&after));
    // merge: complete (no "incomplete"), the failures reported as failures.
    let merged = lightquad::experiment::merge(&registry(), &[dir.join("out")], &dir.join("m"));
    let e = merged.expect_err("failed jobs").to_string();
    assert!(
        e.contains("2 of 12 jobs failed") && !e.contains("incomplete"),
        "{e}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// A reference that cannot be computed is said so on the page, and the run
/// fails: never a page that claims convergence and shows no table.
#[test]
fn a_reference_that_cannot_be_computed_fails_the_run_and_says_why() {
    let text = FILE
        .replace("\"degree\": 5", "\"degree\": 49")
        .replace("{ \"type\": \"closed-form\" }", "{ \"type\": \"converged\" }")
        .replace(
            "{ \"rule\": \"product\", \"outer\": { \"rule\": \"gauss-legendre\" }, \"inner\": { \"rule\": \"trapezoid\" } },\n",
            "",
        );
    let (result, dir) = run(&registry(), &text, "noref");
    let e = result.expect_err("a run without a reference").to_string();
    assert!(e.contains("has no reference"), "{e}");
    let report = fs::read_to_string(dir.join("out/poly-moments/report.md")).expect("report");
    assert!(report.contains("## moment (no reference)"), "{report}");
    assert!(!report.contains("(converged)"), "{report}");
    let _ = fs::remove_dir_all(&dir);
}

//! summary.json and `lightquad compare`: the summary validated against its
//! own schema by an independent validator (boon), its figures recomputed
//! here from results.jsonl and the closed form, the timing repeats shown to
//! leave every value and evaluation count as the first call gave it, and
//! `compare` shown to call a deliberately slowed rule slower and nothing
//! else changed.

use std::collections::BTreeMap;
use std::fs;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use lightquad::error::{QuadError, SpecError};
use lightquad::experiment::compare::{CompareOptions, Speed, compare};
use lightquad::experiment::run::RunOptions;
use lightquad::experiment::{Registry, run_files};
use lightquad::family::{Family, Measured, Method, NoEstimator, Outcome, Quantity};
use lightquad::quadrature::Rule;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::common::{bin, scratch, stderr};

/// `int_0^1 u^2 du = 1/3`, with two planted behaviours: each call of a
/// scene's `tag` is counted, and a call that is not the scene's first adds
/// its index to the value and the count (so a timing repeat that leaked
/// into the results would show); the trapezoid rule spins [`SLOW_NS`] per
/// call.
struct Counted;

/// Extra nanoseconds the trapezoid rule spins per call (0: none).
static SLOW_NS: AtomicU64 = AtomicU64::new(0);

/// Calls per scene tag.
static CALLS: Mutex<BTreeMap<u32, u64>> = Mutex::new(BTreeMap::new());

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct CountedScene {
    /// Calls are counted per tag.
    tag: u32,
}

#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize, JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
enum Q {
    /// `int_0^1 u^2 du`.
    Square,
}

impl Quantity for Q {
    fn name(&self) -> &'static str {
        "square"
    }
    fn all() -> &'static [Self] {
        &[Q::Square]
    }
}

impl Family for Counted {
    const NAME: &'static str = "counted";
    const ABOUT: &'static str = "u^2 with counted calls";
    const EQUATIONS: &'static [&'static str] = &["C-1"];
    const BUDGET_UNIT: &'static str = "evaluations";
    type SceneSpec = CountedScene;
    type Scene = u32;
    type Quantity = Q;
    type Estimator = NoEstimator;

    fn build(spec: &CountedScene) -> Result<u32, SpecError> {
        Ok(spec.tag)
    }
    fn dimension(_: &u32, _: Q) -> usize {
        1
    }
    fn channels(_: &u32, _: Q) -> usize {
        1
    }
    fn estimates(e: &NoEstimator) -> &'static [Q] {
        match *e {}
    }
    fn evaluate(
        tag: &u32,
        method: &Method<NoEstimator>,
        n: usize,
        rng: &mut rand_pcg::Pcg64,
        _: &[Q],
    ) -> Result<Outcome<Q>, QuadError> {
        let Method::Rule(r) = method else {
            unreachable!("no estimators")
        };
        let before = {
            let mut calls = CALLS.lock().expect("lock");
            let c = calls.entry(*tag).or_insert(0);
            *c += 1;
            *c - 1
        };
        let spin = SLOW_NS.load(Ordering::Relaxed);
        if spin > 0 && r.name() == "trapezoid" {
            let start = Instant::now();
            while start.elapsed() < Duration::from_nanos(spin) {
                std::hint::spin_loop();
            }
        }
        let e = r.integrate(n, rng, |u: [f64; 1]| u[0] * u[0])?;
        // A first call per tag reports the integral; a later one (a
        // timing repeat of a tag with a single job) would not.
        let leak = if *tag >= 1000 { before as f64 } else { 0.0 };
        Ok(Outcome::from([(
            Q::Square,
            Measured::scalar(e.value + leak, e.error, e.evaluations + leak as u64),
        )]))
    }
    fn closed_form(_: &u32, _: Q) -> Option<Vec<f64>> {
        Some(vec![1.0 / 3.0])
    }
    fn closed_forms_available() -> &'static str {
        "all"
    }
    fn converged(_: &u32, _: usize, _: &[Q]) -> Result<Outcome<Q>, QuadError> {
        Err(QuadError::invalid("reference", "converged", "closed-form"))
    }
}

fn registry() -> Registry {
    lightquad::families::builtin().with::<Counted>()
}

/// `lightquad compare <dir>/old <dir>/<new> extra...`.
fn compare_bin(dir: &Path, new: &str, extra: &[&str]) -> std::process::Output {
    bin()
        .arg("compare")
        .arg(dir.join("old"))
        .arg(dir.join(new))
        .args(extra)
        .output()
        .expect("runs")
}

/// Runs experiment text `text` into `<dir>/<run>`.
fn run(dir: &Path, run: &str, text: &str) {
    let file = dir.join(format!("{run}.json"));
    fs::write(&file, text).expect("write");
    let opts = RunOptions {
        out: dir.join(run),
        resume: false,
        shard: None,
        progress: false,
    };
    run_files(&registry(), &[file], &opts).expect("runs");
}

/// A single fast job (n = 4 trapezoid, well under the 0.2 ms the clock is
/// read reliably at) is called again in timing batches, and its recorded
/// value and evaluation count are the first call's: the family adds its
/// call index to later calls' results, so a leak would show. A first call
/// that a loaded machine slows past 0.2 ms is not batched, so the run is
/// tried again, each time under a tag of its own, until one is.
#[test]
fn timing_repeats_leave_values_and_counts_as_the_first_call_gave_them() {
    let dir = scratch("timing-repeats");
    let batched = (1001..1011).find_map(|tag| {
        let text = format!(
            r#"{{"name": "once", "family": "counted", "scene": {{"tag": {tag}}}, "quantities": ["square"],
            "rules": [{{"rule": "trapezoid"}}], "budgets": [4], "repeats": 1, "reference": {{"type": "closed-form"}}}}"#
        );
        let run_dir = format!("a{tag}");
        run(&dir, &run_dir, &text);
        let calls = CALLS.lock().expect("lock")[&tag];
        (calls > 5).then_some(run_dir)
    });
    let Some(run_dir) = batched else {
        panic!("no run of ten was timed in batches")
    };
    let line = fs::read_to_string(dir.join(run_dir).join("once/results.jsonl")).expect("results");
    let job: serde_json::Value = serde_json::from_str(line.trim()).expect("json");
    let m = &job["quantities"]["square"];
    // The trapezoid rule at budget 4 on u^2: 3 nodes, h = 1/2,
    // h (0/2 + 1/4 + 1/2) = 3/8.
    assert_eq!(m["value"][0].as_f64(), Some(3.0 / 8.0), "{m}");
    assert_eq!(m["evaluations"].as_u64(), Some(3), "{m}");
    let _ = fs::remove_dir_all(&dir);
}

/// The same experiment run twice, the second time with the trapezoid rule
/// spinning 20 ms more per call: `compare` finds no value changed and
/// calls every trapezoid row slower (over 20x against calls of a few
/// microseconds), no other row by anything like it; the binary exits
/// non-zero only where a value changed.
#[test]
fn compare_calls_a_slowed_rule_slower_and_nothing_else() {
    let dir = scratch("compare-slowed");
    let text = r#"{"name": "slowed", "family": "counted", "scene": {"tag": 7}, "quantities": ["square"],
        "rules": [{"rule": "trapezoid"}, {"rule": "simpson"}, {"rule": "gauss-legendre"}],
        "budgets": [5, 17, 65], "repeats": 3, "reference": {"type": "closed-form"}}"#;
    run(&dir, "old", text);
    SLOW_NS.store(20_000_000, Ordering::Relaxed);
    run(&dir, "new", text);
    SLOW_NS.store(0, Ordering::Relaxed);
    let c = compare(
        &dir.join("old"),
        &dir.join("new"),
        &CompareOptions::default(),
    )
    .expect("compares");
    assert_eq!((c.values_changed(), c.jobs()), (0, 27), "{}", c.markdown());
    // Every trapezoid row is slower, by far more than any timing noise (a
    // spin of 20 ms on calls of a few us, beyond a preempted reading of a
    // loaded machine); a row of another rule called
    // changed (possible on a loaded machine: its intervals apart and its
    // time beyond 1.5x) is nowhere near that.
    let e = &c.experiments[0];
    let slowed = |t: &&lightquad::experiment::compare::TimeChange| t.row.1 == "trapezoid";
    let trapezoid: Vec<usize> = e.times.iter().filter(slowed).map(|t| t.row.2).collect();
    assert_eq!(trapezoid, [5, 17, 65], "{}", c.markdown());
    for t in &e.times {
        let ratio = t.new.median / t.old.median;
        if slowed(&t) {
            assert!(t.speed == Speed::Slower && ratio > 20.0, "{t:?}");
        } else {
            assert!(ratio < 10.0, "{t:?}");
        }
    }
    // The binary agrees, reading only the folders (the counted family is
    // not in its registry).
    let o = compare_bin(&dir, "new", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let md = String::from_utf8_lossy(&o.stdout).to_string();
    for n in [5, 17, 65] {
        assert!(
            md.contains(&format!("| square | trapezoid | {n} | slower |")),
            "{md}"
        );
    }
    let path = dir.join("new/slowed/results.jsonl");
    let jobs = fs::read_to_string(&path).expect("results");
    let first: serde_json::Value =
        serde_json::from_str(jobs.lines().next().expect("a line")).expect("json");
    let v = first["quantities"]["square"]["value"][0]
        .as_f64()
        .expect("value");
    let edited = jobs.replacen(
        &serde_json::to_string(&v).expect("number"),
        &serde_json::to_string(&(v * (1.0 + 4.0 * f64::EPSILON))).expect("number"),
        1,
    );
    fs::write(&path, edited).expect("write");
    let o = compare_bin(&dir, "new", &[]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("1 difference(s)"), "{}", stderr(&o));
    // Within a relative tolerance of 1e-12 it agrees again.
    let o = compare_bin(&dir, "new", &["--tolerance", "1e-12"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // A time no run writes (an edited summary) is not judged, and a summary
    // that is not a regular file is named, not read.
    let summary = dir.join("new/slowed/summary.json");
    let text = fs::read_to_string(&summary).expect("summary");
    fs::write(&summary, text.replacen("\"median\": ", "\"median\": -", 1)).expect("write");
    let c = compare(
        &dir.join("old"),
        &dir.join("new"),
        &CompareOptions::default(),
    )
    .expect("compares");
    assert!(
        c.markdown()
            .contains("1 row time(s) in the summaries are no time"),
        "{}",
        c.markdown()
    );
    fs::remove_file(&summary).expect("rm");
    fs::create_dir(&summary).expect("mkdir");
    let c = compare(
        &dir.join("old"),
        &dir.join("new"),
        &CompareOptions::default(),
    )
    .expect("compares");
    assert!(
        c.markdown().contains("not a regular file"),
        "{}",
        c.markdown()
    );
    fs::remove_dir(&summary).expect("rmdir");
    fs::write(&summary, text).expect("write");
    // An infinite value agrees with a finite one under no tolerance.
    let jobs = fs::read_to_string(&path).expect("results");
    fs::write(
        &path,
        jobs.replacen("\"value\":[", "\"value\":[\"inf\",", 1),
    )
    .expect("write");
    let o = compare_bin(&dir, "new", &["--tolerance", "1e-12"]);
    assert!(
        !o.status.success(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    // An experiment of the baseline missing from the new run fails it too;
    // nothing in common is no comparison at all.
    let copy = dir.join("old/second");
    fs::create_dir_all(&copy).expect("mkdir");
    fs::copy(
        dir.join("old/slowed/results.jsonl"),
        copy.join("results.jsonl"),
    )
    .expect("copy");
    let o = compare_bin(&dir, "old", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    fs::write(&path, jobs).expect("write");
    let o = compare_bin(&dir, "new", &["--tolerance", "1e-12"]);
    assert!(stderr(&o).contains("1 difference(s)"), "{}", stderr(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("only in the baseline: second"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let o = compare_bin(&dir, "new", &["--experiment", "second"]);
    assert!(
        stderr(&o).contains("no experiment to compare"),
        "{}",
        stderr(&o)
    );
    let _ = fs::remove_dir_all(&dir);
}

/// Every summary.json of a run over bundled experiments of every family,
/// and of one whose quantity has no reference (its converged reference
/// fails), is valid against the schema that `lightquad schema --summary`
/// prints, read by boon, an independent validator.
#[test]
fn summaries_are_valid_against_their_schema() {
    let dir = scratch("summary-schema");
    let files: Vec<String> = [
        "calibration-exp",
        "v-tau-stiff-sphere",
        "r-coaxial-disk-1e-3",
        "w-ss-edge-coverage",
        "integral-pixel-texture",
    ]
    .iter()
    .map(|n| format!("{}/experiments/{n}.json", crate::common::root().display()))
    .collect();
    let none = dir.join("none.json");
    fs::write(
        &none,
        r#"{"name": "no-ref", "family": "counted", "scene": {"tag": 3}, "quantities": ["square"],
        "rules": [{"rule": "trapezoid"}], "budgets": [4, 8], "repeats": 1,
        "reference": {"type": "converged", "n": 64}}"#,
    )
    .expect("write");
    let opts = RunOptions {
        out: dir.join("none"),
        resume: false,
        shard: None,
        progress: false,
    };
    let incomplete = run_files(&registry(), &[none], &opts);
    assert!(
        incomplete.is_err(),
        "a quantity without a reference is said"
    );
    let summary = fs::read_to_string(dir.join("none/no-ref/summary.json")).expect("written");
    assert!(summary.contains("\"no_reference\""), "{summary}");
    let out = dir.join("report");
    let o = bin()
        .arg("run")
        .args(&files)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("runs");
    let schema = bin().args(["schema", "--summary"]).output().expect("runs");
    let schema: serde_json::Value = serde_json::from_slice(&schema.stdout).expect("json");
    let mut schemas = boon::Schemas::new();
    let mut compiler = boon::Compiler::new();
    compiler
        .add_resource("summary.schema.json", schema)
        .expect("resource");
    let id = compiler
        .compile("summary.schema.json", &mut schemas)
        .expect("the schema compiles");
    let mut paths = vec![
        out.join("summary.json"),
        dir.join("none/no-ref/summary.json"),
    ];
    for f in fs::read_dir(&out).expect("out").flatten() {
        if f.path().join("summary.json").is_file() {
            paths.push(f.path().join("summary.json"));
        }
    }
    assert!(paths.len() >= 7, "{paths:?}: {}", stderr(&o));
    for p in &paths {
        let v: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(p).expect("read")).expect("json");
        if let Err(e) = schemas.validate(&v, id) {
            panic!("{}: {e:#}", p.display());
        }
    }
    let _ = fs::remove_dir_all(&dir);
}

/// A rule whose rank another rule comes to share is said to be tied, and a
/// rule that keeps its rank number but comes to share it is listed too.
/// Both runs' summaries are one run's with the ranks written in: 1, 2, 3
/// in the baseline; 1, 1 (tied), 3 in the new run.
#[test]
fn compare_says_when_a_rank_becomes_shared() {
    let dir = scratch("compare-tied");
    let text = r#"{"name": "tied", "family": "counted", "scene": {"tag": 9}, "quantities": ["square"],
        "rules": [{"rule": "trapezoid"}, {"rule": "simpson"}, {"rule": "gauss-legendre"}],
        "budgets": [5, 17], "repeats": 2, "reference": {"type": "closed-form"}}"#;
    run(&dir, "old", text);
    let new = dir.join("new/tied");
    fs::create_dir_all(&new).expect("mkdir");
    for f in ["results.jsonl", "summary.json"] {
        fs::copy(dir.join("old/tied").join(f), new.join(f)).expect("copy");
    }
    let rank = |run: &str, ranks: [(&str, u64, bool); 3]| {
        let path = dir.join(run).join("tied/summary.json");
        let mut summary: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(&path).expect("summary")).expect("json");
        let rules = summary["experiments"][0]["quantities"][0]["rules"]
            .as_array_mut()
            .expect("rules");
        for r in rules.iter_mut() {
            let (_, n, tied) = ranks
                .iter()
                .find(|(label, ..)| r["label"] == *label)
                .expect("a rule of the three");
            r["rank"] = (*n).into();
            r["tied"] = (*tied).into();
        }
        fs::write(&path, summary.to_string()).expect("write");
    };
    rank(
        "old",
        [
            ("trapezoid", 1, false),
            ("simpson", 2, false),
            ("gauss-legendre", 3, false),
        ],
    );
    rank(
        "new",
        [
            ("trapezoid", 1, false),
            ("simpson", 1, true),
            ("gauss-legendre", 3, false),
        ],
    );
    let markdown = || {
        compare(
            &dir.join("old"),
            &dir.join("new"),
            &CompareOptions::default(),
        )
        .expect("compares")
        .markdown()
    };
    let md = markdown();
    assert!(
        md.contains("- rank of simpson on square: 2 -> 1 (tied)\n"),
        "{md}"
    );
    assert!(
        md.contains("- rank of trapezoid on square: 1 -> 1 (tied)\n"),
        "{md}"
    );
    assert!(!md.contains("rank of gauss-legendre"), "{md}");
    assert!(md.contains("2 rule(s) changed rank or tie"), "{md}");
    // Ranked at another target, the ranks are not compared, and it is said.
    let path = dir.join("new/tied/summary.json");
    let text = fs::read_to_string(&path).expect("summary");
    let mut summary: serde_json::Value = serde_json::from_str(&text).expect("json");
    let at = summary["experiments"][0]["ranked_at"]
        .as_f64()
        .expect("ranked_at");
    summary["experiments"][0]["ranked_at"] = (at / 8.0).into();
    fs::write(&path, summary.to_string()).expect("write");
    let md = markdown();
    assert!(!md.contains("- rank of"), "{md}");
    assert!(
        md.contains(&format!(
            "ranks not compared: the baseline ranks the rules by their time to {at:e}, the new \
             run to {:e}",
            at / 8.0
        )),
        "{md}"
    );
    let _ = fs::remove_dir_all(&dir);
}

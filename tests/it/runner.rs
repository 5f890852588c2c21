//! The real `lightquad` binary on the bundled experiments and on deliberately
//! broken files: exit status, messages that name the JSON path and what is
//! accepted, nothing left behind; an interrupted run resumed to the same
//! results; results independent of the thread count.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::common;
use common::{bin, root, scratch, stderr};
use std::time::{Duration, Instant};

/// Writes `text` to a scratch folder and runs it into `<folder>/out`.
fn run_text(tag: &str, text: &str) -> (PathBuf, PathBuf, Output) {
    let dir = scratch(tag);
    let file = dir.join("e.json");
    fs::write(&file, text).expect("write");
    let out = dir.join("out");
    let o = bin()
        .args(["run", "--out"])
        .arg(&out)
        .arg(&file)
        .output()
        .expect("runs");
    (dir, out, o)
}

/// VALID's scene with the quantity `I` alone, loaded (its jobs run with
/// `run_job`), and the one rule `rows` is told of (Gauss–Legendre).
fn i_experiment() -> (
    Box<dyn lightquad::experiment::registry::Loaded>,
    [lightquad::experiment::report::RuleInfo; 1],
) {
    let text = VALID.replace("[\"tau\", \"I_E\"]", "[\"I\"]");
    let exp = lightquad::families::builtin()
        .load(
            lightquad::experiment::validate::parse_json(&text).expect("parses"),
            "h",
        )
        .expect("valid");
    let rules = [lightquad::experiment::report::RuleInfo {
        label: "gauss-legendre".into(),
        is_random: false,
        min_budget: Default::default(),
        resolution: Default::default(),
        not_run: None,
    }];
    (exp, rules)
}

/// `lightquad run --resume --out <out> <file>`.
fn resume(out: &Path, file: &Path) -> Output {
    bin()
        .args(["run", "--resume", "--out"])
        .arg(out)
        .arg(file)
        .output()
        .expect("runs")
}

/// `lightquad merge --out <out> <inputs...>`.
fn merge(out: &Path, inputs: &[&Path]) -> Output {
    bin()
        .args(["merge", "--out"])
        .arg(out)
        .args(inputs)
        .output()
        .expect("runs")
}

const VALID: &str = r#"{
  "name": "t",
  "family": "volume",
  "equations": ["V-tau", "V-E"],
  "scene": {
    "ray": { "origin": [-3.0, 0.3, 0.0], "direction": [1.0, 0.0, 0.0] },
    "medium": { "type": "constant-sphere", "centre": [0.0, 0.0, 0.0], "radius": 1.0, "kappa": 2.0 },
    "emission": { "type": "constant", "c": 1.0 }
  },
  "quantities": ["tau", "I_E"],
  "rules": [ { "rule": "gauss-legendre" }, { "rule": "stratified" } ],
  "budgets": [4, 16, 64],
  "repeats": 2,
  "seed": 7,
  "reference": { "type": "closed-form" }
}"#;

/// Runs `check` and `run` on `text`; both must fail naming `path` and `what`,
/// and the run must leave no output folder.
fn rejected(text: &str, path: &str, what: &str) {
    let dir = scratch("bad");
    let file = dir.join("e.json");
    fs::write(&file, text).expect("write");
    let check = bin().arg("check").arg(&file).output().expect("runs");
    assert!(
        !check.status.success(),
        "check accepted a broken file ({path})"
    );
    let msg = stderr(&check);
    assert!(
        msg.contains(&format!("at `{path}`")),
        "no path `{path}` in: {msg}"
    );
    assert!(msg.contains(what), "no `{what}` in: {msg}");
    let out = dir.join("out");
    let run = bin()
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("runs");
    assert!(!run.status.success());
    assert!(!out.exists(), "a failed run left {out:?} behind");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn broken_files_are_rejected_with_the_json_path_and_what_is_accepted() {
    rejected("{ \"name\": ", "name", "the file ends inside a value");
    rejected(
        &VALID.replace("\"seed\": 7", "\"seed\": 7, \"colour\": 1"),
        "colour",
        "unknown field `colour`, expected one of",
    );
    rejected(
        &VALID.replace("\"repeats\": 2", "\"repeats\": \"two\""),
        "repeats",
        "invalid type: string \"two\", expected a whole number",
    );
    rejected(
        &VALID.replace("\"quantities\": [\"tau\", \"I_E\"],", ""),
        "quantities",
        "the required field `quantities` is missing",
    );
    rejected(
        &VALID.replace("[4, 16, 64]", "[4, -16, 64]"),
        "budgets[1]",
        "an integer in 1..=100000000",
    );
    rejected(
        &VALID.replace("[4, 16, 64]", "[4, 16, 4]"),
        "budgets[2]",
        "4 repeats budgets[0]: give each budget once",
    );
    // A repeated target was a second column of the same times.
    rejected(
        &VALID.replace(
            "\"seed\": 7",
            "\"seed\": 7, \"targets\": [1e-3, 1e-6, 0.001]",
        ),
        "targets[2]",
        "0.001 repeats targets[0]: give each target once",
    );
    rejected(
        &VALID.replace("\"kappa\": 2.0", "\"kappa\": -2.0"),
        "scene.medium.kappa",
        "a finite density >= 0",
    );
    rejected(
        &VALID.replace("\"kappa\": 2.0", "\"kappa\": NaN"),
        "scene.medium.kappa",
        "NaN at line 7 column 95 is not a JSON number",
    );
    rejected(
        &VALID.replace("\"rule\": \"stratified\"", "\"rule\": \"boole\""),
        "rules[1]",
        "unknown rule `boole`: expected one of trapezoid, simpson, gauss-legendre",
    );
    rejected(
        &VALID.replace("\"family\": \"volume\"", "\"family\": \"plasma\""),
        "family",
        "unknown family \"plasma\": expected one of calibration, volume",
    );
    rejected(
        &VALID.replace("\"family\": \"volume\",", ""),
        "family",
        "missing: expected one of calibration, volume",
    );
    // Ratio tracking estimates transmittance only: asking it for I_E is refused
    // at `check`, not a row of NaN in the report.
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"ratio-tracking\" }",
        ),
        "rules[1]",
        "estimator `ratio-tracking` estimates only tau, I_B, but quantities[1] is I_E",
    );
    // A 2-D product rule cannot integrate along a ray segment.
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"product\", \"outer\": { \"rule\": \"trapezoid\" }, \"inner\": { \"rule\": \"gauss-legendre\" } }",
        ),
        "rules[1]",
        "rule `product` integrates in dimension 2 only",
    );
    // Every rule parameter is checked where it is written, products included.
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"sobol\", \"replicates\": 1 }",
        ),
        "rules[1].replicates",
        "an integer in 2..=1000000",
    );
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"product\", \"outer\": { \"rule\": \"gauss-legendre\", \"error_estimat\": true }, \"inner\": { \"rule\": \"trapezoid\" } }",
        ),
        "rules[1].outer.error_estimat",
        "unknown field `error_estimat`, expected `error_estimate`",
    );
    rejected(
        &VALID.replace("\"kappa\": 2.0", "\"kappa\": 2.0, \"sigma\": 1"),
        "scene.medium.sigma",
        "unknown field `sigma`, expected one of `centre`, `radius`, `kappa`",
    );
    rejected(
        &VALID.replace("[1.0, 0.0, 0.0] }", "[0.0, 0.0, 0.0] }"),
        "scene.ray.direction",
        "a non-zero direction",
    );
    rejected(
        &VALID.replace("\"type\": \"constant-sphere\", \"centre\": [0.0, 0.0, 0.0], \"radius\": 1.0, \"kappa\": 2.0", "\"type\": \"voxel-grid\", \"min\": [0,0,0], \"max\": [1,1,1], \"resolution\": [1,1,1], \"data\": [1.0]"),
        "reference",
        "has no closed form",
    );
}

#[test]
fn an_unwritable_output_folder_is_an_error_before_any_job() {
    let dir = scratch("unwritable");
    let file = dir.join("e.json");
    fs::write(&file, VALID).expect("write");
    // A regular file where the output folder should be.
    let blocker = dir.join("blocker");
    fs::write(&blocker, "x").expect("write");
    let run = bin()
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(blocker.join("out"))
        .output()
        .expect("runs");
    assert!(!run.status.success());
    assert!(stderr(&run).contains("blocker"), "{}", stderr(&run));
    // A link to nothing was "already exists (os error 17)".
    let link = dir.join("dangling");
    std::os::unix::fs::symlink(dir.join("nowhere").join("x"), &link).expect("symlink");
    let run = bin()
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(&link)
        .output()
        .expect("runs");
    let msg = stderr(&run);
    assert!(
        !run.status.success() && msg.contains("which does not exist"),
        "{msg}"
    );
    // A results file that links to a device was read as earlier results
    // without end until the process was killed; no link in the output
    // folder is followed.
    let out = dir.join("device");
    fs::create_dir_all(out.join("t")).expect("mkdir");
    std::os::unix::fs::symlink("/dev/zero", out.join("t").join("results.jsonl")).expect("symlink");
    let run = bin()
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("runs");
    let msg = stderr(&run);
    assert!(!run.status.success() && msg.contains("is a link"), "{msg}");
    let _ = fs::remove_dir_all(&dir);
}

/// The results of a run, sorted, without timing or machine fields.
fn results(out: &Path, name: &str) -> Vec<String> {
    let text = fs::read_to_string(out.join(name).join("results.jsonl")).expect("results");
    let mut lines: Vec<String> = text
        .lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).expect("a whole JSON line");
            if let Some(o) = v.as_object_mut() {
                o.remove("seconds");
                o.remove("machine");
                // Each quantity's own time.
                if let Some(qs) = o.get_mut("quantities").and_then(|q| q.as_object_mut()) {
                    for m in qs.values_mut().filter_map(|m| m.as_object_mut()) {
                        m.remove("seconds");
                    }
                }
            }
            v.to_string()
        })
        .collect();
    lines.sort();
    lines
}

#[test]
fn results_are_identical_for_one_thread_and_all_threads() {
    let dir = scratch("threads");
    let file = dir.join("e.json");
    fs::write(&file, VALID).expect("write");
    let mut runs = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.join(format!("out{threads}"));
        let o = bin()
            .args(["run", "--threads", threads, "--out"])
            .arg(&out)
            .arg(&file)
            .output()
            .expect("runs");
        assert!(o.status.success(), "{}", stderr(&o));
        runs.push(results(&out, "t"));
    }
    assert_eq!(runs[0].len(), 2 * 3 * 2);
    same(&runs[0], &runs[1]);
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_killed_run_resumes_to_the_results_of_an_uninterrupted_one() {
    let dir = scratch("resume");
    let file = dir.join("e.json");
    // Nested optical depth makes each job slow enough to kill the run midway.
    let slow = VALID
        .replace("[4, 16, 64]", "[64, 128, 256, 512, 768, 1024]")
        .replace("\"repeats\": 2", "\"repeats\": 3")
        .replace("\"scene\": {", "\"scene\": { \"depth_scheme\": \"nested\",");
    fs::write(&file, &slow).expect("write");
    let full = dir.join("full");
    let o = bin()
        .args(["run", "--out"])
        .arg(&full)
        .arg(&file)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));

    let part = dir.join("part");
    let mut child = bin()
        .args(["run", "--threads", "1", "--out"])
        .arg(&part)
        .arg(&file)
        .spawn()
        .expect("spawns");
    let jsonl = part.join("t").join("results.jsonl");
    let start = Instant::now();
    // Wait for some, not all, jobs to finish, then kill -9.
    loop {
        let lines = fs::read_to_string(&jsonl).map_or(0, |t| t.lines().count());
        if lines >= 3 || start.elapsed() > Duration::from_secs(60) {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().expect("SIGKILL");
    let _ = child.wait();
    let before = fs::read_to_string(&jsonl).map_or(0, |t| t.lines().count());
    assert!(
        (1..36).contains(&before),
        "killed after {before} of 36 jobs"
    );

    let o = resume(&part, &file);
    assert!(o.status.success(), "{}", stderr(&o));
    same(&results(&part, "t"), &results(&full, "t"));
    let _ = fs::remove_dir_all(&dir);
}

/// Two result sets are equal; on failure, says how they first differ.
fn same(a: &[String], b: &[String]) {
    assert_eq!(a.len(), b.len(), "{} against {} results", a.len(), b.len());
    if let Some((x, y)) = a.iter().zip(b).find(|(x, y)| x != y) {
        panic!("first difference:\n{x}\n{y}");
    }
}

#[test]
fn shards_merge_into_the_full_report() {
    let dir = scratch("shards");
    let file = dir.join("e.json");
    fs::write(&file, VALID).expect("write");
    let full = dir.join("full");
    assert!(
        bin()
            .args(["run", "--out"])
            .arg(&full)
            .arg(&file)
            .output()
            .expect("runs")
            .status
            .success()
    );
    let shards = dir.join("shards");
    for k in 1..=3 {
        let o = bin()
            .args(["run", "--shard", &format!("{k}/3"), "--out"])
            .arg(&shards)
            .arg(&file)
            .output()
            .expect("runs");
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let merged = dir.join("merged");
    let o = bin()
        .args(["merge", "--out"])
        .arg(&merged)
        .arg(&shards)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    same(&results(&merged, "t"), &results(&full, "t"));
    assert!(merged.join("t").join("report.md").is_file() && merged.join("index.md").is_file());
    let bad = bin()
        .args(["run", "--shard", "4/3"])
        .arg(&file)
        .output()
        .expect("runs");
    assert!(!bad.status.success() && stderr(&bad).contains("1 <= k <= n"));
    let _ = fs::remove_dir_all(&dir);
}

/// An experiment file may name its JSON Schema for an editor (`"$schema"`):
/// every family's branch of the schema `lightquad schema` prints allows the
/// field (its objects are closed, so an editor would flag it otherwise), and
/// `check` accepts any string there and names the field when it is not one.
#[test]
fn a_schema_named_in_the_file_is_accepted_and_allowed_by_the_schema() {
    let schema = bin().arg("schema").output().expect("runs");
    let schema: serde_json::Value =
        serde_json::from_slice(&schema.stdout).expect("the schema is JSON");
    for branch in schema["oneOf"].as_array().expect("oneOf") {
        assert!(
            branch["properties"]["$schema"].is_object(),
            "{} lacks $schema",
            branch["title"]
        );
    }
    let dir = scratch("schema-field");
    let check = |text: &str| {
        let file = dir.join("e.json");
        fs::write(&file, text).expect("write");
        bin().arg("check").arg(&file).output().expect("runs")
    };
    let o = check(&VALID.replacen('{', r#"{"$schema": "./lightquad.schema.json","#, 1));
    assert!(o.status.success(), "{}", stderr(&o));
    let o = check(&VALID.replacen('{', r#"{"$schema": 3,"#, 1));
    assert!(!o.status.success());
    assert!(stderr(&o).contains("at `$schema`"), "{}", stderr(&o));
    let _ = fs::remove_dir_all(&dir);
}

/// The experiment schema, read by boon (an independent validator), refuses
/// what `check` refuses of the lists: an empty or repeated budget, more
/// than 200 budgets, a range's factor of 1, no target, a repeated one or
/// one outside [1e-15, 1), an equation ID not of the family (and any for a
/// family of none), no quantity or a repeated one, and no rule; and both
/// still allow VALID. (A seed past u64 is refused by check and by
/// the schema's maximum read exactly; boon reads 2^64 as the f64 of
/// u64::MAX and allows it.)
#[test]
fn the_schema_refuses_empty_and_repeated_budgets_and_repeated_targets() {
    let schema = bin().arg("schema").output().expect("runs");
    let schema: serde_json::Value = serde_json::from_slice(&schema.stdout).expect("json");
    let mut schemas = boon::Schemas::new();
    let mut compiler = boon::Compiler::new();
    compiler
        .add_resource("experiment.schema.json", schema)
        .expect("resource");
    let id = compiler
        .compile("experiment.schema.json", &mut schemas)
        .expect("the schema compiles");
    let valid = |text: &str| {
        let v: serde_json::Value = serde_json::from_str(text).expect("json");
        schemas.validate(&v, id).is_ok()
    };
    assert!(valid(VALID));
    assert!(valid(&VALID.replace(
        "\"seed\": 7",
        "\"seed\": 7, \"targets\": [1e-3, 1e-6]"
    )));
    let many: Vec<String> = (1..=201).map(|n| n.to_string()).collect();
    let targets = |t: &str| VALID.replace("\"seed\": 7", &format!("\"seed\": 7, \"targets\": {t}"));
    let dir = scratch("schema-lists");
    let file = dir.join("e.json");
    for (refused, field) in [
        (VALID.replace("[4, 16, 64]", "[]"), "budgets"),
        (VALID.replace("[4, 16, 64]", "[4, 16, 4]"), "budgets"),
        (
            VALID.replace("[4, 16, 64]", &format!("[{}]", many.join(", "))),
            "budgets",
        ),
        (
            VALID.replace("[4, 16, 64]", r#"{"from": 4, "to": 64, "factor": 1}"#),
            "budgets",
        ),
        (targets("[1e-3, 1e-6, 1e-3]"), "targets"),
        (targets("[]"), "targets"),
        (targets("[0]"), "targets[0]"),
        (targets("[1e-3, 1]"), "targets[1]"),
        (targets("[1e-3, 1e-16]"), "targets[1]"),
        (VALID.replace("\"V-E\"]", "\"V-e\"]"), "equations[1]"),
        (VALID.replace("[\"tau\", \"I_E\"]", "[]"), "quantities"),
        (
            VALID.replace("[\"tau\", \"I_E\"]", "[\"tau\", \"tau\"]"),
            "quantities",
        ),
        (
            VALID.replace(
                r#"[ { "rule": "gauss-legendre" }, { "rule": "stratified" } ]"#,
                "[]",
            ),
            "rules",
        ),
    ] {
        assert!(!valid(&refused), "the schema allowed: {refused}");
        fs::write(&file, &refused).expect("write");
        let o = bin().arg("check").arg(&file).output().expect("runs");
        assert!(!o.status.success(), "check allowed: {refused}");
        assert!(stderr(&o).contains(&format!("`{field}")), "{}", stderr(&o));
    }
    // A family of no equations: its own file is allowed, and refused with
    // any equation ID in it.
    let calibration = fs::read_to_string(root().join("experiments/calibration-exp.json"))
        .expect("calibration-exp.json");
    assert!(valid(&calibration));
    let with_id = calibration.replacen('{', r#"{"equations": ["V-tau"],"#, 1);
    assert!(!valid(&with_id), "the schema allowed: {with_id}");
    fs::write(&file, &with_id).expect("write");
    let o = bin().arg("check").arg(&file).output().expect("runs");
    assert!(stderr(&o).contains("`equations[0]`"), "{}", stderr(&o));
    fs::write(&file, VALID).expect("write");
    let o = bin().arg("check").arg(&file).output().expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let _ = fs::remove_dir_all(&dir);
}

/// Targets listed in any order are reported from the largest down and the
/// rules ranked at the middle value, not at the list's middle position.
#[test]
fn targets_in_any_order_are_ranked_at_the_middle_value() {
    let text = VALID.replace(
        "\"seed\": 7",
        "\"seed\": 7, \"targets\": [1e-9, 1e-3, 1e-6]",
    );
    let (dir, out, o) = run_text("targets-order", &text);
    let summary: serde_json::Value = serde_json::from_str(
        &fs::read_to_string(out.join("t/summary.json"))
            .unwrap_or_else(|e| panic!("{e}: {}", stderr(&o))),
    )
    .expect("summary.json");
    let e = &summary["experiments"][0];
    assert_eq!(e["ranked_at"].as_f64(), Some(1e-6), "{e}");
    let listed: Vec<f64> = e["targets"]
        .as_array()
        .expect("targets")
        .iter()
        .filter_map(serde_json::Value::as_f64)
        .collect();
    assert_eq!(listed, [1e-3, 1e-6, 1e-9]);
    // Every ranking a person reads names the target it ranks at.
    let index = fs::read_to_string(out.join("index.md")).expect("index.md");
    assert!(index.contains("- tau (to 1e-6): "), "{index}");
    let html = fs::read_to_string(out.join("index.html")).expect("index.html");
    assert!(html.contains("seconds to reach 1e-6 (log)"), "{html}");
    let report = fs::read_to_string(out.join("t/report.md")).expect("report.md");
    assert!(
        report.contains("Target relative errors 1e-3, 1e-6, 1e-9; the index ranks the rules by their time to 1e-6"),
        "{report}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// Targets that differ in their second digit are told apart in every
/// heading; a target whose extrapolated budget lies past the largest a
/// file may ask is said to, not given as a number of evaluations no run
/// could make.
#[test]
fn close_targets_are_told_apart_and_far_extrapolations_are_bounded() {
    let spec = r#"{
      "name": "t", "family": "integral",
      "scene": {"domain": {"type": "interval", "a": 0, "b": 1},
                "integrand": "sqrt(x)", "exact": "0.66666666666666666667"},
      "quantities": ["integral"],
      "rules": [{"rule": "trapezoid"}],
      "budgets": [8, 16, 32, 64], "repeats": 1, "seed": 1,
      "reference": {"type": "closed-form"},
      "targets": [2.5e-3, 3e-3, 1e-15]
    }"#;
    let (dir, out, o) = run_text("close-targets", spec);
    let report = fs::read_to_string(out.join("t/report.md"))
        .unwrap_or_else(|e| panic!("{e}: {}", stderr(&o)));
    for t in ["3e-3", "2.5e-3", "1e-15"] {
        assert!(
            report.contains(&format!("time to {t} (s)")),
            "{t}: {report}"
        );
    }
    let row = report
        .lines()
        .find(|l| l.starts_with("| trapezoid |") && l.contains("not reached"))
        .expect("the trapezoid's times to the targets");
    assert!(
        row.contains(
            "not reached (extrapolated: beyond n = 1e8, the largest budget a file may ask)"
        ),
        "{row}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// `lightquad run` without files runs the bundled suite from any folder (here
/// a fresh one without experiments/ or reference/): every experiment of
/// experiments/, the Mitsuba comparison of every committed values file, and a
/// line per finished experiment on stderr (not a terminal).
#[test]
fn the_bundled_experiments_run_and_report_every_quantity() {
    let dir = scratch("bundled");
    let out = dir.join("report");
    let o = bin()
        .current_dir(&dir)
        .args(["run", "--out", "report"])
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!dir.join("experiments").exists());
    let index = fs::read_to_string(out.join("index.md")).expect("index");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // Each committed values file gives rows with Mitsuba's value (not a note).
    assert!(index.contains("## lightquad vs Mitsuba 3 vs closed form"));
    let mut values = 0;
    for f in fs::read_dir(root.join("reference/values")).expect("values") {
        let v: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(f.expect("entry").path()).expect("read"))
                .expect("json");
        let name = v["experiment"].as_str().expect("experiment");
        for (q, entry) in v["quantities"].as_object().expect("quantities") {
            let value = entry["value"].as_f64().expect("value");
            let row = format!("| {name} | {q} | ");
            let line = index
                .lines()
                .find(|l| l.starts_with(&row))
                .unwrap_or_else(|| panic!("no Mitsuba row for {name} {q}"));
            assert!(
                line.contains(&format!("| {value:.10e} +- ")),
                "{name} {q}: Mitsuba's {value:e} not in {line}"
            );
            values += 1;
        }
    }
    assert!(values >= 5, "{values} Mitsuba values");
    // One progress line per experiment: its name, jobs (as in its results
    // file) and failures.
    let err = stderr(&o);
    for f in fs::read_dir(root.join("experiments")).expect("folder") {
        let p = f.expect("entry").path();
        if p.extension().is_none_or(|x| x != "json") {
            continue;
        }
        let spec: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(&p).expect("read")).expect("json");
        let name = spec["name"].as_str().expect("name");
        let jobs = results(&out, name).len();
        let line = format!("finished {name}: {jobs} jobs, 0 failed, ");
        assert_eq!(
            err.lines().filter(|l| l.starts_with(&line)).count(),
            1,
            "{line} in {err}"
        );
    }
    let files =
        fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments")).expect("folder");
    let mut n = 0;
    for f in files.filter_map(Result::ok) {
        let p = f.path();
        if p.extension().is_none_or(|x| x != "json") {
            continue;
        }
        n += 1;
        let spec: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(&p).expect("read")).expect("json");
        let name = spec["name"].as_str().expect("name");
        assert!(
            index.contains(&format!("]({name}/report.md)")),
            "index lacks {name}"
        );
        let report = fs::read_to_string(out.join(name).join("report.md")).expect("report");
        for q in spec["quantities"].as_array().expect("quantities") {
            let q = q.as_str().expect("name");
            assert!(
                report.contains(&format!("## {q} (reference")),
                "{name} lacks {q}"
            );
            // A plot, unless every row underflowed (nothing to draw: the
            // stiff sphere's tau and I_B, whose rows say so).
            let section = report
                .split(&format!("## {q} (reference"))
                .nth(1)
                .and_then(|s| s.split("\n## ").next())
                .unwrap_or("");
            let rows: Vec<&str> = section
                .lines()
                .filter(|l| l.starts_with("| ") && !l.contains("---"))
                .filter(|l| {
                    l.split('|')
                        .nth(2)
                        .is_some_and(|b| b.trim().parse::<usize>().is_ok())
                })
                .collect();
            let underflowed = !rows.is_empty() && rows.iter().all(|l| l.contains("underflows"));
            assert!(
                underflowed
                    || out
                        .join(name)
                        .join(format!("{name}-{q}-time.svg"))
                        .is_file(),
                "{name} {q}: no plot"
            );
        }
        assert!(
            !report.contains("| NaN") && !report.contains("NaN |"),
            "{name} reports a NaN"
        );
    }
    assert!(n >= 6, "{n} bundled experiments");
    // Every equation ID of the volume document is covered.
    for id in ["V-tau", "V-E", "V-B", "V-Lp", "V-L", "V-I"] {
        assert!(
            fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments"))
                .expect("folder")
                .filter_map(Result::ok)
                .any(|f| fs::read_to_string(f.path())
                    .is_ok_and(|t| t.contains(&format!("\"{id}\"")))),
            "no bundled experiment for {id}"
        );
    }
    let schema = bin().arg("schema").output().expect("runs");
    let schema: serde_json::Value =
        serde_json::from_slice(&schema.stdout).expect("the schema is JSON");
    // One schema per family, told apart by a constant family tag, and every
    // reference resolves to a definition at the root.
    let families: Vec<&str> = schema["oneOf"]
        .as_array()
        .expect("oneOf")
        .iter()
        .map(|b| {
            b["properties"]["family"]["const"]
                .as_str()
                .expect("const family")
        })
        .collect();
    assert_eq!(
        families,
        [
            "calibration",
            "volume",
            "rendering",
            "whitted",
            "furnace",
            "exchange",
            "integral"
        ]
    );
    // Every object the schema describes is closed, as `check` refuses
    // unknown fields: `{"rule": "trapezoid", "foo": 1}` passed the schema;
    // and `name` says what `check` accepts.
    fn open_objects(v: &serde_json::Value, path: &str, out: &mut Vec<String>) {
        match v {
            serde_json::Value::Object(m) => {
                if m.contains_key("properties")
                    && m.get("additionalProperties") != Some(&false.into())
                {
                    out.push(path.to_string());
                }
                m.iter()
                    .for_each(|(k, c)| open_objects(c, &format!("{path}/{k}"), out));
            }
            serde_json::Value::Array(a) => a
                .iter()
                .enumerate()
                .for_each(|(i, c)| open_objects(c, &format!("{path}[{i}]"), out)),
            _ => {}
        }
    }
    let mut open = Vec::new();
    open_objects(&schema, "", &mut open);
    assert!(open.is_empty(), "open objects: {open:?}");
    for branch in schema["oneOf"].as_array().expect("oneOf") {
        assert_eq!(
            branch["properties"]["name"]["pattern"], "^[A-Za-z0-9_-]{1,100}$",
            "{branch}"
        );
    }
    let volume = &schema["oneOf"][1];
    assert!(
        volume["properties"]["scene"]["$ref"].is_string(),
        "{volume}"
    );
    fn refs(v: &serde_json::Value, out: &mut Vec<String>) {
        match v {
            serde_json::Value::Object(m) => m.iter().for_each(|(k, c)| match c {
                serde_json::Value::String(s) if k == "$ref" => out.push(s.clone()),
                _ => refs(c, out),
            }),
            serde_json::Value::Array(a) => a.iter().for_each(|c| refs(c, out)),
            _ => {}
        }
    }
    let mut all = Vec::new();
    refs(&schema, &mut all);
    assert!(all.len() > 10);
    for r in all {
        let name = r.strip_prefix("#/$defs/").expect("a local definition");
        assert!(schema["$defs"][name].is_object(), "{r} does not resolve");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// A family's flag on a value (here `Cancellation`, which a family raises when
/// a sum lost digits) reaches the report's row, once per kind. (The volume
/// family can no longer raise it: its terms are all non-negative since
/// negative emission is refused, so the flag is set on the jobs' values here.)
#[test]
fn a_familys_value_flag_reaches_the_report_row() {
    use lightquad::experiment::report::{RowFlag, rows};
    use lightquad::family::Flag;
    let (exp, rules) = i_experiment();
    let jobs: Vec<_> = [4usize, 16]
        .iter()
        .map(|&n| {
            let mut job = exp.run_job((0, n, 0));
            for m in job.quantities.values_mut() {
                m.flags.push(Flag::Cancellation { parts: 2.0 });
                m.flags.push(Flag::Cancellation { parts: 3.0 });
            }
            job
        })
        .collect();
    let reference = exp.run_job((0, 64, 0)).quantities["I"].value.clone();
    let table = rows(&rules, &jobs, "I", &reference, None);
    assert_eq!(table.len(), 2, "{table:?}");
    for row in &table {
        let n = row
            .flags
            .iter()
            .filter(|f| matches!(f, RowFlag::Job(Flag::Cancellation { .. })))
            .count();
        assert_eq!(n, 1, "{row:?}");
    }
}

/// Runs the binary, killing it after `secs` (a regression must not hang CI).
fn run_with_timeout(args: &[&str], secs: u64) -> Output {
    let mut child = bin()
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("spawns");
    let start = Instant::now();
    loop {
        if child.try_wait().expect("waits").is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(secs) {
            let _ = child.kill();
            panic!("lightquad {args:?} ran past {secs} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("output")
}

#[test]
fn regressions_from_the_runner_review() {
    let dir = scratch("review");
    let path = |name: &str, text: &str| {
        let p = dir.join(name);
        fs::write(&p, text).expect("write");
        p.display().to_string()
    };
    // A value near f64::MAX once hung the plot's axis code forever.
    let huge = path(
        "huge.json",
        &VALID
            .replace("\"c\": 1.0", "\"c\": 1e308")
            .replace("[4, 16, 64]", "[4]"),
    );
    let out = dir.join("huge-out").display().to_string();
    let o = run_with_timeout(&["run", &huge, "--out", &out], 60);
    assert!(o.status.success(), "{}", stderr(&o));

    // A budget factor near 1 once looped without end in validation.
    let slow = path(
        "factor.json",
        &VALID.replace(
            "[4, 16, 64]",
            "{ \"from\": 1, \"to\": 100000000, \"factor\": 1.0000000001 }",
        ),
    );
    let o = run_with_timeout(&["check", &slow], 20);
    assert!(
        !o.status.success() && stderr(&o).contains("at `budgets.factor`"),
        "{}",
        stderr(&o)
    );

    // lambda kappa = 1e600 overflows the extinction: every job used to fail
    // at run time; `check` now refuses it, naming lambda (a job that fails
    // at run time is tested in tests/family_plugin.rs).
    let failing = path(
        "failing.json",
        &VALID
            .replace("\"kappa\": 2.0", "\"kappa\": 1e300")
            .replace("\"ray\": {", "\"lambda\": 1e300, \"ray\": {"),
    );
    let o = run_with_timeout(&["check", &failing], 20);
    assert!(
        !o.status.success()
            && stderr(&o).contains("at `scene.lambda`")
            && stderr(&o).contains("overflows f64"),
        "{}",
        stderr(&o)
    );

    // Shards sharing one output folder, run at the same time, all succeed and
    // merge into the whole.
    let base = path("base.json", VALID);
    let shared = dir.join("shared").display().to_string();
    let children: Vec<_> = (1..=4)
        .map(|k| {
            bin()
                .args([
                    "run",
                    "--threads",
                    "1",
                    "--shard",
                    &format!("{k}/4"),
                    "--out",
                    &shared,
                    &base,
                ])
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("spawns")
        })
        .collect();
    for c in children {
        let o = c.wait_with_output().expect("waits");
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let merged = dir.join("merged").display().to_string();
    let o = run_with_timeout(&["merge", "--out", &merged, &shared], 60);
    assert!(o.status.success(), "{}", stderr(&o));
    // One shard alone is an incomplete merge, and says so.
    let lone = dir.join("lone").display().to_string();
    assert!(
        run_with_timeout(&["run", "--shard", "1/3", "--out", &lone, &base], 60)
            .status
            .success()
    );
    let o = run_with_timeout(
        &[
            "merge",
            "--out",
            &dir.join("m2").display().to_string(),
            &lone,
        ],
        60,
    );
    assert!(
        !o.status.success() && stderr(&o).contains("incomplete"),
        "{}",
        stderr(&o)
    );
    let _ = fs::remove_dir_all(&dir);
}

/// Faults below a rule and in the shape of references are named where they are.
#[test]
fn faults_inside_rules_and_references_are_named_where_they_are() {
    let product = |outer: &str, inner: &str| {
        VALID.replace(
            "{ \"rule\": \"stratified\" }",
            &format!("{{ \"rule\": \"product\", \"outer\": {outer}, \"inner\": {inner} }}"),
        )
    };
    rejected(
        &product(
            "{ \"rule\": \"product\", \"outer\": { \"rule\": \"trapezoid\" }, \"inner\": { \"rule\": \"trapezoid\" } }",
            "{ \"rule\": \"trapezoid\" }",
        ),
        "rules[1].outer.rule",
        "\"product\" is not a single rule: expected one of trapezoid",
    );
    rejected(
        &product(
            "{ \"rule\": \"trapezoid\" }",
            "{ \"rule\": \"sobol\", \"replicates\": 1 }",
        )
        .replace("[\"tau\", \"I_E\"]", "[\"tau\"]"),
        "rules[1].inner.replicates",
        "an integer in 2..=1000000",
    );
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"gauss-kronrod\", \"rel_tol\": \"1e-3\" }",
        ),
        "rules[1].rel_tol",
        "invalid type: string \"1e-3\", expected a number",
    );
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"stratified\", \"n\": 4 }",
        ),
        "rules[1].n",
        "unknown field `n`: this rule takes no parameters",
    );
    rejected(
        &VALID.replace("[\"tau\", \"I_E\"]", "[\"tau\", \"I_E\", \"tau\"]"),
        "quantities[2]",
        "tau is named twice",
    );
    rejected(
        &VALID.replace("{ \"rule\": \"stratified\" }", "\"stratified\""),
        "rules[1]",
        "is not a rule: expected {\"rule\": <name>, <parameters>}",
    );
    // A reference of the wrong shape: exp-rgb has three channels.
    let rgb = r#"{ "name": "c", "family": "calibration", "scene": {}, "quantities": ["exp-rgb"],
        "rules": [{ "rule": "gauss-legendre" }], "budgets": [8],
        "reference": { "type": "value", "values": { "exp-rgb": 1.7 } } }"#;
    rejected(
        rgb,
        "reference.values.exp-rgb",
        "1 value(s) given, but exp-rgb has 3 channel(s): give a list of 3 numbers",
    );
    // A product's factor's parameter, checked where it is written.
    let disk = r#"{ "name": "c", "family": "calibration", "scene": {}, "quantities": ["gaussian-disk"],
        "rules": [{ "rule": "product", "outer": { "rule": "gauss-legendre" }, "inner": { "rule": "sobol", "replicates": 1 } }],
        "budgets": [64], "reference": { "type": "closed-form" } }"#;
    rejected(
        disk,
        "rules[0].inner.replicates",
        "an integer in 2..=1000000",
    );
    // A replicate count no budget can hold is refused at the count, not at
    // `budgets` as "no budget reaches" it.
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"sobol\", \"replicates\": 1000000000000 }",
        ),
        "rules[1].replicates",
        "invalid replicates = 1000000000000: expected an integer in 2..=1000000",
    );
}

/// A medium whose extinction or optical depth overflows f64 is refused at
/// `check` naming the medium (the terms of a linear gradient of radius 1e300
/// came out 0, silently; blobs of amplitude 1e308 failed every job).
#[test]
fn media_whose_optical_depth_overflows_are_refused_at_check() {
    let blobs = VALID.replace(
        "{ \"type\": \"constant-sphere\", \"centre\": [0.0, 0.0, 0.0], \"radius\": 1.0, \"kappa\": 2.0 }",
        "{ \"type\": \"gaussian-blobs\", \"blobs\": [{ \"centre\": [0.0, 0.0, 0.0], \"amplitude\": 1e308, \"width\": 1.0 }, { \"centre\": [0.1, 0.0, 0.0], \"amplitude\": 1e308, \"width\": 1.0 }] }",
    );
    rejected(
        &blobs,
        "scene.medium.blobs[0].amplitude",
        "1e308: the optical depth along the ray overflows f64",
    );
    rejected(
        &blobs,
        "scene.medium.blobs[0].amplitude",
        "no value of this field alone brings it below 1.8e308: expected smaller values here \
         and at scene.medium.blobs[1].amplitude",
    );
    let gradient = VALID.replace(
        "{ \"type\": \"constant-sphere\", \"centre\": [0.0, 0.0, 0.0], \"radius\": 1.0, \"kappa\": 2.0 }",
        "{ \"type\": \"linear-gradient\", \"centre\": [0, 0, 0], \"radius\": 1e300, \"base\": 1.0, \"gradient\": [0.8, 0, 0] }",
    );
    rejected(
        &gradient,
        "scene.medium.radius",
        "1e300: the optical depth along the ray overflows",
    );
    // The same gradient at radius 1e20 is fine.
    let fine = gradient.replace("1e300", "1e20");
    let fine = fine.replace("[4, 16, 64]", "[4]").replace(
        "{ \"type\": \"closed-form\" }",
        "{ \"type\": \"converged\" }",
    );
    let (dir, _, o) = run_text("fine-gradient", &fine);
    assert!(o.status.success(), "{}", stderr(&o));
    let _ = fs::remove_dir_all(&dir);
}

/// A constant sphere whose optical depth overflows is refused at the field
/// that does it, with the value and the largest it may take (kappa = 1e308 and
/// radius = 1e308 were refused at `scene.medium` only). VALID's ray, y = 0.3
/// from the centre, has the chord 2 sqrt(1 - 0.3^2) = 1.908 in the unit
/// sphere, so kappa may reach f64::MAX / 1.908 = 9.42e307; a sphere of radius
/// 1e308 holds the ray's origin, so its chord from t = 0 is r + 3 (about r),
/// and with kappa = 2 the radius may reach f64::MAX / 2 = 8.99e307.
#[test]
fn a_sphere_whose_depth_overflows_is_refused_at_kappa_or_radius_with_the_range() {
    let chord = 2.0 * (1.0f64 - 0.09).sqrt();
    let kappa_max = f64::MAX / chord;
    assert!((9.4e307..9.5e307).contains(&kappa_max), "{kappa_max:e}");
    let with_kappa = |k: &str| VALID.replace("\"kappa\": 2.0", &format!("\"kappa\": {k}"));
    rejected(
        &with_kappa("1e308"),
        "scene.medium.kappa",
        "1e308: the optical depth along the ray overflows f64",
    );
    rejected(
        &with_kappa("1e308"),
        "scene.medium.kappa",
        "expected kappa at most 9.4e307 along this ray",
    );
    let check = |text: &str| {
        let dir = scratch("kappa-edge");
        let file = dir.join("e.json");
        fs::write(&file, text).expect("write");
        let o = bin().arg("check").arg(&file).output().expect("runs");
        let _ = fs::remove_dir_all(&dir);
        o
    };
    // Either side of the bound the message gives.
    let o = check(&with_kappa("9.4e307"));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!check(&with_kappa("9.5e307")).status.success());
    let radius_max = f64::MAX / 2.0;
    assert!((8.9e307..9.0e307).contains(&radius_max));
    rejected(
        &VALID.replace("\"radius\": 1.0", "\"radius\": 1e308"),
        "scene.medium.radius",
        "1e308: the optical depth along the ray overflows f64",
    );
    rejected(
        &VALID.replace("\"radius\": 1.0", "\"radius\": 1e308"),
        "scene.medium.radius",
        "expected radius at most 8.9e307 along this ray",
    );
}

/// The CSV has as many fields on every line as in its header, product labels
/// (which hold a comma) included.
#[test]
fn the_csv_keeps_its_columns_with_product_labels() {
    let (dir, out, o) = run_text(
        "csv",
        r#"{ "name": "c", "family": "calibration", "scene": {}, "quantities": ["gaussian-disk"],
        "rules": [{ "rule": "product", "outer": { "rule": "gauss-legendre" }, "inner": { "rule": "trapezoid" } }],
        "budgets": [16, 64], "repeats": 1, "reference": { "type": "closed-form" } }"#,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = fs::read_to_string(out.join("c").join("results.csv")).expect("csv");
    // RFC 4180 fields: commas inside quotes do not separate.
    let fields = |line: &str| {
        let mut quoted = false;
        1 + line
            .chars()
            .filter(|&c| {
                if c == '"' {
                    quoted = !quoted;
                }
                c == ',' && !quoted
            })
            .count()
    };
    let mut lines = csv.lines();
    let header = fields(lines.next().expect("header"));
    let mut n = 0;
    for line in lines {
        assert_eq!(fields(line), header, "{line}");
        assert!(
            line.contains("\"product(gauss-legendre,trapezoid)\""),
            "{line}"
        );
        n += 1;
    }
    assert_eq!(n, 2);
    let _ = fs::remove_dir_all(&dir);
}

/// Each CSV line carries its quantity's own time as results.jsonl records it,
/// not the whole job's (the sum over the job's quantities).
#[test]
fn the_csv_times_each_quantity_by_its_own_evaluation() {
    let (dir, out, o) = run_text("csvtime", VALID);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut own = std::collections::BTreeMap::new();
    for l in fs::read_to_string(out.join("t/results.jsonl"))
        .expect("jsonl")
        .lines()
    {
        let v: serde_json::Value = serde_json::from_str(l).expect("json");
        let job = (
            v["rule_index"].clone(),
            v["budget"].clone(),
            v["repeat"].clone(),
        );
        for (q, m) in v["quantities"].as_object().expect("quantities") {
            let s = m["seconds"].as_f64().expect("a quantity's own seconds");
            own.insert(
                (
                    job.0.to_string(),
                    job.1.to_string(),
                    job.2.to_string(),
                    q.clone(),
                ),
                s,
            );
        }
    }
    let csv = fs::read_to_string(out.join("t/results.csv")).expect("csv");
    let mut n = 0;
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let key = (
            f[1].to_string(),
            f[3].to_string(),
            f[4].to_string(),
            f[6].to_string(),
        );
        let s: f64 = f[10].parse().expect("seconds");
        let want = own[&key];
        assert!(
            (s - want).abs() <= 1e-9 * want.max(1e-9),
            "{line}: {s} against {want}"
        );
        n += 1;
    }
    assert_eq!(n, own.len());
    let _ = fs::remove_dir_all(&dir);
}

/// Where shards disagree on a job, `merge` keeps the finished result over a
/// failed one, whichever folder comes first.
#[test]
fn merge_prefers_a_finished_job_over_a_failed_copy() {
    let dir = scratch("mergedup");
    let file = dir.join("e.json");
    fs::write(&file, VALID).expect("write");
    let good = dir.join("a-good");
    let o = bin()
        .args(["run", "--out"])
        .arg(&good)
        .arg(&file)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    // A copy whose every job failed.
    let bad = dir.join("0-bad");
    fs::create_dir_all(bad.join("t")).expect("folder");
    fs::copy(
        good.join("t/experiment.json"),
        bad.join("t/experiment.json"),
    )
    .expect("copy");
    let failed: String = fs::read_to_string(good.join("t/results.jsonl"))
        .expect("results")
        .lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).expect("json");
            v["quantities"] = serde_json::json!({});
            v["failure"] = "killed".into();
            format!("{v}\n")
        })
        .collect();
    fs::write(bad.join("t/results.jsonl"), failed).expect("write");
    for order in [[&bad, &good], [&good, &bad]] {
        let merged = dir.join("merged");
        let o = bin()
            .args(["merge", "--out"])
            .arg(&merged)
            .args(order)
            .output()
            .expect("runs");
        assert!(o.status.success(), "{}", stderr(&o));
        same(&results(&merged, "t"), &results(&good, "t"));
        let _ = fs::remove_dir_all(&merged);
    }
    let _ = fs::remove_dir_all(&dir);
}

/// Shards that disagree on a finished job's values (an appended line with
/// another value was merged without a word), and unreadable lines in a
/// shard, make `merge` say so and fail; a merged folder holds its
/// experiment file, so it can be merged again (it could not: no
/// experiment.json).
#[test]
fn merge_says_where_shards_disagree_and_its_output_merges_again() {
    let (dir, good, o) = run_text("mergeconflict", VALID);
    assert!(o.status.success(), "{}", stderr(&o));
    let merged = dir.join("merged");
    let o = merge(&merged, &[&good]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(merged.join("t/experiment.json").is_file());
    let again = dir.join("again");
    let o = merge(&again, &[&merged]);
    assert!(o.status.success(), "{}", stderr(&o));
    same(&results(&again, "t"), &results(&good, "t"));
    // A copy with one value changed, and a line of garbage.
    let other = dir.join("b-other");
    fs::create_dir_all(other.join("t")).expect("folder");
    fs::copy(
        good.join("t/experiment.json"),
        other.join("t/experiment.json"),
    )
    .expect("copy");
    let text = fs::read_to_string(good.join("t/results.jsonl")).expect("results");
    let first = text.lines().next().expect("a line");
    let mut v: serde_json::Value = serde_json::from_str(first).expect("json");
    v["quantities"]["tau"]["value"] = serde_json::json!([9.99]);
    fs::write(other.join("t/results.jsonl"), format!("{v}\n{{garbage\n")).expect("write");
    let conflict = dir.join("conflict");
    let o = merge(&conflict, &[&good, &other]);
    let msg = stderr(&o);
    assert!(!o.status.success(), "accepted: {msg}");
    assert!(
        msg.contains("1 job(s) with different values in two shards"),
        "{msg}"
    );
    assert!(msg.contains("1 unreadable line(s)"), "{msg}");
    let _ = fs::remove_dir_all(&dir);
}

/// A job whose error estimate is infinite (Gauss–Legendre without its
/// estimate) survives the results file: merge and resume read it back (JSON
/// has no infinity; it used to be written as null and then dropped).
#[test]
fn infinite_error_estimates_survive_the_results_file() {
    let (dir, out, o) = run_text(
        "inf",
        &VALID.replace(
            "{ \"rule\": \"gauss-legendre\" }",
            "{ \"rule\": \"gauss-legendre\", \"error_estimate\": false }",
        ),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = fs::read_to_string(out.join("t/results.jsonl")).expect("results");
    assert!(text.contains("\"error\":[\"inf\"]"), "{text}");
    assert!(!text.contains("null]"), "{text}");
    let read = lightquad::experiment::run::read_results(&out.join("t/results.jsonl"), None);
    assert_eq!(read.len(), text.lines().count(), "a line did not read back");
    assert!(
        read.iter()
            .any(|r| r.quantities["tau"].error[0] == f64::INFINITY)
    );
    let merged = dir.join("merged");
    let o = bin()
        .args(["merge", "--out"])
        .arg(&merged)
        .arg(&out)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    same(&results(&merged, "t"), &results(&out, "t"));
    let _ = fs::remove_dir_all(&dir);

    // Where tau underflows to 0 its error was 0 * inf, written as NaN: no
    // estimate is inf there too.
    let stiff = fs::read_to_string(root().join("experiments/v-tau-stiff-sphere.json"))
        .expect("bundled")
        .replace(
            "{ \"rule\": \"gauss-legendre\" }",
            "{ \"rule\": \"gauss-legendre\", \"error_estimate\": false }",
        );
    assert!(
        stiff.contains("error_estimate"),
        "the rule was not replaced"
    );
    let (dir, out, o) = run_text("inf-underflow", &stiff);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = fs::read_to_string(out.join("v-tau-stiff-sphere/results.jsonl")).expect("results");
    assert!(!text.contains("NaN"), "{text}");
    let read = lightquad::experiment::run::read_results(
        &out.join("v-tau-stiff-sphere/results.jsonl"),
        None,
    );
    assert!(
        read.iter().any(|r| r.quantities["tau"].value[0] == 0.0
            && r.quantities["tau"].error[0] == f64::INFINITY)
    );
    let _ = fs::remove_dir_all(&dir);
}

/// Values near the top of the f64 range are integrated (the rules rescale),
/// never a NaN with zero error that "reaches" every target; a family that
/// still computes a non-finite value fails the job (tests/family_plugin.rs).
#[test]
fn emission_near_the_top_of_the_f64_range_is_integrated_not_failed() {
    // c = 1e308: stratified's second differences overflowed and its rows
    // failed ("non-finite I_E"); the rules now rescale the integrand.
    let (dir, out, o) = run_text("big", &VALID.replace("\"c\": 1.0", "\"c\": 1e308"));
    assert!(o.status.success(), "{}", stderr(&o));
    let results = lightquad::experiment::run::read_results(&out.join("t/results.jsonl"), None);
    assert_eq!(results.len(), 12);
    // I_E = c (1 - e^(-sigma L)) / sigma, chord L = 2 sqrt(1 - 0.3^2).
    let chord = 2.0 * (1.0f64 - 0.09).sqrt();
    let exact = 1e308 * (1.0 - (-2.0 * chord).exp()) / 2.0;
    for r in &results {
        assert!(r.failure.is_none(), "{r:?}");
        let m = &r.quantities["I_E"];
        assert!(m.value[0].is_finite() && m.error[0].is_finite(), "{r:?}");
        let rel = (m.value[0] - exact).abs() / exact;
        if r.rule == "gauss-legendre" && r.budget == 64 {
            assert!(rel < 1e-13, "{rel}");
        }
        // Stratified's 95% interval covers at this scale too.
        assert!(rel * exact <= 4.0 * m.error[0].max(1e-15 * exact), "{r:?}");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// A key given twice is refused, not silently the last one, at the key's
/// own path (a top-level key was placed at `.`).
#[test]
fn duplicate_keys_are_refused() {
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"trapezoid\", \"rule\": \"sobol\" }",
        ),
        "rules[1].rule",
        "the key `rule` appears twice",
    );
    rejected(
        &VALID.replace(
            "\"family\": \"volume\",",
            "\"family\": \"calibration\", \"family\": \"volume\",",
        ),
        "family",
        "the key `family` appears twice",
    );
}

/// A merge that misses a shard says so at the top of the index it writes.
#[test]
fn an_incomplete_merge_says_so_in_the_index() {
    let dir = scratch("partial");
    let file = dir.join("e.json");
    fs::write(&file, VALID).expect("write");
    let shards = dir.join("shards");
    let o = bin()
        .args(["run", "--shard", "1/3", "--out"])
        .arg(&shards)
        .arg(&file)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let merged = dir.join("merged");
    let o = bin()
        .args(["merge", "--out"])
        .arg(&merged)
        .arg(&shards)
        .output()
        .expect("runs");
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("the report is incomplete"),
        "{}",
        stderr(&o)
    );
    let index = fs::read_to_string(merged.join("index.md")).expect("index");
    assert!(index.contains("**This report is incomplete**"), "{index}");
    // The experiment's own page says how many rows lack repeats, counted
    // here from its results.
    let results = fs::read_to_string(merged.join("t/results.jsonl")).expect("results");
    let mut rows: std::collections::BTreeMap<(u64, u64), usize> = Default::default();
    for line in results.lines() {
        let v: serde_json::Value = serde_json::from_str(line).expect("json");
        let key = (
            v["rule_index"].as_u64().expect("rule"),
            v["budget"].as_u64().expect("n"),
        );
        *rows.entry(key).or_default() += 1;
    }
    let short = rows.values().filter(|&&k| k < 2).count();
    assert!(short > 0);
    let report = fs::read_to_string(merged.join("t/report.md")).expect("report");
    assert!(
        report.contains(&format!(
            "**Incomplete**: {short} of {} row(s) hold fewer than the 2 repeat(s)",
            rows.len()
        )),
        "{report}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// Regression: a converged reference is converged per
/// quantity, well below the tightest target. The bundled voxel grid's
/// reference was Gauss–Legendre at n = 16 against 32, which changed I_L by
/// 2.2e-6; that one figure was every quantity's accuracy, so every rule was
/// "not reached" at 1e-9 even on tau, where Gauss–Legendre at n = 2 is exact
/// (the density is a cubic on every piece). Now the note names each
/// quantity's own change, all below 1e-11, and Gauss–Legendre reaches 1e-9 on
/// tau at its first budget.
#[test]
fn a_converged_reference_is_converged_per_quantity() {
    let text = fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/v-i-total-voxel-grid.json"),
    )
    .expect("bundled file");
    let (dir, out, o) = run_text("converged", &text);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(out.join("v-i-total-voxel-grid/report.md")).expect("report");
    let note = report
        .lines()
        .find(|l| l.starts_with("Reference:"))
        .expect("a reference line");
    assert!(
        note.contains("every quantity converged to 1e-11 or better"),
        "{note}"
    );
    let tau = &report[report.find("## tau").expect("tau section")..];
    let ranking = tau
        .lines()
        .find(|l| l.starts_with("| gauss-legendre | ") && !l.contains("| 2 |"))
        .expect("gauss-legendre in the order table");
    assert!(!ranking.contains("not reached"), "{ranking}");
    let _ = fs::remove_dir_all(&dir);
}

/// Regressions: a negative emission is
/// refused like a negative background; a reference value for a quantity the
/// experiment does not ask for is refused, not ignored.
#[test]
fn negative_emission_and_stray_reference_values_are_refused() {
    rejected(
        &VALID.replace("\"c\": 1.0", "\"c\": -1.0"),
        "scene.emission.c",
        "a finite number >= 0",
    );
    rejected(
        &VALID.replace(
            "{ \"type\": \"closed-form\" }",
            "{ \"type\": \"value\", \"values\": { \"tau\": 0.02, \"I_E\": 0.4, \"I_L\": 1.0 } }",
        ),
        "reference.values.I_L",
        "not among the experiment's quantities",
    );
}

/// Regression: with kappa 0 no collision is
/// possible, so delta tracking's tau = 1 and I_E = 0 are exact (closed forms
/// 1 and 0): no Wilson bound, no "all walks alike" flag.
#[test]
fn tracking_through_an_empty_medium_is_exact_and_unflagged() {
    let text = VALID.replace("\"kappa\": 2.0", "\"kappa\": 0.0").replace(
        "{ \"rule\": \"gauss-legendre\" }, { \"rule\": \"stratified\" }",
        "{ \"rule\": \"delta-tracking\" }",
    );
    let (dir, out, o) = run_text("empty", &text);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(out.join("t/report.md")).expect("report");
    let rows: Vec<&str> = report
        .lines()
        .filter(|l| {
            l.starts_with("| delta-tracking | 4 |") || l.starts_with("| delta-tracking | 16 |")
        })
        .collect();
    assert_eq!(rows.len(), 4, "{report}");
    for row in rows {
        assert!(
            row.contains("| 0.00e0 | 0.00e0 |") && !row.contains("alike"),
            "{row}"
        );
    }
    let _ = fs::remove_dir_all(&dir);
}

/// A fault inside `budgets` names its own path and reason (it said "data did
/// not match any variant of untagged enum Budgets" at `budgets`).
#[test]
fn a_fault_inside_budgets_names_its_path() {
    let with = |b: &str| VALID.replace("\"budgets\": [4, 16, 64]", &format!("\"budgets\": {b}"));
    rejected(
        &with("{ \"from\": 4, \"to\": 64, \"factor\": \"NaN\" }"),
        "budgets.factor",
        "invalid type: string \"NaN\", expected a number",
    );
    rejected(
        &with("[4, \"x\", 16]"),
        "budgets[1]",
        "invalid type: string \"x\", expected a whole number",
    );
    rejected(
        &with("{ \"from\": 4, \"to\": 64, \"factor\": 2, \"step\": 1 }"),
        "budgets.step",
        "unknown field",
    );
    rejected(&with("\"many\""), "budgets", "a list of budgets");
}

/// A fault inside an internally tagged object (a medium, an emission, a
/// reference, a tracking estimator) names its own path, the value and what
/// is accepted: serde's tagged enums reported `scene.medium` for
/// `"kappa": "2.6"`, fixed-size lists said "expected fewer elements", number
/// types were named as Rust types ("expected f64"), and an unknown field
/// beside a tracking estimator was silently ignored.
#[test]
fn a_fault_inside_a_tagged_object_names_its_own_path() {
    let medium = |m: &str| {
        VALID.replace(
            "{ \"type\": \"constant-sphere\", \"centre\": [0.0, 0.0, 0.0], \"radius\": 1.0, \"kappa\": 2.0 }",
            m,
        )
    };
    rejected(
        &VALID.replace("\"kappa\": 2.0", "\"kappa\": \"2.6\""),
        "scene.medium.kappa",
        "invalid type: string \"2.6\", expected a number",
    );
    rejected(
        &medium(
            "{ \"type\": \"gaussian-blobs\", \"blobs\": [ { \"centre\": [0, 0, 0], \"amplitude\": 1, \"width\": 1 }, { \"centre\": [0, 0, 0], \"amplitude\": 1, \"width\": \"w\" } ] }",
        ),
        "scene.medium.blobs[1].width",
        "expected a number",
    );
    rejected(
        &medium("{ \"type\": \"cube\" }"),
        "scene.medium.type",
        "unknown variant \"cube\": expected one of `constant-sphere`, `gaussian-blobs`, `linear-gradient`, `voxel-grid`",
    );
    rejected(
        &medium("{ \"radius\": 1 }"),
        "scene.medium.type",
        "the required field `type` is missing: expected one of `constant-sphere`",
    );
    rejected(
        &VALID.replace(
            "\"direction\": [1.0, 0.0, 0.0]",
            "\"direction\": [1.0, 0.0, 0.0, 0.0]",
        ),
        "scene.ray.direction",
        "a list of 4 elements: expected exactly 3",
    );
    rejected(
        &VALID.replace(
            "{ \"type\": \"constant\", \"c\": 1.0 }",
            "{ \"type\": \"field\", \"field\": { \"type\": \"constant-sphere\", \"centre\": [0, 0, 0], \"radius\": 1, \"kappa\": [1] } }",
        ),
        "scene.emission.field.kappa",
        "invalid type: a list, expected a number",
    );
    rejected(
        &VALID.replace(
            "{ \"type\": \"constant\", \"c\": 1.0 }",
            "{ \"type\": \"table\", \"points\": [[0, 0], [1, 2, 3]] }",
        ),
        "scene.emission.points[1]",
        "a list of 3 elements: expected exactly 2",
    );
    rejected(
        &VALID.replace(
            "{ \"type\": \"closed-form\" }",
            "{ \"type\": \"value\", \"values\": { \"tau\": 0.5, \"I_E\": \"x\" } }",
        ),
        "reference.values.I_E",
        "expected a number, or a list of numbers",
    );
    rejected(
        &VALID.replace(
            "{ \"type\": \"closed-form\" }",
            "{ \"type\": \"value\", \"values\": { \"tau\": 0.5, \"I_X\": 1 } }",
        ),
        "reference.values.I_X",
        "unknown variant `I_X`, expected one of `tau`",
    );
    rejected(
        &VALID.replace(
            "{ \"type\": \"closed-form\" }",
            "{ \"type\": \"closed-form\", \"n\": 4 }",
        ),
        "reference.n",
        "unknown field `n`",
    );
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"delta-tracking\", \"n\": 3 }",
        ),
        "rules[1].n",
        "unknown field `n` of the estimator `delta-tracking`: expected only `rule`",
    ); // An audit point named twice, or an empty list of them, is a slip.
    let printed = |list: &str| {
        VALID.replace(
            "\"emission\": { \"type\": \"constant\", \"c\": 1.0 }",
            &format!("\"emission\": {{ \"type\": \"constant\", \"c\": 1.0 }}, \"light\": {{ \"toward_light\": [0, 1, 0], \"intensity\": 1 }}, \"printed\": {list}"),
        )
    };
    rejected(
        &printed("[\"s\", \"s\"]"),
        "scene.printed[1]",
        "\"s\" is named twice",
    );
    rejected(&printed("[]"), "scene.printed", "an empty list");
}

/// Delta tracking with an emission field of its own is refused when the
/// experiment is checked (its collisions score c(v) of the density and would
/// miss a field that emits outside the medium), not by failing every job.
#[test]
fn delta_tracking_with_an_emission_field_is_refused_at_check() {
    let text = VALID
        .replace(
            "{ \"type\": \"constant\", \"c\": 1.0 }",
            "{ \"type\": \"field\", \"field\": { \"type\": \"constant-sphere\", \"centre\": [0.0, 0.0, 0.0], \"radius\": 2.0, \"kappa\": 1.0 } }",
        )
        .replace(
            "{ \"rule\": \"gauss-legendre\" }, { \"rule\": \"stratified\" }",
            "{ \"rule\": \"delta-tracking\" }",
        );
    rejected(
        &text,
        "rules[0]",
        "cannot estimate quantities[1] (I_E) in this scene",
    );
}

/// The slope against n is fitted against the resolution the rule really
/// uses: Simpson takes the largest 4k + 1 <= n points, so against the budget
/// its slope read -4.39 on calibration-exp; against its intervals (error
/// `h^4 (f'(1) - f'(0)) / 180`) it is -4.
#[test]
fn simpson_and_the_trapezoid_show_their_orders_against_the_points_they_use() {
    let (dir, out, o) = run_text(
        "slopes",
        r#"{ "name": "s", "family": "calibration", "scene": {}, "quantities": ["exp"],
        "rules": [{ "rule": "simpson" }, { "rule": "trapezoid" }],
        "budgets": [16, 64, 256, 1024, 4096], "repeats": 1,
        "reference": { "type": "closed-form" } }"#,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(out.join("s/report.md")).expect("report");
    for (rule, order) in [("simpson", -4.0), ("trapezoid", -2.0)] {
        let line = report
            .lines()
            .find(|l| l.starts_with(&format!("| {rule} | -")))
            .unwrap_or_else(|| panic!("no slope row for {rule}: {report}"));
        // The cell is "-2.00 ± 0.01": the slope, then its interval.
        let slope: f64 = line
            .split('|')
            .nth(2)
            .and_then(|c| c.split_whitespace().next())
            .expect("cell")
            .parse()
            .expect("a number");
        assert!((slope - order).abs() < 0.02, "{rule}: {line}");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// Two runs into one folder: the second used to replace results.jsonl while
/// the first kept appending to the unlinked file (528 jobs reported, 76
/// lines left). Now a run holds `<out>/.lightquad.lock`; a second run (here
/// this test, holding the lock as a running `lightquad run` would) stops at
/// once with an error naming the folder, and touches nothing.
#[test]
fn a_second_run_into_a_busy_folder_stops_and_touches_nothing() {
    let (dir, out, o) = run_text("busy", VALID);
    assert!(o.status.success(), "{}", stderr(&o));
    let results = out.join("t/results.jsonl");
    let before = fs::read(&results).expect("results");
    let lock = fs::OpenOptions::new()
        .write(true)
        .open(out.join(".lightquad.lock"))
        .expect("the run left its lock file");
    lock.try_lock().expect("free once the run ended");
    let file = dir.join("e.json");
    for args in [
        vec!["run".to_string(), "--out".into()],
        vec![
            "merge".to_string(),
            out.display().to_string(),
            "--out".into(),
        ],
    ] {
        let o = bin()
            .args(&args)
            .arg(&out)
            .args(if args[0] == "run" {
                vec![&file]
            } else {
                vec![]
            })
            .output()
            .expect("runs");
        assert!(!o.status.success(), "{args:?} ran into a busy folder");
        // A merge sees the busy folder as an input first.
        assert!(
            stderr(&o).contains("another lightquad run or merge is writing into this folder")
                || stderr(&o).contains("a lightquad run is still writing into this folder"),
            "{}",
            stderr(&o)
        );
        assert_eq!(fs::read(&results).expect("results"), before, "{args:?}");
    }
    drop(lock);
    let o = bin()
        .args(["run", "--out"])
        .arg(&out)
        .arg(&file)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let _ = fs::remove_dir_all(&dir);
}

/// Inputs that passed `check` or hung: a 300-character
/// name (the run then failed, "File name too long", with a folder left); a
/// Mitsuba values file or an experiment file that is a FIFO or /dev/zero
/// (read forever).
#[test]
fn long_names_and_files_that_are_not_regular_are_refused() {
    let long = VALID.replace(
        "\"name\": \"t\"",
        &format!("\"name\": \"{}\"", "a".repeat(300)),
    );
    rejected(&long, "name", "1 to 100 letters");
    let zero = VALID.replace(
        "{ \"type\": \"closed-form\" }",
        "{ \"type\": \"mitsuba\", \"file\": \"/dev/zero\" }",
    );
    rejected(
        &zero,
        "reference.file",
        "/dev/zero: is a device: expected a regular JSON file",
    );
    let dir = scratch("fifo");
    let fifo = dir.join("f.json");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        let o = run_with_timeout(&["check", &fifo.display().to_string()], 20);
        assert!(
            !o.status.success()
                && stderr(&o).contains("is a FIFO (named pipe): expected a regular JSON file"),
            "{}",
            stderr(&o)
        );
    }
    let _ = fs::remove_dir_all(&dir);
}

/// The nested depth scheme at a budget of 1e6 was accepted and would have run
/// for about 22 hours: a job's cost is estimated before anything runs
/// and refused with the estimate and the flag that lifts it.
#[test]
fn jobs_that_would_take_hours_are_refused_with_their_estimate() {
    let nested = VALID
        .replace("\"scene\": {", "\"scene\": { \"depth_scheme\": \"nested\",")
        .replace("[4, 16, 64]", "[4, 1000000]");
    // 1e6 outer nodes times 1e6 inner ones, per graded piece.
    rejected(&nested, "budgets", "costs about");
    rejected(&nested, "budgets", "--no-cost-limit");
    // 20000 voxels along the ray under the nested scheme at 4 nodes a piece:
    // accepted as 6.8e10 evaluations, about 25 minutes a job (2000 voxels
    // took 15 s): each piece's call and each trilinear lookup now count.
    let voxels = |k: usize| {
        let data: Vec<String> = (0..k)
            .map(|i| format!("{}", 0.1 + (i % 7) as f64 * 0.1))
            .collect();
        VALID
            .replace("\"scene\": {", "\"scene\": { \"depth_scheme\": \"nested\",")
            .replace(
                "{ \"type\": \"constant-sphere\", \"centre\": [0.0, 0.0, 0.0], \"radius\": 1.0, \"kappa\": 2.0 }",
                &format!(
                    "{{ \"type\": \"voxel-grid\", \"min\": [-1, -1, -1], \"max\": [1, 1, 1], \"resolution\": [{k}, 1, 1], \"data\": [{}] }}",
                    data.join(", ")
                ),
            )
            .replace("[4, 16, 64]", "[4]")
            .replace(
                "{ \"type\": \"closed-form\" }",
                "{ \"type\": \"value\", \"values\": { \"tau\": 0.5, \"I_E\": 0.5 } }",
            )
    };
    let slow = voxels(20000);
    assert!(slow.contains("voxel-grid"), "{slow}");
    rejected(&slow, "budgets", "costs about");
    // 2000 voxels (15 s a job) pass.
    let dir = scratch("voxels-2000");
    let file = dir.join("e.json");
    fs::write(&file, voxels(2000)).expect("write");
    let o = bin().arg("check").arg(&file).output().expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let _ = fs::remove_dir_all(&dir);
    let help = bin().args(["run", "--help"]).output().expect("runs");
    assert!(String::from_utf8_lossy(&help.stdout).contains("--no-cost-limit"));
    // The bundled suite is well inside the limit.
    let o = bin().arg("check").output().expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A ray that misses the sphere: every density-driven term is 0 (tau = 1,
/// I_B = I_b), which the closed-form reference used to refuse ("no closed
/// form for this scene").
#[test]
fn a_ray_that_misses_the_medium_has_closed_forms() {
    let text = VALID
        .replace("[-3.0, 0.3, 0.0]", "[-3.0, 5.0, 0.0]")
        .replace(
            "\"emission\": { \"type\": \"constant\", \"c\": 1.0 }",
            "\"emission\": { \"type\": \"constant\", \"c\": 1.0 }, \"background\": 0.5, \
             \"light\": { \"toward_light\": [0, 1, 0], \"intensity\": 2.0 }",
        )
        .replace(
            "[\"tau\", \"I_E\"]",
            "[\"tau\", \"I_E\", \"I_L\", \"I_B\", \"I\"]",
        )
        .replace(
            "\"equations\": [\"V-tau\", \"V-E\"]",
            "\"equations\": [\"V-I\"]",
        );
    let (dir, out, o) = run_text("miss", &text);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(out.join("t/report.md")).expect("report");
    for (q, v) in [
        ("tau", "1.0"),
        ("I_E", "0.0"),
        ("I_L", "0.0"),
        ("I_B", "5.0"),
        ("I", "5.0"),
    ] {
        let want = format!("## {q} (reference {v}");
        assert!(report.contains(&want), "{want}: {report}");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// Shards share a folder, but a whole run or a merge may not join them, and
/// a merge does not read a folder shards are still writing (`run --shard`
/// and `run` were run into one folder at once).
#[test]
fn shards_exclude_whole_runs_and_merges_of_their_folder() {
    let (dir, out, o) = run_text("shardlock", VALID);
    assert!(o.status.success(), "{}", stderr(&o));
    let file = dir.join("e.json");
    // Held shared, as a running `run --shard` holds it.
    let lock = fs::File::open(out.join(".lightquad.lock")).expect("lock file");
    lock.try_lock_shared().expect("free");
    let whole = bin()
        .args(["run", "--out"])
        .arg(&out)
        .arg(&file)
        .output()
        .expect("runs");
    assert!(!whole.status.success(), "a whole run joined running shards");
    assert!(
        stderr(&whole).contains("another lightquad run or merge"),
        "{}",
        stderr(&whole)
    );
    let shard = bin()
        .args(["run", "--shard", "1/2", "--out"])
        .arg(&out)
        .arg(&file)
        .output()
        .expect("runs");
    assert!(shard.status.success(), "{}", stderr(&shard));
    // Shard 2/2 still running: it holds its own lock alone.
    let other = fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(out.join(".lightquad.shard-2-of-2.lock"))
        .expect("shard lock");
    other.try_lock().expect("free");
    let merged = bin()
        .args(["merge", "--out"])
        .arg(dir.join("m"))
        .arg(&out)
        .output()
        .expect("runs");
    assert!(!merged.status.success(), "merged a folder still written");
    assert!(
        stderr(&merged).contains("still writing"),
        "{}",
        stderr(&merged)
    );
    drop((lock, other));
    let _ = fs::remove_dir_all(&dir);
}

/// Values near 1.8e308: the report's mean
/// over repeats overflowed to an unflagged `inf`, and a Monte Carlo standard
/// error of values near 1e308 was stored as `inf`.
#[test]
fn means_and_standard_errors_near_the_top_of_the_f64_range_stay_finite() {
    let text = VALID
        .replace("\"kappa\": 2.0", "\"kappa\": 0.001")
        .replace(
            "\"emission\": { \"type\": \"constant\", \"c\": 1.0 }",
            "\"emission\": { \"type\": \"constant\", \"c\": 1e305 }, \"background\": 1.7e308",
        )
        .replace("[\"tau\", \"I_E\"]", "[\"I_B\", \"I_E\"]")
        .replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"monte-carlo\" }",
        )
        .replace(
            "\"equations\": [\"V-tau\", \"V-E\"]",
            "\"equations\": [\"V-B\", \"V-E\"]",
        );
    let (dir, out, o) = run_text("top", &text);
    assert!(o.status.success(), "{}", stderr(&o));
    for r in lightquad::experiment::run::read_results(&out.join("t/results.jsonl"), None) {
        for m in r.quantities.values() {
            assert!(m.error.iter().all(|e| e.is_finite()), "{r:?}");
        }
    }
    let report = fs::read_to_string(out.join("t/report.md")).expect("report");
    assert!(
        !report.contains("| inf |") && !report.contains(" inf "),
        "{report}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// `--resume` reads every line on its own and says which it does not reuse:
/// one line that is not UTF-8 in the middle of results.jsonl ended the
/// reading, and every later line was dropped and re-run in silence.
#[test]
fn resume_reads_past_a_bad_line_and_says_what_it_does_not_reuse() {
    let (dir, out, o) = run_text("badline", VALID);
    assert!(o.status.success(), "{}", stderr(&o));
    let path = out.join("t/results.jsonl");
    let text = fs::read(&path).expect("results");
    let lines: Vec<&[u8]> = text
        .split(|&b| b == b'\n')
        .filter(|l| !l.is_empty())
        .collect();
    let total = lines.len();
    // A line of invalid UTF-8 after the second line.
    let mut broken = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        broken.extend_from_slice(l);
        broken.push(b'\n');
        if i == 1 {
            broken.extend_from_slice(b"\xff\xfe not a result\n");
        }
    }
    fs::write(&path, &broken).expect("write");
    let o = resume(&out, &dir.join("e.json"));
    assert!(o.status.success(), "{}", stderr(&o));
    let msg = stderr(&o);
    assert!(
        msg.contains("--resume does not reuse 1 unreadable line(s)")
            && msg.contains("0 result(s) of another version"),
        "{msg}"
    );
    // Every job's line is back, none run twice: the lines after the bad
    // one were reused.
    let after = fs::read_to_string(&path).expect("results");
    assert_eq!(after.lines().count(), total, "{after}");
    // Reused lines are kept verbatim (a job run again has another time).
    for l in &lines {
        let l = String::from_utf8_lossy(l);
        assert!(after.lines().any(|a| a == l), "not reused: {l}");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// A value near the top of the range against a reference of the other sign:
/// their difference overflowed, and the report showed a true error of `inf`
/// where it is |I_E - r| / |r| = 1.38.
/// I_E = c (1 - e^{-sigma L}) / sigma with c = 1.7e308, sigma = 2, L = 2
/// sqrt(1 - 0.3^2), against the reference -1.7e308. A radiance is never
/// negative, so `check` now refuses that literal reference (see
/// `a_reference_value_outside_what_the_quantity_can_take_is_refused`); the
/// report's rows are checked on the jobs' real results through the library.
#[test]
fn true_errors_near_the_top_of_the_range_do_not_overflow() {
    let text = VALID
        .replace("\"c\": 1.0", "\"c\": 1.7e308")
        .replace("[\"tau\", \"I_E\"]", "[\"I_E\"]")
        .replace("[4, 16, 64]", "[16]")
        .replace("\"repeats\": 2", "\"repeats\": 1")
        .replace(", { \"rule\": \"stratified\" }", "");
    let registry = lightquad::families::builtin();
    let json = lightquad::experiment::validate::parse_json(&text).expect("json");
    let exp = registry.load(json, "h").expect("valid");
    let results: Vec<_> = exp.jobs(None).into_iter().map(|j| exp.run_job(j)).collect();
    let rule = lightquad::experiment::report::RuleInfo {
        label: "gauss-legendre".into(),
        is_random: false,
        min_budget: Default::default(),
        resolution: Default::default(),
        not_run: None,
    };
    let reference = [-1.7e308];
    let rows = lightquad::experiment::report::rows(&[rule], &results, "I_E", &reference, None);
    let chord = 2.0 * (1.0f64 - 0.09).sqrt();
    let exact = 1.7e308 / 2.0 * (1.0 - (-2.0 * chord).exp());
    let want = exact / 1.7e308 + 1.0;
    assert_eq!(rows.len(), 1);
    assert!(
        (rows[0].rel_error / want - 1.0).abs() < 1e-12,
        "{} vs {want}",
        rows[0].rel_error
    );
    let d = lightquad::experiment::reference::relative_distance(&[exact], &reference);
    assert!((d / want - 1.0).abs() < 1e-15, "{d} vs {want}");
}

/// A value of the wrong JSON kind where a name or an object is needed lists
/// what is accepted: enum fields said
/// only "expected string or map", and `"scene": [1, 2]` was reported at
/// `scene[0]`.
#[test]
fn a_value_of_the_wrong_kind_lists_what_is_accepted() {
    rejected(
        &VALID.replace("\"scene\": {", "\"scene\": [1, 2], \"x\": {"),
        "scene",
        "a list [1,2]: expected an object",
    );
    rejected(
        &VALID.replace("\"scene\": {", "\"scene\": 3, \"x\": {"),
        "scene",
        "a number 3: expected an object",
    );
    rejected(
        &VALID.replace("\"scene\": {", "\"scene\": { \"depth_scheme\": 3,"),
        "scene.depth_scheme",
        "a number 3: expected a name in quotes, `cumulative` or `nested`",
    );
    rejected(
        &VALID.replace("\"scene\": {", "\"scene\": { \"shadow\": {\"a\": 1},"),
        "scene.shadow",
        "expected a name in quotes, `closed-form` or `quadrature`",
    );
    rejected(
        &VALID.replace("[\"tau\", \"I_E\"]", "[\"tau\", 3]"),
        "quantities[1]",
        "a number 3: expected a name in quotes, one of `tau`, `ln_tau`, `I_E`, `I_B`, `I_L`, `I`",
    );
    rejected(
        &VALID.replace("[\"tau\", \"I_E\"]", "\"tau\""),
        "quantities",
        "a string \"tau\": expected a list of names, each one of `tau`",
    );
    rejected(
        &VALID.replace("{ \"rule\": \"stratified\" }", "{ \"rule\": 3 }"),
        "rules[1].rule",
        "a number 3: expected a name in quotes, one of trapezoid, simpson",
    );
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"product\", \"outer\": \"trapezoid\", \"inner\": { \"rule\": \"trapezoid\" } }",
        ),
        "rules[1].outer",
        "\"trapezoid\" is not a rule: expected {\"rule\": <name>, <parameters>}, the name one of trapezoid, simpson",
    );
    rejected(
        &VALID.replace("{ \"type\": \"closed-form\" }", "{ \"type\": 3 }"),
        "reference.type",
        "a number 3: expected a name in quotes, one of `closed-form`, `value`, `mitsuba`, `converged`",
    );
    rejected(
        &VALID.replace(
            "\"emission\": { \"type\": \"constant\", \"c\": 1.0 }",
            "\"emission\": \"constant\"",
        ),
        "scene.emission",
        "\"constant\" is not an object: expected {\"type\": <name>, ...} with the name one of `constant`",
    );
    rejected(
        &VALID.replace(
            "\"budgets\": [4, 16, 64]",
            "\"budgets\": {\"from\": 4}, \"x\": 1",
        ),
        "budgets.to",
        "the required field `to` is missing",
    );
}

/// Every number error states the range the field accepts: `"replicates": -1`
/// said `>= 0` (it accepts 2..=1000000), `budgets: [18446744073709551615]`
/// named no range, and a number past the f64 range said only "number out of
/// range".
#[test]
fn every_number_error_states_the_range_the_field_accepts() {
    rejected(
        &VALID.replace("[4, 16, 64]", "[18446744073709551615]"),
        "budgets[0]",
        "invalid value: integer `18446744073709551615`, expected a whole number in 1..=100000000",
    );
    rejected(
        &VALID.replace("[4, 16, 64]", "{\"from\": 4, \"to\": 1e30, \"factor\": 2}"),
        "budgets.to",
        "expected a whole number in 1..=100000000",
    );
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"sobol\", \"replicates\": -1 }",
        ),
        "rules[1].replicates",
        "invalid value: integer `-1`, expected a whole number in 2..=1000000",
    );
    rejected(
        &VALID.replace(
            "{ \"rule\": \"stratified\" }",
            "{ \"rule\": \"product\", \"outer\": { \"rule\": \"sobol\", \"replicates\": 2.5 }, \"inner\": { \"rule\": \"trapezoid\" } }",
        ),
        "rules[1].outer.replicates",
        "invalid type: floating point `2.5`, expected a whole number in 2..=1000000",
    );
    rejected(
        &VALID.replace("\"repeats\": 2", "\"repeats\": -1"),
        "repeats",
        "expected a whole number in 1..=1000",
    );
    rejected(
        &VALID.replace("\"seed\": 7", "\"seed\": -7"),
        "seed",
        "expected a whole number in 0..=18446744073709551615",
    );
    rejected(
        &VALID.replace(
            "{ \"type\": \"closed-form\" }",
            "{ \"type\": \"converged\", \"n\": -1 }",
        ),
        "reference.n",
        "expected a whole number in 2..=100000",
    );
    rejected(
        &VALID.replace("\"radius\": 1.0", "\"radius\": 1e400"),
        "scene.medium.radius",
        "1e400 (line 7 column 85) is beyond the f64 range (its magnitude is above 1.8e308): \
         expected a finite number",
    );
}

/// A whole number beyond the f64 range (1e400), or beyond what the field holds
/// (1000000000000000000000, which JSON readers give as the float 1e21), is
/// refused naming the range the field accepts (1e400 said only "expected a
/// finite number", 1e21 "invalid type: floating point"); a whole number
/// written with an exponent (1e3) is the whole number JSON Schema's `integer`
/// says it is. The ranges are the schema's (`lightquad schema`: repeats
/// 1..=1000, budgets 1..=100000000, reference.n 2..=100000, seed a u64).
#[test]
fn whole_numbers_beyond_the_range_name_the_range() {
    let schema = bin().arg("schema").output().expect("runs");
    let schema: serde_json::Value = serde_json::from_slice(&schema.stdout).expect("JSON");
    let text = schema.to_string();
    for range in [
        "\"maximum\":1000,\"minimum\":1",
        "\"maximum\":100000000,\"minimum\":1",
        "\"maximum\":100000,\"minimum\":2",
    ] {
        assert!(text.contains(range), "the schema has no {range}");
    }
    let huge = "1000000000000000000000";
    for (number, what) in [
        ("1e400", "1e400 (line 13 column 18) is beyond the f64 range"),
        (huge, "invalid value: floating point `1e+21`"),
    ] {
        rejected(
            &VALID.replace("\"repeats\": 2", &format!("\"repeats\": {number}")),
            "repeats",
            &format!("{what}, expected a whole number in 1..=1000").replace(
                "range, expected",
                "range (its magnitude is above 1.8e308): expected",
            ),
        );
        rejected(
            &VALID.replace("\"seed\": 7", &format!("\"seed\": {number}")),
            "seed",
            "expected a whole number in 0..=18446744073709551615",
        );
        rejected(
            &VALID.replace("[4, 16, 64]", &format!("[4, 16, {number}]")),
            "budgets[2]",
            "expected a whole number in 1..=100000000",
        );
        rejected(
            &VALID.replace(
                "{ \"type\": \"closed-form\" }",
                &format!("{{ \"type\": \"converged\", \"n\": {number} }}"),
            ),
            "reference.n",
            "expected a whole number in 2..=100000",
        );
    }
    rejected(
        &VALID.replace("[4, 16, 64]", "[4, 16, -1e400]"),
        "budgets[2]",
        "-1e400 (line 12 column 27) is beyond the f64 range (its magnitude is above 1.8e308): \
         expected a whole number in 1..=100000000",
    );
    rejected(
        &VALID.replace("\"name\": \"t\"", "\"name\": 1e400"),
        "name",
        "expected a name of 1 to 100 letters",
    );
    // Whole numbers with an exponent are read as such.
    let dir = scratch("exponent");
    let file = dir.join("e.json");
    fs::write(
        &file,
        VALID
            .replace("[4, 16, 64]", "[4, 1.6e1, 64.0]")
            .replace("\"seed\": 7", "\"seed\": 1e5"),
    )
    .expect("write");
    let o = bin().arg("check").arg(&file).output().expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("2 rule(s) x 3 budget(s)"), "{out}");
    let _ = fs::remove_dir_all(&dir);
}

/// A missing field is named at its own path, not at the object that lacks it:
/// `scene.ray.origin`, not `scene.ray`. Every required field of a valid file,
/// dropped in turn.
#[test]
fn a_missing_field_is_named_at_its_own_path() {
    // What each accepts, as the schema (`lightquad schema`) and the README
    // say: a ray's points are 3 numbers, a sphere's radius and density are
    // numbers, the tags name their variants.
    let required = [
        (
            "\"origin\": [-3.0, 0.3, 0.0], ",
            "scene.ray.origin",
            "expected a list of 3 numbers",
        ),
        (
            ", \"direction\": [1.0, 0.0, 0.0]",
            "scene.ray.direction",
            "expected a list of 3 numbers",
        ),
        (
            "\"type\": \"constant-sphere\", ",
            "scene.medium.type",
            "expected one of `constant-sphere`, `gaussian-blobs`, `linear-gradient`, `voxel-grid`",
        ),
        (
            ", \"radius\": 1.0",
            "scene.medium.radius",
            "expected a number (radius)",
        ),
        (
            ", \"kappa\": 2.0",
            "scene.medium.kappa",
            "expected a number (density)",
        ),
        (
            ", \"c\": 1.0",
            "scene.emission.c",
            "expected a number (the constant)",
        ),
        (
            "\"rule\": \"stratified\"",
            "rules[1].rule",
            "expected one of trapezoid, simpson, gauss-legendre",
        ),
        (
            "\"quantities\": [\"tau\", \"I_E\"],",
            "quantities",
            "expected a list, each one of `tau`, `ln_tau`, `I_E`, `I_B`, `I_L`, `I`",
        ),
        (
            "\"type\": \"closed-form\"",
            "reference.type",
            "expected one of `closed-form`, `value`, `mitsuba`, `converged`",
        ),
        (
            "\"name\": \"t\",",
            "name",
            "expected a string (short name (file-name safe",
        ),
    ];
    for (cut, path, expected) in required {
        assert!(VALID.contains(cut), "{cut}");
        let field = path.rsplit('.').next().expect("field");
        let field = field.split('[').next().expect("name");
        rejected(
            &VALID.replace(cut, ""),
            path,
            &format!("the required field `{field}` is missing: {expected}"),
        );
    }
    // Inside a list, the variant the file names.
    rejected(
        &VALID.replace(
            "{ \"type\": \"constant-sphere\", \"centre\": [0.0, 0.0, 0.0], \"radius\": 1.0, \"kappa\": 2.0 }",
            "{ \"type\": \"gaussian-blobs\", \"blobs\": [{ \"centre\": [0, 0, 0], \"width\": 1.0 }] }",
        ),
        "scene.medium.blobs[0].amplitude",
        "the required field `amplitude` is missing: expected a number (peak density)",
    );
    rejected(
        &VALID.replace("[4, 16, 64]", "{ \"from\": 4, \"factor\": 2 }"),
        "budgets.to",
        "the required field `to` is missing: expected a whole number in 1..=100000000",
    );
    rejected(
        &VALID.replace(
            "\"ray\": { \"origin\": [-3.0, 0.3, 0.0], \"direction\": [1.0, 0.0, 0.0] },",
            "",
        ),
        "scene.ray",
        "the required field `ray` is missing",
    );
}

/// A radiance, intensity or transmittance given as a literal reference is
/// refused outside what the quantity can take: `I_E: -1` was accepted and
/// every error measured against it. `ln_tau` may be negative (it is at
/// most 0).
#[test]
fn a_reference_value_outside_what_the_quantity_can_take_is_refused() {
    let with = |values: &str| {
        VALID.replace(
            "{ \"type\": \"closed-form\" }",
            &format!("{{ \"type\": \"value\", \"values\": {{ {values} }} }}"),
        )
    };
    rejected(
        &with("\"tau\": 0.5, \"I_E\": -1"),
        "reference.values.I_E",
        "-1 is not a value I_E can take: expected a number >= 0",
    );
    rejected(
        &with("\"tau\": 1.5, \"I_E\": 1"),
        "reference.values.tau",
        "1.5 is not a value tau can take: expected a number in [0, 1]",
    );
    let ln =
        with("\"ln_tau\": 0.5, \"I_E\": 1").replace("[\"tau\", \"I_E\"]", "[\"ln_tau\", \"I_E\"]");
    rejected(
        &ln,
        "reference.values.ln_tau",
        "0.5 is not a value ln_tau can take: expected a number <= 0",
    );
    // In range: accepted, ln tau negative.
    let dir = scratch("refok");
    let file = dir.join("e.json");
    fs::write(&file, ln.replace("\"ln_tau\": 0.5", "\"ln_tau\": -3.3")).expect("write");
    let check = bin().arg("check").arg(&file).output().expect("runs");
    assert!(check.status.success(), "{}", stderr(&check));
    let _ = fs::remove_dir_all(&dir);
}

/// What an independent check of the reports found: on the stiff
/// sphere (optical depth 1e5) `I_B = e^-100000` reads 0 against a
/// reference of 0 and was shown unflagged, ranked by time and "at the error
/// floor from its first budget: easy"; it is flagged as underflowing like
/// tau, and an underflowed row reaches no target and is never called easy. A random rule on a constant integrand
/// (stratified on tau through a constant sphere: error 0 from the first
/// budget) gets the same note as a deterministic one; stratified sampling
/// on two cells has an infinite estimate, flagged.
#[test]
fn underflow_constant_integrands_and_missing_estimates_are_labelled() {
    let stiff = fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/v-tau-stiff-sphere.json"),
    )
    .expect("bundled");
    let (stiff_dir, out, o) = run_text("stiff", &stiff);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(out.join("v-tau-stiff-sphere/report.md")).expect("report");
    let section = report.split("## I_B").nth(1).expect("an I_B section");
    let rows: Vec<&str> = section
        .lines()
        .filter(|l| l.starts_with("| gauss-legendre | ") || l.starts_with("| trapezoid | "))
        .filter(|l| {
            l.split('|')
                .nth(2)
                .is_some_and(|b| b.trim().parse::<usize>().is_ok())
        })
        .collect();
    assert!(rows.len() >= 6, "{section}");
    for row in rows {
        assert!(row.contains("underflows"), "unflagged: {row}");
        // 0 against 0 is no error of 0 (the second independent check): the
        // true and estimated errors are shown as none.
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        assert_eq!((cells[4], cells[5]), ("—", "—"), "{row}");
    }
    assert!(
        section.starts_with(" (reference 0.000000000000000e0: the true value underflows f64"),
        "{section}"
    );
    let index = fs::read_to_string(out.join("index.md")).expect("index");
    let ib = index
        .lines()
        .find(|l| l.starts_with("- I_B (to "))
        .expect("I_B ranked");
    assert!(
        !ib.contains("easy for it") && ib.contains("not reached"),
        "{ib}"
    );

    let constant = VALID
        .replace(
            r#""quantities": ["tau", "I_E"]"#,
            r#""quantities": ["tau"]"#,
        )
        .replace(r#""budgets": [4, 16, 64]"#, r#""budgets": [2, 16, 64]"#);
    let (constant_dir, out, o) = run_text("constant", &constant);
    assert!(o.status.success(), "{}", stderr(&o));
    let index = fs::read_to_string(out.join("index.md")).expect("index");
    let line = index
        .lines()
        .find(|l| l.contains("stratified"))
        .expect("stratified ranked");
    assert!(line.contains("easy for it"), "{line}");
    let report = fs::read_to_string(out.join("t/report.md")).expect("report");
    let two = report
        .lines()
        .find(|l| l.starts_with("| stratified | 2 |"))
        .expect("a row at n = 2");
    assert!(two.contains("no error estimate"), "{two}");
    for dir in [stiff_dir, constant_dir] {
        let _ = fs::remove_dir_all(dir);
    }
}

/// File system faults name the path and the reason in words: not found, a
/// directory, a FIFO, a device, an --out that is a file; a Mitsuba reference
/// that is some other JSON file says it is not a values file and what it lacks
/// (it was called "stale").
#[test]
fn file_system_faults_name_the_path_and_the_reason() {
    let dir = scratch("fs");
    let check = |path: &Path| {
        let o = bin().arg("check").arg(path).output().expect("runs");
        assert!(!o.status.success());
        stderr(&o)
    };
    let missing = dir.join("missing.json");
    let msg = check(&missing);
    assert!(
        msg.contains(&format!("{}: not found (os error 2)", missing.display())),
        "{msg}"
    );
    let msg = check(&dir);
    assert!(
        msg.contains(&format!(
            "{}: is a directory: expected a regular JSON file",
            dir.display()
        )),
        "{msg}"
    );
    let msg = check(Path::new("/dev/null"));
    assert!(msg.contains("/dev/null: is a device"), "{msg}");
    // --out naming a file.
    let file = dir.join("e.json");
    fs::write(&file, VALID).expect("write");
    let out = dir.join("a-file");
    fs::write(&out, "").expect("write");
    let o = bin()
        .arg("run")
        .arg("--out")
        .arg(&out)
        .arg(&file)
        .output()
        .expect("runs");
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains(&format!(
            "{}: is a file, not a directory: the output folder (--out)",
            out.display()
        )),
        "{}",
        stderr(&o)
    );
    // A Mitsuba reference naming some other JSON file.
    fs::write(dir.join("other.json"), "{\"a\": 1}").expect("write");
    fs::write(
        &file,
        VALID.replace(
            "{ \"type\": \"closed-form\" }",
            "{ \"type\": \"mitsuba\", \"file\": \"other.json\" }",
        ),
    )
    .expect("write");
    let msg = check(&file);
    assert!(
        msg.contains("at `reference.file`")
            && msg.contains("other.json: not a Mitsuba values file: it has no `experiment_hash` and `quantities`")
            && !msg.contains("stale"),
        "{msg}"
    );
    // Named like a bundled experiment whose (bundled) values were made from
    // another file: the named file is still the fault, not those values'
    // staleness.
    let bundled = VALID
        .replace("\"name\": \"t\"", "\"name\": \"v-tau-stiff-sphere\"")
        .replace(
            "{ \"type\": \"closed-form\" }",
            "{ \"type\": \"mitsuba\", \"file\": \"other.json\" }",
        );
    fs::write(&file, &bundled).expect("write");
    let msg = check(&file);
    assert!(
        msg.contains("at `reference.file`")
            && msg.contains("other.json: not a Mitsuba values file: it has no `experiment_hash` and `quantities`")
            && !msg.contains("stale"),
        "{msg}"
    );
    // Not JSON at all: said, with what a values file is.
    fs::write(dir.join("other.json"), "x,y\n1,2\n").expect("write");
    let msg = check(&file);
    assert!(
        msg.contains("other.json is not a Mitsuba values file (not JSON: ")
            && msg.contains("expected the JSON file scripts/reference.sh writes")
            && !msg.contains("stale"),
        "{msg}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// A sphere of subnormal radius is refused at check with the accepted range
/// (radius 1e-310 gave a closed-form ln tau of -inf); tiny normal radii seen
/// from far away are measured right (radius 1e-200 from a distance of 3,
/// ln tau = -kappa 2r = -4e-200).
#[test]
fn sphere_radii_are_normal_numbers_and_tiny_ones_are_measured_right() {
    let with = |r: &str| {
        VALID
            .replace("\"radius\": 1.0", &format!("\"radius\": {r}"))
            .replace("[-3.0, 0.3, 0.0]", "[-3.0, 0.0, 0.0]")
            .replace("[\"tau\", \"I_E\"]", "[\"ln_tau\", \"tau\"]")
            .replace(", { \"rule\": \"stratified\" }", "")
            .replace("[4, 16, 64]", "[4]")
    };
    rejected(
        &with("1e-310"),
        "scene.medium.radius",
        "invalid radius = 1e-310: expected a finite number in [2.2250738585072014e-308, 1.7976931348623157e308]",
    );
    for (r, want) in [
        ("1e-150", "-4.000000000000000e-150"),
        ("1e-200", "-4.000000000000000e-200"),
    ] {
        let (dir, out, o) = run_text("tiny", &with(r));
        assert!(o.status.success(), "{}", stderr(&o));
        let report = fs::read_to_string(out.join("t/report.md")).expect("report");
        assert!(
            report.contains(&format!("## ln_tau (reference {want})")),
            "{report}"
        );
        let _ = fs::remove_dir_all(&dir);
    }
}

/// A constant sphere of radius 1e308
/// (optical depth 8e307, 1024 graded pieces) with a light and a converged
/// reference ran for minutes (n = 1000: 292 s; n = 1e5 for hours): the
/// adaptive rule spent its whole budget on every piece past the depth where
/// the transmittance underflows, and walked the optical depth to nodes
/// whose term was 0 (the light is shadowed everywhere), 6 x 3e6 density
/// lookups per piece at n = 1e5. Those pieces add exactly 0 and are skipped,
/// as are the walks; the same scene at n = 2000 now takes about a second.
/// With the printed light formulas the radius is refused: they square it.
#[test]
fn a_sphere_of_radius_1e308_with_a_converged_reference_runs_in_seconds() {
    let text = VALID
        .replace("\"radius\": 1.0, \"kappa\": 2.0", "\"radius\": 1e308, \"kappa\": 0.8")
        .replace(
            "\"emission\": { \"type\": \"constant\", \"c\": 1.0 }",
            "\"background\": 0.5, \"light\": { \"toward_light\": [0.3, 0.8, -0.2], \"intensity\": 1.0 }",
        )
        .replace("[\"tau\", \"I_E\"]", "[\"I_L\", \"I_B\"]")
        .replace(", { \"rule\": \"stratified\" }", "")
        .replace("[4, 16, 64]", "[4]")
        .replace("\"repeats\": 2", "\"repeats\": 1")
        .replace(
            "{ \"type\": \"closed-form\" }",
            "{ \"type\": \"converged\", \"n\": 2000 }",
        )
        .replace("\"equations\": [\"V-tau\", \"V-E\"]", "\"equations\": [\"V-L\"]");
    let dir = scratch("h7");
    let file = dir.join("e.json");
    fs::write(&file, &text).expect("write");
    let out = dir.join("out");
    let started = Instant::now();
    let o = run_with_timeout(
        &[
            "run",
            "--out",
            &out.display().to_string(),
            &file.display().to_string(),
        ],
        60,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(out.join("t/report.md")).expect("report");
    assert!(
        report.contains("converged evaluation at n = 4000"),
        "{report}"
    );
    eprintln!(
        "radius 1e308, converged n = 2000: {:.1} s",
        started.elapsed().as_secs_f64()
    );
    rejected(
        &text.replace("\"light\": {", "\"printed\": [\"s\"], \"light\": {"),
        "scene.medium.radius",
        "1e308: expected a radius in [1e-150, 1e150] where the printed light formulas",
    );
    let _ = fs::remove_dir_all(&dir);
}

/// A table whose rows count more evaluations than their budget says why,
/// in the Markdown and the HTML page (V-E with Gauss–Legendre showed about
/// 50 n evaluations unexplained). The
/// independent facts: V-E's outer nodes walk the cumulative depth (about
/// 12 lookups each), and Gauss–Legendre's estimate evaluates 3.5 n; the
/// trapezoid on tau alone evaluates exactly its n nodes on the one smooth
/// piece, so a table of those rows has no such line.
#[test]
fn evaluations_above_the_budget_are_explained_in_the_report() {
    let (dir, out, o) = run_text(
        "over-budget",
        &VALID.replace(
            "[ { \"rule\": \"gauss-legendre\" }, { \"rule\": \"stratified\" } ]",
            "[ { \"rule\": \"gauss-legendre\" }, { \"rule\": \"trapezoid\" } ]",
        ),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let md = fs::read_to_string(out.join("t/report.md")).expect("report");
    let html = fs::read_to_string(out.join("t/index.html")).expect("html");
    let tau = md.split("## tau").nth(1).expect("tau section");
    let tau = tau.split("## ").next().expect("tau alone");
    let emission = md.split("## I_E").nth(1).expect("I_E section");
    // The rows themselves: I_E's Gauss–Legendre rows above n, tau's
    // trapezoid rows at n.
    let evaluations = |section: &str, rule: &str, n: usize| -> f64 {
        let line = section
            .lines()
            .find(|l| l.starts_with(&format!("| {rule} | {n} |")))
            .unwrap_or_else(|| panic!("no {rule} row at {n}"));
        line.split('|')
            .nth(6)
            .expect("cell")
            .trim()
            .parse()
            .expect("a number")
    };
    assert!(evaluations(emission, "gauss-legendre", 64) > 3.5 * 64.0);
    assert!(evaluations(tau, "trapezoid", 64) <= 64.0);
    let line = "Evaluations above n (up to ";
    let why = "the cumulative optical depth";
    let gl = "Gauss–Legendre's error estimate evaluates three companion rules";
    let said = emission
        .lines()
        .find(|l| l.starts_with(line))
        .expect("I_E explained");
    assert!(said.contains(why) && said.contains(gl), "{said}");
    assert!(
        html.contains(line) && html.contains(why),
        "no line in the HTML page"
    );
    // Tau's table has Gauss–Legendre's error estimate (3.5 n) but no depth
    // walks; the line is there, and says the same.
    assert!(tau.contains(line), "{tau}");
    // A trapezoid-only tau experiment has no rows above n: no line.
    let (dir2, out2, o) = run_text(
        "at-budget",
        &VALID
            .replace(
                "\"quantities\": [\"tau\", \"I_E\"]",
                "\"quantities\": [\"tau\"]",
            )
            .replace(
                "[ { \"rule\": \"gauss-legendre\" }, { \"rule\": \"stratified\" } ]",
                "[ { \"rule\": \"trapezoid\" } ]",
            ),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let md = fs::read_to_string(out2.join("t/report.md")).expect("report");
    let html = fs::read_to_string(out2.join("t/index.html")).expect("html");
    assert!(!md.contains(line) && !html.contains(line), "{md}");
    let _ = fs::remove_dir_all(&dir);
    let _ = fs::remove_dir_all(&dir2);
}

/// A row of an image-like quantity reports its worst channel and the
/// channels whose 8-bit value (W-Grey) differs from the reference's, both
/// counted here by hand: reference (0.2, 0.4), two repeats at (0.201, 0.41)
/// and (0.2, 0.4 - 0.03). W-Grey: round(255 v); 0.2 -> 51, 0.201 -> 51
/// (51.255), 0.4 -> 102, 0.41 -> 105 (104.55), 0.37 -> 94 (94.35).
#[test]
fn the_largest_channel_error_and_the_8_bit_values_off_are_counted() {
    use lightquad::experiment::report::rows;
    use lightquad::family::Display;
    let (exp, rules) = i_experiment();
    let jobs: Vec<_> = [vec![0.201, 0.41], vec![0.2, 0.37]]
        .into_iter()
        .enumerate()
        .map(|(repeat, value)| {
            let mut job = exp.run_job((0, 16, repeat));
            job.quantities.get_mut("I").expect("I").value = value;
            job
        })
        .collect();
    let display = Display {
        name: "8-bit (W-Grey)",
        half_step: 1.0 / 510.0,
        quantize: lightquad::whitted::image::grey,
    };
    let reference = [0.2, 0.4];
    let table = rows(&rules, &jobs, "I", &reference, Some((&display, &[])));
    assert_eq!(table.len(), 1, "{table:?}");
    let row = &table[0];
    // Scale: rms(0.2, 0.4) = sqrt(0.1); worst channel 0.03 (second repeat).
    let scale = 0.1f64.sqrt();
    assert!((row.max_error - 0.03 / scale).abs() < 1e-12, "{row:?}");
    // RMS over the four differences (0.001, 0.01, 0, -0.03).
    let rms = ((0.001f64.powi(2) + 0.01f64.powi(2) + 0.03f64.powi(2)) / 4.0).sqrt();
    assert!((row.rel_error - rms / scale).abs() < 1e-12, "{row:?}");
    // One value off in each repeat.
    assert_eq!(row.display_off, Some(1.0), "{row:?}");
    // A channel whose reference display is in doubt is not counted: both
    // repeats' one value off is in channel 1.
    let unsure = rows(
        &rules,
        &jobs,
        "I",
        &reference,
        Some((&display, &[false, true])),
    );
    assert_eq!(unsure[0].display_off, Some(0.0), "{unsure:?}");
    // Without a display nothing is counted.
    let plain = rows(&rules, &jobs, "I", &reference, None);
    assert_eq!(plain[0].display_off, None);
}

/// r-coaxial-disk-1e-6: Gauss-Legendre returned pi for pi / (1 + 1e-12), a
/// true error of 0.99982e-12 with an estimate of 2.2e-16, and the row went
/// unflagged because the judge began at 1e-12 (the rows at 1.0001e-12 were
/// flagged). An estimate more than 10x too small is judged from 1e-13.
#[test]
fn an_estimate_4500_times_too_small_at_an_error_of_1e_12_is_flagged() {
    use lightquad::experiment::report::{RowFlag, rows};
    let (exp, rules) = i_experiment();
    let pi = std::f64::consts::PI;
    let mut job = exp.run_job((0, 16, 0));
    let m = job.quantities.get_mut("I").expect("I");
    m.value = vec![pi];
    m.error = vec![2.2e-16 * pi];
    m.flags.clear();
    let exact = pi / (1.0 + 1e-12);
    let table = rows(&rules, &[job], "I", &[exact], None);
    let row = &table[0];
    assert!((row.rel_error - 1e-12).abs() < 1e-15, "{row:?}");
    assert!(row.flags.contains(&RowFlag::EstimateOff), "{row:?}");
}

/// A sampler's budget in two dimensions buys sqrt(n) samples per axis, as
/// for Monte Carlo: the MIS estimators were fitted against n, so their
/// slopes (-0.57) showed as half of Monte Carlo's (-1.13 against sqrt n).
#[test]
fn a_samplers_resolution_per_axis_is_the_rules() {
    use lightquad::family::Estimator;
    use lightquad::quadrature::{MonteCarlo, Rule};
    use lightquad::rendering::experiment::Mis;
    for n in [2usize, 1024, 65536, 65537] {
        for dim in [1usize, 2, 3] {
            let mc = MonteCarlo.resolution(n, dim);
            for mis in Mis::all() {
                assert_eq!(
                    mis.resolution(n, dim),
                    mc,
                    "{} n = {n}, dim = {dim}",
                    mis.name()
                );
            }
        }
    }
    assert_eq!(MonteCarlo.resolution(65536, 2), 256.0);
}

/// The runner runs no more jobs at once than the memory available holds
/// (four jobs of 4 GB on four threads aborted a run): 80% of it over the
/// largest job's estimate, at least one, no cap where memory is unknown.
#[test]
fn jobs_at_once_fit_the_memory_available() {
    use lightquad::experiment::jobs_that_fit;
    assert_eq!(jobs_that_fit(4e9, Some(8e9)), 1);
    assert_eq!(jobs_that_fit(5.6e9, Some(24e9)), 3);
    assert_eq!(jobs_that_fit(1e9, Some(8e9)), 6);
    assert_eq!(jobs_that_fit(9e9, Some(8e9)), 1);
    assert_eq!(jobs_that_fit(0.0, Some(8e9)), usize::MAX);
    assert_eq!(jobs_that_fit(4e9, None), usize::MAX);
}

/// A finite value against a finite reference too small to divide by (a
/// literal 5e-324) has a relative error beyond the f64 range: the row says
/// so (it showed "inf" with no flag); against 0.5 it does not.
#[test]
fn a_relative_error_beyond_the_f64_range_is_flagged() {
    use lightquad::experiment::report::{RowFlag, rows};
    let (exp, rules) = i_experiment();
    let mut job = exp.run_job((0, 16, 0));
    let m = job.quantities.get_mut("I").expect("I");
    m.value = vec![1.75];
    m.error = vec![1e-3];
    m.flags.clear();
    let tiny = rows(&rules, std::slice::from_ref(&job), "I", &[5e-324], None);
    assert!(tiny[0].rel_error.is_infinite(), "{:?}", tiny[0]);
    assert!(
        tiny[0].flags.contains(&RowFlag::ErrorBeyondRange),
        "{:?}",
        tiny[0]
    );
    let plain = rows(&rules, &[job], "I", &[0.5], None);
    assert!((plain[0].rel_error - 2.5).abs() < 1e-15, "{:?}", plain[0]);
    assert!(!plain[0].flags.contains(&RowFlag::ErrorBeyondRange));
}

/// Runs of other files into one output folder: the index says which
/// experiment folders it holds from earlier runs and links them (it listed
/// only the last run's, leaving the others unlinked).
#[test]
fn an_index_links_the_experiments_of_earlier_runs_in_its_folder() {
    let dir = scratch("earlier");
    let out = dir.join("out");
    for file in ["calibration-exp.json", "calibration-disk.json"] {
        let o = bin()
            .args(["run", "--out"])
            .arg(&out)
            .arg(root().join("experiments").join(file))
            .output()
            .expect("runs");
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let md = fs::read_to_string(out.join("index.md")).expect("index");
    assert!(
        md.contains("from earlier runs")
            && md.contains("[calibration-exp](calibration-exp/report.md)"),
        "{md}"
    );
    assert!(
        !md.contains("[calibration-disk](calibration-disk/report.md)."),
        "{md}"
    );
    let html = fs::read_to_string(out.join("index.html")).expect("index");
    assert!(html.contains("<a href=\"calibration-exp/index.html\">calibration-exp</a>"));
    assert!(out.join("calibration-exp/index.html").is_file());
    let _ = fs::remove_dir_all(&dir);
}

/// A write that fails leaves no temporary file, and a whole run removes the
/// temporary files a killed run left (ENOSPC and kill -9 during report
/// writing left `.name.pid.n.tmp` files that `--resume` kept).
#[test]
fn failed_writes_and_killed_runs_leave_no_temporary_files() {
    use lightquad::experiment::run::write_atomic;
    let dir = scratch("temporaries");
    // Renaming onto a non-empty folder fails.
    let target = dir.join("taken");
    fs::create_dir_all(target.join("inside")).expect("folder");
    assert!(write_atomic(&target, b"text").is_err());
    let left: Vec<String> = fs::read_dir(&dir)
        .expect("list")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    // A killed run's leftovers, and a dot file that is not one.
    let out = dir.join("out");
    fs::create_dir_all(out.join("t")).expect("folder");
    for stale in [
        out.join(".index.md.4242.3.tmp"),
        out.join("t/.report.md.4242.7.tmp"),
    ] {
        fs::write(&stale, "half").expect("write");
    }
    fs::write(out.join(".keep"), "").expect("write");
    let file = dir.join("e.json");
    fs::write(&file, VALID).expect("write");
    let o = resume(&out, &file);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!out.join(".index.md.4242.3.tmp").exists());
    assert!(!out.join("t/.report.md.4242.7.tmp").exists());
    assert!(out.join(".keep").exists());
    let _ = fs::remove_dir_all(&dir);
}

/// Shards of an experiment whose Mitsuba values file is named by a path
/// relative to the experiment file: `run` found it, `merge` of the shards'
/// folders did not. A run keeps a copy
/// beside `experiment.json`, and the merged report compares with it.
#[test]
fn shards_with_a_relative_mitsuba_values_file_merge() {
    let dir = scratch("mitsuba-shards");
    fs::create_dir_all(dir.join("experiments")).expect("mkdir");
    fs::create_dir_all(dir.join("values")).expect("mkdir");
    let text = VALID.replace("[\"tau\", \"I_E\"]", "[\"tau\"]").replace(
        "\"reference\": { \"type\": \"closed-form\" }",
        "\"reference\": { \"type\": \"mitsuba\", \"file\": \"../values/t.json\" }",
    );
    assert!(text.contains("../values/t.json"), "{text}");
    let file = dir.join("experiments").join("t.json");
    fs::write(&file, &text).expect("write");
    // tau along the chord y = 0.3 of the unit sphere with kappa 2: exp(-2 L).
    let chord = 2.0 * (1.0f64 - 0.09).sqrt();
    let values = serde_json::json!({
        "experiment": "t",
        "experiment_hash": lightquad::experiment::run::file_hash(text.as_bytes()),
        "mitsuba_variant": "scalar_rgb",
        "mitsuba_version": "test",
        "quantities": {"tau": {"value": (-2.0 * chord).exp(), "std_error": 1e-7, "samples": 1}}
    });
    fs::write(dir.join("values").join("t.json"), values.to_string()).expect("write");
    let shards: Vec<PathBuf> = (1..=2).map(|k| dir.join(format!("s{k}"))).collect();
    for (k, out) in shards.iter().enumerate() {
        let o = bin()
            .args([
                "run",
                "--threads",
                "1",
                "--shard",
                &format!("{}/2", k + 1),
                "--out",
            ])
            .arg(out)
            .arg(&file)
            .output()
            .expect("runs");
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let merged = dir.join("merged");
    let o = merge(&merged, &[&shards[0], &shards[1]]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(merged.join("t").join("report.md")).expect("report");
    assert!(report.contains("lightquad vs Mitsuba 3"), "{report}");
    assert!(merged.join("t").join("mitsuba-values.json").is_file());
    let _ = fs::remove_dir_all(&dir);
}

/// `--resume` and `merge` reuse only results of the file's own jobs, shaped
/// as this version writes them: a line copied with `"rule_index": 99` was
/// kept as a fifth job of a four-job file and shown as a row "rule #99", and
/// a value of two channels for a scalar was shown with no true error, and a
/// line whose seed was edited was reused.
#[test]
fn resume_and_merge_reuse_only_results_of_the_files_jobs() {
    let (dir, out, o) = run_text("misfits", VALID);
    assert!(o.status.success(), "{}", stderr(&o));
    let path = out.join("t/results.jsonl");
    let text = fs::read_to_string(&path).expect("results");
    let total = text.lines().count();
    let mut lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("a result"))
        .collect();
    let mut foreign = lines[0].clone();
    foreign["rule_index"] = serde_json::json!(99);
    let q = lines[1]["quantities"]
        .as_object()
        .and_then(|m| m.keys().next().cloned())
        .expect("a quantity");
    lines[1]["quantities"][&q]["value"] = serde_json::json!([1.0, 2.0]);
    // A seed that is not the job's (the values were not drawn from it).
    let seed = lines[2]["seed"].as_u64().expect("a seed");
    lines[2]["seed"] = serde_json::json!(seed ^ 1);
    // An error estimate below 0 (no rule gives one).
    lines[3]["quantities"][&q]["error"] = serde_json::json!([-1.0]);
    lines.push(foreign);
    let edited: String = lines.iter().map(|l| format!("{l}\n")).collect();
    fs::write(&path, &edited).expect("write");
    // merge of the edited folder passes both over, says so, and calls the
    // merge incomplete (the edited job is missing).
    let merged = dir.join("merged");
    let o = merge(&merged, &[&out]);
    assert!(!o.status.success(), "an incomplete merge succeeded");
    assert!(
        stderr(&o).contains("4 unreadable line(s)"),
        "{}",
        stderr(&o)
    );
    let report = fs::read_to_string(merged.join("t/report.md")).expect("report");
    assert!(!report.contains("rule #99"), "{report}");
    // --resume runs the edited job again and drops the foreign one.
    let o = resume(&out, &dir.join("e.json"));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("does not reuse 4 unreadable line(s)"),
        "{}",
        stderr(&o)
    );
    let after = fs::read_to_string(&path).expect("results");
    assert_eq!(after.lines().count(), total, "{after}");
    assert!(!after.contains("\"rule_index\":99"), "{after}");
    let report = fs::read_to_string(out.join("t/report.md")).expect("report");
    assert!(!report.contains("rule #99"), "{report}");
    let _ = fs::remove_dir_all(&dir);
}

/// What is in the way of an experiment's files is named before any job runs
/// (a file where its folder goes said "already exists", and a folder named
/// results.jsonl was named as the experiment's folder); and a run without
/// `--resume` says it replaces the earlier results of the same file (a rerun
/// killed at once had turned 360 results into 80 without a word).
#[test]
fn what_is_in_the_way_is_named_and_replaced_results_are_said() {
    let dir = scratch("in-the-way");
    let file = dir.join("e.json");
    fs::write(&file, VALID).expect("write");
    let run = |out: &Path| {
        bin()
            .args(["run", "--threads", "1", "--out"])
            .arg(out)
            .arg(&file)
            .output()
            .expect("runs")
    };
    let blocked = dir.join("blocked");
    fs::create_dir_all(&blocked).expect("mkdir");
    fs::write(blocked.join("t"), "not a folder").expect("write");
    let o = run(&blocked);
    assert!(!o.status.success(), "accepted");
    assert!(
        stderr(&o).contains("is in the way") && stderr(&o).contains("blocked/t"),
        "{}",
        stderr(&o)
    );
    let folder = dir.join("folder");
    fs::create_dir_all(folder.join("t").join("results.jsonl")).expect("mkdir");
    let o = run(&folder);
    assert!(!o.status.success(), "accepted");
    assert!(
        stderr(&o).contains("t/results.jsonl") && stderr(&o).contains("is a folder"),
        "{}",
        stderr(&o)
    );
    let out = dir.join("out");
    let o = run(&out);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("replacing"), "{}", stderr(&o));
    let jobs = fs::read_to_string(out.join("t/results.jsonl"))
        .expect("results")
        .lines()
        .count();
    let o = run(&out);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("replacing {jobs} earlier result(s)"))
            && stderr(&o).contains("--resume"),
        "{}",
        stderr(&o)
    );
    let _ = fs::remove_dir_all(&dir);
}

/// A report file that cannot be written is named with the reason in words
/// (a full disk during the report said only "No space left on device").
#[test]
fn a_report_that_cannot_be_written_is_named_and_leaves_no_partial_pages() {
    let dir = scratch("unwritable");
    let path = dir.join("no-such-folder").join("report.md");
    let e = lightquad::experiment::run::write_report_file(&path, b"x").expect_err("no folder");
    assert!(
        e.contains(&path.display().to_string()) && e.contains("not found"),
        "{e}"
    );
    let _ = fs::remove_dir_all(&dir);

    // A report that fails at its index (a folder where index.md goes, as a
    // full disk there would) left the plots and pages written before it; now
    // they are removed, the results kept, and a --resume writes the report.
    let dir = scratch("unfinished");
    let file = dir.join("e.json");
    fs::write(&file, VALID).expect("write");
    let out = dir.join("out");
    fs::create_dir_all(out.join("index.md").join("x")).expect("mkdir");
    let o = bin()
        .args(["run", "--out"])
        .arg(&out)
        .arg(&file)
        .output()
        .expect("runs");
    let msg = stderr(&o);
    assert!(!o.status.success(), "{msg}");
    assert!(
        msg.contains("index.md") && msg.contains("the results are kept"),
        "{msg}"
    );
    let mut left: Vec<String> = fs::read_dir(out.join("t"))
        .expect("experiment folder")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["experiment.json", "results.jsonl"]);
    assert!(!out.join("index.html").exists());
    fs::remove_dir_all(out.join("index.md")).expect("rm");
    let o = resume(&out, &file);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("t").join("index.html").is_file() && out.join("index.md").is_file());
    let _ = fs::remove_dir_all(&dir);
}

/// The experiments' reports are written at once on the run's threads; one
/// that fails removes every report file of the run, those the other
/// threads wrote included, and the failure said is the first in the order
/// of the experiments, whichever finished first.
#[test]
fn reports_written_in_parallel_are_removed_together_and_the_first_failure_is_said() {
    let dir = scratch("parallel-reports");
    let names = ["a", "b", "c", "d", "e", "f"];
    let files: Vec<PathBuf> = names
        .iter()
        .map(|n| {
            let file = dir.join(format!("{n}.json"));
            fs::write(
                &file,
                VALID.replace(r#""name": "t""#, &format!(r#""name": "{n}""#)),
            )
            .expect("write");
            file
        })
        .collect();
    let out = dir.join("out");
    let run = |args: &[&str]| {
        bin()
            .arg("run")
            .args(args)
            .args(["--threads", "2", "--out"])
            .arg(&out)
            .args(&files)
            .output()
            .expect("runs")
    };
    // A folder where the tables of d and f go (as a full disk there would),
    // written after their pages and plots.
    for n in ["d", "f"] {
        fs::create_dir_all(out.join(n).join("results.csv").join("x")).expect("mkdir");
    }
    let o = run(&[]);
    let msg = stderr(&o);
    assert!(!o.status.success(), "{msg}");
    let said: Vec<&str> = msg.lines().filter(|l| l.contains("results.csv")).collect();
    assert!(
        said.len() == 1 && said[0].contains(&out.join("d").display().to_string()),
        "{msg}"
    );
    for n in names {
        let mut left: Vec<String> = fs::read_dir(out.join(n))
            .expect("experiment folder")
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|f| f != "results.csv")
            .collect();
        left.sort();
        assert_eq!(left, ["experiment.json", "results.jsonl"], "{n}: {msg}");
    }
    assert!(!out.join("index.md").exists() && !out.join("index.html").exists());
    // With the folders gone every report is written, whole.
    for n in ["d", "f"] {
        fs::remove_dir_all(out.join(n).join("results.csv")).expect("rm");
    }
    let o = run(&["--resume"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let index = fs::read_to_string(out.join("index.md")).expect("index");
    for n in names {
        assert!(out.join(n).join("report.md").is_file(), "{n}");
        assert!(out.join(n).join("index.html").is_file(), "{n}");
        assert!(index.contains(&format!("{n}/report.md")), "{n}: {index}");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// Shards that needed `--no-cost-limit` (ratio tracking through a blob of
/// amplitude 1e307: its walks would collide about 1e307 times; a
/// delta-tracking walk stops within a few thousand look-ups there, and the
/// guard now lets it through) could never
/// be merged: `merge`, which runs no job, re-ran the cost guard and had no
/// flag to lift it. And `check` advised lowering
/// the budget, which cannot help there.
#[test]
fn shards_run_past_the_cost_limit_merge_and_the_advice_fits_the_cause() {
    let text = r#"{"name": "blob", "family": "volume",
      "scene": {"ray": {"origin": [-6.0, 0.0, 0.05], "direction": [1.0, 0.02, 0.0]},
        "medium": {"type": "gaussian-blobs", "blobs": [
          {"centre": [0.0, 0.1, 0.0], "amplitude": 1e307, "width": 0.4}]}},
      "quantities": ["tau"], "rules": [{"rule": "gauss-legendre"}, {"rule": "ratio-tracking"}],
      "budgets": [4, 16], "reference": {"type": "closed-form"}}"#;
    let dir = scratch("costly-shards");
    let file = dir.join("blob.json");
    fs::write(&file, text).expect("write");
    let o = bin().arg("check").arg(&file).output().expect("runs");
    let msg = stderr(&o);
    assert!(
        !o.status.success() && msg.contains("rules[1]") && msg.contains("at any budget"),
        "{msg}"
    );
    for k in ["1/2", "2/2"] {
        let o = bin()
            .args(["run", "--no-cost-limit", "--shard", k, "--out"])
            .arg(dir.join(k.replace('/', "-")))
            .arg(&file)
            .output()
            .expect("runs");
        assert!(!stderr(&o).contains("costs about"), "{}", stderr(&o));
    }
    let merged = dir.join("merged");
    let o = merge(&merged, &[&dir.join("1-2"), &dir.join("2-2")]);
    let msg = stderr(&o);
    assert!(!msg.contains("costs about"), "merge refused: {msg}");
    assert!(merged.join("blob").join("report.md").is_file(), "{msg}");
    let _ = fs::remove_dir_all(&dir);
}

/// The findings paragraph states what theory says of a case built for it:
/// int_0^1 e^u by the trapezoid rule on n points has error (e - 1) h^2 / 12,
/// h = 1/(n - 1) (3.6e-5 at 64 points, 5.5e-7 at 512: it reaches 1e-3 and
/// never 1e-9, at a slope of -2n/(n - 1), -2.03 to -2.00 here), while
/// Gauss–Legendre is at rounding from 64 nodes (the only one to reach 1e-9).
#[test]
fn the_findings_say_what_theory_says_of_a_case_built_for_it() {
    let (dir, out, o) = run_text(
        "findings",
        r#"{ "name": "f", "family": "calibration", "scene": {}, "quantities": ["exp"],
        "rules": [{ "rule": "trapezoid" }, { "rule": "gauss-legendre" }],
        "budgets": [64, 128, 256, 512], "repeats": 1, "targets": [1e-3, 1e-9],
        "reference": { "type": "closed-form" } }"#,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(out.join("f/report.md")).expect("report");
    let findings = report
        .lines()
        .find(|l| l.starts_with("Findings"))
        .expect("findings");
    assert!(
        findings.contains("Only gauss-legendre reaches 1e-9"),
        "{findings}"
    );
    assert!(!findings.contains("No rule reaches 1e-3"), "{findings}");
    let fitted = findings
        .split("against log evaluations: ")
        .nth(1)
        .expect("fitted slopes");
    let slope: f64 = fitted
        .split("trapezoid ")
        .nth(1)
        .and_then(|t| t.split([',', ' ']).next())
        .and_then(|t| t.trim_end_matches('.').parse().ok())
        .expect("a trapezoid slope");
    assert!((slope + 2.0).abs() < 0.05, "{slope}: {findings}");
    let html = fs::read_to_string(out.join("f/index.html")).expect("html");
    assert!(
        html.contains("<p class=\"findings\">Findings"),
        "the HTML page shows them too"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// A rule whose every job failed has no rank: `sin(x)/x` on [0, 1] is
/// 0/0 at the end the trapezoid and Simpson rules take, so each of their
/// jobs fails, while Gauss–Legendre (no node at an end) reaches the
/// target. The failed rules were ranked 2 and 3, alphabetically, in
/// index.md, index.html and summary.json, though no time orders them.
#[test]
fn rules_whose_every_job_failed_are_not_ranked() {
    let spec = r#"{
      "name": "t", "family": "integral",
      "scene": {"domain": {"type": "interval", "a": 0, "b": 1},
                "integrand": "sin(x)/x", "exact": "0.94608307036718301494"},
      "quantities": ["integral"],
      "rules": [{"rule": "trapezoid"}, {"rule": "simpson"}, {"rule": "gauss-legendre"}],
      "budgets": [8, 16], "repeats": 1, "seed": 1,
      "reference": {"type": "closed-form"}
    }"#;
    let (dir, out, o) = run_text("unranked", spec);
    let summary: serde_json::Value = serde_json::from_str(
        &fs::read_to_string(out.join("t/summary.json"))
            .unwrap_or_else(|e| panic!("{e}: {}", stderr(&o))),
    )
    .expect("summary.json");
    let rules = summary["experiments"][0]["quantities"][0]["rules"]
        .as_array()
        .expect("rules");
    let rank = |label: &str| {
        let rule = rules.iter().find(|r| r["label"] == label).expect(label);
        (rule["rank"].clone(), rule["tied"].clone())
    };
    assert_eq!(rank("gauss-legendre"), (1.into(), false.into()));
    for failed in ["trapezoid", "simpson"] {
        assert_eq!(
            rank(failed),
            (serde_json::Value::Null, false.into()),
            "{failed}"
        );
    }
    let index = fs::read_to_string(out.join("index.md")).expect("index.md");
    let line = index
        .lines()
        .find(|l| l.starts_with("- integral (to "))
        .expect("the quantity's ranking");
    assert!(
        line.contains("simpson (not reached)") && line.contains("trapezoid (not reached)"),
        "{line}"
    );
    assert!(!line.contains("tied"), "{line}");
    // Each failed job records the time it ran until it failed, not 0.
    let results = fs::read_to_string(out.join("t/results.jsonl")).expect("results");
    let failed: Vec<serde_json::Value> = results
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).expect("json"))
        .filter(|v| v["failure"].is_string())
        .collect();
    assert_eq!(failed.len(), 4, "{results}");
    for job in &failed {
        assert!(job["seconds"].as_f64().is_some_and(|s| s > 0.0), "{job}");
    }
    let html = fs::read_to_string(out.join("index.html")).expect("index.html");
    for failed in ["trapezoid", "simpson"] {
        let row = html
            .split("<tr>")
            .find(|r| r.starts_with("<td>integral</td>") && r.contains(failed))
            .unwrap_or_else(|| panic!("{failed}'s row"));
        assert!(
            row.starts_with("<td>integral</td><td class=\"num\">—</td>"),
            "{row}"
        );
    }
    let _ = fs::remove_dir_all(&dir);
}

/// A row where some repeats failed says how many: `sqrt(x - 1/2)` is not a
/// number below 1/2, so a Monte Carlo job of two samples fails unless both
/// land above it (1 in 4). The row said "failed" whether one repeat of
/// four failed or all four; the count here is taken from results.jsonl.
#[test]
fn a_row_says_how_many_of_its_repeats_failed() {
    let spec = r#"{
      "name": "t", "family": "integral",
      "scene": {"domain": {"type": "interval", "a": 0, "b": 1},
                "integrand": "sqrt(x - 0.5)", "exact": "0.2357022603955158"},
      "quantities": ["integral"],
      "rules": [{"rule": "monte-carlo"}],
      "budgets": [2], "repeats": 4, "seed": 3,
      "reference": {"type": "closed-form"}
    }"#;
    let (dir, out, o) = run_text("some-failed", spec);
    let results = fs::read_to_string(out.join("t/results.jsonl"))
        .unwrap_or_else(|e| panic!("{e}: {}", stderr(&o)));
    let failed = results
        .lines()
        .filter(|l| l.contains("\"failure\":\""))
        .count();
    assert!(
        (1..4).contains(&failed),
        "a seed with some repeats failed: {results}"
    );
    let report = fs::read_to_string(out.join("t/report.md")).expect("report");
    let row = report
        .lines()
        .find(|l| l.starts_with("| monte-carlo | 2 |"))
        .expect("the row");
    assert!(
        row.contains(&format!("failed in {failed} of 4 repeats: ")),
        "{row}"
    );
    // The findings paragraph says it too.
    let flags = report
        .lines()
        .find(|l| l.contains("Flags: "))
        .expect("the findings' flags");
    assert!(
        flags.contains(&format!(
            "monte-carlo failed in {failed} of 4 repeats at n = 2"
        )),
        "{flags}"
    );
    let _ = fs::remove_dir_all(&dir);
}

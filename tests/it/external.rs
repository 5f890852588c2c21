//! External estimators: the example programs judged in the bundled
//! experiment, and every fault a program can commit (exiting, hanging,
//! garbage, NaN, the wrong channels, a huge line, a talkative stderr), each
//! failing only its own jobs with a message naming the rule and the request;
//! `--resume` retrying only failed jobs; `check` refusing a missing program;
//! no program outliving a killed lightquad; nothing sent beyond the
//! experiment.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::{Duration, Instant};

use serde_json::Value as Json;

use crate::common::{bin, root, scratch, stderr};

/// An experiment of the calibration family (`int_0^1 e^x dx = e - 1`) in
/// `dir` with Gauss–Legendre and the program `prog.py` (written there).
fn setup(tag: &str, program: &str, external: Json) -> (PathBuf, PathBuf) {
    let dir = scratch(tag);
    std::fs::write(dir.join("prog.py"), program).expect("program");
    let mut rule = serde_json::json!({"rule": "external", "name": "prog", "command": ["python3", "prog.py"], "timeout_s": 20});
    for (k, v) in external.as_object().into_iter().flatten() {
        rule[k] = v.clone();
    }
    let exp = serde_json::json!({
        "name": "ext", "family": "calibration", "scene": {}, "quantities": ["exp"],
        "rules": [{"rule": "gauss-legendre"}, rule],
        "budgets": [4, 8], "repeats": 2, "seed": 1, "reference": {"type": "closed-form"}
    });
    let file = dir.join("exp.json");
    std::fs::write(&file, exp.to_string()).expect("experiment");
    (dir, file)
}

fn run(file: &Path, out: &Path, more: &[&str]) -> Output {
    bin()
        .arg("run")
        .arg(file)
        .arg("--out")
        .arg(out)
        .args(more)
        .output()
        .expect("lightquad runs")
}

fn results(out: &Path) -> Vec<Json> {
    std::fs::read_to_string(out.join("ext/results.jsonl"))
        .expect("results.jsonl")
        .lines()
        .map(|l| serde_json::from_str(l).expect("a result line"))
        .collect()
}

/// The failures of the program's jobs; every Gauss–Legendre job succeeded.
fn failures(out: &Path) -> Vec<String> {
    let all = results(out);
    assert_eq!(all.len(), 8, "2 rules x 2 budgets x 2 repeats");
    for r in all.iter().filter(|r| r["rule"] == "gauss-legendre") {
        assert!(r["failure"].is_null(), "{r}");
    }
    all.iter()
        .filter(|r| r["rule"] == "prog")
        .filter_map(|r| r["failure"].as_str().map(str::to_string))
        .collect()
}

/// The line a program writes when it is ready.
const HELLO: &str = "import json, sys\nprint(json.dumps({'protocol': 'lightquad-estimator', 'version': 1}), flush=True)\n";

/// A correct program: the closed form e - 1, with a standard error, and
/// `before` run first on each request.
fn answering(before: &str) -> String {
    format!(
        "{HELLO}import json, math, sys\n\
         for line in sys.stdin:\n\
         \x20   req = json.loads(line)\n\
         \x20   {before}\n\
         \x20   print(json.dumps({{'id': req['id'], 'value': [math.e - 1], 'std_error': [1e-3]}}), flush=True)\n"
    )
}

#[test]
fn a_correct_program_runs_beside_the_rules() {
    let (dir, file) = setup("ext-ok", &answering("pass"), serde_json::json!({}));
    let out = dir.join("out");
    let o = run(&file, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(failures(&out).is_empty());
    let prog: Vec<Json> = results(&out)
        .into_iter()
        .filter(|r| r["rule"] == "prog")
        .collect();
    for r in &prog {
        let m = &r["quantities"]["exp"];
        assert_eq!(m["value"][0].as_f64(), Some(std::f64::consts::E - 1.0));
        assert_eq!(m["error"][0].as_f64(), Some(1e-3));
        // lightquad timed the request itself.
        assert!(m["seconds"].as_f64().is_some_and(|s| s > 0.0), "{m}");
    }
}

#[test]
fn each_fault_fails_only_its_jobs_and_names_rule_request_and_stderr() {
    let cases: [(&str, String, Json, &[&str]); 9] = [
        (
            "never-ready",
            "import sys, time\ntime.sleep(60)\n".into(),
            serde_json::json!({"timeout_s": 0.5}),
            &["not ready within timeout_s = 0.5 s"],
        ),
        (
            "other-version",
            "import json, sys\nprint(json.dumps({'protocol': 'lightquad-estimator', 'version': 2}), flush=True)\nsys.stdin.read()\n".into(),
            serde_json::json!({}),
            &["version 2", "lightquad speaks \"lightquad-estimator\" version 1"],
        ),
        (
            "exit-at-start",
            "import sys\nsys.stderr.write('cannot load my scene\\n')\nsys.exit(3)\n".into(),
            serde_json::json!({}),
            &["external `prog`", "exp at budget", "no hello line: the program exited (exit status: 3)", "cannot load my scene"],
        ),
        (
            "hang",
            HELLO.to_string()
                + "import sys, time\nsys.stderr.write('thinking\\n'); sys.stderr.flush()\nsys.stdin.readline()\ntime.sleep(60)\n",
            serde_json::json!({"timeout_s": 0.5}),
            &["no answer within timeout_s = 0.5 s", "thinking"],
        ),
        (
            "garbage",
            answering("print('hello from my renderer', flush=True); continue"),
            serde_json::json!({}),
            &["hello from my renderer", "not a response"],
        ),
        (
            "nan",
            HELLO.to_string()
                + "import json, sys\nfor line in sys.stdin:\n    req = json.loads(line)\n    print(json.dumps({'id': req['id'], 'value': [float('nan')]}), flush=True)\n",
            serde_json::json!({}),
            &["NaN", "allow_nan"],
        ),
        (
            "channels",
            HELLO.to_string()
                + "import json, sys\nfor line in sys.stdin:\n    req = json.loads(line)\n    print(json.dumps({'id': req['id'], 'value': [1.0, 2.0, 3.0]}), flush=True)\n",
            serde_json::json!({}),
            &["3 value(s)", "1 channel(s)"],
        ),
        (
            "huge-line",
            HELLO.to_string()
                + "import sys\nfor line in sys.stdin:\n    sys.stdout.write('x' * 3000000 + '\\n'); sys.stdout.flush()\n",
            serde_json::json!({}),
            &["longer than"],
        ),
        (
            "declines",
            HELLO.to_string()
                + "import json, sys\nfor line in sys.stdin:\n    req = json.loads(line)\n    print(json.dumps({'id': req['id'], 'error': 'no spheres here'}), flush=True)\n",
            serde_json::json!({}),
            &["could not estimate it: no spheres here"],
        ),
    ];
    for (tag, program, external, expected) in cases {
        let (dir, file) = setup(tag, &program, external);
        let out = dir.join("out");
        let start = Instant::now();
        let o = run(&file, &out, &[]);
        assert!(!o.status.success(), "{tag}: a failed job fails the run");
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "{tag}: took {:?}",
            start.elapsed()
        );
        let failed = failures(&out);
        assert_eq!(failed.len(), 4, "{tag}: every job of the program failed");
        for f in &failed {
            for e in expected {
                assert!(f.contains(e), "{tag}: {e:?} not in {f:?}");
            }
            assert!(f.contains("repeat") && f.contains("seed"), "{tag}: {f}");
        }
        // The report is written, its failures said.
        let report = std::fs::read_to_string(out.join("ext/report.md")).expect("report");
        assert!(report.contains("gauss-legendre"), "{tag}");
    }
}

#[test]
fn a_program_that_exits_mid_run_fails_the_next_job_and_keeps_what_it_answered() {
    // Answers one request, then exits: on one lane the next job finds it
    // gone and fails, the one after starts a fresh process, and so on.
    let program = answering("pass") + "    sys.exit(0)\n";
    let (dir, file) = setup("ext-midrun", &program, serde_json::json!({}));
    let out = dir.join("out");
    let o = run(&file, &out, &["--threads", "1"]);
    assert!(!o.status.success());
    let failed = failures(&out);
    assert_eq!(failed.len(), 2, "{failed:?}");
    for f in &failed {
        assert!(f.contains("the program exited (exit status: 0)"), "{f}");
    }
    let answered = results(&out)
        .into_iter()
        .filter(|r| r["rule"] == "prog" && r["failure"].is_null())
        .count();
    assert_eq!(answered, 2);
}

#[test]
fn a_talkative_stderr_never_blocks_the_program() {
    // 4 MB on stderr before each answer: a pipe nobody read would block at 64 KB.
    let (dir, file) = setup(
        "ext-stderr",
        &answering("sys.stderr.write('log line ' * 400000 + '\\n'); sys.stderr.flush()"),
        serde_json::json!({"timeout_s": 20}),
    );
    let out = dir.join("out");
    let o = run(&file, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(failures(&out).is_empty());
}

#[test]
fn resume_retries_only_the_failed_jobs() {
    // Fails while a marker file is missing; the test creates it between runs.
    let program = answering(
        "import os\n    if not os.path.exists('ready'):\n        print('not ready', flush=True); continue",
    );
    let (dir, file) = setup("ext-resume", &program, serde_json::json!({}));
    let out = dir.join("out");
    let o = run(&file, &out, &[]);
    assert!(!o.status.success());
    assert_eq!(failures(&out).len(), 4);
    let before: Vec<Json> = results(&out)
        .into_iter()
        .filter(|r| r["rule"] == "gauss-legendre")
        .collect();
    std::fs::write(dir.join("ready"), "").expect("marker");
    let o = run(&file, &out, &["--resume"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(failures(&out).is_empty());
    // Its line says what ran now and what was kept.
    assert!(
        stderr(&o).contains("finished ext: 8 jobs (4 run now, 4 kept from before), 0 failed, "),
        "{}",
        stderr(&o)
    );
    // The finished jobs were kept as they were, not run again.
    let after: Vec<Json> = results(&out)
        .into_iter()
        .filter(|r| r["rule"] == "gauss-legendre")
        .collect();
    let key = |r: &Json| {
        (
            r["budget"].to_string(),
            r["repeat"].to_string(),
            r["seconds"].to_string(),
        )
    };
    let mut b: Vec<_> = before.iter().map(key).collect();
    let mut a: Vec<_> = after.iter().map(key).collect();
    b.sort();
    a.sort();
    assert_eq!(a, b);
}

#[test]
fn check_refuses_a_missing_program_at_its_path() {
    let (dir, file) = setup(
        "ext-missing",
        "",
        serde_json::json!({"command": ["./no-such-renderer"]}),
    );
    let o = bin().arg("check").arg(&file).output().expect("check runs");
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("rules[1].command[0]") && e.contains("no-such-renderer"),
        "{e}"
    );
    // A bare name not on PATH.
    let text = std::fs::read_to_string(&file)
        .expect("file")
        .replace("./no-such-renderer", "no-such-renderer-xyz");
    std::fs::write(&file, text).expect("file");
    let o = bin().arg("check").arg(&file).output().expect("check runs");
    assert!(
        stderr(&o).contains("no program \"no-such-renderer-xyz\" on PATH"),
        "{}",
        stderr(&o)
    );
    // Skipped instead, where the rule allows it: the run exits 0 and the
    // report says why the rule has no rows.
    let text = std::fs::read_to_string(&file).expect("file").replace(
        "\"timeout_s\":20",
        "\"timeout_s\":20,\"if_missing\":\"skip\"",
    );
    std::fs::write(&file, text).expect("file");
    let out = dir.join("out");
    let o = run(&file, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = std::fs::read_to_string(out.join("ext/report.md")).expect("report");
    assert!(
        report.contains("Not run, no rows: prog (its program is missing"),
        "{report}"
    );
}

#[test]
fn bad_external_rules_are_refused_at_their_field() {
    for (rule, path, says) in [
        (
            r#"{"rule": "external", "name": "p", "command": []}"#,
            "rules[1].command",
            "empty list",
        ),
        (
            r#"{"rule": "external", "name": "p", "command": ["python3"], "timeout_s": 0}"#,
            "rules[1].timeout_s",
            "(0, 86400]",
        ),
        (
            r#"{"rule": "external", "name": "monte-carlo", "command": ["python3"]}"#,
            "rules[1].name",
            "lightquad's own rules",
        ),
        (
            r#"{"rule": "external", "name": "a b", "command": ["python3"]}"#,
            "rules[1].name",
            "letters, digits",
        ),
        (
            r#"{"rule": "external", "name": "p", "command": ["python3"], "timeout": 3}"#,
            "rules[1]",
            "unknown field `timeout`",
        ),
        (
            r#"{"rule": "external", "command": ["python3"]}"#,
            "rules[1].name",
            "required field `name` is missing",
        ),
        (
            r#"{"rule": "external", "name": "p", "command": "python3"}"#,
            "rules[1].command",
            "expected a list",
        ),
    ] {
        let dir = scratch("ext-bad");
        let text = format!(
            r#"{{"name": "ext", "family": "calibration", "scene": {{}}, "quantities": ["exp"],
              "rules": [{{"rule": "gauss-legendre"}}, {rule}], "budgets": [4],
              "reference": {{"type": "closed-form"}}}}"#
        );
        let file = dir.join("exp.json");
        std::fs::write(&file, text).expect("file");
        let o = bin().arg("check").arg(&file).output().expect("check runs");
        assert!(!o.status.success(), "{rule}");
        let e = stderr(&o);
        assert!(e.contains(path) && e.contains(says), "{rule}: {e}");
    }
}

#[test]
fn the_program_receives_only_what_the_experiment_states() {
    // Writes each request it gets to requests.jsonl, then answers.
    let (dir, file) = setup(
        "ext-request",
        &answering("open('requests.jsonl', 'a').write(line)"),
        serde_json::json!({}),
    );
    let out = dir.join("out");
    let o = run(&file, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(dir.join("requests.jsonl")).expect("requests");
    let requests: Vec<Json> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("json"))
        .collect();
    assert_eq!(requests.len(), 4);
    for r in &requests {
        let mut keys: Vec<&str> = r
            .as_object()
            .expect("object")
            .keys()
            .map(String::as_str)
            .collect();
        keys.sort_unstable();
        assert_eq!(
            keys,
            [
                "budget",
                "channels",
                "dimension",
                "experiment",
                "family",
                "id",
                "protocol",
                "quantity",
                "repeat",
                "scene",
                "seed",
                "version"
            ]
        );
        assert_eq!(r["protocol"], "lightquad-estimator");
        assert_eq!(r["version"], 1);
        assert_eq!(r["family"], "calibration");
        assert_eq!(r["quantity"], "exp");
        assert_eq!(r["channels"], 1);
        assert_eq!(r["scene"], serde_json::json!({}));
    }
    assert!(
        !text.contains(dir.to_str().expect("utf-8")),
        "a path of the machine was sent"
    );
    // The seeds are the jobs' own, as results.jsonl records them.
    let mut sent: Vec<u64> = requests.iter().filter_map(|r| r["seed"].as_u64()).collect();
    let mut recorded: Vec<u64> = results(&out)
        .iter()
        .filter(|r| r["rule"] == "prog")
        .filter_map(|r| r["seed"].as_u64())
        .collect();
    sent.sort_unstable();
    recorded.sort_unstable();
    assert_eq!(sent, recorded);
}

#[test]
fn kill_9_of_lightquad_leaves_no_program_running() {
    // The program writes its pid, then hangs without reading stdin again.
    let program = format!(
        "{HELLO}import os, sys, time\nopen('pid-%d' % os.getpid(), 'w').close()\nsys.stdin.readline()\ntime.sleep(120)\n"
    );
    let (dir, file) = setup("ext-kill", &program, serde_json::json!({"timeout_s": 100}));
    let mut child = bin()
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(dir.join("out"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("lightquad starts");
    let pids = || -> Vec<u32> {
        std::fs::read_dir(&dir)
            .expect("dir")
            .filter_map(|e| {
                e.ok()?
                    .file_name()
                    .to_str()?
                    .strip_prefix("pid-")?
                    .parse()
                    .ok()
            })
            .collect()
    };
    let start = Instant::now();
    while pids().is_empty() && start.elapsed() < Duration::from_secs(20) {
        std::thread::sleep(Duration::from_millis(50));
    }
    let started = pids();
    assert!(!started.is_empty(), "the program never started");
    std::thread::sleep(Duration::from_millis(300));
    child.kill().expect("kill -9");
    let _ = child.wait();
    let alive = |pid: u32| {
        std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|s| {
            s.rsplit(')')
                .next()
                .is_some_and(|rest| !rest.trim_start().starts_with('Z'))
        })
    };
    let start = Instant::now();
    while pids().iter().any(|&p| alive(p)) && start.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(50));
    }
    let left: Vec<u32> = pids().into_iter().filter(|&p| alive(p)).collect();
    assert!(
        left.is_empty(),
        "programs still running after kill -9: {left:?}"
    );
}

#[test]
fn the_bundled_examples_are_judged_as_planted() {
    let out = scratch("ext-bundled");
    let o = run(
        &root().join("experiments/r-external-estimators.json"),
        &out,
        &[],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: Json = serde_json::from_str(
        &std::fs::read_to_string(out.join("r-external-estimators/summary.json")).expect("summary"),
    )
    .expect("json");
    let rules = &summary["experiments"][0]["quantities"][0]["rules"];
    let verdicts = |label: &str| -> Vec<String> {
        rules
            .as_array()
            .expect("rules")
            .iter()
            .find(|r| r["label"] == label)
            .unwrap_or_else(|| panic!("no rule {label}"))["rows"]
            .as_array()
            .expect("rows")
            .iter()
            .map(|row| {
                row["verdict"]["verdict"]
                    .as_str()
                    .expect("a verdict")
                    .to_string()
            })
            .collect()
    };
    let all = |label: &str, v: &str| verdicts(label).iter().all(|x| x == v);
    assert!(
        all("python-mc", "consistent"),
        "{:?}",
        verdicts("python-mc")
    );
    assert!(
        all("monte-carlo", "consistent"),
        "{:?}",
        verdicts("monte-carlo")
    );
    // The missing cosine biases the estimate by about 9%: called at the
    // largest budgets, where it is far beyond the noise.
    let no_cos = verdicts("python-mc-no-cos");
    assert!(
        no_cos.iter().rev().take(3).all(|v| v == "biased"),
        "{no_cos:?}"
    );
    // Half the standard error: the spread is twice the claim, called at
    // some budget, and the mean never called biased.
    let half = verdicts("python-mc-half-se");
    assert!(half.iter().any(|v| v == "se-too-small"), "{half:?}");
    assert!(!half.iter().any(|v| v == "biased"), "{half:?}");
    // The Rust example, where it was built (cargo test builds examples).
    if root()
        .join("target/release/examples/external_estimator")
        .is_file()
    {
        let rust = verdicts("rust-stratified");
        assert!(
            !rust.iter().any(|v| v == "biased" || v == "se-too-small"),
            "{rust:?}"
        );
    }
}

#[test]
fn a_program_that_stops_reading_a_large_request_still_times_out() {
    // A scene of 3000 lights makes each request far larger than a pipe's
    // buffer; the program says hello and never reads: the write blocks,
    // and the timeout must still fire.
    let dir = scratch("ext-bigreq");
    let program = HELLO.to_string() + "import time\ntime.sleep(60)\n";
    std::fs::write(dir.join("prog.py"), program).expect("program");
    let lights: Vec<Json> = (0..3000)
        .map(|k| {
            let x = -1.0 + 2.0 * f64::from(k) / 3000.0;
            serde_json::json!({"type": "rectangle", "origin": [x, 0.0, 2.0], "edge_u": [0.0004, 0.0, 0.0],
                "edge_v": [0.0, 0.0004, 0.0], "radiance": 1.0})
        })
        .collect();
    let exp = serde_json::json!({
        "name": "ext", "family": "rendering",
        "scene": {"receiver": {"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}, "emitters": lights},
        "quantities": ["E_area"],
        "rules": [{"rule": "external", "name": "prog", "command": ["python3", "prog.py"], "timeout_s": 1}],
        "budgets": [4], "repeats": 2, "reference": {"type": "converged", "n": 2}
    });
    let file = dir.join("exp.json");
    std::fs::write(&file, exp.to_string()).expect("experiment");
    assert!(std::fs::metadata(&file).expect("file").len() > 1 << 18);
    let start = Instant::now();
    let o = run(&file, &dir.join("out"), &[]);
    assert!(
        start.elapsed() < Duration::from_secs(30),
        "{:?}",
        start.elapsed()
    );
    assert!(!o.status.success());
    let text = std::fs::read_to_string(dir.join("out/ext/results.jsonl")).expect("results");
    assert_eq!(
        text.matches("no answer within timeout_s = 1 s").count(),
        2,
        "{text}"
    );
}

#[test]
fn a_timeout_stops_what_the_program_started_too() {
    // `sh -c` forks python (it does not exec it): stopping the shell alone
    // left python running.
    let program = HELLO.to_string()
        + "import os, sys, time\nopen('pid-%d' % os.getpid(), 'w').close()\nsys.stdin.readline()\ntime.sleep(60)\n";
    let (dir, file) = setup(
        "ext-group",
        &program,
        serde_json::json!({"command": ["sh", "-c", "python3 prog.py; true"], "timeout_s": 1}),
    );
    let o = run(&file, &dir.join("out"), &[]);
    assert!(!o.status.success());
    let pids: Vec<u32> = std::fs::read_dir(&dir)
        .expect("dir")
        .filter_map(|e| {
            e.ok()?
                .file_name()
                .to_str()?
                .strip_prefix("pid-")?
                .parse()
                .ok()
        })
        .collect();
    assert!(!pids.is_empty());
    std::thread::sleep(Duration::from_millis(500));
    let alive: Vec<u32> = pids
        .into_iter()
        .filter(|p| {
            std::fs::read_to_string(format!("/proc/{p}/stat")).is_ok_and(|s| {
                s.rsplit(')')
                    .next()
                    .is_some_and(|rest| !rest.trim_start().starts_with('Z'))
            })
        })
        .collect();
    assert!(alive.is_empty(), "still running after the run: {alive:?}");
}

#[test]
fn what_a_program_says_stays_on_one_line_and_false_claims_are_refused() {
    let program = HELLO.to_string()
        + "import json, math, sys\n\
           for line in sys.stdin:\n\
           \x20   req = json.loads(line)\n\
           \x20   if req['budget'] == 4:\n\
           \x20       out = {'id': req['id'], 'error': 'line one\\n# heading\\x1b[31m'}\n\
           \x20   elif req['repeat'] == 0:\n\
           \x20       out = {'id': req['id'], 'value': [math.e - 1], 'evaluations': 0}\n\
           \x20   else:\n\
           \x20       out = {'id': req['id'], 'value': [math.e - 1], 'seconds': 1e300}\n\
           \x20   print(json.dumps(out), flush=True)\n";
    let (dir, file) = setup("ext-text", &program, serde_json::json!({}));
    let out = dir.join("out");
    let o = run(&file, &out, &[]);
    assert!(!o.status.success());
    let failed = failures(&out);
    assert_eq!(failed.len(), 4, "{failed:?}");
    for f in &failed {
        assert!(!f.chars().any(char::is_control), "{f:?}");
    }
    assert!(
        failed
            .iter()
            .any(|f| f.contains("line one # heading\u{fffd}[31m"))
    );
    assert!(failed.iter().any(|f| f.contains("`evaluations` is 0")));
    assert!(
        failed
            .iter()
            .any(|f| f.contains("reported taking 1.000e300 s"))
    );
    let report = std::fs::read_to_string(out.join("ext/report.md")).expect("report");
    assert!(!report.contains("\n# heading") && !report.contains('\u{1b}'));
}

#[test]
fn a_failed_job_is_no_sample_of_its_rows_time() {
    // Repeat 0 fails, repeats 1 and 2 take about 0.05 s each.
    let program = answering(
        "import time\n    time.sleep(0.05)\n    if req['repeat'] == 0:\n        print('x', flush=True); continue",
    );
    let (dir, file) = setup("ext-time", &program, serde_json::json!({}));
    let text = std::fs::read_to_string(&file)
        .expect("file")
        .replace("\"repeats\":2", "\"repeats\":3");
    std::fs::write(&file, text).expect("file");
    let out = dir.join("out");
    let _ = run(&file, &out, &[]);
    let summary: Json = serde_json::from_str(
        &std::fs::read_to_string(out.join("ext/summary.json")).expect("summary"),
    )
    .expect("json");
    let rule = summary["experiments"][0]["quantities"][0]["rules"]
        .as_array()
        .expect("rules")
        .iter()
        .find(|r| r["label"] == "prog")
        .expect("prog")
        .clone();
    for row in rule["rows"].as_array().expect("rows") {
        let t = &row["seconds"];
        assert_eq!(t["samples"], 2, "{row}");
        assert!(t["low"].as_f64().is_some_and(|s| s >= 0.04), "{row}");
    }
}

#[test]
fn a_failed_jobs_time_is_its_request_not_the_programs_start_up() {
    // Each process takes 0.5 s to start and answers garbage at once, so
    // every job of the program starts a fresh one and fails.
    let program = format!(
        "import time\ntime.sleep(0.5)\n{}",
        answering("print('x', flush=True); continue")
    );
    let (dir, file) = setup("ext-start", &program, serde_json::json!({}));
    let out = dir.join("out");
    let _ = run(&file, &out, &[]);
    let failed: Vec<Json> = results(&out)
        .into_iter()
        .filter(|r| r["rule"] == "prog")
        .collect();
    assert_eq!(failed.len(), 4);
    for job in &failed {
        assert!(
            job["failure"]
                .as_str()
                .is_some_and(|f| f.contains("not a response")),
            "{job}"
        );
        let seconds = job["seconds"].as_f64().unwrap_or(f64::NAN);
        assert!(seconds > 0.0 && seconds < 0.25, "{job}");
    }
}

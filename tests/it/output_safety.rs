//! The output folder is written only inside itself (no link in it is
//! followed), a shard leaves the pages it did not write, `merge` refuses
//! shards of different builds, and no message echoes more than an excerpt
//! of a user's value.

use std::fs;
use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::{bin, scratch, stderr};

/// A small calibration experiment named `t`: 2 rules x 2 budgets x 2
/// repeats = 8 jobs, well under a second.
const SMALL: &str = r#"{"name": "t", "family": "calibration", "scene": {}, "quantities": ["exp"],
  "rules": [{"rule": "gauss-legendre"}, {"rule": "monte-carlo"}], "budgets": [4, 16],
  "repeats": 2, "seed": 1, "reference": {"type": "closed-form"}}"#;

/// Jobs of [`SMALL`].
const SMALL_JOBS: usize = 8;

/// A scratch folder holding [`SMALL`] as `e.json`.
fn with_small(tag: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(tag);
    let file = dir.join("e.json");
    fs::write(&file, SMALL).expect("write");
    (dir, file)
}

/// `lightquad run` of `file` into `out`, with `extra` arguments.
fn run(file: &Path, out: &Path, extra: &[&str]) -> Output {
    bin()
        .arg("run")
        .arg(file)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("runs")
}

/// Every file under `dir` (links as links), by path relative to it, with
/// its bytes (a link's target path).
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let path = e.path();
            let kind = e.file_type().expect("type");
            let rel = path.strip_prefix(dir).expect("inside").to_path_buf();
            if kind.is_symlink() {
                let target = fs::read_link(&path).expect("link");
                out.push((rel, target.to_string_lossy().as_bytes().to_vec()));
            } else if kind.is_dir() {
                out.push((rel, Vec::new()));
                stack.push(path);
            } else {
                out.push((rel, fs::read(&path).expect("read")));
            }
        }
    }
    out.sort();
    out
}

/// Where a planted link goes, and where it is planted.
struct Plant {
    /// The link, relative to the output folder.
    link: &'static str,
    /// Its target, relative to the folder outside (`None`: a link to
    /// nothing, whose target must not be created).
    target: &'static str,
    /// Whether the target exists (a file with known bytes, or an empty folder).
    existing: Option<bool>,
}

/// Each link a run could write through (an experiment folder, the lock, a
/// shard's lock, the results, a report page, a plot, the index) is refused
/// with its path and the words "is a link", and the folder it points into
/// is left exactly as it was: nothing created, written or removed there.
/// Before, the experiment folder and the report were written through a link
/// to a folder elsewhere, and a link to nothing at the lock had its target
/// created.
#[test]
fn links_planted_in_the_output_folder_are_refused_and_their_targets_untouched() {
    let plants = [
        // (link, target, Some(true): a folder there, Some(false): a file there, None: nothing)
        Plant {
            link: "t",
            target: "folder",
            existing: Some(true),
        },
        Plant {
            link: ".lightquad.lock",
            target: "lock",
            existing: None,
        },
        Plant {
            link: "t/results.jsonl",
            target: "results.jsonl",
            existing: Some(false),
        },
        Plant {
            link: "t/report.md",
            target: "report.md",
            existing: Some(false),
        },
        Plant {
            link: "t/t-exp-n.svg",
            target: "plot.svg",
            existing: Some(false),
        },
        Plant {
            link: "index.html",
            target: "index.html",
            existing: Some(false),
        },
        Plant {
            link: "t/experiment.json",
            target: "nothing.json",
            existing: None,
        },
    ];
    for (k, plant) in plants.iter().enumerate() {
        let (dir, file) = with_small(&format!("links-{k}"));
        let (out, elsewhere) = (dir.join("out"), dir.join("elsewhere"));
        fs::create_dir_all(&elsewhere).expect("mkdir");
        let target = elsewhere.join(plant.target);
        match plant.existing {
            Some(true) => fs::create_dir_all(&target).expect("mkdir"),
            Some(false) => fs::write(&target, "not lightquad's").expect("write"),
            None => {}
        }
        let link = out.join(plant.link);
        fs::create_dir_all(link.parent().expect("parent")).expect("mkdir");
        symlink(&target, &link).expect("symlink");
        let before = snapshot(&elsewhere);
        let o = run(&file, &out, &[]);
        let msg = stderr(&o);
        assert!(
            !o.status.success(),
            "{}: ran through the link: {msg}",
            plant.link
        );
        assert!(
            msg.contains(&link.display().to_string())
                && msg.contains("is a link")
                && msg.contains("does not follow links in its output folder"),
            "{}: {msg}",
            plant.link
        );
        assert_eq!(
            snapshot(&elsewhere),
            before,
            "{}: written through",
            plant.link
        );
        assert!(
            fs::symlink_metadata(&link).is_ok(),
            "{}: link removed",
            plant.link
        );
        let _ = fs::remove_dir_all(&dir);
    }
}

/// A shard's lock and a merge's experiment folder are refused as links too,
/// and `--out` itself may be a link (the user's choice of where the report
/// goes): the report is written where it points.
#[test]
fn shard_and_merge_refuse_links_and_out_itself_may_be_a_link() {
    let (dir, file) = with_small("links-shard");
    let elsewhere = dir.join("elsewhere");
    fs::create_dir_all(elsewhere.join("folder")).expect("mkdir");
    // A shard's own lock, a link to nothing.
    let out = dir.join("out");
    fs::create_dir_all(&out).expect("mkdir");
    let link = out.join(".lightquad.shard-1-of-2.lock");
    symlink(elsewhere.join("shard-lock"), &link).expect("symlink");
    let o = run(&file, &out, &["--shard", "1/2"]);
    assert!(
        !o.status.success() && stderr(&o).contains("is a link"),
        "{}",
        stderr(&o)
    );
    assert!(
        !elsewhere.join("shard-lock").exists(),
        "the link's target was created"
    );
    // Both shards into a clean folder, merged into one whose experiment
    // folder is a link.
    let shards = dir.join("shards");
    for k in ["1/2", "2/2"] {
        let o = run(&file, &shards, &["--shard", k]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let merged = dir.join("merged");
    fs::create_dir_all(&merged).expect("mkdir");
    symlink(elsewhere.join("folder"), merged.join("t")).expect("symlink");
    let before = snapshot(&elsewhere);
    let o = bin()
        .args(["merge", "--out"])
        .arg(&merged)
        .arg(&shards)
        .output()
        .expect("runs");
    assert!(
        !o.status.success() && stderr(&o).contains("is a link"),
        "{}",
        stderr(&o)
    );
    assert_eq!(snapshot(&elsewhere), before, "merge wrote through the link");
    // --out a link to a folder: followed, by choice.
    let chosen = dir.join("chosen");
    symlink(elsewhere.join("folder"), &chosen).expect("symlink");
    let o = run(&file, &chosen, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let lines = fs::read_to_string(elsewhere.join("folder/t/results.jsonl")).expect("results");
    assert_eq!(lines.lines().count(), SMALL_JOBS);
    let _ = fs::remove_dir_all(&dir);
}

/// A temporary file's name taken by a link (planted for every name the
/// next writes could pick) fails the write: nothing is written through it
/// and no link is renamed into the file's place.
#[test]
fn an_atomic_write_never_writes_through_a_link_at_its_temporary_name() {
    use lightquad::experiment::run::write_atomic;
    let dir = scratch("links-temporary");
    let elsewhere = dir.join("elsewhere");
    fs::create_dir_all(&elsewhere).expect("mkdir");
    let out = dir.join("out");
    fs::create_dir_all(&out).expect("mkdir");
    // `.<name>.<pid>.<n>.tmp` for the first 2048 writes of this process.
    let pid = std::process::id();
    for n in 0..2048 {
        let target = elsewhere.join(format!("{n}"));
        symlink(&target, out.join(format!(".file.{pid}.{n}.tmp"))).expect("symlink");
    }
    let e = write_atomic(&out.join("file"), b"text").expect_err("wrote through a link");
    assert!(e.to_string().contains("is a link"), "{e}");
    assert_eq!(fs::read_dir(&elsewhere).expect("list").count(), 0);
    assert!(
        fs::symlink_metadata(out.join("file")).is_err(),
        "a link renamed into place"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// A shard run into a folder that holds a whole run's report writes its own
/// results file and leaves every page of that report as it was (it removed
/// the index and the experiment's pages).
#[test]
fn a_shard_run_leaves_a_whole_runs_report_alone() {
    let (dir, file) = with_small("shard-pages");
    let out = dir.join("out");
    let o = run(&file, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = snapshot(&out);
    for page in [
        "index.md",
        "index.html",
        "t/report.md",
        "t/index.html",
        "t/results.csv",
    ] {
        assert!(
            before.iter().any(|(p, _)| p == Path::new(page)),
            "{page} not written by the whole run"
        );
    }
    let o = run(&file, &out, &["--shard", "2/4"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let after = snapshot(&out);
    for (path, bytes) in &before {
        let kept = after.iter().find(|(p, _)| p == path);
        assert_eq!(
            kept.map(|(_, b)| b),
            Some(bytes),
            "{} changed",
            path.display()
        );
    }
    // Its own results: jobs 2 and 6 of the 8 (every 4th from the 2nd).
    let shard = fs::read_to_string(out.join("t/results.shard-2-of-4.jsonl")).expect("shard");
    assert_eq!(shard.lines().count(), SMALL_JOBS / 4);
    let _ = fs::remove_dir_all(&dir);
}

/// The commit a results line names (`unknown` where it names none).
fn commit_of(line: &str) -> String {
    let v: serde_json::Value = serde_json::from_str(line).expect("a results line");
    v["git_commit"].as_str().unwrap_or("unknown").to_string()
}

/// Shards computed by two builds (git commits) of one version are refused
/// by `merge`, naming both commits and the shards' files; with
/// `--allow-mixed-commits` the report names both, each with its count of
/// jobs (it named the first line's commit alone).
#[test]
fn merge_refuses_shards_of_two_builds_unless_allowed_and_then_names_both() {
    let (dir, file) = with_small("commits");
    let (one, two) = (dir.join("one"), dir.join("two"));
    for (out, k) in [(&one, "1/2"), (&two, "2/2")] {
        let o = run(&file, out, &["--shard", k]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let first = one.join("t/results.shard-1-of-2.jsonl");
    let ours = commit_of(
        fs::read_to_string(&first)
            .expect("shard")
            .lines()
            .next()
            .expect("a line"),
    );
    // The second shard as another build wrote it.
    let second = two.join("t/results.shard-2-of-2.jsonl");
    let other = "feedfacecafe";
    let edited: String = fs::read_to_string(&second)
        .expect("shard")
        .lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).expect("line");
            v["git_commit"] = other.into();
            format!("{v}\n")
        })
        .collect();
    fs::write(&second, edited).expect("write");
    let merge = |extra: &[&str]| {
        bin()
            .args(["merge", "--out"])
            .arg(dir.join("merged"))
            .arg(&one)
            .arg(&two)
            .args(extra)
            .output()
            .expect("runs")
    };
    let o = merge(&[]);
    let msg = stderr(&o);
    assert!(!o.status.success(), "{msg}");
    for said in [
        format!("commit {ours} (in {})", first.display()),
        format!("commit {other} (in {})", second.display()),
        "--allow-mixed-commits".to_string(),
    ] {
        assert!(msg.contains(&said), "no {said:?} in: {msg}");
    }
    assert!(
        !dir.join("merged").exists(),
        "a refused merge wrote its folder"
    );
    let o = merge(&["--allow-mixed-commits"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(dir.join("merged/t/report.md")).expect("report");
    // 8 jobs dealt to 2 shards: 4 each.
    for said in [
        format!("commit {ours} ({} jobs)", SMALL_JOBS / 2),
        format!("commit {other} ({} jobs)", SMALL_JOBS / 2),
    ] {
        assert!(report.contains(&said), "no {said:?} in the report");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// `check` of a file that is a JSON array or string, or whose values are
/// long strings, quotes at most an excerpt of them (the whole file was
/// echoed: 100 KB on stderr, a file of secrets verbatim).
#[test]
fn errors_quote_an_excerpt_of_a_users_value_never_the_whole() {
    let dir = scratch("excerpts");
    let secret = "SECRET-".repeat(15_000);
    let object = |field: &str, value: serde_json::Value| {
        let mut v: serde_json::Value = serde_json::from_str(SMALL).expect("json");
        v[field] = value;
        v.to_string()
    };
    let numbers: Vec<u32> = (0..20_000).collect();
    let cases = [
        (
            "string",
            serde_json::Value::from(secret.as_str()).to_string(),
        ),
        ("array", serde_json::json!([secret]).to_string()),
        ("numbers", serde_json::json!(numbers).to_string()),
        ("family", object("family", secret.as_str().into())),
        ("budgets", object("budgets", serde_json::json!([secret]))),
        ("name", object("name", secret.as_str().into())),
        ("key", object(&secret, 1.into())),
    ];
    for (what, text) in cases {
        let file = dir.join(format!("{what}.json"));
        fs::write(&file, &text).expect("write");
        let o = bin().arg("check").arg(&file).output().expect("runs");
        let msg = stderr(&o);
        assert!(!o.status.success(), "{what}: accepted");
        // An excerpt is 60 characters: 61 of the secret's never appear.
        assert!(
            !msg.contains(&secret[..61]),
            "{what}: {}",
            &msg[..msg.len().min(300)]
        );
        assert!(
            !msg.contains("0,1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23"),
            "{what}"
        );
        assert!(
            msg.len() < 1000,
            "{what}: {} bytes: {}",
            msg.len(),
            &msg[..300]
        );
        assert!(msg.contains('…'), "{what}: not said to be cut: {msg}");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// The stale-values message says the hash a values file was made from only
/// where the file is a values file of the form lightquad writes (a 16-digit
/// hexadecimal hash); any other JSON file named as one is said not to be a
/// values file, its string unsaid (a file of secrets with an
/// `experiment_hash` key had it printed).
#[test]
fn a_stale_hash_is_said_only_from_a_values_file() {
    let dir = scratch("stale-hash");
    let mut v: serde_json::Value = serde_json::from_str(SMALL).expect("json");
    v["reference"] = serde_json::json!({"type": "mitsuba", "file": "values.json"});
    let file = dir.join("e.json");
    fs::write(&file, v.to_string()).expect("write");
    let values = dir.join("values.json");
    let check = |hash: &str| {
        let text = serde_json::json!({"experiment_hash": hash, "quantities": {}});
        fs::write(&values, text.to_string()).expect("write");
        let o = bin().arg("check").arg(&file).output().expect("runs");
        assert!(!o.status.success());
        stderr(&o)
    };
    let msg = check("password=hunter2");
    assert!(
        !msg.contains("hunter2") && msg.contains("not a Mitsuba values file"),
        "{msg}"
    );
    let msg = check("0123456789abcdef");
    assert!(
        msg.contains("stale") && msg.contains("\"0123456789abcdef\""),
        "{msg}"
    );
    let _ = fs::remove_dir_all(&dir);
}

/// A FIFO planted as a lock file (the run's, a shard's) is refused as not a
/// regular file: opening it for writing blocked the run forever. The run
/// is killed after 20 s if it blocks, and that fails the test.
#[test]
fn a_fifo_as_a_lock_file_is_refused_not_waited_on() {
    for (lock, extra) in [
        (".lightquad.lock", &[][..]),
        (".lightquad.shard-2-of-8.lock", &["--shard", "2/8"][..]),
    ] {
        let (dir, file) = with_small("fifo-lock");
        let out = dir.join("out");
        fs::create_dir_all(&out).expect("out");
        let fifo = out.join(lock);
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo");
        assert!(made.success());
        let mut child = bin()
            .arg("run")
            .arg(&file)
            .arg("--out")
            .arg(&out)
            .args(extra)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("runs");
        let start = std::time::Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().expect("waits") {
                break Some(s);
            }
            if start.elapsed() > std::time::Duration::from_secs(20) {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
            std::thread::sleep(std::time::Duration::from_millis(50));
        };
        let status = status.unwrap_or_else(|| panic!("{lock}: the run blocked on the FIFO"));
        let mut err = String::new();
        use std::io::Read as _;
        let _ = child
            .stderr
            .take()
            .expect("stderr")
            .read_to_string(&mut err);
        assert_eq!(status.code(), Some(1), "{lock}: {err}");
        assert!(err.contains("is a FIFO"), "{lock}: {err}");
    }
}

//! What `render` and `run` leave on disk when something goes wrong (the
//! hostile probe of session 27): an output path that is the input file, a
//! PNG that cannot be written beside a PFM that can, a run killed before its
//! report, and a rerun with fewer rules.

use std::fs;
use std::io::{BufRead, BufReader};
use std::process::Stdio;

use crate::common;
use common::{bin, root, scratch, stderr};

/// `render` refuses to write its PNG or PFM over the experiment file it
/// renders, by the same path, another spelling of it, or a link to it;
/// the file is left as it was.
#[test]
fn render_never_writes_over_its_input() {
    let dir = scratch("render-input");
    let input = dir.join("in.json");
    let text = fs::read(root().join("experiments/w-6-1-phong-pixel.json")).expect("read");
    fs::write(&input, &text).expect("write");
    let link = dir.join("link.png");
    #[cfg(unix)]
    std::os::unix::fs::symlink(&input, &link).expect("link");
    let spelled = dir.join(".").join("in.json");
    let mut cases = vec![
        vec!["--png".into(), input.clone()],
        vec![
            "--png".into(),
            dir.join("a.png"),
            "--pfm".into(),
            input.clone(),
        ],
        vec!["--png".into(), spelled],
    ];
    if cfg!(unix) {
        cases.push(vec!["--png".into(), link.clone()]);
    }
    for args in cases {
        let o = bin()
            .arg("render")
            .arg(&input)
            .args(&args)
            .output()
            .expect("runs");
        assert!(!o.status.success(), "accepted: {args:?}");
        assert!(
            stderr(&o).contains("it is the experiment file being rendered"),
            "{}",
            stderr(&o)
        );
        assert_eq!(fs::read(&input).expect("read"), text, "{args:?}");
        assert!(!dir.join("a.png").exists());
    }
    let _ = fs::remove_dir_all(&dir);
}

/// A PNG whose name the folder refuses (too long) after a PFM that could be
/// written: neither file is left, nor a temporary one.
#[test]
fn render_writes_both_files_or_neither() {
    let dir = scratch("render-both");
    let input = root().join("experiments/w-6-1-phong-pixel.json");
    let long = dir.join(format!("{}.png", "x".repeat(300)));
    let pfm = dir.join("p.pfm");
    let o = bin()
        .arg("render")
        .arg(&input)
        .arg("--png")
        .arg(&long)
        .arg("--pfm")
        .arg(&pfm)
        .output()
        .expect("runs");
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("cannot write the PNG") && stderr(&o).contains("no file was written"),
        "{}",
        stderr(&o)
    );
    let left: Vec<_> = fs::read_dir(&dir).expect("dir").flatten().collect();
    assert!(left.is_empty(), "{left:?}");
    // The same with good names writes both.
    let png = dir.join("p.png");
    let o = bin()
        .arg("render")
        .arg(&input)
        .arg("--png")
        .arg(&png)
        .arg("--pfm")
        .arg(&pfm)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(png.is_file() && pfm.is_file());
    let left = fs::read_dir(&dir).expect("dir").count();
    assert_eq!(left, 2);
    let _ = fs::remove_dir_all(&dir);
}

/// A run into a folder that holds an earlier run's report removes that
/// report before its jobs: killed while it computes its converged reference
/// (after the jobs), it leaves no index and no page, not the earlier ones
/// looking complete beside its new results. A finished rerun with fewer
/// rules leaves no image of the rules it dropped.
#[test]
fn a_rerun_replaces_the_earlier_report_or_leaves_none() {
    let dir = scratch("rerun");
    let out = dir.join("out");
    let file = dir.join("w.json");
    let mut spec: serde_json::Value = serde_json::from_str(
        &fs::read_to_string(root().join("experiments/w-grey-test-scene.json")).expect("read"),
    )
    .expect("json");
    spec["budgets"] = serde_json::json!([1, 4]);
    spec["repeats"] = serde_json::json!(1);
    spec["rules"] = serde_json::json!([{"rule": "centre"}, {"rule": "grid"}]);
    spec["reference"]["n"] = serde_json::json!(50);
    fs::write(&file, spec.to_string()).expect("write");
    let run = |file: &std::path::Path| {
        bin()
            .args(["run", "--threads", "2", "--out"])
            .arg(&out)
            .arg(file)
            .output()
            .expect("runs")
    };
    let o = run(&file);
    assert!(o.status.success(), "{}", stderr(&o));
    let page = out.join("w-grey-test-scene");
    let grid_png = page.join("w-grey-test-scene-image-1-grid-n4.png");
    assert!(out.join("index.md").is_file() && page.join("report.md").is_file());
    assert!(grid_png.is_file());

    // A rerun killed once it says it computes the reference (a large n
    // makes that take long enough).
    spec["reference"]["n"] = serde_json::json!(20000);
    fs::write(&file, spec.to_string()).expect("write");
    let mut child = bin()
        .args(["run", "--threads", "2", "--out"])
        .arg(&out)
        .arg(&file)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .expect("spawns");
    let err = child.stderr.take().expect("stderr");
    let mut said = String::new();
    for line in BufReader::new(err).lines() {
        let line = line.expect("a line");
        said.push_str(&line);
        said.push('\n');
        if line.contains("computing the converged reference") {
            break;
        }
    }
    child.kill().expect("kill");
    let _ = child.wait();
    assert!(said.contains("computing the converged reference"), "{said}");
    for gone in [
        out.join("index.md"),
        out.join("index.html"),
        page.join("report.md"),
        page.join("index.html"),
        grid_png.clone(),
    ] {
        assert!(!gone.exists(), "{} is left: {said}", gone.display());
    }
    assert!(page.join("results.jsonl").is_file());

    // A finished rerun with only the centre rule: no grid image is left.
    spec["reference"]["n"] = serde_json::json!(50);
    spec["rules"] = serde_json::json!([{"rule": "centre"}]);
    fs::write(&file, spec.to_string()).expect("write");
    let o = run(&file);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(page.join("report.md").is_file());
    assert!(!grid_png.exists());
    assert!(
        page.join("w-grey-test-scene-image-0-centre-n4.png")
            .is_file()
    );
    let _ = fs::remove_dir_all(&dir);
}

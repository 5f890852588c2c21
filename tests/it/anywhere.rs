//! Mitsuba values are found relative to the experiment file, never the
//! working folder, and the comparison never silently disappears: a values
//! file beside the experiment is used, a copy of a bundled experiment finds
//! the bundled values, an edited copy is reported stale, and a `mitsuba`
//! reference names a file relative to its experiment. (The bundled suite run
//! from a folder without experiments/ is in runner.rs.)

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin(cwd: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lightquad"));
    c.current_dir(cwd);
    c
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lightquad-anywhere-{}-{tag}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(dir.join("elsewhere")).expect("scratch folder");
    dir
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

const NAME: &str = "mitsuba-tau-constant-sphere";

/// Runs `file` from `cwd` into `cwd/out` and returns the index's Mitsuba row
/// of `tau`.
fn tau_row(cwd: &Path, file: &Path) -> String {
    let o = bin(cwd)
        .args(["run", "--out", "out"])
        .arg(file)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", text(&o));
    let index = fs::read_to_string(cwd.join("out/index.md")).expect("index");
    assert!(index.contains("## lightquad vs Mitsuba 3 vs closed form"));
    let row = format!("| {NAME} | tau | ");
    index
        .lines()
        .find(|l| l.starts_with(&row))
        .unwrap_or_else(|| panic!("no Mitsuba row in {index}"))
        .to_string()
}

#[test]
fn values_are_found_beside_the_experiment_then_among_the_bundled_ones() {
    let dir = scratch("beside");
    let spec = fs::read(root().join(format!("experiments/{NAME}.json"))).expect("read");
    let values: serde_json::Value = serde_json::from_str(
        &fs::read_to_string(root().join(format!("reference/values/{NAME}.json"))).expect("read"),
    )
    .expect("json");
    let committed = values["quantities"]["tau"]["value"]
        .as_f64()
        .expect("value");

    // A project laid out as the repository, with a planted value: that file
    // is used, from a working folder that is neither.
    fs::create_dir_all(dir.join("proj/experiments")).expect("mkdir");
    fs::create_dir_all(dir.join("proj/reference/values")).expect("mkdir");
    fs::write(dir.join(format!("proj/experiments/{NAME}.json")), &spec).expect("write");
    let mut planted = values.clone();
    planted["quantities"]["tau"]["value"] = 0.125.into();
    fs::write(
        dir.join(format!("proj/reference/values/{NAME}.json")),
        planted.to_string(),
    )
    .expect("write");
    let file = dir.join(format!("proj/experiments/{NAME}.json"));
    let row = tau_row(&dir.join("elsewhere"), &file);
    assert!(row.contains("| 1.2500000000e-1 +- "), "{row}");

    // The same bytes alone in a folder: the bundled values, made from them.
    fs::create_dir_all(dir.join("lone")).expect("mkdir");
    fs::write(dir.join(format!("lone/{NAME}.json")), &spec).expect("write");
    let row = tau_row(
        &dir.join("elsewhere"),
        &dir.join(format!("lone/{NAME}.json")),
    );
    assert!(row.contains(&format!("| {committed:.10e} +- ")), "{row}");

    // An edited copy: the bundled values are for other bytes, and the row says
    // so instead of vanishing.
    let edited = String::from_utf8(spec)
        .expect("utf-8")
        .replace("\"repeats\": 3", "\"repeats\": 2");
    fs::create_dir_all(dir.join("edited")).expect("mkdir");
    fs::write(dir.join(format!("edited/{NAME}.json")), edited).expect("write");
    let row = tau_row(
        &dir.join("elsewhere"),
        &dir.join(format!("edited/{NAME}.json")),
    );
    assert!(row.contains("stale") && !row.contains(" +- "), "{row}");

    // A renamed copy: no values are found by its name, and the row names the
    // bundled experiment whose scene it has (the section was dropped).
    let renamed = String::from_utf8(fs::read(&file).expect("read"))
        .expect("utf-8")
        .replace(&format!("\"name\": \"{NAME}\""), "\"name\": \"my-tau\"");
    fs::create_dir_all(dir.join("renamed")).expect("mkdir");
    fs::write(dir.join("renamed/my-tau.json"), renamed).expect("write");
    let o = bin(&dir.join("elsewhere"))
        .args(["run", "--out", "out-renamed"])
        .arg(dir.join("renamed/my-tau.json"))
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", text(&o));
    let index = fs::read_to_string(dir.join("elsewhere/out-renamed/index.md")).expect("index");
    let row = index
        .lines()
        .find(|l| l.starts_with("| my-tau | tau | "))
        .unwrap_or_else(|| panic!("no Mitsuba row in {index}"));
    assert!(
        row.contains(&format!("scene is that of the bundled `{NAME}`")) && !row.contains(" +- "),
        "{row}"
    );

    // Renamed and edited (another kappa): no bundled scene matches, but its
    // description speaks of Mitsuba, and the row says the values are missing.
    let edited = fs::read_to_string(dir.join("renamed/my-tau.json"))
        .expect("read")
        .replace("\"my-tau\"", "\"my-tau2\"");
    let mut json: serde_json::Value = serde_json::from_str(&edited).expect("json");
    json["scene"]["medium"]["kappa"] = 0.9.into();
    fs::write(dir.join("renamed/my-tau2.json"), json.to_string()).expect("write");
    let o = bin(&dir.join("elsewhere"))
        .args(["run", "--out", "out-edited"])
        .arg(dir.join("renamed/my-tau2.json"))
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", text(&o));
    let index = fs::read_to_string(dir.join("elsewhere/out-edited/index.md")).expect("index");
    let row = index
        .lines()
        .find(|l| l.starts_with("| my-tau2 | tau | "))
        .unwrap_or_else(|| panic!("no Mitsuba row in {index}"));
    assert!(row.contains("no Mitsuba values for `my-tau2`"), "{row}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_mitsuba_reference_names_a_file_relative_to_its_experiment() {
    let dir = scratch("named");
    fs::create_dir_all(dir.join("p/vals")).expect("mkdir");
    let spec = r#"{
  "name": "own-mitsuba",
  "family": "volume",
  "scene": {
    "ray": { "origin": [-3.0, 0.0, 0.0], "direction": [1.0, 0.0, 0.0] },
    "medium": { "type": "constant-sphere", "centre": [0.0, 0.0, 0.0], "radius": 1.0, "kappa": 0.5 }
  },
  "quantities": ["tau"],
  "rules": [ { "rule": "gauss-legendre" } ],
  "budgets": [4, 8],
  "repeats": 1,
  "seed": 1,
  "reference": { "type": "mitsuba", "file": "vals/own.json" }
}"#;
    let file = dir.join("p/own.json");
    fs::write(&file, spec).expect("write");
    // tau = exp(-0.5 * 2) through the unit sphere's diameter.
    let tau = (-1.0f64).exp();
    let values = serde_json::json!({
        "experiment": "own-mitsuba",
        "experiment_hash": lightquad::experiment::run::file_hash(spec.as_bytes()),
        "quantities": { "tau": { "value": tau, "std_error": 1e-7 } }
    });
    // Missing: refused at check, naming the path and where it looked.
    let o = bin(&dir.join("elsewhere"))
        .arg("check")
        .arg(&file)
        .output()
        .expect("runs");
    assert!(!o.status.success());
    let err = text(&o);
    assert!(
        err.contains("reference.file") && err.contains("vals/own.json"),
        "{err}"
    );
    fs::write(dir.join("p/vals/own.json"), values.to_string()).expect("write");
    let o = bin(&dir.join("elsewhere"))
        .arg("check")
        .arg(&file)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", text(&o));
    let o = bin(&dir.join("elsewhere"))
        .args(["run", "--out", "out"])
        .arg(&file)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", text(&o));
    let index = fs::read_to_string(dir.join("elsewhere/out/index.md")).expect("index");
    let row = index
        .lines()
        .find(|l| l.starts_with("| own-mitsuba | tau | "))
        .unwrap_or_else(|| panic!("no Mitsuba row in {index}"));
    assert!(row.contains(&format!("| {tau:.10e} +- 1.0e-7")), "{row}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn run_help_says_where_the_report_goes() {
    let o = bin(root()).args(["run", "--help"]).output().expect("runs");
    let help = text(&o);
    for what in ["./report", "index.md", "index.html", "bundled suite"] {
        assert!(help.contains(what), "{what} not in {help}");
    }
}

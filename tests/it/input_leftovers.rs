//! The input checks and the `render` flags, on the real binary: every
//! refusal names the JSON path (or the flag), the value in a short form and
//! what is accepted.

use serde_json::{Value, json};
use std::fs;

use crate::common;
use common::{bin, root, scratch, stderr};

/// A bundled experiment with `edit` applied, checked by the binary.
fn check_edited(file: &str, edit: impl FnOnce(&mut Value)) -> std::process::Output {
    let mut v: Value = serde_json::from_str(
        &fs::read_to_string(root().join("experiments").join(file)).expect("read"),
    )
    .expect("json");
    v["name"] = json!("edited");
    edit(&mut v);
    check_text(&v.to_string())
}

fn check_text(text: &str) -> std::process::Output {
    let dir = scratch("leftovers");
    let f = dir.join("e.json");
    fs::write(&f, text).expect("write");
    let o = bin().arg("check").arg(&f).output().expect("runs");
    let _ = fs::remove_dir_all(&dir);
    o
}

/// Refused, at `path`, with every piece of `what` in the message, and no
/// number written out in more than 24 digits.
fn refused(o: &std::process::Output, path: &str, what: &[&str]) {
    let msg = stderr(o);
    assert!(!o.status.success(), "accepted; stderr: {msg}");
    assert!(
        msg.contains(&format!("at `{path}`")),
        "no `{path}` in: {msg}"
    );
    for w in what {
        assert!(msg.contains(w), "no {w:?} in: {msg}");
    }
    let longest = msg
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(longest <= 24, "a number of {longest} digits in: {msg}");
    assert!(!msg.contains("panicked"), "{msg}");
}

/// A voxel grid's min of -1e308 was echoed as its 309 digits in the max's
/// message; t_min = 1e300 as 301 digits in t_max's.
#[test]
fn huge_numbers_are_echoed_in_a_short_form() {
    let o = check_edited("v-i-total-voxel-grid.json", |v| {
        v["scene"]["medium"]["min"] = json!([-1e308, -1.0, -1.0]);
        v["scene"]["medium"]["max"] = json!([1e308, 1.0, 1.0]);
    });
    refused(
        &o,
        "scene.medium.max[0]",
        &["max[0] = 1e308", "min[0] = -1e308", "finite box width"],
    );
    let o = check_edited("v-e-constant-sphere.json", |v| {
        v["scene"]["t_min"] = json!(1e300);
        v["scene"]["t_max"] = json!(1.0);
    });
    refused(&o, "scene.t_max", &["t_min = 1e300"]);
    // The library's helper, as every message goes through it.
    use lightquad::error::short_numbers;
    let long = format!("{} and {} and 12.5, hash 3c979872b2e1078a", -1e308, 1e-300);
    assert_eq!(
        short_numbers(&long),
        "-1e308 and 1e-300 and 12.5, hash 3c979872b2e1078a"
    );
}

/// Sphere centres, ray origins, light intensities and emission near 1e308
/// passed `check` and then read as a miss (every term 0, no fault) or
/// failed every job: the products used are checked, at the field's path.
#[test]
fn products_that_overflow_at_run_are_refused_at_check() {
    // |o - c| overflows: the sphere the ray crosses was read as a miss.
    let o = check_edited("v-e-constant-sphere.json", |v| {
        v["scene"]["ray"]["origin"] = json!([-1e308, 0.3, 0.0]);
        v["scene"]["medium"]["centre"] = json!([1e308, 0.0, 0.0]);
    });
    refused(
        &o,
        "scene.medium.centre",
        &[
            "[1e308, 0.0, 0.0]",
            "[-1e308, 0.3, 0.0]",
            "within 1e154 of scene.ray.origin",
        ],
    );
    // Its square overflows: 1.1e155 apart.
    let o = check_edited("v-e-constant-sphere.json", |v| {
        v["scene"]["ray"]["origin"] = json!([-1e155, 0.3, 0.0]);
        v["scene"]["medium"]["centre"] = json!([1e154, 0.0, 0.0]);
    });
    refused(&o, "scene.medium.centre", &["1.10e155", "1e154"]);
    // 1e153 apart is accepted, and the chord found (a closed form > 0).
    let o = check_edited("v-e-constant-sphere.json", |v| {
        v["scene"]["ray"]["origin"] = json!([-1e153, 0.3, 0.0]);
    });
    assert!(o.status.success(), "{}", stderr(&o));
    // I_p times the scattering coefficient overflows I_L's integrand.
    let o = check_edited("v-l-single-scattering.json", |v| {
        v["scene"]["light"]["intensity"] = json!(1.7e308);
        v["scene"]["medium"]["kappa"] = json!(1e10);
    });
    refused(
        &o,
        "scene.light.intensity",
        &[
            "1.7e308",
            "I_L's integrand",
            "expected an intensity at most 2.8e299",
        ],
    );
    // The bound, f64::MAX 4 pi / (albedo 0.8 kappa 1e10) = 2.82e299, is
    // accepted.
    let o = check_edited("v-l-single-scattering.json", |v| {
        v["scene"]["light"]["intensity"] = json!(2.8e299);
        v["scene"]["medium"]["kappa"] = json!(1e10);
    });
    assert!(o.status.success(), "{}", stderr(&o));
    // Each term finite, their sum I beyond f64 (every job failed at run).
    let o = check_edited("v-i-total-voxel-grid.json", |v| {
        v["scene"]["emission"] = json!({"type": "constant", "c": 1e308});
        v["scene"]["background"] = json!(1.7e308);
    });
    refused(
        &o,
        "quantities[0]",
        &[
            "I = I_E + I_B + I_L can reach",
            "scene.background",
            "scene.emission",
            "below 1.8e308",
        ],
    );
    // The terms alone stay computable.
    let o = check_edited("v-i-total-voxel-grid.json", |v| {
        v["scene"]["background"] = json!(1.7e308);
        v["scene"]["lambda"] = json!(0.0);
        v["quantities"] = json!(["I_B", "tau"]);
    });
    assert!(o.status.success(), "{}", stderr(&o));
    // The Whitted and rendering families name the coordinate itself.
    let o = check_edited("w-6-1-phong-pixel.json", |v| {
        v["scene"]["camera"]["eye"][1] = json!(1e308);
    });
    refused(&o, "scene.camera.eye[1]", &["1e308 is beyond 1e100"]);
    let o = check_edited("w-6-1-phong-pixel.json", |v| {
        v["scene"]["objects"][0]["centre"][2] = json!(-1e200);
    });
    refused(
        &o,
        "scene.objects[0].centre[2]",
        &["-1e200 is beyond 1e100"],
    );
    let o = check_edited("w-6-1-phong-pixel.json", |v| {
        v["scene"]["lights"][0]["intensity"][0] = json!(1e308);
    });
    refused(&o, "scene.lights[0].intensity[0]", &["1e308", "1e100"]);
    let o = check_edited("r-sphere-below-horizon.json", |v| {
        v["scene"]["emitters"][0]["centre"][0] = json!(1e308);
    });
    refused(
        &o,
        "scene.emitters[0].centre[0]",
        &["1e308 is beyond 1e100"],
    );
    let o = check_edited("r-sphere-below-horizon.json", |v| {
        v["scene"]["receiver"]["point"][2] = json!(-1e300);
    });
    refused(&o, "scene.receiver.point[2]", &["-1e300 is beyond 1e100"]);
}

/// Irradiance and radiance are never negative: a literal reference of -1
/// for E_area was accepted.
#[test]
fn negative_literal_references_of_nonnegative_quantities_are_refused() {
    let o = check_edited("r-sphere-below-horizon.json", |v| {
        v["quantities"] = json!(["E_area", "E_cone"]);
        v["reference"] = json!({"type": "value", "values": {"E_area": -1.0, "E_cone": 0.03}});
    });
    refused(
        &o,
        "reference.values.E_area",
        &["-1 is not a value E_area can take", "a number >= 0"],
    );
    let o = check_edited("r-sphere-below-horizon.json", |v| {
        v["quantities"] = json!(["E_area"]);
        v["reference"] = json!({"type": "value", "values": {"E_area": 0.0296}});
    });
    assert!(o.status.success(), "{}", stderr(&o));
}

/// `"description": 1e400` said "expected a finite number".
#[test]
fn a_number_beyond_f64_as_the_description_asks_for_a_string() {
    let text =
        fs::read_to_string(root().join("experiments/v-e-constant-sphere.json")).expect("read");
    let start = text.find("\"description\": \"").expect("a description");
    let end = start + text[start + 16..].find('"').expect("closing quote") + 17;
    let o = check_text(&format!(
        "{}\"description\": 1e400{}",
        &text[..start],
        &text[end..]
    ));
    refused(&o, "description", &["1e400", "line 4", "expected a string"]);
}

/// `lightquad render`'s own faults.
#[test]
fn render_flags_and_files_are_checked_and_named() {
    let dir = scratch("render-flags");
    let png = dir.join("r.png");
    let render = |args: &[&str]| {
        bin()
            .arg("render")
            .args(["--width", "4", "--height", "3"])
            .args(args)
            .output()
            .expect("runs")
    };
    let p = png.to_str().expect("utf-8");
    // --samples 0 silently became 1.
    let o = render(&["--samples", "0", "--png", p]);
    assert!(!o.status.success() && !png.exists(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--samples = 0") && stderr(&o).contains(">= 1"),
        "{}",
        stderr(&o)
    );
    // --png and --pfm on one file: one overwrote the other.
    let same = dir.join("./sub/../r.png");
    let o = render(&["--png", p, "--pfm", same.to_str().expect("utf-8")]);
    assert!(!o.status.success() && !png.exists(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--png and --pfm both name") && stderr(&o).contains("r.png"),
        "{}",
        stderr(&o)
    );
    // A missing file, a folder and a file that is not JSON are named.
    let missing = dir.join("nope.json");
    let o = render(&["--png", p, missing.to_str().expect("utf-8")]);
    assert!(!o.status.success(), "accepted");
    assert!(stderr(&o).contains("nope.json"), "{}", stderr(&o));
    let o = render(&["--png", p, dir.to_str().expect("utf-8")]);
    assert!(
        !o.status.success() && stderr(&o).contains(dir.to_str().expect("utf-8")),
        "{}",
        stderr(&o)
    );
    let garbage = dir.join("garbage.json");
    fs::write(&garbage, "{\"family\": ").expect("write");
    let o = render(&["--png", p, garbage.to_str().expect("utf-8")]);
    assert!(
        !o.status.success() && stderr(&o).contains("garbage.json"),
        "{}",
        stderr(&o)
    );
    // An unwritable PNG names itself.
    let o = render(&[
        "--png",
        dir.join("no/such/folder.png").to_str().expect("utf-8"),
    ]);
    assert!(
        !o.status.success() && stderr(&o).contains("no/such/folder.png"),
        "{}",
        stderr(&o)
    );
    // Two files and --samples 1 work.
    let pfm = dir.join("r.pfm");
    let o = render(&[
        "--samples",
        "1",
        "--png",
        p,
        "--pfm",
        pfm.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(png.exists() && pfm.exists());
    let _ = fs::remove_dir_all(&dir);
}

/// The narrowest field of view is stated, and a Phong exponent of 0 is the
/// documented constant lobe, accepted.
#[test]
fn the_fov_minimum_is_stated_and_phong_zero_is_accepted() {
    let o = check_edited("w-6-1-phong-pixel.json", |v| {
        v["scene"]["camera"]["fov_y"] = json!(1e-5);
    });
    refused(
        &o,
        "scene.camera.fov_y",
        &["fov_y = 0.00001", "[1e-4, 180)"],
    );
    let o = check_edited("w-6-1-phong-pixel.json", |v| {
        v["scene"]["camera"]["fov_y"] = json!(1e-4);
    });
    assert!(o.status.success(), "{}", stderr(&o));
    let o = check_edited("w-6-1-phong-pixel.json", |v| {
        v["scene"]["objects"][0]["material"]["phong"] = json!(0.0);
    });
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The cost guard counts the work of one evaluation (the hostile probe of
/// session 21): a lookup in 2000 Gaussian blobs, a sample's shadow
/// ray against 2000 occluders, a ray against 500 objects each passed as one
/// evaluation, and jobs of days were accepted. Each is refused now, at
/// `budgets`, with its estimate; without the factor each stays under 1e11.
#[test]
fn the_cost_guard_counts_blobs_occluders_and_objects() {
    let blob = |i: usize| json!({"centre": [-5.0 + 0.005 * i as f64, 0.0, 0.0], "amplitude": 0.5, "width": 0.3});
    let volume = json!({
        "name": "blobs", "family": "volume",
        "scene": {"depth_scheme": "nested", "ray": {"origin": [-6, 0, 0.05], "direction": [1, 0.02, 0]},
                  "medium": {"type": "gaussian-blobs", "blobs": (0..2000).map(blob).collect::<Vec<_>>()},
                  "lambda": 1.0, "emission": {"type": "constant", "c": 1.0}},
        "quantities": ["I_E"], "rules": [{"rule": "gauss-legendre"}], "budgets": [27000],
        "repeats": 1, "reference": {"type": "converged", "n": 16}
    });
    refused(
        &check_text(&volume.to_string()),
        "budgets",
        &["gauss-legendre", "e14", "--no-cost-limit"],
    );
    let tri = |i: usize| {
        let x = 10.0 + 0.001 * i as f64;
        json!({"type": "triangle", "a": [x, 10, 1], "b": [x + 0.0005, 10, 1], "c": [x, 10.0005, 1]})
    };
    let rendering = json!({
        "name": "occluders", "family": "rendering",
        "scene": {"receiver": {"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]},
                  "emitters": [{"type": "rectangle", "origin": [-1.0, -1.0, 2.0], "edge_u": [0.0, 2.0, 0.0],
                                "edge_v": [2.0, 0.0, 0.0], "radiance": 1.0}],
                  "occluders": (0..2000).map(tri).collect::<Vec<_>>()},
        "quantities": ["E_area"], "rules": [{"rule": "monte-carlo"}], "budgets": [100000000],
        "repeats": 1, "reference": {"type": "value", "values": {"E_area": 0.5}, "uncertainty": 0.001}
    });
    refused(
        &check_text(&rendering.to_string()),
        "budgets",
        &["monte-carlo", "e11", "--no-cost-limit"],
    );
    let mut whitted: Value = serde_json::from_str(
        &fs::read_to_string(root().join("experiments/w-grey-test-scene.json")).expect("read"),
    )
    .expect("json");
    whitted["name"] = json!("objects");
    let objects = whitted["scene"]["objects"].as_array_mut().expect("objects");
    for i in 0..497 {
        objects.push(
            json!({"type": "sphere", "centre": [50.0 + i as f64, -50, -50], "radius": 0.001,
                            "material": {"k_a": 0.2, "k_d": 0.3}}),
        );
    }
    whitted["rules"] = json!([{"rule": "grid"}]);
    whitted["budgets"] = json!([1000000]);
    // A cheap reference, so that the job's own cost is what is refused.
    whitted["reference"] = json!({"type": "converged", "n": 100});
    refused(
        &check_text(&whitted.to_string()),
        "budgets",
        &["grid", "e12", "--no-cost-limit"],
    );
}

/// The cost guard counts what the walks do: at optical depth 1e5 a
/// delta-tracking walk stops at its first look-up, so 1e7 walks are about
/// 2e7 evaluations (the estimate `1 + D` a walk, about 1e12, refused them),
/// while a ratio-tracking walk crosses the whole sphere, 1e5 look-ups, and
/// 1e7 of them are still refused, with the advice to lower the budget (the
/// one budget given was taken for the smallest, and the advice said no
/// budget would do: hostile probe, session 30).
#[test]
fn the_cost_guard_counts_what_the_walks_do() {
    let stiff = |tracker: &str| {
        json!({
            "name": "stiff", "family": "volume",
            "scene": {"ray": {"origin": [-3.0, 0.0, 0.0], "direction": [1.0, 0.0, 0.0]},
                      "medium": {"type": "constant-sphere", "centre": [0.0, 0.0, 0.0],
                                 "radius": 1.0, "kappa": 50000.0}},
            "quantities": ["tau"], "rules": [{"rule": tracker}], "budgets": [10000000],
            "repeats": 1, "reference": {"type": "closed-form"}
        })
        .to_string()
    };
    let o = check_text(&stiff("delta-tracking"));
    assert!(o.status.success(), "{}", stderr(&o));
    refused(
        &check_text(&stiff("ratio-tracking")),
        "budgets",
        &[
            "ratio-tracking",
            "e12",
            "lower the budget",
            "--no-cost-limit",
        ],
    );
}

/// V-L by delta tracking through an 8^3 grid of density 1 with a column of
/// 1e6 at x-voxel 2 (y-voxels 4 to 7), light along +y: the shadow rays from
/// the eye ray's first quarter cross the column, about 4.7e5 look-ups a
/// walk. The figure took its shadow rays from the chord's start, middle and
/// end only, none of which crosses the column, and accepted 1e8 walks
/// (weeks of work; hostile probe, session 30); it now refuses them.
#[test]
fn the_cost_guard_sees_a_hot_column_beside_the_eye_ray() {
    let data: Vec<f64> = (0..512)
        .map(|i| {
            if i % 8 == 2 && (i / 8) % 8 >= 4 {
                1e6
            } else {
                1.0
            }
        })
        .collect();
    let spec = json!({
        "name": "column", "family": "volume",
        "scene": {"shadow": "quadrature", "ray": {"origin": [-2.0, -0.5, 0.0], "direction": [1.0, 0.0, 0.0]},
                  "medium": {"type": "voxel-grid", "min": [-1, -1, -1], "max": [1, 1, 1],
                             "resolution": [8, 8, 8], "data": data},
                  "lambda": 1.0, "light": {"toward_light": [0, 1, 0], "intensity": 1.0, "albedo": 0.8}},
        "quantities": ["I_L"], "rules": [{"rule": "delta-tracking"}], "budgets": [100000000],
        "repeats": 1, "reference": {"type": "converged", "n": 8}
    });
    refused(
        &check_text(&spec.to_string()),
        "budgets",
        &["delta-tracking", "e14", "--no-cost-limit"],
    );
}

/// The whole experiment is guarded too: 6 rules at 174 budgets, 1000
/// repeats each (a million jobs), and a 16384 x 16384 image (116 GB of results) passed the
/// per-job guard.
#[test]
fn the_cost_guard_bounds_the_jobs_and_the_results_of_an_experiment() {
    let o = check_edited("calibration-exp.json", |v| {
        v["rules"] = json!([{"rule": "monte-carlo"}, {"rule": "stratified"}, {"rule": "sobol"},
                            {"rule": "trapezoid"}, {"rule": "simpson"}, {"rule": "gauss-legendre"}]);
        v["budgets"] = json!({"from": 8, "to": 1000000, "factor": 1.07});
        v["repeats"] = json!(1000);
    });
    refused(
        &o,
        "budgets",
        &["jobs", "expected at most 1e6", "--no-cost-limit"],
    );
    let o = check_edited("w-grey-test-scene.json", |v| {
        v["scene"]["camera"]["width"] = json!(16384);
        v["scene"]["camera"]["height"] = json!(16384);
        v["scene"]["lights"] = json!([]);
        v["scene"]["objects"] = json!([{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
                                        "material": {"k_a": 0.3, "colour": [0.8, 0.8, 0.7]}}]);
        v["rules"] = json!([{"rule": "centre"}]);
        v["budgets"] = json!([1]);
        v["reference"] = json!({"type": "closed-form"});
    });
    refused(
        &o,
        "budgets",
        &[
            "GB of results",
            "expected at most 2.0 GB",
            "--no-cost-limit",
        ],
    );
}

/// `check` refuses two files of one name as `run` does (it said ok to both,
/// and `run` then refused them).
#[test]
fn check_refuses_two_files_of_one_name() {
    let dir = scratch("dupname");
    let a = root().join("experiments/calibration-exp.json");
    let b = dir.join("copy.json");
    fs::copy(&a, &b).expect("copy");
    let o = bin().arg("check").arg(&a).arg(&b).output().expect("runs");
    refused(
        &o,
        "name",
        &["\"calibration-exp\" is also the name of", "rename one"],
    );
    let _ = fs::remove_dir_all(&dir);
}

/// `check a b c` checks every file: a bad one is named and the next one
/// checked (it stopped at the first bad file, so a second went unseen),
/// and the exit status fails where any file failed.
#[test]
fn check_names_every_bad_file_and_checks_the_rest() {
    let dir = scratch("checkall");
    let good = root().join("experiments/calibration-exp.json");
    let (bad1, bad2) = (dir.join("bad1.json"), dir.join("bad2.json"));
    fs::write(&bad1, "{ \"name\": ").expect("write");
    let mut second: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&good).expect("read")).expect("json");
    second["name"] = json!("second");
    second["repeats"] = json!(0);
    fs::write(&bad2, second.to_string()).expect("write");
    let o = bin()
        .arg("check")
        .args([&bad1, &good, &bad2])
        .output()
        .expect("runs");
    assert!(!o.status.success());
    let (out, err) = (String::from_utf8_lossy(&o.stdout), stderr(&o));
    assert!(out.contains("calibration-exp.json: ok ("), "{out}");
    assert!(
        err.contains("bad1.json") && err.contains("bad2.json"),
        "{err}"
    );
    assert!(err.contains("`repeats`"), "{err}");
    assert!(err.contains("2 of 3 file(s) failed the check"), "{err}");
    // One file given twice is said so, not called a clash of two names.
    let o = bin()
        .arg("check")
        .args([&good, &good])
        .output()
        .expect("runs");
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("this file is given twice"),
        "{}",
        stderr(&o)
    );
    let _ = fs::remove_dir_all(&dir);
}

/// A Mitsuba reference naming a file that is not there is refused naming
/// that file first (the message spoke only of the bundled values being
/// stale).
#[test]
fn a_missing_values_file_is_named() {
    let o = check_edited("mitsuba-tau-constant-sphere.json", |v| {
        // Its own name, so the bundled (now stale) values are found.
        v["name"] = json!("mitsuba-tau-constant-sphere");
        v["reference"] = json!({"type": "mitsuba", "file": "nonexist.json"});
    });
    refused(
        &o,
        "reference.file",
        &["nonexist.json", "could not be read", "stale"],
    );
}

/// A radiance whose integrands overflow is refused at its path (1e308 was
/// accepted, and 10 of 14 jobs then failed with "integrand returned inf");
/// 1e290, the largest accepted, runs every job.
#[test]
fn a_radiance_that_overflows_the_integrands_is_refused() {
    let o = check_edited("r-shadow-boundary.json", |v| {
        v["scene"]["emitters"][0]["radiance"] = json!(1e308);
    });
    refused(&o, "scene.emitters[0].radiance", &["1e308", "[0, 1e290]"]);
    let dir = scratch("radiance");
    let mut v: Value = serde_json::from_str(
        &fs::read_to_string(root().join("experiments/r-shadow-boundary.json")).expect("read"),
    )
    .expect("json");
    v["name"] = json!("bright");
    v["scene"]["emitters"][0]["radiance"] = json!(1e290);
    v["budgets"] = json!([4, 16, 64]);
    let f = dir.join("bright.json");
    fs::write(&f, v.to_string()).expect("write");
    let o = bin()
        .args(["run", "--out"])
        .arg(dir.join("out"))
        .arg(&f)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let _ = fs::remove_dir_all(&dir);
}

/// A converged reference's `n` beyond its range is refused with the range,
/// not first with the cost (which sent the user to --no-cost-limit, and
/// then to the range).
#[test]
fn a_converged_n_beyond_its_range_names_the_range_first() {
    let o = check_edited("v-e-constant-sphere.json", |v| {
        v["reference"] = json!({"type": "converged", "n": 100000000});
    });
    refused(
        &o,
        "reference.n",
        &["100000000 is not an integer in 2..=100000"],
    );
    assert!(!stderr(&o).contains("--no-cost-limit"), "{}", stderr(&o));
}

/// `render` refuses an image whose memory would not fit, before it renders
/// (16384 x 16384 ran out of memory; 8192 x 8192 peaked at 3.2 GB). A small
/// scene, so that the cost limit (which the test scene meets first) does not
/// answer.
#[test]
fn render_refuses_an_image_that_would_not_fit_in_memory() {
    let dir = scratch("bigrender");
    let png = dir.join("big.png");
    let o = bin()
        .args([
            "render",
            "--width",
            "16384",
            "--height",
            "16384",
            "--samples",
            "1",
            "--png",
        ])
        .arg(&png)
        .arg(root().join("experiments/w-corner-image.json"))
        .output()
        .expect("runs");
    refused(
        &o,
        "width",
        &["16384 x 16384 pixels", "GB while rendering", "--width"],
    );
    assert!(!png.exists());
    let _ = fs::remove_dir_all(&dir);
}

/// An empty file, a file cut short and a key that is not a string: each is
/// named where it is (they were named `.` for an empty file and `scene.?`
/// for a key that could not be read).
#[test]
fn empty_cut_short_and_unreadable_keys_are_named_where_they_are() {
    refused(&check_text(""), ".", &["the file is empty"]);
    refused(&check_text(" \n\t"), ".", &["the file is empty"]);
    let text =
        fs::read_to_string(root().join("experiments").join("calibration-exp.json")).expect("read");
    let cut = &text[..text.find("\"rules\"").expect("rules") + "\"rules\": ".len()];
    refused(
        &check_text(cut),
        "rules",
        &["the file ends inside", "cut short"],
    );
    refused(
        &check_text(&text.replacen("\"scene\": {}", "\"scene\": {\"a\": 1, 2: 3}", 1)),
        "scene",
        &["key must be a string"],
    );
    // A byte-order mark was "expected value at line 1 column 1", and more
    // after the object "trailing characters".
    refused(
        &check_text(&format!("\u{feff}{text}")),
        ".",
        &["byte-order mark"],
    );
    refused(
        &check_text(&format!("{text}\n{{}}")),
        ".",
        &["more after the experiment's JSON object", "one JSON object"],
    );
    // `Infinity` (what JavaScript and Python write) was "expected value".
    let infinite = text.replacen(
        "{\"type\": \"closed-form\"}",
        "{\"type\": \"literal\", \"values\": {\"exp\": Infinity}}",
        1,
    );
    assert_ne!(infinite, text, "the reference was not replaced");
    refused(
        &check_text(&infinite),
        "reference.values.exp",
        &[
            "Infinity",
            "is not a JSON number",
            "expected a finite number",
        ],
    );
}

/// `render` counts the whole ray tree, as `run` does: a scene at depth 16
/// with a mirror and a glass sphere at 1000 x 1000 and 9 rays a pixel passed
/// the primary-ray count and would have run for hours. And it checks its
/// flags and output folders before rendering: `--width 0` was named as the
/// file's `scene.camera.width`, and an unwritable `--pfm` was found after
/// the render, leaving the PNG behind.
#[test]
fn render_counts_the_ray_tree_and_checks_its_outputs_first() {
    let dir = scratch("render-tree");
    let mut v: Value = serde_json::from_str(
        &fs::read_to_string(root().join("experiments/w-grey-test-scene.json")).expect("read"),
    )
    .expect("json");
    v["scene"]["max_depth"] = json!(16);
    let file = dir.join("deep.json");
    fs::write(&file, v.to_string()).expect("write");
    let png = dir.join("r.png");
    let render = |args: &[&str]| {
        bin()
            .arg("render")
            .args(args)
            .arg("--png")
            .arg(&png)
            .arg(&file)
            .output()
            .expect("runs")
    };
    let o = render(&["--width", "1000", "--height", "1000", "--samples", "9"]);
    refused(
        &o,
        "samples",
        &["depth 16", "ray-object tests", "max_depth"],
    );
    assert!(!png.exists());
    let o = render(&["--width", "0"]);
    assert!(!o.status.success(), "accepted");
    assert!(stderr(&o).contains("--width = 0"), "{}", stderr(&o));
    // Past the largest side too: it was named as the file's camera width.
    let o = render(&["--height", "100000"]);
    let msg = stderr(&o);
    assert!(!o.status.success(), "accepted");
    assert!(
        msg.contains("--height = 100000")
            && msg.contains("1..=16384")
            && !msg.contains("scene.camera"),
        "{msg}"
    );
    let pfm = dir.join("no").join("r.pfm");
    let o = render(&[
        "--width",
        "4",
        "--height",
        "3",
        "--pfm",
        pfm.to_str().expect("utf-8"),
    ]);
    assert!(!o.status.success(), "accepted");
    assert!(
        stderr(&o).contains("--pfm") && stderr(&o).contains("folder does not exist"),
        "{}",
        stderr(&o)
    );
    assert!(!png.exists(), "a PNG was left behind");
    let _ = fs::remove_dir_all(&dir);
}

/// An equation ID in a family that has none said so with an empty list
/// ("expected one of" and nothing).
#[test]
fn an_equation_id_in_a_family_without_equations_says_there_are_none() {
    let o = check_edited("calibration-exp.json", |v| {
        v["equations"] = json!(["ZZZ"]);
    });
    refused(&o, "equations[0]", &["\"ZZZ\"", "instantiates no equation"]);
}

/// `lightquad schema | head -1` ended with "error: Broken pipe": a reader
/// that stops early is no failure.
#[test]
fn a_reader_that_stops_early_is_no_error() {
    use std::io::Read;
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_lightquad"))
        .arg("schema")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("runs");
    let mut first = [0u8; 1];
    child
        .stdout
        .take()
        .expect("stdout")
        .read_exact(&mut first)
        .expect("a byte");
    // The pipe is closed here, before the schema is written whole.
    let o = child.wait_with_output().expect("ends");
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(
        o.status.success() && err.is_empty(),
        "{:?}: {err}",
        o.status
    );
}

/// A run whose stderr is closed (`run 2>&1 | head -2`) finishes its jobs and
/// its report: the first progress line to the closed pipe panicked, and the
/// run stopped after three experiments without a report. `merge` likewise.
#[test]
fn a_run_whose_stderr_is_closed_finishes_its_report() {
    let dir = common::scratch("closed-stderr");
    let experiments: Vec<std::path::PathBuf> = ["calibration-exp.json", "calibration-disk.json"]
        .iter()
        .map(|f| common::root().join("experiments").join(f))
        .collect();
    let closed = |cmd: &mut std::process::Command| {
        let mut child = cmd
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("runs");
        // Closed before the first line is written.
        drop(child.stderr.take());
        child.wait().expect("ends")
    };
    let status = closed(
        std::process::Command::new(env!("CARGO_BIN_EXE_lightquad"))
            .args(["run", "--out"])
            .arg(dir.join("run"))
            .args(&experiments),
    );
    assert!(status.success(), "{status:?}");
    for name in ["calibration-exp", "calibration-disk"] {
        assert!(
            dir.join("run").join(name).join("report.md").exists(),
            "{name}"
        );
    }
    assert!(dir.join("run/index.html").exists());
    let status = closed(
        std::process::Command::new(env!("CARGO_BIN_EXE_lightquad"))
            .arg("merge")
            .arg(dir.join("run"))
            .arg("--out")
            .arg(dir.join("merged")),
    );
    assert!(status.success(), "{status:?}");
    assert!(dir.join("merged/index.html").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A voxel count names a range a person can read: `1..=18446744073709551615`
/// was printed for `resolution[0]: []`.
#[test]
fn a_voxel_count_names_a_readable_range() {
    let mut spec: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("experiments/v-i-total-voxel-grid.json"))
            .expect("read"),
    )
    .expect("json");
    spec["scene"]["medium"]["resolution"][0] = serde_json::json!([]);
    let dir = scratch("voxel-count");
    let file = dir.join("e.json");
    std::fs::write(&file, spec.to_string()).expect("write");
    let o = bin().arg("check").arg(&file).output().expect("runs");
    let msg = stderr(&o);
    assert!(!o.status.success(), "accepted");
    for want in [
        "at `scene.medium.resolution[0]`",
        "1..=4294967295 (their product is the length of data)",
    ] {
        assert!(msg.contains(want), "no {want:?} in {msg}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

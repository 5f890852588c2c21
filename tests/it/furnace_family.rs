//! The furnace family: the full rendering equation in an
//! integrating sphere through the experiment layer. Values against the
//! closed forms summed here term by term (`L_e sum rho^k` for the white
//! furnace, the cap's share `L_e (1 - cos alpha)/2` per bounce otherwise),
//! the bounces a truncation needs against `ln tol / ln rho`, and bad scenes
//! named at their JSON paths.

use crate::common;
use std::fs;

use common::{bin, rel, rng, scratch, stderr};
use lightquad::experiment::validate::{deserialize, validate};
use lightquad::family::{Family, Method};
use lightquad::quadrature::{AnyRule, BaseRule, GaussLegendre, Sobol};
use lightquad::rendering::closed::{Furnace, FurnaceQuantity as Q, PathTracing};
use serde_json::{Value, json};

fn scene(v: Value) -> lightquad::rendering::closed::Built {
    Furnace::build(&serde_json::from_value(v).expect("spec")).expect("builds")
}

/// `L_e sum_{k=1}^{K} rho^k s` term by term, `s` the cap's share per bounce.
fn series(le_here: f64, share: f64, rho: f64, k: u32) -> f64 {
    let mut sum = 0.0;
    let mut term = 1.0;
    for _ in 0..k {
        term *= rho;
        sum += term;
    }
    le_here + share * sum
}

#[test]
fn closed_forms_are_the_series_summed_term_by_term() {
    // The white furnace: every wall emits, share L_e.
    let white =
        scene(json!({"albedo": 0.999, "emission": 2.0, "point": [0, 0, -1], "bounces": 500}));
    let l = Furnace::closed_form(&white, Q::L).expect("closed")[0];
    assert!(rel(l, 2.0 / (1.0 - 0.999)) < 1e-13, "{l}");
    let lk = Furnace::closed_form(&white, Q::LK).expect("closed")[0];
    let want = series(2.0, 2.0, 0.999, 500);
    assert!(rel(lk, want) < 1e-13, "{lk} vs {want}");
    // A cap of half-angle 0.5 seen from the opposite pole (outside it):
    // share L_e (1 - cos 0.5) / 2 a bounce.
    let share = (1.0 - 0.5f64.cos()) / 2.0;
    let cap = scene(json!({"albedo": 0.9, "emission": 1.0, "half_angle": 0.5,
        "point": [0, 0, -1], "bounces": 20}));
    let lk = Furnace::closed_form(&cap, Q::LK).expect("closed")[0];
    assert!(rel(lk, series(0.0, share, 0.9, 20)) < 1e-13, "{lk}");
    let l = Furnace::closed_form(&cap, Q::L).expect("closed")[0];
    assert!(rel(l, share * 0.9 / 0.1) < 1e-13, "{l}");
    // Inside the cap the point's own emission adds.
    let inside = scene(json!({"albedo": 0.9, "emission": 1.0, "half_angle": 0.5,
        "point": [0, 0.1, 1], "bounces": 3}));
    let lk = Furnace::closed_form(&inside, Q::LK).expect("closed")[0];
    assert!(rel(lk, series(1.0, share, 0.9, 3)) < 1e-14, "{lk}");
}

#[test]
fn the_default_series_is_truncated_below_1e_16_and_says_the_bounces_each_accuracy_needs() {
    // The white furnace's relative truncation after K bounces is
    // rho^(K+1): the fewest K for a tolerance, counted power by power.
    let fewest = |tol: f64| {
        let (mut k, mut p) = (0u32, 0.999f64);
        while p > tol {
            p *= 0.999;
            k += 1;
        }
        k
    };
    let white = scene(json!({"albedo": 0.999, "emission": 1.0, "point": [0, 0, -1]}));
    // Counting 36 800 products rounds by about 1e-12 relative: within a
    // bounce of the exact power.
    assert!(
        white.bounces.abs_diff(fewest(1e-16)) <= 1,
        "{}",
        white.bounces
    );
    let section = Furnace::scene_audit(&white).expect("section");
    for tol in [1e-3, 1e-6, 1e-10] {
        let want = format!("{tol:.0e}: {}", fewest(tol));
        assert!(section.contains(&want), "no {want:?} in {section}");
    }
}

#[test]
fn rules_and_path_tracing_reach_the_closed_forms_within_their_errors() {
    let mut r = rng(3);
    // The white furnace: a constant per bounce, so every rule is exact but
    // for the series' rounding, which its error estimate carries.
    let white = scene(json!({"albedo": 0.999, "emission": 1.0, "point": [0, 0, -1]}));
    let gl = Method::Rule(AnyRule::Base(BaseRule::GaussLegendre(
        GaussLegendre::default(),
    )));
    let out = Furnace::evaluate(&white, &gl, 256, &mut r, &[Q::L]).expect("runs");
    let m = &out[&Q::L];
    let err = (m.value[0] - 1000.0).abs();
    assert!(err < 1e-9 && err <= m.error[0], "{m:?}");
    // The cap: L_K by Sobol' at 2^16 points per bounce integral (a jump
    // along the cap's outline: first order at best), L by path tracing.
    let cap = scene(json!({"albedo": 0.9, "emission": 1.0, "half_angle": 0.5,
        "point": [0, 0, -1], "bounces": 20}));
    let share = (1.0 - 0.5f64.cos()) / 2.0;
    let sobol = Method::Rule(AnyRule::Base(BaseRule::Sobol(Sobol::default())));
    let out = Furnace::evaluate(&cap, &sobol, 1 << 16, &mut r, &[Q::LK]).expect("runs");
    let lk = out[&Q::LK].value[0];
    assert!(rel(lk, series(0.0, share, 0.9, 20)) < 2e-3, "{lk}");
    let out = Furnace::evaluate(
        &cap,
        &Method::Estimator(PathTracing::PathTracing),
        200_000,
        &mut r,
        &[Q::L],
    )
    .expect("runs");
    let m = &out[&Q::L];
    let z = (m.value[0] - share * 9.0).abs() / m.error[0];
    assert!(z < 4.0, "{m:?}: {z} standard errors");
    // Paths ended after K = 20 bounces estimate L_K (the series above).
    let out = Furnace::evaluate(
        &cap,
        &Method::Estimator(PathTracing::PathTracing),
        200_000,
        &mut r,
        &[Q::LK],
    )
    .expect("runs");
    let m = &out[&Q::LK];
    let z = (m.value[0] - series(0.0, share, 0.9, 20)).abs() / m.error[0];
    assert!(z < 4.0, "{m:?}: {z} standard errors");
    // A path survives its k-th bounce with probability 0.9^k and takes at
    // most 20: sum_{k=1}^{20} 0.9^k = 9 (1 - 0.9^20) = 7.906 bounces on
    // average (9 untruncated).
    let per_path = m.evaluations as f64 / 200_000.0;
    let want = 9.0 * (1.0 - 0.9f64.powi(20));
    assert!((per_path - want).abs() < 0.05, "{per_path} vs {want}");
}

/// A file with the furnace scene `scene`.
fn file(scene: Value, quantities: Value, rules: Value) -> Value {
    json!({"name": "f", "family": "furnace", "scene": scene, "quantities": quantities,
        "rules": rules, "budgets": [16], "repeats": 1, "reference": {"type": "closed-form"}})
}

#[test]
fn bad_scenes_are_named_at_their_paths() {
    let good = json!({"albedo": 0.5, "emission": 1.0, "point": [0, 0, -1]});
    let cases: Vec<(&str, Value, &[&str])> = vec![
        ("albedo", json!(1.0), &["scene.albedo", "[0, 1)"]),
        ("albedo", json!(-0.1), &["scene.albedo", "[0, 1)"]),
        ("half_angle", json!(4.0), &["scene.half_angle", "[0, pi]"]),
        ("point", json!([0, 0, 0]), &["scene.point", "non-zero"]),
        ("axis", json!([0, 0, 0]), &["scene.axis", "non-zero"]),
        ("radius", json!(0.0), &["scene.radius", "> 0"]),
        ("radius", json!(1e200), &["scene.radius", "1e100"]),
        ("emission", json!(1e299), &["scene.emission", "1e300"]),
        (
            "bounces",
            json!(200_000_000u64),
            &["scene.bounces", "at most 100000000"],
        ),
        ("colour", json!(1), &["scene", "colour"]),
    ];
    for (field, value, want) in cases {
        let mut s = good.clone();
        s[field] = value.clone();
        if field == "emission" {
            s["albedo"] = json!(0.999);
        }
        let json = file(s, json!(["L"]), json!([{"rule": "gauss-legendre"}]));
        let e = deserialize(json)
            .and_then(|spec| validate::<Furnace>(spec, "h"))
            .err()
            .unwrap_or_else(|| panic!("{field} = {value} accepted"));
        let msg = e.to_string();
        for w in want {
            assert!(msg.contains(w), "{field} = {value}: no {w:?} in {msg}");
        }
    }
    // An albedo so near 1 that the default series would be endless.
    let json = file(
        json!({"albedo": 0.999_999_999_99, "emission": 1.0, "point": [0, 0, -1]}),
        json!(["L"]),
        json!([{"rule": "gauss-legendre"}]),
    );
    let msg = deserialize(json)
        .and_then(|spec| validate::<Furnace>(spec, "h"))
        .map(|_| ())
        .expect_err("refused")
        .to_string();
    assert!(
        msg.contains("scene.albedo") && msg.contains("scene.bounces"),
        "{msg}"
    );
}

#[test]
fn the_bundled_white_furnace_runs_and_its_report_tells_the_truncation() {
    let dir = scratch("furnace-run");
    let o = bin()
        .args(["run", "--out"])
        .arg(&dir)
        .arg(common::root().join("experiments/r-furnace-albedo-0999.json"))
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let report = fs::read_to_string(dir.join("r-furnace-albedo-0999/report.md")).expect("report");
    for want in [
        "## The Neumann series bounce by bounce",
        "1e-6: 13808",
        "| path-tracing | 4096 |",
    ] {
        assert!(report.contains(want), "no {want:?} in the report");
    }
    let _ = fs::remove_dir_all(&dir);
}

/// The converged value of `L` is `L` itself, whatever `K` the file keeps
/// for the rules' series (the report's cross-check column showed `L_5 =
/// 4.686` as lightquad's `L` beside Mitsuba's 9.9993 and the closed form
/// 10); `L_K` keeps the file's `K`.
#[test]
fn the_converged_whole_radiance_ignores_the_files_truncation() {
    let built = scene(
        json!({"albedo": 0.9, "emission": 1.0, "point": [0.0, 0.0, -1.0],
                             "bounces": 5}),
    );
    let out = Furnace::converged(&built, 4, &[Q::L, Q::LK]).expect("converges");
    let (l, lk) = (&out[&Q::L], &out[&Q::LK]);
    assert!(rel(l.value[0], 10.0) < 1e-12, "{:?}", l.value);
    assert!(l.error[0] < 1e-12 * 10.0, "{:?}", l.error);
    assert!(
        rel(lk.value[0], series(1.0, 1.0, 0.9, 5)) < 1e-13,
        "{:?}",
        lk.value
    );
}

//! The tracking estimators' "carried by a few walks" flag, measured for
//! coverage over 200 repeats a scene: where the mean of a product of many
//! factors rests on walks not yet seen (ratio tracking through an optical
//! depth of 200, delta tracking's light score whose shadow rays cross 50 of
//! it), every run whose true error exceeds 4 reported standard errors must
//! carry the flag; on easy scenes (optical depth 0.1 to 5, Gaussian blobs,
//! a voxel grid) at most 5% of runs may. True errors are against the
//! family's closed forms, or its converged quadrature where there is none.

use lightquad::experiment::validate::{Experiment, deserialize, validate};
use lightquad::family::{Family, Flag, Method, Quantity};
use lightquad::volume::experiment::{Volume, VolumeQuantity};
use rand::SeedableRng;
use serde_json::{Value, json};

const REPEATS: u64 = 200;

fn load(scene: Value, q: &str) -> Experiment<Volume> {
    let spec = json!({
        "name": "t", "family": "volume", "scene": scene, "quantities": [q],
        "rules": [{"rule": "delta-tracking"}], "budgets": [16], "repeats": 1,
        "reference": {"type": "converged", "n": 16}
    });
    validate::<Volume>(deserialize(spec).expect("parses"), "hash").expect("valid")
}

/// A unit sphere of constant `kappa` on a ray `offset` from its centre,
/// with constant emission and a light along the ray (`along`) or across it.
fn sphere(kappa: f64, offset: f64, along: bool) -> Value {
    let toward = if along {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    json!({
        "ray": {"origin": [-3.0, offset, 0.0], "direction": [1.0, 0.0, 0.0]},
        "medium": {"type": "constant-sphere", "centre": [0.0, 0.0, 0.0], "radius": 1.0, "kappa": kappa},
        "emission": {"type": "constant", "c": 1.0},
        "light": {"toward_light": toward, "intensity": 2.0, "albedo": 0.8},
        "shadow": "quadrature"
    })
}

/// Per run of `tracker` on quantity `q` at each budget: (error in
/// standard errors, flagged).
fn runs(scene: &Value, q: &str, tracker: &str, budgets: &[usize]) -> Vec<(usize, f64, bool)> {
    let exp = load(scene.clone(), q);
    let quantity = *<VolumeQuantity as Quantity>::all()
        .iter()
        .find(|x| x.name() == q)
        .expect("a quantity");
    let truth = Volume::closed_form(&exp.scene, quantity).map_or_else(
        || Volume::converged(&exp.scene, 4096, &[quantity]).expect("converges")[&quantity].value[0],
        |v| v[0],
    );
    let method: Method<_> = serde_json::from_value(json!({ "rule": tracker })).expect("method");
    let mut out = Vec::new();
    for &n in budgets {
        for seed in 0..REPEATS {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed * 7919 + n as u64);
            let m = &Volume::evaluate(&exp.scene, &method, n, &mut rng, &[quantity])
                .expect("evaluates")[&quantity];
            let heavy = m.flags.iter().any(|f| matches!(f, Flag::HeavyWalks { .. }));
            let alike = m
                .flags
                .iter()
                .any(|f| matches!(f, Flag::AllWalksAlike { .. }));
            let off = (m.value[0] - truth).abs() / m.error[0];
            // A run whose walks all scored alike carries its own flag.
            if !alike {
                out.push((n, off, heavy));
            }
        }
    }
    out
}

/// Counts: (runs, runs beyond 4 SE, those of them unflagged, flagged runs).
fn tally(runs: &[(usize, f64, bool)]) -> (usize, usize, usize, usize) {
    let beyond = runs.iter().filter(|r| r.1 > 4.0).count();
    let missed = runs.iter().filter(|r| r.1 > 4.0 && !r.2).count();
    let flagged = runs.iter().filter(|r| r.2).count();
    (runs.len(), beyond, missed, flagged)
}

#[test]
fn heavy_walks_are_flagged_where_their_error_bars_fail() {
    let hard = [
        (
            "ratio tau, kappa 100 through the centre",
            sphere(100.0, 0.0, true),
            "tau",
            "ratio-tracking",
        ),
        (
            "ratio tau, kappa 100 at offset 0.5",
            sphere(100.0, 0.5, true),
            "tau",
            "ratio-tracking",
        ),
        (
            "delta I_L, kappa 50",
            sphere(50.0, 0.0, true),
            "I_L",
            "delta-tracking",
        ),
    ];
    for (what, scene, q, tracker) in hard {
        let r = runs(&scene, q, tracker, &[16, 256, 4096]);
        let (n, beyond, missed, flagged) = tally(&r);
        eprintln!(
            "{what}: {n} runs, {beyond} beyond 4 SE, {missed} of them unflagged, {flagged} flagged"
        );
        for b in [16, 256, 4096] {
            let at: Vec<_> = r.iter().filter(|x| x.0 == b).copied().collect();
            eprintln!("at {b}: {:?}", tally(&at));
        }
        assert_eq!(
            missed, 0,
            "{what}: {missed} of {beyond} runs beyond 4 SE carry no flag"
        );
    }
}

#[test]
fn easy_walks_are_seldom_flagged() {
    let blobs = json!({
        "ray": {"origin": [-6.0, 0.0, 0.05], "direction": [1.0, 0.02, 0.0]},
        "medium": {"type": "gaussian-blobs", "blobs": [
            {"centre": [0.0, 0.1, 0.0], "amplitude": 1.2, "width": 0.4},
            {"centre": [0.6, -0.2, 0.1], "amplitude": 0.8, "width": 0.25}]},
        "emission": {"type": "proportional", "k": 0.5},
        "light": {"toward_light": [-1.0, 0.3, 0.0], "intensity": 2.0, "albedo": 0.8},
        "shadow": "quadrature"
    });
    let text = std::fs::read_to_string(
        crate::common::root().join("experiments/v-i-total-voxel-grid.json"),
    )
    .expect("bundled");
    let voxels = serde_json::from_str::<Value>(&text).expect("json")["scene"].clone();
    let mut cases = Vec::new();
    for kappa in [0.05, 0.5, 1.0, 2.5] {
        for tracker in ["ratio-tracking", "residual-ratio-tracking"] {
            cases.push((
                format!("{tracker} tau, kappa {kappa}"),
                sphere(kappa, 0.0, false),
                "tau",
                tracker,
            ));
        }
        for q in ["I_E", "I_L", "I"] {
            cases.push((
                format!("delta {q}, kappa {kappa}"),
                sphere(kappa, 0.0, false),
                q,
                "delta-tracking",
            ));
        }
    }
    for tracker in ["ratio-tracking", "residual-ratio-tracking"] {
        cases.push((
            format!("{tracker} tau, blobs"),
            blobs.clone(),
            "tau",
            tracker,
        ));
    }
    for q in ["I_E", "I_L", "I"] {
        cases.push((
            format!("delta {q}, blobs"),
            blobs.clone(),
            q,
            "delta-tracking",
        ));
        cases.push((
            format!("delta {q}, voxel grid"),
            voxels.clone(),
            q,
            "delta-tracking",
        ));
    }
    for (what, scene, q, tracker) in cases {
        let r = runs(&scene, q, tracker, &[16, 256]);
        let (n, beyond, missed, flagged) = tally(&r);
        eprintln!(
            "{what}: {n} runs, {beyond} beyond 4 SE, {missed} of them unflagged, {flagged} flagged"
        );
        for b in [16, 256] {
            let at: Vec<_> = r.iter().filter(|x| x.0 == b).copied().collect();
            eprintln!("at {b}: {:?}", tally(&at));
        }
        assert!(flagged * 20 <= n, "{what}: {flagged} of {n} runs flagged");
    }
}

/// Residual ratio tracking through a medium known constant is exact and
/// says so: tau = e^-200 through a unit sphere of kappa 100 (written here),
/// to rounding, with an error bar of rounding's size, no flag, and no
/// tentative collision (ratio tracking spends hundreds a walk).
#[test]
fn residual_ratio_tracking_is_exact_and_cheap_in_a_constant_medium() {
    let exp = load(sphere(100.0, 0.0, true), "tau");
    let tau = (-200.0_f64).exp();
    let by = |tracker: &str| {
        let method: Method<_> = serde_json::from_value(json!({ "rule": tracker })).expect("method");
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let q = VolumeQuantity::Tau;
        Volume::evaluate(&exp.scene, &method, 256, &mut rng, &[q]).expect("evaluates")[&q].clone()
    };
    let rrt = by("residual-ratio-tracking");
    assert!(
        (rrt.value[0] / tau - 1.0).abs() < 1e-12,
        "{:e} against {tau:e}",
        rrt.value[0]
    );
    assert!(rrt.error[0] < 1e-12 * tau, "error {:e}", rrt.error[0]);
    assert!(rrt.flags.is_empty(), "{:?}", rrt.flags);
    let ratio = by("ratio-tracking");
    assert!(
        rrt.evaluations * 1000 < ratio.evaluations,
        "{} against {}",
        rrt.evaluations,
        ratio.evaluations
    );
}

/// Trackers alone on a tau that underflows f64 (optical depth 2e5, e^-2e5
/// is below 1e-86000): the heading says the true value underflows, no row
/// shows a true error, and no tracker reaches a target, for an estimate of
/// 0 is off by all of a value f64 cannot hold.
#[test]
fn trackers_alone_on_an_underflowing_tau_reach_nothing() {
    let dir = crate::common::scratch("under");
    let file = dir.join("under.json");
    let text = json!({
        "name": "under", "family": "volume", "scene": {
            "ray": {"origin": [-3.0, 0.0, 0.0], "direction": [1.0, 0.0, 0.0]},
            "medium": {"type": "constant-sphere", "centre": [0.0, 0.0, 0.0], "radius": 1.0, "kappa": 1e5}},
        "quantities": ["tau"],
        "rules": [{"rule": "delta-tracking"}, {"rule": "residual-ratio-tracking"}],
        "budgets": [16, 256], "repeats": 2, "reference": {"type": "closed-form"}
    });
    std::fs::write(&file, text.to_string()).expect("write");
    let out = dir.join("out");
    let o = crate::common::bin()
        .args(["run", "--out"])
        .arg(&out)
        .arg(&file)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = std::fs::read_to_string(out.join("under/report.md")).expect("report");
    let heading = report
        .lines()
        .find(|l| l.starts_with("## tau"))
        .expect("a tau section");
    assert!(heading.contains("underflows f64"), "{heading}");
    for row in report.lines().filter(|l| {
        l.starts_with("| delta-tracking |") || l.starts_with("| residual-ratio-tracking |")
    }) {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        if cells.len() > 8 {
            assert_eq!(cells[4], "—", "a true error shown: {row}");
            assert!(row.contains("underflows"), "{row}");
        } else {
            assert!(
                cells
                    .iter()
                    .skip(3)
                    .all(|c| c.is_empty() || *c == "—" || *c == "not reached"),
                "{row}"
            );
        }
    }
    let index = std::fs::read_to_string(out.join("index.md")).expect("index");
    assert!(index.contains("delta-tracking (not reached)"), "{index}");
    let _ = std::fs::remove_dir_all(&dir);
}

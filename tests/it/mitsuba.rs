//! lightquad against Mitsuba 3: the values the harness in reference/ wrote
//! (reference/values/*.json, or the folder named by LIGHTQUAD_REFERENCE_VALUES,
//! which CI points at a quick regeneration) must match lightquad's converged
//! values within 4 standard errors plus a float32 floor, and must have been made
//! from the experiment file as it is now (a stale hash fails the test). Every
//! family the harness knows is compared: volume (V-tau, V-L), rendering
//! (irradiance and Lambertian reflected radiance, R-H and R-A), the furnace and
//! Whitted's pixel coverage (W-SS).

use std::path::{Path, PathBuf};

use lightquad::experiment::run::file_hash;
use lightquad::experiment::validate::{deserialize, parse_json, validate};
use lightquad::family::{Family, Quantity as _};
use lightquad::quadrature::GaussLegendre;
use lightquad::rendering::closed::Furnace;
use lightquad::rendering::exchange::Exchange;
use lightquad::rendering::experiment::Rendering;
use lightquad::volume::experiment::{Built, Volume, VolumeQuantity as Quantity};
use lightquad::volume::{DepthScheme, ShadowMethod, evaluate};
use lightquad::whitted::experiment::Whitted;
use rand::SeedableRng;
use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn values_dir() -> PathBuf {
    std::env::var_os("LIGHTQUAD_REFERENCE_VALUES")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("reference/values"))
}

/// lightquad's converged value (Gauss–Legendre, 400 nodes per graded piece)
/// and `ln tau` for V-tau, which stays exact where tau underflows.
fn lightquad_value(file: &Path, q: Quantity) -> (f64, f64) {
    let scene = volume_scene(file).scene;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
    let rule = GaussLegendre {
        error_estimate: false,
    };
    let res = evaluate(
        &scene,
        &rule,
        400,
        DepthScheme::Cumulative,
        ShadowMethod::ClosedFormWhereAvailable,
        &mut rng,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    match q {
        Quantity::Tau => (res.transmittance, res.log_transmittance),
        Quantity::LnTau => (res.log_transmittance, res.log_transmittance),
        Quantity::Light => (res.light.map_or(0.0, |t| t.value), f64::NAN),
        Quantity::Emission => (res.emission.map_or(0.0, |t| t.value), f64::NAN),
        Quantity::Background => (res.background.map_or(0.0, |t| t.value), f64::NAN),
        Quantity::Total => (res.total, f64::NAN),
    }
}

/// The volume scene of an experiment file, built.
fn volume_scene(file: &Path) -> Built {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let spec = parse_json(&text)
        .and_then(deserialize::<Volume>)
        .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    Volume::build(&spec.scene).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
}

/// lightquad's converged value of quantity `name` of an experiment of family
/// `F` (its converged evaluation at n = 400, as the report's cross-check
/// table shows it).
fn converged<F: Family>(file: &Path, name: &str) -> f64 {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let exp = parse_json(&text)
        .and_then(deserialize::<F>)
        .and_then(|spec| validate::<F>(spec, "hash"))
        .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let q = *exp
        .spec
        .quantities
        .iter()
        .find(|q| q.name() == name)
        .unwrap_or_else(|| panic!("{}: no quantity {name}", file.display()));
    let out = F::converged(&exp.scene, 400, &[q]).unwrap_or_else(|e| panic!("{e}"));
    out[&q].value[0]
}

/// lightquad's value of quantity `name` of the experiment at `file`, by its
/// family, with `ln tau` beside V-tau (NaN otherwise).
fn lightquad(file: &Path, name: &str) -> (f64, f64) {
    let json: Value = serde_json::from_str(&std::fs::read_to_string(file).expect("read"))
        .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    match json["family"].as_str() {
        Some("volume") => lightquad_value(file, quantity(name)),
        Some("rendering") => (converged::<Rendering>(file, name), f64::NAN),
        Some("furnace") => (converged::<Furnace>(file, name), f64::NAN),
        Some("whitted") => (converged::<Whitted>(file, name), f64::NAN),
        Some("exchange") => (converged::<Exchange>(file, name), f64::NAN),
        other => panic!("{}: no comparison for family {other:?}", file.display()),
    }
}

fn quantity(name: &str) -> Quantity {
    match name {
        "tau" => Quantity::Tau,
        "ln_tau" => Quantity::LnTau,
        "I_E" => Quantity::Emission,
        "I_B" => Quantity::Background,
        "I_L" => Quantity::Light,
        _ => Quantity::Total,
    }
}

#[test]
fn lightquad_agrees_with_mitsuba_within_four_standard_errors() {
    let dir = values_dir();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    let mut compared = 0;
    let mut kinds = std::collections::BTreeSet::new();
    for path in files {
        let v: Value = serde_json::from_str(&std::fs::read_to_string(&path).expect("read"))
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let experiment = root().join(v["experiment_file"].as_str().expect("experiment_file"));
        let hash = file_hash(&std::fs::read(&experiment).expect("experiment file"));
        assert_eq!(
            v["experiment_hash"].as_str(),
            Some(hash.as_str()),
            "{} is stale: regenerate it with scripts/reference.sh",
            path.display()
        );
        for (name, entry) in v["quantities"].as_object().expect("quantities") {
            let (lq, lq_log) = lightquad(&experiment, name);
            let mi = entry["value"].as_f64().expect("value");
            let se = entry["std_error"].as_f64().expect("std_error");
            // float32 renderer: at least 1e-6 relative, or the harness's own bound.
            let floor = entry["float32_error"]
                .as_f64()
                .unwrap_or(0.0)
                .max(1e-6 * mi.abs());
            let diff = (lq - mi).abs();
            eprintln!(
                "{} {name}: lightquad {lq:.10e}, Mitsuba {mi:.10e} +- {se:.1e} ({:.2} SE)",
                v["experiment"].as_str().unwrap_or("?"),
                if se > 0.0 { (lq - mi) / se } else { 0.0 }
            );
            assert!(
                diff <= 4.0 * se + floor,
                "{}: {name} differs by {diff:e}",
                path.display()
            );
            // Where tau underflows, compare the logarithms.
            if let Some(log) = entry["log_value"].as_f64() {
                assert!(
                    (lq_log - log).abs() <= 1e-6 * log.abs().max(1.0),
                    "ln tau {lq_log} vs {log}"
                );
            }
            compared += 1;
            kinds.insert(name.clone());
        }
    }
    assert!(compared >= 2, "only {compared} values compared");
    // Both families' CI regeneration (scripts/reference.sh --ci) and the
    // committed values cover V-tau, V-L, irradiance, reflected radiance and
    // the furnace, and pixel coverage.
    for kind in ["tau", "I_L", "E_area", "L_area", "L", "coverage"] {
        assert!(kinds.contains(kind), "no {kind} compared: {kinds:?}");
    }
}

/// The README's time to regenerate every values file is the sum of the
/// `run_seconds` the committed files record (always the committed folder,
/// also when LIGHTQUAD_REFERENCE_VALUES names another), so the figure a
/// reader sees cannot drift from the files.
#[test]
fn the_readme_states_the_regeneration_time_the_values_files_record() {
    let mut total = 0.0;
    for entry in std::fs::read_dir(root().join("reference/values")).expect("values folder") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|x| x == "json") {
            let v: Value =
                serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("JSON");
            total += v["run_seconds"]
                .as_f64()
                .unwrap_or_else(|| panic!("{} has no run_seconds", path.display()));
        }
    }
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README");
    let readme = readme.split_whitespace().collect::<Vec<_>>().join(" ");
    let said = format!("the committed ones add up to {total:.0} s");
    assert!(readme.contains(&said), "README lacks `{said}`");
}

/// The cross-check rows of the white furnace and of W-SS's coverage:
/// lightquad's converged value meets the closed form to 1e-12 (the W-SS
/// coverage was 3.4e-5 off when its pixel was integrated whole), and no
/// row is marked unverified where the closed form confirms it.
#[test]
fn cross_check_rows_with_a_closed_form_agree_and_are_verified() {
    use lightquad::experiment::reference::crosscheck;
    use lightquad::experiment::source::Origin;
    use lightquad::experiment::validate::validate_from;
    fn rows<F: Family>(name: &str) -> Vec<lightquad::experiment::reference::Crosscheck> {
        let text = std::fs::read_to_string(root().join(format!("experiments/{name}.json")))
            .expect("bundled");
        let exp = parse_json(&text)
            .and_then(deserialize::<F>)
            .and_then(|spec| validate_from::<F>(spec, &file_hash(text.as_bytes()), Origin::Bundled))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        crosscheck(&exp)
    }
    let mut all = rows::<Furnace>("mitsuba-r-furnace-bounces");
    all.extend(rows::<Whitted>("w-ss-edge-coverage"));
    let checked: Vec<_> = all.iter().filter(|r| r.lightquad.is_finite()).collect();
    assert!(checked.len() >= 3, "{all:?}");
    for r in checked {
        let closed = r
            .closed_form
            .unwrap_or_else(|| panic!("{r:?}: a closed form"));
        assert!(((r.lightquad - closed) / closed).abs() <= 1e-12, "{r:?}");
        assert!(r.verified, "{r:?}");
    }
}

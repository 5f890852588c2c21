//! The reference stage is bounded and priced at `check`: quantities a scene
//! cannot produce are refused at their path, a converged reference whose
//! first evaluations pass the job limits is refused at `reference.n`, and
//! the Mitsuba comparison evaluates lightquad's side only where it has a
//! Mitsuba value to set it beside.

use crate::common::{bin, root, scratch, stderr};
use serde_json::{Value as Json, json};

/// A bundled experiment, parsed.
fn bundled(name: &str) -> Json {
    let path = root().join("experiments").join(format!("{name}.json"));
    serde_json::from_str(&std::fs::read_to_string(path).expect("bundled file")).expect("JSON")
}

/// `lightquad check` of `spec` written to a scratch file: (exit code, stderr).
fn check(tag: &str, spec: &Json) -> (Option<i32>, String) {
    let dir = scratch(tag);
    let file = dir.join("e.json");
    std::fs::write(&file, serde_json::to_string_pretty(spec).expect("JSON")).expect("write");
    let out = bin().arg("check").arg(&file).output().expect("runs");
    (out.status.code(), stderr(&out))
}

#[test]
fn a_volume_term_the_scene_lacks_is_refused_at_its_quantity() {
    // Each quantity is identically 0 where its term is missing: I_L without a
    // light or without a medium to scatter it, I_E without emission, I_B
    // without a background. The probe's case ran every rule to 0 against a
    // reference of 0 and exited 0.
    let mut no_light = bundled("v-e-constant-sphere");
    no_light["quantities"] = json!(["I_E", "I_L"]);
    let mut no_medium = bundled("v-l-single-scattering");
    no_medium["scene"]
        .as_object_mut()
        .expect("scene")
        .remove("medium");
    let mut no_emission = bundled("v-l-single-scattering");
    no_emission["quantities"] = json!(["I_L", "I_E"]);
    let mut no_background = bundled("v-e-constant-sphere");
    no_background["quantities"] = json!(["I_B"]);
    for (tag, spec, at, why) in [
        ("no-light", &no_light, "quantities[1]", "no light"),
        ("no-medium", &no_medium, "quantities[0]", "no medium"),
        ("no-emission", &no_emission, "quantities[1]", "no emission"),
        (
            "no-background",
            &no_background,
            "quantities[0]",
            "no background",
        ),
    ] {
        let (code, err) = check(tag, spec);
        assert_eq!(code, Some(1), "{tag}: {err}");
        assert!(
            err.contains(&format!("at `{at}`")) && err.contains(why),
            "{tag}: {err}"
        );
    }
    // The bundled scenes with the term pass.
    for name in ["v-e-constant-sphere", "v-l-single-scattering"] {
        let (code, err) = check(name, &bundled(name));
        assert_eq!(code, Some(0), "{name}: {err}");
    }
}

#[test]
fn a_converged_reference_beyond_a_jobs_memory_is_refused_at_check() {
    // The furnace's converged evaluation integrates each hemisphere with
    // Genz–Malik at n^2 evaluations: at n = 1e5 that is 1e10 evaluations and
    // tens of GB. It passed `check`, ran every job and then failed without a
    // path.
    let mut spec = bundled("r-furnace-albedo-0999");
    spec["reference"] = json!({"type": "converged", "n": 100000});
    let (code, err) = check("furnace-n", &spec);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("at `reference.n`"), "{err}");
    // n = 64 (4096 evaluations a hemisphere) is far inside the limits.
    spec["reference"] = json!({"type": "converged", "n": 64});
    let (code, err) = check("furnace-64", &spec);
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn the_mitsuba_comparison_evaluates_lightquad_only_beside_a_mitsuba_value() {
    // An edited copy of a bundled Mitsuba experiment keeping its name has
    // stale values: its comparison rows say so, and lightquad's converged
    // value at n = 400 is not computed for them (a copy of the voxel grid
    // with every density 0 spent minutes on it). The unedited bytes find
    // their values and compute it.
    let name = "mitsuba-tau-constant-sphere";
    let bytes =
        std::fs::read(root().join("experiments").join(format!("{name}.json"))).expect("read");
    let mut edited: Json = serde_json::from_slice(&bytes).expect("JSON");
    edited["repeats"] = json!(1);
    let edited = serde_json::to_vec_pretty(&edited).expect("JSON");
    let computing = "computing lightquad's value for the Mitsuba comparison";
    for (tag, text, computes) in [("same", bytes, true), ("edited", edited, false)] {
        let dir = scratch(tag);
        let file = dir.join(format!("{name}.json"));
        std::fs::write(&file, &text).expect("write");
        let out = bin()
            .args(["run", "--out"])
            .arg(dir.join("out"))
            .arg(&file)
            .output()
            .expect("runs");
        let err = stderr(&out);
        assert!(out.status.success(), "{tag}: {err}");
        assert_eq!(err.contains(computing), computes, "{tag}: {err}");
        let report =
            std::fs::read_to_string(dir.join("out").join(name).join("report.md")).expect("report");
        assert_eq!(report.contains("is stale"), !computes, "{tag}");
        assert_eq!(
            report.contains("no Mitsuba value to compare"),
            !computes,
            "{tag}"
        );
    }
}

#[test]
fn a_rendering_reference_is_priced_by_its_blockers() {
    // The converged rendering reference integrates, for each light, the
    // light and what each blocker hides, every evaluation testing every
    // blocker: 100 n (1 + B)^2 a light. 1000 sphere blockers under a sky at
    // n = 400 and 800: 100 x 1200 x 1001^2 = 1.2e11 > 1e11, refused at
    // `reference.n` (priced as one integral, 3.6e7, it ran for more than
    // 400 s); 100 blockers: 1.2e9, accepted.
    let spec = |count: usize| {
        let occluders: Vec<Json> = (0..count)
            .map(|k| json!({"type": "sphere", "centre": [0.001 * k as f64, 5, 1], "radius": 0.01}))
            .collect();
        json!({"name": "mo", "family": "rendering",
            "scene": {"receiver": {"point": [0, 0, 0], "normal": [0, 0, 1]},
                      "emitters": [{"type": "environment", "radiance": 1.0}],
                      "occluders": occluders},
            "quantities": ["E_cosine"], "rules": [{"rule": "gauss-legendre"}], "budgets": [16],
            "repeats": 1, "reference": {"type": "converged"}})
    };
    let (code, err) = check("spheres-1000", &spec(1000));
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("at `reference.n`") && err.contains("1.2e11"),
        "{err}"
    );
    let (code, err) = check("spheres-100", &spec(100));
    assert_eq!(code, Some(0), "{err}");
}

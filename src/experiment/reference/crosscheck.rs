//! The "lightquad vs Mitsuba vs closed form" rows: every case the Mitsuba
//! harness covers, with its values beside lightquad's and the closed form.

use crate::experiment::source::{Origin, Values, find_values};
use crate::experiment::spec::{MitsubaReference, ReferenceSpec};
use crate::experiment::validate::Experiment;
use crate::family::{Family, Quantity};

use super::converged::converged_measured;
use super::mitsuba::not_values;
use super::relative_distance;

/// One row of the "lightquad vs Mitsuba vs closed form" comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Crosscheck {
    /// Experiment name.
    pub experiment: String,
    /// The quantity's name.
    pub quantity: &'static str,
    /// lightquad's converged value (the family's converged evaluation at
    /// [`CROSSCHECK_N`]); NaN where there is no Mitsuba value to compare it
    /// with, or it is not one number.
    pub lightquad: f64,
    /// False when that evaluation doubts its own error estimate and no
    /// closed form confirms it (to 1e-12): the table marks it unverified.
    pub verified: bool,
    /// Mitsuba's value and standard error, when it has one.
    pub mitsuba: Option<(f64, f64)>,
    /// The closed form, where the family has one.
    pub closed_form: Option<f64>,
    /// Why Mitsuba has no value, or that its file is stale.
    pub note: String,
}

/// The `n` of lightquad's converged value in the comparison.
pub const CROSSCHECK_N: usize = 400;

/// Whether the comparison evaluates lightquad's converged value (at
/// [`CROSSCHECK_N`]): where a Mitsuba values file made from this very file
/// is found, as [`crosscheck`] finds it.
pub fn compares(origin: &Origin, name: &str, hash: &str, named: Option<&str>) -> bool {
    matches!(find_values(origin, name, hash, named), Values::Found { .. })
}

/// Whether the experiment's name or description speaks of Mitsuba.
fn mentions_mitsuba<F: Family>(exp: &Experiment<F>) -> bool {
    [&exp.spec.name, &exp.spec.description]
        .iter()
        .any(|t| t.to_lowercase().contains("mitsuba"))
}

/// The bundled experiment with Mitsuba values whose scene `exp` has, under
/// another name.
fn copy_of_bundled<F: Family>(exp: &Experiment<F>) -> Option<String> {
    crate::experiment::source::bundled_experiments()
        .iter()
        .find_map(|(file, text)| {
            let name = file.strip_suffix(".json")?;
            if name == exp.spec.name || crate::experiment::source::bundled_values(name).is_none() {
                return None;
            }
            let spec = crate::experiment::validate::deserialize::<F>(
                crate::experiment::validate::parse_json(text).ok()?,
            )
            .ok()?;
            (spec.family == exp.spec.family && spec.scene == exp.spec.scene)
                .then(|| name.to_string())
        })
}

/// The comparison rows of an experiment with Mitsuba values (found as
/// [`find_values`] says: relative to the experiment file, or built into the
/// binary); none when it has none and none is expected. Values that are
/// expected but missing, or stale, give rows saying so, so the comparison
/// never silently disappears. Scalar quantities only (Mitsuba's files hold
/// scalars).
pub fn crosscheck<F: Family>(exp: &Experiment<F>) -> Vec<Crosscheck> {
    let named = match &exp.spec.reference {
        ReferenceSpec::Mitsuba(MitsubaReference { file }) => Some(file.as_str()),
        _ => None,
    };
    let (json, note) = match find_values(&exp.origin, &exp.spec.name, &exp.hash, named) {
        Values::NotExpected => match copy_of_bundled(exp) {
            // A renamed copy of a bundled Mitsuba experiment lost its values
            // (they are found by name and hash): said, not dropped.
            Some(bundled) => (
                serde_json::Value::Null,
                Some(format!(
                    "no Mitsuba values for `{}`: its scene is that of the bundled `{bundled}`, \
                     whose values belong to that file alone (values are found by the \
                     experiment's name and the hash of its file); make this file's with \
                     `cd reference && .venv/bin/python -m lqref --out DIR FILE`, DIR being \
                     `reference/values` beside the experiment's folder",
                    exp.spec.name
                )),
            ),
            // An experiment that says it is cross-checked against Mitsuba
            // (its name or description) but has no values: said, not
            // dropped (an edited, renamed copy of a bundled one).
            None if mentions_mitsuba(exp) => (
                serde_json::Value::Null,
                Some(format!(
                    "no Mitsuba values for `{}` (it names Mitsuba, but no values file was found \
                     for its name and file hash): make them with `cd reference && \
                     .venv/bin/python -m lqref --out DIR FILE`, DIR being `reference/values` \
                     beside the experiment's folder",
                    exp.spec.name
                )),
            ),
            None => return Vec::new(),
        },
        Values::Found { json, .. } => (json, None),
        Values::Stale {
            location,
            made_from,
            ..
        } => (
            serde_json::Value::Null,
            Some(format!(
                "values file {location} is stale (made from experiment hash {made_from}, this \
                 file hashes to {}; the hash is of the file's bytes: any edit counts, \
                 reformatting included): regenerate with scripts/reference.sh",
                exp.hash
            )),
        ),
        Values::NotValues { location, why } => {
            (serde_json::Value::Null, Some(not_values(&location, &why)))
        }
        Values::Missing { looked } => (
            serde_json::Value::Null,
            Some(format!(
                "MISSING: no Mitsuba values file found (looked for {}): generate it with \
                 scripts/reference.sh",
                looked.join(", ")
            )),
        ),
    };
    // lightquad's side is evaluated only where there is a Mitsuba value to
    // set it beside: a stale file's rows say so without it (an edited copy
    // of a bundled experiment, keeping its name, evaluated at n = 400
    // whatever its scene cost).
    let lightquad = if note.is_none() {
        crate::say!(
            "{}: computing lightquad's value for the Mitsuba comparison (the converged \
             evaluation at n = {CROSSCHECK_N})",
            exp.spec.name
        );
        converged_measured(exp, CROSSCHECK_N).unwrap_or_default()
    } else {
        Default::default()
    };
    let scalar = |v: Option<&Vec<f64>>| v.and_then(|v| (v.len() == 1).then(|| v[0]));
    exp.spec
        .quantities
        .iter()
        .map(|q| {
            let entry = &json["quantities"][q.name()];
            let mitsuba = match (entry["value"].as_f64(), entry["std_error"].as_f64()) {
                (Some(v), Some(se)) if note.is_none() => Some((v, se)),
                _ => None,
            };
            let note = note.clone().unwrap_or_else(|| {
                json["unsupported"][q.name()]
                    .as_str()
                    .unwrap_or("")
                    .to_string()
            });
            let value = scalar(lightquad.get(q).map(|m| &m.value)).unwrap_or(f64::NAN);
            let closed_form = scalar(F::closed_form(&exp.scene, *q).as_ref());
            let confirmed = closed_form.is_some_and(|c| relative_distance(&[value], &[c]) <= 1e-12);
            let trusted = lightquad
                .get(q)
                .is_none_or(|m| !m.flags.contains(&crate::family::Flag::UnreliableEstimate));
            Crosscheck {
                experiment: exp.spec.name.clone(),
                quantity: q.name(),
                lightquad: value,
                verified: confirmed || trusted,
                mitsuba,
                closed_form,
                note,
            }
        })
        .collect()
}

/// What the comparison's table shows, said above it in every report.
pub const CROSSCHECK_INTRO: &str = "Every case the Mitsuba harness (reference/) covers: \
     lightquad's converged value (the family's converged evaluation at n = 400, computed apart \
     from the experiment's reference), Mitsuba's value with its standard error (float32 \
     renderer: expect ~1e-6 relative at best), the closed form where one exists; where Mitsuba \
     has no value, the row says why.";

/// The comparison as a Markdown table.
pub fn crosscheck_markdown(rows: &[Crosscheck]) -> String {
    let mut md = String::from(
        "| experiment | quantity | lightquad (converged) | Mitsuba 3 +- std. error | closed form | lightquad - Mitsuba |\n\
         |---|---|---:|---:|---:|---|\n",
    );
    for r in rows {
        let mitsuba = r.mitsuba.map_or(format!("— {}", r.note), |(v, se)| {
            format!("{v:.10e} +- {se:.1e}")
        });
        let closed = r.closed_form.map_or("—".into(), |c| format!("{c:.10e}"));
        let agreement = match r.mitsuba {
            Some((v, se)) if se > 0.0 => format!("{:+.2} SE", (r.lightquad - v) / se),
            // 0 against 0 has no relative difference to show: an underflowed
            // value (tau at depth 1e5) is compared by its logarithm.
            Some((v, _)) if v == 0.0 && r.lightquad == 0.0 => {
                "both 0 in f64: no relative difference (an underflowed value is compared as its \
                 logarithm, ln_tau)"
                    .into()
            }
            Some((v, _)) => format!(
                "{:+.1e} relative (deterministic, float32)",
                relative_distance(&[r.lightquad], &[v]) * if r.lightquad >= v { 1.0 } else { -1.0 }
            ),
            None => "—".into(),
        };
        let unverified = if r.verified {
            ""
        } else {
            " (unverified: its evaluation doubts its own error estimate)"
        };
        // A colour or an image has no single number to show.
        let lightquad = if r.lightquad.is_finite() {
            format!("{:.10e}{unverified}", r.lightquad)
        } else if r.mitsuba.is_none() {
            "— (no Mitsuba value to compare)".to_string()
        } else {
            "— (not one number: a colour or an image)".to_string()
        };
        md.push_str(&format!(
            "| {} | {} | {lightquad} | {mitsuba} | {closed} | {agreement} |\n",
            r.experiment, r.quantity
        ));
    }
    md
}

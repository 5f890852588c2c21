//! Values from the Mitsuba 3 harness's values files (`reference/`), refused
//! when they were made from another experiment file or are not values.

use std::collections::BTreeMap;

use crate::error::SpecError;
use crate::family::Quantity;

use super::Known;

/// Reads a Mitsuba values file for an experiment whose file hashes to `hash`:
/// the value and standard error per quantity.
pub fn mitsuba_values<Q: Quantity>(
    path: &str,
    hash: &str,
    quantities: &[Q],
) -> Result<Known<Q>, SpecError> {
    let at = "reference.file";
    let text = crate::experiment::source::read_text(std::path::Path::new(path)).map_err(|e| {
        SpecError::at(
            at,
            format!("{path}: {e} (run scripts/reference.sh to generate it)"),
        )
    })?;
    let json = crate::experiment::source::values_json(&text)
        .map_err(|e| SpecError::at(at, format!("{path}: {e}")))?;
    let made_from = json["experiment_hash"].as_str().unwrap_or("");
    if made_from != hash {
        return Err(stale_values(path, made_from, hash));
    }
    values_from_json(path, &json, quantities)
}

/// Why the file a Mitsuba reference names is not a values file, with what
/// a values file is.
pub(super) fn not_values(location: &str, why: &str) -> String {
    if !why.starts_with("not JSON") {
        // Not a values file, or not a regular file: said with what is expected.
        format!("{location}: {why}")
    } else {
        format!(
            "{location} is not a Mitsuba values file ({why}): expected the JSON file \
             scripts/reference.sh writes, with `experiment_hash`, a string, and `quantities`, an \
             object of values"
        )
    }
}

pub(super) fn stale_values(path: &str, made_from: &str, hash: &str) -> SpecError {
    SpecError::at(
        "reference.file",
        format!(
            "{path} is stale: it was made from an experiment file with hash {made_from:?}, this one \
             hashes to {hash:?} (the hash is of the file's bytes: any edit counts, reformatting \
             included); regenerate it (scripts/reference.sh)"
        ),
    )
}

/// The value and standard error per quantity of a values file's JSON.
pub(super) fn values_from_json<Q: Quantity>(
    path: &str,
    json: &serde_json::Value,
    quantities: &[Q],
) -> Result<Known<Q>, SpecError> {
    let at = "reference.file";
    let mut values = BTreeMap::new();
    let mut worst = 0.0f64;
    for q in quantities {
        let entry = &json["quantities"][q.name()];
        let (Some(v), Some(se)) = (entry["value"].as_f64(), entry["std_error"].as_f64()) else {
            return Err(SpecError::at(
                at,
                format!(
                    "{path} has no value for quantity {} (Mitsuba cannot compute it here?)",
                    q.name()
                ),
            ));
        };
        let (lo, hi) = q.bounds();
        if !(lo..=hi).contains(&v) {
            return Err(SpecError::at(
                at,
                format!(
                    "{path} gives {} = {v}, which is not a value it can take: expected {}",
                    q.name(),
                    crate::family::bounds_in_words((lo, hi))
                ),
            ));
        }
        values.insert(*q, vec![v]);
        worst = worst.max(se);
    }
    Ok(Known {
        values,
        uncertainty: worst,
        note: format!(
            "Mitsuba 3 values from `{path}` ({} {}), largest standard error {worst:.1e} (float32 \
             renderer: ~1e-6 relative floor).",
            json["mitsuba_variant"].as_str().unwrap_or("?"),
            json["mitsuba_version"].as_str().unwrap_or("?")
        ),
    })
}

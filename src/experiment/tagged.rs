//! Internally tagged enums of experiment files (`{"type": "constant-sphere",
//! "radius": 1}`) read so that a fault inside a variant names its own JSON
//! path.
//!
//! serde's derived reader for such enums buffers the object before it knows
//! the variant and reads the variant from the buffer, which no path tracking
//! sees: `"kappa": "2.6"` was reported at `scene.medium`, not
//! `scene.medium.kappa`. Here the tag is taken first and the variant's fields
//! are read as a struct of their own, with their path tracked and handed up
//! (see [`SUB_PATH`]).
//!
//! ```
//! use lightquad::experiment::tagged::{split_tag, variant};
//! use serde_json::json;
//!
//! #[derive(serde::Deserialize)]
//! #[serde(deny_unknown_fields)]
//! struct Sphere { radius: f64 }
//!
//! let value = json!({"type": "sphere", "radius": "1"});
//! let (tag, fields) = split_tag::<serde_json::Error>(value, "type", &["sphere"])?;
//! assert_eq!(tag, "sphere");
//! let e = variant::<Sphere, serde_json::Error>(fields).err().expect("refused");
//! // The fault is named below the object, at `radius`.
//! assert!(e.to_string().starts_with("at `.radius`"), "{e}");
//! # Ok::<(), serde_json::Error>(())
//! ```

use serde::Deserialize;
use serde::de::{DeserializeOwned, Error};
use serde_json::Value;

/// Marks the start of a path below the current one in an error message
/// (`at `.outer`: ...`), which [`located`] moves into the error's JSON path.
pub const SUB_PATH: &str = "at `.";

/// Takes the tag `tag` (one of `names`) out of an object, leaving the other
/// fields; a value that is not an object, a missing tag or one not in
/// `names` is refused with every accepted name listed.
pub fn split_tag<E: Error>(value: Value, tag: &str, names: &[&str]) -> Result<(String, Value), E> {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    let quoted = quoted.join(", ");
    let accepted = || format!("expected one of {quoted}");
    let Value::Object(mut map) = value else {
        return Err(E::custom(format!(
            "{value} is not an object: expected {{\"{tag}\": <name>, ...}} with the name one of {quoted}"
        )));
    };
    match map.remove(tag) {
        None => Err(E::custom(format!("missing field `{tag}`: {}", accepted()))),
        Some(Value::String(name)) if names.contains(&name.as_str()) => {
            Ok((name, Value::Object(map)))
        }
        Some(other) => Err(below(
            tag,
            &format!("unknown variant {other}: {}", accepted()),
        )),
    }
}

/// Reads a variant's fields (the object without its tag) as `T`; a fault is
/// reported at its path below the object (`kappa`, `blobs[1].width`).
pub fn variant<T: DeserializeOwned, E: Error>(fields: Value) -> Result<T, E> {
    serde_path_to_error::deserialize(fields).map_err(|e| {
        let (path, message) = located(&e.path().to_string(), &e.inner().to_string());
        below(&path, &message)
    })
}

/// The path and message of an error that serde tracked to `path` (`.` for
/// the root), with a path below it that an inner reader put at the start of
/// the message (see [`below`]) moved into the path.
pub fn located(path: &str, message: &str) -> (String, String) {
    let mut path = if path == "." {
        String::new()
    } else {
        path.to_string()
    };
    let mut message = message.to_string();
    while let Some((inner, rest)) = message
        .strip_prefix(SUB_PATH)
        .and_then(|m| m.split_once("`: "))
    {
        path = if path.is_empty() {
            inner.to_string()
        } else if inner.starts_with('[') {
            format!("{path}{inner}")
        } else {
            format!("{path}.{inner}")
        };
        message = rest.to_string();
    }
    (path, message)
}

/// An error at `path` below the current one (empty: at it).
pub fn below<E: Error>(path: &str, message: &str) -> E {
    if path.is_empty() {
        E::custom(message)
    } else {
        E::custom(format!("{SUB_PATH}{path}`: {message}"))
    }
}

/// The fields of a variant that has none (`{"type": "closed-form"}`).
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoFields {}

/// Reads a fixed-length array (`[x, y, z]`) from a list whose length is
/// checked with the length named: serde's own reader says only "expected
/// fewer elements in array" for a list too long. For
/// `#[serde(deserialize_with = "...::array")]` on `[T; N]` fields.
pub fn array<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
where
    D: serde::Deserializer<'de>,
    T: serde::Deserialize<'de>,
{
    let items = Vec::<T>::deserialize(d)?;
    let len = items.len();
    items
        .try_into()
        .map_err(|_| D::Error::custom(format!("a list of {len} elements: expected exactly {N}")))
}

/// Reads a list of fixed-length arrays (`[[v, c], ...]`), a list of the
/// wrong length named at its index, as [`array()`] does.
pub fn arrays<'de, D, T, const N: usize>(d: D) -> Result<Vec<[T; N]>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: serde::Deserialize<'de>,
{
    let items = Vec::<Vec<T>>::deserialize(d)?;
    items
        .into_iter()
        .enumerate()
        .map(|(i, item)| {
            let len = item.len();
            item.try_into().map_err(|_| {
                below(
                    &format!("[{i}]"),
                    &format!("a list of {len} elements: expected exactly {N}"),
                )
            })
        })
        .collect()
}

/// Says what a number field accepts in words a user knows: serde names Rust
/// types (`expected f64`, `expected usize`).
pub fn plain_words(message: &str) -> String {
    let mut m = message.to_string();
    // A Rust struct's name means nothing to a user: "expected struct
    // SceneSpec" (or "... with 11 elements", when a list was given).
    if let Some(i) = m.find("expected struct ") {
        let head = m[..i].replace("invalid length", "a list of length");
        m = format!("{head}expected an object ({{\"field\": value, ...}})");
    }
    for (rust, words) in [
        ("expected f64", "expected a number"),
        ("expected f32", "expected a number"),
        ("expected i64", "expected a whole number"),
        ("expected i32", "expected a whole number"),
        ("expected usize", "expected a whole number >= 0"),
        ("expected u64", "expected a whole number >= 0"),
        ("expected u32", "expected a whole number >= 0"),
    ] {
        // The Rust type ends the message or is followed by a note.
        if let Some(head) = m.strip_suffix(rust) {
            m = format!("{head}{words}");
        } else {
            m = m.replace(&format!("{rust} "), &format!("{words} "));
        }
    }
    m
}

/// Reads a list that, when given, names at least one item (an optional list
/// field whose absence already means "none": `[]` is refused as a likely
/// slip rather than read as "none").
pub fn non_empty<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: serde::Deserialize<'de>,
{
    let items = Vec::<T>::deserialize(d)?;
    if items.is_empty() {
        return Err(D::Error::custom(
            "an empty list: name at least one item, or leave the field out",
        ));
    }
    Ok(items)
}

/// Reads a map whose keys are names of a kind (`{"tau": 0.5}`), a fault in
/// a key or a value named at that key (`values.tau`): serde's own reader
/// names a key it could not read as `?`.
pub fn keyed<'de, D, K, V>(d: D) -> Result<std::collections::BTreeMap<K, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    K: DeserializeOwned + Ord,
    V: DeserializeOwned,
{
    let map = serde_json::Map::<String, Value>::deserialize(d)?;
    map.into_iter()
        .map(|(name, value)| {
            let key = serde_json::from_value(Value::String(name.clone()))
                .map_err(|e| below(&name, &e.to_string()))?;
            let value =
                variant::<V, serde_json::Error>(value).map_err(|e| below(&name, &e.to_string()))?;
            Ok((key, value))
        })
        .collect()
}

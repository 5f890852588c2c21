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
        Some(other @ Value::String(_)) => Err(below(
            tag,
            &format!(
                "unknown variant {}: {}",
                crate::error::excerpt(&other.to_string()),
                accepted()
            ),
        )),
        Some(other) => Err(below(
            tag,
            &format!(
                "{}: expected a name in quotes, one of {quoted}",
                kind(&other)
            ),
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
    // A missing field is named at its own path (`scene.ray.origin`), not at
    // the object that lacks it; the message no longer starts "missing field",
    // so an outer level does not move it again.
    if let Some((field, rest)) = message
        .strip_prefix("missing field `")
        .and_then(|m| m.split_once('`'))
    {
        let field = field.to_string();
        message = format!("the required field `{field}` is missing{rest}");
        path = if path.is_empty() {
            field
        } else {
            format!("{path}.{field}")
        };
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
    // serde's names of JSON kinds, and of a number past the f64 range.
    m = m
        .replace("invalid type: map,", "invalid type: an object,")
        .replace("invalid type: sequence,", "invalid type: a list,")
        .replace("expected a sequence", "expected a list");
    // A file cut short (a truncated copy, a write that was killed).
    if let Some(rest) = m.strip_prefix("EOF while parsing ") {
        let (what, at) = rest.split_once(" at line").unwrap_or((rest, ""));
        let at = if at.is_empty() {
            String::new()
        } else {
            format!(" at line{at}")
        };
        m = format!("the file ends inside {what}{at}: is it cut short?");
    }
    if let Some(rest) = m.strip_prefix("number out of range") {
        m = format!(
            "a number beyond the f64 range (its magnitude is above 1.8e308){rest}: expected a \
             finite number"
        );
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

/// Reads a whole number into `T`, naming the range the field accepts,
/// `lo..=hi`, where a value `T` cannot hold is refused: serde said `expected
/// a whole number >= 0` of `"replicates": -1` (which accepts 2..=1000000) and
/// nothing of the range for 18446744073709551615 in `budgets`. A value `T`
/// holds is returned as it is, for the caller's own check of the range
/// (whose message names the field's meaning).
pub fn whole<'de, D, T>(d: D, lo: i128, hi: i128, note: &str) -> Result<T, D::Error>
where
    D: serde::Deserializer<'de>,
    T: TryFrom<i128>,
{
    struct Whole<'n, T> {
        lo: i128,
        hi: i128,
        note: &'n str,
        out: std::marker::PhantomData<T>,
    }
    impl<T: TryFrom<i128>> Whole<'_, T> {
        fn take<E: Error>(&self, x: i128, got: serde::de::Unexpected) -> Result<T, E> {
            T::try_from(x).map_err(|_| E::invalid_value(got, self))
        }
    }
    impl<'de, T: TryFrom<i128>> serde::de::Visitor<'de> for Whole<'_, T> {
        type Value = T;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            write!(
                f,
                "a whole number in {}..={}{}",
                self.lo, self.hi, self.note
            )
        }
        fn visit_i64<E: Error>(self, x: i64) -> Result<T, E> {
            self.take(x.into(), serde::de::Unexpected::Signed(x))
        }
        fn visit_u64<E: Error>(self, x: u64) -> Result<T, E> {
            self.take(x.into(), serde::de::Unexpected::Unsigned(x))
        }
        /// JSON has one kind of number: `1e5` is the whole number 100000
        /// (as JSON Schema's `integer` says), read where f64 holds it
        /// exactly; a larger one (`1e21`, or 1000000000000000000000, which
        /// the JSON reader gives as a float) is out of the range, not of
        /// the wrong kind.
        fn visit_f64<E: Error>(self, x: f64) -> Result<T, E> {
            const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
            let got = serde::de::Unexpected::Float(x);
            if x.fract() != 0.0 || !x.is_finite() {
                Err(E::invalid_type(got, &self))
            } else if x.abs() <= EXACT {
                self.take(x as i128, got)
            } else {
                Err(E::invalid_value(got, &self))
            }
        }
    }
    d.deserialize_any(Whole {
        lo,
        hi,
        note,
        out: std::marker::PhantomData,
    })
}

/// A count of at least 1 (voxels along an axis), read by [`whole`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Count(pub usize);

impl<'de> Deserialize<'de> for Count {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        // A bound a person can read (18446744073709551615 was printed):
        // data holds one value per voxel, so no file reaches 2^32 per axis.
        whole(
            d,
            1,
            i128::from(u32::MAX),
            " (their product is the length of data)",
        )
        .map(Count)
    }
}

/// Reads `[n_x, n_y, n_z]` counts of at least 1 (see [`array()`], [`Count`]).
pub fn counts<'de, D, const N: usize>(d: D) -> Result<[usize; N], D::Error>
where
    D: serde::Deserializer<'de>,
{
    let counts: [Count; N] = array(d)?;
    Ok(counts.map(|c| c.0))
}

/// Reads an object into `T` with a fault inside named at its own path (as
/// [`variant`]); anything else is refused as what it is: serde's derived
/// reader takes a list for a struct too, and `"scene": [1, 2]` was reported
/// at `scene[0]` as "expected string or map".
pub fn object<'de, D, T>(d: D) -> Result<T, D::Error>
where
    D: serde::Deserializer<'de>,
    T: DeserializeOwned,
{
    let value = Value::deserialize(d)?;
    if !value.is_object() {
        return Err(D::Error::custom(format!(
            "{}: expected an object ({{\"field\": value, ...}})",
            kind(&value)
        )));
    }
    variant(value)
}

/// [`object`] for an optional field (`null` is `None`).
pub fn optional_object<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: DeserializeOwned,
{
    match Value::deserialize(d)? {
        Value::Null => Ok(None),
        value => object(value).map(Some).map_err(D::Error::custom),
    }
}

/// What a JSON value is, with the value (shortened): `a list [1, 2]`.
pub fn kind(value: &Value) -> String {
    let what = match value {
        Value::Null => return "null".into(),
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "a list",
        Value::Object(_) => "an object",
    };
    format!("{what} {}", crate::error::excerpt(&value.to_string()))
}

/// The names a unit enum accepts, as serde lists them (`` `cumulative` or
/// `nested` ``, `` one of `tau`, `ln_tau`, ... ``), found by offering it a
/// name that no enum has.
fn accepted_names<T: DeserializeOwned>() -> String {
    let probe = Value::String("\u{0}".into());
    match serde_json::from_value::<T>(probe) {
        Err(e) => {
            let e = e.to_string();
            match e.split_once("expected ") {
                Some((_, names)) => names.to_string(),
                None => e,
            }
        }
        Ok(_) => "a name".into(),
    }
}

/// Reads one name of a unit enum (`"depth_scheme": "nested"`); a value that
/// is not a name is refused with the names listed (serde said only
/// "expected string or map").
pub fn named<'de, D, T>(d: D) -> Result<T, D::Error>
where
    D: serde::Deserializer<'de>,
    T: DeserializeOwned,
{
    let value = Value::deserialize(d)?;
    name_of(value).map_err(D::Error::custom)
}

fn name_of<T: DeserializeOwned>(value: Value) -> Result<T, String> {
    if !value.is_string() {
        return Err(format!(
            "{}: expected a name in quotes, {}",
            kind(&value),
            accepted_names::<T>()
        ));
    }
    serde_json::from_value(value).map_err(|e| e.to_string())
}

/// Reads a list of names of a unit enum (`"quantities": ["tau"]`), a fault
/// named at its index with the names listed (see [`named`]).
pub fn names<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: DeserializeOwned,
{
    let value = Value::deserialize(d)?;
    let Value::Array(items) = value else {
        return Err(D::Error::custom(format!(
            "{}: expected a list of names, each {}",
            kind(&value),
            accepted_names::<T>()
        )));
    };
    items
        .into_iter()
        .enumerate()
        .map(|(i, item)| name_of(item).map_err(|m| below(&format!("[{i}]"), &m)))
        .collect()
}

/// [`names`] for an optional list that, when given, names at least one item
/// (see [`non_empty`]).
pub fn non_empty_names<'de, D, T>(d: D) -> Result<Vec<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: DeserializeOwned,
{
    let items: Vec<T> = names(d)?;
    if items.is_empty() {
        return Err(D::Error::custom(
            "an empty list: name at least one item, or leave the field out",
        ));
    }
    Ok(items)
}

//! An experiment file's text to its typed spec: JSON syntax, numbers beyond
//! f64 refused, and every fault named by its JSON path.

use crate::error::SpecError;
use crate::experiment::spec::ExperimentSpec;
use crate::family::Family;

/// Parses the text of an experiment file as JSON (syntax only: the family's
/// format is checked by [`deserialize`]); a syntax error names the JSON path
/// it is in, and its line and column.
pub fn parse_json(text: &str) -> Result<serde_json::Value, SpecError> {
    parse_raw(text).map_err(|(path, e)| error_at(&path, &e))
}

/// [`parse_json`] with the JSON path and serde's error as they are.
fn parse_raw(text: &str) -> Result<serde_json::Value, (String, serde_json::Error)> {
    // Nothing but white space: said in words (serde says "EOF while parsing a
    // value at line 1 column 0").
    if text.trim().is_empty() {
        return Err((
            ".".into(),
            serde::de::Error::custom(
                "the file is empty: an experiment file is one JSON object (`lightquad schema` \
                 prints its format)",
            ),
        ));
    }
    // A byte-order mark (some editors on Windows write one): said in words
    // (serde says "expected value at line 1 column 1").
    if text.starts_with('\u{feff}') {
        return Err((
            ".".into(),
            serde::de::Error::custom(
                "the file starts with a byte-order mark (U+FEFF): save it as UTF-8 without one",
            ),
        ));
    }
    let de = &mut serde_json::Deserializer::from_str(text);
    // serde_path_to_error names a key it could not read (not a string) `?`:
    // the fault is then placed at the object that holds it.
    let Strict(json) = serde_path_to_error::deserialize(&mut *de).map_err(|e| {
        let path = e.path().to_string();
        let path = match path.strip_suffix('?') {
            Some(parent) => parent.trim_end_matches('.').to_string(),
            None => path,
        };
        let e = e.into_inner();
        // `Infinity` and `NaN` (what JavaScript and Python write) are no
        // JSON: said so, with the word, not "expected value".
        let word = not_json_number(text, e.line(), e.column());
        match word {
            Some(w) => (
                path,
                serde::de::Error::custom(format!(
                    "{w} at line {} column {} is not a JSON number (JSON has no infinities or \
                     NaN): expected a finite number",
                    e.line(),
                    e.column()
                )),
            ),
            None => (path, e),
        }
    })?;
    de.end().map_err(|e| {
        (
            ".".to_string(),
            serde::de::Error::custom(format!(
                "more after the experiment's JSON object at line {} column {}: a file holds one \
                 JSON object and nothing else",
                e.line(),
                e.column()
            )),
        )
    })?;
    Ok(json)
}

/// Marks a number beyond the f64 range, put in its place as a string by
/// [`parse_and_load`] so that the field's own reader says what it accepts.
const BEYOND_F64: &str = "lightquad-beyond-f64:";

/// Parses `text` and hands the JSON to `load` (the family's reader and
/// validation), with a number beyond the f64 range (`1e400`) named with the
/// range its field accepts: the JSON reader refuses such a number before
/// any field's reader sees it, and said only "expected a finite number" of
/// `"repeats": 1e400` (a whole number in 1..=1000). Each such number is
/// read as a marked string; the field's reader then refuses it, saying what
/// it expects, and the message is rewritten to name the number.
pub fn parse_and_load<T>(
    text: &str,
    load: impl FnOnce(serde_json::Value) -> Result<T, SpecError>,
) -> Result<T, SpecError> {
    let mut text = std::borrow::Cow::Borrowed(text);
    // The first number beyond the range, as the reader reported it.
    let mut first: Option<(SpecError, String, String)> = None;
    let json = loop {
        match parse_raw(&text) {
            Ok(json) => break json,
            Err((path, e)) => {
                let beyond = e.to_string().starts_with("number out of range");
                let at = (e.line(), e.column());
                let error = error_at(&path, &e);
                let Some((start, end)) = beyond.then(|| number_at(&text, at.0, at.1)).flatten()
                else {
                    return Err(first.map_or(error, |f| f.0));
                };
                let literal = text[start..end].to_string();
                let place = format!("line {} column {}", at.0, at.1);
                first.get_or_insert((error, literal.clone(), place));
                text = std::borrow::Cow::Owned(format!(
                    "{}\"{BEYOND_F64}{literal}\"{}",
                    &text[..start],
                    &text[end..]
                ));
            }
        }
    };
    let Some((original, literal, place)) = first else {
        return load(json);
    };
    match load(json) {
        Err(e) if e.message.contains(BEYOND_F64) => {
            let marked = format!("{BEYOND_F64}{literal}");
            let after = e
                .message
                .find(&marked)
                .map_or("", |i| &e.message[i + marked.len()..]);
            // serde's "..., expected X", or a check's "\"...\" is not X".
            let expected = after
                .find("expected ")
                .map(|i| after[i + "expected ".len()..].to_string())
                .or_else(|| after.strip_prefix("\" is not ").map(str::to_string))
                .filter(|x| !x.is_empty() && !x.contains(BEYOND_F64))
                .map_or("a finite number".to_string(), |x| {
                    if x == "a number" {
                        "a finite number".to_string()
                    } else {
                        x
                    }
                });
            Err(SpecError::at(
                e.path,
                format!(
                    "{} ({place}) is beyond the f64 range (its magnitude is above 1.8e308): \
                     expected {expected}",
                    crate::error::shortened(literal)
                ),
            ))
        }
        // The field took the marked string: it reads text (a name, a
        // description), and a number is none, however large.
        Ok(_) => Err(SpecError::at(
            original.path,
            format!(
                "{} ({place}) is a number (beyond the f64 range, its magnitude above 1.8e308): \
                 expected a string",
                crate::error::shortened(literal)
            ),
        )),
        // Another fault, a real one, came before the field was read.
        Err(other) => Err(other),
    }
}

/// The byte range of the number that ends at (or spans) 1-based `line` and
/// `column` of `text`, as serde_json reports the position of a number it
/// cannot hold.
fn number_at(text: &str, line: usize, column: usize) -> Option<(usize, usize)> {
    let line_start = if line <= 1 {
        0
    } else {
        text.match_indices('\n').nth(line - 2)?.0 + 1
    };
    let bytes = text.as_bytes();
    let is_number = |b: u8| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E');
    let mut end = (line_start + column).min(bytes.len());
    while end < bytes.len() && is_number(bytes[end]) {
        end += 1;
    }
    let mut start = end;
    while start > line_start && is_number(bytes[start - 1]) {
        start -= 1;
    }
    (start < end).then_some((start, end))
}

/// The non-JSON number word (`Infinity`, `-Infinity`, `NaN`, `inf`, `nan`)
/// at serde's `line`, `column` (1-based, at the word's first character or
/// just after a sign), if that is what stopped the reader.
fn not_json_number(text: &str, line: usize, column: usize) -> Option<&'static str> {
    let line_start = if line <= 1 {
        0
    } else {
        text.match_indices('\n').nth(line - 2)?.0 + 1
    };
    let at = (line_start + column.saturating_sub(1)).min(text.len());
    let from = text.get(at.saturating_sub(1)..)?;
    ["-Infinity", "Infinity", "NaN", "-inf", "inf", "nan"]
        .into_iter()
        .find(|w| from.starts_with(w) || from.get(1..).is_some_and(|t| t.starts_with(w)))
}

/// A JSON value read with a key given twice in an object refused (serde_json
/// would keep the last silently, and `{"rule": "trapezoid", "rule": "sobol"}`
/// would run Sobol').
struct Strict(serde_json::Value);

impl<'de> serde::Deserialize<'de> for Strict {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(StrictVisitor).map(Strict)
    }
}

struct StrictVisitor;

impl<'de> serde::de::Visitor<'de> for StrictVisitor {
    type Value = serde_json::Value;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, b: bool) -> Result<Self::Value, E> {
        Ok(b.into())
    }
    fn visit_i64<E>(self, n: i64) -> Result<Self::Value, E> {
        Ok(n.into())
    }
    fn visit_u64<E>(self, n: u64) -> Result<Self::Value, E> {
        Ok(n.into())
    }
    fn visit_f64<E>(self, x: f64) -> Result<Self::Value, E> {
        Ok(x.into())
    }
    fn visit_str<E>(self, s: &str) -> Result<Self::Value, E> {
        Ok(s.into())
    }
    fn visit_unit<E>(self) -> Result<Self::Value, E> {
        Ok(serde_json::Value::Null)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut items = Vec::new();
        while let Some(Strict(v)) = seq.next_element()? {
            items.push(v);
        }
        Ok(items.into())
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut object = serde_json::Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if object.contains_key(&key) {
                return Err(crate::experiment::tagged::below(
                    &key,
                    &format!("the key `{key}` appears twice in its object: give each key once"),
                ));
            }
            let Strict(v) = map.next_value()?;
            object.insert(key, v);
        }
        Ok(object.into())
    }
}

/// A serde error at its JSON path (`.` for the root).
fn path_error<E: std::fmt::Display>(e: serde_path_to_error::Error<E>) -> SpecError {
    error_at(&e.path().to_string(), e.inner())
}

/// A serde error `e` at JSON path `path` (`.` for the root), with a path
/// below it that an inner reader named moved into the path.
fn error_at(path: &str, e: &impl std::fmt::Display) -> SpecError {
    let (path, message) = crate::experiment::tagged::located(path, &e.to_string());
    let message = crate::experiment::tagged::plain_words(&message);
    SpecError::at(if path.is_empty() { ".".into() } else { path }, message)
}

/// Reads a parsed file as an experiment of family `F`, naming the JSON path
/// of any fault.
pub fn deserialize<F: Family>(json: serde_json::Value) -> Result<ExperimentSpec<F>, SpecError> {
    serde_path_to_error::deserialize(&json)
        .map_err(path_error)
        .map_err(|e| with_expected::<F>(e, &json))
}

/// A missing required field's error with what the field accepts, from the
/// family's schema: serde names only the field ("the required field
/// `radius` is missing").
fn with_expected<F: Family>(mut e: SpecError, json: &serde_json::Value) -> SpecError {
    if e.message.starts_with("the required field `") && !e.message.contains("expected") {
        let schema = schemars::schema_for!(ExperimentSpec<F>).to_value();
        if let Some(words) = crate::experiment::expected::describe(&schema, json, &e.path) {
            e.message = format!("{}: expected {words}", e.message);
        }
    }
    e
}

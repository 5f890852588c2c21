//! From a parsed [`ExperimentSpec`] to a runnable [`Experiment`]: every number
//! checked once, here, with the JSON path of the fault in the error. The
//! family checks its scene ([`Family::build`]); this module checks the rest,
//! and that every rule and estimator can compute every quantity asked for.
//!
//! ```
//! use lightquad::calibration::Calibration;
//! use lightquad::experiment::validate::{deserialize, parse_json, validate};
//!
//! let text = r#"{"name": "e", "family": "calibration", "scene": {}, "quantities": ["exp"],
//!   "rules": [{"rule": "gauss-legendre"}], "budgets": {"from": 2, "to": 32, "factor": 2},
//!   "reference": {"type": "closed-form"}}"#;
//! let exp = validate::<Calibration>(deserialize(parse_json(text)?)?, "hash")?;
//! // The range expands to its budgets; the closed form e - 1 is known before any run.
//! assert_eq!(exp.budgets, [2, 4, 8, 16, 32]);
//! let known = exp.known.as_ref().ok_or("no reference values")?;
//! let exact = known.values[&exp.spec.quantities[0]][0];
//! assert!((exact - (std::f64::consts::E - 1.0)).abs() < 1e-15);
//! // A fault names its JSON path.
//! let bad = text.replace("\"factor\": 2", "\"factor\": 1");
//! let e = validate::<Calibration>(deserialize(parse_json(&bad)?)?, "hash").err().ok_or("accepted")?;
//! assert!(e.to_string().contains("budgets.factor"), "{e}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::collections::BTreeMap;

use super::reference::{Known, known_values};
use super::source::Origin;
use super::spec::{Budgets, ExperimentSpec};
pub use crate::error::SpecError;
use crate::family::{Estimator, Family, Method, Quantity};
use crate::quadrature::Rule;

/// Largest budget accepted (per smooth piece).
pub const MAX_BUDGET: i64 = 100_000_000;

/// Most budgets a range may expand to.
const MAX_BUDGETS: usize = 200;

/// A validated experiment of family `F`, ready to run.
#[derive(Debug)]
pub struct Experiment<F: Family> {
    /// The file as parsed.
    pub spec: ExperimentSpec<F>,
    /// The scene, built.
    pub scene: F::Scene,
    /// The budgets, ascending.
    pub budgets: Vec<usize>,
    /// FNV-1a hash of the file's bytes.
    pub hash: String,
    /// Reference values known before running (closed forms, literals, Mitsuba
    /// values); a converged reference is computed when the report is written.
    pub known: Option<Known<F::Quantity>>,
    /// Where its file came from: Mitsuba values are looked for relative to it.
    pub origin: Origin,
}

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
                return Err(super::tagged::below(
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
    let (path, message) = super::tagged::located(path, &e.to_string());
    let message = super::tagged::plain_words(&message);
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
        if let Some(words) = super::expected::describe(&schema, json, &e.path) {
            e.message = format!("{}: expected {words}", e.message);
        }
    }
    e
}

/// Validates a parsed experiment whose file hashes to `hash`, as if its file
/// were in the working folder.
pub fn validate<F: Family>(
    spec: ExperimentSpec<F>,
    hash: &str,
) -> Result<Experiment<F>, SpecError> {
    validate_from(spec, hash, Origin::default())
}

/// Validates a parsed experiment whose file hashes to `hash` and came from
/// `origin` (a Mitsuba values file is looked for relative to it).
pub fn validate_from<F: Family>(
    spec: ExperimentSpec<F>,
    hash: &str,
    origin: Origin,
) -> Result<Experiment<F>, SpecError> {
    check_header::<F>(&spec)?;
    let scene = F::build(&spec.scene)?;
    for (k, q) in spec.quantities.iter().enumerate() {
        if let Some(why) = F::lacks(&scene, *q) {
            let at = format!("quantities[{k}]");
            return Err(SpecError::at(
                at,
                format!("{} cannot be computed in this scene: {why}", q.name()),
            ));
        }
    }
    check_methods::<F>(&spec, &scene)?;
    let budgets = budgets(&spec.budgets)?;
    // Budgets below a rule's minimum are skipped for that rule; a rule left
    // with none is an error, so no rule silently disappears.
    let largest = budgets.last().copied().unwrap_or(0);
    for (i, m) in spec.rules.iter().enumerate() {
        let need = min_budget::<F>(&scene, m, &spec.quantities);
        if largest < need {
            return Err(SpecError::at(
                "budgets",
                format!(
                    "no budget reaches what rules[{i}] ({}) needs: at least {need}",
                    m.name()
                ),
            ));
        }
    }
    check_cost::<F>(&spec, &scene, &budgets)?;
    let known = known_values::<F>(&spec, &scene, hash, &origin)?;
    Ok(Experiment {
        spec,
        scene,
        budgets,
        hash: hash.to_string(),
        known,
        origin,
    })
}

/// The smallest budget `method` needs for every quantity of the experiment.
pub fn min_budget<F: Family>(
    scene: &F::Scene,
    method: &Method<F::Estimator>,
    quantities: &[F::Quantity],
) -> usize {
    quantities
        .iter()
        .map(|q| method.min_budget(F::dimension(scene, *q)))
        .max()
        .unwrap_or(1)
}

/// The most integrand evaluations one job may cost by its family's estimate
/// ([`Family::cost`]): 1e11, minutes to hours at a nanosecond or more per
/// evaluation. `run --no-cost-limit` lifts it ([`lift_cost_limit`]).
pub const MAX_JOB_EVALUATIONS: f64 = 1e11;

/// The most bytes one job may hold by its family's estimate
/// ([`Family::memory`]): 4 GiB, so that the default of one job per core fits
/// a machine of 8 GiB a core (Gauss–Legendre at 1e8 nodes needs about 5.6
/// GB). `--no-cost-limit` lifts it too.
pub const MAX_JOB_BYTES: f64 = 4.0 * (1u64 << 30) as f64;

/// The most work a whole experiment may cost by its family's estimates
/// (every rule at every budget it runs, every repeat): 1e12 simple
/// evaluations, hours on a few cores. 300 rules at 185 budgets and 1000
/// repeats passed the per-job guard: 55 million jobs, 3e14 evaluations.
pub const MAX_EXPERIMENT_EVALUATIONS: f64 = 1e12;

/// The most jobs one experiment may have (rules x budgets x repeats).
pub const MAX_JOBS: f64 = 1e6;

/// The most bytes of results one experiment may write, estimated at 400
/// bytes a job and 48 a channel (value and error): 2 GB. An image of
/// 1024 x 1024 pixels wrote 106 MB of results.jsonl for a few jobs.
pub const MAX_RESULTS_BYTES: f64 = 2e9;

static COST_LIMIT_LIFTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Lets experiments whose jobs cost more than [`MAX_JOB_EVALUATIONS`] through
/// (the command line's `--no-cost-limit`), for this process.
pub fn lift_cost_limit() {
    COST_LIMIT_LIFTED.store(true, std::sync::atomic::Ordering::Relaxed);
}

/// Whether `--no-cost-limit` was passed ([`lift_cost_limit`]).
pub fn cost_limit_lifted() -> bool {
    COST_LIMIT_LIFTED.load(std::sync::atomic::Ordering::Relaxed)
}

/// Refuses an experiment whose costliest job (the largest budget each rule
/// runs at, every quantity) would pass [`MAX_JOB_EVALUATIONS`], with the
/// estimate: the nested depth scheme at a budget of 1e6 was accepted and ran
/// for about 22 hours.
fn check_cost<F: Family>(
    spec: &ExperimentSpec<F>,
    scene: &F::Scene,
    budgets: &[usize],
) -> Result<(), SpecError> {
    if cost_limit_lifted() {
        return Ok(());
    }
    // The converged reference runs before the report: adaptive
    // Gauss–Kronrod capped at 15 + 30 n evaluations a piece, at n and 2n at
    // least (then doubled until it converges; its tolerance usually stops it
    // far below the cap, so the cap of the first two evaluations is the
    // bound checked). A scene of radius 1e308 with n = 1e5 passed and ran
    // without end.
    if let super::spec::ReferenceSpec::Converged(c) = &spec.reference
        && let Ok(gk) = crate::quadrature::AnyRule::by_name("gauss-kronrod")
    {
        // Its range first: an n beyond it is refused whatever the cost limit
        // (the cost was reported first, and lifting the limit then met the
        // range).
        super::reference::check_converged_n(c.n)?;
        let budget = c.n.saturating_mul(60).saturating_add(15);
        let method = Method::Rule(gk);
        let cost: f64 = 1.5
            * spec
                .quantities
                .iter()
                .map(|&q| F::cost(scene, &method, budget, q))
                .sum::<f64>();
        if cost.is_nan() || cost > MAX_JOB_EVALUATIONS {
            return Err(SpecError::at(
                "reference.n",
                format!(
                    "the converged reference's first evaluations, at n = {} and {}, cost up \
                     to about {cost:.1e} integrand evaluations: expected at most \
                     {MAX_JOB_EVALUATIONS:.0e} (lower n, or pass --no-cost-limit to check and \
                     run to go ahead)",
                    c.n,
                    2 * c.n
                ),
            ));
        }
    }
    let Some(&largest) = budgets.last() else {
        return Ok(());
    };
    for (i, m) in spec.rules.iter().enumerate() {
        let cost: f64 = spec
            .quantities
            .iter()
            .map(|&q| F::cost(scene, m, largest, q))
            .sum();
        if cost.is_nan() || cost > MAX_JOB_EVALUATIONS {
            // Where even the least budget the rule runs at costs too much,
            // the scene makes the rule too dear (ratio tracking through a
            // blob of amplitude 1e307 collides about that often a walk):
            // lowering the budget, the advice given, could not help. (The
            // experiment's own smallest budget said so of any single budget.)
            let least = min_budget::<F>(scene, m, &spec.quantities);
            let at_least: f64 = spec
                .quantities
                .iter()
                .map(|&q| F::cost(scene, m, least, q))
                .sum();
            let advice = if at_least.is_nan() || at_least > MAX_JOB_EVALUATIONS {
                format!(
                    "even at budget {least} it costs about {at_least:.1e}, so this scene makes the \
                     rule too dear at any budget: remove rules[{i}] or change the scene (a \
                     tracking walk through a deep or loose majorant makes many look-ups)"
                )
            } else {
                "lower the budget".to_string()
            };
            return Err(SpecError::at(
                "budgets",
                format!(
                    "a job of rules[{i}] ({}) at budget {largest} costs about {cost:.1e} integrand \
                     evaluations: expected at most {MAX_JOB_EVALUATIONS:.0e} per job ({advice}, \
                     or pass --no-cost-limit to check and run to go ahead)",
                    m.label()
                ),
            ));
        }
        let bytes = spec
            .quantities
            .iter()
            .map(|&q| F::memory(scene, m, largest, q))
            .fold(0.0, f64::max);
        if bytes.is_nan() || bytes > MAX_JOB_BYTES {
            return Err(SpecError::at(
                "budgets",
                format!(
                    "a job of rules[{i}] ({}) at budget {largest} needs about {:.1} GB of memory: \
                     expected at most {:.1} GB per job (lower the budget, or pass --no-cost-limit \
                     to check and run to go ahead)",
                    m.label(),
                    bytes / 1e9,
                    MAX_JOB_BYTES / 1e9
                ),
            ));
        }
    }
    // The whole experiment: every rule at each budget it runs, every repeat.
    let repeats = spec.repeats as f64;
    let (mut jobs, mut total) = (0.0, 0.0);
    for m in &spec.rules {
        let need = min_budget::<F>(scene, m, &spec.quantities);
        for &b in budgets.iter().filter(|&&b| b >= need) {
            jobs += repeats;
            total += repeats
                * spec
                    .quantities
                    .iter()
                    .map(|&q| F::cost(scene, m, b, q))
                    .sum::<f64>();
        }
    }
    let channels: f64 = spec
        .quantities
        .iter()
        .map(|&q| F::channels(scene, q) as f64)
        .sum();
    let written = jobs * (400.0 + 48.0 * channels);
    let whole = "rules x budgets x repeats";
    let lower =
        "(fewer rules, budgets or repeats, or pass --no-cost-limit to check and run to go ahead)";
    if total.is_nan() || total > MAX_EXPERIMENT_EVALUATIONS {
        return Err(SpecError::at(
            "budgets",
            format!(
                "the experiment's {jobs:.0} jobs ({whole}) cost about {total:.1e} integrand \
                 evaluations in all: expected at most {MAX_EXPERIMENT_EVALUATIONS:.0e} {lower}"
            ),
        ));
    }
    if jobs > MAX_JOBS {
        return Err(SpecError::at(
            "budgets",
            format!(
                "the experiment has {jobs:.0} jobs ({whole}): expected at most {MAX_JOBS:.0e} {lower}"
            ),
        ));
    }
    if written > MAX_RESULTS_BYTES {
        return Err(SpecError::at(
            "budgets",
            format!(
                "the experiment's {jobs:.0} jobs of {channels:.0} channels each would write about \
                 {:.1} GB of results: expected at most {:.1} GB {lower}",
                written / 1e9,
                MAX_RESULTS_BYTES / 1e9
            ),
        ));
    }
    Ok(())
}

/// The longest experiment name: it names a folder, and file systems refuse
/// names past 255 bytes (a 300-character name passed `check` and failed the
/// run with an empty folder left).
pub const MAX_NAME: usize = 100;

/// Name, family tag, equation IDs, quantities, repeats and targets.
fn check_header<F: Family>(spec: &ExperimentSpec<F>) -> Result<(), SpecError> {
    let name_ok = !spec.name.is_empty()
        && spec.name.len() <= MAX_NAME
        && spec
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
    if !name_ok {
        return Err(SpecError::at(
            "name",
            format!(
                "{:?} is not a name of 1 to {MAX_NAME} letters, digits, '-' and '_' (it names the report's folder)",
                spec.name
            ),
        ));
    }
    if spec.family != F::NAME {
        return Err(SpecError::at(
            "family",
            format!("{:?} is not the family {:?}", spec.family, F::NAME),
        ));
    }
    for (i, id) in spec.equations.iter().enumerate() {
        if !F::EQUATIONS.contains(&id.as_str()) {
            return Err(SpecError::at(
                format!("equations[{i}]"),
                if F::EQUATIONS.is_empty() {
                    format!(
                        "unknown equation ID {id:?}: the family {} instantiates no equation of \
                         the documents; expected no `equations` (or an empty list)",
                        F::NAME
                    )
                } else {
                    format!(
                        "unknown equation ID {id:?} for family {}: expected one of {}",
                        F::NAME,
                        F::EQUATIONS.join(", ")
                    )
                },
            ));
        }
    }
    if spec.quantities.is_empty() {
        let all: Vec<_> = F::Quantity::all().iter().map(Quantity::name).collect();
        return Err(SpecError::at(
            "quantities",
            format!("an empty list: name at least one of {}", all.join(", ")),
        ));
    }
    for (i, q) in spec.quantities.iter().enumerate() {
        if spec.quantities[..i].contains(q) {
            return Err(SpecError::at(
                format!("quantities[{i}]"),
                format!("{} is named twice: name each quantity once", q.name()),
            ));
        }
    }
    if !(1..=1000).contains(&spec.repeats) {
        return Err(SpecError::at(
            "repeats",
            format!("{} is not an integer in 1..=1000", spec.repeats),
        ));
    }
    for (i, t) in spec.targets.iter().enumerate() {
        if !(t.is_finite() && *t > 0.0 && *t < 1.0) {
            return Err(SpecError::at(
                format!("targets[{i}]"),
                format!("{t} is not a relative error in (0, 1)"),
            ));
        }
    }
    Ok(())
}

/// Every rule's parameters, and that every rule and estimator can compute
/// every quantity asked for (a rule in the quantity's dimension; an
/// estimator only the quantities it estimates).
fn check_methods<F: Family>(spec: &ExperimentSpec<F>, scene: &F::Scene) -> Result<(), SpecError> {
    if spec.rules.is_empty() {
        return Err(SpecError::at(
            "rules",
            format!(
                "an empty list: name at least one of {}",
                Method::<F::Estimator>::names().join(", ")
            ),
        ));
    }
    for (i, method) in spec.rules.iter().enumerate() {
        let at = format!("rules[{i}]");
        match method {
            Method::Rule(rule) => {
                rule.check().map_err(|e| SpecError::from_quad(&at, e))?;
                for (k, q) in spec.quantities.iter().enumerate() {
                    let dim = F::dimension(scene, *q);
                    if !rule.dimensions().contains(dim) {
                        return Err(SpecError::at(
                            at,
                            format!(
                                "rule `{}` integrates in dimension {}, but quantities[{k}] ({}) is an \
                                 integral in dimension {dim} in family {}: use a rule for dimension {dim}",
                                rule.name(),
                                rule.dimensions(),
                                q.name(),
                                F::NAME
                            ),
                        ));
                    }
                }
            }
            Method::Estimator(e) => {
                F::check_estimator(e).map_err(|err| SpecError::from_quad(&at, err))?;
                let can = F::estimates(e);
                for (k, q) in spec.quantities.iter().enumerate() {
                    if !can.contains(q) {
                        let names: Vec<_> = can.iter().map(Quantity::name).collect();
                        return Err(SpecError::at(
                            at,
                            format!(
                                "estimator `{}` estimates only {}, but quantities[{k}] is {}: \
                                 give it an experiment of its own, or use a quadrature rule",
                                e.name(),
                                names.join(", "),
                                q.name()
                            ),
                        ));
                    }
                    if let Some(why) = F::refuses(scene, e, *q) {
                        return Err(SpecError::at(
                            at,
                            format!(
                                "estimator `{}` cannot estimate quantities[{k}] ({}) in this scene: {why}",
                                e.name(),
                                q.name()
                            ),
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}

/// The budgets, ascending and distinct.
fn budgets(spec: &Budgets) -> Result<Vec<usize>, SpecError> {
    let check = |path: String, n: i64| -> Result<usize, SpecError> {
        if (1..=MAX_BUDGET).contains(&n) {
            Ok(n as usize)
        } else {
            Err(SpecError::at(
                path,
                format!("{n} is not an integer in 1..={MAX_BUDGET}"),
            ))
        }
    };
    let mut out = match spec {
        Budgets::List(list) if list.is_empty() => {
            return Err(SpecError::at(
                "budgets",
                "an empty list: give at least one budget",
            ));
        }
        Budgets::List(list) => list
            .iter()
            .enumerate()
            .map(|(i, &n)| check(format!("budgets[{i}]"), n))
            .collect::<Result<Vec<_>, _>>()?,
        Budgets::Range(r) => {
            let from = check("budgets.from".into(), r.from)?;
            let to = check("budgets.to".into(), r.to)?;
            if to < from {
                return Err(SpecError::at(
                    "budgets.to",
                    format!("{to} is below from = {from}"),
                ));
            }
            geometric(from, to, r.factor)?
        }
    };
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

/// `from, from * factor, ... <= to`, each at least one above the last (so
/// factors near 1 still advance), at most [`MAX_BUDGETS`] of them.
fn geometric(from: usize, to: usize, factor: f64) -> Result<Vec<usize>, SpecError> {
    if !(factor.is_finite() && factor > 1.0) {
        return Err(SpecError::at(
            "budgets.factor",
            format!("{factor} is not a finite number > 1"),
        ));
    }
    let mut v = vec![from];
    loop {
        let last = v[v.len() - 1];
        let next = ((last as f64 * factor).round() as usize).max(last + 1);
        if next > to {
            return Ok(v);
        }
        if v.len() == MAX_BUDGETS {
            return Err(SpecError::at(
                "budgets.factor",
                format!(
                    "{factor} gives more than {MAX_BUDGETS} budgets from {from} to {to}: use a larger factor"
                ),
            ));
        }
        v.push(next);
    }
}

/// Literal reference values, checked: finite, one per quantity.
pub fn literal_values<Q: Quantity>(
    values: &BTreeMap<Q, super::spec::Literal>,
    quantities: &[Q],
    channels: impl Fn(Q) -> usize,
) -> Result<BTreeMap<Q, Vec<f64>>, SpecError> {
    // A value for a quantity the experiment does not ask for is a mistake
    // (a typo, or a quantity dropped from the list): refused, not ignored.
    if let Some(extra) = values.keys().find(|q| !quantities.contains(q)) {
        return Err(SpecError::at(
            format!("reference.values.{}", extra.name()),
            format!(
                "{} is not among the experiment's quantities ({}): remove it or add it to quantities",
                extra.name(),
                quantities
                    .iter()
                    .map(|q| q.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    let mut out = BTreeMap::new();
    for q in quantities {
        let Some(v) = values.get(q) else {
            return Err(SpecError::at(
                "reference.values",
                format!("no value for quantity {}", q.name()),
            ));
        };
        let at = format!("reference.values.{}", q.name());
        let got = v.channels();
        let want = channels(*q);
        if got.iter().any(|x| !x.is_finite()) {
            return Err(SpecError::at(at, format!("{got:?} is not finite")));
        }
        if got.len() != want {
            return Err(SpecError::at(
                at,
                format!(
                    "{} value(s) given, but {} has {want} channel(s): give {}",
                    got.len(),
                    q.name(),
                    if want == 1 {
                        "one number".to_string()
                    } else {
                        format!("a list of {want} numbers")
                    }
                ),
            ));
        }
        let (lo, hi) = q.bounds();
        if let Some((i, x)) = got
            .iter()
            .enumerate()
            .find(|(_, x)| !(lo..=hi).contains(*x))
        {
            let at = if let super::spec::Literal::Channels(_) = v {
                format!("{at}[{i}]")
            } else {
                at
            };
            return Err(SpecError::at(
                at,
                format!(
                    "{x} is not a value {} can take: expected {}",
                    q.name(),
                    crate::family::bounds_in_words((lo, hi))
                ),
            ));
        }
        out.insert(*q, got);
    }
    Ok(out)
}

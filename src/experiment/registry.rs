//! The families an experiment file may name, and the object-safe face of a
//! loaded experiment ([`Loaded`]) through which the runner, the reports and
//! `merge` handle every family alike.
//!
//! A [`Registry`] holds one [`FamilyEntry`] per family, made by
//! [`Registry::with`] from the family's type; [`crate::families::builtin`]
//! is the crate's own, and a user's family plugs in with one more `with`.
//!
//! ```
//! use lightquad::calibration::Calibration;
//! use lightquad::experiment::Registry;
//!
//! // A registry of one family; a family of your own plugs in the same way.
//! let registry = Registry::new().with::<Calibration>();
//! assert!(registry.get("calibration").is_some() && registry.get("volume").is_none());
//! let mut json = serde_json::json!({"name": "e", "family": "calibration", "scene": {},
//!     "quantities": ["exp"], "rules": [{"rule": "gauss-legendre"}], "budgets": [8],
//!     "repeats": 1, "reference": {"type": "closed-form"}});
//! let exp = registry.load(json.clone(), "hash")?;
//! // The loaded experiment hides its family: jobs run through the trait object.
//! assert_eq!(exp.family(), "calibration");
//! let jobs = exp.jobs(None); // (rule, budget, repeat)
//! assert_eq!(jobs, [(0, 8, 0)]);
//! let result = exp.run_job(jobs[0]);
//! assert!((result.quantities["exp"].value[0] - (std::f64::consts::E - 1.0)).abs() < 1e-15);
//! // A family the registry lacks is refused, naming those it has.
//! json["family"] = "volume".into();
//! let e = registry.load(json, "hash").err().ok_or("accepted")?;
//! assert!(e.to_string().contains("calibration"), "{e}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::Path;

use super::reference::{Crosscheck, crosscheck, reference};
use super::report::{Page, RuleInfo, Summary, write_experiment};
use super::run::{JobKey, JobResult, jobs, run_job};
use super::source::Origin;
use super::spec::ExperimentSpec;
use super::validate::{Experiment, deserialize, validate_from};
use crate::error::SpecError;
use crate::family::{Estimator, Family, Method, Quantity};

/// A loaded, validated experiment of any family.
pub trait Loaded: Send + Sync {
    /// Its name.
    fn name(&self) -> &str;
    /// What it shows.
    fn description(&self) -> &str;
    /// Its family's tag.
    fn family(&self) -> &'static str;
    /// The hash of its file.
    fn hash(&self) -> &str;
    /// Rules, budgets and repeats, for `check`.
    fn shape(&self) -> (usize, usize, usize);
    /// Its jobs, restricted to a shard.
    fn jobs(&self, shard: Option<(usize, usize)>) -> Vec<JobKey>;
    /// Runs one job.
    fn run_job(&self, key: JobKey) -> JobResult;
    /// Writes its report page from `results` into `dir`.
    fn write_report(&self, dir: &Path, results: &[JobResult]) -> Result<Written, String>;
    /// The `n` of a converged reference, which the report computes first
    /// (it can take longer than the jobs; the runner says so).
    fn converged_reference(&self) -> Option<usize>;
    /// Its estimated evaluations, as `check` prices them: its jobs' in all
    /// ([`super::validate::jobs_cost`]) and its reference stage's
    /// ([`super::validate::reference_cost`]).
    fn cost(&self) -> [f64; 2];
    /// Doubts about its scene that do not stop it ([`Family::warnings`]),
    /// each at its JSON path.
    fn warnings(&self) -> Vec<SpecError>;
    /// The memory the costliest of `jobs` holds by the family's estimate
    /// ([`Family::memory`], every quantity), in bytes: the runner refuses a
    /// job past a hard cap and runs fewer jobs at once where the machine
    /// cannot hold one per thread. Only the jobs still to run count (a
    /// `--resume` whose large jobs are finished was refused for them).
    fn max_job_bytes(&self, jobs: &[JobKey]) -> f64;
    /// The Mitsuba values file made from this experiment's bytes, where one
    /// was found ([`find_values`](super::source::find_values)): the run keeps
    /// a copy beside its results, so that `merge` of its folder finds it
    /// wherever the reference's relative path pointed.
    fn mitsuba_values(&self) -> Option<serde_json::Value>;
    /// The results read back that are results of its jobs, and how many
    /// were not ([`super::run::reusable`]).
    fn reusable(&self, results: Vec<JobResult>) -> (Vec<JobResult>, usize);
}

/// The bytes a job's result holds per channel while it is written: value
/// and error in memory (16) and as JSON text in a growing string (about 50,
/// up to twice that as it grows). An image of 1024 x 1024 pixels wrote a
/// line of tens of MB, and under an address-space cap of 300 MB the run
/// aborted allocating it.
pub const RESULT_BYTES_PER_CHANNEL: f64 = 128.0;

impl<F: Family> Loaded for Experiment<F> {
    fn name(&self) -> &str {
        &self.spec.name
    }
    fn description(&self) -> &str {
        &self.spec.description
    }
    fn family(&self) -> &'static str {
        F::NAME
    }
    fn hash(&self) -> &str {
        &self.hash
    }
    fn shape(&self) -> (usize, usize, usize) {
        (self.spec.rules.len(), self.budgets.len(), self.spec.repeats)
    }
    fn jobs(&self, shard: Option<(usize, usize)>) -> Vec<JobKey> {
        jobs(self, shard)
    }
    fn run_job(&self, key: JobKey) -> JobResult {
        run_job(self, key)
    }
    fn warnings(&self) -> Vec<SpecError> {
        F::warnings(&self.scene)
    }
    fn cost(&self) -> [f64; 2] {
        let named = match &self.spec.reference {
            super::spec::ReferenceSpec::Mitsuba(m) => Some(m.file.as_str()),
            _ => None,
        };
        let compared = super::reference::compares(&self.origin, &self.spec.name, &self.hash, named);
        [
            super::validate::jobs_cost(&self.spec, &self.scene, &self.budgets)[1],
            super::validate::reference_cost(&self.spec, &self.scene, compared),
        ]
    }
    fn max_job_bytes(&self, jobs: &[JobKey]) -> f64 {
        // Repeats hold the same memory: each (rule, budget) is costed once.
        let pairs: std::collections::BTreeSet<(usize, usize)> =
            jobs.iter().map(|&(m, n, _)| (m, n)).collect();
        pairs
            .into_iter()
            .filter_map(|(m, n)| {
                self.spec
                    .rules
                    .get(m)
                    .and_then(|rule| rule.own())
                    .map(|rule| (rule, n))
            })
            .flat_map(|(rule, n)| {
                self.spec
                    .quantities
                    .iter()
                    .map(move |&q| F::memory(&self.scene, rule, n, q))
            })
            .fold(0.0, f64::max)
            + RESULT_BYTES_PER_CHANNEL
                * self
                    .spec
                    .quantities
                    .iter()
                    .map(|&q| F::channels(&self.scene, q) as f64)
                    .sum::<f64>()
    }
    fn reusable(&self, results: Vec<JobResult>) -> (Vec<JobResult>, usize) {
        super::run::reusable(self, results)
    }
    fn mitsuba_values(&self) -> Option<serde_json::Value> {
        let named = match &self.spec.reference {
            super::spec::ReferenceSpec::Mitsuba(m) => Some(m.file.as_str()),
            _ => None,
        };
        match super::source::find_values(&self.origin, &self.spec.name, &self.hash, named) {
            super::source::Values::Found { json, .. } => Some(json),
            _ => None,
        }
    }
    fn converged_reference(&self) -> Option<usize> {
        match &self.spec.reference {
            super::spec::ReferenceSpec::Converged(c) => Some(c.n),
            _ => None,
        }
    }
    fn write_report(&self, dir: &Path, results: &[JobResult]) -> Result<Written, String> {
        let reference = reference(self);
        let crosscheck = crosscheck(self);
        let page = page(self, &reference, &crosscheck);
        let (summary, numbers) = write_experiment(dir, &page, results)?;
        let problems = reference
            .missing
            .iter()
            .map(|(q, why)| format!("{}: {q} has no reference ({why})", self.spec.name))
            .collect();
        Ok(Written {
            summary,
            numbers,
            crosscheck,
            problems,
        })
    }
}

/// What writing an experiment's report page gives the index.
#[derive(Debug, Clone)]
pub struct Written {
    /// Per quantity, each rule's time to the middle target.
    pub summary: Summary,
    /// What the page shows, for `summary.json`.
    pub numbers: super::report::ExperimentSummary,
    /// The Mitsuba comparison rows.
    pub crosscheck: Vec<Crosscheck>,
    /// What the page could not show (a quantity without a reference).
    pub problems: Vec<String>,
}

/// The report's view of an experiment.
fn page<'a, F: Family>(
    exp: &'a Experiment<F>,
    reference: &'a super::reference::Reference,
    crosscheck: &'a [Crosscheck],
) -> Page<'a> {
    let spec = &exp.spec;
    let rules = spec
        .rules
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let twice = spec.rules.iter().filter(|r| r.label() == m.label()).count() > 1;
            RuleInfo {
                label: if twice {
                    format!("{}#{i}", m.label())
                } else {
                    m.label()
                },
                is_random: m.is_random(),
                min_budget: spec
                    .quantities
                    .iter()
                    .map(|&q| {
                        let least = super::validate::quantity_min_budget::<F>(&exp.scene, m, q);
                        (q.name().to_string(), least)
                    })
                    .collect(),
                not_run: match exp.programs.get(&i) {
                    Some(super::external::Found::Skipped(why)) => {
                        Some(format!("its program is missing: {why}"))
                    }
                    _ => None,
                },
                resolution: spec
                    .quantities
                    .iter()
                    .map(|&q| F::dimension(&exp.scene, q))
                    .map(|d| {
                        let by_budget = exp
                            .budgets
                            .iter()
                            .map(|&b| (b, m.resolution(b, d)))
                            .collect();
                        (d, by_budget)
                    })
                    .collect(),
            }
        })
        .collect();
    Page {
        name: &spec.name,
        hash: &exp.hash,
        description: &spec.description,
        family: F::NAME,
        equations: &spec.equations,
        budgets: &exp.budgets,
        budget_unit: F::BUDGET_UNIT,
        over_budget: F::OVER_BUDGET,
        repeats: spec.repeats,
        seed: spec.seed,
        settings: F::settings(&spec.scene),
        quantities: spec.quantities.iter().map(Quantity::name).collect(),
        dimensions: spec
            .quantities
            .iter()
            .map(|&q| F::dimension(&exp.scene, q))
            .collect(),
        displays: spec.quantities.iter().map(|&q| F::display(q)).collect(),
        images: spec
            .quantities
            .iter()
            .map(|&q| F::image(&exp.scene, q))
            .collect(),
        rules,
        targets: &spec.targets,
        reference,
        crosscheck,
        scene_audit: F::scene_audit(&exp.scene),
    }
}

type LoadFn = fn(serde_json::Value, &str, Origin) -> Result<Box<dyn Loaded>, SpecError>;

/// What the runner and the CLI know of a family.
#[derive(Clone)]
pub struct FamilyEntry {
    /// The tag in experiment files.
    pub name: &'static str,
    /// One line on what it covers.
    pub about: &'static str,
    /// Its equation IDs.
    pub equations: &'static [&'static str],
    load: LoadFn,
    schema: fn() -> schemars::Schema,
    estimators: fn() -> Vec<(&'static str, &'static str)>,
    quantities: fn() -> Vec<&'static str>,
    audit: fn() -> Option<String>,
}

impl FamilyEntry {
    fn of<F: Family>() -> Self {
        FamilyEntry {
            name: F::NAME,
            about: F::ABOUT,
            equations: F::EQUATIONS,
            load: |json, hash, origin| {
                Ok(Box::new(validate_from::<F>(
                    deserialize::<F>(json)?,
                    hash,
                    origin,
                )?))
            },
            schema: || schemars::schema_for!(ExperimentSpec<F>),
            estimators: || {
                F::Estimator::all()
                    .iter()
                    .map(|e| (e.name(), e.about()))
                    .collect()
            },
            quantities: || F::Quantity::all().iter().map(Quantity::name).collect(),
            audit: F::audit,
        }
    }

    /// The family's estimators beside the rules: name and one line each.
    pub fn estimators(&self) -> Vec<(&'static str, &'static str)> {
        (self.estimators)()
    }

    /// The family's quantities.
    pub fn quantities(&self) -> Vec<&'static str> {
        (self.quantities)()
    }

    /// The JSON Schema of the family's experiment files.
    pub fn schema(&self) -> schemars::Schema {
        (self.schema)()
    }

    /// The family's audit of printed formulas, as Markdown.
    pub fn audit(&self) -> Option<String> {
        (self.audit)()
    }
}

/// The families an experiment file may name.
#[derive(Clone, Default)]
pub struct Registry {
    entries: Vec<FamilyEntry>,
}

impl Registry {
    /// A registry with no family.
    pub fn new() -> Self {
        Registry::default()
    }

    /// This registry and family `F` (replacing one of the same name).
    pub fn with<F: Family>(mut self) -> Self {
        self.entries.retain(|e| e.name != F::NAME);
        self.entries.push(FamilyEntry::of::<F>());
        self
    }

    /// Every family, in registration order.
    pub fn entries(&self) -> &[FamilyEntry] {
        &self.entries
    }

    /// The family named `name`.
    pub fn get(&self, name: &str) -> Option<&FamilyEntry> {
        self.entries.iter().find(|e| e.name == name)
    }

    /// Reads a parsed experiment file by its `family` tag and validates it, as
    /// if its file were in the working folder.
    pub fn load(&self, json: serde_json::Value, hash: &str) -> Result<Box<dyn Loaded>, SpecError> {
        self.load_from(json, hash, Origin::default())
    }

    /// Reads a parsed experiment file that came from `origin` by its `family`
    /// tag and validates it.
    pub fn load_from(
        &self,
        json: serde_json::Value,
        hash: &str,
        origin: Origin,
    ) -> Result<Box<dyn Loaded>, SpecError> {
        let names: Vec<&str> = self.entries.iter().map(|e| e.name).collect();
        let accepted = format!("expected one of {}", names.join(", "));
        if !json.is_object() {
            return Err(SpecError::at(
                ".",
                format!(
                    "an experiment file is a JSON object, not {} ({})",
                    json_kind(&json),
                    crate::error::excerpt(&json.to_string())
                ),
            ));
        }
        let tag = match json.get("family") {
            None => return Err(SpecError::at("family", format!("missing: {accepted}"))),
            Some(serde_json::Value::String(s)) => s.clone(),
            Some(other) => {
                return Err(SpecError::at(
                    "family",
                    format!(
                        "{} is not a family name: {accepted}",
                        crate::error::excerpt(&other.to_string())
                    ),
                ));
            }
        };
        let Some(entry) = self.get(&tag) else {
            return Err(SpecError::at(
                "family",
                format!("unknown family {tag:?}: {accepted}"),
            ));
        };
        (entry.load)(json, hash, origin)
    }

    /// The JSON Schema (2020-12) of experiment files: one of the families'
    /// schemas, told apart by the constant `family`; each family's
    /// definitions are kept under `$defs/<family>.<name>`.
    pub fn schema(&self) -> serde_json::Value {
        let mut defs = serde_json::Map::new();
        let mut branches = Vec::new();
        for e in &self.entries {
            let mut branch = e.schema().to_value();
            prefix_refs(&mut branch, e.name);
            let Some(object) = branch.as_object_mut() else {
                continue;
            };
            if let Some(serde_json::Value::Object(own)) = object.remove("$defs") {
                defs.extend(own.into_iter().map(|(k, v)| (format!("{}.{k}", e.name), v)));
            }
            object.remove("$schema");
            object.insert("title".into(), format!("{} experiment", e.name).into());
            branch["properties"]["family"] =
                serde_json::json!({ "const": e.name, "description": e.about });
            branch["properties"]["name"]["pattern"] =
                format!("^[A-Za-z0-9_-]{{1,{}}}$", super::validate::MAX_NAME).into();
            // The family's own equation IDs, as `check` accepts them; none
            // where it instantiates no equation of the documents.
            branch["properties"]["equations"]["items"] = if e.equations.is_empty() {
                serde_json::json!(false)
            } else {
                serde_json::json!({ "enum": e.equations })
            };
            branches.push(branch);
        }
        for v in defs.values_mut().chain(branches.iter_mut()) {
            closed_objects(v);
        }
        serde_json::json!({
            "$schema": "https://json-schema.org/draft/2020-12/schema",
            "title": "lightquad experiment",
            "description": "An experiment file; `family` decides the format of `scene`, `quantities` and the family's estimators in `rules`.",
            "oneOf": branches,
            "$defs": defs,
        })
    }

    /// Every rule and every family's estimators: name and one line each.
    pub fn methods(&self) -> Vec<(String, &'static str)> {
        let mut out: Vec<(String, &'static str)> = crate::quadrature::AnyRule::listing()
            .into_iter()
            .map(|(n, a)| (n.to_string(), a))
            .collect();
        for e in &self.entries {
            for (n, a) in e.estimators() {
                out.push((format!("{n} ({} family)", e.name), a));
            }
        }
        out
    }
}

/// Marks every object schema below `v` that lists its properties as closed
/// (`"additionalProperties": false`), as `check` reads every object (unknown
/// fields are refused): a variant without fields of its own (`{"rule":
/// "trapezoid"}`) was open, so the schema accepted `{"rule": "trapezoid",
/// "foo": 1}`, which `check` refuses. The schema composes no object from
/// parts (no `allOf`), so closing each is exact.
fn closed_objects(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(map) => {
            if map.contains_key("properties") && !map.contains_key("additionalProperties") {
                map.insert("additionalProperties".into(), false.into());
            }
            map.values_mut().for_each(closed_objects);
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(closed_objects),
        _ => {}
    }
}

/// Rewrites every `{"$ref": "#/$defs/X"}` below `v` to `#/$defs/<family>.X`.
fn prefix_refs(v: &mut serde_json::Value, family: &str) {
    match v {
        serde_json::Value::Object(map) => {
            for (key, child) in map.iter_mut() {
                match child {
                    serde_json::Value::String(target) if key == "$ref" => {
                        if let Some(name) = target.strip_prefix("#/$defs/") {
                            *target = format!("#/$defs/{family}.{name}");
                        }
                    }
                    _ => prefix_refs(child, family),
                }
            }
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(|c| prefix_refs(c, family)),
        _ => {}
    }
}

/// Method names for a family, for messages.
pub fn method_names<F: Family>() -> Vec<&'static str> {
    Method::<F::Estimator>::names()
}

/// What kind of JSON value `json` is, in words.
fn json_kind(json: &serde_json::Value) -> &'static str {
    match json {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::Object(_) => "an object",
    }
}

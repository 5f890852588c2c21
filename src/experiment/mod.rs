//! Experiments: JSON files that describe a scene, the quantities to compute,
//! the rules and budgets to compare and a reference; runs that write one JSON
//! line per job; and reports of error against run time.
//!
//! Data flow: file -> [`spec`] (serde, unknown fields rejected, JSON paths in
//! errors) -> [`validate`](mod@validate) (every number checked, the scene built) -> [`run`](mod@run)
//! (jobs in parallel, results appended as they finish) -> [`report`] (Markdown,
//! SVG, CSV, index). The built-in studies ([`core_study`], [`volume_study`])
//! are the `lightquad study` command.

pub mod core_study;
pub mod fit;
pub mod report;
pub mod run;
pub mod spec;
pub mod validate;
pub mod volume_study;

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use rand::SeedableRng;

use run::{JobResult, RunOptions, file_hash, read_results, run_experiment, write_atomic};
use spec::Quantity;
use validate::{Experiment, SpecError, parse, validate};

use crate::quadrature::GaussLegendre;
use crate::volume::evaluate;

/// An error of a run, naming the file (and the JSON path when it is a spec fault).
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// A fault in an experiment file.
    #[error("{file}: {source}")]
    Spec {
        /// The file.
        file: String,
        /// The fault.
        source: SpecError,
    },
    /// Jobs failed (their reasons are in the report); the report was written.
    #[error("{failed} of {total} jobs failed (reasons in the report: {index})")]
    Failed {
        /// Failed jobs.
        failed: usize,
        /// All jobs.
        total: usize,
        /// The report's index page.
        index: String,
    },
    /// A file or folder that cannot be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The path.
        path: String,
        /// What went wrong.
        message: String,
    },
}

fn io(path: &Path, e: impl std::fmt::Display) -> RunError {
    RunError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Reads, parses and validates one experiment file; returns it with its hash.
pub fn load(path: &Path) -> Result<(Experiment, String), RunError> {
    let bytes = fs::read(path).map_err(|e| io(path, e))?;
    let text = String::from_utf8(bytes.clone()).map_err(|e| io(path, format!("not UTF-8: {e}")))?;
    let spec_error = |source| RunError::Spec {
        file: path.display().to_string(),
        source,
    };
    let mut exp = validate(parse(&text).map_err(spec_error)?).map_err(spec_error)?;
    let hash = file_hash(&bytes);
    if let spec::ReferenceSpec::Mitsuba { file } = &exp.spec.reference {
        let (values, uncertainty, _) =
            validate::mitsuba_reference(file, &hash, &exp.spec.quantities).map_err(spec_error)?;
        exp.reference = values;
        exp.uncertainty = uncertainty;
    }
    Ok((exp, hash))
}

/// The experiment files of a folder, sorted.
pub fn experiment_files(dir: &Path) -> Result<Vec<PathBuf>, RunError> {
    let mut files: Vec<PathBuf> = fs::read_dir(dir)
        .map_err(|e| io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json") && !p.ends_with("schema.json"))
        .collect();
    files.sort();
    Ok(files)
}

/// The reference values of an experiment and a sentence on where they come
/// from; a converged reference is computed here, and its own convergence
/// (n against 2n nodes) is reported.
/// The reference values of an experiment, a sentence on where they come from,
/// and their relative accuracy (errors below it are not resolved).
pub fn reference(exp: &Experiment) -> (BTreeMap<Quantity, f64>, String, f64) {
    let (values, note) = reference_values(exp);
    // Relative accuracy: the stated uncertainty against the smallest reference
    // magnitude; for a converged reference, its change from n to 2n nodes.
    let smallest = values
        .values()
        .map(|v| v.abs())
        .filter(|v| *v > 0.0)
        .fold(f64::INFINITY, f64::min);
    let mut accuracy = if smallest.is_finite() {
        exp.uncertainty / smallest
    } else {
        0.0
    };
    if let spec::ReferenceSpec::Converged { .. } = exp.spec.reference {
        accuracy = accuracy.max(converged_change(&note));
    }
    (values, note, accuracy)
}

/// The relative change recorded in a converged reference's note.
fn converged_change(note: &str) -> f64 {
    note.split("change is ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.0)
}

/// Every quantity of the experiment by Gauss–Legendre with `n` nodes per
/// graded piece (cumulative depth, closed-form shadow rays where available):
/// the converged reference and lightquad's column in the Mitsuba comparison.
pub fn converged_values(exp: &Experiment, n: usize) -> BTreeMap<Quantity, f64> {
    let rule = GaussLegendre {
        error_estimate: false,
    };
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0);
    let mut job = JobResult::empty();
    if let Ok(res) = evaluate(
        &exp.scene,
        &rule,
        n,
        crate::volume::DepthScheme::Cumulative,
        crate::volume::ShadowMethod::ClosedFormWhereAvailable,
        &mut rng,
    ) {
        run::collect_into(&res, &exp.spec.quantities, &mut job);
    }
    job.values
}

fn reference_values(exp: &Experiment) -> (BTreeMap<Quantity, f64>, String) {
    match &exp.spec.reference {
        spec::ReferenceSpec::ClosedForm {} => (
            exp.reference.clone(),
            "closed forms (`lightquad::exact`).".into(),
        ),
        spec::ReferenceSpec::Mitsuba { file } => (
            exp.reference.clone(),
            format!(
                "Mitsuba 3 values from `{file}`, largest standard error {:.1e} (float32 renderer: ~1e-6 relative floor).",
                exp.uncertainty
            ),
        ),
        spec::ReferenceSpec::Value { uncertainty, .. } => (
            exp.reference.clone(),
            format!("literal values, uncertainty {uncertainty:e}."),
        ),
        spec::ReferenceSpec::Converged { n } => {
            let (a, b) = (converged_values(exp, *n), converged_values(exp, 2 * n));
            let worst = exp
                .spec
                .quantities
                .iter()
                .filter_map(|q| {
                    let (x, y) = (a.get(q)?, b.get(q)?);
                    Some(if *y != 0.0 {
                        ((x - y) / y).abs()
                    } else {
                        (x - y).abs()
                    })
                })
                .fold(0.0, f64::max);
            let verdict = if worst <= 1e-12 {
                "converged"
            } else {
                "NOT converged: treat errors below this with suspicion"
            };
            (
                b,
                format!(
                    "Gauss–Legendre with {} nodes per piece; against {n} nodes the largest relative change is {worst:.1e} ({verdict}).",
                    2 * n
                ),
            )
        }
    }
}

/// One row of the "lightquad vs Mitsuba vs closed form" comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct Crosscheck {
    /// Experiment name.
    pub experiment: String,
    /// The quantity.
    pub quantity: Quantity,
    /// lightquad's converged value (Gauss–Legendre, 400 nodes per graded piece).
    pub lightquad: f64,
    /// Mitsuba's value and standard error, when it has one.
    pub mitsuba: Option<(f64, f64)>,
    /// The closed form, where `exact` has one.
    pub closed_form: Option<f64>,
    /// Why Mitsuba has no value, or that its file is stale.
    pub note: String,
}

/// The comparison rows of an experiment that has a Mitsuba values file in
/// `reference/values/<name>.json` (relative to the working folder); none otherwise.
pub fn crosscheck(exp: &Experiment, hash: &str) -> Vec<Crosscheck> {
    let path = Path::new("reference/values").join(format!("{}.json", exp.spec.name));
    let Ok(text) = fs::read_to_string(&path) else {
        return Vec::new();
    };
    let Ok(json) = serde_json::from_str::<serde_json::Value>(&text) else {
        return Vec::new();
    };
    let stale = json["experiment_hash"].as_str() != Some(hash);
    let lightquad = converged_values(exp, 400);
    exp.spec
        .quantities
        .iter()
        .map(|q| {
            let entry = &json["quantities"][q.name()];
            let mitsuba = match (entry["value"].as_f64(), entry["std_error"].as_f64()) {
                (Some(v), Some(se)) if !stale => Some((v, se)),
                _ => None,
            };
            let note = if stale {
                "values file is stale (experiment changed): regenerate with scripts/reference.sh"
                    .into()
            } else {
                json["unsupported"][q.name()]
                    .as_str()
                    .unwrap_or("")
                    .to_string()
            };
            Crosscheck {
                experiment: exp.spec.name.clone(),
                quantity: *q,
                lightquad: lightquad.get(q).copied().unwrap_or(f64::NAN),
                mitsuba,
                closed_form: validate::closed_form(&exp.spec, &exp.scene, *q),
                note,
            }
        })
        .collect()
}

/// The comparison as a Markdown table.
pub fn crosscheck_markdown(rows: &[Crosscheck]) -> String {
    let mut md = String::from(
        "| experiment | quantity | lightquad (GL, 400 nodes per piece) | Mitsuba 3 +- std. error | closed form | lightquad - Mitsuba |\n\
         |---|---|---:|---:|---:|---|\n",
    );
    for r in rows {
        let mitsuba = r.mitsuba.map_or(format!("— {}", r.note), |(v, se)| {
            format!("{v:.10e} +- {se:.1e}")
        });
        let closed = r.closed_form.map_or("—".into(), |c| format!("{c:.10e}"));
        let agreement = match r.mitsuba {
            Some((v, se)) if se > 0.0 => format!("{:+.2} SE", (r.lightquad - v) / se),
            Some((v, _)) => format!(
                "{:+.1e} relative (deterministic, float32)",
                if v != 0.0 {
                    (r.lightquad - v) / v
                } else {
                    r.lightquad - v
                }
            ),
            None => "—".into(),
        };
        md.push_str(&format!(
            "| {} | {} | {:.10e} | {mitsuba} | {closed} | {agreement} |\n",
            r.experiment,
            r.quantity.name(),
            r.lightquad
        ));
    }
    md
}

/// Runs experiment files and writes their reports under `opts.out`.
/// Every file is validated and the output folder checked before any job runs,
/// so a bad input leaves nothing behind.
pub fn run_files(files: &[PathBuf], opts: &RunOptions) -> Result<PathBuf, RunError> {
    let loaded: Vec<(Experiment, String, PathBuf, Vec<u8>)> = files
        .iter()
        .map(|f| {
            let bytes = fs::read(f).map_err(|e| io(f, e))?;
            load(f).map(|(e, h)| (e, h, f.clone(), bytes))
        })
        .collect::<Result<_, _>>()?;
    let mut names = std::collections::BTreeSet::new();
    for (e, _, f, _) in &loaded {
        if !names.insert(e.spec.name.clone()) {
            return Err(RunError::Spec {
                file: f.display().to_string(),
                source: SpecError::at(
                    "name",
                    format!(
                        "{:?} is used by another experiment in this run",
                        e.spec.name
                    ),
                ),
            });
        }
    }
    fs::create_dir_all(&opts.out).map_err(|e| io(&opts.out, e))?;
    let probe = opts
        .out
        .join(format!(".lightquad-write-probe-{}", std::process::id()));
    write_atomic(&probe, b"").map_err(|e| io(&opts.out, format!("not writable: {e}")))?;
    let _ = fs::remove_file(&probe);

    let total: usize = loaded
        .iter()
        .map(|(e, _, _, _)| run::jobs(e, opts.shard).len())
        .sum();
    let bar = if opts.progress {
        indicatif::ProgressBar::new(total as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut entries = Vec::new();
    let mut checks = Vec::new();
    let (mut failed, mut ran) = (0usize, 0usize);
    for (exp, hash, _, bytes) in &loaded {
        let dir = opts.out.join(&exp.spec.name);
        fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
        // The bytes that were validated (not a re-read), written only when they
        // differ, so shards sharing the folder do not race on it.
        let spec_path = dir.join("experiment.json");
        if fs::read(&spec_path).ok().as_deref() != Some(bytes.as_slice()) {
            write_atomic(&spec_path, bytes).map_err(|e| io(&dir, e))?;
        }
        bar.set_message(exp.spec.name.clone());
        let results = run_experiment(exp, hash, opts, &bar).map_err(|e| io(&dir, e))?;
        ran += results.len();
        failed += results.iter().filter(|r| r.failure.is_some()).count();
        if opts.shard.is_none() {
            let (values, note, accuracy) = reference(exp);
            let rows = crosscheck(exp, hash);
            let extra = if rows.is_empty() {
                String::new()
            } else {
                crosscheck_markdown(&rows)
            };
            let summary =
                report::write_experiment(&dir, exp, &results, &values, &note, accuracy, &extra)
                    .map_err(|e| io(&dir, e))?;
            entries.push((exp.spec.name.clone(), exp.spec.description.clone(), summary));
            checks.extend(rows);
        }
    }
    bar.finish_and_clear();
    if opts.shard.is_none() {
        report::write_index(
            &opts.out,
            &entries,
            &crosscheck_markdown(&checks),
            checks.is_empty(),
        )
        .map_err(|e| io(&opts.out, e))?;
    }
    if failed > 0 {
        return Err(RunError::Failed {
            failed,
            total: ran,
            index: opts.out.join("index.md").display().to_string(),
        });
    }
    Ok(opts.out.join("index.md"))
}

/// Joins the shards' results under `out` (written by `run --shard k/n` into
/// the same or copied folders) into one results file and report per experiment.
pub fn merge(inputs: &[PathBuf], out: &Path) -> Result<PathBuf, RunError> {
    let mut by_experiment: BTreeMap<String, (Experiment, String, Vec<JobResult>)> = BTreeMap::new();
    for input in inputs {
        for entry in fs::read_dir(input)
            .map_err(|e| io(input, e))?
            .filter_map(Result::ok)
        {
            let dir = entry.path();
            let spec_file = dir.join("experiment.json");
            if !spec_file.is_file() {
                continue;
            }
            let (exp, hash) = load(&spec_file)?;
            let slot = by_experiment
                .entry(exp.spec.name.clone())
                .or_insert_with(|| (exp.clone(), hash.clone(), Vec::new()));
            if slot.1 != hash {
                return Err(io(
                    &spec_file,
                    "a different version of this experiment than the other shards (hash differs)",
                ));
            }
            for f in fs::read_dir(&dir)
                .map_err(|e| io(&dir, e))?
                .filter_map(Result::ok)
            {
                let name = f.file_name().to_string_lossy().to_string();
                if name.starts_with("results") && name.ends_with(".jsonl") {
                    slot.2.extend(read_results(&f.path(), Some(&hash)));
                }
            }
        }
    }
    if by_experiment.is_empty() {
        return Err(RunError::Io {
            path: inputs
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
            message: "no experiment folders (with an experiment.json) found: give the --out folders of the shards".into(),
        });
    }
    fs::create_dir_all(out).map_err(|e| io(out, e))?;
    let mut missing_jobs = Vec::new();
    let mut entries = Vec::new();
    let mut checks = Vec::new();
    for (name, (exp, hash, mut results)) in by_experiment {
        results.sort_by_key(JobResult::key);
        results.dedup_by_key(|r| r.key());
        let expected = run::jobs(&exp, None).len();
        if results.len() < expected {
            missing_jobs.push(format!("{name}: {} of {expected} jobs", results.len()));
        }
        let dir = out.join(&name);
        fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
        let mut text = String::new();
        for r in &results {
            text.push_str(&serde_json::to_string(r).map_err(|e| io(&dir, e))?);
            text.push('\n');
        }
        write_atomic(&dir.join("results.jsonl"), text.as_bytes()).map_err(|e| io(&dir, e))?;
        let (values, note, accuracy) = reference(&exp);
        let rows = crosscheck(&exp, &hash);
        let extra = if rows.is_empty() {
            String::new()
        } else {
            crosscheck_markdown(&rows)
        };
        let summary =
            report::write_experiment(&dir, &exp, &results, &values, &note, accuracy, &extra)
                .map_err(|e| io(&dir, e))?;
        entries.push((name, exp.spec.description.clone(), summary));
        checks.extend(rows);
    }
    report::write_index(
        out,
        &entries,
        &crosscheck_markdown(&checks),
        checks.is_empty(),
    )
    .map_err(|e| io(out, e))?;
    if !missing_jobs.is_empty() {
        return Err(RunError::Io {
            path: out.display().to_string(),
            message: format!(
                "merged an incomplete set (is a shard missing, or from another version of the file?): {}",
                missing_jobs.join("; ")
            ),
        });
    }
    Ok(out.join("index.md"))
}

/// The JSON Schema of experiment files.
pub fn schema() -> String {
    serde_json::to_string_pretty(&schemars::schema_for!(spec::ExperimentSpec)).unwrap_or_default()
}

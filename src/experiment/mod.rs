//! Experiments: JSON files that name an equation family, describe a scene in
//! that family's format, the quantities to compute, the rules and budgets to
//! compare and a reference; runs that write one JSON line per job; and reports
//! of error against run time.
//!
//! Data flow: file -> JSON -> the [`Registry`] reads the `family` tag ->
//! [`spec`] (serde, unknown fields rejected, JSON paths in errors) ->
//! [`validate`](mod@validate) (every number checked, the family builds its
//! scene) -> [`run`](mod@run) (jobs in parallel, results appended as they
//! finish) -> [`report`] (Markdown, SVG, CSV, index) and [`html`] (the same as
//! HTML pages). Nothing here names a family: it is generic over
//! [`Family`](crate::family::Family), and [`crate::families`] is the one
//! registry that names them.
//!
//! ```
//! use lightquad::experiment::validate::parse_json;
//!
//! // An experiment file, checked as `lightquad check` does: 2 rules x 3 budgets
//! // x 2 repeats = 12 jobs.
//! let text = r#"{"name": "e", "family": "calibration", "scene": {},
//!   "quantities": ["exp"], "rules": [{"rule": "trapezoid"}, {"rule": "gauss-legendre"}],
//!   "budgets": [4, 16, 64], "repeats": 2, "reference": {"type": "closed-form"}}"#;
//! let registry = lightquad::families::builtin();
//! let exp = registry.load(parse_json(text)?, "hash")?;
//! assert_eq!(exp.shape(), (2, 3, 2));
//! assert_eq!(exp.jobs(None).len(), 12);
//! // A fault names its JSON path.
//! let bad = text.replace("\"repeats\": 2", "\"repeats\": 0");
//! let e = registry.load(parse_json(&bad)?, "hash").err().expect("refused");
//! assert!(e.to_string().contains("repeats"), "{e}");
//! # Ok::<(), lightquad::error::SpecError>(())
//! ```
//!
//! Beside the public modules: `input` reads experiment files, `output`
//! locks and checks the output folder, and `merge` gathers shards' results;
//! running and reporting are here.

pub mod compare;
pub mod expected;
pub mod external;
pub mod fit;
pub mod html;
mod input;
pub mod markdown;
pub mod memory;
mod merge;
mod output;
pub mod plot;
mod progress;
pub mod reference;
pub mod registry;
pub mod report;
pub mod run;
pub mod source;
pub mod spec;
pub mod tagged;
pub mod timing;
pub mod validate;

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

pub use registry::{FamilyEntry, Loaded, Registry};
use run::{JobResult, RunOptions, write_atomic};
pub use source::Source;
pub use validate::SpecError;

use input::load_all;
pub use input::{experiment_files, load, load_source};
pub use merge::{MergeOptions, merge, merge_with};
use output::{experiment_folder, keep_values, lock_output, no_top_links, writable};

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
    /// The report was written but lacks something: a shard's jobs after a
    /// merge, or a quantity's reference.
    #[error("the report is incomplete ({index}): {problems}")]
    Incomplete {
        /// What is missing, `;`-separated.
        problems: String,
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

fn io<E: std::fmt::Display + 'static>(path: &Path, e: E) -> RunError {
    // A file system error says what happened in words (`not found`,
    // `permission denied`, `is a directory`) beside the system's own.
    let message = match (&e as &dyn std::any::Any).downcast_ref::<std::io::Error>() {
        Some(e) => source::describe(e),
        None => e.to_string(),
    };
    RunError::Io {
        path: path.display().to_string(),
        message,
    }
}

/// Runs experiment files of any family in `registry` and writes their reports
/// under `opts.out`. Every file is validated and the output folder checked
/// before any job runs, so a bad input leaves nothing behind.
pub fn run_files(
    registry: &Registry,
    files: &[PathBuf],
    opts: &RunOptions,
) -> Result<PathBuf, RunError> {
    let sources: Vec<Source> = files.iter().cloned().map(Source::File).collect();
    run_sources(registry, &sources, opts)
}

/// [`run_files`] for experiments that are files or bundled ones
/// ([`Source::bundled_suite`]: what `lightquad run` runs without files).
pub fn run_sources(
    registry: &Registry,
    files: &[Source],
    opts: &RunOptions,
) -> Result<PathBuf, RunError> {
    if let Some((k, n)) = opts.shard
        && (k == 0 || k > n)
    {
        return Err(RunError::Io {
            path: opts.out.display().to_string(),
            message: format!("invalid shard {k}/{n}: expected k/n with 1 <= k <= n"),
        });
    }
    let loaded = load_all(registry, files)?;
    if opts.progress {
        for (exp, _, _) in &loaded {
            for w in exp.warnings() {
                crate::say!(
                    "warning: {}: {}",
                    exp.name(),
                    crate::error::readable(&w.to_string())
                );
            }
        }
    }
    // A job past a hard cap on this process (prlimit, a cgroup) aborts the
    // whole run when an allocation fails: refused before any job runs. Only
    // the jobs still to run count: a --resume whose large jobs are finished
    // goes on.
    // Every worker makes its allocator's arena first (64 MB of address space
    // each under glibc), so the room under a cap is measured with them. A
    // hard cap is not lifted by --no-cost-limit: past it the process aborts
    // (it did, with the flag the refusal had suggested).
    memory::warm_workers();
    if let Some(cap) = memory::hard_cap() {
        for (exp, source, _) in &loaded {
            let pending = run::pending_jobs(exp.as_ref(), opts);
            let need = exp.max_job_bytes(&pending);
            if need + memory::REPORT_RESERVE > cap.room {
                let what = if need > 0.0 {
                    format!(
                        "its largest pending job needs about {} of memory and the run keeps {} \
                         for the families' working memory and the reports",
                        memory::bytes(need),
                        memory::bytes(memory::REPORT_RESERVE)
                    )
                } else {
                    format!(
                        "no job is pending, but writing its report keeps about {}",
                        memory::bytes(memory::REPORT_RESERVE)
                    )
                };
                return Err(RunError::Spec {
                    file: source.display(),
                    source: crate::error::SpecError::at(
                        "budgets",
                        format!(
                            "{what}, and this process may allocate only {} more under {} \
                             (raise the limit; or lower the budgets or --threads, each worker \
                             thread holding an allocator arena of 64 MB of address space)",
                            memory::bytes(cap.room),
                            cap.what
                        ),
                    ),
                });
            }
        }
    }
    writable(&opts.out)?;
    let _lock = lock_output(&opts.out, opts.shard)?;
    // Alone in the folder (a whole run's lock), the temporary files of a
    // killed run can go; shards share the folder and leave them.
    if opts.shard.is_none() {
        run::remove_stale_temporaries(&opts.out);
    }
    // Every experiment's folder and files, before any job runs: a file where
    // a folder goes (or a folder where a file goes) stopped the run after
    // the experiments before it had run, with "already exists".
    // No link where the run writes, in the folder or in an experiment's
    // (a link there was written through, to wherever it pointed).
    no_top_links(&opts.out)?;
    for (exp, _, _) in &loaded {
        experiment_folder(&opts.out.join(exp.name()))?;
    }
    // A shard writes its own results file and no report: the pages there
    // (a whole run's, or a merge's) stay, still those of the results beside
    // them. A whole run's pages go until its own are written.
    if opts.shard.is_none() {
        run::clear_reports(&opts.out, loaded.iter().map(|(e, _, _)| e.name()));
    }
    let total: usize = loaded
        .iter()
        .map(|(e, _, _)| e.jobs(opts.shard).len())
        .sum();
    let bar = progress::bar(opts.progress, total);
    let mut done = Vec::new();
    for (exp, _, bytes) in loaded {
        let dir = opts.out.join(exp.name());
        fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
        // The bytes that were validated (not a re-read), written only when they
        // differ, so shards sharing the folder do not race on it.
        let spec_path = dir.join("experiment.json");
        if fs::read(&spec_path).ok().as_deref() != Some(bytes.as_slice()) {
            write_atomic(&spec_path, &bytes).map_err(|e| io(&dir, e))?;
        }
        keep_values(exp.as_ref(), &dir)?;
        bar.set_message(exp.name().to_string());
        let started = std::time::Instant::now();
        // No more jobs at once than the machine's memory holds (four jobs of
        // 4 GB each on four threads aborted the run).
        let threads = rayon::current_num_threads();
        let pending = run::pending_jobs(exp.as_ref(), opts);
        let need = exp.max_job_bytes(&pending);
        let room = memory::available().map(|a| (a - memory::REPORT_RESERVE).max(0.0));
        let fit = jobs_that_fit(need, room).min(threads);
        if fit < threads {
            crate::say!(
                "{}: its largest jobs hold about {} each: {fit} at a time instead of \
                 {threads}, to fit in the memory available",
                exp.name(),
                memory::bytes(need)
            );
        }
        let results = run::run_experiment_in_lanes(exp.as_ref(), opts, &bar, fit)
            // A full disk while the jobs run: what was written is kept, and a
            // resumed run goes on from it.
            .map_err(|e| {
                io(
                    &dir,
                    format!(
                        "{}; the results written so far are kept: fix this and `run --resume` with \
                     the same experiments goes on from them",
                        source::describe(&e)
                    ),
                )
            })?;
        let kept = results.len().saturating_sub(pending.len());
        let took = started.elapsed();
        progress::finished(opts.progress, &bar, exp.name(), &results, kept, took);
        done.push((exp, results));
    }
    bar.finish_and_clear();
    if opts.shard.is_some() {
        let failed = failures(&done);
        return match failed {
            (0, _) => Ok(opts.out.clone()),
            (failed, total) => Err(RunError::Failed {
                failed,
                total,
                index: opts.out.display().to_string(),
            }),
        };
    }
    write_reports(registry, &opts.out, &done, Vec::new())
}

/// How many jobs of `bytes` each fit at once in `available` bytes (at
/// least one: a single job was checked against the per-job limit; unknown
/// memory caps nothing).
pub fn jobs_that_fit(bytes: f64, available: Option<f64>) -> usize {
    match available {
        Some(a) if bytes > 0.0 => ((0.8 * a / bytes).floor() as usize).max(1),
        _ => usize::MAX,
    }
}

/// Failed and total jobs.
fn failures(done: &[(Box<dyn Loaded>, Vec<JobResult>)]) -> (usize, usize) {
    let all = done.iter().flat_map(|(_, r)| r);
    let failed = all.clone().filter(|r| r.failure.is_some()).count();
    (failed, all.count())
}

/// A report that could not be finished, said with what was kept.
fn unfinished(why: String) -> String {
    format!(
        "{why}; no report was written (its files so far were removed), the results are kept: \
         `run --resume` (or `merge`) with the same experiments writes it once this is fixed"
    )
}

/// The report path shared by `run` and `merge`: a page per experiment, the
/// index, and an error when jobs failed or (after a merge) are missing.
fn write_reports(
    registry: &Registry,
    out: &Path,
    done: &[(Box<dyn Loaded>, Vec<JobResult>)],
    missing: Vec<String>,
) -> Result<PathBuf, RunError> {
    let report_files = run::ReportFiles::begin();
    // The experiments' pages at once on rayon's threads, as many as the
    // memory holds (a report's converged reference and images take up to
    // REPORT_RESERVE): one after another, a report's serial parts (its
    // plots, and the end of each doubling of a converged reference) left
    // the other threads idle. After a failure no report is started (an
    // error waited on every converged reference), and the failure said is
    // the first in entry order, whatever the order the reports finish in.
    let at_once = memory::available().map_or(usize::MAX, |a| {
        (a / memory::REPORT_RESERVE).floor().max(1.0) as usize
    });
    let order: Vec<usize> = (0..done.len()).collect();
    let pages = crate::parallel::try_dealt(&order, at_once, |k| {
        let (exp, results) = &done[k];
        let dir = out.join(exp.name());
        // A converged reference is computed now, after the jobs: say so, or
        // a long one looks like a hang (a scene of radius 1e308 took minutes).
        if let Some(n) = exp.converged_reference() {
            crate::say!(
                "{}: computing the converged reference (n = {n}, doubled until it converges)",
                exp.name()
            );
        }
        report_files
            .record(|| exp.write_report(&dir, results))
            .map_err(|e| io(&dir, unfinished(e)))
    });
    let mut entries = Vec::new();
    let mut numbers = Vec::new();
    let mut checks = Vec::new();
    let mut problems = missing;
    for ((exp, _), written) in done.iter().zip(pages?) {
        entries.push((
            exp.name().to_string(),
            exp.description().to_string(),
            written.summary,
        ));
        numbers.push(written.numbers);
        checks.extend(written.crosscheck);
        problems.extend(written.problems);
    }
    // The audits of the families that have experiments here.
    let families: BTreeSet<&str> = done.iter().map(|(e, _)| e.family()).collect();
    let audits: Vec<String> = registry
        .entries()
        .iter()
        .filter(|e| families.contains(e.name))
        .filter_map(FamilyEntry::audit)
        .collect();
    // Experiment folders of earlier runs into this folder, said and linked.
    let ours: BTreeSet<&str> = done.iter().map(|(e, _)| e.name()).collect();
    let mut earlier: Vec<String> = fs::read_dir(out)
        .map(|d| {
            d.flatten()
                .map(|e| e.path())
                .filter(|p| p.join("experiment.json").is_file() && p.join("report.md").is_file())
                .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .filter(|n| !ours.contains(n.as_str()))
                .collect()
        })
        .unwrap_or_default();
    earlier.sort();
    report_files
        .record(|| report::write_index(out, &entries, &checks, &audits, &problems, &earlier))
        .map_err(|e| io(out, unfinished(e)))?;
    report_files
        .record(|| report::write_summary(out, &numbers))
        .map_err(|e| io(out, unfinished(e)))?;
    report_files.finish();
    let index = out.join("index.md");
    if !problems.is_empty() {
        return Err(RunError::Incomplete {
            problems: problems.join("; "),
            index: index.display().to_string(),
        });
    }
    match failures(done) {
        (0, _) => Ok(index),
        (failed, total) => Err(RunError::Failed {
            failed,
            total,
            index: index.display().to_string(),
        }),
    }
}

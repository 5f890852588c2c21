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
//! self-contained HTML pages). Nothing here names a
//! family: it is generic over [`Family`](crate::family::Family), and
//! [`crate::families`] is the one registry that names them.
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

pub mod expected;
pub mod fit;
pub mod html;
pub mod markdown;
pub mod memory;
pub mod plot;
mod progress;
pub mod reference;
pub mod registry;
pub mod report;
pub mod run;
pub mod source;
pub mod spec;
pub mod tagged;
pub mod validate;

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

pub use registry::{FamilyEntry, Loaded, Registry};
use run::{JobResult, RunOptions, file_hash, write_atomic};
pub use source::Source;
pub use validate::SpecError;

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

/// Reads, parses and validates one experiment file of any family in `registry`.
pub fn load(registry: &Registry, path: &Path) -> Result<Box<dyn Loaded>, RunError> {
    load_source(registry, &Source::File(path.to_path_buf()))
}

/// Reads, parses and validates one experiment (a file or a bundled one).
pub fn load_source(registry: &Registry, source: &Source) -> Result<Box<dyn Loaded>, RunError> {
    let bytes = read_source(source)?;
    load_bytes(registry, source, &bytes)
}

fn read_source(source: &Source) -> Result<Vec<u8>, RunError> {
    source.read().map_err(|message| RunError::Io {
        path: source.display(),
        message,
    })
}

fn load_bytes(
    registry: &Registry,
    source: &Source,
    bytes: &[u8],
) -> Result<Box<dyn Loaded>, RunError> {
    let file = source.display();
    let text = std::str::from_utf8(bytes).map_err(|e| RunError::Io {
        path: file.clone(),
        message: format!("not UTF-8: {e}"),
    })?;
    let spec_error = |source| RunError::Spec {
        file: file.clone(),
        source,
    };
    validate::parse_and_load(text, |json| {
        registry.load_from(json, &file_hash(bytes), source.origin())
    })
    .map_err(spec_error)
}

/// An experiment with the bytes it was loaded from.
type Input = (Box<dyn Loaded>, Source, Vec<u8>);

/// Loads every file and checks that no two share a name.
fn load_all(registry: &Registry, files: &[Source]) -> Result<Vec<Input>, RunError> {
    let mut names = BTreeSet::new();
    let mut out = Vec::new();
    for f in files {
        let bytes = read_source(f)?;
        let exp = load_bytes(registry, f, &bytes)?;
        if !names.insert(exp.name().to_string()) {
            return Err(RunError::Spec {
                file: f.display(),
                source: SpecError::at(
                    "name",
                    format!("{:?} is used by another experiment in this run", exp.name()),
                ),
            });
        }
        out.push((exp, f.clone(), bytes));
    }
    Ok(out)
}

/// Holds `<out>/.lightquad.lock` locked for as long as the run writes there
/// (`run --shard` runs share it, each holding its shard's own lock alone, so
/// shards may share a folder but a whole run or a merge may not join them): a second run
/// into the same folder stops at once with an error instead of replacing the
/// first's results file while the first keeps appending to the replaced one
/// (528 jobs reported, 76 lines left). The lock is advisory and released by
/// the operating system when the process ends, also after `kill -9`.
fn lock_output(out: &Path, shard: Option<(usize, usize)>) -> Result<Vec<fs::File>, RunError> {
    let open = |name: String| {
        let path = out.join(name);
        fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .map(|f| (f, path.clone()))
            .map_err(|e| io(&path, e))
    };
    let busy = |path: &Path| {
        io(
            out,
            format!(
                "another lightquad run or merge is writing into this folder (it holds {}): \
                 wait for it to finish or give another --out",
                path.display()
            ),
        )
    };
    let take = |(file, path): (fs::File, PathBuf), shared: bool| {
        let got = if shared {
            file.try_lock_shared()
        } else {
            file.try_lock()
        };
        match got {
            Ok(()) => Ok(file),
            Err(fs::TryLockError::WouldBlock) => Err(busy(&path)),
            Err(fs::TryLockError::Error(e)) => Err(io(&path, format!("cannot lock: {e}"))),
        }
    };
    // Shards share the folder lock (with each other, never with a whole run
    // or a merge) and hold their own shard's lock alone.
    let folder = open(".lightquad.lock".into())?;
    match shard {
        None => Ok(vec![take(folder, false)?]),
        Some((k, n)) => {
            let whole = take(folder, true)?;
            let own = take(open(format!(".lightquad.shard-{k}-of-{n}.lock"))?, false)?;
            Ok(vec![whole, own])
        }
    }
}

/// Writes the experiment's Mitsuba values, where it has some, beside its
/// `experiment.json` in `dir` ([`source::VALUES_COPY`]), unless the same
/// bytes are there (shards sharing the folder do not race on it): a
/// reference named by a path relative to the experiment file is not found
/// from the output folder, and `merge` of shards failed on it.
fn keep_values(exp: &dyn Loaded, dir: &Path) -> Result<(), RunError> {
    let Some(values) = exp.mitsuba_values() else {
        return Ok(());
    };
    let copy = dir.join(source::VALUES_COPY);
    let text = serde_json::to_vec_pretty(&values).map_err(|e| io(dir, e))?;
    if fs::read(&copy).ok().as_deref() != Some(text.as_slice()) {
        write_atomic(&copy, &text).map_err(|e| io(&copy, e))?;
    }
    Ok(())
}

/// Makes an experiment's folder under `--out` (or finds it there), with no
/// folder where its files go; what is in the way is named.
fn experiment_folder(dir: &Path) -> Result<(), RunError> {
    if fs::symlink_metadata(dir).is_ok() && !dir.is_dir() {
        return Err(io(
            dir,
            "is in the way: a file (or a broken link) where this experiment's results folder \
             goes; expected a folder or nothing (remove it, or choose another --out)",
        ));
    }
    fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    for file in [
        "experiment.json",
        "results.jsonl",
        "report.md",
        "index.html",
    ] {
        let path = dir.join(file);
        if path.is_dir() {
            return Err(io(
                &path,
                "is a folder where the run writes a file: expected a file or nothing (remove it, \
                 or choose another --out)",
            ));
        }
        // A device or a pipe (a link to /dev/full) was read as earlier
        // results without end until the process was killed.
        if fs::metadata(&path).is_ok_and(|m| !m.is_file()) {
            return Err(io(
                &path,
                "is not a regular file (a device, a pipe, or a link to one) where the run keeps \
                 a file: expected a regular file or nothing (remove it, or choose another --out)",
            ));
        }
    }
    Ok(())
}

/// Checks that `dir` exists (or can be made) and is writable.
fn writable(dir: &Path) -> Result<(), RunError> {
    if let Ok(meta) = fs::metadata(dir)
        && !meta.is_dir()
    {
        return Err(io(
            dir,
            "is a file, not a directory: the output folder (--out) must be a directory or \
             not exist yet",
        ));
    }
    // A link to nothing: creating the folder says only "already exists".
    if fs::metadata(dir).is_err()
        && let Ok(target) = fs::read_link(dir)
    {
        return Err(io(
            dir,
            format!(
                "is a link to {}, which does not exist: the output folder (--out) must be a \
                 directory or not exist yet (make the link's target, or choose another --out)",
                target.display()
            ),
        ));
    }
    fs::create_dir_all(dir).map_err(|e| {
        io(
            dir,
            format!(
                "cannot create the output folder (--out): {}",
                source::describe(&e)
            ),
        )
    })?;
    let probe = dir.join(format!(".lightquad-write-probe-{}", std::process::id()));
    write_atomic(&probe, b"")
        .map_err(|e| io(dir, format!("not writable: {}", source::describe(&e))))?;
    let _ = fs::remove_file(&probe);
    Ok(())
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
                crate::say!("warning: {}: {w}", exp.name());
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
            let need = exp.max_job_bytes(&run::pending_jobs(exp.as_ref(), opts));
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
    for (exp, _, _) in &loaded {
        experiment_folder(&opts.out.join(exp.name()))?;
    }
    run::clear_reports(&opts.out, loaded.iter().map(|(e, _, _)| e.name()));
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
        let need = exp.max_job_bytes(&run::pending_jobs(exp.as_ref(), opts));
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
        progress::finished(opts.progress, &bar, exp.name(), &results, started.elapsed());
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
    let mut entries = Vec::new();
    let mut checks = Vec::new();
    let mut problems = missing;
    for (exp, results) in done {
        let dir = out.join(exp.name());
        // A converged reference is computed now, after the jobs: say so, or
        // a long one looks like a hang (a scene of radius 1e308 took minutes).
        if let Some(n) = exp.converged_reference() {
            crate::say!(
                "{}: computing the converged reference (n = {n}, doubled until it converges)",
                exp.name()
            );
        }
        let written = exp
            .write_report(&dir, results)
            .map_err(|e| io(&dir, unfinished(e)))?;
        entries.push((
            exp.name().to_string(),
            exp.description().to_string(),
            written.summary,
        ));
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
    report::write_index(out, &entries, &checks, &audits, &problems, &earlier)
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

/// Joins the shards' results under `inputs` (written by `run --shard k/n` into
/// the same or copied folders) into one results file and report per experiment.
pub fn merge(registry: &Registry, inputs: &[PathBuf], out: &Path) -> Result<PathBuf, RunError> {
    let mut by_name: BTreeMap<String, Gathered> = BTreeMap::new();
    // Shards still writing into an input would be merged half done.
    let mut reading = Vec::new();
    for input in inputs {
        let shard_locks = fs::read_dir(input)
            .map_err(|e| io(input, e))?
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with(".lightquad.shard-"))
            });
        for lock in std::iter::once(input.join(".lightquad.lock")).chain(shard_locks) {
            let Ok(file) = fs::File::open(&lock) else {
                continue;
            };
            match file.try_lock_shared() {
                Ok(()) => reading.push(file),
                Err(fs::TryLockError::WouldBlock) => {
                    return Err(io(
                        input,
                        format!(
                            "a lightquad run is still writing into this folder (it holds {}): \
                             merge it once the run has finished",
                            lock.display()
                        ),
                    ));
                }
                Err(fs::TryLockError::Error(e)) => {
                    return Err(io(&lock, format!("cannot lock: {e}")));
                }
            }
        }
    }
    for input in inputs {
        let mut dirs: Vec<PathBuf> = fs::read_dir(input)
            .map_err(|e| io(input, e))?
            .flatten()
            .map(|e| e.path())
            .collect();
        dirs.sort();
        for dir in dirs {
            let spec_file = dir.join("experiment.json");
            if spec_file.is_file() {
                gather(registry, &spec_file, &mut by_name)?;
            }
        }
    }
    if by_name.is_empty() {
        return Err(RunError::Io {
            path: inputs
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
            message: "no experiment folders (with an experiment.json) found: give the --out folders of the shards".into(),
        });
    }
    writable(out)?;
    // The inputs have been read; `out` may be one of them.
    drop(reading);
    let _lock = lock_output(out, None)?;
    run::remove_stale_temporaries(out);
    run::clear_reports(out, by_name.keys().map(String::as_str));
    let mut missing = Vec::new();
    let mut done = Vec::new();
    for (name, g) in by_name {
        let Gathered {
            exp,
            mut results,
            spec,
            unread,
        } = g;
        // One result per job of this experiment, a finished one before a
        // failed one where shards disagree.
        let expected: BTreeSet<_> = exp.jobs(None).into_iter().collect();
        results.retain(|r| expected.contains(&r.key()));
        results.sort_by_key(|r| (r.key(), r.failure.is_some()));
        // Two finished results of one job must agree (a job is
        // deterministic): values that differ mean an edited or foreign
        // shard, said and not settled in silence (9.99 from an appended
        // line was merged without a word).
        let conflicts: Vec<String> = results
            .windows(2)
            .filter(|w| {
                w[0].key() == w[1].key()
                    && w[0].failure.is_none()
                    && w[1].failure.is_none()
                    && values_differ(&w[0], &w[1])
            })
            .map(|w| format!("{:?}", w[0].key()))
            .collect();
        if !conflicts.is_empty() {
            missing.push(format!(
                "{name}: {} job(s) with different values in two shards (rule, budget, repeat: {}): \
                 which is right cannot be told: the first in the folders' order was kept",
                conflicts.len(),
                conflicts.join(", ")
            ));
        }
        if unread.unreadable > 0 {
            missing.push(format!(
                "{name}: {} unreadable line(s) in the shards' results (torn, edited, or not a \
                 result of this file's jobs) were passed over",
                unread.unreadable
            ));
        }
        results.dedup_by_key(|r| r.key());
        if results.len() < expected.len() {
            missing.push(format!(
                "{name}: {} of {} jobs (is a shard missing, or from another version of the file or of lightquad?)",
                results.len(),
                expected.len()
            ));
        }
        let dir = out.join(&name);
        fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
        // The experiment file beside its results, so the merged folder is
        // one `merge` and the report's link can read again.
        write_atomic(&dir.join("experiment.json"), &spec).map_err(|e| io(&dir, e))?;
        keep_values(exp.as_ref(), &dir)?;
        let mut text = String::new();
        for r in &results {
            text.push_str(&serde_json::to_string(r).map_err(|e| io(&dir, e))?);
            text.push('\n');
        }
        write_atomic(&dir.join("results.jsonl"), text.as_bytes()).map_err(|e| io(&dir, e))?;
        done.push((exp, results));
    }
    write_reports(registry, out, &done, missing)
}

/// One experiment's shards as `merge` gathers them: the experiment, its
/// results, the experiment file's bytes and the lines not read.
struct Gathered {
    exp: Box<dyn Loaded>,
    results: Vec<JobResult>,
    spec: Vec<u8>,
    unread: run::Unread,
}

/// Whether two results of one job hold different values or errors (bit for
/// bit: a job is deterministic).
fn values_differ(a: &JobResult, b: &JobResult) -> bool {
    let same = |x: &[f64], y: &[f64]| {
        x.len() == y.len() && x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits())
    };
    a.quantities.len() != b.quantities.len()
        || a.quantities
            .iter()
            .zip(&b.quantities)
            .any(|((p, m), (q, n))| {
                p != q || !same(&m.value, &n.value) || !same(&m.error, &n.error)
            })
}

/// Adds one shard folder's experiment and results to `by_name`.
fn gather(
    registry: &Registry,
    spec_file: &Path,
    by_name: &mut BTreeMap<String, Gathered>,
) -> Result<(), RunError> {
    let exp = load(registry, spec_file)?;
    let spec = fs::read(spec_file).map_err(|e| io(spec_file, e))?;
    let hash = exp.hash().to_string();
    let name = exp.name().to_string();
    let slot = by_name.entry(name).or_insert_with(|| Gathered {
        exp,
        results: Vec::new(),
        spec,
        unread: run::Unread::default(),
    });
    if slot.exp.hash() != hash {
        return Err(io(
            spec_file,
            "a different version of this experiment than the other shards (hash differs)",
        ));
    }
    let dir = spec_file.parent().unwrap_or(Path::new("."));
    let mut files: Vec<PathBuf> = fs::read_dir(dir)
        .map_err(|e| io(dir, e))?
        .flatten()
        .map(|f| f.path())
        .filter(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy())
                .is_some_and(|n| n.starts_with("results") && n.ends_with(".jsonl"))
        })
        .collect();
    files.sort();
    for f in files {
        // Lines of this lightquad version only, as `--resume` keeps.
        let (lines, unread) = run::read_results_counted(&f, Some(&hash));
        let (lines, misfits) = slot.exp.reusable(lines);
        slot.unread.unreadable += unread.unreadable + misfits;
        slot.results.extend(
            lines
                .into_iter()
                .filter(|r| r.version == env!("CARGO_PKG_VERSION")),
        );
    }
    Ok(())
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

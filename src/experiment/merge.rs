//! `lightquad merge`: the results files of shards gathered into one, each
//! job once, a job whose values differ between files refused.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

use crate::experiment::registry::{Loaded, Registry};
use crate::experiment::run::{self, JobResult, write_atomic};

use super::input::load;
use super::output::{experiment_folder, keep_values, lock_output, no_top_links, writable};
use super::{RunError, io, write_reports};

/// Joins the shards' results under `inputs` (written by `run --shard k/n` into
/// the same or copied folders) into one results file and report per
/// experiment; shards computed by different builds (git commits) are
/// refused ([`merge_with`] can allow them).
pub fn merge(registry: &Registry, inputs: &[PathBuf], out: &Path) -> Result<PathBuf, RunError> {
    merge_with(registry, inputs, out, &MergeOptions::default())
}

/// Options of a merge.
#[derive(Debug, Clone, Default)]
pub struct MergeOptions {
    /// Merge shards whose results were computed by different builds of
    /// lightquad (different git commits of one version); the report then
    /// names every commit.
    pub allow_mixed_commits: bool,
}

/// [`merge`] with `options`.
pub fn merge_with(
    registry: &Registry,
    inputs: &[PathBuf],
    out: &Path,
    options: &MergeOptions,
) -> Result<PathBuf, RunError> {
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
    if !options.allow_mixed_commits {
        one_build(inputs, &by_name)?;
    }
    writable(out)?;
    // The inputs have been read; `out` may be one of them.
    drop(reading);
    let _lock = lock_output(out, None)?;
    // No link where the merge writes (a link there was written through).
    no_top_links(out)?;
    for name in by_name.keys() {
        experiment_folder(&out.join(name))?;
    }
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
            ..
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
    /// The files the results came from, by the build (git commit) that
    /// computed them.
    builds: BTreeMap<String, BTreeSet<PathBuf>>,
}

/// The build that computed a result, as reports name it.
fn build_of(r: &JobResult) -> &str {
    r.git_commit.as_deref().unwrap_or("unknown")
}

/// Refuses results of more than one build (git commit) among the gathered
/// shards: each is named with the results files that hold it (a report
/// named only the first one's commit).
fn one_build(inputs: &[PathBuf], by_name: &BTreeMap<String, Gathered>) -> Result<(), RunError> {
    let mut builds: BTreeMap<&str, BTreeSet<&Path>> = BTreeMap::new();
    for g in by_name.values() {
        for (build, files) in &g.builds {
            builds
                .entry(build)
                .or_default()
                .extend(files.iter().map(PathBuf::as_path));
        }
    }
    if builds.len() < 2 {
        return Ok(());
    }
    /// Files named per build; the rest are counted.
    const NAMED: usize = 3;
    let each: Vec<String> = builds
        .iter()
        .map(|(build, files)| {
            let mut names: Vec<String> = files
                .iter()
                .take(NAMED)
                .map(|f| f.display().to_string())
                .collect();
            if files.len() > NAMED {
                names.push(format!("{} more", files.len() - NAMED));
            }
            format!("commit {build} (in {})", names.join(", "))
        })
        .collect();
    Err(RunError::Io {
        path: inputs
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        message: format!(
            "the shards' results were computed by {} different builds of lightquad {}: {}; \
             expected the results of one build (run the other shards again with one \
             build), or pass --allow-mixed-commits to merge them with the report naming \
             every commit",
            builds.len(),
            env!("CARGO_PKG_VERSION"),
            each.join("; ")
        ),
    })
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
        builds: BTreeMap::new(),
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
        let lines: Vec<JobResult> = lines
            .into_iter()
            .filter(|r| r.version == env!("CARGO_PKG_VERSION"))
            .collect();
        for r in &lines {
            slot.builds
                .entry(build_of(r).to_string())
                .or_default()
                .insert(f.clone());
        }
        slot.results.extend(lines);
    }
    Ok(())
}

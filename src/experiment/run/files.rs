//! The files of a run: the results file's path and its lines read back
//! (only those that are results of this experiment's jobs), files written
//! atomically or all or none, report files removed again when a report is
//! left unfinished, stale reports and temporaries cleared.

use std::collections::BTreeSet;
use std::fs::{self, File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::experiment::validate::{Experiment, quantities_at};
use crate::family::{Family, Quantity};

use super::{JobKey, JobResult, job_seed, jobs, links};

/// The results read back from a file (`--resume`, `merge`) that are results
/// of `exp`'s jobs as this version runs them: a job of its list, by the rule
/// its index names, with the job's own seed (an edited seed was reused), with exactly its quantities, each with its channel count
/// of finite values and of errors (or a failure). Returns them and how many
/// were not: a hand-edited line with `"rule_index": 99` was reused as a job
/// of a rule the file does not have, and one with two channels of a scalar
/// shown as a value with no error.
pub fn reusable<F: Family>(
    exp: &Experiment<F>,
    results: Vec<JobResult>,
) -> (Vec<JobResult>, usize) {
    let jobs: BTreeSet<JobKey> = jobs(exp, None).into_iter().collect();
    let fits = |r: &JobResult| {
        let job = r.experiment == exp.spec.name
            && r.family == F::NAME
            && jobs.contains(&r.key())
            && r.seed == job_seed(exp.spec.seed, r.rule_index, r.budget, r.repeat)
            && exp
                .spec
                .rules
                .get(r.rule_index)
                .is_some_and(|m| m.label() == r.rule);
        let asked = exp.spec.rules.get(r.rule_index).map_or_else(Vec::new, |m| {
            quantities_at::<F>(&exp.scene, m, &exp.spec.quantities, r.budget)
        });
        let shaped = r.failure.is_some()
            || (r.quantities.len() == asked.len()
                && asked.iter().all(|q| {
                    let want = F::channels(&exp.scene, *q);
                    r.quantities.get(q.name()).is_some_and(|m| {
                        m.value.len() == want
                            && m.error.len() == want
                            && m.value.iter().all(|x| x.is_finite())
                            && !m.error.iter().any(|e| *e < 0.0)
                    })
                }));
        job && shaped && r.seconds.is_finite()
    };
    let before = results.len();
    let kept: Vec<JobResult> = results.into_iter().filter(fits).collect();
    let dropped = before - kept.len();
    (kept, dropped)
}

/// Reads the complete, parseable lines of a results file for `hash`.
pub fn read_results(path: &Path, hash: Option<&str>) -> Vec<JobResult> {
    read_results_counted(path, hash).0
}

/// Lines of a results file that were not read back.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Unread {
    /// Lines that are not a job's result (torn by a kill, edited, not UTF-8).
    pub unreadable: usize,
    /// Results of another version of the experiment file (another hash).
    pub other_version: usize,
}

/// [`read_results`], and how many lines it passed over: each line on its
/// own, so one bad line (torn, or not UTF-8) no longer ends the reading and
/// silently drops every line after it.
pub fn read_results_counted(path: &Path, hash: Option<&str>) -> (Vec<JobResult>, Unread) {
    let mut unread = Unread::default();
    let Ok(file) = File::open(path) else {
        return (Vec::new(), unread);
    };
    let mut out = Vec::new();
    for line in BufReader::new(file).split(b'\n') {
        let Ok(line) = line else {
            unread.unreadable += 1;
            break;
        };
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        match serde_json::from_slice::<JobResult>(&line) {
            Err(_) => unread.unreadable += 1,
            Ok(r) if hash.is_some_and(|h| r.experiment_hash != h) => unread.other_version += 1,
            Ok(r) => out.push(r),
        }
    }
    (out, unread)
}

/// How many lines of a results file are results of the experiment file
/// hashing to `hash`: each line is read for its hash alone (an image's
/// results run to a hundred megabytes, and only the count is said).
pub(super) fn results_of(path: &Path, hash: &str) -> usize {
    #[derive(Deserialize)]
    struct HashOnly {
        experiment_hash: String,
    }
    let Ok(file) = File::open(path) else {
        return 0;
    };
    BufReader::new(file)
        .split(b'\n')
        .map_while(Result::ok)
        .filter(|line| {
            serde_json::from_slice::<HashOnly>(line).is_ok_and(|h| h.experiment_hash == hash)
        })
        .count()
}

/// Writes `text` to `path` atomically (a temporary file, then a rename), so a
/// reader never sees a half-written file. A link at `path` is refused, not
/// followed ([`super::links`]); the temporary file is created new (a link
/// at its name fails it), and the rename replaces the entry at `path`, so a
/// link put there meanwhile is replaced, never written through.
pub fn write_atomic(path: &Path, text: &[u8]) -> std::io::Result<()> {
    links::refuse_link(path)?;
    // A name no other process or thread writing beside us can pick (shards of
    // one run may share an output folder).
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let unique = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = path
        .file_name()
        .map_or("out".into(), |n| n.to_string_lossy().to_string());
    let tmp = path.with_file_name(format!(".{name}.{}.{unique}.tmp", std::process::id()));
    // A name that is taken (a link planted there) fails here, and is not
    // ours to remove.
    let mut file = links::create_new(&tmp).map_err(|e| {
        if links::is_link(&tmp) {
            links::link_error(&tmp)
        } else {
            e
        }
    })?;
    let written = file
        .write_all(text)
        .and_then(|()| file.sync_all())
        .and_then(|()| fs::rename(&tmp, path));
    // A write that failed (a full disk) leaves no temporary file behind.
    if written.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    written
}

/// Writes every `(path, bytes)` or none. A regular file (or one not there
/// yet) is written to a temporary file beside it, renamed into place only
/// when every file is written; a link is followed to the file it names. A
/// path that is not a regular file (`/dev/full`, a pipe) is written in
/// place, never renamed over, after the temporary files and before the
/// renames. On failure the temporary files are removed (and any renamed
/// already), and the error comes with the index of the file it concerns.
pub fn write_all_or_none<'a>(
    files: impl IntoIterator<Item = (&'a Path, &'a [u8])>,
) -> Result<(), (usize, std::io::Error)> {
    let files: Vec<(PathBuf, &[u8])> = files
        .into_iter()
        .map(|(path, bytes)| {
            let linked = fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
            let path = match linked.then(|| fs::canonicalize(path)) {
                Some(Ok(target)) => target,
                _ => path.to_path_buf(),
            };
            (path, bytes)
        })
        .collect();
    let special = |path: &Path| fs::metadata(path).is_ok_and(|m| !m.is_file());
    let mut temporary: Vec<(usize, PathBuf)> = Vec::with_capacity(files.len());
    let clean = |temporary: &[(usize, PathBuf)]| {
        for (_, t) in temporary {
            let _ = fs::remove_file(t);
        }
    };
    for (k, (path, bytes)) in files.iter().enumerate() {
        if special(path) {
            continue;
        }
        let name = path
            .file_name()
            .map_or("out".into(), |n| n.to_string_lossy().to_string());
        // The final name is in the temporary one, so that a name the
        // folder refuses (too long) fails here, before any rename.
        let tmp = path.with_file_name(format!(".{name}.{}.{k}.tmp", std::process::id()));
        let written = File::create(&tmp).and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        });
        temporary.push((k, tmp));
        if let Err(e) = written {
            clean(&temporary);
            return Err((k, e));
        }
    }
    for (k, (path, bytes)) in files.iter().enumerate() {
        if special(path)
            && let Err(e) = OpenOptions::new()
                .write(true)
                .open(path)
                .and_then(|mut f| f.write_all(bytes))
        {
            clean(&temporary);
            return Err((k, e));
        }
    }
    for (done, (k, tmp)) in temporary.iter().enumerate() {
        if let Err(e) = fs::rename(tmp, &files[*k].0) {
            // Neither the rest nor the ones already in place.
            clean(&temporary[done..]);
            for (renamed, _) in &temporary[..done] {
                let _ = fs::remove_file(&files[*renamed].0);
            }
            return Err((*k, e));
        }
    }
    Ok(())
}

/// The paths of the report files written so far by one report.
type Written = std::sync::Arc<std::sync::Mutex<Vec<PathBuf>>>;

thread_local! {
    /// The list of the report being written on this thread, inside
    /// [`ReportFiles::record`].
    static WRITTEN: std::cell::RefCell<Option<Written>> =
        const { std::cell::RefCell::new(None) };
}

/// A report written whole or not at all: the files [`write_report_file`]
/// writes inside [`record`](Self::record) are removed again when the guard
/// is dropped without [`finish`](Self::finish) (a full disk at the index
/// left the plots and pages written before it, with no index). Results
/// files are not report files and stay. Several threads may each call
/// `record` on one guard; but a file is recorded only on a thread inside
/// `record`, so work that the closure hands to other threads (a `par_iter`
/// in it) must not write report files, or must call `record` itself.
#[derive(Debug, Default)]
pub struct ReportFiles {
    written: Written,
    finished: bool,
}

impl ReportFiles {
    /// Starts a report with no files written.
    pub fn begin() -> Self {
        Self::default()
    }

    /// Runs `f`, recording the report files it writes on this thread (not
    /// those written by work it hands to other threads). The threads of
    /// reports written in parallel each record into the one list; a thread
    /// that takes up another report's work while it waits (rayon's work
    /// stealing) records that work into that report's list, and returns to
    /// this one after it.
    pub fn record<R>(&self, f: impl FnOnce() -> R) -> R {
        /// Puts the list that was there back, also when `f` panics.
        struct Restore(Option<Written>);
        impl Drop for Restore {
            fn drop(&mut self) {
                let before = self.0.take();
                WRITTEN.with(|w| *w.borrow_mut() = before);
            }
        }
        let _restore = Restore(WRITTEN.with(|w| w.replace(Some(self.written.clone()))));
        f()
    }

    /// Keeps every file written: the report is complete.
    pub fn finish(mut self) {
        self.finished = true;
    }
}

impl Drop for ReportFiles {
    fn drop(&mut self) {
        if self.finished {
            return;
        }
        // A thread that panicked while holding the list left it whole (a
        // push), so a poisoned lock still gives every path.
        let written = std::mem::take(
            &mut *self
                .written
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner),
        );
        for path in written {
            let _ = fs::remove_file(path);
        }
    }
}

/// [`write_atomic`] for a report's files, its failure in words with the
/// file named (a full disk said only "No space left on device"); recorded
/// for [`ReportFiles`] once written (a write that failed left nothing of
/// ours at the path, and what is there, a link refused, stays).
pub fn write_report_file(path: &Path, bytes: &[u8]) -> Result<(), String> {
    write_atomic(path, bytes).map_err(|e| {
        format!(
            "cannot write {}: {}",
            path.display(),
            crate::experiment::source::describe(&e)
        )
    })?;
    WRITTEN.with(|w| {
        if let Some(list) = w.borrow().as_ref() {
            list.lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .push(path.to_path_buf());
        }
    });
    Ok(())
}

/// Whether `name` is one of [`write_atomic`]'s temporary files
/// (`.<name>.<pid>.<n>.tmp`).
fn is_temporary(name: &str) -> bool {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let Some(inner) = name.strip_prefix('.').and_then(|n| n.strip_suffix(".tmp")) else {
        return false;
    };
    let mut parts = inner.rsplitn(3, '.');
    matches!(
        (parts.next(), parts.next(), parts.next()),
        (Some(n), Some(pid), Some(file)) if digits(n) && digits(pid) && !file.is_empty()
    )
}

/// The extensions of the files a report writes into an experiment's folder
/// (its pages, its table of results, its plots and images); the results and
/// the experiment file are not among them.
const REPORT_EXTENSIONS: [&str; 6] = ["md", "html", "csv", "svg", "png", "pfm"];

/// Whether a run or a merge writes a file named `name` into an experiment's
/// folder: the experiment file, its Mitsuba values, results (a shard's
/// too) and the report's files.
pub fn written_here(name: &str) -> bool {
    let report = Path::new(name)
        .extension()
        .and_then(|x| x.to_str())
        .is_some_and(|x| REPORT_EXTENSIONS.contains(&x));
    report
        || name == SUMMARY_FILE
        || name == "experiment.json"
        || name == crate::experiment::source::VALUES_COPY
        || (name.starts_with("results") && name.ends_with(".jsonl"))
}

/// The summary a report writes beside its index and in each experiment's
/// folder ([`crate::experiment::report::ReportSummary`]).
pub const SUMMARY_FILE: &str = "summary.json";

/// The files a run or a merge writes into the output folder itself.
pub const WRITTEN_AT_TOP: [&str; 3] = ["index.md", "index.html", SUMMARY_FILE];

/// Removes what an earlier run's report wrote: the index of `out` and the
/// report files of the experiment folders `names` (regular files only: a
/// folder that is a link is not entered). A run that is killed before its
/// own report is written then leaves no report, rather than the earlier one
/// looking complete beside the new results (and no image of a rule the
/// experiment no longer has).
pub fn clear_reports<'a>(out: &Path, names: impl IntoIterator<Item = &'a str>) {
    for index in WRITTEN_AT_TOP {
        let _ = fs::remove_file(out.join(index));
    }
    for name in names {
        let dir = out.join(name);
        if links::is_link(&dir) {
            continue;
        }
        let Ok(entries) = fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let path = e.path();
            let report = path
                .extension()
                .and_then(|x| x.to_str())
                .is_some_and(|x| REPORT_EXTENSIONS.contains(&x))
                || e.file_name() == SUMMARY_FILE;
            if report && e.file_type().is_ok_and(|t| t.is_file()) {
                let _ = fs::remove_file(&path);
            }
        }
    }
}

/// Removes the temporary files that runs killed while writing left in `out`
/// and its experiment folders; for a caller that holds the folder's lock
/// alone (no other run writes there).
pub fn remove_stale_temporaries(out: &Path) {
    let Ok(top) = fs::read_dir(out) else {
        return;
    };
    // Folders and files as they are, links not followed: a link to a folder
    // elsewhere is not entered.
    let mut dirs = vec![out.to_path_buf()];
    dirs.extend(
        top.flatten()
            .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
            .map(|e| e.path()),
    );
    for dir in dirs {
        let Ok(entries) = fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            if e.file_name().to_str().is_some_and(is_temporary)
                && e.file_type().is_ok_and(|t| t.is_file())
            {
                let _ = fs::remove_file(e.path());
            }
        }
    }
}

/// The results file of experiment `name` under `out`: `results.jsonl`, or a
/// shard's own file.
pub fn results_path(out: &Path, name: &str, shard: Option<(usize, usize)>) -> PathBuf {
    out.join(name).join(match shard {
        None => "results.jsonl".to_string(),
        Some((k, n)) => format!("results.shard-{k}-of-{n}.jsonl"),
    })
}

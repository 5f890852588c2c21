//! The output folder: its lock (one run or merge at a time per folder or
//! shard), the check that it can be written, an experiment's own folder,
//! and the values files a run keeps.

use std::fs;
use std::path::{Path, PathBuf};

use crate::experiment::registry::Loaded;
use crate::experiment::run::{WRITTEN_AT_TOP, links, write_atomic, written_here};
use crate::experiment::source;

use super::{RunError, io};

/// Holds `<out>/.lightquad.lock` locked for as long as the run writes there
/// (`run --shard` runs share it, each holding its shard's own lock alone, so
/// shards may share a folder but a whole run or a merge may not join them): a second run
/// into the same folder stops at once with an error instead of replacing the
/// first's results file while the first keeps appending to the replaced one
/// (528 jobs reported, 76 lines left). The lock is advisory and released by
/// the operating system when the process ends, also after `kill -9`.
pub(super) fn lock_output(
    out: &Path,
    shard: Option<(usize, usize)>,
) -> Result<Vec<fs::File>, RunError> {
    // Never through a link: a link to nothing there had its target created.
    let open = |name: String| {
        let path = out.join(name);
        if links::is_link(&path) {
            return Err(io(&path, links::link_words(&path)));
        }
        links::open_or_create(&path)
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
pub(super) fn keep_values(exp: &dyn Loaded, dir: &Path) -> Result<(), RunError> {
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

/// Refuses a link where the run writes into the output folder itself (its
/// index pages); the experiment folders are [`experiment_folder`]'s.
pub(super) fn no_top_links(out: &Path) -> Result<(), RunError> {
    for name in WRITTEN_AT_TOP {
        let path = out.join(name);
        if links::is_link(&path) {
            return Err(io(&path, links::link_words(&path)));
        }
    }
    Ok(())
}

/// Makes an experiment's folder under `--out` (or finds it there), with no
/// folder where its files go and no link where it or its files go; what is
/// in the way is named.
pub(super) fn experiment_folder(dir: &Path) -> Result<(), RunError> {
    if links::is_link(dir) {
        return Err(io(dir, links::link_words(dir)));
    }
    if fs::symlink_metadata(dir).is_ok() && !dir.is_dir() {
        return Err(io(
            dir,
            "is in the way: a file where this experiment's results folder \
             goes; expected a folder or nothing (remove it, or choose another --out)",
        ));
    }
    fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let entries = fs::read_dir(dir).map_err(|e| io(dir, e))?;
    for e in entries.flatten() {
        let written = e.file_name().to_str().is_some_and(written_here);
        if written && e.file_type().is_ok_and(|t| t.is_symlink()) {
            return Err(io(&e.path(), links::link_words(&e.path())));
        }
    }
    for file in [
        "experiment.json",
        "results.jsonl",
        "report.md",
        "index.html",
        crate::experiment::run::SUMMARY_FILE,
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
pub(super) fn writable(dir: &Path) -> Result<(), RunError> {
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

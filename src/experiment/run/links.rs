//! No links followed inside the output folder: every path a run or a merge
//! creates or writes under `--out` (experiment folders, locks, results,
//! report pages, images, temporary files) is refused when it is a symbolic
//! link, so nothing is written outside the folder through one. `--out`
//! itself may be a link (the user's own choice of where the report goes).
//!
//! New files are created with `create_new` (which fails on any existing
//! name, a link to nothing included, rather than creating the link's
//! target); an existing file is opened and then checked to be the very file
//! at its path (same device and inode as the path's own, unfollowed, entry),
//! so a link put in its place between the check and the open is caught.

use std::fs::{self, File, OpenOptions};
use std::io;
use std::path::Path;

/// What is wrong with a link at `path` where the run writes: where it
/// points, and that links in the output folder are not followed.
pub fn link_words(path: &Path) -> String {
    let target = fs::read_link(path).map_or_else(|_| "?".to_string(), |t| t.display().to_string());
    format!(
        "is a link (to {target}): lightquad does not follow links in its output folder \
         (--out); expected a file, a folder or nothing there (remove the link, or choose \
         another --out)"
    )
}

/// The error for a link at `path` where the run writes, naming the path.
pub fn link_error(path: &Path) -> io::Error {
    io::Error::other(format!("{} {}", path.display(), link_words(path)))
}

/// Whether `path` itself (not what it points to) is a symbolic link.
pub fn is_link(path: &Path) -> bool {
    fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink())
}

/// `Ok` when `path` is not a symbolic link (absent, a file, a folder).
pub fn refuse_link(path: &Path) -> io::Result<()> {
    if is_link(path) {
        Err(link_error(path))
    } else {
        Ok(())
    }
}

/// A new file at `path`, for writing; fails when anything is there, a link
/// included (whose target is then left uncreated).
pub fn create_new(path: &Path) -> io::Result<File> {
    OpenOptions::new().write(true).create_new(true).open(path)
}

/// `path` opened with `options` (which must not create it), refused when
/// the path is a link, also one put there between the check and the open:
/// the file opened must be the one the path's own entry names.
pub fn open_unlinked(path: &Path, options: &OpenOptions) -> io::Result<File> {
    refuse_link(path)?;
    refuse_special(path)?;
    let file = options.open(path)?;
    if !same_entry(&file, path)? {
        return Err(link_error(path));
    }
    Ok(file)
}

/// Refuses an existing `path` that is not a regular file (a FIFO planted as
/// the lock file blocked the run forever at its opening).
pub fn refuse_special(path: &Path) -> io::Result<()> {
    match fs::symlink_metadata(path) {
        Ok(meta) if !meta.is_file() => Err(io::Error::other(format!(
            "{}: lightquad writes only regular files in its output folder (--out); remove it",
            crate::experiment::source::not_regular(&meta)
        ))),
        _ => Ok(()),
    }
}

/// Opens `path` for writing without truncating it: created new when absent,
/// else the file there, never through a link.
pub fn open_or_create(path: &Path) -> io::Result<File> {
    refuse_link(path)?;
    match create_new(path) {
        Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {
            open_unlinked(path, OpenOptions::new().write(true))
        }
        other => other,
    }
}

/// Whether the open `file` is the entry at `path` itself (not a file a link
/// there points to).
#[cfg(unix)]
fn same_entry(file: &File, path: &Path) -> io::Result<bool> {
    use std::os::unix::fs::MetadataExt;
    let (opened, entry) = (file.metadata()?, fs::symlink_metadata(path)?);
    Ok(!entry.file_type().is_symlink()
        && opened.dev() == entry.dev()
        && opened.ino() == entry.ino())
}

/// Whether the open `file` is the entry at `path` itself: where inodes
/// cannot be compared, the entry is at least no link.
#[cfg(not(unix))]
fn same_entry(_file: &File, path: &Path) -> io::Result<bool> {
    Ok(!is_link(path))
}

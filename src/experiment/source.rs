//! Where experiments and their Mitsuba values come from: files, or the
//! bundled suite built into the binary (every `experiments/*.json` and
//! `reference/values/*.json` of the source tree, embedded by `build.rs`), so
//! that `lightquad run` works the same from any folder.
//!
//! A Mitsuba values file is looked for relative to the experiment file, never
//! the working folder: first the file its `reference` names (`{"type":
//! "mitsuba", "file": ...}`, relative to the experiment file's folder), then
//! `<experiment folder>/../reference/values/<name>.json` (this repository's
//! layout), then the values built into the binary. Values are keyed by the
//! experiment file's hash, so the first one made from these exact bytes is
//! used wherever it was found.
//!
//! ```
//! use lightquad::experiment::source::{Origin, Values, bundled_experiments, find_values};
//! use lightquad::experiment::run::file_hash;
//!
//! // The bundled suite holds the experiments of experiments/ ...
//! let (file, text) = bundled_experiments()
//!     .iter()
//!     .find(|(f, _)| *f == "v-l-single-scattering.json")
//!     .expect("bundled");
//! assert!(text.contains("\"family\": \"volume\""));
//! // ... and their Mitsuba values, found for these bytes from any folder.
//! let hash = file_hash(text.as_bytes());
//! let found = find_values(&Origin::Bundled, "v-l-single-scattering", &hash, None);
//! assert!(matches!(found, Values::Found { .. }), "{file}: {found:?}");
//! // An edited copy is told apart by its hash: the values are stale.
//! let stale = find_values(&Origin::Bundled, "v-l-single-scattering", "0123", None);
//! assert!(matches!(stale, Values::Stale { .. }));
//! ```

use std::fs;
use std::path::{Path, PathBuf};

mod generated {
    include!(concat!(env!("OUT_DIR"), "/bundled.rs"));
}

/// The bundled experiment files: (file name, exact text), sorted by name.
pub fn bundled_experiments() -> &'static [(&'static str, &'static str)] {
    generated::EXPERIMENTS
}

/// The bundled Mitsuba values file of experiment `name`, if any.
pub fn bundled_values(name: &str) -> Option<&'static str> {
    let file = format!("{name}.json");
    generated::VALUES
        .iter()
        .find(|(f, _)| *f == file)
        .map(|(_, text)| *text)
}

/// Where to find the experiments of a run.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// An experiment file.
    File(PathBuf),
    /// A file of the bundled suite, by file name (e.g. `v-l-single-scattering.json`).
    Bundled(&'static str),
}

impl Source {
    /// The whole bundled suite.
    pub fn bundled_suite() -> Vec<Source> {
        bundled_experiments()
            .iter()
            .map(|(f, _)| Source::Bundled(f))
            .collect()
    }

    /// The path shown in messages: the file, or `<bundled>/<file name>`.
    pub fn display(&self) -> String {
        match self {
            Source::File(p) => p.display().to_string(),
            Source::Bundled(f) => format!("<bundled>/{f}"),
        }
    }

    /// The file's bytes.
    pub fn read(&self) -> Result<Vec<u8>, String> {
        match self {
            Source::File(p) => read_regular(p),
            Source::Bundled(f) => bundled_experiments()
                .iter()
                .find(|(name, _)| name == f)
                .map(|(_, text)| text.as_bytes().to_vec())
                .ok_or_else(|| {
                    format!(
                        "no such bundled experiment; the bundled ones are {}",
                        bundled_experiments()
                            .iter()
                            .map(|(f, _)| *f)
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                }),
        }
    }

    /// Where relative paths inside the experiment are resolved.
    pub fn origin(&self) -> Origin {
        match self {
            Source::File(p) => Origin::Folder(match p.parent() {
                Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
                _ => PathBuf::from("."),
            }),
            Source::Bundled(_) => Origin::Bundled,
        }
    }
}

/// Where a loaded experiment came from: relative paths inside it (a Mitsuba
/// values file) are resolved against it.
#[derive(Debug, Clone, PartialEq)]
pub enum Origin {
    /// A file in this folder.
    Folder(PathBuf),
    /// The bundled suite: its values are the bundled ones.
    Bundled,
}

impl Default for Origin {
    /// The working folder (for experiments given as JSON, without a file).
    fn default() -> Self {
        Origin::Folder(PathBuf::from("."))
    }
}

/// The Mitsuba values of an experiment, as [`find_values`] found them.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// None expected and none found: the experiment has no Mitsuba comparison.
    NotExpected,
    /// A values file made from this experiment's exact bytes.
    Found {
        /// Where it was found (a path, or `<bundled>/values/<name>.json`).
        location: String,
        /// Its JSON.
        json: serde_json::Value,
    },
    /// Values for another version of the experiment (another hash) only.
    Stale {
        /// Where they were found.
        location: String,
        /// The hash they were made from.
        made_from: String,
        /// The file the reference names, where it could not be read, and
        /// why (the stale values were found elsewhere).
        named_missing: Option<String>,
    },
    /// The file the reference names exists but is not a values file (another
    /// JSON file, not JSON, a folder): said as such, not reported stale
    /// because other values were found elsewhere.
    NotValues {
        /// The file.
        location: String,
        /// What it is instead.
        why: String,
    },
    /// Expected (the experiment names a values file, or is one of the bundled
    /// experiments with Mitsuba values) but found nowhere.
    Missing {
        /// Where they were looked for.
        looked: Vec<String>,
    },
}

/// The copy of its Mitsuba values a run writes beside `experiment.json` in
/// the experiment's output folder.
pub const VALUES_COPY: &str = "mitsuba-values.json";

/// Looks for the Mitsuba values of experiment `name` whose file hashes to
/// `hash`: `named` (the file its reference names, relative to the experiment
/// file's folder), then the copy a run kept in that folder ([`VALUES_COPY`],
/// where it is: a run's output folder read again by `merge`), then
/// `<folder>/../reference/values/<name>.json`, then the bundled values. The first made from these bytes wins; otherwise the first
/// found is stale.
pub fn find_values(origin: &Origin, name: &str, hash: &str, named: Option<&str>) -> Values {
    // Each place with its values, or why it has none (said when none is found).
    let mut places: Vec<(String, Result<serde_json::Value, String>)> = Vec::new();
    let mut named_missing = None;
    if let Origin::Folder(dir) = origin {
        if let Some(file) = named {
            let path = resolve(dir, file);
            // The name is the user's text: said as an excerpt.
            let shown = crate::error::excerpt(&path.display().to_string());
            let json = read_text(&path).and_then(|t| values_json(&t));
            // A file that is there but is no values file is the fault, even
            // where other (stale) values are found.
            if let Err(why) = &json
                && path.exists()
            {
                return Values::NotValues {
                    location: shown,
                    why: why.clone(),
                };
            }
            if let Err(why) = &json {
                named_missing = Some(format!("{shown} ({why})"));
            }
            places.push((shown, json));
        }
        let copy = dir.join(VALUES_COPY);
        if copy.is_file() {
            places.push((
                copy.display().to_string(),
                read_text(&copy).and_then(|t| values_json(&t)),
            ));
        }
        let path = dir
            .join("..")
            .join("reference")
            .join("values")
            .join(format!("{name}.json"));
        places.push((
            path.display().to_string(),
            read_text(&path).and_then(|t| values_json(&t)),
        ));
    }
    places.push((
        format!("<bundled>/values/{name}.json"),
        bundled_values(name)
            .ok_or_else(|| "not bundled".to_string())
            .and_then(values_json),
    ));
    let mut stale = None;
    for (location, json) in &places {
        let Ok(json) = json else {
            continue;
        };
        let made_from = json["experiment_hash"].as_str().unwrap_or("").to_string();
        if made_from == hash {
            return Values::Found {
                location: location.clone(),
                json: json.clone(),
            };
        }
        stale.get_or_insert(Values::Stale {
            location: location.clone(),
            made_from,
            named_missing: named_missing.clone(),
        });
    }
    if let Some(s) = stale {
        s
    } else if named.is_some() || bundled_values(name).is_some() {
        Values::Missing {
            looked: places
                .into_iter()
                .map(|(l, json)| match json {
                    Err(why) => format!("{l} ({why})"),
                    Ok(_) => l,
                })
                .collect(),
        }
    } else {
        Values::NotExpected
    }
}

/// The JSON of a Mitsuba values file, or why `text` is not one: another
/// JSON file was reported "stale" (made from the hash "").
pub fn values_json(text: &str) -> Result<serde_json::Value, String> {
    let json: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let missing: Vec<&str> = [
        ("experiment_hash", json["experiment_hash"].is_string()),
        ("quantities", json["quantities"].is_object()),
    ]
    .into_iter()
    .filter(|(_, present)| !present)
    .map(|(field, _)| field)
    .collect();
    if missing.is_empty() {
        // The hash is said in messages (a stale file's): only one of the
        // form lightquad writes, never any string a JSON file holds.
        let hash = json["experiment_hash"].as_str().unwrap_or("");
        if !is_file_hash(hash) {
            return Err(format!(
                "not a Mitsuba values file: its `experiment_hash` ({} characters) is not a hash \
                 of an experiment file (16 lowercase hexadecimal digits, as scripts/reference.sh \
                 writes it)",
                hash.chars().count()
            ));
        }
        Ok(json)
    } else {
        Err(format!(
            "not a Mitsuba values file: it has no {} (scripts/reference.sh writes \
             `experiment_hash`, a string, and `quantities`, an object of values)",
            missing
                .iter()
                .map(|f| format!("`{f}`"))
                .collect::<Vec<_>>()
                .join(" and ")
        ))
    }
}

/// Whether `hash` has the form of [`crate::experiment::run::file_hash`]'s:
/// 16 lowercase hexadecimal digits.
fn is_file_hash(hash: &str) -> bool {
    hash.len() == 16 && hash.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'))
}

/// Why a file operation failed, in words with the operating system's own
/// (`not found`, `permission denied`, `is a directory`).
pub fn describe(e: &std::io::Error) -> String {
    use std::io::ErrorKind::*;
    let words = match e.kind() {
        NotFound => "not found",
        PermissionDenied => "permission denied",
        IsADirectory => "is a directory",
        NotADirectory => "a part of the path is a file, not a directory",
        AlreadyExists => "already exists",
        ReadOnlyFilesystem => "the file system is read-only",
        StorageFull => "no space left on the device",
        _ => return e.to_string(),
    };
    match e.raw_os_error() {
        Some(code) => format!("{words} (os error {code})"),
        None => words.to_string(),
    }
}

/// What kind of thing a path that is not a regular file is (`is a FIFO
/// (named pipe)`, `is a device`, ...).
pub fn not_regular(meta: &fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "is a FIFO (named pipe)";
        }
        if t.is_char_device() || t.is_block_device() {
            return "is a device";
        }
        if t.is_socket() {
            return "is a socket";
        }
    }
    if meta.is_dir() {
        "is a directory"
    } else {
        "is not a regular file"
    }
}

/// `file` relative to `dir` (absolute paths as they are).
fn resolve(dir: &Path, file: &str) -> PathBuf {
    let file = Path::new(file);
    if file.is_absolute() {
        file.to_path_buf()
    } else {
        dir.join(file)
    }
}

/// The largest experiment or values file read: far above any real one (the
/// bundled ones are under 10 KiB), far below what would exhaust memory.
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// The bytes of a regular file of at most [`MAX_FILE_BYTES`]: a FIFO,
/// `/dev/zero` or a directory is refused at once instead of read forever.
pub fn read_regular(path: &Path) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let meta = fs::metadata(path).map_err(|e| describe(&e))?;
    if !meta.is_file() {
        return Err(format!(
            "{}: expected a regular JSON file",
            not_regular(&meta)
        ));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!(
            "{} bytes: expected a file of at most {MAX_FILE_BYTES} bytes",
            meta.len()
        ));
    }
    let mut bytes = Vec::new();
    fs::File::open(path)
        .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| describe(&e))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(format!("grew past {MAX_FILE_BYTES} bytes while read"));
    }
    Ok(bytes)
}

/// [`read_regular`] as UTF-8 text.
pub fn read_text(path: &Path) -> Result<String, String> {
    String::from_utf8(read_regular(path)?).map_err(|e| format!("not UTF-8: {e}"))
}

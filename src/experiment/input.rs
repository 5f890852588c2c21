//! Reading experiment files: a path or a bundled source to its bytes and
//! its loaded experiment, several files loaded at once (their names checked
//! unique), and the experiment files of a folder.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

use crate::experiment::registry::{Loaded, Registry};
use crate::experiment::run::file_hash;
use crate::experiment::source::Source;
use crate::experiment::validate::{self, SpecError};

use super::{RunError, io};

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
pub(super) fn load_all(registry: &Registry, files: &[Source]) -> Result<Vec<Input>, RunError> {
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

/// The experiment files of a folder, sorted: every `.json` file but a JSON
/// Schema kept beside them (a name ending in `schema.json`, as
/// `lightquad schema > lightquad.schema.json` writes it).
pub fn experiment_files(dir: &Path) -> Result<Vec<PathBuf>, RunError> {
    let mut files: Vec<PathBuf> = fs::read_dir(dir)
        .map_err(|e| io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json") && !is_schema(p))
        .collect();
    files.sort();
    Ok(files)
}

/// Whether `path` names a JSON Schema file (`schema.json`,
/// `lightquad.schema.json`), which an experiment folder may hold for editors.
fn is_schema(path: &Path) -> bool {
    path.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.ends_with("schema.json"))
}

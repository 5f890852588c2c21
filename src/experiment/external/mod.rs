//! External estimators: a program outside lightquad (a renderer, a
//! prototype, Mitsuba 3) listed among an experiment's rules and judged in the
//! same report as lightquad's own rules.
//!
//! ```json
//! {"rule": "external", "name": "my-renderer", "command": ["python3", "my_estimator.py"], "timeout_s": 60}
//! ```
//!
//! The program is started when a lane first needs it and then answers one
//! request after another on its stdin and stdout, one JSON line each
//! ([`protocol`]; `docs/external-estimators.md`). A relative program path
//! and the program's working folder are the experiment file's folder (for
//! the bundled suite, `experiments/` of the source tree the binary was
//! built from); the program receives nothing of the machine but what the
//! experiment states.
//!
//! ```
//! use lightquad::experiment::external::External;
//!
//! let rule: External = serde_json::from_str(
//!     r#"{"name": "my-renderer", "command": ["python3", "estimate.py"]}"#,
//! )?;
//! assert_eq!(rule.timeout_s, 60.0); // the default
//! assert!(rule.random);
//! # Ok::<(), serde_json::Error>(())
//! ```

pub mod protocol;
mod server;

use std::path::{Path, PathBuf};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

pub use server::{Program, Servers, Watcher};

use super::source::Origin;

/// The longest an external estimator may take for one request, seconds.
pub const MAX_TIMEOUT_S: f64 = 86_400.0;

/// The longest name of an external estimator (it labels rows, plots and
/// file columns).
pub const MAX_NAME: usize = 60;

/// `{"rule": "external", ...}` of an experiment file: a program that
/// estimates the experiment's quantities (the `rule` tag itself is read by
/// [`crate::family::Listed`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct External {
    /// Its name in the reports (letters, digits, `-`, `_`, `.`; not the name
    /// of one of lightquad's own rules).
    pub name: String,
    /// The program and its arguments: `["python3", "my_estimator.py"]`. A
    /// program path with a `/` is relative to the experiment file's folder,
    /// which is also the program's working folder; a bare name is looked up
    /// on `PATH`.
    pub command: Vec<String>,
    /// Seconds lightquad waits for one answer before it stops the program
    /// and fails the job (default 60, at most 86400).
    #[serde(default = "default_timeout")]
    pub timeout_s: f64,
    /// True (the default) when the estimate is random: the report then tests
    /// its bias and its standard errors over the repeats.
    #[serde(default = "yes")]
    pub random: bool,
    /// What a missing program means: `"fail"` (the default) refuses the
    /// experiment at `check`; `"skip"` runs the rest and says in the report
    /// why this rule has no rows (for a bundled experiment whose program is
    /// optional, such as Mitsuba's harness in its own environment).
    #[serde(default)]
    pub if_missing: IfMissing,
}

fn default_timeout() -> f64 {
    60.0
}

fn yes() -> bool {
    true
}

/// [`External::if_missing`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum IfMissing {
    /// Refuse the experiment.
    #[default]
    Fail,
    /// Run the rest; the report says why this rule has no rows.
    Skip,
}

/// Where an external estimator's program was found, or why it was not.
#[derive(Debug, Clone, PartialEq)]
pub enum Found {
    /// Ready to start.
    Program(Program),
    /// Missing, and its rule asks to be skipped: the reason.
    Skipped(String),
}

impl External {
    /// Checks the name, command and timeout and finds the program from
    /// `origin`; `taken` are the names of lightquad's own rules. An error
    /// names its field below the rule's path.
    pub fn check(&self, origin: &Origin, taken: &[&str]) -> Result<Found, (String, String)> {
        self.check_name(taken)?;
        if !(self.timeout_s.is_finite() && self.timeout_s > 0.0 && self.timeout_s <= MAX_TIMEOUT_S)
        {
            return Err((
                "timeout_s".into(),
                format!(
                    "{}: expected seconds in (0, {MAX_TIMEOUT_S}]",
                    self.timeout_s
                ),
            ));
        }
        let Some(program) = self.command.first() else {
            return Err((
                "command".into(),
                "an empty list: expected the program and its arguments, \
                 [\"python3\", \"my_estimator.py\"]"
                    .into(),
            ));
        };
        if let Some(k) = self
            .command
            .iter()
            .position(|a| a.is_empty() || a.contains('\0'))
        {
            return Err((
                format!("command[{k}]"),
                "an empty string or one with a NUL byte: expected a program name or argument"
                    .into(),
            ));
        }
        // Absolute, as the program starts in `folder` (a relative path would
        // be read from there a second time).
        let folder = std::path::absolute(folder(origin)).map_err(|e| {
            (
                "command[0]".to_string(),
                format!("the experiment's folder cannot be resolved: {e}"),
            )
        })?;
        match locate(program, &folder) {
            Ok(path) => Ok(Found::Program(Program {
                path,
                args: self.command[1..].to_vec(),
                folder,
            })),
            Err(why) => match self.if_missing {
                IfMissing::Fail => Err(("command[0]".into(), why)),
                IfMissing::Skip => Ok(Found::Skipped(why)),
            },
        }
    }

    fn check_name(&self, taken: &[&str]) -> Result<(), (String, String)> {
        let fits = !self.name.is_empty()
            && self.name.len() <= MAX_NAME
            && self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'));
        if !fits {
            return Err((
                "name".into(),
                format!(
                    "{:?}: expected 1 to {MAX_NAME} letters, digits, `-`, `_` or `.`",
                    crate::error::excerpt(&self.name)
                ),
            ));
        }
        if !self.name.chars().any(|c| c.is_ascii_alphanumeric()) {
            return Err((
                "name".into(),
                format!("{:?}: expected at least one letter or digit", self.name),
            ));
        }
        if taken.iter().any(|t| t.eq_ignore_ascii_case(&self.name))
            || self.name.eq_ignore_ascii_case("external")
        {
            return Err((
                "name".into(),
                format!(
                    "{:?} is the name of one of lightquad's own rules: name the program for what it is",
                    self.name
                ),
            ));
        }
        Ok(())
    }
}

/// The folder relative paths of an experiment are read from: the file's
/// own, or `experiments/` of the source tree for the bundled suite.
pub fn folder(origin: &Origin) -> PathBuf {
    match origin {
        Origin::Folder(dir) => dir.clone(),
        Origin::Bundled => Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments"),
    }
}

/// The program file `name` names: relative to `folder` when it has a `/`,
/// else the first executable of that name on `PATH`.
fn locate(name: &str, folder: &Path) -> Result<PathBuf, String> {
    if name.contains('/') {
        let path = folder.join(name);
        return executable(&path).map(|()| path);
    }
    let dirs = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&dirs)
        .map(|d| d.join(name))
        .find(|p| executable(p).is_ok())
        .ok_or_else(|| format!("no program {name:?} on PATH"))
}

/// Ok when `path` is a regular file with an execute bit.
fn executable(path: &Path) -> Result<(), String> {
    use std::os::unix::fs::PermissionsExt;
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() && m.permissions().mode() & 0o111 != 0 => Ok(()),
        Ok(m) if m.is_file() => Err(format!("{} is not executable", path.display())),
        Ok(_) => Err(format!("{} is not a file", path.display())),
        Err(e) => Err(format!("no program {}: {e}", path.display())),
    }
}

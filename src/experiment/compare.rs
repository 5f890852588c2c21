//! `lightquad compare OLD NEW`: a run against a baseline. Two report
//! folders are compared experiment by experiment: every job's values, error
//! estimates, evaluation counts and failure (bit for bit, or within a
//! relative tolerance), every row's time (faster or slower only where the
//! two medians' confidence intervals do not overlap), and every rule's rank.
//!
//! ```
//! use lightquad::experiment::compare::{CompareOptions, compare};
//! use lightquad::experiment::run::RunOptions;
//!
//! let text = r#"{"name": "doc-compare", "family": "calibration", "scene": {}, "quantities": ["exp"],
//!   "rules": [{"rule": "trapezoid"}], "budgets": [8, 64], "repeats": 3, "reference": {"type": "closed-form"}}"#;
//! let base = std::env::temp_dir().join(format!("lightquad-doc-compare-{}", std::process::id()));
//! let file = base.join("e.json");
//! std::fs::create_dir_all(&base)?;
//! std::fs::write(&file, text)?;
//! let registry = lightquad::families::builtin();
//! for run in ["old", "new"] {
//!     let opts = RunOptions { out: base.join(run), resume: false, shard: None, progress: false };
//!     lightquad::experiment::run_files(&registry, &[file.clone()], &opts)?;
//! }
//! // The same build twice: every value agrees bit for bit.
//! let c = compare(&base.join("old"), &base.join("new"), &CompareOptions::default())?;
//! assert_eq!((c.values_changed(), c.jobs()), (0, 6));
//! assert!(c.markdown().contains("doc-compare"));
//! std::fs::remove_dir_all(&base)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::Path;

use super::report::{ExperimentSummary, ReportSummary, SUMMARY_VERSION};
use super::run::{JobKey, JobResult, SUMMARY_FILE, read_results_counted};
use super::timing::TimeInterval;

/// How to compare.
#[derive(Debug, Clone)]
pub struct CompareOptions {
    /// Values and error estimates agree where they differ by at most this
    /// much relative to the larger magnitude; None: bit for bit.
    pub tolerance: Option<f64>,
    /// Compare only these experiments (none: every one both folders have).
    pub experiments: Vec<String>,
    /// A time changed only where the ratio of the medians is beyond
    /// `1 + noise` either way (as well as the intervals being apart): what
    /// changes from one run to the next is outside both runs' intervals.
    pub noise: f64,
}

/// The default noise threshold: see [`CompareOptions::noise`] and the
/// README's measurement of two runs of one build.
pub const NOISE: f64 = super::timing::RUN_NOISE;

impl Default for CompareOptions {
    fn default() -> Self {
        CompareOptions {
            tolerance: None,
            experiments: Vec::new(),
            noise: NOISE,
        }
    }
}

/// A row's time, old against new.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Speed {
    /// The new interval lies wholly below the old.
    Faster,
    /// The new interval lies wholly above the old.
    Slower,
    /// The intervals overlap: no change the timings can tell.
    Unchanged,
}

/// A row whose time changed.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeChange {
    /// Quantity, rule label and budget.
    pub row: (String, String, usize),
    /// Faster or slower.
    pub speed: Speed,
    /// The old and new median times and intervals.
    pub old: TimeInterval,
    /// The new one.
    pub new: TimeInterval,
}

/// One experiment compared.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExperimentComparison {
    /// Its name.
    pub name: String,
    /// The experiment file's hash, old and new, where it changed.
    pub hash_changed: Option<(String, String)>,
    /// Jobs in both folders.
    pub jobs: usize,
    /// What changed in a job's values, one line each, and the baseline's
    /// jobs the new run lacks.
    pub values: Vec<String>,
    /// Jobs whose values changed or that the new run lacks.
    pub jobs_changed: usize,
    /// Jobs only the new run has (not a change: the baseline had less).
    pub added: Vec<String>,
    /// Rows compared by time: an interval on each side.
    pub timed_rows: usize,
    /// Rows with a single reading on a side, not judged.
    pub single: usize,
    /// Each timed row's new median over its old.
    pub ratios: Vec<f64>,
    /// Rows whose time changed beyond both intervals.
    pub times: Vec<TimeChange>,
    /// Rules whose standing changed: (quantity, label, old, new).
    pub ranks: Vec<(String, String, Standing, Standing)>,
    /// Pairs of rules of one quantity ranked apart in both runs, in
    /// opposite orders: (quantity, one label, the other).
    pub swapped: Vec<(String, String, String)>,
    /// What could not be compared.
    pub notes: Vec<String>,
}

/// A rule's place in its quantity's ranking at the middle target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Standing {
    /// Its rank (None: the target not reached).
    pub rank: Option<usize>,
    /// Whether another rule of the quantity holds the same rank (their
    /// times not told apart).
    pub tied: bool,
}

impl std::fmt::Display for Standing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.rank, self.tied) {
            (None, _) => f.write_str("—"),
            (Some(r), false) => write!(f, "{r}"),
            (Some(r), true) => write!(f, "{r} (tied)"),
        }
    }
}

/// Two report folders compared.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Comparison {
    /// The folders, as given.
    pub folders: (String, String),
    /// The tolerance used (None: bit for bit).
    pub tolerance: Option<f64>,
    /// The noise threshold used.
    pub noise: f64,
    /// Experiments in both.
    pub experiments: Vec<ExperimentComparison>,
    /// Experiments only the old folder has.
    pub only_old: Vec<String>,
    /// Experiments only the new folder has.
    pub only_new: Vec<String>,
}

/// Compares report folder `new` with the baseline `old`.
pub fn compare(old: &Path, new: &Path, opts: &CompareOptions) -> Result<Comparison, String> {
    if !(opts.noise.is_finite() && opts.noise >= 0.0) {
        return Err(format!(
            "invalid --noise = {}: expected a relative change >= 0 (0.5: a time must change by \
             more than 1.5x either way)",
            opts.noise
        ));
    }
    if let Some(t) = opts.tolerance
        && !(t.is_finite() && t >= 0.0)
    {
        return Err(format!(
            "invalid --tolerance = {t}: expected a relative tolerance >= 0 (0: bit for bit but \
             for the sign of zero)"
        ));
    }
    let (a, b) = (experiments_in(old)?, experiments_in(new)?);
    let wanted = |n: &String| opts.experiments.is_empty() || opts.experiments.contains(n);
    for n in &opts.experiments {
        if !a.contains(n) && !b.contains(n) {
            return Err(format!(
                "no experiment {n:?} in {} or {}: expected one of {}",
                old.display(),
                new.display(),
                a.union(&b).cloned().collect::<Vec<_>>().join(", ")
            ));
        }
    }
    let mut out = Comparison {
        folders: (old.display().to_string(), new.display().to_string()),
        tolerance: opts.tolerance,
        noise: opts.noise,
        only_old: a.difference(&b).filter(|n| wanted(n)).cloned().collect(),
        only_new: b.difference(&a).filter(|n| wanted(n)).cloned().collect(),
        ..Comparison::default()
    };
    if a.intersection(&b).filter(|n| wanted(n)).count() == 0 {
        return Err(format!(
            "no experiment to compare: {} holds {}, {} holds {}",
            old.display(),
            a.iter().cloned().collect::<Vec<_>>().join(", "),
            new.display(),
            b.iter().cloned().collect::<Vec<_>>().join(", ")
        ));
    }
    for name in a.intersection(&b).filter(|n| wanted(n)) {
        out.experiments
            .push(experiment(name, &old.join(name), &new.join(name), opts)?);
    }
    Ok(out)
}

/// The experiment folders of a report folder: those with a results.jsonl.
fn experiments_in(dir: &Path) -> Result<BTreeSet<String>, String> {
    let entries = std::fs::read_dir(dir).map_err(|e| {
        format!(
            "{}: {e}: expected a report folder (the --out of a run)",
            dir.display()
        )
    })?;
    let mut names = BTreeSet::new();
    for e in entries.flatten() {
        let results = e.path().join("results.jsonl");
        match std::fs::metadata(&results) {
            Ok(m) if m.is_file() => {}
            Ok(_) => {
                return Err(format!(
                    "{}: not a regular file (a device, a pipe, or a link to one): expected a \
                     run's results",
                    results.display()
                ));
            }
            Err(_) => continue,
        }
        match e.file_name().to_str() {
            Some(n) => names.insert(n.to_string()),
            None => {
                return Err(format!(
                    "{}: a folder name that is not UTF-8: no run writes one",
                    e.path().display()
                ));
            }
        };
    }
    if names.is_empty() {
        return Err(format!(
            "{}: no experiment folder with a results.jsonl: expected a report folder (the --out \
             of a run)",
            dir.display()
        ));
    }
    Ok(names)
}

/// One experiment, old against new.
fn experiment(
    name: &str,
    old: &Path,
    new: &Path,
    opts: &CompareOptions,
) -> Result<ExperimentComparison, String> {
    let tolerance = opts.tolerance;
    let mut c = ExperimentComparison {
        name: name.to_string(),
        ..ExperimentComparison::default()
    };
    let (a, b) = (jobs(old, &mut c.notes), jobs(new, &mut c.notes));
    let hash =
        |j: &BTreeMap<JobKey, JobResult>| j.values().next().map(|r| r.experiment_hash.clone());
    if let (Some(x), Some(y)) = (hash(&a), hash(&b))
        && x != y
    {
        c.hash_changed = Some((x, y));
    }
    for (key, x) in &a {
        let changes = match b.get(key) {
            Some(y) => {
                c.jobs += 1;
                job_changes(x, y, tolerance)
            }
            None => vec![format!("{} missing from the new run", job_name(x))],
        };
        c.jobs_changed += usize::from(!changes.is_empty());
        c.values.extend(changes);
    }
    for (key, y) in &b {
        if !a.contains_key(key) {
            c.added
                .push(format!("{} new (not in the baseline)", job_name(y)));
        }
    }
    let (ha, hb) = (hash(&a), hash(&b));
    match (
        summary(old, name, ha.as_deref()),
        summary(new, name, hb.as_deref()),
    ) {
        (Ok(x), Ok(y)) => times_and_ranks(&x, &y, opts.noise, &mut c),
        (Err(e), _) | (_, Err(e)) => c.notes.push(format!("times and ranks not compared: {e}")),
    }
    Ok(c)
}

/// An experiment folder's jobs by key; unread lines said in `notes`.
fn jobs(dir: &Path, notes: &mut Vec<String>) -> BTreeMap<JobKey, JobResult> {
    let path = dir.join("results.jsonl");
    let (results, unread) = read_results_counted(&path, None);
    if unread.unreadable > 0 {
        notes.push(format!(
            "{}: {} line(s) that are no job's result were passed over",
            path.display(),
            unread.unreadable
        ));
    }
    let lines = results.len();
    let jobs: BTreeMap<JobKey, JobResult> = results.into_iter().map(|r| (r.key(), r)).collect();
    if jobs.len() < lines {
        notes.push(format!(
            "{}: {} line(s) repeat a job of an earlier line; the last of each is compared",
            path.display(),
            lines - jobs.len()
        ));
    }
    jobs
}

/// How a job is named in a change.
fn job_name(r: &JobResult) -> String {
    format!("{} n = {} repeat {}", r.rule, r.budget, r.repeat)
}

/// Whether two numbers agree: bit for bit (NaN agrees with NaN), or, both
/// finite, within `tolerance` of the larger magnitude.
fn agree(x: f64, y: f64, tolerance: Option<f64>) -> bool {
    if x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()) {
        return true;
    }
    // A non-finite number agrees only with itself: against an infinite
    // magnitude every difference is "within" a relative tolerance.
    if !(x.is_finite() && y.is_finite()) {
        return false;
    }
    match tolerance {
        Some(t) => x == y || (x - y).abs() <= t * x.abs().max(y.abs()),
        None => false,
    }
}

/// The differences between two runs of one job, one line each.
fn job_changes(x: &JobResult, y: &JobResult, tolerance: Option<f64>) -> Vec<String> {
    let job = job_name(x);
    let mut out = Vec::new();
    if x.rule != y.rule || x.seed != y.seed {
        out.push(format!(
            "{job}: rule or seed changed ({} -> {})",
            x.rule, y.rule
        ));
    }
    if x.failure != y.failure {
        out.push(format!(
            "{job}: failure {:?} -> {:?}",
            x.failure.as_deref().unwrap_or("none"),
            y.failure.as_deref().unwrap_or("none")
        ));
    }
    let names: BTreeSet<&String> = x.quantities.keys().chain(y.quantities.keys()).collect();
    for q in names {
        let (Some(a), Some(b)) = (x.quantities.get(q), y.quantities.get(q)) else {
            out.push(format!("{job}: {q} only in one run"));
            continue;
        };
        let differs = |u: &[f64], v: &[f64]| {
            u.len() != v.len() || u.iter().zip(v).any(|(&s, &t)| !agree(s, t, tolerance))
        };
        if differs(&a.value, &b.value) {
            out.push(format!(
                "{job}: {q} value {} -> {}",
                numbers(&a.value),
                numbers(&b.value)
            ));
        }
        if differs(&a.error, &b.error) {
            out.push(format!(
                "{job}: {q} error estimate {} -> {}",
                numbers(&a.error),
                numbers(&b.error)
            ));
        }
        if a.evaluations != b.evaluations {
            out.push(format!(
                "{job}: {q} evaluations {} -> {}",
                a.evaluations, b.evaluations
            ));
        }
    }
    out
}

/// A channel vector in a line: every digit of up to 3 channels.
fn numbers(v: &[f64]) -> String {
    match v {
        [x] => format!("{x:e}"),
        _ if v.len() <= 3 => format!(
            "[{}]",
            v.iter()
                .map(|x| format!("{x:e}"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        _ => format!("{} channels", v.len()),
    }
}

/// The largest summary.json compare reads (the bundled suite's largest,
/// an image experiment's, is far below a megabyte).
const MAX_SUMMARY_BYTES: u64 = 256 << 20;

/// An experiment folder's summary.json, checked to be of experiment `name`
/// and of the results' experiment file (`hash`).
fn summary(dir: &Path, name: &str, hash: Option<&str>) -> Result<ExperimentSummary, String> {
    let path = dir.join(SUMMARY_FILE);
    // A pipe would block the read and a device (a link to /dev/zero) never
    // end it: only a regular file of a summary's size is read.
    match std::fs::metadata(&path) {
        Ok(m) if !m.is_file() => {
            return Err(format!(
                "{}: not a regular file (a device, a pipe, or a link to one)",
                path.display()
            ));
        }
        Ok(m) if m.len() > MAX_SUMMARY_BYTES => {
            return Err(format!(
                "{}: {} bytes, more than the {MAX_SUMMARY_BYTES} a summary is read up to",
                path.display(),
                m.len()
            ));
        }
        _ => {}
    }
    let text = std::fs::read_to_string(&path).map_err(|e| {
        format!(
            "{}: {e} (a report written before summary.json existed, or a run killed before its \
             report: `lightquad run --resume` writes it)",
            path.display()
        )
    })?;
    let s: ReportSummary = serde_json::from_str(&text).map_err(|e| {
        format!(
            "{}: not a summary.json this build reads: {e}",
            path.display()
        )
    })?;
    if s.summary_version != SUMMARY_VERSION {
        return Err(format!(
            "{}: summary_version {}, this build reads {SUMMARY_VERSION}",
            path.display(),
            s.summary_version
        ));
    }
    let e = s
        .experiments
        .into_iter()
        .next()
        .ok_or_else(|| format!("{}: no experiment in it", path.display()))?;
    if e.experiment != name || hash.is_some_and(|h| h != e.experiment_hash) {
        return Err(format!(
            "{}: the summary of {:?} (file hash {}), not of the results beside it ({name:?}, {}): \
             a stale or misplaced summary (`lightquad run --resume` writes it anew)",
            path.display(),
            e.experiment,
            e.experiment_hash,
            hash.unwrap_or("no job")
        ));
    }
    Ok(e)
}

/// Whether a time read from a summary is one a run writes: finite and
/// positive, its median inside its interval (an edited file's -1 s, or a
/// low end above the high, is no time to judge by).
fn plausible(t: &TimeInterval) -> bool {
    [t.low, t.median, t.high]
        .iter()
        .all(|x| x.is_finite() && *x > 0.0)
        && t.low <= t.median
        && t.median <= t.high
        && (0.0..=1.0).contains(&t.confidence)
}

/// The rows' times and the rules' ranks, old against new.
fn times_and_ranks(
    a: &ExperimentSummary,
    b: &ExperimentSummary,
    noise: f64,
    c: &mut ExperimentComparison,
) {
    type Key = (String, String, usize);
    // A row's time is its finished repeats' (a failed job is no sample of
    // it); a row where every repeat failed has none.
    let rows = |s: &ExperimentSummary| -> BTreeMap<Key, TimeInterval> {
        let mut m = BTreeMap::new();
        for q in &s.quantities {
            for r in &q.rules {
                for row in &r.rows {
                    if let Some(t) = row.seconds.filter(plausible) {
                        m.insert((q.quantity.clone(), r.label.clone(), row.budget), t);
                    }
                }
            }
        }
        m
    };
    let (ra, rb) = (rows(a), rows(b));
    let implausible: usize = [a, b]
        .iter()
        .flat_map(|s| &s.quantities)
        .flat_map(|q| &q.rules)
        .flat_map(|r| &r.rows)
        .filter(|row| row.seconds.is_some_and(|t| !plausible(&t)))
        .count();
    if implausible > 0 {
        c.notes.push(format!(
            "{implausible} row time(s) in the summaries are no time a run writes (not positive \
             and finite, or outside their own interval): not judged"
        ));
    }
    for (key, old) in &ra {
        let Some(new) = rb.get(key) else { continue };
        c.ratios.push(new.median / old.median);
        if old.samples < 2 || new.samples < 2 {
            c.single += 1;
            continue;
        }
        c.timed_rows += 1;
        let ratio = new.median / old.median;
        let speed = if new.high < old.low && ratio * (1.0 + noise) < 1.0 {
            Speed::Faster
        } else if new.low > old.high && ratio > 1.0 + noise {
            Speed::Slower
        } else {
            Speed::Unchanged
        };
        if speed != Speed::Unchanged {
            c.times.push(TimeChange {
                row: key.clone(),
                speed,
                old: *old,
                new: *new,
            });
        }
    }
    if a.ranked_at.to_bits() != b.ranked_at.to_bits() {
        c.notes.push(format!(
            "ranks not compared: the baseline ranks the rules by their time to {:e}, the new \
             run to {:e} (its targets changed)",
            a.ranked_at, b.ranked_at
        ));
        return;
    }
    let (ka, kb) = (standings(a), standings(b));
    for (key, old) in &ka {
        if let Some(new) = kb.get(key)
            && new != old
        {
            c.ranks.push((key.0.clone(), key.1.clone(), *old, *new));
        }
    }
    // Pairs of one quantity's rules ranked apart in both runs, in opposite orders.
    let both: Vec<(&(String, String), usize, usize)> = ka
        .iter()
        .filter_map(|(k, x)| Some((k, x.rank?, kb.get(k)?.rank?)))
        .collect();
    for (i, (k, x, y)) in both.iter().enumerate() {
        for (l, u, v) in &both[i + 1..] {
            if k.0 == l.0 && ((x < u && y > v) || (x > u && y < v)) {
                c.swapped.push((k.0.clone(), k.1.clone(), l.1.clone()));
            }
        }
    }
}

/// Each rule's standing by (quantity, label): its rank, and whether
/// another rule of the quantity holds the same one.
fn standings(s: &ExperimentSummary) -> BTreeMap<(String, String), Standing> {
    let mut out = BTreeMap::new();
    for q in &s.quantities {
        for r in &q.rules {
            let tied =
                r.rank.is_some() && q.rules.iter().filter(|other| other.rank == r.rank).count() > 1;
            let standing = Standing { rank: r.rank, tied };
            out.insert((q.quantity.clone(), r.label.clone()), standing);
        }
    }
    out
}

impl Comparison {
    /// What fails the comparison: every difference in a job's values, and
    /// every job and experiment of the baseline the new run lacks.
    pub fn values_changed(&self) -> usize {
        self.experiments
            .iter()
            .map(|e| e.values.len())
            .sum::<usize>()
            + self.only_old.len()
    }

    /// Jobs in both runs whose values differ, and the baseline's jobs the
    /// new run lacks.
    pub fn jobs_changed(&self) -> usize {
        self.experiments.iter().map(|e| e.jobs_changed).sum()
    }

    /// Jobs compared.
    pub fn jobs(&self) -> usize {
        self.experiments.iter().map(|e| e.jobs).sum()
    }

    /// The median over every timed row of new time / old time: the new
    /// run's pace against the baseline's (None: no row timed in both).
    pub fn pace(&self) -> Option<f64> {
        let mut r: Vec<f64> = self
            .experiments
            .iter()
            .flat_map(|e| e.ratios.iter().copied())
            .filter(|x| x.is_finite())
            .collect();
        r.sort_by(f64::total_cmp);
        (!r.is_empty()).then(|| r[r.len() / 2])
    }

    /// Rows faster, slower, and timed in both with an interval on each side.
    pub fn speeds(&self) -> (usize, usize, usize) {
        let count = |s| {
            self.experiments
                .iter()
                .flat_map(|e| &e.times)
                .filter(|t| t.speed == s)
                .count()
        };
        let timed = self.experiments.iter().map(|e| e.timed_rows).sum();
        (count(Speed::Faster), count(Speed::Slower), timed)
    }

    /// The comparison as a short Markdown page.
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "# lightquad compare\n\nBaseline `{}`, new `{}`.\n\n",
            self.folders.0, self.folders.1
        );
        let (faster, slower, timed) = self.speeds();
        let share = |k: usize| 100.0 * k as f64 / timed.max(1) as f64;
        let ranks: usize = self.experiments.iter().map(|e| e.ranks.len()).sum();
        let swapped: usize = self.experiments.iter().map(|e| e.swapped.len()).sum();
        let pace = self.pace().map_or("no row timed in both".into(), |p| {
            format!("the median row's new time is {p:.2}x its old")
        });
        let how = match self.tolerance {
            None => "bit for bit".to_string(),
            Some(t) => format!("within a relative {t:e}"),
        };
        let single: usize = self.experiments.iter().map(|e| e.single).sum();
        let single = if single > 0 {
            format!(
                "; {single} row(s) with a single reading on a side (one repeat) not judged: \
                 one reading has no interval"
            )
        } else {
            String::new()
        };
        let missing = if self.only_old.is_empty() {
            String::new()
        } else {
            format!(
                "; {} experiment(s) of the baseline missing from the new run",
                self.only_old.len()
            )
        };
        let _ = writeln!(
            md,
            "- experiments compared: {}{}{}\n- values ({how}): {} of {} job(s) in both differ or \
             are missing from the new run ({} difference(s)){missing}\n\
             - times: {faster} row(s) faster ({:.1}%), {slower} slower ({:.1}%), {} without a change \
             the timings can tell, of {timed} (faster or slower: the two medians' confidence \
             intervals are apart and their ratio is beyond {:.2}x either way, the noise \
             threshold; {pace}{single})\n- ranks at the middle target: {ranks} rule(s) changed \
             rank or tie (`N (tied)`: another rule holds rank N too); {swapped} pair(s) of rules ranked apart in both runs swapped order \
             (the other changes are rules moving between tied and apart, or into or out of the \
             ranking)\n",
            self.experiments.len(),
            listed(", only in the baseline: ", &self.only_old),
            listed(", only in the new run: ", &self.only_new),
            self.jobs_changed(),
            self.jobs(),
            self.values_changed() - self.only_old.len(),
            share(faster),
            share(slower),
            timed - faster - slower,
            1.0 + self.noise,
        );
        for e in &self.experiments {
            experiment_markdown(&mut md, e);
        }
        md
    }

    /// The comparison as an HTML page (the Markdown's).
    pub fn html(&self) -> String {
        super::html::markdown_page("lightquad compare", &self.markdown())
    }
}

/// Writes `compare.md` and `compare.html` into `dir` (made if missing), each
/// whole or not at all.
pub fn write(dir: &Path, c: &Comparison) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    super::run::write_atomic(&dir.join("compare.md"), c.markdown().as_bytes())
        .map_err(|e| format!("{}: {e}", dir.join("compare.md").display()))?;
    super::run::write_atomic(&dir.join("compare.html"), c.html().as_bytes())
        .map_err(|e| format!("{}: {e}", dir.join("compare.html").display()))
}

/// `", only in X: a, b"`, or nothing.
fn listed(lead: &str, names: &[String]) -> String {
    if names.is_empty() {
        String::new()
    } else {
        format!("{lead}{}", names.join(", "))
    }
}

/// A user's string (an experiment, rule or failure, a hash from a file) as
/// Markdown text on one line.
fn one_line(s: &str) -> String {
    super::markdown::plain(&s.replace(['\n', '\r'], " "))
}

/// Lines shown per kind of change before the rest are counted.
const SHOWN: usize = 20;

/// One experiment's section: only what changed, and what could not be compared.
fn experiment_markdown(md: &mut String, e: &ExperimentComparison) {
    let changed = e.hash_changed.is_some()
        || !e.values.is_empty()
        || !e.added.is_empty()
        || !e.times.is_empty()
        || !e.ranks.is_empty()
        || !e.notes.is_empty();
    let swapped = &e.swapped;
    if !changed {
        return;
    }
    let _ = writeln!(md, "## {}\n", one_line(&e.name));
    if let Some((a, b)) = &e.hash_changed {
        let _ = writeln!(
            md,
            "The experiment file changed (hash {} -> {}): values may differ for that reason.\n",
            one_line(a),
            one_line(b)
        );
    }
    for n in &e.notes {
        let _ = writeln!(md, "- {}", one_line(n));
    }
    for v in e.values.iter().take(SHOWN) {
        let _ = writeln!(md, "- value: {}", one_line(v));
    }
    if e.values.len() > SHOWN {
        let _ = writeln!(md, "- and {} more value change(s)", e.values.len() - SHOWN);
    }
    for v in e.added.iter().take(SHOWN) {
        let _ = writeln!(md, "- {}", one_line(v));
    }
    if e.added.len() > SHOWN {
        let _ = writeln!(md, "- and {} more new job(s)", e.added.len() - SHOWN);
    }
    if !e.times.is_empty() {
        md.push_str(
            "\n| quantity | rule | n | change | old median (s) | new median (s) | new / old | old interval | new interval |\n|---|---|---:|---|---:|---:|---:|---:|---:|\n",
        );
        for t in e.times.iter().take(SHOWN) {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.2e} | {:.2e} | {:.2} | {:.1e} to {:.1e} | {:.1e} to {:.1e} |",
                one_line(&t.row.0),
                one_line(&t.row.1),
                t.row.2,
                if t.speed == Speed::Faster {
                    "faster"
                } else {
                    "slower"
                },
                t.old.median,
                t.new.median,
                t.new.median / t.old.median,
                t.old.low,
                t.old.high,
                t.new.low,
                t.new.high
            );
        }
        if e.times.len() > SHOWN {
            let _ = writeln!(
                md,
                "\nand {} more row(s) faster or slower",
                e.times.len() - SHOWN
            );
        }
    }
    if !e.ranks.is_empty() {
        md.push('\n');
    }
    for (q, label, a, b) in &e.ranks {
        let _ = writeln!(
            md,
            "- rank of {} on {}: {a} -> {b}",
            one_line(label),
            one_line(q),
        );
    }
    for (q, x, y) in swapped {
        let _ = writeln!(
            md,
            "- {} and {} swapped order on {}",
            one_line(x),
            one_line(y),
            one_line(q)
        );
    }
    md.push('\n');
}

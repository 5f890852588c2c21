//! Running experiments: jobs (rule x budget x repeat) in parallel, each with a
//! random stream derived from (seed, job) so results do not depend on the
//! thread count; one JSON line per job appended as it finishes, so an
//! interrupted run keeps what it finished and `--resume` does only the rest.
//!
//! ```
//! use lightquad::experiment::run::{JobResult, RunOptions, file_hash, read_results, run_experiment};
//!
//! // FNV-1a: the empty file hashes to the offset basis.
//! assert_eq!(file_hash(b""), "cbf29ce484222325");
//! let text = r#"{"name": "doc-run", "family": "calibration", "scene": {}, "quantities": ["exp"],
//!   "rules": [{"rule": "gauss-legendre"}, {"rule": "monte-carlo"}], "budgets": [4, 16],
//!   "repeats": 2, "seed": 7, "reference": {"type": "closed-form"}}"#;
//! let registry = lightquad::families::builtin();
//! let exp = registry.load(serde_json::from_str(text)?, &file_hash(text.as_bytes()))?;
//! let out = std::env::temp_dir().join(format!("lightquad-doc-run-{}", std::process::id()));
//! let opts = RunOptions { out: out.clone(), resume: false, shard: None, progress: false };
//! let results = run_experiment(exp.as_ref(), &opts, &indicatif::ProgressBar::hidden())?;
//! assert_eq!(results.len(), 2 * 2 * 2); // rules x budgets x repeats
//! // One JSON line per job in <out>/<name>/results.jsonl.
//! let mut lines = read_results(&out.join("doc-run/results.jsonl"), Some(exp.hash()));
//! lines.sort_by_key(JobResult::key); // written in the order the jobs finished
//! assert_eq!(lines, results);
//! let gl = results.iter().find(|r| r.rule == "gauss-legendre" && r.budget == 16).ok_or("missing")?;
//! assert!((gl.quantities["exp"].value[0] - (std::f64::consts::E - 1.0)).abs() < 1e-15);
//! // Each job's seed comes from (seed, job), not from the thread that ran it.
//! assert_ne!(results[4].seed, results[5].seed);
//! std::fs::remove_dir_all(&out)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! `files` holds what a run reads and writes on disk: the results file read
//! back (and which of its lines are this experiment's jobs), atomic and
//! all-or-nothing writes, the report files and the clearing of stale ones;
//! the jobs, their seeds and timing, and running them (with `--resume`) are
//! here.

use std::collections::{BTreeMap, BTreeSet};
use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use rand::SeedableRng;
use serde::{Deserialize, Serialize};

use super::Loaded;
use super::external::protocol::{self, Request};
use super::external::{External, Found};
use super::timing::timed;
use super::validate::{Experiment, min_budget, quantities_at};
use crate::family::{Family, Listed, Measured, Method, Outcome, Quantity};

mod files;
pub mod links;

use files::results_of;
pub use files::{
    ReportFiles, SUMMARY_FILE, Unread, WRITTEN_AT_TOP, clear_reports, read_results,
    read_results_counted, remove_stale_temporaries, results_path, reusable, write_all_or_none,
    write_atomic, write_report_file, written_here,
};

/// A job's identity within its experiment: (rule index, budget, repeat).
pub type JobKey = (usize, usize, usize);

/// One finished job, as written to `results.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobResult {
    /// Experiment name.
    pub experiment: String,
    /// FNV-1a hash of the experiment file.
    pub experiment_hash: String,
    /// The equation family.
    pub family: String,
    /// Index of the rule in the file's `rules`.
    pub rule_index: usize,
    /// Rule or estimator name.
    pub rule: String,
    /// Budget (evaluations per smooth piece; walks for tracking).
    pub budget: usize,
    /// Repeat index.
    pub repeat: usize,
    /// The job's own seed, derived from the file's seed and the job.
    pub seed: u64,
    /// Each quantity: its channels, error estimates, cost and flags.
    pub quantities: BTreeMap<String, Measured>,
    /// Wall time of the evaluation, seconds (the clock is read outside it):
    /// the sum of its quantities' times. For a failed job, the time of its
    /// work until it failed: the finished quantities' times and the failing
    /// evaluation's own (an external program's request from sending it,
    /// not the program's start-up); 0 where nothing ran (a rule the file
    /// does not have, a program that did not start).
    pub seconds: f64,
    /// Why the job failed, if it did.
    pub failure: Option<String>,
    /// lightquad version.
    pub version: String,
    /// Git commit of the build, when known.
    pub git_commit: Option<String>,
    /// CPU model and core count.
    pub machine: String,
}

impl JobResult {
    /// The identity of the job within its experiment.
    pub fn key(&self) -> JobKey {
        (self.rule_index, self.budget, self.repeat)
    }
}

/// Options of a run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Output folder (one sub-folder per experiment).
    pub out: PathBuf,
    /// Keep finished jobs and run only the rest.
    pub resume: bool,
    /// Run only shard `k` of `n` (1-based) of every experiment's jobs.
    pub shard: Option<(usize, usize)>,
    /// Report progress on stderr: a bar on a terminal, a line per finished
    /// experiment otherwise.
    pub progress: bool,
}

/// FNV-1a 64-bit hash, hex: identifies an experiment file's exact bytes.
pub fn file_hash(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// SplitMix64: a seed per job from the file's seed and the job's identity.
fn job_seed(seed: u64, rule_index: usize, budget: usize, repeat: usize) -> u64 {
    let mut z = seed
        ^ (rule_index as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (budget as u64).wrapping_mul(0xbf58_476d_1ce4_e5b9)
        ^ (repeat as u64).wrapping_mul(0x94d0_49bb_1331_11eb);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The machine: CPU model and cores.
/// Read once per process: every job line carries it.
pub fn machine() -> String {
    static MACHINE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    MACHINE.get_or_init(read_machine).clone()
}

fn read_machine() -> String {
    let model = fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!("{model}, {cores} cores")
}

/// Runs one job of an experiment.
pub fn run_job<F: Family>(exp: &Experiment<F>, (rule_index, budget, repeat): JobKey) -> JobResult {
    let spec = &exp.spec;
    let seed = job_seed(spec.seed, rule_index, budget, repeat);
    let method = spec.rules.get(rule_index);
    let mut out = JobResult {
        experiment: spec.name.clone(),
        experiment_hash: exp.hash.clone(),
        family: F::NAME.to_string(),
        rule_index,
        rule: method.map_or_else(|| format!("rules[{rule_index}]"), |m| m.label()),
        budget,
        repeat,
        seed,
        quantities: BTreeMap::new(),
        seconds: 0.0,
        failure: None,
        version: env!("CARGO_PKG_VERSION").to_string(),
        git_commit: Some(env!("LIGHTQUAD_GIT_COMMIT").to_string()).filter(|c| !c.is_empty()),
        machine: machine(),
    };
    let Some(method) = method else {
        out.failure = Some(format!(
            "no rules[{rule_index}]: the experiment has {} rule(s)",
            spec.rules.len()
        ));
        return out;
    };
    let asked = quantities_at::<F>(&exp.scene, method, &spec.quantities, budget);
    let outcome = match method {
        Listed::Own(method) => own_outcome(exp, method, &asked, budget, seed),
        Listed::External(x) => external_outcome(exp, x, &asked, (rule_index, budget, repeat), seed),
    };
    let outcome = match outcome {
        Ok(outcome) => outcome,
        Err(failed) => {
            out.failure = Some(failed.why);
            out.seconds = failed.seconds;
            return out;
        }
    };
    out.seconds = outcome.values().filter_map(|m| m.seconds).sum();
    match shaped::<F>(&exp.scene, &asked, outcome) {
        Ok(values) => out.quantities = values,
        Err(e) => out.failure = Some(e),
    }
    out
}

/// A job that failed: why, and the seconds of its work until then (the
/// finished quantities' times, one evaluation each, and the failing one's).
struct Failed {
    why: String,
    seconds: f64,
}

/// Each quantity `asked` evaluated alone by the family's `method`, from the
/// job's seed, and timed alone: its time to a target is then its own cost (a
/// family computes only what the asked-for quantities need).
fn own_outcome<F: Family>(
    exp: &Experiment<F>,
    method: &Method<F::Estimator>,
    asked: &[F::Quantity],
    budget: usize,
    seed: u64,
) -> Result<Outcome<F::Quantity>, Failed> {
    let mut outcome = Outcome::new();
    let mut finished = 0.0;
    for q in asked {
        let evaluate = || {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            F::evaluate(
                &exp.scene,
                method,
                budget,
                &mut rng,
                std::slice::from_ref(q),
            )
        };
        let start = Instant::now();
        let result = evaluate();
        let once = start.elapsed().as_secs_f64();
        // Timing repeats only time: the values and counts are the first call's.
        let seconds = if result.is_ok() {
            timed(once, || {
                let _ = std::hint::black_box(evaluate());
            })
        } else {
            once
        };
        let values = result.map_err(|e| Failed {
            why: crate::error::readable(&format!("{}: {e}", q.name())),
            seconds: finished + once,
        })?;
        finished += seconds;
        for (k, mut m) in values {
            m.seconds = Some(seconds);
            outcome.insert(k, m);
        }
    }
    Ok(outcome)
}

/// Each quantity `asked` of an external program, once (its request is timed
/// as it is answered: asking again would be another estimate).
fn external_outcome<F: Family>(
    exp: &Experiment<F>,
    external: &External,
    asked: &[F::Quantity],
    (rule_index, budget, repeat): JobKey,
    seed: u64,
) -> Result<Outcome<F::Quantity>, Failed> {
    let failed = |why: String, seconds: f64| Failed { why, seconds };
    let Some(Found::Program(program)) = exp.programs.get(&rule_index) else {
        let why = format!(
            "rules[{rule_index}] ({}): its program was not found",
            external.name
        );
        return Err(failed(why, 0.0));
    };
    let scene = serde_json::to_value(&exp.spec.scene).map_err(|e| failed(e.to_string(), 0.0))?;
    let mut outcome = Outcome::new();
    let mut finished = 0.0;
    for &q in asked {
        let request = Request {
            protocol: protocol::NAME.into(),
            version: protocol::VERSION,
            id: 0,
            experiment: exp.spec.name.clone(),
            family: F::NAME.into(),
            scene: scene.clone(),
            quantity: q.name().into(),
            channels: F::channels(&exp.scene, q),
            dimension: F::dimension(&exp.scene, q),
            budget,
            seed,
            repeat,
        };
        let m = exp
            .servers
            .ask(rule_index, program, request, external.timeout_s)
            .map_err(|e| {
                let why = format!("external `{}`: {}", external.name, e.why);
                failed(crate::error::readable(&why), finished + e.seconds)
            })?;
        finished += m.seconds.unwrap_or(0.0);
        outcome.insert(q, m);
    }
    Ok(outcome)
}

/// The family's outcome by quantity name, checked to hold exactly the
/// quantities asked for, each with its channel count of values and errors (a
/// family that breaks this gets a failed job, not a misattributed number).
fn shaped<F: Family>(
    scene: &F::Scene,
    quantities: &[F::Quantity],
    mut values: crate::family::Outcome<F::Quantity>,
) -> Result<BTreeMap<String, Measured>, String> {
    let mut out = BTreeMap::new();
    for q in quantities {
        let Some(m) = values.remove(q) else {
            return Err(format!("the {} family returned no {}", F::NAME, q.name()));
        };
        if let Some(x) = m.value.iter().find(|x| !x.is_finite()) {
            return Err(format!(
                "the {} family computed a non-finite {} ({x}): the integrand overflowed or is undefined",
                F::NAME,
                q.name()
            ));
        }
        let want = F::channels(scene, *q);
        if m.value.len() != want || m.error.len() != want {
            return Err(format!(
                "the {} family returned {} value(s) and {} error(s) for {}, which has {want} channel(s)",
                F::NAME,
                m.value.len(),
                m.error.len(),
                q.name()
            ));
        }
        out.insert(q.name().to_string(), m);
    }
    if let Some(q) = values.keys().next() {
        return Err(format!(
            "the {} family returned {}, which was not asked for",
            F::NAME,
            q.name()
        ));
    }
    Ok(out)
}

/// Every job of an experiment in a fixed order, restricted to a shard; a
/// rule's budgets below its minimum for every quantity are left out (a job
/// computes the quantities whose minimum its budget reaches).
pub fn jobs<F: Family>(exp: &Experiment<F>, shard: Option<(usize, usize)>) -> Vec<JobKey> {
    let mut all = Vec::new();
    for (r, method) in exp.spec.rules.iter().enumerate() {
        // An external rule whose program is missing (and may be) has no jobs.
        if matches!(exp.programs.get(&r), Some(Found::Skipped(_))) {
            continue;
        }
        let least = min_budget::<F>(&exp.scene, method, &exp.spec.quantities);
        for &b in exp.budgets.iter().filter(|&&b| b >= least) {
            for k in 0..exp.spec.repeats {
                all.push((r, b, k));
            }
        }
    }
    match shard {
        None => all,
        Some((k, n)) => all
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % n == k - 1)
            .map(|(_, j)| j)
            .collect(),
    }
}

/// The finished jobs a `--resume` keeps from a results file, and what it
/// passes over.
pub struct Finished {
    /// One result per job that did not fail (the last line wins), of this
    /// experiment file and this lightquad release.
    pub results: Vec<JobResult>,
    /// Lines that are not results of this file's jobs.
    pub unread: Unread,
    /// Results written by another lightquad release.
    pub other_release: usize,
}

/// Reads the finished jobs of `exp` from `path` ([`Finished`]); nothing is
/// written or said.
pub fn finished_jobs(exp: &dyn Loaded, path: &Path) -> Finished {
    let mut by_key = BTreeMap::new();
    let (read, mut unread) = read_results_counted(path, Some(exp.hash()));
    let (read, misfits) = exp.reusable(read);
    unread.unreadable += misfits;
    let mut other_release = 0;
    for r in read {
        if r.version != env!("CARGO_PKG_VERSION") {
            other_release += 1;
        } else if r.failure.is_none() {
            by_key.insert(r.key(), r);
        } else {
            // A failed job is tried again (an external program that timed
            // out or crashed may answer now); the last line wins.
            by_key.remove(&r.key());
        }
    }
    Finished {
        results: by_key.into_values().collect(),
        unread,
        other_release,
    }
}

/// The jobs of `exp` a run with `opts` still has to do: all of its shard's,
/// less those finished in its results file on `--resume`.
pub fn pending_jobs(exp: &dyn Loaded, opts: &RunOptions) -> Vec<JobKey> {
    let done: BTreeSet<JobKey> = if opts.resume {
        finished_jobs(exp, &results_path(&opts.out, exp.name(), opts.shard))
            .results
            .iter()
            .map(JobResult::key)
            .collect()
    } else {
        BTreeSet::new()
    };
    exp.jobs(opts.shard)
        .into_iter()
        .filter(|j| !done.contains(j))
        .collect()
}

/// Runs one experiment's pending jobs, appending to `<out>/<name>/results.jsonl`;
/// returns every result of the experiment (old and new), sorted by job.
pub fn run_experiment(
    exp: &dyn Loaded,
    opts: &RunOptions,
    progress: &indicatif::ProgressBar,
) -> std::io::Result<Vec<JobResult>> {
    run_experiment_in_lanes(exp, opts, progress, usize::MAX)
}

/// [`run_experiment`] with at most `lanes` jobs at once (the memory holds
/// no more): the pool's threads stay, and a lane takes the next job when it
/// is free (a smaller pool of new threads could not be started under a
/// tight memory cap).
pub fn run_experiment_in_lanes(
    exp: &dyn Loaded,
    opts: &RunOptions,
    progress: &indicatif::ProgressBar,
    lanes: usize,
) -> std::io::Result<Vec<JobResult>> {
    let dir = opts.out.join(exp.name());
    links::refuse_link(&dir)?;
    fs::create_dir_all(&dir)?;
    let path = results_path(&opts.out, exp.name(), opts.shard);
    // Keep finished jobs on --resume (rewriting the file without a torn last
    // line); start afresh otherwise.
    let kept = if opts.resume {
        let finished = finished_jobs(exp, &path);
        // Lines not reused are said, not dropped in silence (their jobs run
        // again).
        if finished.unread != Unread::default() || finished.other_release > 0 {
            crate::say!(
                "{}: --resume does not reuse {} unreadable line(s) (torn, edited, or not a \
                 result of this file's jobs), {} result(s) of another \
                 version of the experiment file and {} of another lightquad release in {}: \
                 their jobs run again",
                exp.name(),
                finished.unread.unreadable,
                finished.unread.other_version,
                finished.other_release,
                path.display()
            );
        }
        finished.results
    } else {
        // A run without --resume starts afresh: earlier results of this very
        // file are said to be replaced, not dropped in silence (a rerun
        // killed at once had turned 360 results into 80).
        let earlier = results_of(&path, exp.hash());
        if earlier > 0 {
            crate::say!(
                "{}: replacing {earlier} earlier result(s) of this file in {} (pass --resume to \
                 keep them and run only the rest)",
                exp.name(),
                path.display()
            );
        }
        Vec::new()
    };
    let mut text = String::new();
    for r in &kept {
        text.push_str(&serde_json::to_string(r).map_err(std::io::Error::other)?);
        text.push('\n');
    }
    write_atomic(&path, text.as_bytes())?;
    let done: BTreeSet<_> = kept.iter().map(JobResult::key).collect();
    let mut pending: Vec<_> = exp
        .jobs(opts.shard)
        .into_iter()
        .filter(|j| !done.contains(j))
        .collect();
    // The largest budgets first: a large job started last left the other
    // threads idle while it ran (the longest-first order balances the
    // threads best; the results are sorted after).
    pending.sort_by_key(|&(rule, budget, repeat)| (std::cmp::Reverse(budget), rule, repeat));
    let all_jobs = exp.jobs(opts.shard).len();
    progress.inc((all_jobs - pending.len()) as u64);
    let ticker = super::progress::Ticker::new(
        exp.name(),
        all_jobs,
        all_jobs - pending.len(),
        opts.progress && progress.is_hidden(),
    );
    let file = Mutex::new(links::open_unlinked(
        &path,
        OpenOptions::new().append(true),
    )?);
    // Tables built once on first use, built here, before any job is timed:
    // the Student-t table cost the first random job of a run some 2.4 ms,
    // which with one repeat was that rule's time, and its rank.
    let _ = crate::estimate::t95_factor(2.0);
    let run = |&key: &JobKey| {
        let result = exp.run_job(key);
        let line = serde_json::to_string(&result).map_err(std::io::Error::other)? + "\n";
        // One write per line, flushed, so a killed run leaves whole lines.
        let mut f = file
            .lock()
            .map_err(|_| std::io::Error::other("results file lock poisoned"))?;
        f.write_all(line.as_bytes())?;
        f.flush()?;
        progress.inc(1);
        ticker.tick();
        Ok(result)
    };
    // Dealt one at a time in that order to whichever lane is free: rayon's
    // halving left v-i-total-voxel-grid at 1.73 on two threads where the
    // longest-first schedule of its job times gives 2.00.
    let order: Vec<usize> = (0..pending.len()).collect();
    let fresh: Vec<std::io::Result<JobResult>> =
        crate::parallel::dealt(&order, lanes, |k| run(&pending[k]));
    let mut all = kept;
    for r in fresh {
        all.push(r?);
    }
    all.sort_by_key(JobResult::key);
    Ok(all)
}

//! Running experiments: jobs (rule x budget x repeat) in parallel, each with a
//! random stream derived from (seed, job) so results do not depend on the
//! thread count; one JSON line per job appended as it finishes, so an
//! interrupted run keeps what it finished and `--resume` does only the rest.

use std::collections::{BTreeMap, BTreeSet};
use std::fs::{self, File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use rand::SeedableRng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::spec::{DepthSchemeSpec, Quantity, RuleSpec, ShadowSpec};
use super::validate::Experiment;
use crate::quadrature::{
    AnyRule, BaseRule, GaussKronrod, GaussLegendre, MonteCarlo, Sobol, Stratified, Trapezoid,
};
use crate::volume::tracking::{Extinction, Tracker, transmittance};
use crate::volume::{DepthScheme, ShadowMethod, VolumeResult, evaluate};

/// One finished job, as written to `results.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobResult {
    /// Experiment name.
    pub experiment: String,
    /// FNV-1a hash of the experiment file.
    pub experiment_hash: String,
    /// Index of the rule in the file's `rules`.
    pub rule_index: usize,
    /// Rule name.
    pub rule: String,
    /// Budget (evaluations per smooth piece; walks for tracking).
    pub budget: usize,
    /// Repeat index.
    pub repeat: usize,
    /// The job's own seed, derived from the file's seed and the job.
    pub seed: u64,
    /// Value per quantity.
    pub values: BTreeMap<Quantity, f64>,
    /// The rule's error estimate per quantity.
    pub estimated_errors: BTreeMap<Quantity, f64>,
    /// Density evaluations per quantity.
    pub evaluations: BTreeMap<Quantity, u64>,
    /// The summed magnitude of the parts of a quantity (for V-I: |I_E| + |I_B|
    /// + |I_L|), when it is a sum; the report flags cancellation against it.
    #[serde(default)]
    pub magnitudes: BTreeMap<Quantity, f64>,
    /// Wall time of the evaluation, seconds (the clock is read outside it).
    pub seconds: f64,
    /// Why the job failed, if it did.
    pub failure: Option<String>,
    /// True when tau underflowed and only its logarithm is meaningful.
    pub underflow: bool,
    /// lightquad version.
    pub version: String,
    /// Git commit of the build, when known.
    pub git_commit: Option<String>,
    /// CPU model and core count.
    pub machine: String,
}

impl JobResult {
    /// A result with no values (a scratch record).
    pub fn empty() -> Self {
        JobResult {
            experiment: String::new(),
            experiment_hash: String::new(),
            rule_index: 0,
            rule: String::new(),
            budget: 0,
            repeat: 0,
            seed: 0,
            values: BTreeMap::new(),
            estimated_errors: BTreeMap::new(),
            evaluations: BTreeMap::new(),
            magnitudes: BTreeMap::new(),
            seconds: 0.0,
            failure: None,
            underflow: false,
            version: env!("CARGO_PKG_VERSION").to_string(),
            git_commit: None,
            machine: String::new(),
        }
    }

    /// The identity of the job within its experiment.
    pub fn key(&self) -> (usize, usize, usize) {
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
    /// Show a progress bar (on a terminal).
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

/// The quadrature rule a spec names (tracking estimators are not rules).
pub fn quadrature_rule(spec: &RuleSpec) -> Option<AnyRule> {
    Some(AnyRule::Base(match spec {
        RuleSpec::Trapezoid {} => BaseRule::Trapezoid(Trapezoid),
        RuleSpec::GaussLegendre { error_estimate } => BaseRule::GaussLegendre(GaussLegendre {
            error_estimate: *error_estimate,
        }),
        RuleSpec::GaussKronrod { abs_tol, rel_tol } => BaseRule::GaussKronrod(GaussKronrod {
            abs_tol: *abs_tol,
            rel_tol: *rel_tol,
        }),
        RuleSpec::MonteCarlo {} => BaseRule::MonteCarlo(MonteCarlo),
        RuleSpec::Stratified {} => BaseRule::Stratified(Stratified),
        RuleSpec::Sobol { replicates } => BaseRule::Sobol(Sobol {
            replicates: *replicates,
        }),
        _ => return None,
    }))
}

fn tracker(spec: &RuleSpec) -> Option<Tracker> {
    match spec {
        RuleSpec::DeltaTracking {} => Some(Tracker::Delta),
        RuleSpec::RatioTracking {} => Some(Tracker::Ratio),
        RuleSpec::ResidualRatioTracking {} => Some(Tracker::ResidualRatio),
        _ => None,
    }
}

/// The quantities of a volume result.
pub fn collect_into(res: &VolumeResult, quantities: &[Quantity], out: &mut JobResult) {
    for q in quantities {
        let (v, e, k) = match q {
            Quantity::Tau => (
                res.transmittance,
                res.transmittance * res.optical_depth.error,
                res.optical_depth.evaluations,
            ),
            Quantity::Emission => res
                .emission
                .map_or((0.0, 0.0, 0), |t| (t.value, t.error, t.evaluations)),
            Quantity::Background => res
                .background
                .map_or((0.0, 0.0, 0), |t| (t.value, t.error, t.evaluations)),
            Quantity::Light => res
                .light
                .map_or((0.0, 0.0, 0), |t| (t.value, t.error, t.evaluations)),
            Quantity::Total => {
                let terms = [res.emission, res.background, res.light];
                let e = terms.iter().flatten().map(|t| t.error).sum();
                let k = res.optical_depth.evaluations
                    + terms.iter().flatten().map(|t| t.evaluations).sum::<u64>();
                let magnitude = terms.iter().flatten().map(|t| t.value.abs()).sum::<f64>();
                out.magnitudes.insert(*q, magnitude);
                (res.total, e, k)
            }
        };
        out.values.insert(*q, v);
        out.estimated_errors.insert(*q, e);
        out.evaluations.insert(*q, k);
    }
}

/// Runs one job.
pub fn run_job(
    exp: &Experiment,
    hash: &str,
    rule_index: usize,
    budget: usize,
    repeat: usize,
) -> JobResult {
    let spec = &exp.spec;
    let seed = job_seed(spec.seed, rule_index, budget, repeat);
    let rule_spec = &spec.rules[rule_index.min(spec.rules.len() - 1)];
    let mut out = JobResult {
        experiment: spec.name.clone(),
        experiment_hash: hash.to_string(),
        rule_index,
        rule: rule_spec.name().to_string(),
        budget,
        repeat,
        seed,
        git_commit: Some(env!("LIGHTQUAD_GIT_COMMIT").to_string()).filter(|c| !c.is_empty()),
        machine: machine(),
        ..JobResult::empty()
    };
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let scheme = match spec.depth_scheme {
        DepthSchemeSpec::Cumulative => DepthScheme::Cumulative,
        DepthSchemeSpec::Nested => DepthScheme::Nested,
    };
    let shadow = match spec.shadow {
        ShadowSpec::ClosedForm => ShadowMethod::ClosedFormWhereAvailable,
        ShadowSpec::Quadrature => ShadowMethod::Quadrature,
    };
    if let Some(rule) = quadrature_rule(rule_spec) {
        let start = Instant::now();
        let res = evaluate(&exp.scene, &rule, budget, scheme, shadow, &mut rng);
        out.seconds = start.elapsed().as_secs_f64();
        match res {
            Ok(res) => {
                out.underflow = res.underflow;
                collect_into(&res, &spec.quantities, &mut out);
            }
            Err(e) => out.failure = Some(e.to_string()),
        }
    } else if let Some(tracker) = tracker(rule_spec) {
        // Tracking estimators compute tau only.
        if let Some(medium) = exp.scene.medium.as_deref() {
            let sigma = Extinction {
                medium,
                lambda: exp.scene.lambda,
            };
            let start = Instant::now();
            let res = transmittance(
                tracker,
                sigma,
                &exp.scene.ray,
                exp.scene.t_min,
                exp.scene.t_max,
                budget.max(2),
                &mut rng,
            );
            out.seconds = start.elapsed().as_secs_f64();
            match res {
                Ok(est) => {
                    out.values.insert(Quantity::Tau, est.value);
                    out.estimated_errors.insert(Quantity::Tau, est.error);
                    out.evaluations.insert(Quantity::Tau, est.evaluations);
                }
                Err(e) => out.failure = Some(e.to_string()),
            }
        } else {
            out.values.insert(Quantity::Tau, 1.0);
            out.estimated_errors.insert(Quantity::Tau, 0.0);
            out.evaluations.insert(Quantity::Tau, 0);
        }
    }
    out
}

/// Every job of an experiment in a fixed order, restricted to a shard.
pub fn jobs(exp: &Experiment, shard: Option<(usize, usize)>) -> Vec<(usize, usize, usize)> {
    let mut all = Vec::new();
    for (r, rule) in exp.spec.rules.iter().enumerate() {
        for &b in exp.budgets.iter().filter(|&&b| b >= rule.min_budget()) {
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

/// Reads the complete, parseable lines of a results file for `hash`.
pub fn read_results(path: &Path, hash: Option<&str>) -> Vec<JobResult> {
    let Ok(file) = File::open(path) else {
        return Vec::new();
    };
    BufReader::new(file)
        .lines()
        .map_while(Result::ok)
        .filter_map(|l| serde_json::from_str::<JobResult>(&l).ok())
        .filter(|r| hash.is_none_or(|h| r.experiment_hash == h))
        .collect()
}

/// Writes `text` to `path` atomically (a temporary file, then a rename), so a
/// reader never sees a half-written file.
pub fn write_atomic(path: &Path, text: &[u8]) -> std::io::Result<()> {
    // A name no other process or thread writing beside us can pick (shards of
    // one run may share an output folder).
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let unique = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = path
        .file_name()
        .map_or("out".into(), |n| n.to_string_lossy().to_string());
    let tmp = path.with_file_name(format!(".{name}.{}.{unique}.tmp", std::process::id()));
    {
        let mut f = File::create(&tmp)?;
        f.write_all(text)?;
        f.sync_all()?;
    }
    fs::rename(&tmp, path)
}

/// Runs one experiment's pending jobs, appending to `<out>/<name>/results.jsonl`;
/// returns every result of the experiment (old and new), sorted by job.
pub fn run_experiment(
    exp: &Experiment,
    hash: &str,
    opts: &RunOptions,
    progress: &indicatif::ProgressBar,
) -> std::io::Result<Vec<JobResult>> {
    let dir = opts.out.join(&exp.spec.name);
    fs::create_dir_all(&dir)?;
    let path = dir.join(match opts.shard {
        None => "results.jsonl".to_string(),
        Some((k, n)) => format!("results.shard-{k}-of-{n}.jsonl"),
    });
    // Keep finished jobs on --resume (rewriting the file without a torn last
    // line); start afresh otherwise.
    let kept = if opts.resume {
        // Lines of this experiment file and this lightquad version only, one per
        // job (the last wins).
        let mut by_key = BTreeMap::new();
        for r in read_results(&path, Some(hash)) {
            if r.version == env!("CARGO_PKG_VERSION") {
                by_key.insert(r.key(), r);
            }
        }
        by_key.into_values().collect()
    } else {
        Vec::new()
    };
    let mut text = String::new();
    for r in &kept {
        text.push_str(&serde_json::to_string(r).map_err(std::io::Error::other)?);
        text.push('\n');
    }
    write_atomic(&path, text.as_bytes())?;
    let done: BTreeSet<_> = kept.iter().map(JobResult::key).collect();
    let pending: Vec<_> = jobs(exp, opts.shard)
        .into_iter()
        .filter(|j| !done.contains(j))
        .collect();
    progress.inc((jobs(exp, opts.shard).len() - pending.len()) as u64);
    let file = Mutex::new(OpenOptions::new().append(true).open(&path)?);
    let fresh: Vec<std::io::Result<JobResult>> = pending
        .par_iter()
        .map(|&(r, b, k)| {
            let result = run_job(exp, hash, r, b, k);
            let line = serde_json::to_string(&result).map_err(std::io::Error::other)? + "\n";
            // One write per line, flushed, so a killed run leaves whole lines.
            let mut f = file
                .lock()
                .map_err(|_| std::io::Error::other("results file lock poisoned"))?;
            f.write_all(line.as_bytes())?;
            f.flush()?;
            progress.inc(1);
            Ok(result)
        })
        .collect();
    let mut all = kept;
    for r in fresh {
        all.push(r?);
    }
    all.sort_by_key(JobResult::key);
    Ok(all)
}

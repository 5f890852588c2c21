//! The `lightquad` command line: thin parsing over the library.

use std::io::{BufWriter, Write};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use std::path::PathBuf;

use lightquad::error::readable;
use lightquad::experiment;
use lightquad::experiment::Source;
use lightquad::experiment::run::RunOptions;
use lightquad::families;
use lightquad::quadrature::gauss_legendre;

/// How accurate is each numerical approximation of a light-transport integral,
/// and what does it cost?
#[derive(Parser)]
#[command(name = "lightquad", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the quadrature rules and every family's estimators, one line each,
    /// then the families with their quantities.
    Rules,
    /// Print a rule's nodes and weights on [-1, 1] as JSON
    /// `{"nodes": [...], "weights": [...]}`, every digit needed to round-trip an f64.
    Nodes {
        /// Rule name: `gauss-legendre`, `trapezoid` or `simpson` (rules with a
        /// fixed node set).
        rule: String,
        /// Number of nodes (Gauss–Legendre: 1..=100000000; trapezoid: 2..=100000000; Simpson: odd, 3..=100000000).
        n: usize,
    },
    /// Run experiments and write a report of error against run time to the
    /// --out folder (default ./report, in the working folder): index.md and
    /// index.html, a folder per experiment.
    ///
    /// Without files, runs the bundled suite: the experiments/ folder of
    /// lightquad's source and its Mitsuba 3 values, built into this binary, so
    /// it runs the same from any folder. A given file's Mitsuba values are
    /// looked for relative to the file (../reference/values/<name>.json), then
    /// among the bundled ones.
    Run {
        /// Experiment files; none runs the bundled suite.
        files: Vec<PathBuf>,
        /// Output folder: <out>/index.md, <out>/index.html, <out>/<experiment>/.
        /// It may be a link; a link inside it where the run writes is refused.
        #[arg(long, default_value = "report")]
        out: PathBuf,
        /// Keep the jobs an interrupted run finished and run only the rest.
        #[arg(long)]
        resume: bool,
        /// Run only shard k of n of every experiment's jobs (for a Slurm job
        /// array or GNU parallel); join the shards with `lightquad merge`.
        #[arg(long, value_parser = parse_shard)]
        shard: Option<(usize, usize)>,
        /// Worker threads (default: all cores). Results do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Run experiments whose jobs are estimated to cost more than 1e11
        /// integrand evaluations each (refused by default, with the estimate).
        #[arg(long)]
        no_cost_limit: bool,
    },
    /// Validate experiment files without running them.
    Check {
        /// Experiment files; none checks the bundled suite.
        files: Vec<PathBuf>,
        /// Accept experiments whose jobs are estimated to cost more than
        /// 1e11 integrand evaluations each, as `run --no-cost-limit` does.
        #[arg(long)]
        no_cost_limit: bool,
    },
    /// Print the JSON Schema of experiment files (with --summary: of the
    /// summary.json files a report writes; with --protocol: of the messages
    /// between lightquad and an external estimator).
    Schema {
        /// The schema of summary.json instead.
        #[arg(long, conflicts_with = "protocol")]
        summary: bool,
        /// The schema of the external estimators' protocol instead.
        #[arg(long)]
        protocol: bool,
    },
    /// Join the results of `run --shard` folders into one report.
    Merge {
        /// Output folders of the shards.
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// Output folder of the merged report.
        #[arg(long, default_value = "report")]
        out: PathBuf,
        /// Merge shards whose results were computed by different builds of
        /// lightquad (different git commits; refused by default); the report
        /// names every commit.
        #[arg(long)]
        allow_mixed_commits: bool,
    },
    /// Compare a run (NEW, a report folder) with a baseline (OLD): every
    /// job's values bit for bit (or within --tolerance), every row's time
    /// (faster or slower where the medians' confidence intervals do not
    /// overlap), every rule's rank. Prints a Markdown summary; exits
    /// non-zero where a value changed, unless --allow-value-changes.
    Compare {
        /// The baseline report folder.
        old: PathBuf,
        /// The report folder to judge.
        new: PathBuf,
        /// Only these experiments (default: every one both folders have).
        #[arg(long = "experiment")]
        experiments: Vec<String>,
        /// Values agree within this relative difference (default: bit for bit).
        #[arg(long)]
        tolerance: Option<f64>,
        /// A time changed only beyond this relative change either way (and
        /// outside both intervals): 0.5 means 1.5x faster or slower.
        #[arg(long, default_value_t = experiment::compare::NOISE)]
        noise: f64,
        /// Exit 0 even where values changed (they are still reported).
        #[arg(long)]
        allow_value_changes: bool,
        /// Also write compare.md and compare.html into this folder.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Print the families' audits of the source documents' printed formulas
    /// (Markdown; also at the end of every report's index).
    Audit,
    /// Render the scene of a `whitted` experiment file (none: the bundled
    /// w-grey-test-scene) to an 8-bit PNG by W-Grey, and a PFM of the same
    /// floats; prints the rays traced by kind.
    Render {
        /// A `whitted` experiment file; none renders the bundled test scene.
        file: Option<PathBuf>,
        /// The PNG to write.
        #[arg(long)]
        png: PathBuf,
        /// The PFM (32-bit float RGB) to write too.
        #[arg(long)]
        pfm: Option<PathBuf>,
        /// Image width in pixels (default: the file's).
        #[arg(long)]
        width: Option<usize>,
        /// Image height in pixels (default: the file's).
        #[arg(long)]
        height: Option<usize>,
        /// Rays per pixel on W-SS's grid, at least 1, rounded down to a square (9: 3 x 3).
        #[arg(long, default_value_t = 9)]
        samples: usize,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        // A reader that stopped early (`lightquad schema | head`) is no
        // failure of ours: quiet, as other tools end on a closed pipe.
        Err(e)
            if e.downcast_ref::<std::io::Error>()
                .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe) =>
        {
            ExitCode::SUCCESS
        }
        Err(e) => {
            lightquad::say!("error: {}", readable(&e.to_string()));
            ExitCode::FAILURE
        }
    }
}

type Failure = Box<dyn std::error::Error>;

/// The most worker threads `run` accepts (far above any core count it helps).
const MAX_THREADS: usize = 1024;

fn run(command: Command) -> Result<(), Failure> {
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    let registry = families::builtin();
    match command {
        Command::Rules => list_rules(&mut out, &registry)?,
        Command::Nodes { rule, n } => {
            let (x, w) = fixed_nodes(&rule, n)?;
            write_json_array(&mut out, "{\"nodes\": [", &x)?;
            write_json_array(&mut out, "], \"weights\": [", &w)?;
            writeln!(out, "]}}")?;
        }
        Command::Run {
            files,
            out: dir,
            resume,
            shard,
            threads,
            no_cost_limit,
        } => {
            if no_cost_limit {
                experiment::validate::lift_cost_limit();
            }
            if let Some(t) = threads {
                if !(1..=MAX_THREADS).contains(&t) {
                    return Err(format!(
                        "invalid --threads = {t}: expected a number of threads in 1..={MAX_THREADS}"
                    )
                    .into());
                }
                // Threads past a cap do not fail to start: one aborts the
                // process when its signal stack cannot be mapped. Refused
                // first, where the cap is known.
                let need = experiment::memory::thread_reserve(t);
                if let Some(cap) = experiment::memory::hard_cap().filter(|c| need > c.room) {
                    return Err(format!(
                        "invalid --threads = {t}: {t} worker threads reserve about {} of \
                         address space (their stacks and allocator arenas), and {} leaves {}: \
                         expected fewer threads",
                        experiment::memory::bytes(need),
                        cap.what,
                        experiment::memory::bytes(cap.room)
                    )
                    .into());
                }
                rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build_global()
                    .map_err(|e| {
                        format!(
                            "invalid --threads = {t}: {t} worker threads could not be started \
                             ({e}); this process's limits (ulimit -v, ulimit -u, a cgroup) allow \
                             fewer: expected fewer threads"
                        )
                    })?;
            }
            let sources = sources(files)?;
            let opts = RunOptions {
                out: dir,
                resume,
                shard,
                progress: true,
            };
            let index = experiment::run_sources(&registry, &sources, &opts)?;
            match shard {
                None => writeln!(out, "report: {}", index.display())?,
                Some(_) => writeln!(
                    out,
                    "shard written under {}; join shards with `lightquad merge`",
                    opts.out.display()
                )?,
            }
        }
        Command::Check {
            files,
            no_cost_limit,
        } => {
            if no_cost_limit {
                experiment::validate::lift_cost_limit();
            }
            check_files(&mut out, &registry, sources(files)?)?;
        }
        Command::Schema {
            summary: false,
            protocol: false,
        } => writeln!(out, "{}", serde_json::to_string_pretty(&registry.schema())?)?,
        Command::Schema { protocol: true, .. } => writeln!(
            out,
            "{}",
            serde_json::to_string_pretty(&experiment::external::protocol::schema())?
        )?,
        Command::Schema { summary: true, .. } => writeln!(
            out,
            "{}",
            serde_json::to_string_pretty(&experiment::report::summary_schema())?
        )?,
        Command::Merge {
            inputs,
            out: dir,
            allow_mixed_commits,
        } => {
            // A merge runs no job: the cost guard, which shards that needed
            // --no-cost-limit passed, would refuse to join them.
            experiment::validate::lift_cost_limit();
            let options = experiment::MergeOptions {
                allow_mixed_commits,
            };
            let index = experiment::merge_with(&registry, &inputs, &dir, &options)?;
            writeln!(out, "report: {}", index.display())?;
        }
        Command::Compare {
            old,
            new,
            experiments,
            tolerance,
            noise,
            allow_value_changes,
            out: dir,
        } => {
            let opts = experiment::compare::CompareOptions {
                tolerance,
                experiments,
                noise,
            };
            let c = experiment::compare::compare(&old, &new, &opts)?;
            let md = c.markdown();
            write!(out, "{md}")?;
            out.flush()?;
            if let Some(dir) = dir {
                experiment::compare::write(&dir, &c)?;
            }
            if c.values_changed() > 0 && !allow_value_changes {
                return Err(format!(
                    "{} difference(s) against the baseline: changed values, or jobs or \
                     experiments missing from the new run (listed above; \
                     --allow-value-changes to accept them)",
                    c.values_changed()
                )
                .into());
            }
        }
        Command::Render {
            file,
            png,
            pfm,
            width,
            height,
            samples,
        } => {
            if samples == 0 {
                return Err(
                    "invalid --samples = 0: expected a number of rays per pixel >= 1 \
                            (rounded down to a square: 1, 4, 9, ...)"
                        .into(),
                );
            }
            // The flags are named as flags, not as the file's camera fields
            // they replace.
            let most = lightquad::whitted::scene::MAX_SIDE;
            for (flag, given) in [("--width", width), ("--height", height)] {
                if let Some(g) = given
                    && !(1..=most).contains(&g)
                {
                    return Err(format!(
                        "invalid {flag} = {g}: expected a number of pixels in 1..={most}"
                    )
                    .into());
                }
            }
            if let Some(p) = &pfm
                && same_file(&png, p)
            {
                return Err(format!(
                    "--png and --pfm both name {}: expected two different files (the second \
                     would overwrite the first)",
                    png.display()
                )
                .into());
            }
            // Where the files go, checked before rendering (a render can take
            // minutes, and an unwritable --pfm was found only after it).
            for (flag, path) in
                std::iter::once(("--png", &png)).chain(pfm.as_ref().map(|p| ("--pfm", p)))
            {
                let folder = match path.parent() {
                    Some(f) if !f.as_os_str().is_empty() => f,
                    _ => std::path::Path::new("."),
                };
                // A FIFO or a device is written in place, never renamed
                // over: a FIFO no one reads blocked the render forever.
                if let Ok(meta) = std::fs::metadata(path)
                    && !meta.is_dir()
                    && !meta.is_file()
                {
                    return Err(format!(
                        "invalid {flag} = {}: it {}: expected a regular file or a new name \
                         (the image is written beside it and renamed into place)",
                        path.display(),
                        experiment::source::not_regular(&meta)
                    )
                    .into());
                }
                if path.is_dir() || !folder.is_dir() {
                    return Err(format!(
                        "invalid {flag} = {}: expected a file in an existing folder ({})",
                        path.display(),
                        if path.is_dir() {
                            "it is a folder"
                        } else {
                            "its folder does not exist"
                        }
                    )
                    .into());
                }
            }
            // An output that is the input would replace the experiment file
            // with image bytes.
            if let Some(f) = &file {
                for (flag, path) in
                    std::iter::once(("--png", &png)).chain(pfm.as_ref().map(|p| ("--pfm", p)))
                {
                    if same_file(path, f) {
                        return Err(format!(
                            "invalid {flag} = {}: it is the experiment file being rendered; \
                             expected another file",
                            path.display()
                        )
                        .into());
                    }
                }
            }
            let source = match file {
                Some(f) => Source::File(f),
                None => Source::Bundled("w-grey-test-scene.json"),
            };
            let in_file = |e: &dyn std::fmt::Display| format!("{}: {e}", source.display());
            let text = source.read().map_err(|e| in_file(&e))?;
            let text =
                std::str::from_utf8(&text).map_err(|e| in_file(&format!("not UTF-8: {e}")))?;
            let json = experiment::validate::parse_json(text).map_err(|e| in_file(&e))?;
            let (image, rays, warnings) =
                lightquad::whitted::experiment::render_spec(&json, width, height, samples)
                    .map_err(|e| in_file(&e))?;
            for w in &warnings {
                lightquad::say!(
                    "warning: {}: {}",
                    source.display(),
                    readable(&w.to_string())
                );
            }
            // Both files or neither: each is encoded, then written beside
            // its place under a temporary name, and only when both are
            // written are they renamed into place.
            let mut files = vec![(
                "PNG",
                png.clone(),
                image
                    .png()
                    .map_err(|e| format!("cannot encode the PNG: {e}"))?,
            )];
            if let Some(p) = &pfm {
                files.push((
                    "PFM",
                    p.clone(),
                    image
                        .pfm()
                        .map_err(|e| format!("cannot encode the PFM: {e}"))?,
                ));
            }
            experiment::run::write_all_or_none(
                files
                    .iter()
                    .map(|(_, path, bytes)| (path.as_path(), bytes.as_slice())),
            )
            .map_err(|(k, e)| {
                format!(
                    "cannot write the {} {}: {e} (no file was written)",
                    files[k].0,
                    files[k].1.display()
                )
            })?;
            writeln!(
                out,
                "{}: {} x {} pixels, {} rays ({} primary, {} shadow, {} reflection, {} refraction)",
                png.display(),
                image.width(),
                image.height(),
                rays.total(),
                rays.primary,
                rays.shadow,
                rays.reflection,
                rays.refraction
            )?;
        }
        Command::Audit => {
            for audit in registry.entries().iter().filter_map(|f| f.audit()) {
                writeln!(out, "{audit}")?;
            }
        }
    }
    out.flush()?;
    Ok(())
}

/// Whether `a` and `b` name one file: the same path once made absolute and
/// rid of `.` and `..`, or, where both exist, the same canonical file (a
/// link to the other).
fn same_file(a: &std::path::Path, b: &std::path::Path) -> bool {
    use std::path::Component;
    let plain = |p: &std::path::Path| {
        let mut out = PathBuf::new();
        for c in std::path::absolute(p)
            .unwrap_or_else(|_| p.to_path_buf())
            .components()
        {
            match c {
                Component::CurDir => {}
                Component::ParentDir => {
                    out.pop();
                }
                other => out.push(other),
            }
        }
        out
    };
    if plain(a) == plain(b) {
        return true;
    }
    matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

/// The experiments of `run` and `check`: the files, or the bundled suite.
fn sources(files: Vec<PathBuf>) -> Result<Vec<Source>, Failure> {
    if !files.is_empty() {
        return Ok(files.into_iter().map(Source::File).collect());
    }
    let suite = Source::bundled_suite();
    if suite.is_empty() {
        return Err(
            "this lightquad was built without its experiments/ folder, so it bundles no \
                    experiments: give experiment files"
                .into(),
        );
    }
    Ok(suite)
}

/// `check`: every file read, validated and priced, in order, its verdict
/// printed (`ok` on stdout, each error on stderr) and the next file checked
/// after a bad one; an error at the end where any file failed.
fn check_files(
    out: &mut impl Write,
    registry: &experiment::Registry,
    files: Vec<Source>,
) -> Result<(), Failure> {
    // Names shared between files are refused as `run` refuses them.
    let mut names = std::collections::BTreeMap::new();
    let mut failed = 0;
    let total = files.len();
    for f in files {
        if let Err(e) = check_file(out, registry, &f, &mut names) {
            failed += 1;
            // The `ok` lines before it first, so the two streams read in order.
            out.flush()?;
            lightquad::say!("error: {}", readable(&e.to_string()));
        }
    }
    if failed > 0 {
        return Err(
            format!("{failed} of {total} file(s) failed the check (each named above)").into(),
        );
    }
    Ok(())
}

/// One file of `check`: its `ok` line, or why it is refused.
fn check_file(
    out: &mut impl Write,
    registry: &experiment::Registry,
    f: &Source,
    names: &mut std::collections::BTreeMap<String, String>,
) -> Result<(), Failure> {
    let exp = experiment::load_source(registry, f)?;
    // The first file of a name keeps it: a later one is refused, and its
    // refusal names the file that holds the name.
    if let Some(other) = names.get(exp.name()) {
        let why = if *other == f.display() {
            "this file is given twice: give it once".to_string()
        } else {
            format!(
                "{:?} is also the name of {other}: one run (one output folder) cannot hold \
                 both; rename one",
                exp.name()
            )
        };
        return Err(experiment::RunError::Spec {
            file: f.display(),
            source: lightquad::error::SpecError::at("name", why),
        }
        .into());
    }
    names.insert(exp.name().to_string(), f.display());
    for w in exp.warnings() {
        lightquad::say!("warning: {}: {}", f.display(), readable(&w.to_string()));
    }
    let (rules, budgets, repeats) = exp.shape();
    let [jobs, reference] = exp.cost();
    let reference = if reference > 0.0 {
        format!(", its reference stage up to {reference:.1e}")
    } else {
        String::new()
    };
    writeln!(
        out,
        "{}: ok ({}, family {}, {rules} rule(s) x {budgets} budget(s) x {repeats} repeat(s), hash {}; \
         priced for the cost limits at about {jobs:.1e} integrand evaluations in its \
         jobs{reference}: estimates that count the rules' caps and every ray a \
         branching ray tree may spawn, so the work done is often less)",
        f.display(),
        exp.name(),
        exp.family(),
        exp.hash()
    )?;
    Ok(())
}

/// Every rule and estimator, then the families with their quantities.
fn list_rules(out: &mut impl Write, registry: &experiment::Registry) -> Result<(), Failure> {
    for (name, about) in registry.methods() {
        writeln!(out, "{name:<40} {about}")?;
    }
    writeln!(out)?;
    for f in registry.entries() {
        writeln!(
            out,
            "family {:<12} {} (equations {}; quantities {})",
            f.name,
            f.about,
            if f.equations.is_empty() {
                "none".to_string()
            } else {
                f.equations.join(", ")
            },
            f.quantities().join(", ")
        )?;
    }
    Ok(())
}

/// Nodes and weights on `[-1, 1]` of a rule with a fixed node set.
fn fixed_nodes(rule: &str, n: usize) -> Result<(Vec<f64>, Vec<f64>), Failure> {
    use lightquad::QuadError;
    use lightquad::quadrature::trapezoid::MAX_POINTS;
    match rule {
        "gauss-legendre" => {
            let t = gauss_legendre::table(n)?;
            Ok((t.x().to_vec(), t.w().to_vec()))
        }
        "simpson" => {
            let t = lightquad::quadrature::simpson::unit_nodes(n).map_err(|_| {
                QuadError::invalid(
                    "n",
                    n,
                    format!("an odd number of Simpson nodes in 3..={MAX_POINTS}"),
                )
            })?;
            // From [0, 1] to [-1, 1].
            Ok((
                t.u.iter().map(|u| 2.0 * u - 1.0).collect(),
                t.w.iter().map(|w| 2.0 * w).collect(),
            ))
        }
        "trapezoid" if n > MAX_POINTS => {
            Err(QuadError::invalid("n", n, format!("at most {MAX_POINTS} trapezoid nodes")).into())
        }
        "trapezoid" if n < 2 => {
            Err(QuadError::invalid("n", n, "at least 2 trapezoid nodes").into())
        }
        "trapezoid" => {
            let h = 2.0 / (n - 1) as f64;
            let x = (0..n).map(|i| -1.0 + i as f64 * h).collect();
            let w = (0..n)
                .map(|i| if i == 0 || i == n - 1 { 0.5 * h } else { h })
                .collect();
            Ok((x, w))
        }
        other => Err(format!(
            "invalid rule `{other}` for `nodes`: expected gauss-legendre, trapezoid or simpson \
             (the rules with a fixed node set)"
        )
        .into()),
    }
}

/// Writes `prefix` then the numbers comma-separated; `{:?}` prints the shortest
/// decimal that round-trips an f64 and is valid JSON.
fn write_json_array(out: &mut impl Write, prefix: &str, xs: &[f64]) -> std::io::Result<()> {
    out.write_all(prefix.as_bytes())?;
    for (i, x) in xs.iter().enumerate() {
        if i > 0 {
            out.write_all(b", ")?;
        }
        write!(out, "{x:?}")?;
    }
    Ok(())
}

/// Parses `k/n` with 1 <= k <= n.
fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let bad = || format!("invalid shard {s:?}: expected k/n with 1 <= k <= n, e.g. 2/8");
    let (k, n) = s.split_once('/').ok_or_else(bad)?;
    let (k, n): (usize, usize) = (
        k.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if k == 0 || k > n {
        return Err(bad());
    }
    Ok((k, n))
}

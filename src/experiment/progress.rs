//! Progress of a run on stderr: on a terminal, a bar with the jobs done, the
//! elapsed time, an ETA and the running experiment's name; otherwise (a log
//! file, a pipe, a batch job) one line per finished experiment.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

use super::run::JobResult;

/// The bar of a run of `total` jobs: hidden unless `show` and stderr is a
/// terminal.
pub(super) fn bar(show: bool, total: usize) -> ProgressBar {
    if !show || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total as u64);
    if let Ok(style) = ProgressStyle::with_template(
        "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} jobs, ETA {eta} | {msg}",
    ) {
        bar.set_style(style);
    }
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// The line of a finished experiment: its name, jobs (of which `kept` were
/// kept from an earlier run by `--resume`, not run now), failures and
/// seconds.
pub(super) fn line(name: &str, results: &[JobResult], kept: usize, elapsed: Duration) -> String {
    let failed = results.iter().filter(|r| r.failure.is_some()).count();
    let jobs = results.len();
    let jobs = if kept > 0 {
        format!(
            "{jobs} jobs ({} run now, {kept} kept from before)",
            jobs - kept
        )
    } else {
        format!("{jobs} jobs")
    };
    format!(
        "finished {name}: {jobs}, {failed} failed, {:.1} s",
        elapsed.as_secs_f64()
    )
}

/// Says that experiment `name` finished: above the bar on a terminal, as a
/// line on stderr otherwise; nothing unless `show`.
pub(super) fn finished(
    show: bool,
    bar: &ProgressBar,
    name: &str,
    results: &[JobResult],
    kept: usize,
    elapsed: Duration,
) {
    if !show {
        return;
    }
    let line = line(name, results, kept, elapsed);
    if bar.is_hidden() {
        crate::say!("{line}");
    } else {
        bar.println(line);
    }
}

/// How often a run without a bar (a log file, a pipe) says how far the
/// running experiment is: a long one printed nothing for minutes.
pub const LINE_EVERY: Duration = Duration::from_secs(30);

/// The jobs of one experiment finished so far, said as a line every
/// [`LINE_EVERY`] where no bar shows them.
pub struct Ticker {
    name: String,
    total: usize,
    started: std::time::Instant,
    state: std::sync::Mutex<(usize, std::time::Instant)>,
    show: bool,
}

impl Ticker {
    /// A ticker for `total` jobs of experiment `name`, `done` of them
    /// finished before; silent unless `show`.
    pub fn new(name: &str, total: usize, done: usize, show: bool) -> Self {
        let now = std::time::Instant::now();
        Ticker {
            name: name.to_string(),
            total,
            started: now,
            state: std::sync::Mutex::new((done, now)),
            show,
        }
    }

    /// Counts a finished job, and says the count if the last line is older
    /// than [`LINE_EVERY`].
    pub fn tick(&self) {
        let Ok(mut state) = self.state.lock() else {
            return;
        };
        state.0 += 1;
        if self.show && state.1.elapsed() >= LINE_EVERY {
            state.1 = std::time::Instant::now();
            crate::say!(
                "{}: {}/{} jobs finished, {:.0} s",
                self.name,
                state.0,
                self.total,
                self.started.elapsed().as_secs_f64()
            );
        }
    }
}

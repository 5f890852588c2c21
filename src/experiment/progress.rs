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

/// The line of a finished experiment: its name, jobs, failures and seconds.
pub(super) fn line(name: &str, results: &[JobResult], elapsed: Duration) -> String {
    let failed = results.iter().filter(|r| r.failure.is_some()).count();
    format!(
        "finished {name}: {} jobs, {failed} failed, {:.1} s",
        results.len(),
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
    elapsed: Duration,
) {
    if !show {
        return;
    }
    let line = line(name, results, elapsed);
    if bar.is_hidden() {
        crate::say!("{line}");
    } else {
        bar.println(line);
    }
}

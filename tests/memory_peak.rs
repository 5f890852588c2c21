//! The memory a job holds, estimated before it runs (`Rule::memory`:
//! Gauss–Legendre at 1e8 nodes holds about 5 GB), against the peak resident
//! memory the operating system measured for the real binary running that
//! job.
//!
//! A binary of its own: Linux counts into a spawned child's peak resident
//! memory the peak of the process that spawned it (`posix_spawn` shares its
//! memory until `exec`), so the parent must stay small. Among the other
//! integration tests it measured the test binary's own peak, and no job.

use std::path::PathBuf;
use std::process::Command;

use lightquad::quadrature::{GaussLegendre, Rule, Trapezoid};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lightquad"))
}

/// A one-job experiment: tau through the constant sphere with `rule` (its
/// JSON object) at `n`.
fn experiment(rule: &str, n: usize) -> String {
    format!(
        r#"{{"name": "m", "family": "volume", "equations": ["V-tau"],
  "scene": {{ "ray": {{ "origin": [-3.0, 0.3, 0.0], "direction": [1.0, 0.0, 0.0] }},
    "medium": {{ "type": "constant-sphere", "centre": [0, 0, 0], "radius": 1.0, "kappa": 2.0 }} }},
  "quantities": ["tau"], "rules": [{rule}], "budgets": [{n}], "repeats": 1,
  "reference": {{ "type": "closed-form" }} }}"#
    )
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lightquad-peak-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch");
    dir
}

/// Runs the job in a child process and returns that child's own peak
/// resident memory in bytes (`wait4` on its pid: `getrusage(RUSAGE_CHILDREN)`
/// would report the largest of every child this process has waited for).
#[cfg(target_os = "linux")]
fn run_and_measure(rule: &str, n: usize) -> f64 {
    use std::io::Read;
    use std::process::Stdio;
    let tag: String = rule.chars().filter(char::is_ascii_alphanumeric).collect();
    let dir = scratch(&format!("{tag}-{n}"));
    let file = dir.join("e.json");
    std::fs::write(&file, experiment(rule, n)).expect("write");
    #[expect(clippy::zombie_processes, reason = "reaped by wait4 below")]
    let mut child = bin()
        .arg("run")
        .arg(&file)
        .arg("--out")
        .arg(dir.join("out"))
        .args(["--threads", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs");
    // Drained to the end whatever its bytes, so the child never blocks on a
    // full pipe.
    let mut bytes = Vec::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = e.read_to_end(&mut bytes);
    }
    let stderr = String::from_utf8_lossy(&bytes);
    let pid = libc::pid_t::try_from(child.id()).expect("pid fits pid_t");
    let mut status = 0;
    // SAFETY: wait4 writes one int and one rusage struct, both on our stack;
    // the child is reaped here and never waited for through `child`.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let rc = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(rc, pid, "wait4 failed");
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "status {status}: {stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
    usage.ru_maxrss as f64 * 1024.0
}

/// The estimates of the two rules whose tables grow with n (Gauss–Legendre
/// with its estimate and without) are within a
/// factor 1.5 of the peak memory measured (above the binary's own baseline,
/// measured on a job of 16 nodes).
#[cfg(target_os = "linux")]
#[test]
fn memory_estimates_match_the_measured_peak() {
    let baseline = run_and_measure(r#"{"rule": "trapezoid"}"#, 16);
    let n = 4_000_000;
    let bare = GaussLegendre {
        error_estimate: false,
    };
    for (rule, estimate) in [
        (r#"{"rule": "trapezoid"}"#, Trapezoid.memory(n, 1)),
        (
            r#"{"rule": "gauss-legendre"}"#,
            GaussLegendre::default().memory(n, 1),
        ),
        (
            r#"{"rule": "gauss-legendre", "error_estimate": false}"#,
            bare.memory(n, 1),
        ),
    ] {
        let measured = run_and_measure(rule, n) - baseline;
        let ratio = estimate / measured;
        eprintln!(
            "{rule} n = {n}: estimate {estimate:.3e} B, measured {measured:.3e} B, ratio {ratio:.2}"
        );
        assert!(
            (1.0 / 1.5..=1.5).contains(&ratio),
            "{rule} at n = {n}: estimate {estimate:.3e} B, measured {measured:.3e} B above a \
             baseline of {baseline:.3e} B (ratio {ratio:.2})"
        );
    }
}

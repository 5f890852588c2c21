//! The memory a run may use: what the system has free (`MemAvailable`) and
//! the hard caps on this process (`prlimit`'s address-space and data limits,
//! a cgroup v2 `memory.max`), each as the room left under it. A job past a
//! hard cap does not slow down but aborts the whole process when an
//! allocation fails, so the runner refuses it with the cap named.
//!
//! Linux only (the files are read from /proc and /sys); elsewhere nothing is
//! known and nothing is capped.

use std::fs;

/// A hard cap on this process's memory and the room left under it.
#[derive(Debug, Clone, PartialEq)]
pub struct Cap {
    /// Bytes that may still be allocated under the cap.
    pub room: f64,
    /// The cap, in words (`the address-space limit (prlimit --as) of 2.0 GB`).
    pub what: String,
}

/// The memory a run keeps free beside its jobs' node tables (the part
/// [`crate::family::Family::memory`] estimates): the families' working
/// memory, converged references and reports. Measured under `ulimit -v`
/// with two threads on the bundled suite: with 110 MB of room an allocation
/// of 4.7 MB failed, with 130 MB it ran.
pub const REPORT_RESERVE: f64 = 128e6;

/// Makes every worker thread of the pool allocate once, so that its
/// allocator's arena (glibc reserves 64 MB of address space per thread
/// arena) exists before the room under a cap is measured: a run under
/// `ulimit -v` that fitted at the start aborted when the workers made theirs.
pub fn warm_workers() {
    rayon::broadcast(|_| std::hint::black_box(vec![0u8; 64]).len());
}

/// The address space `threads` worker threads reserve as they start: a
/// 2 MiB stack each (Rust's default), and glibc's 64 MiB arena for each of
/// the first `8 x cores` of them that allocate.
pub fn thread_reserve(threads: usize) -> f64 {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    let arenas = threads.min(8 * cores) as f64;
    threads as f64 * 2.0 * 1024.0 * 1024.0 + arenas * 64.0 * 1024.0 * 1024.0
}

/// A number of bytes as a person reads it: `512 KB`, `42.0 MB`, `1.50 GB`
/// (0.00 GB beside 0.00 GB told two sizes apart by nothing).
pub fn bytes(b: f64) -> String {
    if b >= 1e9 {
        format!("{:.2} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.1} MB", b / 1e6)
    } else {
        format!("{:.0} KB", (b / 1e3).ceil())
    }
}

/// The memory available to new work: the least of the system's
/// `MemAvailable` and the room under every hard cap, in bytes; `None` where
/// none is known.
pub fn available() -> Option<f64> {
    let free = mem_available();
    match (free, hard_cap()) {
        (Some(f), Some(c)) => Some(f.min(c.room)),
        (f, c) => f.or(c.map(|c| c.room)),
    }
}

/// The tightest hard cap on this process, if any.
pub fn hard_cap() -> Option<Cap> {
    let limits = fs::read_to_string("/proc/self/limits").unwrap_or_default();
    let status = fs::read_to_string("/proc/self/status").unwrap_or_default();
    let mut caps = Vec::new();
    for (limit, used, what) in [
        (
            "Max address space",
            "VmSize:",
            "the address-space limit (prlimit --as)",
        ),
        (
            "Max data size",
            "VmData:",
            "the data-segment limit (prlimit --data)",
        ),
    ] {
        if let (Some(cap), Some(used)) = (soft_limit(&limits, limit), status_kib(&status, used)) {
            caps.push(Cap {
                room: (cap - used).max(0.0),
                what: format!("{what} of {}", bytes(cap)),
            });
        }
    }
    if let (Some(max), Some(current)) = (
        read_bytes("/sys/fs/cgroup/memory.max"),
        read_bytes("/sys/fs/cgroup/memory.current"),
    ) {
        caps.push(Cap {
            room: (max - current).max(0.0),
            what: format!("the cgroup's memory.max of {}", bytes(max)),
        });
    }
    caps.into_iter().min_by(|a, b| a.room.total_cmp(&b.room))
}

/// `MemAvailable` of /proc/meminfo, in bytes.
fn mem_available() -> Option<f64> {
    let text = fs::read_to_string("/proc/meminfo").ok()?;
    status_kib(&text, "MemAvailable:")
}

/// The soft limit of the /proc/self/limits row `name`, in bytes (`None`
/// when unlimited).
fn soft_limit(limits: &str, name: &str) -> Option<f64> {
    let row = limits.lines().find(|l| l.starts_with(name))?;
    row[name.len()..].split_whitespace().next()?.parse().ok()
}

/// A `key: N kB` line of /proc's status files, in bytes.
fn status_kib(text: &str, key: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// A file holding a byte count (`max` reads as none).
fn read_bytes(path: &str) -> Option<f64> {
    fs::read_to_string(path).ok()?.trim().parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_rows_are_read_by_their_soft_column() {
        let limits = "Limit                     Soft Limit           Hard Limit           Units\n\
                      Max data size             unlimited            unlimited            bytes\n\
                      Max address space         2147483648           unlimited            bytes\n";
        assert_eq!(soft_limit(limits, "Max address space"), Some(2147483648.0));
        assert_eq!(soft_limit(limits, "Max data size"), None);
        assert_eq!(
            status_kib("VmSize:\t  123 kB\n", "VmSize:"),
            Some(123.0 * 1024.0)
        );
    }
}

//! Shared test helpers: reference-data loading and the tolerances every test
//! file uses, each with a sentence on when it applies.
#![allow(dead_code)]

use serde_json::Value as Json;

/// Unit roundoff of f64.
pub const EPS: f64 = f64::EPSILON;

/// Loads a JSON file from tests/data.
pub fn data(name: &str) -> Json {
    let path = format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Parses a decimal string (40 digits) to the nearest f64.
pub fn num(v: &Json) -> f64 {
    v.as_str()
        .unwrap_or_else(|| panic!("expected a decimal string, got {v}"))
        .parse()
        .unwrap_or_else(|e| panic!("{v}: {e}"))
}

/// Parses an array of decimal strings.
pub fn nums(v: &Json) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("expected an array, got {v}"))
        .iter()
        .map(num)
        .collect()
}

/// Relative difference `|a - b| / |b|` (absolute when b = 0).
pub fn rel(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        (a - b).abs()
    } else {
        ((a - b) / b).abs()
    }
}

/// A deterministic rng for the rule calls.
pub fn rng(seed: u64) -> rand_pcg::Pcg64 {
    use rand::SeedableRng;
    rand_pcg::Pcg64::seed_from_u64(seed)
}

/// Least-squares slope of `log(err)` against `log(n)`: the observed order.
pub fn fitted_order(points: &[(f64, f64)]) -> f64 {
    let m = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (n, e)| (a + n.ln(), b + e.ln()));
    let (mx, my) = (sx / m, sy / m);
    let (num, den) = points.iter().fold((0.0, 0.0), |(a, b), (n, e)| {
        let dx = n.ln() - mx;
        (a + dx * (e.ln() - my), b + dx * dx)
    });
    num / den
}

/// The `lightquad` binary under test.
pub fn bin() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_lightquad"))
}

/// A fresh, empty scratch folder under the system's temporary folder,
/// unique per process, `tag` and call.
pub fn scratch(tag: &str) -> std::path::PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "lightquad-test-{}-{tag}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::SeqCst)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// A command's standard error as text.
pub fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// The crate's root folder.
pub fn root() -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The bundled experiments whose file names start with `prefix` (`r-`,
/// `w-`), `(path, parsed)`, sorted by path.
pub fn bundled(prefix: &str) -> Vec<(std::path::PathBuf, Json)> {
    let mut out: Vec<(std::path::PathBuf, Json)> = std::fs::read_dir(root().join("experiments"))
        .expect("experiments/")
        .filter_map(Result::ok)
        .map(|f| f.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(prefix) && n.ends_with(".json"))
        })
        .map(|p| {
            let v =
                serde_json::from_str(&std::fs::read_to_string(&p).expect("read")).expect("json");
            (p, v)
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// Pearson's statistic over `(expected, observed)` cells plus the cell of
/// missed samples, cells expecting fewer than 5 pooled (Mitsuba 3's
/// convention). Returns (statistic, degrees of freedom, p-value).
pub fn pearson(
    missed_expected: f64,
    missed: f64,
    cells: impl Iterator<Item = (f64, f64)>,
) -> (f64, usize, f64) {
    use statrs::distribution::{ChiSquared, ContinuousCDF};
    let mut cells: Vec<(f64, f64)> = std::iter::once((missed_expected, missed))
        .chain(cells)
        .collect();
    for &(e, o) in &cells {
        assert!(e > 0.0 || o == 0.0, "{o} samples in a cell expecting none");
    }
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut pooled, mut kept) = ((0.0, 0.0), Vec::new());
    for (e, o) in cells {
        if e < 5.0 {
            pooled = (pooled.0 + e, pooled.1 + o);
        } else {
            kept.push((e, o));
        }
    }
    if pooled.0 >= 5.0 {
        kept.push(pooled);
    } else if let Some(first) = kept.first_mut() {
        *first = (first.0 + pooled.0, first.1 + pooled.1);
    }
    let stat: f64 = kept.iter().map(|(e, o)| (o - e) * (o - e) / e).sum();
    let dof = kept.len() - 1;
    let p = ChiSquared::new(dof as f64).expect("dof > 0").sf(stat);
    (stat, dof, p)
}

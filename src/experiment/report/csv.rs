//! `results.csv`: a line per job and quantity, timed by the quantity's own
//! evaluation (the job's time where the job failed before any quantity).

use std::fmt::Write as _;

use crate::experiment::run::JobResult;

/// A CSV line per job and quantity (a channel vector as `;`-separated numbers).
pub(super) fn csv(results: &[JobResult]) -> String {
    let mut csv = String::from(
        "experiment,rule_index,rule,budget,repeat,seed,quantity,value,estimated_error,evaluations,seconds,failure\n",
    );
    let join = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:e}"))
            .collect::<Vec<_>>()
            .join(";")
    };
    for r in results {
        let lead = format!(
            "{},{},{},{},{},{}",
            field(&r.experiment),
            r.rule_index,
            field(&r.rule),
            r.budget,
            r.repeat,
            r.seed
        );
        let failure = field(r.failure.as_deref().unwrap_or(""));
        if r.quantities.is_empty() {
            let why = if failure.is_empty() {
                "no value"
            } else {
                &failure
            };
            let _ = writeln!(csv, "{lead},,,,,{:e},{why}", r.seconds);
        }
        for (q, m) in &r.quantities {
            let _ = writeln!(
                csv,
                "{lead},{},{},{},{},{:e},{failure}",
                field(q),
                join(&m.value),
                join(&m.error),
                m.evaluations,
                m.seconds.unwrap_or(r.seconds)
            );
        }
    }
    csv
}

/// A CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

//! `results.csv`: a line per job and quantity, timed by the quantity's own
//! evaluation (a job that failed before any quantity: the time it ran until
//! it failed), with the quantity's reference and the job's true error
//! against it.

use std::fmt::Write as _;

use super::Page;
use super::rows::{halving, scale_of};
use crate::experiment::reference::rms;
use crate::experiment::run::JobResult;
use crate::family::Flag;

/// A CSV line per job and quantity (a channel vector as `;`-separated
/// numbers): `reference` is the quantity's reference per channel and
/// `rel_error` the job's root-mean-square error over channels against it,
/// relative to the reference's root mean square as in the report (both
/// empty where the quantity has no reference; the error empty where the
/// value underflowed).
pub(super) fn csv(page: &Page, results: &[JobResult]) -> String {
    let mut csv = String::from(
        "experiment,rule_index,rule,budget,repeat,seed,quantity,value,estimated_error,evaluations,seconds,reference,rel_error,failure\n",
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
            let _ = writeln!(csv, "{lead},,,,,{:e},,,{why}", r.seconds);
        }
        for (q, m) in &r.quantities {
            // A value that underflowed has no error f64 can show (0 against
            // a reference that also reads 0): empty, as the report's "—".
            let underflow = m.flags.contains(&Flag::Underflow);
            let (reference, error) = match page.reference.values.get(q) {
                Some(v) if underflow => (join(v), String::new()),
                Some(v) => (join(v), format!("{:e}", true_error(&m.value, v))),
                None => (String::new(), String::new()),
            };
            let _ = writeln!(
                csv,
                "{lead},{},{},{},{},{:e},{reference},{error},{failure}",
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

/// The root-mean-square error of `value` against `reference` over
/// channels, relative to the reference's root mean square (absolute where
/// that is 0); a missing channel is NaN. Near the top of the range the
/// halves are subtracted and the result doubled, as the report's rows do.
fn true_error(value: &[f64], reference: &[f64]) -> f64 {
    let n = value.len().max(reference.len());
    let at = |v: &[f64], c: usize| v.get(c).copied().unwrap_or(f64::NAN);
    let (halve, double) = halving(value.iter().chain(reference));
    rms((0..n).map(|c| at(value, c) * halve - at(reference, c) * halve)) / scale_of(reference)
        * double
}

/// A CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

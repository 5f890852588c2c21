//! Statistical verdicts on a random method's repeats at each budget: is its
//! mean the reference (bias), and are its standard errors the spread of its
//! values (honest error bars)?
//!
//! At a budget with `R >= 2` repeats `v_1..v_R` (standard errors
//! `s_1..s_R`) of a channel whose reference is `r` to within `tol`:
//!
//! - bias: `t = max(|mean - r| - tol, 0) / (max(sd, rms s_i) / sqrt R)`,
//!   two-sided Student's t with `R - 1` degrees of freedom. The larger of
//!   the observed spread and the claimed error bars: a few repeats of a
//!   skewed estimator that happen to cluster do not call a bias that is not
//!   there (the test stays conservative, its false-alarm rate at most the
//!   level); error bars that claim too much weaken it, and the error-bar
//!   test says so;
//! - error bars: `X = (R - 1) sd^2 / mean(s_i^2)`, two-sided against
//!   chi-square with `R - 1` degrees of freedom (a mean of squared
//!   standard errors is judged, so a standard error from few samples is not
//!   called too small for its own noise);
//! - coverage, shown beside: the fraction of repeats with
//!   `|v_i - r| <= 1.96 s_i + tol`, with its Wilson 95% interval.
//!
//! Each test is made at `1 - (1 - alpha)^(1/m)` (Šidák), `m` the budgets
//! times the channels judged for the rule, so that a method with no fault
//! is called faulty at some budget with probability at most `alpha`.
//!
//! ```
//! use lightquad::experiment::report::verdict::{Verdict, judge_budget};
//!
//! // Five repeats around 1.0 with honest standard errors: consistent.
//! let repeats = [(1.01, 0.02), (0.98, 0.02), (1.02, 0.02), (0.99, 0.02), (1.00, 0.02)];
//! let v = judge_budget(&[repeats.to_vec()], &[1.0], &[0.0], 0.01);
//! assert_eq!(v.verdict, Verdict::Consistent);
//! // The same spread around 1.1: biased.
//! let shifted: Vec<_> = repeats.iter().map(|&(x, s)| (x + 0.1, s)).collect();
//! let v = judge_budget(&[shifted], &[1.0], &[0.0], 0.01);
//! assert_eq!(v.verdict, Verdict::Biased);
//! ```

use statrs::distribution::{ChiSquared, ContinuousCDF, StudentsT};

/// The probability that a method with no fault is called faulty at some
/// budget, per rule, quantity and test.
pub const ALPHA: f64 = 0.01;

/// What the tests say of one budget.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// Neither test rejects.
    Consistent,
    /// The mean is not the reference.
    Biased,
    /// The values spread more than the standard errors say.
    SeTooSmall,
    /// The values spread less than the standard errors say.
    SeTooLarge,
    /// The method doubted a repeat's standard error (a sample variance
    /// carried by a few samples, as of an infinite-variance integrand or a
    /// rare event, or samples all alike), no bias was found, and the error
    /// bars were not found too small: neither test nor the coverage
    /// rejected them, or the error-bar test found them too large, as a
    /// bound is ([`Judged::in_doubt`]).
    SeInDoubt,
    /// The mean is the reference, but the method gives no standard error.
    NoSe,
    /// Fewer than two repeats: nothing to test.
    TooFewRepeats,
}

impl Verdict {
    /// As the reports print it.
    pub fn words(self) -> &'static str {
        match self {
            Verdict::Consistent => "consistent",
            Verdict::Biased => "biased",
            Verdict::SeTooSmall => "SE too small",
            Verdict::SeTooLarge => "SE too large",
            Verdict::SeInDoubt => "not rejected, SE in doubt",
            Verdict::NoSe => "no SE given",
            Verdict::TooFewRepeats => "too few repeats",
        }
    }
}

/// The tests at one budget, over every channel.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Judged {
    /// Repeats that gave a value.
    pub repeats: usize,
    /// The bias statistic `t` of the channel with the smallest p-value,
    /// signed as its mean's offset from the reference.
    pub t: f64,
    /// The smallest two-sided p-value of the bias test over the channels.
    pub p_bias: f64,
    /// `sd / sqrt(mean s_i^2)` of the channel farthest from 1 (in log), or
    /// None where no standard error was given.
    pub se_ratio: Option<f64>,
    /// The smallest two-sided p-value of the error-bar test.
    pub p_se: Option<f64>,
    /// Channel-repeats within 1.96 standard errors (and the reference's
    /// tolerance) of the reference, and those with a standard error.
    pub covered: [usize; 2],
    /// The Wilson 95% interval of the coverage.
    pub coverage: Option<[f64; 2]>,
    /// What they say at the per-test level.
    pub verdict: Verdict,
    /// The smallest over the channels of `P(X <= k)`, `X ~ Binomial(R,
    /// 0.95)`, `k` the channel's repeats within 1.96 standard errors: how
    /// likely so few are from honest error bars (1 where none is given).
    /// Per channel, as the channels of one repeat share its samples.
    pub p_coverage: f64,
    /// Repeats whose standard error the method itself doubted
    /// ([`Judged::in_doubt`]).
    pub doubted: usize,
}

impl Judged {
    /// The verdict where `doubted` of the repeats carry the method's doubt
    /// of their standard error (a sample variance carried by a few samples,
    /// samples or walks all alike, an error that is a bound): the tests'
    /// spread-based verdicts cannot lean on those error bars. A bias and
    /// error bars too small stand; error bars too large are what a bound
    /// gives, so in doubt; and where neither test rejects, the coverage
    /// decides: fewer repeats within 1.96 standard errors than 95%
    /// coverage makes likely at `level` (one-sided binomial) is error bars
    /// too small (a heavy tail's lucky repeat inflates the spread the
    /// error-bar test measures, not the misses), else in doubt.
    pub fn in_doubt(mut self, doubted: usize, level: f64) -> Judged {
        self.doubted = doubted;
        if doubted == 0 {
            return self;
        }
        self.verdict = match self.verdict {
            Verdict::SeTooLarge => Verdict::SeInDoubt,
            Verdict::Consistent if self.p_coverage < level => Verdict::SeTooSmall,
            Verdict::Consistent => Verdict::SeInDoubt,
            other => other,
        };
        self
    }
}

/// `P(X <= k)` for `X ~ Binomial(n, 0.95)`, `[k, n] = covered`: how likely
/// so few covered repeats are from honest 95% error bars (1 with none).
pub(crate) fn coverage_p([k, n]: [usize; 2]) -> f64 {
    use statrs::distribution::{Binomial, DiscreteCDF};
    if n == 0 {
        return 1.0;
    }
    Binomial::new(0.95, n as u64).map_or(1.0, |d| d.cdf(k as u64))
}

/// Judges one budget: `channels[c]` holds the repeats' `(value, standard
/// error)` of channel `c` (a standard error that is not finite: none
/// given), `reference[c]` and `tol[c]` its reference and the reference's
/// absolute accuracy; each test at level `level` (already corrected).
pub fn judge_budget(
    channels: &[Vec<(f64, f64)>],
    reference: &[f64],
    tol: &[f64],
    level: f64,
) -> Judged {
    let repeats = channels.first().map_or(0, Vec::len);
    let mut out = Judged {
        repeats,
        t: 0.0,
        p_bias: 1.0,
        se_ratio: None,
        p_se: None,
        covered: [0, 0],
        coverage: None,
        verdict: Verdict::TooFewRepeats,
        p_coverage: 1.0,
        doubted: 0,
    };
    if repeats < 2 {
        return out;
    }
    let mut has_se = true;
    let mut worst_log_ratio = -1.0;
    for (c, xs) in channels.iter().enumerate() {
        let r = reference.get(c).copied().unwrap_or(f64::NAN);
        let tol = tol.get(c).copied().unwrap_or(0.0);
        let (t, p) = bias(xs, r, tol);
        if p < out.p_bias || (p == out.p_bias && t.abs() > out.t.abs()) {
            out.t = t;
            out.p_bias = p;
        }
        has_se &= xs.iter().all(|(_, s)| s.is_finite());
        let mut channel = [0, 0];
        for &(v, s) in xs.iter().filter(|(_, s)| s.is_finite()) {
            channel[1] += 1;
            channel[0] += usize::from((v - r).abs() <= 1.96 * s + tol);
        }
        out.covered = [out.covered[0] + channel[0], out.covered[1] + channel[1]];
        out.p_coverage = out.p_coverage.min(coverage_p(channel));
        if let Some((ratio, p)) = spread(xs) {
            let off = ratio.ln().abs();
            if out.p_se.is_none_or(|q| p < q) || (out.p_se == Some(p) && off > worst_log_ratio) {
                out.p_se = Some(p);
                out.se_ratio = Some(ratio);
                worst_log_ratio = off;
            }
        }
    }
    if !has_se {
        out.p_se = None;
        out.se_ratio = None;
    }
    out.coverage = (out.covered[1] > 0).then(|| wilson(out.covered[0], out.covered[1]));
    out.verdict = if out.p_bias < level {
        Verdict::Biased
    } else if !has_se {
        Verdict::NoSe
    } else {
        match (out.p_se, out.se_ratio) {
            (Some(p), Some(ratio)) if p < level => {
                if ratio > 1.0 {
                    Verdict::SeTooSmall
                } else {
                    Verdict::SeTooLarge
                }
            }
            _ => Verdict::Consistent,
        }
    };
    out
}

/// The mean, sample standard deviation and root mean square standard
/// error (infinite where one is missing) of a channel's repeats, each in
/// units of `scale`, the largest magnitude among them, so that values near
/// the top of the f64 range do not overflow their squares.
struct Moments {
    scale: f64,
    mean: f64,
    sd: f64,
    se: f64,
}

fn moments(xs: &[(f64, f64)]) -> Moments {
    let n = xs.len() as f64;
    let scale = xs
        .iter()
        .map(|&(v, s)| v.abs().max(if s.is_finite() { s } else { 0.0 }))
        .fold(0.0, f64::max);
    let scale = if scale > 0.0 && scale.is_finite() {
        scale
    } else {
        1.0
    };
    let mean = xs.iter().map(|(v, _)| v / scale).sum::<f64>() / n;
    let sd = (xs
        .iter()
        .map(|(v, _)| (v / scale - mean).powi(2))
        .sum::<f64>()
        / (n - 1.0))
        .sqrt();
    let se = if xs.iter().all(|(_, s)| s.is_finite()) {
        (xs.iter().map(|(_, s)| (s / scale).powi(2)).sum::<f64>() / n).sqrt()
    } else {
        f64::INFINITY
    };
    Moments {
        scale,
        mean,
        sd,
        se,
    }
}

/// The bias test of one channel: `(t, two-sided p)`, `t` signed as the
/// mean's offset from the reference.
fn bias(xs: &[(f64, f64)], reference: f64, tol: f64) -> (f64, f64) {
    let n = xs.len() as f64;
    let m = moments(xs);
    // The larger of the spread and the claimed error bars (where given).
    let sd = if m.se.is_finite() {
        m.sd.max(m.se)
    } else {
        m.sd
    };
    // A reference is known only to within its accuracy (and rounding).
    let r = reference / m.scale;
    let tol = (tol / m.scale).max(4.0 * f64::EPSILON * r.abs());
    let off = ((m.mean - r).abs() - tol).max(0.0);
    let sign = if m.mean < r { -1.0 } else { 1.0 };
    if !off.is_finite() {
        return (sign * f64::INFINITY, 0.0);
    }
    if off == 0.0 {
        return (0.0, 1.0);
    }
    if sd == 0.0 {
        return (sign * f64::INFINITY, 0.0);
    }
    let t = off / (sd / n.sqrt());
    let p = StudentsT::new(0.0, 1.0, n - 1.0).map_or(f64::NAN, |d| 2.0 * d.sf(t));
    (sign * t, p)
}

/// The error-bar test of one channel: `(sd / rms(s), two-sided p)`, None
/// where a standard error is missing.
fn spread(xs: &[(f64, f64)]) -> Option<(f64, f64)> {
    let m = moments(xs);
    if !m.se.is_finite() {
        return None;
    }
    // Both at rounding level (a constant integrand: every repeat alike,
    // its standard error the rounding of its sum): nothing to judge.
    let rounding = 16.0 * f64::EPSILON * m.mean.abs();
    if m.sd <= rounding && m.se <= rounding {
        return Some((1.0, 1.0));
    }
    match (m.sd > 0.0, m.se > 0.0) {
        (false, false) => return Some((1.0, 1.0)),
        (true, false) => return Some((f64::INFINITY, 0.0)),
        (false, true) => return Some((0.0, 0.0)),
        (true, true) => {}
    }
    let ratio = m.sd / m.se;
    let n = xs.len() as f64;
    let x = (n - 1.0) * ratio * ratio;
    let d = ChiSquared::new(n - 1.0).ok()?;
    let p = (2.0 * d.cdf(x).min(d.sf(x))).min(1.0);
    Some((ratio, p))
}

/// The Wilson score 95% interval of `k` successes in `n` trials.
pub fn wilson(k: usize, n: usize) -> [f64; 2] {
    let (k, n) = (k as f64, n as f64);
    let z = 1.959_963_984_540_054_f64;
    let p = k / n;
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z / (1.0 + z * z / n) * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    [(centre - half).max(0.0), (centre + half).min(1.0)]
}

/// The per-test level that keeps the chance of any false call among `m`
/// tests at `alpha` (Šidák).
pub fn sidak(alpha: f64, m: usize) -> f64 {
    // -expm1(ln(1 - alpha) / m): no cancellation for a small alpha or a
    // large m (1 - (1 - alpha)^(1/m) rounds to 0 there).
    -((-alpha).ln_1p() / m.max(1) as f64).exp_m1()
}

/// One random rule's verdicts on one quantity, budget by budget.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RuleVerdicts {
    /// The rule's index in the file.
    pub rule_index: usize,
    /// Its label.
    pub label: String,
    /// The per-test level: [`ALPHA`] Šidák-corrected over its budgets and
    /// channels.
    pub level: f64,
    /// Per budget (ascending), the tests.
    pub budgets: Vec<(usize, Judged)>,
}

impl RuleVerdicts {
    /// The budgets of each verdict, in words: `biased at 1024, 4096;
    /// consistent at 16, 64`.
    pub fn in_words(&self) -> String {
        let mut seen: Vec<Verdict> = Vec::new();
        for (_, j) in &self.budgets {
            if !seen.contains(&j.verdict) {
                seen.push(j.verdict);
            }
        }
        seen.sort_by_key(|v| *v == Verdict::Consistent);
        seen.iter()
            .map(|v| {
                let at: Vec<String> = self
                    .budgets
                    .iter()
                    .filter(|(_, j)| j.verdict == *v)
                    .map(|(b, _)| b.to_string())
                    .collect();
                format!("{} at {}", v.words(), at.join(", "))
            })
            .collect::<Vec<_>>()
            .join("; ")
    }
}

/// The verdicts of every random rule of `page` on quantity `q`, from the
/// jobs' values, standard errors and the reference (`None` where `q` has no
/// reference).
pub fn verdicts(
    page: &super::Page,
    results: &[crate::experiment::run::JobResult],
    q: &str,
) -> Vec<RuleVerdicts> {
    let Some(reference) = page.reference.values.get(q) else {
        return Vec::new();
    };
    let scale = crate::experiment::reference::rms(reference.iter().copied());
    let tol: Vec<f64> = match page.reference.channel_accuracy.get(q) {
        Some(acc) if acc.len() == reference.len() => acc.clone(),
        _ => vec![page.reference.accuracy_of(q) * scale; reference.len()],
    };
    let mut out = Vec::new();
    for (i, rule) in page.rules.iter().enumerate() {
        if !rule.is_random {
            continue;
        }
        // Per budget, per channel, the repeats' (value, standard error); and
        // the budgets where the method doubted a repeat's standard error.
        let mut by_budget: std::collections::BTreeMap<usize, Vec<Vec<(f64, f64)>>> =
            std::collections::BTreeMap::new();
        let mut doubted: std::collections::BTreeMap<usize, usize> =
            std::collections::BTreeMap::new();
        for r in results
            .iter()
            .filter(|r| r.rule_index == i && r.failure.is_none())
        {
            let Some(m) = r.quantities.get(q) else {
                continue;
            };
            // A value that underflows f64 is 0 whatever its truth: no test.
            if m.value.len() != reference.len()
                || m.error.len() != reference.len()
                || m.flags.contains(&crate::family::Flag::Underflow)
            {
                continue;
            }
            if m.flags.iter().any(doubts_se) {
                *doubted.entry(r.budget).or_default() += 1;
            }
            let cells = by_budget
                .entry(r.budget)
                .or_insert_with(|| vec![Vec::new(); reference.len()]);
            for (c, cell) in cells.iter_mut().enumerate() {
                cell.push((m.value[c], m.error[c]));
            }
        }
        let judged = by_budget
            .values()
            .filter(|cells| cells.first().is_some_and(|c| c.len() >= 2))
            .count();
        if judged == 0 {
            continue;
        }
        let level = sidak(ALPHA, judged * reference.len());
        out.push(RuleVerdicts {
            rule_index: i,
            label: rule.label.clone(),
            level,
            budgets: by_budget
                .into_iter()
                .map(|(b, cells)| {
                    let j = judge_budget(&cells, reference, &tol, level);
                    (b, j.in_doubt(doubted.get(&b).copied().unwrap_or(0), level))
                })
                .collect(),
        });
    }
    out
}

/// Whether a job's flag says its standard error is not a sample standard
/// error to be trusted: a rejection still stands, but "consistent" would
/// vouch for error bars the method itself doubted.
fn doubts_se(flag: &crate::family::Flag) -> bool {
    use crate::family::Flag;
    matches!(
        flag,
        Flag::UnreliableEstimate | Flag::HeavyWalks { .. } | Flag::AllWalksAlike { .. }
    )
}

/// The verdicts as a Markdown section (empty when there are none).
pub fn markdown(verdicts: &[RuleVerdicts]) -> String {
    use std::fmt::Write as _;
    if verdicts.is_empty() {
        return String::new();
    }
    let mut md = format!(
        "### Verdicts on the random rules\n\n\
         Per budget, over its repeats: the bias test (Student's t of the mean against the \
         reference, less the reference's accuracy, over the larger of the values' spread and \
         their root mean square standard error) and the error-bar test (chi-square of the \
         values' spread against the mean squared standard error), each at α = {ALPHA} per rule \
         over all its budgets and channels (Šidák: the level per test is given by rule); \
         coverage is the share of repeats within 1.96 standard errors of the reference, with \
         its Wilson 95% interval (about 95% for honest error bars).\n\n"
    );
    let in_doubt = |v: &RuleVerdicts| v.budgets.iter().any(|(_, j)| j.doubted > 0);
    if verdicts.iter().any(in_doubt) {
        md.push_str(
            "Where the rule itself doubted the standard error of some repeats (counted beside \
             the verdict: a sample variance carried by a few samples, as of an infinite variance \
             or a rare event; samples or walks all alike; an error that is a bound), the \
             error-bar test cannot lean on those error bars: error bars larger than the spread \
             are \"not rejected, SE in doubt\", and where neither test rejects the coverage \
             decides, \"SE too small\" where a channel's coverage is below what 95% error bars \
             make likely at the level (one-sided binomial), else \"not rejected, SE in doubt\": \
             the error bars rest on the repeats' agreement alone.\n\n",
        );
    }
    for v in verdicts {
        let _ = writeln!(
            md,
            "- **{}**: {} (level per test {:.1e}).",
            v.label,
            v.in_words(),
            v.level
        );
    }
    md.push_str(
        "\n| verdict | rule | n | repeats | bias t | p (bias) | sd / SE | p (SE) | coverage |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for v in verdicts {
        for (b, j) in &v.budgets {
            let _ = writeln!(
                md,
                "| {}{} | {} | {b} | {} | {} | {} | {} | {} | {} |",
                j.verdict.words(),
                if j.doubted > 0 {
                    format!(" ({} of {} flagged)", j.doubted, j.repeats)
                } else {
                    String::new()
                },
                v.label,
                j.repeats,
                number(j.t, j.repeats),
                number(j.p_bias, j.repeats),
                j.se_ratio.map_or("—".into(), |r| format!("{r:.2}")),
                j.p_se.map_or("—".into(), |p| format!("{p:.2e}")),
                coverage(j)
            );
        }
    }
    md
}

fn number(x: f64, repeats: usize) -> String {
    if repeats < 2 {
        "—".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else {
        format!("{x:.2e}")
    }
}

fn coverage(j: &Judged) -> String {
    match j.coverage {
        Some([lo, hi]) => format!(
            "{}/{} ({:.0}% to {:.0}%)",
            j.covered[0],
            j.covered[1],
            100.0 * lo,
            100.0 * hi
        ),
        None => "—".into(),
    }
}

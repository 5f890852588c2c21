//! Tests of an estimator against a reference value over seeded repeats.
//!
//! Repeat `i` of `R` gives `x_i` per channel, and optionally its standard
//! error `s_i`. Per channel, against the reference `r` known to `tol`:
//!
//! - **mean**: `t = max(|mean - r| - tol, 0) / (sd / sqrt R)`, two-sided
//!   Student's t with `R - 1` degrees of freedom (the spread of the
//!   repeats, not the error bars: a dishonest error bar cannot hide a bias);
//! - **variance**, where the variance of one repeat is stated
//!   ([`EstimatorTest::variance`]) or each repeat gives its standard
//!   error: the log of the ratio of `A = mean(R / (R - 1) (x_i -
//!   mean)^2)` to `B = mean(s_i^2)` over its delta-method standard error
//!   (from the draws' own moments), two-sided normal. It asks no
//!   normality of `x`, so it holds for skewed estimators, asymptotically:
//!   `tests/it/testing_api.rs` measures its false alarms at 100 and 400
//!   repeats (about twice its level at 100, at its level at 400);
//! - **coverage**, where standard errors are given: the `k` of `R` repeats
//!   with `|x_i - r| <= 1.96 s_i + tol`, one-sided binomial against 0.95
//!   (error bars that cover too little fail; the Wilson 95% interval is
//!   reported). For an estimator far from normal (few samples of a skewed
//!   integrand) 1.96 standard errors cover less than 95% though the
//!   standard error is right: test at a budget where it is near normal.
//!
//! Each check is made at `alpha` Šidák-corrected over the checks, the
//! channels and the `tests` of the suite. Values are scaled by a power of
//! 2 per channel first, so values near `1e300` do not overflow a square.

use std::fmt;

use statrs::distribution::{ContinuousCDF, Normal, StudentsT};

use crate::error::QuadError;
use crate::experiment::report::verdict::{coverage_p, wilson};

use super::{Truth, check_alpha, check_count, repeat_rng, sidak};

/// The most repeats of one test.
pub const MAX_REPEATS: usize = 10_000_000;

/// The most values (repeats times channels) one test keeps.
pub const MAX_VALUES: usize = 100_000_000;

/// One draw of an estimator: a value per channel and, optionally, its
/// standard error per channel.
pub trait Draw {
    /// The value per channel.
    fn values(&self) -> Vec<f64>;
    /// The standard error per channel, where the estimator gives one.
    fn std_errors(&self) -> Option<Vec<f64>> {
        None
    }
}

impl Draw for f64 {
    fn values(&self) -> Vec<f64> {
        vec![*self]
    }
}

/// `(value, standard error)`.
impl Draw for (f64, f64) {
    fn values(&self) -> Vec<f64> {
        vec![self.0]
    }
    fn std_errors(&self) -> Option<Vec<f64>> {
        Some(vec![self.1])
    }
}

impl<const N: usize> Draw for [f64; N] {
    fn values(&self) -> Vec<f64> {
        self.to_vec()
    }
}

impl Draw for Vec<f64> {
    fn values(&self) -> Vec<f64> {
        self.clone()
    }
}

/// `(values, standard errors)`.
impl<const N: usize> Draw for ([f64; N], [f64; N]) {
    fn values(&self) -> Vec<f64> {
        self.0.to_vec()
    }
    fn std_errors(&self) -> Option<Vec<f64>> {
        Some(self.1.to_vec())
    }
}

/// `(values, standard errors)`.
impl Draw for (Vec<f64>, Vec<f64>) {
    fn values(&self) -> Vec<f64> {
        self.0.clone()
    }
    fn std_errors(&self) -> Option<Vec<f64>> {
        Some(self.1.clone())
    }
}

/// The value an estimator should have, per channel, with its absolute
/// accuracy (a difference within it is no bias).
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// Per channel.
    pub value: Vec<f64>,
    /// Per channel, absolute.
    pub accuracy: Vec<f64>,
}

impl Reference {
    /// The same value known to `accuracy` (absolute, every channel).
    pub fn within(mut self, accuracy: f64) -> Self {
        self.accuracy = vec![accuracy; self.value.len()];
        self
    }
}

impl From<Vec<f64>> for Reference {
    fn from(value: Vec<f64>) -> Self {
        let accuracy = vec![0.0; value.len()];
        Reference { value, accuracy }
    }
}

impl From<f64> for Reference {
    fn from(value: f64) -> Self {
        vec![value].into()
    }
}

impl<const N: usize> From<[f64; N]> for Reference {
    fn from(value: [f64; N]) -> Self {
        value.to_vec().into()
    }
}

impl From<&Truth> for Reference {
    fn from(truth: &Truth) -> Self {
        Reference {
            value: truth.value.clone(),
            accuracy: truth.accuracy.clone(),
        }
    }
}

impl From<Truth> for Reference {
    fn from(truth: Truth) -> Self {
        (&truth).into()
    }
}

/// Settings of an estimator test; see the [module](self).
///
/// ```
/// use lightquad::testing::EstimatorTest;
/// use lightquad::rand::RngExt;
///
/// // One uniform sample of 2 x on [0, 1]: mean 1, variance 1/3.
/// let test = EstimatorTest::new(1000).seed(3).variance(vec![1.0 / 3.0]);
/// let good = test.run(1.0, |rng| 2.0 * rng.random::<f64>())?;
/// assert!(good.passed, "{good}");
/// // A sampler that never reaches the top tenth: biased.
/// let bad = test.run(1.0, |rng| 2.0 * 0.9 * rng.random::<f64>())?;
/// assert!(!bad.passed);
/// # Ok::<(), lightquad::QuadError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct EstimatorTest {
    repeats: usize,
    seed: u64,
    alpha: f64,
    tests: usize,
    variance: Option<Vec<f64>>,
}

impl EstimatorTest {
    /// `repeats` independent draws, seed 0, `alpha = 0.01`, one test.
    pub fn new(repeats: usize) -> Self {
        EstimatorTest {
            repeats,
            seed: 0,
            alpha: 0.01,
            tests: 1,
            variance: None,
        }
    }

    /// The seed: repeat `i` draws from its own stream of it.
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// The chance that a correct estimator fails one of the suite's tests.
    pub fn alpha(mut self, alpha: f64) -> Self {
        self.alpha = alpha;
        self
    }

    /// How many tests the suite makes with this `alpha` (Šidák).
    pub fn tests(mut self, tests: usize) -> Self {
        self.tests = tests;
        self
    }

    /// The variance of one draw, per channel, as the estimator's theory
    /// states it: checked against the draws' spread.
    pub fn variance(mut self, variance: Vec<f64>) -> Self {
        self.variance = Some(variance);
        self
    }

    /// Draws the repeats from `estimator` and tests them against `reference`.
    pub fn run<D, F>(
        &self,
        reference: impl Into<Reference>,
        mut estimator: F,
    ) -> Result<EstimatorOutcome, QuadError>
    where
        D: Draw,
        F: FnMut(&mut rand_pcg::Pcg64) -> D,
    {
        let reference = self.check(reference.into())?;
        let channels = reference.value.len();
        let mut draws: Vec<Vec<(f64, Option<f64>)>> = vec![Vec::new(); channels];
        for k in 0..self.repeats {
            let d = estimator(&mut repeat_rng(self.seed, k));
            let (values, errors) = (d.values(), d.std_errors());
            checked_draw(k, &values, errors.as_deref(), channels)?;
            for (c, x) in values.into_iter().enumerate() {
                let s = errors.as_ref().map(|e| e[c]);
                draws[c].push((x, s));
            }
        }
        Ok(self.judge(&reference, &draws))
    }

    /// The settings and the reference, checked.
    fn check(&self, reference: Reference) -> Result<Reference, QuadError> {
        check_count("repeats", self.repeats, 2, MAX_REPEATS)?;
        check_alpha(self.alpha)?;
        check_count("tests", self.tests, 1, super::chi_square::MAX_TESTS)?;
        check_count("reference channels", reference.value.len(), 1, 1 << 20)?;
        if reference.accuracy.len() != reference.value.len() {
            return Err(QuadError::invalid(
                "reference accuracy",
                format!("{} channels", reference.accuracy.len()),
                format!(
                    "{} channels, as the reference's value",
                    reference.value.len()
                ),
            ));
        }
        let values = self.repeats.saturating_mul(reference.value.len());
        if values > MAX_VALUES {
            return Err(QuadError::invalid(
                "repeats",
                self.repeats,
                format!(
                    "at most {MAX_VALUES} values in all with {} channels: fewer repeats",
                    reference.value.len()
                ),
            ));
        }
        for (c, (&v, &a)) in reference.value.iter().zip(&reference.accuracy).enumerate() {
            if !v.is_finite() {
                return Err(QuadError::invalid(
                    format!("reference[{c}]"),
                    v,
                    "a finite value",
                ));
            }
            if !(a.is_finite() && a >= 0.0) {
                return Err(QuadError::invalid(
                    format!("reference accuracy[{c}]"),
                    a,
                    "a finite number >= 0",
                ));
            }
        }
        if let Some(var) = &self.variance {
            if var.len() != reference.value.len() {
                return Err(QuadError::invalid(
                    "variance",
                    format!("{} channels", var.len()),
                    format!("{} channels, as the reference", reference.value.len()),
                ));
            }
            if let Some((c, v)) = var
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
            {
                return Err(QuadError::invalid(
                    format!("variance[{c}]"),
                    v,
                    "a finite number >= 0",
                ));
            }
        }
        Ok(reference)
    }

    /// The checks of every channel.
    fn judge(&self, reference: &Reference, draws: &[Vec<(f64, Option<f64>)>]) -> EstimatorOutcome {
        let has_se = draws.iter().all(|d| d.iter().all(|(_, s)| s.is_some()));
        let kinds = 1 + usize::from(has_se || self.variance.is_some()) + usize::from(has_se);
        let level = sidak(self.alpha, self.tests.saturating_mul(kinds * draws.len()));
        let mut checks = Vec::new();
        let (mut mean, mut sd) = (Vec::new(), Vec::new());
        for (c, d) in draws.iter().enumerate() {
            // In units of the channel's largest magnitude (a power of 2, so
            // exactly): squares of values near 1e300 do not overflow.
            let stated = self.variance.as_ref().map(|v| v[c]);
            let unit = unit(d, reference.value[c], reference.accuracy[c], stated);
            let d: Vec<(f64, Option<f64>)> = d
                .iter()
                .map(|(x, s)| (x / unit, s.map(|s| s / unit)))
                .collect();
            let xs: Vec<f64> = d.iter().map(|p| p.0).collect();
            let (m, s) = mean_sd(&xs);
            mean.push(m * unit);
            sd.push(s * unit);
            let (r, tol) = (reference.value[c] / unit, reference.accuracy[c] / unit);
            checks.push(mean_check(c, m, s, xs.len(), r, tol, level, unit));
            let var: Option<Vec<f64>> = match stated {
                Some(v) => Some(vec![v / unit / unit; xs.len()]),
                None if has_se => Some(d.iter().map(|p| p.1.unwrap_or(0.0).powi(2)).collect()),
                None => None,
            };
            if let Some(var) = var {
                checks.push(variance_check(c, &xs, m, &var, level, unit));
            }
            if has_se {
                checks.push(coverage_check(c, &d, r, tol, level));
            }
        }
        EstimatorOutcome {
            passed: checks.iter().all(|k| k.passed),
            repeats: self.repeats,
            level,
            mean,
            sd,
            checks,
        }
    }
}

/// Checks one draw: `channels` finite values, standard errors finite and
/// `>= 0`, naming the repeat and channel.
fn checked_draw(
    k: usize,
    values: &[f64],
    errors: Option<&[f64]>,
    channels: usize,
) -> Result<(), QuadError> {
    if values.len() != channels {
        return Err(QuadError::invalid(
            format!("repeat {k}: the estimator's value"),
            format!("{} channels", values.len()),
            format!("{channels} channels, as the reference"),
        ));
    }
    if let Some((c, x)) = values.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(QuadError::invalid(
            format!("repeat {k}: the estimator's value[{c}]"),
            x,
            "a finite value",
        ));
    }
    if let Some(e) = errors {
        if e.len() != channels {
            return Err(QuadError::invalid(
                format!("repeat {k}: the estimator's standard error"),
                format!("{} channels", e.len()),
                format!("{channels} channels, as the reference"),
            ));
        }
        if let Some((c, s)) = e
            .iter()
            .enumerate()
            .find(|(_, s)| !(s.is_finite() && **s >= 0.0))
        {
            return Err(QuadError::invalid(
                format!("repeat {k}: the estimator's standard error[{c}]"),
                s,
                "a finite number >= 0",
            ));
        }
    }
    Ok(())
}

/// The power of 2 at or above the largest magnitude among a channel's
/// values, standard errors, reference, its accuracy and the stated
/// variance's square root (1 where all are 0).
fn unit(d: &[(f64, Option<f64>)], r: f64, tol: f64, variance: Option<f64>) -> f64 {
    let big = d
        .iter()
        .flat_map(|(x, s)| [x.abs(), s.unwrap_or(0.0)])
        .chain([r.abs(), tol, variance.unwrap_or(0.0).sqrt()])
        .fold(0.0, f64::max);
    if big > 0.0 && big.is_finite() {
        2f64.powi(big.log2().ceil() as i32)
    } else {
        1.0
    }
}

/// The mean and the sample standard deviation (`R - 1`), by Welford's
/// update (no cancellation for values far from 0).
fn mean_sd(xs: &[f64]) -> (f64, f64) {
    let (mut m, mut s2) = (0.0, 0.0);
    for (i, &x) in xs.iter().enumerate() {
        let d = x - m;
        m += d / (i + 1) as f64;
        s2 += d * (x - m);
    }
    let n = xs.len() as f64;
    (m, (s2 / (n - 1.0)).max(0.0).sqrt())
}

/// The two-sided p-value of a t (or, for `dof` infinite, normal) statistic;
/// a spread of 0 gives 1 for no offset and 0 for any.
fn two_sided(t: f64, dof: f64) -> f64 {
    // A statistic that is not a number is a failure, never a pass.
    if t.is_nan() {
        return 0.0;
    }
    if t.is_infinite() {
        return 0.0;
    }
    let sf = if dof.is_finite() {
        StudentsT::new(0.0, 1.0, dof).map_or(0.0, |d| d.sf(t.abs()))
    } else {
        Normal::standard().sf(t.abs())
    };
    (2.0 * sf).min(1.0)
}

/// `offset / scale` with `0 / 0 = 0` and `x / 0 = inf`.
fn ratio(offset: f64, scale: f64) -> f64 {
    if offset == 0.0 {
        0.0
    } else if scale > 0.0 {
        offset / scale
    } else {
        offset.signum() * f64::INFINITY
    }
}

/// The mean check of one channel, its figures in units of `unit`.
#[allow(clippy::too_many_arguments)]
fn mean_check(
    c: usize,
    m: f64,
    sd: f64,
    n: usize,
    r: f64,
    tol: f64,
    level: f64,
    unit: f64,
) -> Check {
    let off = ((m - r).abs() - tol).max(0.0) * (m - r).signum();
    let t = ratio(off, sd / (n as f64).sqrt());
    let p = two_sided(t, (n - 1) as f64);
    Check {
        kind: CheckKind::Mean,
        channel: c,
        statistic: t,
        p_value: p,
        passed: p > level,
        detail: format!(
            "mean {:.6e} against {:.6e} (t = {t:.3}, {} dof)",
            m * unit,
            r * unit,
            n - 1
        ),
    }
}

/// The variance check of one channel against the per-draw variances `var`:
/// `z = ln(A / B) / sqrt(Var A / A^2 + Var B / B^2 - 2 Cov(A, B) / (A B))`,
/// `A` the mean of `a_i = R / (R - 1) (x_i - mean)^2`, `B` the mean of
/// `b_i = var_i`, their (co)variances those of the means, from the
/// draws' own moments (the delta method; the logarithm takes out most of
/// the skew of a variance).
fn variance_check(c: usize, xs: &[f64], m: f64, var: &[f64], level: f64, unit: f64) -> Check {
    let n = xs.len() as f64;
    let a: Vec<f64> = xs
        .iter()
        .map(|x| n / (n - 1.0) * (x - m) * (x - m))
        .collect();
    let (ma, sa) = mean_sd(&a);
    let (mb, sb) = mean_sd(var);
    let cov = a
        .iter()
        .zip(var)
        .map(|(x, y)| (x - ma) * (y - mb))
        .sum::<f64>()
        / (n - 1.0);
    let spread = (sa * sa / (ma * ma) + sb * sb / (mb * mb) - 2.0 * cov / (ma * mb)) / n;
    let z = if ma == mb {
        0.0
    } else if ma > 0.0 && mb > 0.0 {
        ratio((ma / mb).ln(), spread.max(0.0).sqrt())
    } else {
        (ma - mb).signum() * f64::INFINITY
    };
    let p = two_sided(z, f64::INFINITY);
    let (spread, claimed) = (ma.sqrt() * unit, mb.sqrt() * unit);
    Check {
        kind: CheckKind::Variance,
        channel: c,
        statistic: z,
        p_value: p,
        passed: p > level,
        detail: format!(
            "spread {spread:.4e} against {claimed:.4e} (ratio {}, z = {z:.3})",
            if claimed > 0.0 {
                format!("{:.3}", spread / claimed)
            } else {
                "-".into()
            }
        ),
    }
}

/// The coverage check of one channel.
fn coverage_check(c: usize, d: &[(f64, Option<f64>)], r: f64, tol: f64, level: f64) -> Check {
    let n = d.len();
    let k = d
        .iter()
        .filter(|(x, s)| (x - r).abs() <= 1.96 * s.unwrap_or(0.0) + tol)
        .count();
    let p = coverage_p([k, n]);
    let [lo, hi] = wilson(k, n);
    Check {
        kind: CheckKind::Coverage,
        channel: c,
        statistic: k as f64 / n as f64,
        p_value: p,
        passed: p > level,
        detail: format!(
            "{k} of {n} within 1.96 SE ({:.1}%, 95% interval {:.1}%..{:.1}%)",
            100.0 * k as f64 / n as f64,
            100.0 * lo,
            100.0 * hi
        ),
    }
}

/// Which check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckKind {
    /// The mean against the reference.
    Mean,
    /// The spread against the stated variance or the error bars.
    Variance,
    /// The coverage of the error bars.
    Coverage,
}

/// One check of one channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// Which.
    pub kind: CheckKind,
    /// The channel.
    pub channel: usize,
    /// Its statistic: t, z, or the fraction covered.
    pub statistic: f64,
    /// Its p-value.
    pub p_value: f64,
    /// `p_value` above the level.
    pub passed: bool,
    /// In words.
    pub detail: String,
}

/// What an [`EstimatorTest`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimatorOutcome {
    /// Every check passed.
    pub passed: bool,
    /// Repeats drawn.
    pub repeats: usize,
    /// The per-check level.
    pub level: f64,
    /// The repeats' mean per channel.
    pub mean: Vec<f64>,
    /// Their standard deviation per channel.
    pub sd: Vec<f64>,
    /// Every check.
    pub checks: Vec<Check>,
}

impl EstimatorOutcome {
    /// The check of `kind` on `channel`, where it was made.
    pub fn check(&self, kind: CheckKind, channel: usize) -> Option<&Check> {
        self.checks
            .iter()
            .find(|k| k.kind == kind && k.channel == channel)
    }

    /// Panics with the outcome in words unless it passed.
    pub fn assert_passed(&self) {
        assert!(self.passed, "{self}");
    }
}

impl fmt::Display for EstimatorOutcome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let verdict = if self.passed { "passed" } else { "FAILED" };
        write!(
            f,
            "estimator test {verdict} over {} repeats (level {:.2e} per check)",
            self.repeats, self.level
        )?;
        for k in &self.checks {
            let mark = if k.passed { "ok" } else { "FAIL" };
            write!(
                f,
                "\n  {mark} {:?}[{}]: {}, p = {:.3e}",
                k.kind, k.channel, k.detail, k.p_value
            )?;
        }
        Ok(())
    }
}

//! How a job is timed, and how sure a row's time is.
//!
//! A job is evaluated once for its values; where that call is shorter than
//! the clock reads reliably ([`MIN_TIMED_SECONDS`]), the same call, from the
//! same seed, is repeated in [`TIMING_BATCHES`] batches long enough to read
//! (criterion's approach), and each batch's mean per call is a sample. The
//! repeats never touch the recorded values or evaluation counts: they only
//! time; the job's time is the median batch. A row's time is the median of
//! its repeats' times, with a distribution-free confidence interval
//! ([`TimeInterval`]): the repeats ran at different moments of the run, so
//! their spread holds the machine's changing load within the run. It does
//! not hold what changes from one run to the next (the whole of a second
//! run on an idle machine can be 25% slower): `lightquad compare` judges
//! against that with a noise threshold.
//!
//! ```
//! use lightquad::experiment::timing::TimeInterval;
//!
//! // Nine samples: the median is the 5th; the 2nd and 8th order statistics
//! // bound it with confidence 1 - 2 P(Bin(9, 1/2) <= 1) = 0.961.
//! let t = TimeInterval::of(&[9.0, 1.0, 8.0, 2.0, 7.0, 3.0, 6.0, 4.0, 5.0]).ok_or("empty")?;
//! assert_eq!((t.median, t.low, t.high), (5.0, 2.0, 8.0));
//! assert!((t.confidence - 0.9609375).abs() < 1e-12);
//! // Three samples reach no 95%: their range, with its own confidence (0.75).
//! let t = TimeInterval::of(&[3.0, 1.0, 2.0]).ok_or("empty")?;
//! assert_eq!((t.low, t.median, t.high, t.confidence), (1.0, 2.0, 3.0, 0.75));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::time::Instant;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Below this, one evaluation's wall time is mostly clock resolution and
/// scheduling noise (sub-microsecond jobs ranked by a single reading swapped
/// places from run to run): such a job is timed again, in batches.
pub const MIN_TIMED_SECONDS: f64 = 2e-4;

/// Batches a fast job is timed in; each batch's mean per call is a sample.
pub const TIMING_BATCHES: usize = 5;

/// The confidence a row's time interval aims at; fewer than six samples
/// cannot reach it, and their interval states the confidence it has.
pub const CONFIDENCE: f64 = 0.95;

/// How much a row's time moves from one run of a build to the next, beyond
/// what its interval holds: two runs of the bundled suite on an idle
/// 2-core machine (2026-12-02) had 99% of rows within 1.32x of each other,
/// and 1 of 2193 rows with intervals apart beyond 1.5x.
pub const RUN_NOISE: f64 = 0.5;

/// The time per call of an evaluation whose first call took `once`
/// seconds: that reading where it is at least [`MIN_TIMED_SECONDS`];
/// otherwise the median over [`TIMING_BATCHES`] batches, each long enough
/// to read the clock reliably, of the mean time of `again` (the same
/// evaluation, from the same seed).
pub fn timed(once: f64, mut again: impl FnMut()) -> f64 {
    if once >= MIN_TIMED_SECONDS {
        return once;
    }
    let per_batch = (MIN_TIMED_SECONDS / once.max(1e-9)).ceil().min(10_000.0) as usize;
    let mut means: Vec<f64> = (0..TIMING_BATCHES)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..per_batch {
                again();
            }
            start.elapsed().as_secs_f64() / per_batch as f64
        })
        .collect();
    means.sort_by(f64::total_cmp);
    means[(TIMING_BATCHES - 1) / 2]
}

/// A time with a distribution-free confidence interval for its median.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TimeInterval {
    /// The lower median of the samples, seconds.
    pub median: f64,
    /// The interval's lower end: an order statistic, seconds.
    pub low: f64,
    /// The interval's upper end, seconds.
    pub high: f64,
    /// The probability that the interval holds the true median, exact for
    /// independent samples of any continuous distribution: at least
    /// [`CONFIDENCE`] from six samples on; below that, the range of the
    /// samples with the confidence it has (`1 - 2^(1-n)`: 0.75 for three).
    pub confidence: f64,
    /// Samples: one per repeat.
    pub samples: usize,
}

impl TimeInterval {
    /// The median of `samples` (non-finite ones left out) and the tightest
    /// pair of order statistics `(x_k, x_(n+1-k))` that holds it with
    /// probability at least [`CONFIDENCE`], the sample range where none
    /// does; None without a finite sample.
    pub fn of(samples: &[f64]) -> Option<TimeInterval> {
        let mut x: Vec<f64> = samples.iter().copied().filter(|s| s.is_finite()).collect();
        if x.is_empty() {
            return None;
        }
        x.sort_by(f64::total_cmp);
        let n = x.len();
        // Coverage of (x_k, x_(n+1-k)): 1 - 2 P(Bin(n, 1/2) <= k - 1).
        let coverage = |k: usize| 1.0 - 2.0 * binomial_half_cdf(n, k - 1);
        let mut k = 1;
        while k < n.div_ceil(2) && coverage(k + 1) >= CONFIDENCE {
            k += 1;
        }
        Some(TimeInterval {
            median: x[(n - 1) / 2],
            low: x[k - 1],
            high: x[n - k],
            confidence: coverage(k),
            samples: n,
        })
    }

    /// Whether two intervals share a time.
    pub fn overlaps(&self, other: &TimeInterval) -> bool {
        self.low <= other.high && other.low <= self.high
    }

    /// Whether two times are told apart: their intervals are disjoint; where
    /// either is a single reading (no interval), their ratio is beyond
    /// `1 + RUN_NOISE`, what two runs of one build differ by.
    pub fn apart(&self, other: &TimeInterval) -> bool {
        if self.samples < 2 || other.samples < 2 {
            let (a, b) = (self.median.min(other.median), self.median.max(other.median));
            b > a * (1.0 + RUN_NOISE)
        } else {
            !self.overlaps(other)
        }
    }
}

/// `P(Bin(n, 1/2) <= k)`, summed in log space (no overflow for any n).
fn binomial_half_cdf(n: usize, k: usize) -> f64 {
    let ln_half_n = -(n as f64) * std::f64::consts::LN_2;
    let mut ln_choose = 0.0; // ln C(n, 0)
    let mut sum = 0.0;
    for j in 0..=k.min(n) {
        if j > 0 {
            ln_choose += ((n + 1 - j) as f64).ln() - (j as f64).ln();
        }
        sum += (ln_choose + ln_half_n).exp();
    }
    sum.min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order statistics' coverage against a direct count: for n = 15
    /// (three repeats of five batches) the pair (x_4, x_12) has
    /// 1 - 2 (1 + 15 + 105 + 455) / 2^15 = 0.96484375.
    #[test]
    fn fifteen_samples_give_the_fourth_and_twelfth() {
        let samples: Vec<f64> = (1..=15).map(f64::from).collect();
        let Some(t) = TimeInterval::of(&samples) else {
            panic!("no interval")
        };
        assert_eq!((t.low, t.median, t.high), (4.0, 8.0, 12.0));
        assert!((t.confidence - (1.0 - 2.0 * 576.0 / 32768.0)).abs() < 1e-15);
        // One sample: no interval to speak of.
        let Some(one) = TimeInterval::of(&[2.0]) else {
            panic!("no interval")
        };
        assert_eq!((one.low, one.high, one.confidence), (2.0, 2.0, 0.0));
        assert!(TimeInterval::of(&[f64::NAN]).is_none());
    }

    /// A fast call is repeated in batches; a slow one is read once.
    #[test]
    fn only_calls_below_the_clock_floor_are_repeated() {
        let mut calls = 0;
        // A slow reading is the time: no call again.
        assert_eq!(timed(1.0, || calls += 1), 1.0);
        assert_eq!(calls, 0);
        // 1e-4 s against a floor of 2e-4: five batches of two calls.
        let t = timed(1e-4, || calls += 1);
        assert_eq!(calls, 2 * TIMING_BATCHES);
        assert!(t.is_finite() && t >= 0.0);
    }
}

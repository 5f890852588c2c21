//! The errors of a set of walks: the sample standard error, the Wilson
//! interval for 0/1 scores, and the bound `W(n) D` when every walk scored
//! alike.

use crate::error::QuadError;
use crate::quadrature::monte_carlo::Welford;

use super::Tracked;

/// The `z` of the two-sided 95% intervals the errors stand for.
const Z: f64 = 1.96;

/// `W(n) = z / (2 (n + z^2))`: the half-width of the Wilson score interval
/// for 0 successes in `n` trials, `z^2 / (2 (n + z^2))`, divided by `z`.
fn wilson_unseen(n: u64) -> f64 {
    let n = n as f64;
    Z / (2.0 * (n + Z * Z))
}

/// The error of `k` successes in `n` 0/1 trials: the half-width of the
/// Wilson score interval, `z/(n + z^2) sqrt(k (n - k)/n + z^2/4)`, divided
/// by `z`. Up to O(1/n) it is the standard error `sqrt(p (1 - p) / n)` once
/// `k` and `n - k` are large; at `k = 0` or `k = n` it is `W(n)`, not 0.
/// `k > n` or `n = 0` is an error.
pub fn wilson_error(k: u64, n: u64) -> Result<f64, QuadError> {
    if n == 0 || k > n {
        return Err(QuadError::invalid(
            "k",
            format!("{k} of n = {n}"),
            "0 <= k <= n successes of n >= 1 trials",
        ));
    }
    let (k, n) = (k as f64, n as f64);
    Ok((k * (n - k) / n + 0.25 * Z * Z).sqrt() / (n + Z * Z))
}

/// Walk scores summed as the tracking errors need them.
#[derive(Debug, Clone, Default)]
pub(super) struct Scores {
    walks: Welford<f64>,
    first: Option<f64>,
    alike: bool,
}

impl Scores {
    pub(super) fn add(&mut self, x: f64) {
        match self.first {
            None => {
                self.first = Some(x);
                self.alike = true;
            }
            Some(f) => self.alike &= f == x,
        }
        self.walks.add(x);
    }

    /// The mean with its standard error; when every walk scored alike, the
    /// bound `W(n) D` with `D = spread(x)` instead.
    pub(super) fn tracked(&self, evaluations: u64, spread: impl Fn(f64) -> f64) -> Tracked {
        let (n, x) = (self.walks.count(), self.walks.mean());
        // No unseen outcome can move a score (D = 0): the walks are exact,
        // not merely alike, and carry neither a bound nor the flag.
        let exact = self.alike && spread(x) == 0.0;
        let error = if self.alike {
            wilson_unseen(n) * spread(x)
        } else {
            self.walks.interval_error()
        };
        Tracked {
            value: x,
            error,
            evaluations,
            walks: n,
            all_alike: self.alike && !exact,
        }
    }

    /// The mean of 0/1 scores with the Wilson error.
    pub(super) fn binary(&self, evaluations: u64) -> Tracked {
        let n = self.walks.count();
        let x = self.walks.mean();
        // n >= 2 walks (checked on entry) and 0 <= k <= n by construction.
        let k = ((x * n as f64).round() as u64).min(n);
        Tracked {
            value: x,
            error: wilson_error(k, n.max(1)).unwrap_or(f64::INFINITY),
            evaluations,
            walks: n,
            all_alike: self.alike,
        }
    }
}

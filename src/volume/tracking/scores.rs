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

/// The error of `k` successes in `n` 0/1 trials, read around `p = k / n`:
/// the standard error of a proportion taken at Wilson's centre instead of
/// at `p`,
///
/// ```text
/// error = sqrt(c (1 - c) / (n - 1)),   c = (k + z^2/2) / (n + z^2),
/// ```
///
/// the ordinary standard error up to O(1/n) once `k` and `n - k` are large,
/// and not 0 at `k = 0` or `k = n` (about `1.39 / n` there). Exact binomial
/// sums over the runs with `0 < k < n` (those at 0 or `n` are flagged as
/// all alike) give the coverage of `p +- 1.96 error` at 92-100% at 16
/// trials and 93-96% at 256 for success rates from 0.03 to 0.5 (at 16 the
/// runs of a small rate with `k >= 1` cover more by construction); Wilson's
/// half-width around `p` (the interval centred at `c`, read around `p`)
/// covered 86-88% at 16 trials for rates 0.2 to 0.4. `k > n`, `n < 2`
/// are errors.
pub fn wilson_error(k: u64, n: u64) -> Result<f64, QuadError> {
    if n < 2 || k > n {
        return Err(QuadError::invalid(
            "k",
            format!("{k} of n = {n}"),
            "0 <= k <= n successes of n >= 2 trials",
        ));
    }
    let (k, n) = (k as f64, n as f64);
    let centre = (k + 0.5 * Z * Z) / (n + Z * Z);
    Ok((centre * (1.0 - centre) / (n - 1.0)).sqrt())
}

/// How the non-zero scores `w_i` share their sum: their effective number
/// `ESS = (sum |w_i|)^2 / sum w_i^2` (about their count where they are alike
/// in size, about 1 where one carries the sum), summed relative to the
/// largest `|w|` so far (rescaled when it grows) so that scores of 1e-200
/// and less neither underflow when squared nor lose the ratio; and the
/// sample variance `s^2` of `ln |w_i|`.
#[derive(Debug, Clone, Default)]
struct Dispersion {
    largest: f64,
    sum: f64,
    squares: f64,
    count: u64,
    logs: Welford<f64>,
}

impl Dispersion {
    fn add(&mut self, x: f64) {
        let a = x.abs();
        if a == 0.0 || !a.is_finite() {
            return;
        }
        if a > self.largest {
            let r = if self.largest > 0.0 {
                self.largest / a
            } else {
                0.0
            };
            self.sum *= r;
            self.squares *= r * r;
            self.largest = a;
        }
        let y = a / self.largest;
        self.sum += y;
        self.squares += y * y;
        self.count += 1;
        self.logs.add(a.ln());
    }

    /// True when the non-zero scores' mean rests on scores not seen, by
    /// either of two signs (at least 4 of them):
    /// - a few carry their sum: `ESS < max(2, count / HEAVY_SHARE)`;
    /// - their logarithms spread as a log-normal's whose mean is carried by
    ///   values beyond the largest of `count` draws: for `ln w ~ N(m, s^2)`
    ///   the mean `E w = exp(m + s^2 / 2)` is carried by draws near
    ///   `m + s^2`, the largest of `k` draws lies near `m + s sqrt(2 ln k)`,
    ///   so they are not seen where `s^2 > 2 ln k`.
    fn carried_by_few(&self) -> bool {
        let k = self.count as f64;
        let ess = self.sum * self.sum / self.squares;
        let few = ess < (k / HEAVY_SHARE).max(2.0);
        let s2 = self.logs.standard_error() * self.logs.standard_error() * k;
        let spread = s2 > 2.0 * k.ln();
        self.count >= 4 && (few || spread)
    }
}

/// One of the two signs that the walks' non-zero scores are carried by a
/// few ([`super::Tracked::heavy`]): their effective number below
/// 1/`HEAVY_SHARE` of their count (or 2). Scores of a product of many
/// factors (ratio tracking through an optical depth of 200) give an
/// effective number near 1 at any count; scores with a relative variance
/// `v` give about `count / (1 + v)`, so the flag asks for `v` above 15.
const HEAVY_SHARE: f64 = 16.0;

/// Walk scores summed as the tracking errors need them.
#[derive(Debug, Clone, Default)]
pub(super) struct Scores {
    walks: Welford<f64>,
    first: Option<f64>,
    alike: bool,
    dispersion: Dispersion,
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
        self.dispersion.add(x);
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
            heavy: !self.alike && self.dispersion.carried_by_few(),
            underflows: false,
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
            error: wilson_error(k, n).unwrap_or(f64::INFINITY),
            evaluations,
            walks: n,
            all_alike: self.alike,
            heavy: false,
            underflows: false,
        }
    }
}

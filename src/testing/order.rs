//! The convergence order of a method: the least-squares slope of
//! `ln error` against `ln budget`, with the regression's 95% confidence
//! interval ([`crate::experiment::fit::line`], as the reports fit it).

use std::fmt;

use crate::error::QuadError;
use crate::experiment::fit;

use super::{check_count, repeat_rng};

/// A fitted order; see the [module](self).
///
/// ```
/// use lightquad::testing::Order;
/// use lightquad::quadrature::{Rule, Trapezoid};
/// use lightquad::rand::SeedableRng;
///
/// // The composite trapezoid rule on int_0^1 e^x dx: order -2.
/// let mut rng = lightquad::rand_pcg::Pcg64::seed_from_u64(0);
/// let mut points = Vec::new();
/// for n in [64, 128, 256, 512, 1024] {
///     let v = Trapezoid.integrate(n, &mut rng, |u: [f64; 1]| u[0].exp())?.value;
///     points.push((n as f64, (v - (1f64.exp() - 1.0)).abs()));
/// }
/// let order = Order::fit(&points)?;
/// order.assert_near(-2.0, 0.05);
/// assert!(order.check(-1.0, 0.5).is_err());
/// # Ok::<(), lightquad::QuadError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Order {
    /// The slope: the order (`-0.5` for Monte Carlo against samples).
    pub slope: f64,
    /// Its 95% confidence interval (infinite through two points).
    pub interval: [f64; 2],
    /// The largest factor by which a point lies off the fitted line.
    pub off: f64,
    /// The `(budget, error)` points fitted.
    pub points: Vec<(f64, f64)>,
}

impl Order {
    /// The order of `(cost, error)` points: at least two of distinct
    /// cost, each with a positive, finite cost and error, else an error
    /// naming the point.
    pub fn fit(points: &[(f64, f64)]) -> Result<Order, QuadError> {
        // Every point is fitted or the call fails: a point the fit left out
        // (an error that overflowed, an exact 0) would hide what it says.
        if let Some((k, p)) = points
            .iter()
            .enumerate()
            .find(|(_, (c, e))| !(c.is_finite() && *c > 0.0 && e.is_finite() && *e > 0.0))
        {
            return Err(QuadError::invalid(
                format!("points[{k}]"),
                format!("{p:?}"),
                "a finite cost > 0 and a finite error > 0 (an exact result has no order)",
            ));
        }
        let Some(line) = fit::line(points) else {
            return Err(QuadError::invalid(
                "points",
                format!("{points:?}"),
                "at least two points of distinct cost with a finite cost and error > 0",
            ));
        };
        Ok(Order {
            slope: line.slope,
            interval: [line.slope - line.half_width, line.slope + line.half_width],
            off: line.off,
            points: points.to_vec(),
        })
    }

    /// The order of `method`'s root-mean-square error against `reference`
    /// over `repeats` seeded repeats at each budget (one for a
    /// deterministic method). A value that is not finite is an error
    /// naming its budget and repeat.
    pub fn measure<F>(
        budgets: &[usize],
        repeats: usize,
        seed: u64,
        reference: f64,
        mut method: F,
    ) -> Result<Order, QuadError>
    where
        F: FnMut(usize, &mut rand_pcg::Pcg64) -> f64,
    {
        check_count("budgets", budgets.len(), 2, 10_000)?;
        check_count("repeats", repeats, 1, 100_000_000)?;
        if !reference.is_finite() {
            return Err(QuadError::invalid("reference", reference, "a finite value"));
        }
        let mut points = Vec::with_capacity(budgets.len());
        for (b, &n) in budgets.iter().enumerate() {
            let mut sum = 0.0;
            for k in 0..repeats {
                let v = method(n, &mut repeat_rng(seed, b * repeats + k));
                if !v.is_finite() {
                    return Err(QuadError::invalid(
                        format!("the value at budget {n}, repeat {k}"),
                        v,
                        "a finite value",
                    ));
                }
                sum += (v - reference) * (v - reference);
            }
            points.push((n as f64, (sum / repeats as f64).sqrt()));
        }
        Order::fit(&points)
    }

    /// `Ok` when the slope is within `tolerance` of `expected`, else the
    /// order in words.
    pub fn check(&self, expected: f64, tolerance: f64) -> Result<(), String> {
        if (self.slope - expected).abs() <= tolerance {
            Ok(())
        } else {
            Err(format!(
                "the order is not {expected} within {tolerance}: {self}"
            ))
        }
    }

    /// Panics unless the slope is within `tolerance` of `expected`.
    pub fn assert_near(&self, expected: f64, tolerance: f64) {
        if let Err(e) = self.check(expected, tolerance) {
            panic!("{e}");
        }
    }
}

impl fmt::Display for Order {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "slope {:.3} (95% interval {:.3}..{:.3}) through {} points, the farthest {:.2}x off the line",
            self.slope,
            self.interval[0],
            self.interval[1],
            self.points.len(),
            self.off
        )
    }
}

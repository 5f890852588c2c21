//! Fitted convergence orders.
//!
//! ```
//! use lightquad::experiment::fit::{fitted_line, fitted_order};
//!
//! // Errors of an order-2 rule, e = 3 n^-2, have slope -2 and lie on the line
//! // (the largest factor a point is off it: 1).
//! let law: Vec<(f64, f64)> = [4.0, 8.0, 16.0, 32.0].iter().map(|&n: &f64| (n, 3.0 / (n * n))).collect();
//! let (slope, off) = fitted_line(&law).ok_or("no fit")?;
//! assert!((slope + 2.0).abs() < 1e-12 && (off - 1.0).abs() < 1e-12);
//! // An exact result (error 0) carries no slope and is left out; one point is no fit.
//! let mut with_exact = law.clone();
//! with_exact.push((64.0, 0.0));
//! assert_eq!(fitted_order(&with_exact), Some(slope));
//! assert_eq!(fitted_order(&law[..1]), None);
//! // Errors that jump up and down by 1000x: a slope, but no order.
//! let (_, off) = fitted_line(&[(1.0, 1.0), (2.0, 1e-3), (4.0, 1.0), (8.0, 1e-3)]).ok_or("no fit")?;
//! assert!(off > 10.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

/// Least-squares slope of `ln(error)` against `ln(cost)`: the observed order of
/// convergence (`-2` for the trapezoid rule against nodes per axis, `-0.5` for
/// Monte Carlo against samples). Points with a zero or non-finite error are
/// left out (an exact result carries no slope); `None` below two points.
pub fn fitted_order(points: &[(f64, f64)]) -> Option<f64> {
    fitted_line(points).map(|(slope, _)| slope)
}

/// [`fitted_order`] with the largest distance of a point from the fitted
/// line, as a factor (`e^max |residual|` in log space): near 1 where the
/// errors follow a power law, large where they oscillate (a kink between
/// nodes that moves with n), so the slope is not an order.
pub fn fitted_line(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    line(points).map(|l| (l.slope, l.off))
}

/// A least-squares line through `(ln cost, ln error)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// The slope: the observed order.
    pub slope: f64,
    /// `ln error` where `ln cost` is 0.
    pub intercept: f64,
    /// The largest factor by which a point lies off the line.
    pub off: f64,
    /// Half the width of the slope's 95% confidence interval: `t(0.975,
    /// m - 2) s / sqrt(Sxx)` with `s^2` the residuals' mean square over
    /// `m - 2`; infinite through two points (no residual to judge by).
    pub half_width: f64,
    /// Points fitted.
    pub points: usize,
}

impl Line {
    /// The cost at which the line reaches `error`: `exp((ln error - intercept) / slope)`;
    /// None unless the slope is negative.
    pub fn cost_at(&self, error: f64) -> Option<f64> {
        (self.slope < 0.0).then(|| ((error.ln() - self.intercept) / self.slope).exp())
    }
}

/// The least-squares line of `ln(error)` against `ln(cost)` with its
/// slope's confidence interval (the regression's t interval: exact for
/// errors scattered normally about a power law in log space); points with
/// a zero or non-finite error or cost left out; None below two points.
pub fn line(points: &[(f64, f64)]) -> Option<Line> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(c, e)| *c > 0.0 && *e > 0.0 && c.is_finite() && e.is_finite())
        .map(|(c, e)| (c.ln(), e.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let m = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / m;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / m;
    let (num, den) = pts.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    if den <= 0.0 {
        return None;
    }
    let slope = num / den;
    let residuals: Vec<f64> = pts.iter().map(|(x, y)| y - my - slope * (x - mx)).collect();
    let worst = residuals.iter().map(|r| r.abs()).fold(0.0f64, f64::max);
    let half_width = if pts.len() > 2 {
        let dof = m - 2.0;
        let s2 = residuals.iter().map(|r| r * r).sum::<f64>() / dof;
        t_975(dof) * (s2 / den).sqrt()
    } else {
        f64::INFINITY
    };
    Some(Line {
        slope,
        intercept: my - slope * mx,
        off: worst.exp(),
        half_width,
        points: pts.len(),
    })
}

/// The 0.975 quantile of Student's t with `dof` degrees of freedom (12.71
/// for one, 4.30 for two).
fn t_975(dof: f64) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    StudentsT::new(0.0, 1.0, dof).map_or(f64::INFINITY, |t| t.inverse_cdf(0.975))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_power_law_fits_exactly_and_an_oscillation_does_not() {
        let law: Vec<(f64, f64)> = [4.0f64, 8.0, 16.0, 32.0]
            .map(|n| (n, 3.0 * n.powi(-2)))
            .into();
        let Some((slope, off)) = fitted_line(&law) else {
            panic!("no fit")
        };
        assert!((slope + 2.0).abs() < 1e-12 && (off - 1.0).abs() < 1e-12);
        // Errors of GL on a kink that moves between nodes (the voxel grid's
        // I_L, n = 128..1024 in the independent check): 8.9e-8, 4.6e-10,
        // 1.1e-8, 1.1e-9.
        let kink = [
            (128.0, 8.9e-8),
            (192.0, 4.6e-10),
            (256.0, 1.1e-8),
            (1024.0, 1.1e-9),
        ];
        let Some((_, off)) = fitted_line(&kink) else {
            panic!("no fit")
        };
        assert!(off > 10.0, "{off}");
    }

    /// The slope's interval against a hand computation: through (1, e^0),
    /// (2, e^-1.1), (4, e^-1.9) in log-log, x = 0, ln 2, ln 4; the t
    /// quantile for one degree of freedom is tan(0.475 pi) = 12.7062.
    #[test]
    fn the_slope_interval_is_the_regression_t_interval() {
        let pts = [(1.0, 1.0), (2.0, (-1.1f64).exp()), (4.0, (-1.9f64).exp())];
        let Some(l) = line(&pts) else {
            panic!("no fit")
        };
        let (x, y) = ([0.0, 2f64.ln(), 4f64.ln()], [0.0, -1.1, -1.9]);
        let (mx, my) = (x.iter().sum::<f64>() / 3.0, y.iter().sum::<f64>() / 3.0);
        let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
        let b = x
            .iter()
            .zip(&y)
            .map(|(a, c)| (a - mx) * (c - my))
            .sum::<f64>()
            / sxx;
        let rss: f64 = x
            .iter()
            .zip(&y)
            .map(|(a, c)| (c - my - b * (a - mx)).powi(2))
            .sum();
        let t = (0.475 * std::f64::consts::PI).tan();
        assert!((l.slope - b).abs() < 1e-14);
        assert!((l.half_width - t * (rss / sxx).sqrt()).abs() < 1e-9 * l.half_width);
        // On a power law the interval closes; through two points it is open.
        let Some(law) = line(&[(1.0, 1.0), (2.0, 0.25), (4.0, 0.0625)]) else {
            panic!("no fit")
        };
        assert!(law.half_width < 1e-12, "{}", law.half_width);
        assert_eq!(line(&pts[..2]).map(|l| l.half_width), Some(f64::INFINITY));
        // The cost where the law reaches 1e-4: n^-2 = 1e-4 at n = 100.
        assert!(law.cost_at(1e-4).is_some_and(|n| (n - 100.0).abs() < 1e-9));
    }
}

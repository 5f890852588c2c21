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
    let worst = pts
        .iter()
        .map(|(x, y)| (y - my - slope * (x - mx)).abs())
        .fold(0.0f64, f64::max);
    Some((slope, worst.exp()))
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
}

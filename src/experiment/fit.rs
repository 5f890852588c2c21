//! Fitted convergence orders.

/// Least-squares slope of `ln(error)` against `ln(cost)`: the observed order of
/// convergence (`-2` for the trapezoid rule against nodes per axis, `-0.5` for
/// Monte Carlo against samples). Points with a zero or non-finite error are
/// left out (an exact result carries no slope); `None` below two points.
pub fn fitted_order(points: &[(f64, f64)]) -> Option<f64> {
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
    (den > 0.0).then(|| num / den)
}
